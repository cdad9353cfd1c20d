//! The robustness of the model-free sliding-mode law along a reference
//! (model-free-sliding-mode-soft-landing [SM §4.1]).
//!
//! The law u = u_max·sgn(φ)·sgn*(s) [SM 34] uses no model, but whether its
//! u_max is large enough does. Along the reference, at the state
//! x_r = T⁻¹(z_r, v_r, a_r) that tracks it exactly:
//! - [SM 13] F*_mag = m·a_r − F_pas(z_r, v_r) ≤ 0 (the magnet only attracts) and
//!   [SM 14] F*_mag ≥ −½·R_g′(z_r)·φ_sat² (saturation): the reference is feasible;
//! - [SM 26] B_j = −L_g L_f²h, [SM 25] f_j = L_f³h, both from the model's own
//!   derivation (`derive/linearization.rs`), so every gap, core and coil is covered;
//! - [SM 48] u* = |f_j − j_r| / |B_j|, the input of ideal tracking;
//! - [SM 49]–[SM 50] required u_max = max u* + (max|ε| + η)/min|B_j|, with
//!   ε = (λ₁ + λ₂)·ã + λ₁λ₂·ṽ [SM 24] bounded by the error bounds [SM 52]
//!   (by default 20 % of max|v_r| and of max|a_r|).
//!
//! The whole operation is sampled, the rests before t₀ and after t_f
//! included: holding the takeoff flux needs an input too. On a
//! Jiles–Atherton core f_j and B_j read H_c, taken along the reference's flux
//! path (`model::FieldPath`, the nominal core's even in a Monte-Carlo draw).

use crate::description::{schema, SlidingSurface};
use crate::model::{FieldPath, Model};
use crate::sym::Tape;

use crate::design::derive::linearization::Linearization;
use crate::design::trajectory::feasibility::reference_field;
use crate::design::trajectory::reference::Reference;

/// The end of an operation [s from its start]: the rest after landing lasts
/// as long as the one before takeoff [SM 45], t_f − t_land = t_takeoff − t₀.
pub fn operation_end(takeoff: f64, landing: f64) -> f64 {
    landing + takeoff
}

/// [SM 52]: |ṽ| ≤ velocity·max|v_r|, |ã| ≤ acceleration·max|a_r|.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorBounds {
    pub velocity: f64,
    pub acceleration: f64,
}

impl Default for ErrorBounds {
    /// The paper's conservative 20 % [SM 52].
    fn default() -> Self {
        ErrorBounds {
            velocity: 0.2,
            acceleration: 0.2,
        }
    }
}

/// One instant of the analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Time from the operation's start [s].
    pub t: f64,
    pub z: f64,
    pub v: f64,
    pub a: f64,
    pub jerk: f64,
    /// [SM 13] F*_mag [N] (≤ 0 where feasible).
    pub force: f64,
    /// [SM 14] −½·R_g′(z_r)·φ_sat² [N] (−∞ without saturation).
    pub force_bound: f64,
    /// The input of ideal tracking, signed: u_r = (f_j − j_r)/B_j = α + β·j_r
    /// [PT 32]; NaN where the reference is infeasible.
    pub u_ref: f64,
    /// [SM 48] u* = |u_r| [V or A]; +∞ where the reference is infeasible.
    pub u_star: f64,
    /// [SM 26] |B_j| [1/(s³·V)·m]; 0 where the reference is infeasible.
    pub b_j: f64,
}

/// The analysis of one operation.
#[derive(Debug, Clone, PartialEq)]
pub struct Robustness {
    /// [SM 13]–[SM 14] hold at every sample.
    pub feasible: bool,
    /// The first and last infeasible instants [s], where there are any.
    pub infeasible: Option<(f64, f64)>,
    /// max u* [SM 48] and where it lies [s].
    pub max_u_star: f64,
    pub max_u_star_t: f64,
    /// min |B_j| and where it lies [s].
    pub min_b_j: f64,
    pub min_b_j_t: f64,
    /// [SM 50] the bound of |ε|.
    pub max_epsilon: f64,
    /// [SM 49] the sufficient u_max: max u* + (max|ε| + η)/min|B_j|, the
    /// paper's form for a supply ±u_max.
    pub required_u_max: f64,
    /// The same condition [SM 27] on the negative side, for a supply whose
    /// u_min is not −u_max: the law's negative switch is u_min (saturated), so
    /// it must reach min u_r − (max|ε| + η)/min|B_j| (≤ 0 where the reference
    /// ever needs a negative input or margin).
    pub required_u_min: f64,
    pub samples: Vec<Sample>,
}

impl Robustness {
    /// Whether the supply [u_min, u_max] meets [SM 49] on both sides.
    pub fn met(&self, u_min: f64, u_max: f64) -> bool {
        self.feasible && u_max >= self.required_u_max && u_min <= self.required_u_min
    }
}

/// The model functions the analysis evaluates, compiled once per model with
/// the parameters as inputs, so that a Monte-Carlo draw only changes numbers.
pub struct Evaluator {
    /// (states, u, t, parameters) → [α, β, a(x)].
    law: Tape,
    /// (ξ, parameters) → φ² of T⁻¹.
    flux: Tape,
    /// The parameters' names, in the tapes' order.
    names: Vec<String>,
    /// Where m and φ_sat are among the parameters.
    mass: Option<usize>,
    phi_sat: Option<usize>,
    /// H_c along the reference on a Jiles–Atherton core, from rest at z_max
    /// and at z_min (`feasibility::reference_field`; the nominal core).
    field_from: Option<[FieldPath; 2]>,
    /// z_min, z_max: which start a reference has.
    stroke: [f64; 2],
}

impl Evaluator {
    pub fn new(model: &Model, lin: &Linearization) -> Evaluator {
        let mech = &model.description.mechanics;
        let stroke = [mech.z_min, mech.z_max];
        let mut nominal = model.clone();
        let field_from = reference_field(&mut nominal, stroke[1])
            .zip(reference_field(&mut nominal, stroke[0]))
            .map(|(open, closed)| [open, closed]);
        let params: Vec<_> = model.params.iter().map(|(_, id, _)| id).collect();
        let names: Vec<String> = model.params.iter().map(|(n, _, _)| n.to_owned()).collect();
        let with_params = |mut inputs: Vec<_>| {
            inputs.extend(&params);
            inputs
        };
        let compile = |inputs: Vec<_>, outputs: &[_]| {
            Tape::compile(&model.graph, &with_params(inputs), outputs)
                .expect("the linearization uses states, u, t and parameters only")
        };
        let law = compile(
            model.tape_inputs(),
            &[lin.alpha, lin.beta, lin.transform[2]],
        );
        let flux = compile(lin.xi.to_vec(), &[lin.flux_squared]);
        let index_of = |path: &str| {
            let symbol = schema::key(path).symbol;
            names.iter().position(|n| Some(n.as_str()) == symbol)
        };
        Evaluator {
            law,
            flux,
            mass: index_of("mechanics.mass"),
            phi_sat: index_of("core.phi_sat"),
            names,
            field_from,
            stroke,
        }
    }

    /// The parameters' names, in the order [`Evaluator::analyse`] takes their values.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The values of `model`'s parameters in this evaluator's order, or the
    /// first name `model` lacks (a model of other variants).
    pub fn values(&self, model: &Model) -> Result<Vec<f64>, String> {
        self.names
            .iter()
            .map(|n| model.params.value(n).ok_or_else(|| n.clone()))
            .collect()
    }

    /// The sample at `t` of the reference `r` with the parameter values `p`.
    fn sample(&self, t: f64, r: &dyn Reference, p: &[f64], work: &mut Work) -> Sample {
        let f = r.at(t);
        work.flux_in.clear();
        work.flux_in.extend([f.z, f.v, f.a]);
        work.flux_in.extend(p);
        let mut phi2 = [0.0];
        self.flux
            .eval(&work.flux_in, &mut work.flux_scratch, &mut phi2);
        work.law_in.clear();
        work.law_in.extend([f.z, f.v, 0.0]);
        if work.field.is_some() {
            work.law_in.push(0.0);
        }
        work.law_in.extend([0.0, t]);
        work.law_in.extend(p);
        // H_c on the flux path (a = L_f²z reads none: only α, β change)
        let field = match (&mut work.field, phi2[0] > 0.0) {
            (Some(path), true) => path.advance(phi2[0].sqrt()),
            (Some(path), false) => path.field(),
            (None, _) => 0.0,
        };
        if let Some(hc) = work
            .field
            .is_some()
            .then(|| work.law_in.get_mut(3))
            .flatten()
        {
            *hc = field;
        }
        let mut at_flux = |phi: f64| {
            work.law_in[2] = phi;
            let mut out = [0.0; 3];
            self.law.eval(&work.law_in, &mut work.law_scratch, &mut out);
            out
        };
        let mass = self
            .mass
            .and_then(|k| p.get(k))
            .copied()
            .unwrap_or(f64::NAN);
        // a(x) = a₀(z, v) + c₂(z)·φ² [PT 42]: F_mag = m·(a − a₀) [SM 13]
        let a0 = at_flux(0.0)[2];
        let force = mass * (f.a - a0);
        // [SM 14]
        let force_bound = match self.phi_sat.and_then(|k| p.get(k)) {
            Some(&phi_sat) => mass * (at_flux(phi_sat)[2] - a0),
            None => f64::NEG_INFINITY,
        };
        let feasible = phi2[0] > 0.0 && force <= 0.0 && force >= force_bound;
        let (u_ref, b_j) = if feasible {
            let [alpha, beta, _] = at_flux(phi2[0].sqrt());
            // u_r = α + β·j_r = (f_j − j_r)/B_j [PT 32], [SM 48]
            (alpha + beta * f.jerk, (1.0 / beta).abs())
        } else {
            (f64::NAN, 0.0)
        };
        let u_star = if feasible { u_ref.abs() } else { f64::INFINITY };
        Sample {
            t,
            z: f.z,
            v: f.v,
            a: f.a,
            jerk: f.jerk,
            force,
            force_bound,
            u_ref,
            u_star,
            b_j,
        }
    }

    /// The analysis of the reference `r` over [0, t_end], `samples` + 1
    /// instants, for the surface's λ₁, λ₂, η and the parameter values
    /// `params` (in the order of [`Evaluator::names`]).
    #[allow(clippy::too_many_arguments)]
    pub fn analyse(
        &self,
        r: &dyn Reference,
        t_end: f64,
        samples: usize,
        surface: &SlidingSurface,
        bounds: &ErrorBounds,
        params: &[f64],
    ) -> Robustness {
        let times = sample_times(r, t_end, samples);
        let [z_min, z_max] = self.stroke;
        let from_closed = {
            let z0 = r.at(0.0).z;
            (z0 - z_min).abs() < (z0 - z_max).abs()
        };
        let mut work = Work {
            law_in: Vec::new(),
            flux_in: Vec::new(),
            law_scratch: self.law.scratch(),
            flux_scratch: self.flux.scratch(),
            field: (self.field_from.as_ref()).map(|[open, closed]| {
                if from_closed {
                    closed.clone()
                } else {
                    open.clone()
                }
            }),
        };
        let samples: Vec<Sample> = times
            .iter()
            .map(|&t| self.sample(t, r, params, &mut work))
            .collect();
        summarise(samples, surface, bounds)
    }
}

/// The buffers of one analysis.
struct Work {
    law_in: Vec<f64>,
    flux_in: Vec<f64>,
    law_scratch: Vec<f64>,
    flux_scratch: Vec<f64>,
    /// H_c along the reference (Jiles–Atherton core).
    field: Option<FieldPath>,
}

/// `samples` + 1 instants evenly over [0, t_end], plus the motion's ends (the
/// reference's kinks).
fn sample_times(r: &dyn Reference, t_end: f64, samples: usize) -> Vec<f64> {
    let n = samples.max(1);
    let (t0, tf) = r.motion();
    let mut times: Vec<f64> = (0..=n).map(|k| t_end * k as f64 / n as f64).collect();
    times.extend([t0, tf].into_iter().filter(|t| (0.0..=t_end).contains(t)));
    times.sort_by(f64::total_cmp);
    times.dedup();
    times
}

/// [SM 49]–[SM 50], [SM 52] over the samples.
fn summarise(samples: Vec<Sample>, surface: &SlidingSurface, bounds: &ErrorBounds) -> Robustness {
    let max_abs =
        |f: fn(&Sample) -> f64| samples.iter().map(f).fold(0.0, |m: f64, x| m.max(x.abs()));
    let (v_max, a_max) = (max_abs(|s| s.v), max_abs(|s| s.a));
    let SlidingSurface {
        lambda1,
        lambda2,
        eta,
        ..
    } = *surface;
    // [SM 24] with [SM 52], by the triangle inequality [SM 50]
    let max_epsilon = (lambda1 + lambda2) * bounds.acceleration * a_max
        + lambda1 * lambda2 * bounds.velocity * v_max;
    let infeasible: Vec<f64> = samples
        .iter()
        .filter(|s| !s.u_star.is_finite())
        .map(|s| s.t)
        .collect();
    let worst_u = samples
        .iter()
        .max_by(|a, b| a.u_star.total_cmp(&b.u_star))
        .copied();
    let weakest = samples
        .iter()
        .min_by(|a, b| a.b_j.total_cmp(&b.b_j))
        .copied();
    let (max_u_star, max_u_star_t) = worst_u.map_or((f64::NAN, f64::NAN), |s| (s.u_star, s.t));
    let (min_b_j, min_b_j_t) = weakest.map_or((f64::NAN, f64::NAN), |s| (s.b_j, s.t));
    // [SM 49], and its negative side
    let margin = (max_epsilon + eta) / min_b_j;
    let required_u_max = max_u_star + margin;
    let min_u_ref = samples
        .iter()
        .map(|s| s.u_ref)
        .fold(f64::INFINITY, f64::min);
    let required_u_min = min_u_ref - margin;
    Robustness {
        feasible: infeasible.is_empty(),
        infeasible: infeasible
            .first()
            .zip(infeasible.last())
            .map(|(a, b)| (*a, *b)),
        max_u_star,
        max_u_star_t,
        min_b_j,
        min_b_j_t,
        max_epsilon,
        required_u_max,
        required_u_min,
        samples,
    }
}
