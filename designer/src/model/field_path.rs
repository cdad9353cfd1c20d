//! The Jiles–Atherton core's field H_c along a flux path, without time.
//!
//! The inverse Jiles–Atherton model is rate independent: [JA 33]
//! dH_c/dt = (dH_c/dB_c)(φ, H_c, δ)·φ̇/A_c depends on φ̇ only through its
//! sign δ, so H_c is a function of the path φ takes: dH_c = (dH_c/dB_c)·dφ/A_c.
//! Designs evaluate their law along a reference's flux φ_r(t) (T⁻¹ gives it
//! without H_c) and need the H_c the core holds there; this integrates it
//! over φ in small steps (midpoint rule), each step on the branch of its
//! sign.

use crate::description::Core;
use crate::sym::Tape;

use super::core::ja_field_rate;
use super::statics::anhysteretic_field;
use super::Model;

/// The flux step [Wb] of the integration, as a fraction of the core's
/// saturation flux μ0·M_sat·A_c.
const STEP_FRACTION: f64 = 1e-4;

/// H_c following a flux path from a demagnetised or anhysteretic start.
#[derive(Debug, Clone)]
pub struct FieldPath {
    /// (φ, H_c, Δφ) → ΔH_c = (dH_c/dB_c)·Δφ/A_c [JA 33].
    tape: Tape,
    scratch: Vec<f64>,
    step: f64,
    phi: f64,
    hc: f64,
}

impl FieldPath {
    /// The path of `model`'s core starting at `flux` on the anhysteretic
    /// curve (H_c = 0 at φ = 0); `None` for a core without the field state.
    pub fn anhysteretic(model: &Model, flux: f64) -> Option<FieldPath> {
        let Core::JilesAtherton(ja) = &model.description.core else {
            return None;
        };
        let (&phi, &hc) = (model.states.get(2)?, model.states.get(3)?);
        let mut m = model.clone();
        let dphi = m.graph.symbol("field_path_dphi");
        let rate = ja_field_rate(&mut m.graph, &mut m.params, ja, phi, hc, dphi);
        let bound = m.bind_params(&[rate]);
        let tape = Tape::compile(&m.graph, &[phi, hc, dphi], &bound).ok()?;
        let saturation = super::gap::MU0 * ja.m_sat * ja.area;
        Some(FieldPath {
            scratch: tape.scratch(),
            tape,
            step: STEP_FRACTION * saturation,
            phi: flux,
            hc: anhysteretic_field(ja, flux / ja.area),
        })
    }

    /// H_c now [A/m].
    pub fn field(&self) -> f64 {
        self.hc
    }

    /// Moves the flux to `flux` and returns H_c there.
    pub fn advance(&mut self, flux: f64) -> f64 {
        let span = flux - self.phi;
        if !span.is_finite() || span == 0.0 {
            return self.hc;
        }
        let n = (span.abs() / self.step).ceil().clamp(1.0, 1e6);
        let dphi = span / n;
        let mut out = [0.0];
        for _ in 0..n as usize {
            // midpoint rule on dH_c/dφ, on the branch of dφ's sign
            self.tape
                .eval(&[self.phi, self.hc, dphi], &mut self.scratch, &mut out);
            let half = [self.phi + 0.5 * dphi, self.hc + 0.5 * out[0], dphi];
            self.tape.eval(&half, &mut self.scratch, &mut out);
            self.phi += dphi;
            self.hc += out[0];
        }
        self.phi = flux;
        self.hc
    }
}
