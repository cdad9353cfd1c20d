//! A position hold by the model-based sliding mode of
//! jiles-atherton-actuator-model [JA §6.2] (`[controller] law =
//! "model-sliding-mode"` with `position`), as plain data: the law's p and K,
//! the position, the limits and the guard. Code generation renders a
//! [`HoldDesign`]; the runtime's `hold` module applies it.
//!
//! The position must be holdable: at rest there the flux must balance the
//! spring with an attracting force (φ² > 0 on T⁻¹ [PT 42]), and the steady
//! input R·i of that flux (the Jiles–Atherton core on its anhysteretic curve)
//! must lie within the supply [JA 94].

use crate::description::{Description, Drive, ModelSurface};
use crate::model::{rest_point, Model};

use super::decisions::{model_sliding_gains, round_down_1sig};
use crate::design::derive::linearization::{FluxSquared, Linearization};
use crate::design::error::PlanError;

/// Fraction of the holding flux below which the law is not evaluated.
const GUARD_FRACTION: f64 = 1e-3;
/// Fraction of the stroke within which the armature is at a stop [JA 86].
const LANDED_FRACTION: f64 = 1e-9;

/// The designed position hold: everything the emitted module states.
#[derive(Debug, Clone)]
pub struct HoldDesign {
    pub linearization: Linearization,
    /// p [1/s] of [JA 88], K [1/s] of [JA 93].
    pub p: f64,
    pub k: f64,
    /// z_ref [m].
    pub position: f64,
    /// T_s [s].
    pub sample_period: f64,
    /// u ∈ [0, u_max] [JA 94].
    pub u_max: f64,
    pub z_min: f64,
    pub z_max: f64,
    /// [Wb]: where φ̂ ≤ `phi_guard` the law is not evaluated and u = u_max.
    pub phi_guard: f64,
    /// [m]: within this distance of a stop the armature is at it [JA 86].
    pub landed_band: f64,
    /// The flux and the steady input that hold the armature at rest at the
    /// position (0 at a stop the spring holds).
    pub holding_flux: f64,
    pub holding_input: f64,
}

impl HoldDesign {
    /// K of the tracking law [PT 50] that is [JA 89].
    pub fn gains(&self) -> [f64; 3] {
        model_sliding_gains(self.p, self.k)
    }
}

/// The flux and the steady input (R·i [V], or i [A] with current drive)
/// that hold the armature at rest at `position`; 0 at a stop the spring
/// holds. Errors: no attracting flux balances the spring there, or the input
/// exceeds the supply.
pub(super) fn holding(
    description: &Description,
    model: &mut Model,
    rest_flux_squared: &mut FluxSquared,
    position: f64,
    at_stop: bool,
) -> Result<(f64, f64), PlanError> {
    // [PT 42] φ² at rest: ξ = [z, 0, 0]
    let flux_squared = rest_flux_squared.at([position, 0.0, 0.0]);
    let holding_flux = if flux_squared > 0.0 && flux_squared.is_finite() {
        flux_squared.sqrt()
    } else if at_stop {
        0.0
    } else {
        return Err(PlanError::Unholdable {
            position,
            flux_squared,
        });
    };
    let rest = rest_point(model, position, holding_flux);
    let holding_input = match description.supply.drive {
        Drive::Voltage => rest.voltage,
        Drive::Current => rest.current,
    };
    let u_max = description.supply.u_max;
    if !at_stop && !(holding_input < u_max) {
        return Err(PlanError::HoldingInput {
            position,
            input: holding_input,
            u_max,
        });
    }
    Ok((holding_flux, holding_input))
}

/// Designs the hold of `[controller]` (law "model-sliding-mode" with
/// `position`).
pub fn design_hold(
    description: &Description,
    model: &mut Model,
    surface: &ModelSurface,
    position: f64,
) -> Result<HoldDesign, PlanError> {
    let Some(controller) = &description.controller else {
        return Err(PlanError::NothingToBuild);
    };
    let linearization = Linearization::derive(model)?;
    let mech = &description.mechanics;
    let stroke = mech.z_max - mech.z_min;
    let band = controller
        .landed_band
        .unwrap_or_else(|| round_down_1sig(LANDED_FRACTION * stroke));
    let at_stop = position <= mech.z_min + band || position >= mech.z_max - band;
    let mut rest_flux_squared =
        FluxSquared::new(model, &linearization).map_err(PlanError::UnboundSymbol)?;
    let (holding_flux, holding_input) = holding(
        description,
        model,
        &mut rest_flux_squared,
        position,
        at_stop,
    )?;
    let u_max = description.supply.u_max;
    // the guard: 10⁻³ of the holding flux (of mid-stroke's at a stop)
    let guard_base = if holding_flux > 0.0 {
        holding_flux
    } else {
        (rest_flux_squared.at([mech.z_min + 0.5 * stroke, 0.0, 0.0]))
            .max(0.0)
            .sqrt()
    };
    if !(guard_base > 0.0 && guard_base.is_finite()) {
        return Err(PlanError::NoFluxFloor);
    }
    let design = HoldDesign {
        linearization,
        p: surface.p,
        k: surface.k,
        position,
        sample_period: controller.sample_period,
        u_max,
        z_min: mech.z_min,
        z_max: mech.z_max,
        phi_guard: round_down_1sig(GUARD_FRACTION * guard_base),
        landed_band: band,
        holding_flux,
        holding_input,
    };
    for (name, value) in [
        ("p", design.p),
        ("k", design.k),
        ("sample_period", design.sample_period),
        ("u_max", design.u_max),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(PlanError::BadValue {
                name: name.into(),
                value,
            });
        }
    }
    Ok(design)
}
