//! The backstepping position controller (`[controller] law = "backstepping"`,
//! switched-force-backstepping [SB]) as plain data: the derived law, its
//! gains, the reference, the certified region and the switching strategy.
//! Code generation renders a [`BacksteppingDesign`]; the runtime's
//! `backstepping` module applies it.
//!
//! - every target y_r must be holdable (an attracting flux balances the
//!   spring there within the supply, as for the hold of `law/hold.rs`);
//! - the spring's rest X₀, the state u = 0 converges to: the zero of the
//!   passive force F_p(z, 0) within the stroke, or the stop it pushes
//!   against (z_max for the bundled valves, whose preload holds them open);
//! - the region (`region.rs`) on A = [[−α₁, 1], [−1, −α₂]] [SB 14] and
//!   F_d = g − kᵀZ, whose g and k are read off the derived F_d (affine,
//!   checked by `derivation.rs`); the switching strategies need X₀ ∈ D.

use crate::description::{BacksteppingKeys, Description, Mechanics, SetPoint, Switching};
use crate::model::Model;
use crate::sym::Id;

use super::derivation::Backstepping;
use super::region::{decay_limit, design_region, Region, Target};
use crate::design::derive::linearization::{FluxSquared, Linearization};
use crate::design::error::PlanError;
use crate::design::law::decisions::round_down_1sig;
use crate::design::law::hold::holding;

/// The default decay: this fraction of the largest a quadratic V certifies.
const DEFAULT_DECAY_FRACTION: f64 = 0.2;
/// Fraction of the smallest holding flux below which the law is not
/// evaluated (g_F ∝ φ vanishes at φ = 0).
const GUARD_FRACTION: f64 = 1e-3;

/// The designed backstepping controller: everything the emitted module states.
#[derive(Debug, Clone)]
pub struct BacksteppingDesign {
    pub linearization: Linearization,
    pub law: Backstepping,
    /// α₁, α₂, α₃ [1/s].
    pub gains: [f64; 3],
    pub switching: Switching,
    pub reference: SetPoint,
    pub region: Region,
    /// T_s [s].
    pub sample_period: f64,
    /// The supply: u ∈ [u_min, u_max].
    pub u_min: f64,
    pub u_max: f64,
    pub z_min: f64,
    pub z_max: f64,
    /// [Wb]: where φ ≤ `phi_guard` the law is not evaluated and u = u_max.
    pub phi_guard: f64,
    /// z of the spring's rest X₀ [m].
    pub rest: f64,
    /// Per target: the flux and steady input that hold it.
    pub holding: Vec<(f64, f64)>,
}

impl BacksteppingDesign {
    /// The law's design symbols and their values: α₁, α₂, α₃ (`gain_a…`)
    /// and p₁₂, p₂₂ of P (`region_p…`), for the tapes and the emitted consts.
    pub fn bound_symbols(&self) -> [(&'static str, Id, f64); 5] {
        let law = &self.law;
        let [a1, a2, a3] = self.gains;
        let [_, p12, p22] = self.region.p;
        [
            ("gain_a1", law.gains[0], a1),
            ("gain_a2", law.gains[1], a2),
            ("gain_a3", law.gains[2], a3),
            ("region_p12", law.coupling[0], p12),
            ("region_p22", law.coupling[1], p22),
        ]
    }
}

/// Designs the controller of `[controller]` with law "backstepping".
pub fn design_backstepping(
    description: &Description,
    model: &mut Model,
    keys: &BacksteppingKeys,
) -> Result<BacksteppingDesign, PlanError> {
    let Some(controller) = &description.controller else {
        return Err(PlanError::NothingToBuild);
    };
    let linearization = Linearization::derive(model)?;
    let law = Backstepping::derive(model, &linearization)?;
    let mech = &description.mechanics;
    let positions = keys.reference.positions();
    let mut rest_flux_squared =
        FluxSquared::new(model, &linearization).map_err(PlanError::UnboundSymbol)?;
    let holding = positions
        .iter()
        .map(|&z| holding(description, model, &mut rest_flux_squared, z, false))
        .collect::<Result<Vec<_>, _>>()?;
    let [a1, a2, _] = keys.gains;
    let rest = spring_rest(mech);
    let (gradient, targets) = force_half_planes(model, &law, keys.gains, &positions, rest);
    let a = [[-a1, 1.0], [-1.0, -a2]];
    let decay = keys
        .decay
        .unwrap_or_else(|| DEFAULT_DECAY_FRACTION * decay_limit(a));
    let need_rest = keys.switching != Switching::None;
    let region = design_region(a, decay, gradient, targets, need_rest)?;
    let smallest_flux = holding.iter().map(|h| h.0).fold(f64::INFINITY, f64::min);
    if !(smallest_flux > 0.0 && smallest_flux.is_finite()) {
        return Err(PlanError::NoFluxFloor);
    }
    Ok(BacksteppingDesign {
        linearization,
        law,
        gains: keys.gains,
        switching: keys.switching,
        reference: keys.reference,
        region,
        sample_period: controller.sample_period,
        u_min: description.supply.u_min,
        u_max: description.supply.u_max,
        z_min: mech.z_min,
        z_max: mech.z_max,
        phi_guard: round_down_1sig(GUARD_FRACTION * smallest_flux),
        rest,
        holding,
    })
}

/// The value of `e` at the model's parameters, the states z, v and the law's
/// symbols given.
fn evaluate(model: &Model, e: Id, values: &[(Id, f64)]) -> f64 {
    let g = &model.graph;
    let named: Vec<(&str, f64)> = values
        .iter()
        .filter_map(|&(id, x)| g.name_of(id).map(|n| (n, x)))
        .collect();
    g.eval(e, &|name| {
        named
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, x)| x)
            .or_else(|| model.params.value(name))
            .unwrap_or(f64::NAN)
    })
}

/// z of X₀: where F_p(z, 0) = 0 within [z_min, z_max], else the stop the
/// passive force pushes the armature against (v̇ = −F_p/m with no flux).
fn spring_rest(m: &Mechanics) -> f64 {
    let (z_min, z_max) = (m.z_min, m.z_max);
    let (at_min, at_max) = (m.passive_at_rest(z_min), m.passive_at_rest(z_max));
    if at_max < 0.0 {
        z_max
    } else if at_min > 0.0 {
        z_min
    } else if at_min == at_max {
        z_max
    } else {
        // F_p is affine in z: its zero
        z_min + at_min * (z_max - z_min) / (at_min - at_max)
    }
}

/// k of F_d = g − kᵀZ, and per target its g and X₀'s errors Z₀.
fn force_half_planes(
    model: &Model,
    law: &Backstepping,
    gains: [f64; 3],
    positions: &[f64],
    rest: f64,
) -> ([f64; 2], Vec<Target>) {
    let (z, v) = (model.states[0], model.states[1]);
    let [a1, a2, _] = gains;
    let at = |y_r: f64, z1: f64, z2: f64| {
        let values = [
            (z, y_r + z1),
            (v, z2 - a1 * z1),
            (law.target, y_r),
            (law.gains[0], a1),
            (law.gains[1], a2),
        ];
        evaluate(model, law.desired_force, &values)
    };
    let y0 = positions.first().copied().unwrap_or(0.0);
    let g0 = at(y0, 0.0, 0.0);
    // F_d is affine in Z: unit steps give −k exactly (up to rounding)
    let gradient = [g0 - at(y0, 1e-3, 0.0), g0 - at(y0, 0.0, 1e-3)].map(|d| d / 1e-3);
    let targets = positions
        .iter()
        .map(|&y_r| Target {
            position: y_r,
            holding_force: at(y_r, 0.0, 0.0),
            rest: [rest - y_r, a1 * (rest - y_r)],
        })
        .collect();
    (gradient, targets)
}
