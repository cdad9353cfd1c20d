//! Run-to-run self-calibration from the coil current, written once for
//! every design and both floats.
//!
//! Exact feedback linearization cancels the model, so every parameter error
//! goes straight into the landing. These devices repeat the same operation,
//! so between two operations the model's identifiable parameters θ are
//! updated from the error between the **measured** coil current and the
//! current the model predicts for the **measured** voltage (the output-error
//! scheme of Serrano-Seco, Ramirez-Laboreo, Moya-Lasheras, arXiv 2512.15734,
//! with a Gauss–Newton step instead of a derivative-free search):
//!
//! - during an operation a [`Record`] keeps the measured voltage and current,
//!   decimated by the design into a fixed buffer (no allocation);
//! - after it, [`calibrate`] replays the voltage through the model from the
//!   rest the record starts at (the flux from the first current), with the
//!   forward sensitivities S = ∂x/∂θ integrated beside the state
//!   ([`replay`]), accumulates JᵀJ and Jᵀe of the current's error, and takes
//!   bounded Levenberg–Marquardt steps in relative coordinates θ = θ_d·(1 + δ);
//! - it refuses a record that does not look like an operation (too short,
//!   non-finite, a saturated ADC, a supply dip, or no evidence of motion:
//!   the replay with the armature held at its start explains the current as
//!   well as the free one) and keeps θ in its physical domain.
//!
//! Two updates share the record, the settings, the bounds and the refusals:
//!
//! - the replay above ([`calibrate`]), for a design whose law reads measured
//!   states: the model as a [`Predictor`] (f, i and their symbolic
//!   Jacobians);
//! - the innovations update ([`innovations`]), for a design an observer
//!   drives, over a whole run: θ makes the UKF's one-step current predictions
//!   right. It is what the emitted file carries (its UKF `Model` is
//!   [`Adaptive`]).
//!
//! Generated code holds the model and the design's [`Settings`]; this module
//! the algorithms. The designer runs the same code on tapes (`reldesign loop
//! --runs`).

pub mod innovations;
mod record;
mod replay;

pub use innovations::Adaptive;
pub use record::Record;
pub use replay::{replay, Replay};

use crate::control::saturate_to;
use crate::linalg::Scalar;
use crate::math::Real;

/// f(x, u; θ) of the continuous model, x = [z, v, φ], with its Jacobians.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Derivative<T, const P: usize> {
    /// ẋ = f(x, u; θ) in free motion.
    pub dx: [T; 3],
    /// ∂f/∂x (rows).
    pub f_x: [[T; 3]; 3],
    /// ∂f/∂θ (rows).
    pub f_theta: [[T; P]; 3],
}

/// The coil current i(x, u; θ) with its gradients.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Current<T, const P: usize> {
    pub i: T,
    /// ∂i/∂x.
    pub i_x: [T; 3],
    /// ∂i/∂θ.
    pub i_theta: [T; P],
}

/// The model the calibration replays, with P adapted parameters θ (the
/// emitted file implements it with straight-line code, the designer with
/// tapes).
pub trait Predictor<T, const P: usize> {
    /// f(x, u; θ) and its Jacobians.
    fn derivative(&self, theta: &[T; P], x: &[T; 3], u: T) -> Derivative<T, P>;
    /// i(x, u; θ) and its gradients.
    fn current(&self, theta: &[T; P], x: &[T; 3], u: T) -> Current<T, P>;
}

/// The design's choices for the calibration (the emitted module's consts).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings<T, const P: usize> {
    /// θ_d: the design's values (the update works relative to them).
    pub nominal: [T; P],
    /// The physical domain: θ stays in [lower, upper].
    pub lower: [T; P],
    pub upper: [T; P],
    /// Largest change of a parameter in one update, relative to θ_d.
    pub max_step: T,
    /// The controller's sample period T_s [s].
    pub sample_period: T,
    /// Samples per stored sample (the replay steps d·T_s).
    pub decimation: u32,
    /// The stops [m].
    pub z_min: T,
    pub z_max: T,
    /// Levenberg–Marquardt iterations per update (each a replay with
    /// sensitivities and at least one without).
    pub iterations: u32,
    /// A record with fewer stored samples is refused.
    pub min_samples: usize,
    /// |i| at or above this [A] is a saturated ADC: the record is refused.
    pub current_limit: T,
    /// A sample whose measured voltage differs from the commanded one by more
    /// than this [V] is a dip of the supply …
    pub dip_tolerance: T,
    /// … and a record with more than this share of such samples is refused.
    pub dip_share: T,
    /// Motion is evident where the free replay leaves less than this share
    /// of the squared error the replay held at its start stop leaves.
    pub motion_evidence: T,
    /// The innovations update's forward-difference step h, relative to θ_d
    /// (unused by the replay, whose sensitivities are symbolic).
    pub difference_step: T,
    /// [A²]: an update that leaves a larger mean squared current error has
    /// not found a model that explains the valve's current, whatever θ
    /// (a valve that departs from its description in a way the adapted
    /// parameters cannot follow, e.g. a hysteretic core);
    /// [`Calibration::unexplained`] counts such updates in a row. Infinite:
    /// never.
    pub unexplained: T,
}

/// Why a record changed nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refusal {
    /// Fewer than `min_samples` stored samples.
    TooShort,
    /// A sample was NaN or infinite.
    NotFinite,
    /// The current reached the ADC's limit.
    Saturated,
    /// The measured voltage fell short of the command: a supply dip.
    SupplyDip,
    /// The replay held at the start stop explains the current as well as
    /// the free one: the armature did not (visibly) move.
    NoMotion,
    /// The replay or the step was not finite, or no step lowered the error.
    NoProgress,
}

/// What an update did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Outcome<T> {
    /// θ moved; the mean squared current error [A²] before and after.
    Updated { before: T, after: T },
    /// θ is unchanged.
    Refused(Refusal),
}

/// The adapted parameters, carried from run to run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Calibration<T, const P: usize> {
    /// θ now.
    pub theta: [T; P],
    /// Updates taken and refused since the last reset.
    pub updates: u32,
    pub refusals: u32,
    /// Updates in a row (refusals skipped) that left a mean squared current
    /// error above [`Settings::unexplained`]: the model, adapted, still does
    /// not explain this valve's current, and its landings are not to be
    /// trusted; 0 after an update that explains it, and after a reset.
    pub unexplained: u32,
}

impl<T: Scalar, const P: usize> Calibration<T, P> {
    /// θ = the design's values.
    #[must_use]
    pub const fn new(settings: &Settings<T, P>) -> Self {
        Calibration {
            theta: settings.nominal,
            updates: 0,
            refusals: 0,
            unexplained: 0,
        }
    }

    /// Back to the design's values (the field engineer's way back).
    pub fn reset(&mut self, settings: &Settings<T, P>) {
        *self = Self::new(settings);
    }

    /// Updates θ from `record` ([`calibrate`]) and counts the outcome.
    pub fn update<M: Predictor<T, P>, const S: usize>(
        &mut self,
        model: &M,
        settings: &Settings<T, P>,
        record: &Record<T, S>,
    ) -> Outcome<T> {
        let outcome = calibrate(model, settings, record, &mut self.theta);
        self.count(outcome, settings);
        outcome
    }

    /// Counts an update's outcome, and whether it left the current
    /// unexplained ([`Settings::unexplained`]).
    fn count(&mut self, outcome: Outcome<T>, settings: &Settings<T, P>) {
        match outcome {
            Outcome::Updated { after, .. } => {
                self.updates = self.updates.saturating_add(1);
                // a NaN error explains nothing
                self.unexplained = if after <= settings.unexplained {
                    0
                } else {
                    self.unexplained.saturating_add(1)
                };
            }
            Outcome::Refused(_) => self.refusals = self.refusals.saturating_add(1),
        }
    }
}

/// One update of θ from `record`: the checks, then up to
/// `settings.iterations` bounded Levenberg–Marquardt steps on the record's
/// current error; θ is left unchanged on a refusal.
pub fn calibrate<T: Scalar, M: Predictor<T, P>, const P: usize, const S: usize>(
    model: &M,
    settings: &Settings<T, P>,
    record: &Record<T, S>,
    theta: &mut [T; P],
) -> Outcome<T> {
    if let Some(refusal) = record.refusal(settings) {
        return Outcome::Refused(refusal);
    }
    let mut fitted = *theta;
    let mut current = replay(model, settings, record, &fitted, true, false);
    if !current.cost.finite() {
        return Outcome::Refused(Refusal::NoProgress);
    }
    let before = current.cost;
    let mut damping = T::ONE / small::<T>(1000);
    let mut moved = false;
    for _ in 0..settings.iterations {
        let mut accepted = false;
        for _ in 0..6 {
            let Some(step) = lm_step(&current, damping) else {
                break;
            };
            let trial_theta = bounded(&fitted, &step, settings);
            let trial = replay(model, settings, record, &trial_theta, true, false);
            if trial.cost.finite() && trial.cost < current.cost {
                fitted = trial_theta;
                current = trial;
                damping = damping / small::<T>(4);
                accepted = true;
                moved = true;
                break;
            }
            damping = damping * small::<T>(8);
        }
        if !accepted {
            break;
        }
    }
    if !moved {
        return Outcome::Refused(Refusal::NoProgress);
    }
    // motion: the fitted model held at its start stop must explain the
    // current clearly worse than the free one
    let held = replay(model, settings, record, &fitted, false, true);
    if current.cost >= settings.motion_evidence * held.cost || !held.cost.finite() {
        return Outcome::Refused(Refusal::NoMotion);
    }
    *theta = fitted;
    Outcome::Updated {
        before,
        after: current.cost,
    }
}

/// The Levenberg–Marquardt step δ in relative coordinates:
/// (JᵀJ + μ·diag(JᵀJ))·δ = Jᵀe; `None` where it does not factor.
fn lm_step<T: Scalar, const P: usize>(r: &Replay<T, P>, damping: T) -> Option<[T; P]> {
    let mut a = r.jtj;
    for (k, row) in a.iter_mut().enumerate() {
        let d = row.get_mut(k)?;
        // a floor keeps a column without information from making A singular
        *d = *d * (T::ONE + damping) + r.jtj_floor * damping;
    }
    crate::linalg::cholesky_solve(&a, &r.jte)
}

/// θ_d·(1 + δ) added to θ, each change bounded by `max_step`·θ_d and θ kept
/// in [lower, upper].
fn bounded<T: Scalar, const P: usize>(
    theta: &[T; P],
    step: &[T; P],
    settings: &Settings<T, P>,
) -> [T; P] {
    let mut next = *theta;
    let limits = settings.lower.iter().zip(&settings.upper);
    for ((((t, s), n), (lo, hi)), out) in theta
        .iter()
        .zip(step)
        .zip(&settings.nominal)
        .zip(limits)
        .zip(next.iter_mut())
    {
        let s = saturate_to(*s, -settings.max_step, settings.max_step);
        let value = *t + s * Real::abs(*n);
        *out = saturate_to(value, *lo, *hi);
    }
    next
}

/// A small integer as T (no `as`).
pub(crate) fn small<T: Scalar>(n: u32) -> T {
    let mut x = T::ZERO;
    let mut bit = T::ONE;
    let mut n = n;
    while n > 0 {
        if n & 1 == 1 {
            x = x + bit;
        }
        bit = bit + bit;
        n >>= 1;
    }
    x
}
