//! The prediction-error update on the observer's innovations: θ chosen so
//! that the unscented Kalman filter's own one-step current predictions over
//! a run are right, i.e. Σ νₖ² minimal, νₖ = i_k − î_{k|k−1} the filter's
//! innovations on the run's measured voltage and current with the model at
//! θ (the output-error scheme of arXiv 2512.15734, with the predictor the
//! design already runs: its filter).
//!
//! Why not the open-loop replay of `replay.rs` for an observer-driven
//! design: the replay's lift-off comes out of the pre-movement's force
//! balance, so its error is a narrow valley in θ; the filter keeps its state
//! near the valve's, so the error is smooth and its minimum wide.
//!
//! νₖ depends on θ through the filter's gains and covariances as well as
//! through the model, so ∂ν/∂θ is taken by forward differences: P filters at
//! θ + h·θ_d,j run in lockstep with the one at θ over the record, and JᵀJ,
//! Jᵀν accumulate on the fly (no stored residuals or Jacobian). Then bounded
//! Levenberg–Marquardt steps in relative coordinates θ = θ_d·(1 + δ), each
//! trial one filter pass. RAM: the record (2·S floats) and P + 1 filters.

use crate::linalg::Scalar;
use crate::math::Real;
use crate::observe::{Jitter, Sampled, Ukf};

use super::{bounded, small, Calibration, Outcome, Record, Refusal, Settings};

/// A filter model with P adapted parameters θ that can be set (the emitted
/// file's `Model`, the designer's tapes).
pub trait Adaptive<T: Scalar, const N: usize, const P: usize>: Sampled<T, N> + Sized {
    /// This model with the adapted parameters at `theta`.
    #[must_use]
    fn with_theta(&self, theta: &[T; P]) -> Self;
}

/// Σ νₖ² over a record and, with the differences, JᵀJ and Jᵀν in relative
/// coordinates (J = ∂ν/∂δ, δ = (θ − θ_now)/θ_d).
struct Normal<T, const P: usize> {
    /// Mean ν² [A²].
    cost: T,
    jtj: [[T; P]; P],
    /// −Jᵀν: the right-hand side of the Gauss–Newton step.
    rhs: [T; P],
}

/// The mean squared innovation of the filter on `model` at `theta` over
/// `record` (∞ where a pass is not finite).
fn cost<M, T, const N: usize, const S: usize, const P: usize, const K: usize>(
    model: &M,
    theta: &[T; P],
    record: &Record<T, K>,
) -> T
where
    M: Adaptive<T, N, P>,
    T: Jitter,
{
    let adapted = model.with_theta(theta);
    let settings = adapted.settings();
    let mut filter = Ukf::<M, T, N, S>::with_model(adapted, &settings);
    let mut sum = T::ZERO;
    for (u, y) in record.samples() {
        filter.step(u, y);
        let nu = filter.innovation().0;
        sum = sum + nu * nu;
    }
    mean(sum, record.len())
}

/// Σ ν² / n (∞ for a non-finite sum or no sample).
fn mean<T: Scalar>(sum: T, n: usize) -> T {
    let n = u32::try_from(n).unwrap_or(u32::MAX);
    if n == 0 || !sum.finite() {
        return T::ONE / T::ZERO;
    }
    sum / small::<T>(n)
}

/// The filter at `theta` and P filters at θ + h·|θ_d,j|, in lockstep over
/// `record`: the cost and the normal equations of ν's forward differences.
fn linearise<M, T, const N: usize, const S: usize, const P: usize, const K: usize>(
    model: &M,
    settings: &Settings<T, P>,
    theta: &[T; P],
    record: &Record<T, K>,
) -> Option<Normal<T, P>>
where
    M: Adaptive<T, N, P>,
    T: Jitter,
{
    let h = settings.difference_step;
    let adapted = model.with_theta(theta);
    let filter_settings = adapted.settings();
    let mut base = Ukf::<M, T, N, S>::with_model(adapted, &filter_settings);
    let mut nudged: [Ukf<M, T, N, S>; P] = core::array::from_fn(|j| {
        let mut t = *theta;
        if let (Some(tj), Some(n)) = (t.get_mut(j), settings.nominal.get(j)) {
            *tj = *tj + h * Real::abs(*n);
        }
        Ukf::with_model(model.with_theta(&t), &filter_settings)
    });
    let mut jtj = [[T::ZERO; P]; P];
    let mut rhs = [T::ZERO; P];
    let mut sum = T::ZERO;
    for (u, y) in record.samples() {
        base.step(u, y);
        let nu = base.innovation().0;
        sum = sum + nu * nu;
        let mut column = [T::ZERO; P];
        for (c, f) in column.iter_mut().zip(nudged.iter_mut()) {
            f.step(u, y);
            *c = (f.innovation().0 - nu) / h;
        }
        for ((row, ci), r) in jtj.iter_mut().zip(&column).zip(rhs.iter_mut()) {
            *r = *r - *ci * nu;
            for (a, cj) in row.iter_mut().zip(&column) {
                *a = *a + *ci * *cj;
            }
        }
    }
    let cost = mean(sum, record.len());
    cost.finite().then_some(Normal { cost, jtj, rhs })
}

/// (JᵀJ + μ·diag JᵀJ + floor)·δ = −Jᵀν; `None` where it does not factor.
fn step<T: Scalar, const P: usize>(normal: &Normal<T, P>, damping: T) -> Option<[T; P]> {
    let mut a = normal.jtj;
    let largest = (0..P)
        .filter_map(|k| a.get(k).and_then(|row| row.get(k)).copied())
        .fold(T::ZERO, |m, d| if d > m { d } else { m });
    // a floor keeps a direction without information from making A singular
    let floor = largest / small::<T>(1_000_000);
    for (k, row) in a.iter_mut().enumerate() {
        let d = row.get_mut(k)?;
        *d = *d * (T::ONE + damping) + floor;
    }
    crate::linalg::cholesky_solve(&a, &normal.rhs)
}

/// One update of θ from a run's `record` (every sample, `settings.decimation`
/// = 1): the record's checks (too short, non-finite, saturated, a supply
/// dip), then up to `settings.iterations` bounded Levenberg–Marquardt steps
/// on Σ νₖ²; θ moves only where the error falls and stays in its domain.
/// `S` is the filter's number of sigma points (2N + 1).
pub fn update<M, T, const N: usize, const S: usize, const P: usize, const K: usize>(
    model: &M,
    settings: &Settings<T, P>,
    record: &Record<T, K>,
    theta: &mut [T; P],
) -> Outcome<T>
where
    M: Adaptive<T, N, P>,
    T: Jitter,
{
    if let Some(refusal) = record.refusal(settings) {
        return Outcome::Refused(refusal);
    }
    let mut fitted = *theta;
    let Some(mut normal) = linearise::<M, T, N, S, P, K>(model, settings, &fitted, record) else {
        return Outcome::Refused(Refusal::NoProgress);
    };
    let before = normal.cost;
    let mut damping = T::ONE / small::<T>(1000);
    let mut moved = false;
    for iteration in 0..settings.iterations {
        let mut accepted = false;
        for _ in 0..6 {
            let Some(delta) = step(&normal, damping) else {
                break;
            };
            let trial = bounded(&fitted, &delta, settings);
            let trial_cost = cost::<M, T, N, S, P, K>(model, &trial, record);
            if trial_cost.finite() && trial_cost < normal.cost {
                fitted = trial;
                damping = damping / small::<T>(4);
                accepted = true;
                moved = true;
                normal.cost = trial_cost;
                break;
            }
            damping = damping * small::<T>(8);
        }
        if !accepted {
            break;
        }
        // the last iteration needs no new Jacobian
        if iteration + 1 < settings.iterations {
            match linearise::<M, T, N, S, P, K>(model, settings, &fitted, record) {
                Some(n) => normal = n,
                None => break,
            }
        }
    }
    if !moved {
        return Outcome::Refused(Refusal::NoProgress);
    }
    *theta = fitted;
    Outcome::Updated {
        before,
        after: normal.cost,
    }
}

impl<T: Jitter, const P: usize> Calibration<T, P> {
    /// Updates θ from a run's `record` by the filter's innovations
    /// ([`update`]) and counts the outcome.
    pub fn update_innovations<
        M: Adaptive<T, N, P>,
        const N: usize,
        const S: usize,
        const K: usize,
    >(
        &mut self,
        model: &M,
        settings: &Settings<T, P>,
        record: &Record<T, K>,
    ) -> Outcome<T> {
        let outcome = update::<M, T, N, S, P, K>(model, settings, record, &mut self.theta);
        self.count(outcome, settings);
        outcome
    }
}
