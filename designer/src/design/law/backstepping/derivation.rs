//! Backstepping position control through the magnetic force
//! (switched-force-backstepping [SB §III], Theorems 1–2), derived by the
//! symbolic core from the model's own f(x, u) for any gap × core × coil.
//!
//! reldesign's state is the flux, the paper's the current; the force is the
//! model's F = −F_mag = ½·R_gap'(z)·φ² ≥ 0 (attracting, towards z_min), so the
//! paper's switched force map [SB 2–3], whose coefficients are unpublished,
//! is not needed. With the passive force F_p(z, v) = k_s·z + c·v + F0 and
//! m·v̇ = −F − F_p:
//!
//! - [SB 9] z₁ = z − y_r, z₂ = v + α₁·z₁;
//! - F_d, the force that makes ż₂ = −z₁ − α₂·z₂ (so Ż = A·Z, A = [[−α₁, 1],
//!   [−1, −α₂]], [SB 14]): F_d = m·(z₁ + α₂·z₂ + α₁·v) − F_p(z, v). This is
//!   Theorem 1's F_d = m·(a·z₁ + (b + α₂)·z₂ − d) in reldesign's signs, derived
//!   from V₁ = ½‖Z‖² (ERRATA: [SB §IV] prints it with other signs);
//! - z₃ = F − F_d; with V = ZᵀPZ + ½·z₃² (P of the region, `region.rs`;
//!   P = ½I is the paper's V), ż₂ = −z₁ − α₂·z₂ − z₃/m and the law
//!   Ḟ = Ḟ_d − α₃·z₃ + (2/m)·(PZ)₂ gives V̇ = Zᵀ(AᵀP + PA)Z − α₃·z₃² [SB 18];
//! - Ḟ = f_F + g_F·u (f_F = L_f F, g_F = L_g F on the rows (z, v, φ)), so
//!   u = (Ḟ_desired − f_F)/g_F [SB 19]; g_F = R_gap'·φ·∂φ̇/∂u vanishes at
//!   φ = 0, where the runtime does not evaluate the law.
//!
//! With the Jiles–Atherton core, H_c enters f_F through φ̇ (as it enters α, β
//! of `derive/linearization.rs`) and is an input of the law; the force itself reads
//! φ only. Parameters, gains, y_r and P stay symbolic.

use crate::model::Model;
use crate::sym::{Graph, Id};

use crate::design::derive::lie::lie;
use crate::design::derive::linearization::{DesignError, Linearization};

/// The backstepping law's expressions, in full (over states, y_r, gains,
/// P and parameters) and as stages for emitted code.
#[derive(Debug, Clone, PartialEq)]
pub struct Backstepping {
    /// y_r (symbol `y_ref`).
    pub target: Id,
    /// α₁, α₂, α₃ (symbols `gain_a1`, `gain_a2`, `gain_a3`).
    pub gains: [Id; 3],
    /// p₁₂, p₂₂ of P (symbols `region_p12`, `region_p22`): the coupling
    /// (2/m)·(PZ)₂.
    pub coupling: [Id; 2],
    /// F = −F_mag ≥ 0 [N].
    pub force: Id,
    /// f_F, g_F: Ḟ = f_F + g_F·u.
    pub force_drift: Id,
    pub force_gain: Id,
    /// F_d(z, v; y_r) [SB Theorem 1].
    pub desired_force: Id,
    /// u [SB 19].
    pub law: Id,
    /// The errors z₁, z₂ [SB 9].
    pub errors: [Id; 2],
    /// The law as equations: (name, symbol, expression over the symbols of
    /// the stages before it, equation), in order; u last.
    pub stages: Vec<Stage>,
    /// States outside (z, v, φ) the law reads (H_c), as in [`Linearization`].
    pub exogenous: Vec<Id>,
}

/// One named equation of the law: `name` = `expr`, `symbol` standing for it
/// in later stages.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stage {
    pub name: &'static str,
    pub symbol: Id,
    pub expr: Id,
    pub equation: &'static str,
}

/// Why the backstepping law cannot be derived.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BacksteppingError {
    #[error(transparent)]
    Linearization(#[from] DesignError),
    #[error("the passive force is not linear in (z, v): F_d is not affine in the errors and the region of [SB lemma 1] is not a half-plane")]
    NonlinearPassiveForce,
    #[error("the model has no mass parameter `m`")]
    NoMass,
    #[error(
        "internal error: a stage symbol of the backstepping law is left in its full expressions"
    )]
    Staging,
}

/// Names of the law's symbols, which must be new to the model's graph.
pub const SYMBOLS: [&str; 6] = [
    "y_ref",
    "gain_a1",
    "gain_a2",
    "gain_a3",
    "region_p12",
    "region_p22",
];

/// The stages' names (their symbols are `bs_` + name).
pub const STAGES: [&str; 8] = [
    "z1",
    "z2",
    "force",
    "desired_force",
    "desired_rate",
    "force_drift",
    "force_gain",
    "u",
];

impl Backstepping {
    /// Derives the law on `model`, whose linearization `lin` gives the
    /// input-affine rows (z, v, φ).
    pub fn derive(
        model: &mut Model,
        lin: &Linearization,
    ) -> Result<Backstepping, BacksteppingError> {
        let mass = model.params.symbol("m").ok_or(BacksteppingError::NoMass)?;
        let (z, v) = (model.states[0], model.states[1]);
        let accel = model.f[1];
        let passive = model.passive_force;
        let f_mag = model.f_mag;
        let g = &mut model.graph;
        if !is_affine(g, passive, &[z, v]) {
            return Err(BacksteppingError::NonlinearPassiveForce);
        }
        let [target, a1, a2, a3, p12, p22] = SYMBOLS.map(|name| g.symbol(name));
        let s = STAGES.map(|name| g.symbol(&format!("bs_{name}")));
        let [s_z1, s_z2, s_force, s_desired, s_rate, s_drift, s_gain, _] = s;
        // [SB 9]
        let z1 = g.sub(z, target);
        let a1z1 = g.mul(a1, s_z1);
        let z2 = g.add(v, a1z1);
        // [SB Theorem 1] F_d = m·(z₁ + α₂·z₂ + α₁·v) − F_p(z, v)
        let a2z2 = g.mul(a2, s_z2);
        let a1v = g.mul(a1, v);
        let wanted = g.sum(&[s_z1, a2z2, a1v]);
        let m_wanted = g.mul(mass, wanted);
        let desired = g.sub(m_wanted, passive);
        let desired_full = unstage(g, desired, &[(s_z1, z1), (s_z2, z2)]);
        // Ḟ_d along the motion (y_r constant): ∂F_d/∂z·v + ∂F_d/∂v·v̇
        let rate = lie(g, &[v, accel], &[z, v], desired_full);
        // F and Ḟ = f_F + g_F·u on the rows (z, v, φ)
        let force = g.neg(f_mag);
        let rows = &lin.system.states;
        let drift = lie(g, &lin.system.drift, rows, force);
        let gain = lie(g, &lin.system.input_field, rows, force);
        // [SB 18] Ḟ* = Ḟ_d − α₃·(F − F_d) + (2/m)·(p₁₂·z₁ + p₂₂·z₂)
        let z3 = g.sub(s_force, s_desired);
        let damping = g.mul(a3, z3);
        let pz1 = g.mul(p12, s_z1);
        let pz2 = g.mul(p22, s_z2);
        let pz = g.add(pz1, pz2);
        let two_pz = g.scale(2.0, pz);
        let coupling = g.div(two_pz, mass);
        let without_damping = g.add(s_rate, coupling);
        let wanted_rate = g.sub(without_damping, damping);
        // [SB 19] u = (Ḟ* − f_F)/g_F
        let num = g.sub(wanted_rate, s_drift);
        let u = g.div(num, s_gain);
        let exprs = [z1, z2, force, desired, rate, drift, gain, u];
        let equations = [
            "[SB 9] z₁ = z − y_r",
            "[SB 9] z₂ = v + α₁·z₁",
            "[PT 11] F = −F_mag = ½·R_gap'(z)·φ² (attracting)",
            "[SB Theorem 1] F_d = m·(z₁ + α₂·z₂ + α₁·v) − F_p(z, v): ż₂ = −z₁ − α₂·z₂ [SB 14]",
            "Ḟ_d = ∂F_d/∂z·v + ∂F_d/∂v·v̇ (y_r constant)",
            "f_F = L_f F: Ḟ = f_F + g_F·u",
            "g_F = L_g F (∝ φ: 0 at φ = 0)",
            "[SB 19] u = (Ḟ_d − α₃·(F − F_d) + (2/m)·(p₁₂·z₁ + p₂₂·z₂) − f_F)/g_F",
        ];
        let stages: Vec<Stage> = (0..STAGES.len())
            .map(|k| Stage {
                name: STAGES[k],
                symbol: s[k],
                expr: exprs[k],
                equation: equations[k],
            })
            .collect();
        // in full: each stage's symbol replaced by its full expression
        let mut full: Vec<(Id, Id)> = Vec::new();
        for stage in &stages {
            let e = unstage(g, stage.expr, &full);
            full.push((stage.symbol, e));
        }
        if full
            .iter()
            .any(|&(_, e)| s.iter().any(|&sym| g.depends_on(e, sym)))
        {
            return Err(BacksteppingError::Staging);
        }
        let value = |k: usize| full[k].1;
        Ok(Backstepping {
            target,
            gains: [a1, a2, a3],
            coupling: [p12, p22],
            force: value(2),
            force_drift: value(5),
            force_gain: value(6),
            desired_force: value(3),
            law: value(7),
            errors: [value(0), value(1)],
            stages,
            exogenous: lin.exogenous.clone(),
        })
    }
}

/// `e` with the stage symbols of `map` replaced, later entries first (a later
/// stage's expression may read an earlier one's symbol).
fn unstage(g: &mut Graph, e: Id, map: &[(Id, Id)]) -> Id {
    map.iter().rev().fold(e, |e, &(s, x)| {
        let one = std::iter::once((s, x)).collect();
        g.substitute(e, &one)
    })
}

/// e is affine in `vars`: every second derivative vanishes identically.
fn is_affine(g: &mut Graph, e: Id, vars: &[Id]) -> bool {
    let zero = g.zero();
    vars.iter().all(|&x| {
        let d = g.diff(e, x);
        vars.iter().all(|&y| g.diff(d, y) == zero)
    })
}
