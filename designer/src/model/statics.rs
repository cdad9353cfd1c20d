//! Static operating points for `reldesign check`: the pull-in point (the
//! smallest steady input that lifts the armature off z_max) and the drop-out
//! point (the largest steady input at which it leaves z_min).
//!
//! At rest φ̇ = 0, so the eddy current vanishes and N·i = R_gap(z)·φ + MMF_core(φ)
//! (perfect-tracking-soft-landing [PT 4]). Lift-off at z_max happens when
//! ½·R_gap'(z_max)·φ² > −F(z_max, 0); release at z_min when
//! ½·R_gap'(z_min)·φ² < −F(z_min, 0) (jiles-atherton-actuator-model [JA 49–50]).
//! The Jiles–Atherton core is evaluated on its anhysteretic curve.

use crate::bisect::bisect;
use crate::description::{Core, Description, Drive};
use crate::sim::State;
use crate::sym::Tape;

use super::gap::MU0;
use super::Model;

/// A static switching point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SwitchingPoint {
    pub flux: f64,
    pub current: f64,
    /// Steady coil voltage R·i.
    pub voltage: f64,
}

/// Static summary of an actuator.
#[derive(Debug, Clone, PartialEq)]
pub struct Statics {
    /// Passive force F(z, 0) at z_max and at z_min [N].
    pub passive_at_max: f64,
    pub passive_at_min: f64,
    pub pull_in: Result<SwitchingPoint, String>,
    pub drop_out: Result<SwitchingPoint, String>,
    /// Steady flux and magnetic force at z_min with the largest input.
    pub hold_flux: f64,
    pub hold_force: f64,
}

impl Statics {
    pub fn of(model: &mut Model) -> Statics {
        let gap = GapCurve::new(model);
        let d = &model.description;
        let (z_min, z_max) = (d.mechanics.z_min, d.mechanics.z_max);
        let m = &d.mechanics;
        let (passive_at_max, passive_at_min) = (m.passive_at_rest(z_max), m.passive_at_rest(z_min));
        let core = CoreCurve(&d.core);
        let point = |z: f64, flux: f64| steady_point(&gap, d, z, flux);
        let pull_in = if passive_at_max > 0.0 {
            Err(format!("at zero flux the passive force ({passive_at_max:.4} N) already pushes the armature away from z_max"))
        } else if passive_at_max == 0.0 {
            // No spring holds it at z_max: any flux pulls it in.
            Ok(point(z_max, 0.0))
        } else {
            let flux = (-2.0 * passive_at_max / gap.slope(z_max)).sqrt();
            match core.flux_limit() {
                Some(limit) if flux >= limit => {
                    Err(format!("needs a flux of {flux:.4e} Wb, beyond the core's saturation flux {limit:.4e} Wb"))
                }
                _ => Ok(point(z_max, flux)),
            }
        };
        let drop_out = if passive_at_min >= 0.0 {
            Err(format!(
                "the passive force at z_min ({passive_at_min:+.4} N) never pushes the armature off"
            ))
        } else {
            Ok(point(
                z_min,
                (-2.0 * passive_at_min / gap.slope(z_min)).sqrt(),
            ))
        };
        let ampere_turns = d.coil.turns
            * match d.supply.drive {
                Drive::Voltage => {
                    d.supply.u_max.abs().max(d.supply.u_min.abs()) / d.coil.resistance
                }
                Drive::Current => d.supply.u_max.abs().max(d.supply.u_min.abs()),
            };
        let hold_flux = steady_flux(
            |f| gap.value(z_min) * f + core.mmf(f),
            ampere_turns,
            core.flux_limit(),
        );
        let hold_force = -0.5 * gap.slope(z_min) * hold_flux * hold_flux;
        Statics {
            passive_at_max,
            passive_at_min,
            pull_in,
            drop_out,
            hold_flux,
            hold_force,
        }
    }
}

/// The steady point at rest at `z` with `flux` (φ̇ = 0: N·i = R_gap·φ +
/// MMF_core(φ), the Jiles–Atherton core on its anhysteretic curve).
pub fn rest_point(model: &mut Model, z: f64, flux: f64) -> SwitchingPoint {
    let gap = GapCurve::new(model);
    steady_point(&gap, &model.description, z, flux)
}

/// [PT 4] N·i = R_gap(z)·φ + MMF_core(φ) at rest, and its voltage R·i.
fn steady_point(gap: &GapCurve, d: &Description, z: f64, flux: f64) -> SwitchingPoint {
    let current = (gap.value(z) * flux + CoreCurve(&d.core).mmf(flux)) / d.coil.turns;
    SwitchingPoint {
        flux,
        current,
        voltage: d.coil.resistance * current,
    }
}

/// R_gap and R_gap' as numeric functions (compiled from the model).
struct GapCurve {
    tape: Tape,
    dim: usize,
}

impl GapCurve {
    fn new(model: &mut Model) -> GapCurve {
        GapCurve {
            tape: model.compile(&[model.r_gap, model.r_gap_dz]),
            dim: model.dim(),
        }
    }

    fn eval(&self, z: f64) -> [f64; 2] {
        let mut inputs: State = [0.0; 4];
        inputs[0] = z;
        let mut all = inputs.to_vec();
        all.truncate(self.dim);
        all.extend([0.0, 0.0]);
        let mut out = [0.0; 2];
        self.tape.eval(&all, &mut self.tape.scratch(), &mut out);
        out
    }

    fn value(&self, z: f64) -> f64 {
        self.eval(z)[0]
    }

    fn slope(&self, z: f64) -> f64 {
        self.eval(z)[1]
    }
}

/// The static magnetisation curve MMF_core(φ).
struct CoreCurve<'a>(&'a Core);

impl CoreCurve<'_> {
    fn mmf(&self, flux: f64) -> f64 {
        match self.0 {
            Core::Linear { r0 } => r0 * flux,
            Core::Saturating { r0, phi_sat } => r0 * flux / (1.0 - flux.abs() / phi_sat),
            Core::JilesAtherton(ja) => anhysteretic_field(ja, flux / ja.area) * ja.length,
        }
    }

    fn flux_limit(&self) -> Option<f64> {
        match self.0 {
            Core::Saturating { phi_sat, .. } => Some(*phi_sat),
            _ => None,
        }
    }
}

/// H on the anhysteretic curve for flux density B: solves
/// M = M_sat·L((B − μ0(1 − α)M)/b) by bisection (the right side decreases in M).
#[allow(clippy::neg_cmp_op_on_partial_ord)] // deliberate: a NaN residual keeps the upper half
pub fn anhysteretic_field(ja: &crate::description::JilesAtherton, b_c: f64) -> f64 {
    let langevin = |x: f64| {
        if x.abs() < 1e-4 {
            x / 3.0
        } else {
            1.0 / x.tanh() - 1.0 / x
        }
    };
    let residual = |m: f64| m - ja.m_sat * langevin((b_c - MU0 * (1.0 - ja.alpha) * m) / ja.b);
    b_c / MU0 - bisect(-ja.m_sat, ja.m_sat, |m| !(residual(m) > 0.0))
}

/// The flux φ ≥ 0 with mmf(φ) = ampere_turns (mmf increasing), by bisection.
fn steady_flux(mmf: impl Fn(f64) -> f64, ampere_turns: f64, limit: Option<f64>) -> f64 {
    let mut hi = limit.map_or(1e-6, |l| l * (1.0 - 1e-12));
    if limit.is_none() {
        while mmf(hi) < ampere_turns && hi < 1.0 {
            hi *= 2.0;
        }
    }
    bisect(0.0, hi, |phi| mmf(phi) < ampere_turns)
}
