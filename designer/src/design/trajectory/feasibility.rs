//! Feasibility of a reference for perfect tracking
//! (perfect-tracking-soft-landing [PT §4]; model-free-sliding-mode [SM §3.1]).
//!
//! Along the motion, with ξ_r = [z_r, ż_r, z̈_r] and x_r = T⁻¹(ξ_r) [PT 55]:
//! - [PT 57] z_min ≤ z_r ≤ z_max;
//! - [PT 56] the state stays in the linearizable region: the flux the reference
//!   needs, φ_r² = −2(m·z̈_r + F(z_r, ż_r))/R_gap'(z_r), is positive — the
//!   magnetic force can only attract (sliding-mode paper [SM 13]) — and below
//!   φ_sat² for a saturating core (its [SM 14]);
//! - [PT 54] the input u_r = α(x_r) + β(x_r)·z_r⁽³⁾ stays within the bounds.
//!
//! On a Jiles–Atherton core α and β read the field H_c, which T⁻¹ does not
//! give: it follows the reference's flux path (`model::FieldPath`), from a
//! demagnetised core for an operation that starts at z_max and from the
//! anhysteretic field of the holding flux under u_max for one that starts at
//! z_min (what the closing left).
//!
//! The report says which condition fails, where, by how much, and what to try.

use crate::description::Core;
use crate::model::{FieldPath, Model, Statics};
use crate::sym::Tape;

use super::reference::Reference;
use crate::design::derive::linearization::Linearization;

/// One condition evaluated along the reference.
#[derive(Debug, Clone, PartialEq)]
pub struct Condition {
    /// Equation number and statement, e.g. "[PT 54] u_min ≤ α + β·z⁽³⁾ ≤ u_max".
    pub name: &'static str,
    /// First and last violating instants, if any.
    pub violated: Option<(f64, f64)>,
    /// The worst instant and the value there, with the bound it is held to.
    pub worst_t: f64,
    pub worst_value: f64,
    pub bound: f64,
}

/// All conditions, with the extremes of the required input and flux.
#[derive(Debug, Clone, PartialEq)]
pub struct Feasibility {
    pub conditions: Vec<Condition>,
    pub max_input: f64,
    pub min_input: f64,
    pub min_flux: f64,
    pub max_flux: f64,
}

impl Feasibility {
    pub fn is_feasible(&self) -> bool {
        self.conditions.iter().all(|c| c.violated.is_none())
    }

    /// A readable report: each condition, and a hint for the failing ones.
    pub fn report(&self) -> String {
        let mut s = String::new();
        for c in &self.conditions {
            match c.violated {
                None => s.push_str(&format!("  ok    {}\n", c.name)),
                Some((a, b)) => s.push_str(&format!(
                    "  FAIL  {}: violated on [{:.4}, {:.4}] ms, worst {:.4e} at {:.4} ms (bound {:.4e}); {}\n",
                    c.name,
                    a * 1e3,
                    b * 1e3,
                    c.worst_value,
                    c.worst_t * 1e3,
                    c.bound,
                    hint(c.name)
                )),
            }
        }
        s.push_str(&format!(
            "  required input in [{:.3}, {:.3}], flux in [{:.4e}, {:.4e}] Wb\n",
            self.min_input, self.max_input, self.min_flux, self.max_flux
        ));
        s
    }
}

/// H_c along a reference starting at rest at `z0` (see the module docs):
/// `None` for a core without the field state.
pub fn reference_field(model: &mut Model, z0: f64) -> Option<FieldPath> {
    model.has_field_state().then_some(())?;
    let mech = &model.description.mechanics;
    let from_closed = (z0 - mech.z_min).abs() < (z0 - mech.z_max).abs();
    let flux = if from_closed {
        Statics::of(model).hold_flux
    } else {
        0.0
    };
    FieldPath::anhysteretic(model, flux)
}

fn hint(name: &str) -> &'static str {
    if name.starts_with("(54)") {
        "try a longer motion (t_f − t₀) or an energy-optimal trajectory with a lower u_bound"
    } else if name.starts_with("(56)") {
        "the reference asks for a force the magnet cannot give: slow the motion down (longer t_f − t₀)"
    } else {
        "the reference leaves the stroke: check z₀, z_f"
    }
}

/// Tracks the worst value and the violation interval of one condition.
struct Tracker {
    condition: Condition,
    /// +1: the value must stay ≤ bound; −1: ≥ bound.
    sense: f64,
    /// Excess tolerated as round-off: an energy-optimal reference rides
    /// exactly on its input bound.
    slack: f64,
    worst_margin: f64,
}

impl Tracker {
    fn new(name: &'static str, bound: f64, sense: f64, slack: f64) -> Tracker {
        Tracker {
            condition: Condition {
                name,
                violated: None,
                worst_t: f64::NAN,
                worst_value: f64::NAN,
                bound,
            },
            sense,
            slack,
            worst_margin: f64::NEG_INFINITY,
        }
    }

    fn observe(&mut self, t: f64, value: f64) {
        let excess = self.sense * (value - self.condition.bound);
        let excess = if excess.is_nan() {
            f64::INFINITY
        } else {
            excess
        };
        if excess > self.worst_margin {
            self.worst_margin = excess;
            self.condition.worst_t = t;
            self.condition.worst_value = value;
        }
        if excess > self.slack {
            let (a, _) = self.condition.violated.unwrap_or((t, t));
            self.condition.violated = Some((a, t));
        }
    }
}

/// Evaluates [PT 54], [PT 56], [PT 57] on `samples` + 1 instants of the motion.
pub fn check(
    model: &mut Model,
    lin: &Linearization,
    reference: &dyn Reference,
    u_bounds: (f64, f64),
    samples: usize,
) -> Feasibility {
    let flux2 = model.bind_params(&[lin.flux_squared]);
    let flux_tape =
        Tape::compile(&model.graph, &lin.xi, &flux2).expect("φ² depends on ξ and parameters only");
    let law = model.compile(&[lin.alpha, lin.beta]);
    let mech = &model.description.mechanics;
    let phi_sat = match model.description.core {
        Core::Saturating { phi_sat, .. } => phi_sat,
        _ => f64::INFINITY,
    };
    let stroke_slack = 1e-9 * (mech.z_max - mech.z_min);
    let input_slack = 1e-6 * u_bounds.0.abs().max(u_bounds.1.abs()).max(1.0);
    let mut z_low = Tracker::new("(57) z_r ≥ z_min", mech.z_min, -1.0, stroke_slack);
    let mut z_high = Tracker::new("(57) z_r ≤ z_max", mech.z_max, 1.0, stroke_slack);
    let mut attract = Tracker::new(
        "(56) φ_r² > 0 (the magnetic force only attracts)",
        0.0,
        -1.0,
        0.0,
    );
    let mut saturation = Tracker::new("(56) φ_r² < φ_sat²", phi_sat * phi_sat, 1.0, 0.0);
    let mut u_high = Tracker::new("(54) α + β·z⁽³⁾ ≤ u_max", u_bounds.1, 1.0, input_slack);
    let mut u_low = Tracker::new("(54) α + β·z⁽³⁾ ≥ u_min", u_bounds.0, -1.0, input_slack);
    let (t0, tf) = reference.motion();
    let (mut flux_range, mut input_range) = (
        (f64::INFINITY, f64::NEG_INFINITY),
        (f64::INFINITY, f64::NEG_INFINITY),
    );
    let (mut fs, mut ls) = (flux_tape.scratch(), law.scratch());
    let mut field = reference_field(model, reference.at(t0).z);
    let mut law_in = vec![0.0; model.dim() + 2];
    for k in 0..=samples {
        let t = t0 + (tf - t0) * k as f64 / samples as f64;
        let r = reference.at(t);
        z_low.observe(t, r.z);
        z_high.observe(t, r.z);
        let mut phi2 = [0.0];
        flux_tape.eval(&[r.z, r.v, r.a], &mut fs, &mut phi2);
        attract.observe(t, phi2[0]);
        saturation.observe(t, phi2[0]);
        if phi2[0] > 0.0 {
            let phi = phi2[0].sqrt();
            flux_range = (flux_range.0.min(phi), flux_range.1.max(phi));
            let mut ab = [0.0; 2];
            law_in[..3].copy_from_slice(&[r.z, r.v, phi]);
            if let Some(path) = &mut field {
                law_in[3] = path.advance(phi);
            }
            if let Some(time) = law_in.last_mut() {
                *time = t;
            }
            law.eval(&law_in, &mut ls, &mut ab);
            let u = ab[0] + ab[1] * r.jerk;
            input_range = (input_range.0.min(u), input_range.1.max(u));
            u_high.observe(t, u);
            u_low.observe(t, u);
        }
    }
    Feasibility {
        conditions: [z_low, z_high, attract, saturation, u_high, u_low]
            .into_iter()
            .map(|t| t.condition)
            .collect(),
        max_input: input_range.1,
        min_input: input_range.0,
        min_flux: flux_range.0,
        max_flux: flux_range.1,
    }
}
