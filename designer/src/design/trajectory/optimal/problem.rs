//! The energy-optimal problem (perfect-tracking-soft-landing [PT 58–66]):
//! what is asked ([`OptimalSpec`], with the initial guess's costates), why
//! it failed ([`OptimalError`]), and the Hamiltonian system [PT 65–66]
//! compiled to tapes. The guess, the search within the stroke and the
//! solver above them all read it here, so none of them reads another's file
//! for it.

use std::cell::RefCell;
use std::collections::HashMap;

use crate::design::derive::linearization::Linearization;
use crate::design::trajectory::bvp::BvpError;
use crate::model::Model;
use crate::sym::{Id, Tape};

/// How the costates p₁, p₂ of the initial guess are built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CostateGuess {
    /// Solve the costate equations along the integrator chain for p₂, p₁.
    Chain,
    /// p₁ = p₂ = 0 (only p₃ from pᵀg = −2u_r).
    Zero,
}

/// The optimal-control problem.
#[derive(Debug, Clone, PartialEq)]
pub struct OptimalSpec {
    pub z0: f64,
    pub zf: f64,
    pub t0: f64,
    pub tf: f64,
    /// Trajectory bounds on u (tighter than the supply, to leave a margin to
    /// the tracking controller).
    pub u_min: f64,
    pub u_max: f64,
    /// Collocation tolerance (RMS relative residual, scaled variables) and
    /// boundary tolerance.
    pub tol: f64,
    /// Nodes of the uniform initial mesh.
    pub nodes: usize,
    pub max_nodes: usize,
    pub costate_guess: CostateGuess,
    /// The largest u_max worth trying when the problem has no solution (the
    /// supply): the needed bound is searched up to it. Default: ∞.
    pub u_max_limit: f64,
    /// σ [m] of the arrival stop's position into the stroke (half-normal from
    /// z_f); > 0 adds the expected squared contact speed to the cost
    /// (`optimal/robust.rs`). Default: 0, the deterministic problem.
    pub contact_uncertainty: f64,
}

impl OptimalSpec {
    /// Defaults: tol 1e-6, 151 initial nodes, at most 20000 nodes, chain costates.
    pub fn new(z0: f64, zf: f64, t0: f64, tf: f64, u_min: f64, u_max: f64) -> OptimalSpec {
        OptimalSpec {
            z0,
            zf,
            t0,
            tf,
            u_min,
            u_max,
            tol: 1e-6,
            nodes: 151,
            max_nodes: 20000,
            costate_guess: CostateGuess::Chain,
            u_max_limit: f64::INFINITY,
            contact_uncertainty: 0.0,
        }
    }
}

/// Why [`energy_optimal`] failed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum OptimalError {
    #[error("the model has {0} states: the energy-optimal design (Pontryagin) needs a costate for every state, and the Jiles–Atherton core's Ḣ_c switches branch with sign(dφ/dt), which depends on u, so the Hamiltonian is not differentiable there; design the reference with trajectory.shape = \"polynomial\", or solve it on a \"saturating\" core fitted to the same valve and track it on this model")]
    NotAffine(usize),
    #[error("invalid optimal-control problem: {0}")]
    InvalidSpec(String),
    #[error("the {which} state is infeasible: resting at z = {z:e} needs φ² = {flux_squared:e} (must be > 0, finite): the spring and preload cannot be balanced by a positive flux there")]
    InfeasibleBoundary {
        which: &'static str,
        z: f64,
        flux_squared: f64,
    },
    #[error("the initial guess is not finite at t = {t:e} ({what}): the polynomial reference leaves the domain of T⁻¹ (φ² ≤ 0); lengthen the motion")]
    Guess { t: f64, what: &'static str },
    #[error("the Hamiltonian boundary-value problem did not converge: {source}")]
    Bvp {
        #[source]
        source: BvpError,
    },
    #[error("the free arc of {duration:e} s leaves the stroke (z in [{:e}, {:e}] m)", z_range[0], z_range[1])]
    OutsideStroke { z_range: [f64; 2], duration: f64 },
    #[error("no free arc of at most {total:e} s was found that stays within the stroke")]
    NoShortArc { total: f64 },
    #[error("the motion needs u_max ≥ {needed:.4} (the bound is {given:.4}): with u_max = {given:.4} no motion of {duration:e} s exists ({source})")]
    BoundTooLow {
        needed: f64,
        given: f64,
        duration: f64,
        #[source]
        source: Box<OptimalError>,
    },
    #[error("the motion needs t_f − t₀ ≥ {needed:.4e} s (it is {given:.4e} s): no shorter motion exists within u ∈ [{u_min:.4}, {u_max:.4}] ({source})")]
    TooShort {
        needed: f64,
        given: f64,
        u_min: f64,
        u_max: f64,
        #[source]
        source: Box<OptimalError>,
    },
    #[error("the probability-based reference for a stop spread σ = {sigma:e} m did not converge: the continuation from the deterministic optimum reached {:.3}·W of the contact weight W ({source}); a smaller trajectory.contact_uncertainty, a longer motion or a larger trajectory.u_bound leaves it more room", reached)]
    Contact {
        reached: f64,
        sigma: f64,
        #[source]
        source: Box<OptimalError>,
    },
    #[error("the solver found no solution, and neither a larger bound (up to ×4, within the supply) nor a longer motion (up to ×16) has one: please report this description ({source})")]
    Unsolved {
        #[source]
        source: Box<OptimalError>,
    },
}

impl OptimalError {
    /// Whether the error says the problem may have no solution (rather than
    /// that the problem or the model is malformed).
    pub(super) fn may_be_infeasible(&self) -> bool {
        matches!(
            self,
            OptimalError::Bvp { .. }
                | OptimalError::Guess { .. }
                | OptimalError::OutsideStroke { .. }
                | OptimalError::NoShortArc { .. }
        )
    }
}

/// The symbolic Hamiltonian system compiled to tapes over
/// (z, v, φ, p₁, p₂, p₃, t), parameters bound, for fixed input bounds.
#[derive(Debug, Clone)]
pub struct HamiltonianSystem {
    /// [ẋ; ṗ] (6 outputs).
    pub rhs: Tape,
    /// ∂[ẋ; ṗ]/∂[x; p], row-major 6×6.
    pub jacobian: Tape,
    /// [u*, −pᵀg/2 (unclamped), a = T₃(x), jerk, H].
    pub aux: Tape,
    pub u_min: f64,
    pub u_max: f64,
    scratch: RefCell<(Vec<f64>, Vec<f64>)>,
}

/// The position the Hamiltonian system's model sees: z itself down to
/// z_b = z_min − Z_EPS/4, and below it z_b − δ·w/√(1 + w²), w = (z_b − z)/δ,
/// δ = Z_EPS/2, which joins z with matching first and second derivatives and
/// never goes below z_min − ¾·Z_EPS. Collocation midpoints, interpolated mesh
/// nodes and Newton iterates may dip past the closing stop; the McLyman
/// logarithm ln(k/(z + Z_EPS)) stays defined there, and the model is the
/// description's own wherever it was defined before. Arcs that actually leave
/// the stroke are rejected by the search (`optimal/search.rs`).
fn stroke_extension(g: &mut crate::sym::Graph, z: Id, z_min: f64) -> Id {
    let delta = 0.5 * crate::model::Z_EPS;
    let z_b = z_min - 0.25 * crate::model::Z_EPS;
    let zmin = g.constant(z_b);
    let depth = g.sub(zmin, z);
    let w = g.scale(1.0 / delta, depth);
    let w2 = g.powi(w, 2);
    let one = g.one();
    let r = g.add(one, w2);
    let root = g.sqrt(r);
    let s = g.div(w, root);
    let ds = g.scale(-delta, s);
    let below = g.add(zmin, ds);
    g.piecewise(z, &[z_b], &[below, z])
}

/// The running cost of the contact (`optimal/robust.rs`):
/// L_c = W·ρ(z)·|v|³, ρ the half-normal density of scale σ of the stop's
/// position into the stroke from `z_stop` (its Gaussian continued outside,
/// where the arc does not go), so that ∫L_c dt = W·E[v_c²] over the stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactCost {
    pub weight: f64,
    pub sigma: f64,
    pub z_stop: f64,
}

impl ContactCost {
    fn build(&self, g: &mut crate::sym::Graph, z: Id, v: Id) -> Id {
        let zs = g.constant(self.z_stop);
        let d = g.sub(z, zs);
        let d2 = g.powi(d, 2);
        let e = g.scale(-0.5 / (self.sigma * self.sigma), d2);
        let rho = g.exp(e);
        let peak = 2.0 / (self.sigma * (2.0 * std::f64::consts::PI).sqrt());
        let av = g.abs(v);
        let v2 = g.powi(v, 2);
        let v3 = g.mul(v2, av);
        let l = g.mul(rho, v3);
        g.scale(self.weight * peak, l)
    }
}

/// Indices of [`HamiltonianSystem::aux`] outputs.
pub(in crate::design) const AUX_U: usize = 0;
pub(in crate::design) const AUX_RAW: usize = 1;
pub(in crate::design) const AUX_A: usize = 2;
pub(in crate::design) const AUX_JERK: usize = 3;
pub(in crate::design) const AUX_H: usize = 4;

impl HamiltonianSystem {
    /// Derives the system symbolically from `model.f` and the linearization.
    pub fn derive(
        model: &mut Model,
        lin: &Linearization,
        u_min: f64,
        u_max: f64,
    ) -> Result<HamiltonianSystem, OptimalError> {
        Self::derive_with(model, lin, u_min, u_max, None)
    }

    /// The system of the cost ∫(u² + L_c(x)) dt, with L_c the contact term
    /// of `contact` (`optimal/robust.rs`): u* is unchanged (L_c does not
    /// depend on u), ṗ gains −∂L_c/∂x and H gains L_c.
    pub fn derive_with(
        model: &mut Model,
        lin: &Linearization,
        u_min: f64,
        u_max: f64,
        contact: Option<&ContactCost>,
    ) -> Result<HamiltonianSystem, OptimalError> {
        if model.dim() != 3 || lin.system.input_field.len() != 3 {
            return Err(OptimalError::NotAffine(model.dim()));
        }
        if !(u_min < u_max) {
            return Err(OptimalError::InvalidSpec(format!(
                "u_min = {u_min} must be below u_max = {u_max}"
            )));
        }
        for name in ["p1", "p2", "p3"] {
            if model.params.symbol(name).is_some() {
                return Err(OptimalError::InvalidSpec(format!(
                    "a model parameter is named `{name}`, the costate symbol"
                )));
            }
        }
        let x: Vec<Id> = model.states.clone();
        let (u, t) = (model.input, model.time);
        let z_min = model.description.mechanics.z_min;
        let g = &mut model.graph;
        // the model seen through the stroke extension (identity on the stroke)
        let zeta = stroke_extension(g, x[0], z_min);
        let ext: HashMap<Id, Id> = std::iter::once((x[0], zeta)).collect();
        let f: Vec<Id> = model.f.iter().map(|&fi| g.substitute(fi, &ext)).collect();
        let gfield: Vec<Id> = (lin.system.input_field.iter())
            .map(|&gi| g.substitute(gi, &ext))
            .collect();
        let p = [g.symbol("p1"), g.symbol("p2"), g.symbol("p3")];
        // u* = clamp(−pᵀg/2, u_min, u_max)
        let pg_terms: Vec<Id> = p
            .iter()
            .zip(&gfield)
            .map(|(&pi, &gi)| g.mul(pi, gi))
            .collect();
        let pg = g.sum(&pg_terms);
        let raw = g.scale(-0.5, pg);
        let lo = g.constant(u_min);
        let hi = g.constant(u_max);
        let above = g.max(raw, lo);
        let ustar = g.min(above, hi);
        let to_ustar: HashMap<Id, Id> = std::iter::once((u, ustar)).collect();
        // ẋ = f(x, u*)
        let mut rhs: Vec<Id> = f.iter().map(|&fi| g.substitute(fi, &to_ustar)).collect();
        // ṗ = −(∂f/∂x)ᵀp at u* (− ∂L_c/∂x with the contact term)
        let lc = contact.map(|c| c.build(g, x[0], x[1]));
        let dlc = lc.map(|l| g.jacobian(&[l], &x).remove(0));
        let a = g.jacobian(&f, &x);
        for k in 0..3 {
            let mut terms: Vec<Id> = (0..3).map(|i| g.mul(a[i][k], p[i])).collect();
            if let Some(d) = &dlc {
                terms.push(d[k]);
            }
            let s = g.sum(&terms);
            let s = g.substitute(s, &to_ustar);
            rhs.push(g.neg(s));
        }
        // H = u² + pᵀf (+ L_c)
        let pf_terms: Vec<Id> = (0..3).map(|i| g.mul(p[i], rhs[i])).collect();
        let pf = g.sum(&pf_terms);
        let u2 = g.powi(ustar, 2);
        let h = g.add(u2, pf);
        let h = match lc {
            Some(l) => g.add(h, l),
            None => h,
        };
        let ju = g.mul(lin.lglf2h, ustar);
        let jerk = g.add(lin.lf3h, ju);
        let accel = lin.transform[2];
        let mut all = rhs.clone();
        all.extend([ustar, raw, accel, jerk, h]);
        let bound = model.bind_params(&all);
        let (rhs_b, aux_b) = bound.split_at(6);
        let y: Vec<Id> = x.iter().chain(p.iter()).copied().collect();
        let jac = model.graph.jacobian(rhs_b, &y);
        let jac_flat: Vec<Id> = jac.into_iter().flatten().collect();
        let mut inputs = y.clone();
        inputs.push(t);
        let compile = |outs: &[Id]| {
            Tape::compile(&model.graph, &inputs, outs).map_err(|e| {
                OptimalError::InvalidSpec(format!("the Hamiltonian system is not closed: {e}"))
            })
        };
        let rhs = compile(rhs_b)?;
        let jacobian = compile(&jac_flat)?;
        let aux = compile(aux_b)?;
        let scratch = RefCell::new((rhs.scratch(), jacobian.scratch()));
        Ok(HamiltonianSystem {
            rhs,
            jacobian,
            aux,
            u_min,
            u_max,
            scratch,
        })
    }

    fn inputs(t: f64, y: &[f64]) -> [f64; 7] {
        [y[0], y[1], y[2], y[3], y[4], y[5], t]
    }

    /// [u*, −pᵀg/2, a, jerk, H] at (t, [x; p]).
    pub fn aux_at(&self, t: f64, y: &[f64]) -> [f64; 5] {
        let mut out = [0.0; 5];
        self.aux
            .eval(&Self::inputs(t, y), &mut self.aux.scratch(), &mut out);
        out
    }
}

impl HamiltonianSystem {
    /// [ẋ; ṗ] at (t, [x; p]).
    pub(crate) fn rhs_at(&self, t: f64, y: &[f64], dy: &mut [f64]) {
        let mut s = self.scratch.borrow_mut();
        self.rhs.eval(&Self::inputs(t, y), &mut s.0, dy);
    }

    /// ∂[ẋ; ṗ]/∂[x; p] at (t, [x; p]), row-major.
    pub(crate) fn jacobian_at(&self, t: f64, y: &[f64], j: &mut [f64]) {
        let mut s = self.scratch.borrow_mut();
        self.jacobian.eval(&Self::inputs(t, y), &mut s.1, j);
    }
}
