//! The controller's design decisions as plain data: the law's values (the gains
//! K of [PT 48], or the sliding surface [SM 17]), the guard at φ → 0, the
//! landed band, the press and the creep after t_f
//! (perfect-tracking-soft-landing [PT §3.2] and [PT §4]). Code generation only renders
//! a [`ControllerDesign`]; the runtime's `control` module applies it.

pub use crate::description::triple_pole_settling_product;
use crate::description::{Gains, Operation};
use crate::model::Model;

use crate::design::derive::linearization::{FluxSquared, Linearization};
use crate::design::error::PlanError;
use crate::design::trajectory::feasibility::Feasibility;
use crate::design::trajectory::optimal::OptimalTrajectory;
use crate::design::trajectory::segments::Segments;
use crate::design::trajectory::takeoff::Takeoff;

/// Fraction of the smallest reference flux below which the law is not
/// evaluated (before rounding down to one significant digit).
const GUARD_FRACTION: f64 = 1e-3;

/// Fraction of the stroke within which the armature counts as landed.
const LANDED_FRACTION: f64 = 1e-9;
/// Fraction of the stroke within which an estimated armature had arrived at
/// t_f + the arrival margin (the bounce that counts, issue 35).
const ESTIMATED_ARRIVAL_FRACTION: f64 = 1e-2;
/// The reference after t_f lies this fraction of the stroke beyond the end stop.
const PRESS_FRACTION: f64 = 1e-6;
/// After t_f the reference creeps on beyond the stop by this fraction of the
/// stroke per motion time t_f − t₀ …
const CREEP_FRACTION: f64 = 2.5e-3;
/// … up to this fraction of the stroke beyond it.
const CREEP_MAX_FRACTION: f64 = 0.05;

/// Reference samples per segment when searching the smallest flux.
const FLUX_SAMPLES: usize = 64;

/// K = [k1, k2, k3] of [PT 48] (see [`Gains::k`]).
pub fn gains(g: &Gains) -> [f64; 3] {
    g.k()
}

/// One designed operation: its reference, feasibility and table.
#[derive(Debug, Clone)]
pub struct DesignedOperation {
    pub operation: Operation,
    /// Rest position before t₀ (z₀ of [PT 51]).
    pub z0: f64,
    /// Rest position after t_f (z_f of [PT 51]); the end stop of the hold.
    pub zf: f64,
    pub feasibility: Feasibility,
    /// z_m on [t₀, t_f], times from the operation's start.
    pub table: Segments,
    /// The energy-optimal solution when the shape is `energy-optimal`.
    pub optimal: Option<OptimalTrajectory>,
    /// The shortest takeoff the supply allows against the planned one
    /// (`trajectory/takeoff.rs`); `None` in a design not made by `plan.rs`.
    pub takeoff: Option<Takeoff>,
}

/// The law's own design values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LawDesign {
    /// K = [k1, k2, k3] of [PT 48] (see [`gains`]).
    FeedbackLinearization { gains: [f64; 3] },
    /// λ₁, λ₂ of the surface [SM 17]; with `nonnegative_current` the step
    /// reads the current and keeps it ≥ 0 ([SM §5]).
    SlidingMode {
        lambda1: f64,
        lambda2: f64,
        nonnegative_current: bool,
    },
    /// p of the surface [JA 88] and K of the reaching law [JA 93]: the law
    /// [JA 89] is the tracking law [PT 50] with the gains
    /// [`model_sliding_gains`].
    ModelSlidingMode { p: f64, k: f64 },
}

/// The gains K of [PT 48] that make [PT 50] the model-based sliding-mode law
/// [JA 89]: with e = x − x_r, [JA 89] asks z⁽³⁾ = j_r − 2p·ė_a… precisely
/// w = j_r − 2p·e_a − p²·e_v − K·s, s = e_a + 2p·e_v + p²·e_z [JA 88], so
/// w = j_r − (2p + K)·e_a − (p² + 2pK)·e_v − K·p²·e_z: K = [K·p², p² + 2pK,
/// 2p + K], the error dynamics (d/dt + p)²(d/dt + K).
pub fn model_sliding_gains(p: f64, k: f64) -> [f64; 3] {
    [k * p * p, p * p + 2.0 * p * k, 2.0 * p + k]
}

impl LawDesign {
    /// K of the tracking law [PT 50], for the laws that are it.
    pub fn tracking_gains(&self) -> Option<[f64; 3]> {
        match *self {
            LawDesign::FeedbackLinearization { gains } => Some(gains),
            LawDesign::ModelSlidingMode { p, k } => Some(model_sliding_gains(p, k)),
            LawDesign::SlidingMode { .. } => None,
        }
    }

    /// The values that must be positive and finite, by name.
    fn positive_values(&self) -> Vec<(String, f64)> {
        match *self {
            LawDesign::FeedbackLinearization { gains } => gains
                .iter()
                .enumerate()
                .map(|(k, &g)| (format!("k{}", k + 1), g))
                .collect(),
            LawDesign::SlidingMode {
                lambda1, lambda2, ..
            } => vec![("lambda1".into(), lambda1), ("lambda2".into(), lambda2)],
            LawDesign::ModelSlidingMode { p, k } => vec![("p".into(), p), ("k".into(), k)],
        }
    }
}

/// What the description asks of the controller: the inputs of the decisions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControllerSpec {
    pub law: LawDesign,
    /// T_s [s].
    pub sample_period: f64,
    /// Supply limits [V or A].
    pub u_min: f64,
    pub u_max: f64,
    /// t₀, t_f [s] from the operation's start.
    pub takeoff: f64,
    pub landing: f64,
    /// `[controller] creep_speed` [m/s]; `None`: the default creep.
    pub creep_speed: Option<f64>,
    /// `[controller] landed_band` [m]; `None`: 10⁻⁹ of the stroke.
    pub landed_band: Option<f64>,
    /// The law reads an estimate of the position (`[controller] estimator`).
    pub estimated: bool,
}

/// The designed controller: everything the emitted module states, as numbers.
#[derive(Debug, Clone)]
pub struct ControllerDesign {
    pub linearization: Linearization,
    /// The law and its design values.
    pub law: LawDesign,
    /// T_s [s]: the controller runs once per sample period.
    pub sample_period: f64,
    /// Supply limits: every output is saturated to [u_min, u_max].
    pub u_min: f64,
    pub u_max: f64,
    /// t₀, t_f [s] from the operation's start.
    pub takeoff: f64,
    pub landing: f64,
    /// [Wb]: where φ ≤ `phi_guard` the law is not evaluated and u = u_max;
    /// 10⁻³ of the smallest flux the reference needs, rounded down.
    pub phi_guard: f64,
    /// [m]: within this distance of the end stop the armature is in contact
    /// (the expert rules after t_f); 10⁻⁹ of the stroke, rounded down.
    pub landed_band: f64,
    /// After t_f the reference lies `press`·stroke beyond the end stop …
    pub press: f64,
    /// … and creeps on at `creep`·stroke per second [1/s] …
    pub creep: f64,
    /// … up to `creep_max`·stroke beyond it.
    pub creep_max: f64,
    /// [s] after t_f: an armature not at its stop by then is driven there
    /// (`reldesign_runtime::control::finish_stroke`): the motion time
    /// t_f − t₀, so that a slow landing is not pushed.
    pub arrival_margin: f64,
    /// [m]: read farther than this from its stop at t_f + `arrival_margin`
    /// (and not held there) the armature landed late. `landed_band` where
    /// the law reads the position; where it reads an estimate, which creeps
    /// onto its clamp, the larger of it and 1 % of the stroke (below a
    /// standoff: an estimate hovering where the approach starts is late).
    pub arrival_band: f64,
    /// In the order of `[trajectory].operations`, no operation twice.
    pub operations: Vec<DesignedOperation>,
}

impl ControllerDesign {
    /// Checks `spec` and the operations' tables, and takes the decisions:
    /// the guard threshold from the smallest flux the references need, the
    /// landed band from the stroke, the creep from `creep_speed`.
    pub fn decide(
        model: &Model,
        linearization: Linearization,
        spec: &ControllerSpec,
        operations: Vec<DesignedOperation>,
    ) -> Result<ControllerDesign, PlanError> {
        let stroke = check(spec, &operations)?;
        let phi_min = smallest_reference_flux(model, &linearization, &operations)?;
        let creep = match spec.creep_speed {
            Some(speed) => speed / stroke,
            None => CREEP_FRACTION / (spec.landing - spec.takeoff),
        };
        let landed_band = spec
            .landed_band
            .unwrap_or_else(|| round_down_1sig(LANDED_FRACTION * stroke));
        let arrival_band = if spec.estimated {
            landed_band.max(ESTIMATED_ARRIVAL_FRACTION * stroke)
        } else {
            landed_band
        };
        Ok(ControllerDesign {
            linearization,
            law: spec.law,
            sample_period: spec.sample_period,
            u_min: spec.u_min,
            u_max: spec.u_max,
            takeoff: spec.takeoff,
            landing: spec.landing,
            phi_guard: round_down_1sig(GUARD_FRACTION * phi_min),
            landed_band,
            press: PRESS_FRACTION,
            creep,
            creep_max: CREEP_MAX_FRACTION,
            // no hover: driven to its stop when it is late by a whole motion
            // time (a slow but landing approach, e.g. sensorless creeping
            // onto the stop, is left to land)
            arrival_margin: spec.landing - spec.takeoff,
            arrival_band,
            operations,
        })
    }
}

/// The checks of [`ControllerDesign::decide`]; the stroke max |z₀ − z_f|.
fn check(spec: &ControllerSpec, operations: &[DesignedOperation]) -> Result<f64, PlanError> {
    if operations.is_empty() {
        return Err(PlanError::NoOperation);
    }
    let bad = |name: &str, value: f64| PlanError::BadValue {
        name: name.to_owned(),
        value,
    };
    let positive =
        |name: &str, v: f64| (v.is_finite() && v > 0.0).then_some(()).ok_or(bad(name, v));
    let finite = |name: &str, v: f64| v.is_finite().then_some(()).ok_or(bad(name, v));
    for (name, value) in spec.law.positive_values() {
        positive(&name, value)?;
    }
    positive("sample_period", spec.sample_period)?;
    positive("takeoff", spec.takeoff)?;
    positive("landing - takeoff", spec.landing - spec.takeoff)?;
    finite("u_min", spec.u_min)?;
    finite("u_max", spec.u_max)?;
    positive("u_max - u_min", spec.u_max - spec.u_min)?;
    if let Some(band) = spec.landed_band {
        positive("landed_band", band)?;
    }
    if let Some(speed) = spec.creep_speed {
        positive("creep_speed", speed)?;
    }
    let mut stroke: f64 = 0.0;
    for (k, op) in operations.iter().enumerate() {
        if operations[..k].iter().any(|o| o.operation == op.operation) {
            return Err(PlanError::DuplicateOperation(op.operation));
        }
        finite("z0", op.z0)?;
        finite("zf", op.zf)?;
        stroke = stroke.max((op.z0 - op.zf).abs());
        let s = &op.table;
        let first = s
            .segments
            .first()
            .ok_or(PlanError::EmptyTable(op.operation))?[0];
        let tol = 1e-9 * spec.landing;
        if (first - spec.takeoff).abs() > tol || (s.end - spec.landing).abs() > tol {
            return Err(PlanError::TableTiming {
                operation: op.operation,
                first,
                end: s.end,
                takeoff: spec.takeoff,
                landing: spec.landing,
            });
        }
        for &x in s.segments.iter().flatten() {
            finite("reference table entry", x)?;
        }
    }
    positive("stroke |z0 - zf|", stroke)?;
    Ok(stroke)
}

/// `x > 0` rounded down to one significant digit (so that a small change of
/// the design does not change the emitted threshold).
pub(super) fn round_down_1sig(x: f64) -> f64 {
    let e = x.log10().floor();
    let digit = (x / 10f64.powf(e)).floor().clamp(1.0, 9.0);
    format!("{digit}e{e}").parse().unwrap_or(x)
}

/// min over the reference (rest positions and samples of every segment) of
/// the flux T⁻¹ needs, √((ξ₃ − a₀)/c₂) [PT 42], over the samples where it is
/// positive and finite.
fn smallest_reference_flux(
    model: &Model,
    lin: &Linearization,
    operations: &[DesignedOperation],
) -> Result<f64, PlanError> {
    let mut flux_squared = FluxSquared::new(model, lin).map_err(PlanError::UnboundSymbol)?;
    let mut smallest = f64::INFINITY;
    let mut visit = |xi: [f64; 3]| {
        let phi2 = flux_squared.at(xi);
        if phi2.is_finite() && phi2 > 0.0 {
            smallest = smallest.min(phi2.sqrt());
        }
    };
    for op in operations {
        visit([op.z0, 0.0, 0.0]);
        visit([op.zf, 0.0, 0.0]);
        let segs = &op.table.segments;
        for (k, seg) in segs.iter().enumerate() {
            let next = segs.get(k + 1).map_or(op.table.end, |s| s[0]);
            let h = next - seg[0];
            for i in 0..=FLUX_SAMPLES {
                let tau = h * i as f64 / FLUX_SAMPLES as f64;
                let f = Segments::eval_segment(seg, tau);
                visit([f.z, f.v, f.a]);
            }
        }
    }
    if smallest.is_finite() {
        Ok(smallest)
    } else {
        Err(PlanError::NoFluxFloor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_significant_digit_rounds_down() {
        assert_eq!(round_down_1sig(3.7e-9), 3e-9);
        assert_eq!(round_down_1sig(1e-6), 1e-6);
        assert_eq!(round_down_1sig(9.99e-4), 9e-4);
    }

    #[test]
    fn gains_from_settling_time_and_poles() {
        // "a 1 ms 5 % settling time of the triple pole is λ ≈ 6296 s⁻¹"
        let [k1, k2, k3] = gains(&Gains::SettlingTime(1e-3));
        let lambda = k3 / 3.0;
        assert!((lambda - 6295.8).abs() < 0.05, "λ = {lambda}");
        assert!((k2 - 3.0 * lambda * lambda).abs() <= 1e-9 * k2);
        assert!((k1 - lambda.powi(3)).abs() <= 1e-9 * k1);
        // the step response of the triple pole is at 95 % at t_s
        let x: f64 = lambda * 1e-3;
        assert!(((-x).exp() * (1.0 + x + x * x / 2.0) - 0.05).abs() < 1e-12);
        // (s + 1)(s + 2)(s + 3) = s³ + 6s² + 11s + 6
        assert_eq!(gains(&Gains::Poles([-1.0, -2.0, -3.0])), [6.0, 11.0, 6.0]);
    }
}
