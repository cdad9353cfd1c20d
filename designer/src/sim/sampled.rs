//! Sampled-data simulation: a digital controller in the loop.
//!
//! The controller is called at every sample time `t_k = k·Ts` (`k = 0, 1, …`,
//! `t_k ≤ t_end`) with a [`Measurement`] of the plant there; its output is held
//! constant (zero-order hold) until the next sample. Integration stops exactly
//! at each sample and restarts afterwards (the input jumps there), so the
//! result is the exact sampled-data closed loop up to the integration
//! tolerance.
//!
//! The measurement at `t_k` is the state reached with the previous held value
//! (after the events that value caused); events caused by the new value at
//! `t_k` itself (e.g. an immediate lift-off) appear in the recorded output at
//! `t_k`, which follows the post-event convention of [`simulate`](super::simulate).

use super::hybrid::{check_times, Engine, NoQuadrature, Options, Quadrature, SimError, Trajectory};
use super::input::Affine;
use super::{Mode, Plant, State};

/// What the controller sees at a sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measurement {
    pub t: f64,
    /// Full plant state (an observer-based controller uses only part of it).
    pub x: State,
    pub mode: Mode,
}

/// A discrete-time controller: called once per sample, in time order.
pub trait Controller {
    /// The input to hold from `t` until the next sample.
    fn control(&mut self, t: f64, m: &Measurement) -> f64;
}

impl<F: FnMut(f64, &Measurement) -> f64> Controller for F {
    fn control(&mut self, t: f64, m: &Measurement) -> f64 {
        self(t, m)
    }
}

/// Simulates the sampled-data loop from `t = 0` to `t_end`, recording at the
/// sample times `k·Ts ≤ t_end`.
pub fn simulate_sampled<P: Plant, C: Controller + ?Sized>(
    plant: &P,
    controller: &mut C,
    ts: f64,
    t_end: f64,
    x0: State,
    mode0: Mode,
    opts: &Options,
) -> Result<Trajectory, SimError> {
    simulate_sampled_with(
        plant,
        controller,
        ts,
        t_end,
        x0,
        mode0,
        &[],
        &NoQuadrature,
        opts,
    )
}

/// [`simulate_sampled`] that also records at `extra_times` (non-decreasing,
/// within `[0, t_end]`; merged with the sample times) and integrates
/// quadratures.
#[allow(clippy::too_many_arguments)]
pub fn simulate_sampled_with<P: Plant, C: Controller + ?Sized, Q: Quadrature>(
    plant: &P,
    controller: &mut C,
    ts: f64,
    t_end: f64,
    x0: State,
    mode0: Mode,
    extra_times: &[f64],
    quad: &Q,
    opts: &Options,
) -> Result<Trajectory, SimError> {
    if !(ts > 0.0 && ts.is_finite()) {
        return Err(SimError::Options(
            "sample period must be positive and finite",
        ));
    }
    if !(t_end >= 0.0 && t_end.is_finite()) {
        return Err(SimError::Options("t_end must be finite and ≥ 0"));
    }
    if !extra_times.is_empty() {
        check_times(extra_times)?;
        if extra_times[0] < 0.0 || extra_times[extra_times.len() - 1] > t_end {
            return Err(SimError::OutputTimes("extra times outside [0, t_end]"));
        }
    }
    let last = last_sample(ts, t_end);
    let times = merge((0..=last).map(|k| sample_time(k, ts)), extra_times);
    let mut eng = Engine::new(plant, quad, 0.0, x0, mode0, &times, opts)?;
    let mut k = 0u64;
    loop {
        let tk = sample_time(k, ts);
        let m = Measurement {
            t: tk,
            x: eng.state(),
            mode: eng.mode(),
        };
        debug_assert_eq!(eng.t(), tk);
        let hold = Affine::constant(controller.control(tk, &m));
        let t_next = sample_time(k + 1, ts);
        if k == last {
            if tk < t_end {
                eng.advance(t_end, hold)?;
            }
            return eng.finish(hold);
        }
        eng.advance(t_next, hold)?;
        k += 1;
    }
}

fn sample_time(k: u64, ts: f64) -> f64 {
    k as f64 * ts
}

/// Index of the last sample time `≤ t_end`.
fn last_sample(ts: f64, t_end: f64) -> u64 {
    let mut k = (t_end / ts).floor() as u64;
    while sample_time(k, ts) > t_end && k > 0 {
        k -= 1;
    }
    while sample_time(k + 1, ts) <= t_end {
        k += 1;
    }
    k
}

/// Sorted union of two sorted sequences, without duplicates.
fn merge(a: impl Iterator<Item = f64>, b: &[f64]) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::with_capacity(b.len() + a.size_hint().0);
    let mut b = b.iter().copied().peekable();
    for ta in a {
        while let Some(tb) = b.next_if(|&tb| tb < ta) {
            out.push(tb);
        }
        out.push(ta);
    }
    out.extend(b);
    out.dedup();
    out
}
