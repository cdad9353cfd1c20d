//! Voltage edges between samples: where inside its sample interval each step
//! of the measured coil voltage happened (issue 12 §1).
//!
//! A DAQ samples an instantaneous value, so a step of the supply falls
//! anywhere between two samples. Linear interpolation of `v` replays it as a
//! ramp across the interval, equivalent to a step at the midpoint: up to half
//! a sample of volt-second error per edge, which the fit would otherwise
//! explain with a cause that is not there. The edge's instant τ is a
//! nuisance parameter of the record:
//!
//! - [`edges`] finds the steps and a first τ from the current, which changes
//!   slope at τ (and jumps there by k_e·Δv/(N² + R·k_e) with eddy currents,
//!   [JA 41]): cubics through the samples before and after meet at
//!   τ; where they are too noisy to place τ within 0.14 sample (RMS), or do
//!   not meet inside the interval, the midpoint stays.
//! - [`located`] refines τ with a reference model, edge after edge: the
//!   instant whose replay from the sample before the edge (the earlier edges
//!   placed) best matches the current after it. The kink alone cannot follow a current that bends
//!   within a sample or two (a falling edge on a held valve; the reversal of
//!   a Jiles–Atherton core).
//! - [`replay_input`] is the voltage every replay uses: the samples joined
//!   linearly, a step at τ across each placed edge. `diagnose` places the
//!   record's edges once with its baseline, the same for every candidate.

use nalgebra::{SMatrix, SVector};

use crate::description::{Description, Drive};
use crate::model::{Model, ModelPlant};
use crate::replay::rest_state;
use crate::sim::{simulate, InputError, Mode, Options, PiecewiseLinear, State, Trajectory};

use super::Measured;

/// Most samples on each side of an edge that its curves are fitted to.
const SIDE_SAMPLES: usize = 8;
/// Fewest samples on each side (a cubic and its residual scale need 5).
const MIN_SIDE_SAMPLES: usize = 5;
/// A step is an edge when it exceeds this multiple of the voltage noise …
const EDGE_NOISE_MULTIPLE: f64 = 10.0;
/// … and this fraction of the record's voltage span,
const EDGE_SPAN_FRACTION: f64 = 0.05;
/// and the neighbouring steps are below this fraction of it (a step, not
/// a fast ramp or a PWM burst).
const FLAT_FRACTION: f64 = 0.2;
/// How far inside its sample interval a placed edge stays (fraction of a
/// sample): at t_k itself the replayed input's value at that sample would be
/// the step's after value (the right limit at a jump), and with eddy
/// currents the current there, which answers the voltage at once, would
/// jump a sample early.
pub const INSIDE: f64 = 1e-3;
/// τ is kept when its standard error is below this fraction of a sample:
/// the midpoint's own error, uniform over ±½ sample, has an RMS of
/// 1/√12 ≈ 0.29 sample, so a kept τ is at least twice as good.
const MAX_TAU_ERROR: f64 = 0.14;

/// One step of the voltage between samples `k` and `k + 1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Edge {
    /// Index of the last sample before the step.
    pub k: usize,
    /// Estimated instant of the step, in [t_k, t_{k+1}] [s].
    pub tau: f64,
    /// Whether τ was estimated from the current (else the midpoint).
    pub located: bool,
}

/// How the model's coil current answers a voltage step at once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurrentJump {
    /// N [-], R [Ω] at t = 0, dR/dt [Ω/s], k_e [A/V] (`coil.eddy`).
    pub turns: f64,
    pub resistance: f64,
    pub resistance_drift: f64,
    pub eddy: f64,
}

impl CurrentJump {
    /// The coil of `d`.
    pub fn of(d: &crate::description::Description) -> CurrentJump {
        CurrentJump {
            turns: d.coil.turns,
            resistance: d.coil.resistance,
            resistance_drift: d.coil.resistance_drift,
            eddy: d.coil.eddy,
        }
    }

    /// No eddy currents: the current is continuous.
    pub const NONE: CurrentJump = CurrentJump {
        turns: 1.0,
        resistance: 1.0,
        resistance_drift: 0.0,
        eddy: 0.0,
    };

    /// Δi/Δv at time t: k_e/(N² + R(t)·k_e) ([JA 41]).
    fn gain(&self, t: f64) -> f64 {
        let r = self.resistance + self.resistance_drift * t;
        let gain = self.eddy / (self.turns * self.turns + r * self.eddy);
        if gain.is_finite() {
            gain
        } else {
            0.0
        }
    }
}

/// The edges of the measured voltage, each with its instant estimated for a
/// model whose current jumps as `jump` says.
pub fn edges(data: &Measured, jump: CurrentJump) -> Vec<Edge> {
    let steps = step_indices(&data.v);
    steps
        .iter()
        .enumerate()
        .map(|(n, &k)| {
            let lo = if n == 0 { 0 } else { steps[n - 1] + 1 };
            let hi = steps.get(n + 1).copied().unwrap_or(data.len() - 1);
            locate(data, k, lo, hi, jump.gain(data.t[k]))
        })
        .collect()
}

/// The voltage the replays of `diagnose` and `fit` use: the samples joined
/// linearly, and a step at τ across each of the record's placed edges
/// ([`Measured::edges`]; none placed: linear interpolation throughout).
pub fn replay_input(data: &Measured) -> Result<PiecewiseLinear, InputError> {
    match data.len() {
        0 => PiecewiseLinear::new(Vec::new(), Vec::new()),
        n => input_with(data, 0, n - 1, data.edges.as_deref().unwrap_or(&[])),
    }
}

/// The measured voltage over samples from..=to, joined linearly, a step at
/// τ across each of `edges` (in order; those not inside the range skipped).
fn input_with(
    data: &Measured,
    from: usize,
    to: usize,
    edges: &[Edge],
) -> Result<PiecewiseLinear, InputError> {
    let (t, sample) = knots_with(data, from, to, edges);
    PiecewiseLinear::new(t, sample.iter().map(|&k| data.v[k]).collect())
}

/// The knots of [`replay_input`], and the sample whose voltage each one
/// takes (a perturbation of the samples moves the input by the same
/// knots: `sensitivity::InputPerturbations`).
pub fn replay_knots(data: &Measured) -> (Vec<f64>, Vec<usize>) {
    match data.len() {
        0 => (Vec::new(), Vec::new()),
        n => knots_with(data, 0, n - 1, data.edges.as_deref().unwrap_or(&[])),
    }
}

/// The knots of [`input_with`] and their samples.
fn knots_with(data: &Measured, from: usize, to: usize, edges: &[Edge]) -> (Vec<f64>, Vec<usize>) {
    let mut t = Vec::with_capacity(to + 1 - from + 2 * edges.len());
    let mut sample = Vec::with_capacity(t.capacity());
    let mut edges = edges.iter().skip_while(|e| e.k < from).peekable();
    for k in from..=to {
        t.push(data.t[k]);
        sample.push(k);
        if let Some(e) = edges.next_if(|e| e.k == k && k < to) {
            t.extend([e.tau, e.tau]);
            sample.extend([k, k + 1]);
        }
    }
    (t, sample)
}

/// Samples after an edge that the placement compares: few, so that a
/// model's own error after the edge (the diagnosis's baseline misses the
/// data) is not taken for the edge's instant. (64 samples move a fitted
/// drift rate less with the current noise but the saturation and fringing
/// values more, through the baseline's placement.)
const WINDOW: usize = 16;
/// Trial instants across the interval (fractions of a sample).
const TRIALS: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];

/// Samples before an edge whose mean residual is taken as the replay's
/// offset there (an error carried from earlier, not the edge's).
const OFFSET_SAMPLES: usize = 4;

/// The edges placed by the model `d` itself, in time order: the replay of
/// the record, with the edges placed so far, is advanced to the sample before
/// the next edge; from there, each of [`TRIALS`] is replayed over the next
/// [`WINDOW`] samples, and the instant whose current best matches the
/// measured one (least squares, less the replay's offset before the edge;
/// refined by a parabola) is the edge's. This is the nuisance parameter
/// estimated once for a record and a reference model; the kink of [`edges`]
/// cannot follow a current that bends within a sample or two (a falling
/// edge on a held, saturated valve). Where `d` cannot replay the record, the
/// kink's instants stay for the remaining edges (the replays that follow
/// report the failure).
pub fn located(d: &Description, data: &Measured) -> Vec<Edge> {
    let mut edges = edges(data, CurrentJump::of(d));
    if edges.is_empty() || d.supply.drive != Drive::Voltage {
        return edges;
    }
    let mut model = Model::build(d);
    let plant = ModelPlant::new(&mut model);
    let mut at = Replayed {
        k: 0,
        x: rest_state(&model),
        mode: Mode::StuckMax,
        offset: 0.0,
    };
    for n in 0..edges.len() {
        let previous = n.checked_sub(1).map(|m| edges[m]);
        let Some(next) = advance(&plant, data, &at, edges[n].k, previous) else {
            break;
        };
        at = next;
        let end = edges
            .get(n + 1)
            .map_or(data.len() - 1, |e| e.k)
            .min(at.k + WINDOW);
        if let Some(tau) = place(&plant, data, &at, end) {
            edges[n].tau = tau;
            edges[n].located = true;
        }
    }
    edges
}

/// A replay of the record stopped at sample `k`.
struct Replayed {
    k: usize,
    x: State,
    mode: Mode,
    /// Mean simulated − measured current over the last samples before k.
    offset: f64,
}

/// The replay from `at` to sample `k`, with `previous` (the last placed
/// edge, if it lies at `at.k`) as a step.
fn advance(
    plant: &ModelPlant,
    data: &Measured,
    at: &Replayed,
    k: usize,
    previous: Option<Edge>,
) -> Option<Replayed> {
    let (tr, current) = replay_segment(plant, data, at, k, previous)?;
    let tail = current.len().min(OFFSET_SAMPLES);
    let first = current.len() - tail;
    let offset = (first..current.len())
        .map(|j| current[j] - data.i[at.k + j])
        .sum::<f64>()
        / tail.max(1) as f64;
    Some(Replayed {
        k,
        x: *tr.x.last()?,
        mode: *tr.mode.last()?,
        offset,
    })
}

/// The edge after sample `at.k`: the trial instant whose replay up to sample
/// `end` best matches the measured current, less the offset.
fn place(plant: &ModelPlant, data: &Measured, at: &Replayed, end: usize) -> Option<f64> {
    let k = at.k;
    if end <= k + 1 {
        return None;
    }
    let (t0, dt) = (data.t[k], data.t[k + 1] - data.t[k]);
    let cost = |frac: f64| {
        let edge = Edge {
            k,
            tau: t0 + frac * dt,
            located: true,
        };
        let (_, current) = replay_segment(plant, data, at, end, Some(edge))?;
        Some(
            current
                .iter()
                .zip(&data.i[k..=end])
                .map(|(a, b)| (a - b - at.offset).powi(2))
                .sum::<f64>(),
        )
    };
    let costs: Option<Vec<f64>> = TRIALS.iter().map(|&f| cost(f)).collect();
    // The cost is nearly quadratic in τ (the current after the edge shifts
    // with it): a parabola through the best trial and its neighbours, then
    // again through three points a quarter of the trials' spacing apart.
    let coarse = parabola_minimum(&TRIALS, &costs?)?;
    let h = 0.25 * (TRIALS[1] - TRIALS[0]);
    // (Kept inside the interval: a trial before t_k is no edge of it.)
    let centre = coarse.clamp(h, 1.0 - h);
    let fine = [centre - h, centre, centre + h];
    let costs: Option<Vec<f64>> = fine.iter().map(|&f| cost(f)).collect();
    let frac = parabola_minimum(&fine, &costs?)?.clamp(INSIDE, 1.0 - INSIDE);
    Some(t0 + frac * dt)
}

/// The replay from `at` to sample `to` with `step` (an edge after sample
/// `at.k`, if any), and its coil current at the samples.
fn replay_segment(
    plant: &ModelPlant,
    data: &Measured,
    at: &Replayed,
    to: usize,
    step: Option<Edge>,
) -> Option<(Trajectory, Vec<f64>)> {
    let steps: &[Edge] = match &step {
        Some(e) => std::slice::from_ref(e),
        None => &[],
    };
    let input = input_with(data, at.k, to, steps).ok()?;
    let times = &data.t[at.k..=to];
    let tr = simulate(plant, &input, at.x, at.mode, times, &Options::default()).ok()?;
    let (current, _) = plant.currents_and_voltages(&tr.t, &tr.x, &tr.u);
    Some((tr, current))
}

/// The vertex of the parabola through the lowest of `costs` (at the
/// equally spaced `x`) and its two neighbours (the two nearest when it is an
/// end), within one spacing of that point; the point itself where the three
/// are not convex.
fn parabola_minimum(x: &[f64], costs: &[f64]) -> Option<f64> {
    let best = (0..costs.len()).min_by(|&a, &b| costs[a].total_cmp(&costs[b]))?;
    if costs.len() < 3 {
        return x.get(best).copied();
    }
    let j = best.clamp(1, costs.len() - 2);
    let h = x[j + 1] - x[j];
    let (a, b, c) = (costs[j - 1], costs[j], costs[j + 1]);
    let curvature = a - 2.0 * b + c;
    if !(curvature > 0.0) {
        return Some(x[best]);
    }
    let vertex = x[j] + 0.5 * h * (a - c) / curvature;
    Some(vertex.clamp(x[best] - h, x[best] + h))
}

/// Indices k with a step between samples k and k + 1.
fn step_indices(v: &[f64]) -> Vec<usize> {
    if v.len() < 2 * MIN_SIDE_SAMPLES {
        return Vec::new();
    }
    let d: Vec<f64> = v.windows(2).map(|w| w[1] - w[0]).collect();
    let (lo, hi) = v
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    let threshold = (EDGE_NOISE_MULTIPLE * noise_of_steps(&d)).max(EDGE_SPAN_FRACTION * (hi - lo));
    (0..d.len())
        .filter(|&k| {
            let jump = d[k].abs();
            let flat = |j: Option<usize>| {
                j.and_then(|j| d.get(j))
                    .is_none_or(|x| x.abs() < FLAT_FRACTION * jump)
            };
            jump > threshold && jump > 0.0 && flat(k.checked_sub(1)) && flat(Some(k + 1))
        })
        .collect()
}

/// σ of the sample noise from the first differences: their median absolute
/// value is 0.6745·√2·σ for white noise on a piecewise-constant signal.
fn noise_of_steps(d: &[f64]) -> f64 {
    let mut a: Vec<f64> = d.iter().map(|x| x.abs()).collect();
    a.sort_by(f64::total_cmp);
    let median = a.get(a.len() / 2).copied().unwrap_or(0.0);
    median / (0.6745 * std::f64::consts::SQRT_2)
}

/// The edge between k and k + 1, its curves fitted within samples lo..=hi;
/// the current jumps by `gain`·Δv at the edge.
fn locate(data: &Measured, k: usize, lo: usize, hi: usize, gain: f64) -> Edge {
    let (t0, t1) = (data.t[k], data.t[k + 1]);
    let dt = t1 - t0;
    let mid = 0.5 * (t0 + t1);
    let midpoint = Edge {
        k,
        tau: mid,
        located: false,
    };
    let before = (k + 1).saturating_sub(SIDE_SAMPLES).max(lo)..=k;
    let after = k + 1..=(k + SIDE_SAMPLES).min(hi);
    if before.clone().count() < MIN_SIDE_SAMPLES || after.clone().count() < MIN_SIDE_SAMPLES {
        return midpoint;
    }
    let (Some(a), Some(b)) = (
        Curve::fit(&data.t, &data.i, before, mid, dt),
        Curve::fit(&data.t, &data.i, after, mid, dt),
    ) else {
        return midpoint;
    };
    // Where the two curves meet (x = (τ − mid)/dt): Newton from the midpoint.
    let jump = gain * (data.v[k + 1] - data.v[k]);
    let gap = |x: f64| a.value(x) + jump - b.value(x);
    let mut x = 0.0;
    for _ in 0..3 {
        x -= gap(x) / (a.slope(x) - b.slope(x));
    }
    // δx = −δgap/gap′, both fits' coefficient errors.
    let var = (a.variance(x) + b.variance(x)) / (a.slope(x) - b.slope(x)).powi(2);
    if !(x.is_finite() && var.sqrt() < MAX_TAU_ERROR && x.abs() <= 0.5) {
        return midpoint;
    }
    Edge {
        k,
        tau: (mid + x * dt).clamp(t0 + INSIDE * dt, t1 - INSIDE * dt),
        located: true,
    }
}

/// Coefficients of the curves through the current on each side of an edge:
/// cubics, as the current right after a falling edge on a held valve bends
/// within a few samples (on the semera valve at 20 µs a quadratic places τ
/// 2.4 µs early, a cubic within 0.3 µs).
const COEFFICIENTS: usize = 4;

/// A least-squares polynomial i ≈ Σ c_j·x^j in x = (t − t_ref)/dt with the
/// covariance of its coefficients (residual scale of the fit).
struct Curve {
    c: SVector<f64, COEFFICIENTS>,
    cov: SMatrix<f64, COEFFICIENTS, COEFFICIENTS>,
}

impl Curve {
    fn fit(
        t: &[f64],
        y: &[f64],
        range: std::ops::RangeInclusive<usize>,
        t_ref: f64,
        dt: f64,
    ) -> Option<Curve> {
        let n = range.clone().count();
        // At least one residual degree of freedom for the noise scale.
        let dof = n.checked_sub(COEFFICIENTS).filter(|&d| d > 0)?;
        let mut xtx = SMatrix::<f64, COEFFICIENTS, COEFFICIENTS>::zeros();
        let mut xty = SVector::<f64, COEFFICIENTS>::zeros();
        for j in range.clone() {
            let g = powers((t[j] - t_ref) / dt);
            xtx += g * g.transpose();
            xty += g * y[j];
        }
        let inv = xtx.try_inverse()?;
        let c = inv * xty;
        let rss: f64 = range
            .map(|j| (y[j] - c.dot(&powers((t[j] - t_ref) / dt))).powi(2))
            .sum();
        Some(Curve {
            c,
            cov: inv * (rss / dof as f64),
        })
    }

    fn value(&self, x: f64) -> f64 {
        self.c.dot(&powers(x))
    }

    fn slope(&self, x: f64) -> f64 {
        (1..COEFFICIENTS)
            .map(|j| j as f64 * self.c[j] * x.powi(j as i32 - 1))
            .sum()
    }

    /// Variance of the fitted value at x.
    fn variance(&self, x: f64) -> f64 {
        let g = powers(x);
        (g.transpose() * self.cov * g)[(0, 0)]
    }
}

/// (1, x, x², …)
fn powers(x: f64) -> SVector<f64, COEFFICIENTS> {
    SVector::from_fn(|j, _| x.powi(j as i32))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A first-order circuit driven by a step at `tau`: i is continuous with
    /// a kink there; samples every `dt`, no noise.
    fn rl_record(tau: f64, dt: f64) -> Measured {
        let (r, l, u) = (10.0, 0.05, 12.0);
        let n = 200;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let v = t.iter().map(|&t| if t >= tau { u } else { 0.0 }).collect();
        let i = t
            .iter()
            .map(|&t| {
                if t >= tau {
                    u / r * (1.0 - (-(t - tau) * r / l).exp())
                } else {
                    0.0
                }
            })
            .collect();
        Measured {
            t,
            v,
            i,
            z: None,
            phi: None,
            lambda: None,
            dt,
            file_name: "rl.csv".into(),
            edges: None,
        }
    }

    #[test]
    fn a_step_inside_an_interval_is_placed_from_the_current_kink() {
        let dt = 40e-6;
        for frac in [0.05, 0.3, 0.5, 0.8, 1.0] {
            let tau = 50.0 * dt + frac * dt;
            let e = edges(&rl_record(tau, dt), CurrentJump::NONE);
            assert_eq!(e.len(), 1, "{frac}: {e:?}");
            let e = e[0];
            assert_eq!(e.k, if frac < 1.0 { 50 } else { 50 });
            assert!(e.located, "{frac}");
            // The exponential's curvature over 6 samples biases τ slightly.
            assert!(
                (e.tau - tau).abs() < 0.02 * dt,
                "{frac}: {} vs {tau}",
                e.tau
            );
        }
    }

    #[test]
    fn the_replay_input_steps_at_tau() {
        let dt = 40e-6;
        let tau = 50.3 * dt;
        let data = rl_record(tau, dt);
        let data = Measured {
            edges: Some(edges(&data, CurrentJump::NONE)),
            ..data
        };
        let input = replay_input(&data).unwrap();
        use crate::sim::Input;
        assert_eq!(input.value(tau - 0.01 * dt), 0.0);
        assert_eq!(input.value(tau + 0.01 * dt), 12.0);
        assert_eq!(input.value(data.t[50]), 0.0);
    }

    /// A step right after a sample (or right before the next) stays
    /// [`INSIDE`] the interval: the replay's input at either sample is that
    /// sample's own voltage.
    #[test]
    fn an_edge_at_a_sample_stays_inside_its_interval() {
        use crate::sim::Input;
        let dt = 40e-6;
        for frac in [1e-9, 1.0 - 1e-9] {
            let data = rl_record(50.0 * dt + frac * dt, dt);
            let e = edges(&data, CurrentJump::NONE);
            assert_eq!(e.len(), 1, "{frac}: {e:?}");
            let (t0, t1) = (data.t[e[0].k], data.t[e[0].k + 1]);
            let inside = INSIDE * dt * (1.0 - 1e-9);
            assert!(
                e[0].tau >= t0 + inside && e[0].tau <= t1 - inside,
                "{frac}: {e:?}"
            );
            let input = replay_input(&Measured {
                edges: Some(e.clone()),
                ..data.clone()
            })
            .unwrap();
            assert_eq!(input.value(t0), data.v[e[0].k], "{frac}");
            assert_eq!(input.value(t1), data.v[e[0].k + 1], "{frac}");
        }
    }

    #[test]
    fn a_smooth_voltage_has_no_edges() {
        let mut data = rl_record(1.0, 40e-6);
        data.v = data.t.iter().map(|t| 12.0 * (t / 2e-3).sin()).collect();
        assert!(edges(&data, CurrentJump::NONE).is_empty());
    }
}
