//! The validity region of the backstepping position law
//! (switched-force-backstepping [SB lemma 1], [SB Theorem 3]): where the
//! desired force F_d stays ≥ 0, so that an only-attracting magnet can apply it.
//!
//! In the errors Z = (z₁, z₂) the mechanical loop is Ż = A·Z [SB 14] and F_d
//! is affine, F_d = g − kᵀZ (g: the force that holds the target). For a
//! quadratic V = ZᵀPZ with AᵀP + PA ⪯ −α·P, the level set D = {V ≤ C} is
//! invariant, and the largest inside {F_d ≥ 0} has C = g² / (kᵀP⁻¹k)
//! [SB lemma 1] (the tangent level set of a half-plane).
//!
//! - the paper's V₁ = ½‖Z‖² [SB 11] (P = ½I): its region (Fig. 5);
//! - [SB Theorem 3]: min tr P s.t. AᵀP + PA + αP ⪯ 0, P ⪰ I (the scale of P
//!   is free, the region's shape is not; P ⪰ I fixes the scale);
//! - extended: if the spring's rest X₀ (the state u = 0 converges to) is not
//!   in D, which the switching strategies [SB Theorems 4–5] need, the same
//!   program with, per target, Z₀ᵀPZ₀ ≤ ρ·C. With C as above that is
//!   kᵀP⁻¹k ≤ ρ·g² / Z₀ᵀPZ₀, i.e. P − (Z₀ᵀPZ₀ / (ρ·g²))·kkᵀ ⪰ 0 by a Schur
//!   complement: an LMI linear in P. Infeasible (a dual certificate) means no
//!   one P with that decay puts every target's X₀ within ρ·C: not a search
//!   that gave up. The targets are then tried one by one to name the culprit.
//!
//! Every constraint is a 2×2 LMI, a second-order cone (`lmi.rs`). The
//! solution is then certified independently of the solver: P ≻ 0,
//! λ_max(AᵀP + PA + αP) ≤ 1e-7·λ_max(P)·α, and every X₀ inside D where the
//! switching needs it; otherwise the design is refused.
//!
//! The scale of P does not change D, but it is part of the law: its coupling
//! term (2/m)·(PZ)₂ [SB 18] reads P as normalised here (P ⪰ I).

use super::lmi::{eigenvalues, Lmi2, Sdp2, SdpOutcome, Sym2};

/// X₀ must lie at most at this fraction of the region's level C in the
/// extended program, so that the spring carries the state strictly inside.
pub const REST_MARGIN: f64 = 0.9;

/// One constant reference and its region.
#[derive(Debug, Clone, PartialEq)]
pub struct Target {
    /// y_r [m].
    pub position: f64,
    /// g = F_d at Z = 0 [N]: the force that holds the armature at y_r.
    pub holding_force: f64,
    /// Z₀: the spring's rest X₀ in the errors of this target.
    pub rest: [f64; 2],
}

/// The region of one target under one P.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Level {
    /// C of D = {ZᵀPZ ≤ C}.
    pub c: f64,
    /// V(Z₀) < C: X₀ ∈ D.
    pub contains_rest: bool,
}

/// The designed region: the LMI's P and the level of every target, with the
/// paper's identity region beside it.
#[derive(Debug, Clone, PartialEq)]
pub struct Region {
    /// The closed loop of (z₁, z₂) [SB 14].
    pub a: [[f64; 2]; 2],
    /// α of AᵀP + PA ⪯ −αP.
    pub decay: f64,
    /// F_d = g − kᵀZ: k.
    pub force_gradient: [f64; 2],
    /// P as [p₁₁, p₁₂, p₂₂].
    pub p: Sym2,
    /// Per target, with P.
    pub levels: Vec<Level>,
    /// Per target, with the paper's P = ½I.
    pub identity: Vec<Level>,
    /// Whether the rest constraints were needed (the paper's program alone
    /// left some X₀ outside).
    pub extended: bool,
    pub targets: Vec<Target>,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RegionError {
    #[error(
        "no quadratic V decays at the rate α = {decay} s⁻¹: the closed loop's slowest rate \
         allows α ≤ {limit} s⁻¹ (twice the least |Re λ(A)|); lower `controller.decay` or raise \
         the gains"
    )]
    DecayTooFast { decay: f64, limit: f64 },
    #[error(
        "no quadratic V = ZᵀPZ with decay α = {decay} s⁻¹ has the spring's rest (z = {rest:e} m, \
         v = 0) inside its region F_d ≥ 0 {which} (the LMI program is infeasible): the \
         switching strategies cannot reach the region; change the gains (a stiffer mechanical \
         loop α₁·α₂), move the target towards the rest, lower `controller.decay`, or use \
         `switching = \"none\"`"
    )]
    RestOutside {
        decay: f64,
        rest: f64,
        which: String,
    },
    #[error("the LMI solution is not certified: {0}")]
    Uncertified(String),
    /// (`design_region`'s own check of its input: a design refuses such a
    /// target before, as one that cannot be held.)
    #[error("the target {position:e} m needs a pushing force (F_d = {force:e} N at rest there): the magnet only attracts")]
    Pushing { position: f64, force: f64 },
    #[error("the LMI solver failed: {0}")]
    Solver(String),
}

/// V = ZᵀPZ [SB 21].
pub fn quadratic(p: Sym2, z: [f64; 2]) -> f64 {
    let [a, b, c] = p;
    a * z[0] * z[0] + 2.0 * b * z[0] * z[1] + c * z[1] * z[1]
}

/// kᵀP⁻¹k, through the 2×2 adjugate.
fn inverse_quadratic(p: Sym2, k: [f64; 2]) -> f64 {
    let [a, b, c] = p;
    quadratic([c, -b, a], k) / (a * c - b * b)
}

/// The level of `target` under P [SB lemma 1].
pub fn level(p: Sym2, k: [f64; 2], target: &Target) -> Level {
    let g = target.holding_force;
    let c = g * g / inverse_quadratic(p, k);
    Level {
        c,
        contains_rest: quadratic(p, target.rest) < c,
    }
}

/// AᵀP + PA + αP for P = E (one basis matrix), as [a, b, c].
fn lyapunov_term(a: [[f64; 2]; 2], decay: f64, e: Sym2) -> Sym2 {
    let p = [[e[0], e[1]], [e[1], e[2]]];
    let entry = |i: usize, j: usize| {
        (0..2)
            .map(|k| a[k][i] * p[k][j] + p[i][k] * a[k][j])
            .sum::<f64>()
            + decay * p[i][j]
    };
    [entry(0, 0), entry(0, 1), entry(1, 1)]
}

const BASIS: [Sym2; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// −(AᵀP + PA + αP) ⪰ 0 [SB Theorem 3].
fn decay_lmi(a: [[f64; 2]; 2], decay: f64) -> Lmi2 {
    let coefficients = BASIS
        .iter()
        .map(|&e| lyapunov_term(a, decay, e).map(|x| -x))
        .collect();
    Lmi2 {
        constant: [0.0; 3],
        coefficients,
    }
}

/// P ⪰ I.
fn scale_lmi() -> Lmi2 {
    Lmi2 {
        constant: [-1.0, 0.0, -1.0],
        coefficients: BASIS.to_vec(),
    }
}

/// P − (Z₀ᵀPZ₀ / (ρ·g²))·kkᵀ ⪰ 0: X₀ at most at ρ·C.
fn rest_lmi(k: [f64; 2], target: &Target) -> Lmi2 {
    let g = target.holding_force;
    let kk = [k[0] * k[0], k[0] * k[1], k[1] * k[1]].map(|x| x / (REST_MARGIN * g * g));
    let [z1, z2] = target.rest;
    let weights = [z1 * z1, 2.0 * z1 * z2, z2 * z2];
    let coefficients = BASIS
        .iter()
        .zip(weights)
        .map(|(e, w)| [e[0] - w * kk[0], e[1] - w * kk[1], e[2] - w * kk[2]])
        .collect();
    Lmi2 {
        constant: [0.0; 3],
        coefficients,
    }
}

/// Twice the least |Re λ(A)|: the largest decay any quadratic V certifies.
pub fn decay_limit(a: [[f64; 2]; 2]) -> f64 {
    let trace = a[0][0] + a[1][1];
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    let disc = 0.25 * trace * trace - det;
    let slowest = if disc >= 0.0 {
        0.5 * trace + disc.sqrt()
    } else {
        0.5 * trace
    };
    -2.0 * slowest
}

/// min tr P under `lmis`.
fn min_trace(lmis: Vec<Lmi2>) -> Result<Option<Sym2>, RegionError> {
    let program = Sdp2 {
        objective: vec![1.0, 0.0, 1.0],
        lmis,
        equalities: vec![],
    };
    match program.solve() {
        SdpOutcome::Optimal { x, .. } => Ok(Some([x[0], x[1], x[2]])),
        SdpOutcome::Infeasible => Ok(None),
        SdpOutcome::Failed(why) => Err(RegionError::Solver(why)),
    }
}

/// The region of the closed loop `a` with decay `decay` for `targets`
/// (module docs); `need_rest`: every X₀ must lie in its region (the
/// switching strategies), else an error.
pub fn design_region(
    a: [[f64; 2]; 2],
    decay: f64,
    force_gradient: [f64; 2],
    targets: Vec<Target>,
    need_rest: bool,
) -> Result<Region, RegionError> {
    if let Some(t) = targets.iter().find(|t| t.holding_force <= 0.0) {
        return Err(RegionError::Pushing {
            position: t.position,
            force: t.holding_force,
        });
    }
    let k = force_gradient;
    let limit = decay_limit(a);
    let paper = min_trace(vec![decay_lmi(a, decay), scale_lmi()])?
        .ok_or(RegionError::DecayTooFast { decay, limit })?;
    let levels = |p: Sym2| targets.iter().map(|t| level(p, k, t)).collect::<Vec<_>>();
    let mut p = paper;
    let mut extended = false;
    if levels(p).iter().any(|l| !l.contains_rest) {
        let mut lmis = vec![decay_lmi(a, decay), scale_lmi()];
        lmis.extend(targets.iter().map(|t| rest_lmi(k, t)));
        match min_trace(lmis)? {
            Some(found) => {
                p = found;
                extended = true;
            }
            None if need_rest => {
                return Err(RegionError::RestOutside {
                    decay,
                    rest: targets.first().map_or(f64::NAN, |t| t.position + t.rest[0]),
                    which: culprit(a, decay, k, &targets)?,
                });
            }
            None => {}
        }
    }
    let region = Region {
        a,
        decay,
        force_gradient: k,
        p,
        levels: levels(p),
        identity: levels([0.5, 0.0, 0.5]),
        extended,
        targets,
    };
    region.certify(need_rest)?;
    Ok(region)
}

/// Which target's rest no P can hold: the first that is infeasible alone, or
/// all of them together.
fn culprit(
    a: [[f64; 2]; 2],
    decay: f64,
    k: [f64; 2],
    targets: &[Target],
) -> Result<String, RegionError> {
    for t in targets {
        let alone = vec![decay_lmi(a, decay), scale_lmi(), rest_lmi(k, t)];
        if min_trace(alone)?.is_none() {
            return Ok(format!("for the target {:e} m", t.position));
        }
    }
    Ok("for both targets at once (each alone has one: one P must serve both)".to_string())
}

/// Relative tolerance of the certificate's eigenvalue checks.
const CERTIFICATE_TOLERANCE: f64 = 1e-7;

impl Region {
    /// The solution checked independently of the solver (module docs).
    fn certify(&self, need_rest: bool) -> Result<(), RegionError> {
        let (p, lyap) = self.certificate();
        if !(p[0] > 0.0) {
            return Err(RegionError::Uncertified(format!(
                "P's eigenvalues {p:?} are not > 0"
            )));
        }
        if !(lyap[1] <= CERTIFICATE_TOLERANCE * p[1] * self.decay.max(1.0)) {
            return Err(RegionError::Uncertified(format!(
                "AᵀP + PA + αP has the eigenvalue {:e} > 0",
                lyap[1]
            )));
        }
        if need_rest && self.levels.iter().any(|l| !l.contains_rest) {
            return Err(RegionError::Uncertified(
                "the spring's rest lies outside a target's region".into(),
            ));
        }
        Ok(())
    }

    /// The eigenvalues (smaller first) of P and of AᵀP + PA + αP: P ≻ 0 and
    /// the second ⪯ 0 make V = ZᵀPZ decay at α.
    pub fn certificate(&self) -> ([f64; 2], [f64; 2]) {
        let lyap = BASIS
            .iter()
            .zip(self.p)
            .map(|(&e, w)| lyapunov_term(self.a, self.decay, e).map(|x| x * w))
            .fold([0.0; 3], |s, t| [s[0] + t[0], s[1] + t[1], s[2] + t[2]]);
        (eigenvalues(self.p), eigenvalues(lyap))
    }
}
