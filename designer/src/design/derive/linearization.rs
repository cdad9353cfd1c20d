//! Exact feedback linearization of the actuator for the output y = z
//! (perfect-tracking-soft-landing [PT §3.1]), derived by the symbolic core from the
//! model's own f(x, u): nothing here is typed in from the paper.
//!
//! - [PT 30] z⁽³⁾ = L_f³h + L_g L_f²h · u, relative degree 3 away from φ = 0;
//! - [PT 32] α = −L_f³h / L_g L_f²h, β = 1 / L_g L_f²h (the paper's [PT 34–35]);
//! - [PT 41] T(x) = [z, v, L_f²h] = [z, v, a];
//! - [PT 42] T⁻¹(ξ): a is quadratic in φ (a = a₀(z, v) + c₂(z)·φ²), checked
//!   symbolically, so φ = √((ξ₃ − a₀)/c₂) on D₀⁺ (φ > 0);
//! - model-free-sliding-mode-soft-landing [SM 25–26]: jerk j = f_j − B_j·u with
//!   f_j = L_f³h and B_j = −L_g L_f²h.
//!
//! Parameters stay symbolic.
//!
//! **The Jiles–Atherton core** (state [z, v, φ, H_c]) is not input-affine as a
//! whole: Ḣ_c's branch δ = sign(φ̇) depends on u. The output chain does not
//! need that row: the force, so a = L_f²z, depends on (z, v, φ) only (checked),
//! so L_f³z = ∂a/∂z·v + ∂a/∂v·a + ∂a/∂φ·φ̇ reads Ḣ_c nowhere, and φ̇ is affine in
//! u with H_c in its drift (the MMF H_c·l_c, jiles-atherton-actuator-model
//! [JA 15], [JA 92]). The chain is derived on the rows (z, v, φ) with H_c an
//! exogenous state: α, β, L_f³z depend on H_c, which the observer supplies;
//! T and T⁻¹ do not (T⁻¹ is given H_c: (ξ, H_c) ↦ (z, v, φ, H_c)), and Ḣ_c
//! is the internal dynamics the linearization leaves alone.

use crate::model::Model;
use crate::sym::{Graph, Id, Tape};

use super::lie::{vanishing_factors, AffineSystem};

/// α, β, T, T⁻¹ and the jerk terms of one actuator, as expressions.
#[derive(Debug, Clone, PartialEq)]
pub struct Linearization {
    pub system: AffineSystem,
    /// T(x) = [z, v, a] [PT 41]
    pub transform: [Id; 3],
    /// L_f³h
    pub lf3h: Id,
    /// L_g L_f²h
    pub lglf2h: Id,
    /// α(x) [PT 32]
    pub alpha: Id,
    /// β(x) [PT 32]
    pub beta: Id,
    /// f_j [SM 25]
    pub jerk_drift: Id,
    /// B_j [SM 26]
    pub jerk_gain: Id,
    /// The linearizing coordinates ξ₁, ξ₂, ξ₃ (symbols `xi1`, `xi2`, `xi3`).
    pub xi: [Id; 3],
    /// T⁻¹(ξ) [PT 42], on D₀⁺.
    pub inverse: [Id; 3],
    /// φ² required by ξ: (ξ₃ − a₀(ξ₁, ξ₂))/c₂(ξ₁), the radicand of T⁻¹.
    /// [PT 56] asks 0 < φ² < φ_sat².
    pub flux_squared: Id,
    /// States whose zero makes L_g L_f²h vanish (relative degree lost), e.g. φ.
    pub singular_at: Vec<Id>,
    /// States outside the chain (z, v, φ) that α, β and the jerk terms read:
    /// H_c with the Jiles–Atherton core, none otherwise.
    pub exogenous: Vec<Id>,
}

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DesignError {
    #[error("the acceleration depends on the core's field state H_c: the chain z, v, a does not close on (z, v, φ)")]
    FieldInForce,
    #[error("the model is not affine in the input u, so it cannot be feedback-linearized")]
    NotAffine,
    #[error("the output z does not have relative degree 3 (L_g L_f^k z ≡ 0 for k < 3): the input does not reach the position through the flux")]
    RelativeDegree { found: Option<usize> },
    #[error("the acceleration is not of the form a₀(z, v) + c₂(z)·φ²: T⁻¹ cannot be solved for φ")]
    NotQuadraticInFlux,
}

impl Linearization {
    /// Derives the linearization of `model` for y = z.
    pub fn derive(model: &mut Model) -> Result<Linearization, DesignError> {
        let (states, f, u) = (model.states.clone(), model.f.clone(), model.input);
        // the chain's rows (z, v, φ); a field state H_c stays exogenous
        let (chain_states, exogenous) = states.split_at(states.len().min(3));
        let g = &mut model.graph;
        let system = AffineSystem::split(g, chain_states, &f[..chain_states.len()], u)
            .ok_or(DesignError::NotAffine)?;
        let z = states[0];
        let chain = system
            .output_derivatives(g, z, 3)
            .ok_or(DesignError::RelativeDegree { found: None })?;
        if chain.degree != 3 {
            return Err(DesignError::RelativeDegree {
                found: Some(chain.degree),
            });
        }
        let (accel, lf3h, lglf2h) = (chain.lf[2], chain.lf[3], chain.gain);
        // [JA 39] the force reads φ, not H_c: L_f³z needs no Ḣ_c
        if exogenous.iter().any(|&s| g.depends_on(accel, s)) {
            return Err(DesignError::FieldInForce);
        }
        // [PT 32]
        let ratio = g.div(lf3h, lglf2h);
        let alpha = g.neg(ratio);
        let beta = g.recip(lglf2h);
        // [SM 26]
        let jerk_gain = g.neg(lglf2h);
        let xi = [g.symbol("xi1"), g.symbol("xi2"), g.symbol("xi3")];
        let (inverse, flux_squared) = inverse_transform(g, &states, accel, xi)?;
        let singular_at = vanishing_factors(g, lglf2h, &states);
        Ok(Linearization {
            transform: [z, states[1], accel],
            lf3h,
            lglf2h,
            alpha,
            beta,
            jerk_drift: lf3h,
            jerk_gain,
            xi,
            inverse,
            flux_squared,
            singular_at,
            exogenous: exogenous.to_vec(),
            system,
        })
    }

    /// Why the relative degree is lost where it is, for messages.
    pub fn singularity_text(&self, g: &Graph) -> String {
        let names: Vec<&str> = self
            .singular_at
            .iter()
            .filter_map(|&s| g.name_of(s))
            .collect();
        match names.as_slice() {
            [] => "L_g L_f²z does not vanish identically on any state hyperplane".into(),
            _ => format!(
                "relative degree 3 is lost where {} = 0 (L_g L_f²z vanishes there): the controller works in D₀⁺ = {{{} > 0}}",
                names.join(" = 0 or "),
                names.join(", ")
            ),
        }
    }
}

/// [PT 42]: x = T⁻¹(ξ) from a = a₀(z, v) + c₂(z)·φ², and the radicand φ².
fn inverse_transform(
    g: &mut Graph,
    states: &[Id],
    accel: Id,
    xi: [Id; 3],
) -> Result<([Id; 3], Id), DesignError> {
    let (z, v, phi) = (states[0], states[1], states[2]);
    let zero = g.zero();
    let at_zero_flux = |g: &mut Graph, e: Id| {
        let map = std::iter::once((phi, zero)).collect();
        g.substitute(e, &map)
    };
    let a0 = at_zero_flux(g, accel);
    let da = g.diff(accel, phi);
    let slope_at_zero = at_zero_flux(g, da);
    let d2a = g.diff(da, phi);
    let c2 = g.scale(0.5, d2a);
    let d3a = g.diff(d2a, phi);
    if slope_at_zero != zero || d3a != zero || states[3..].iter().any(|&s| g.depends_on(accel, s)) {
        return Err(DesignError::NotQuadraticInFlux);
    }
    let to_xi = [(z, xi[0]), (v, xi[1])].into_iter().collect();
    let (a0, c2) = (g.substitute(a0, &to_xi), g.substitute(c2, &to_xi));
    let num = g.sub(xi[2], a0);
    let ratio = g.div(num, c2);
    Ok(([xi[0], xi[1], g.sqrt(ratio)], ratio))
}

/// φ² = (ξ₃ − a₀(ξ₁, ξ₂))/c₂(ξ₁) of T⁻¹ [PT 42] compiled at the model's
/// parameter values, to evaluate at many ξ.
pub struct FluxSquared {
    tape: Tape,
    scratch: Vec<f64>,
    /// ξ, then the parameters' values.
    point: Vec<f64>,
}

impl FluxSquared {
    /// The radicand of `lin` on `model`; `Err` names a symbol left unbound.
    pub fn new(model: &Model, lin: &Linearization) -> Result<FluxSquared, String> {
        let mut inputs = lin.xi.to_vec();
        inputs.extend(model.params.iter().map(|(_, id, _)| id));
        let tape = Tape::compile(&model.graph, &inputs, &[lin.flux_squared]).map_err(|e| e.0)?;
        let mut point = vec![0.0; 3];
        point.extend(model.params.iter().map(|(_, _, v)| v));
        Ok(FluxSquared {
            scratch: tape.scratch(),
            tape,
            point,
        })
    }

    /// φ² at ξ = [z, v, a].
    pub fn at(&mut self, xi: [f64; 3]) -> f64 {
        self.point[..3].copy_from_slice(&xi);
        let mut out = [0.0];
        self.tape.eval(&self.point, &mut self.scratch, &mut out);
        out[0]
    }
}
