//! A two-point boundary-value-problem solver of the bvp4c / scipy `solve_bvp`
//! class, generic: it knows nothing about actuators.
//!
//! Solves y' = f(t, y), bc(y(a), y(b)) = 0 with y ∈ ℝⁿ and n boundary
//! conditions (separated or not). The algorithm follows Kierzenka & Shampine,
//! "A BVP solver based on residual control and the MATLAB PSE" (ACM TOMS 27,
//! 2001) as implemented in scipy's `scipy/integrate/_bvp.py`:
//!
//! - **Collocation.** The solution is a C¹ piecewise cubic (3-stage Lobatto
//!   IIIA): on each interval [tᵢ, tᵢ₊₁] of width h it interpolates yᵢ, fᵢ,
//!   yᵢ₊₁, fᵢ₊₁ and satisfies the ODE at the midpoint, which gives the
//!   residual (Simpson's rule)
//!   `Φᵢ = yᵢ₊₁ − yᵢ − h/6·(fᵢ + 4·f(t_mid, y_mid) + fᵢ₊₁)`,
//!   `y_mid = (yᵢ + yᵢ₊₁)/2 − h/8·(fᵢ₊₁ − fᵢ)`. Fourth order at the nodes.
//! - **Newton.** The (m−1)·n collocation residuals and the n boundary
//!   residuals are solved by scipy's damped Newton: at most 8 iterations and 4
//!   Jacobian evaluations per mesh, Armijo backtracking (σ = 0.2, τ = 0.5,
//!   4 halvings) on the squared norm of the Newton step J⁻¹·res (a step
//!   that leaves the domain of f, non-finite values, is halved up to 24
//!   times: iterates stay where f is defined), and a
//!   Jacobian re-use (chord step) after a full step was accepted. The Jacobian
//!   blocks ∂Φᵢ/∂yᵢ, ∂Φᵢ/∂yᵢ₊₁ are built from the caller's ∂f/∂y at the nodes
//!   and midpoints, exactly as scipy does.
//! - **Linear algebra.** The global Jacobian is block-bidiagonal plus the
//!   boundary rows [B_a 0 … 0 B_b]. It is factored in O(m·n³) time and memory
//!   by sequential block elimination with Householder QR: each interior yᵢ is
//!   eliminated from the 2n rows that contain it (the carried rows and block
//!   row i), the y₀ column being carried along; the last 2n×2n system in
//!   (y₀, y_{m−1}) together with the boundary rows is solved by LU with
//!   partial pivoting. This is Gaussian elimination of the whole matrix with
//!   the column order (y₁, …, y_{m−2}, y₀, y_{m−1}) and orthogonal row
//!   transformations, which is stable for dichotomic problems (growing and
//!   decaying modes, as in Hamiltonian systems).
//! - **Residual control.** After Newton, the relative residual
//!   r = (S′ − f(t, S))/(1 + |f|) of the cubic S is estimated on every
//!   interval in the RMS sense by 5-point Lobatto quadrature (the residual
//!   vanishes at the nodes; midpoint and ±√(3/7)·h/2 are sampled). Intervals
//!   with residual > tol get one node (two if ≥ 100·tol); the new mesh is
//!   initialized from the cubic. Stops when no node is added and the boundary
//!   residual is ≤ bc_tol.
//!
//! **Scaling.** States of very different magnitudes (metres ~1e-3, webers
//! ~1e-5) make the relative residual 1 + |f| meaningless for the small ones.
//! [`BvpOptions::scale`] gives a per-component scale s: the solver works in
//! ŷ = y/s (tolerances, residuals, Newton norms are in ŷ), and
//! [`BvpOptions::bc_scale`] divides the boundary residuals. Results are
//! returned unscaled.
//!
//! Right-hand sides that are only piecewise smooth (e.g. a saturated optimal
//! input u* = clamp(·)) are handled: the residual control concentrates nodes
//! around the kinks.

// `!(x > tol)` is deliberate: it is also true for NaN. Index loops mirror the
// matrix formulas.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

use std::fmt;

/// y' = f(t, y), bc(y(a), y(b)) = 0.
pub trait BvpProblem {
    /// n, the number of states (and of boundary conditions).
    fn dim(&self) -> usize;
    /// dy = f(t, y).
    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]);
    /// ∂fᵢ/∂yⱼ, row-major n×n (`j[i * n + j]`).
    fn jacobian(&self, t: f64, y: &[f64], j: &mut [f64]);
    /// The n boundary residuals.
    fn bc(&self, ya: &[f64], yb: &[f64], r: &mut [f64]);
    /// ∂bcₖ/∂y(a)ⱼ and ∂bcₖ/∂y(b)ⱼ, row-major n×n each.
    fn bc_jacobian(&self, ya: &[f64], yb: &[f64], ja: &mut [f64], jb: &mut [f64]);
}

/// Options of [`solve_bvp`]. `Default` is scipy's (tol = 1e-3, bc_tol = tol,
/// max_nodes = 1000).
#[derive(Debug, Clone, PartialEq)]
pub struct BvpOptions {
    /// Tolerance on the RMS relative collocation residual of every interval.
    pub tol: f64,
    /// Tolerance on the absolute (scaled) boundary residuals; `None` = tol.
    pub bc_tol: Option<f64>,
    /// The solver fails rather than grow the mesh beyond this.
    pub max_nodes: usize,
    /// Newton iterations per mesh (scipy: 8).
    pub max_newton: usize,
    /// Jacobian evaluations per mesh (scipy: 4).
    pub max_jacobians: usize,
    /// Refinements that add no node but leave the boundary residual above
    /// bc_tol before giving up (scipy: 10).
    pub max_iterations: usize,
    /// Per-component scale of y (length n, positive): the solver works in y/scale.
    pub scale: Option<Vec<f64>>,
    /// Per-condition scale of the boundary residuals (length n, positive).
    pub bc_scale: Option<Vec<f64>>,
}

impl Default for BvpOptions {
    fn default() -> Self {
        BvpOptions {
            tol: 1e-3,
            bc_tol: None,
            max_nodes: 1000,
            max_newton: 8,
            max_jacobians: 4,
            max_iterations: 10,
            scale: None,
            bc_scale: None,
        }
    }
}

/// A converged (or best-effort, inside an error) solution: the mesh, the
/// nodal values, the nodal derivatives f(tᵢ, yᵢ), and the C¹ cubic through them.
#[derive(Clone, PartialEq)]
pub struct BvpSolution {
    /// The final mesh.
    pub t: Vec<f64>,
    /// y at the nodes: `y[i]` is the state at `t[i]` (unscaled).
    pub y: Vec<Vec<f64>>,
    /// f(tᵢ, yᵢ) at the nodes (unscaled).
    pub yp: Vec<Vec<f64>>,
    /// RMS relative residual of each interval (in scaled variables).
    pub rms_residuals: Vec<f64>,
    /// max of `rms_residuals`.
    pub max_residual: f64,
    /// max |bc| (scaled by `bc_scale`).
    pub bc_residual: f64,
    /// Newton iterations over all meshes.
    pub newton_iterations: usize,
    /// Jacobian evaluations (factorizations) over all meshes.
    pub jacobian_evaluations: usize,
    /// Solve-and-estimate passes (scipy's `niter`); refinements = this − 1.
    pub mesh_refinements: usize,
    /// Right-hand-side evaluations (nodes + midpoints + residual samples).
    pub rhs_evaluations: usize,
}

impl fmt::Debug for BvpSolution {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("BvpSolution")
            .field("nodes", &self.t.len())
            .field("interval", &(self.t.first(), self.t.last()))
            .field("max_residual", &self.max_residual)
            .field("bc_residual", &self.bc_residual)
            .field("newton_iterations", &self.newton_iterations)
            .field("jacobian_evaluations", &self.jacobian_evaluations)
            .field("mesh_refinements", &self.mesh_refinements)
            .finish_non_exhaustive()
    }
}

impl BvpSolution {
    /// n.
    pub fn dim(&self) -> usize {
        self.y.first().map_or(0, Vec::len)
    }

    /// Index i of the interval [tᵢ, tᵢ₊₁] used for t (end intervals extrapolate).
    fn interval(&self, t: f64) -> usize {
        let m = self.t.len();
        if m < 2 {
            return 0;
        }
        let k = self.t.partition_point(|&x| x <= t);
        k.saturating_sub(1).min(m - 2)
    }

    /// The cubic Hermite interpolant S(t) (C¹, the collocation polynomial).
    pub fn eval(&self, t: f64) -> Vec<f64> {
        self.eval_with(t).0
    }

    /// S′(t).
    pub fn eval_derivative(&self, t: f64) -> Vec<f64> {
        self.eval_with(t).1
    }

    /// (S(t), S′(t)).
    pub fn eval_with(&self, t: f64) -> (Vec<f64>, Vec<f64>) {
        let n = self.dim();
        let mut y = vec![0.0; n];
        let mut dy = vec![0.0; n];
        if self.t.len() < 2 {
            if let Some(y0) = self.y.first() {
                y.copy_from_slice(y0);
                dy.copy_from_slice(&self.yp[0]);
            }
            return (y, dy);
        }
        let i = self.interval(t);
        let h = self.t[i + 1] - self.t[i];
        let s = (t - self.t[i]) / h;
        hermite(
            s,
            h,
            &self.y[i],
            &self.yp[i],
            &self.y[i + 1],
            &self.yp[i + 1],
            &mut y,
            &mut dy,
        );
        (y, dy)
    }

    /// Component k of y at the nodes.
    pub fn component(&self, k: usize) -> Vec<f64> {
        self.y.iter().map(|y| y[k]).collect()
    }
}

/// Why [`solve_bvp`] failed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum BvpError {
    #[error("invalid BVP input: {0}")]
    InvalidInput(String),
    #[error("the {what} returned a non-finite value at t = {t:e} (y = {y:?})")]
    NonFinite {
        what: &'static str,
        t: f64,
        y: Vec<f64>,
    },
    #[error("singular collocation Jacobian on a mesh of {nodes} nodes (pass {iteration}, max relative residual {max_residual:.3e}): the linearized BVP has no unique solution at the current iterate (check the boundary conditions, the Jacobians and the initial guess)")]
    SingularJacobian {
        nodes: usize,
        iteration: usize,
        max_residual: f64,
    },
    #[error("Newton diverged on a mesh of {nodes} nodes: f or bc is non-finite at t = {t:e} even after the smallest damped step: the Newton iterates leave the domain of f")]
    NewtonDiverged { nodes: usize, t: f64 },
    #[error("the mesh would need {needed} nodes > max_nodes = {max_nodes}; on the current {nodes} nodes the max relative residual is {max_residual:.3e} (tol {tol:e}) and the BC residual {bc_residual:.3e}")]
    MaxNodesExceeded {
        nodes: usize,
        needed: usize,
        max_nodes: usize,
        max_residual: f64,
        tol: f64,
        bc_residual: f64,
        best: Box<BvpSolution>,
    },
    #[error("the boundary residual {bc_residual:.3e} is still above bc_tol = {bc_tol:e} after {iterations} passes (max relative residual {max_residual:.3e})")]
    BcTolerance {
        iterations: usize,
        bc_residual: f64,
        bc_tol: f64,
        max_residual: f64,
        best: Box<BvpSolution>,
    },
    #[error("Newton did not converge on the fixed mesh of {nodes} nodes: max collocation residual {collocation_residual:.3e}, BC residual {bc_residual:.3e}")]
    NotConverged {
        nodes: usize,
        collocation_residual: f64,
        bc_residual: f64,
        best: Box<BvpSolution>,
    },
}

// ---------------------------------------------------------------------------
// Scaled evaluation of the user's problem.

struct Eval<'a, P: ?Sized> {
    p: &'a P,
    n: usize,
    s: Vec<f64>,
    bs: Vec<f64>,
    ya: Vec<f64>,
    yb: Vec<f64>,
    ja: Vec<f64>,
    jb: Vec<f64>,
    nfev: usize,
}

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

impl<'a, P: BvpProblem + ?Sized> Eval<'a, P> {
    /// f̂(t, ŷ) = f(t, s∘ŷ)/s.
    fn rhs(&mut self, t: f64, yh: &[f64], out: &mut [f64]) -> Result<(), BvpError> {
        self.nfev += 1;
        for k in 0..self.n {
            self.ya[k] = yh[k] * self.s[k];
        }
        self.p.rhs(t, &self.ya, out);
        if !all_finite(out) {
            return Err(BvpError::NonFinite {
                what: "right-hand side f",
                t,
                y: self.ya.clone(),
            });
        }
        for k in 0..self.n {
            out[k] /= self.s[k];
        }
        Ok(())
    }

    /// Ĵ = S⁻¹ J S.
    fn jac(&mut self, t: f64, yh: &[f64], out: &mut [f64]) -> Result<(), BvpError> {
        let n = self.n;
        for k in 0..n {
            self.ya[k] = yh[k] * self.s[k];
        }
        self.p.jacobian(t, &self.ya, out);
        if !all_finite(out) {
            return Err(BvpError::NonFinite {
                what: "Jacobian ∂f/∂y",
                t,
                y: self.ya.clone(),
            });
        }
        for i in 0..n {
            for j in 0..n {
                out[i * n + j] *= self.s[j] / self.s[i];
            }
        }
        Ok(())
    }

    fn unscale_ends(&mut self, yah: &[f64], ybh: &[f64]) {
        for k in 0..self.n {
            self.ya[k] = yah[k] * self.s[k];
            self.yb[k] = ybh[k] * self.s[k];
        }
    }

    fn bc(&mut self, ta: f64, yah: &[f64], ybh: &[f64], out: &mut [f64]) -> Result<(), BvpError> {
        self.unscale_ends(yah, ybh);
        self.p.bc(&self.ya, &self.yb, out);
        if !all_finite(out) {
            return Err(BvpError::NonFinite {
                what: "boundary conditions",
                t: ta,
                y: self.ya.clone(),
            });
        }
        for k in 0..self.n {
            out[k] /= self.bs[k];
        }
        Ok(())
    }

    fn bc_jac(
        &mut self,
        ta: f64,
        yah: &[f64],
        ybh: &[f64],
        ja: &mut [f64],
        jb: &mut [f64],
    ) -> Result<(), BvpError> {
        let n = self.n;
        self.unscale_ends(yah, ybh);
        self.p
            .bc_jacobian(&self.ya, &self.yb, &mut self.ja, &mut self.jb);
        if !all_finite(&self.ja) || !all_finite(&self.jb) {
            return Err(BvpError::NonFinite {
                what: "boundary-condition Jacobian",
                t: ta,
                y: self.ya.clone(),
            });
        }
        for k in 0..n {
            for j in 0..n {
                ja[k * n + j] = self.ja[k * n + j] * self.s[j] / self.bs[k];
                jb[k * n + j] = self.jb[k * n + j] * self.s[j] / self.bs[k];
            }
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------
// Cubic Hermite on one interval, local coordinate s ∈ [0, 1].

#[allow(clippy::too_many_arguments)]
fn hermite(
    s: f64,
    h: f64,
    y0: &[f64],
    f0: &[f64],
    y1: &[f64],
    f1: &[f64],
    y: &mut [f64],
    dy: &mut [f64],
) {
    let s2 = s * s;
    let s3 = s2 * s;
    let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
    let h10 = s3 - 2.0 * s2 + s;
    let h01 = -2.0 * s3 + 3.0 * s2;
    let h11 = s3 - s2;
    let d00 = (6.0 * s2 - 6.0 * s) / h;
    let d10 = 3.0 * s2 - 4.0 * s + 1.0;
    let d01 = -d00;
    let d11 = 3.0 * s2 - 2.0 * s;
    for k in 0..y.len() {
        y[k] = h00 * y0[k] + h * h10 * f0[k] + h01 * y1[k] + h * h11 * f1[k];
        dy[k] = d00 * y0[k] + d10 * f0[k] + d01 * y1[k] + d11 * f1[k];
    }
}

// ---------------------------------------------------------------------------
// Collocation residuals.

struct Colloc {
    /// Φᵢ, (m−1)·n.
    res: Vec<f64>,
    /// y_mid, (m−1)·n.
    y_mid: Vec<f64>,
    /// f at nodes, m·n.
    f: Vec<f64>,
    /// f at midpoints, (m−1)·n.
    f_mid: Vec<f64>,
    /// bc residuals, n.
    bc: Vec<f64>,
}

impl Colloc {
    fn new(n: usize, m: usize) -> Colloc {
        Colloc {
            res: vec![0.0; (m - 1) * n],
            y_mid: vec![0.0; (m - 1) * n],
            f: vec![0.0; m * n],
            f_mid: vec![0.0; (m - 1) * n],
            bc: vec![0.0; n],
        }
    }
}

fn collocation<P: BvpProblem + ?Sized>(
    ev: &mut Eval<'_, P>,
    x: &[f64],
    y: &[f64],
    c: &mut Colloc,
) -> Result<(), BvpError> {
    let n = ev.n;
    let m = x.len();
    for i in 0..m {
        ev.rhs(x[i], &y[i * n..(i + 1) * n], &mut c.f[i * n..(i + 1) * n])?;
    }
    for i in 0..m - 1 {
        let h = x[i + 1] - x[i];
        let (y0, y1) = (&y[i * n..(i + 1) * n], &y[(i + 1) * n..(i + 2) * n]);
        let (f0, f1) = (&c.f[i * n..(i + 1) * n], &c.f[(i + 1) * n..(i + 2) * n]);
        let ym = &mut c.y_mid[i * n..(i + 1) * n];
        for k in 0..n {
            ym[k] = 0.5 * (y0[k] + y1[k]) - 0.125 * h * (f1[k] - f0[k]);
        }
        ev.rhs(x[i] + 0.5 * h, ym, &mut c.f_mid[i * n..(i + 1) * n])?;
        let fm = &c.f_mid[i * n..(i + 1) * n];
        let r = &mut c.res[i * n..(i + 1) * n];
        for k in 0..n {
            r[k] = y1[k] - y0[k] - h / 6.0 * (f0[k] + f1[k] + 4.0 * fm[k]);
        }
    }
    ev.bc(x[0], &y[..n], &y[(m - 1) * n..], &mut c.bc)
}

// ---------------------------------------------------------------------------
// Block elimination of the collocation Jacobian.

/// Factorization of
/// ```text
/// [A₀ B₀            ]
/// [   A₁ B₁         ]
/// [      …  …       ]
/// [         A B     ]
/// [Ba            Bb ]
/// ```
///
/// The buffers are kept across factorizations (Newton iterations and meshes)
/// so that the hot loop does not allocate; the Householder vectors are stored
/// column-major so that the dot products of the solve run over contiguous
/// memory, and the reflections are applied to the work matrix row by row.
#[derive(Default)]
struct BlockFactor {
    n: usize,
    m: usize,
    /// Householder vectors of each interior step: (m−2) × (n × 2n), column-
    /// major: vector k occupies `[k * 2n .. (k + 1) * 2n]`, v_k in rows k..2n.
    hv: Vec<f64>,
    /// (m−2) × n.
    beta: Vec<f64>,
    /// (m−2) × (n × n): R (upper), coefficient rows on y₀, on yᵢ₊₁.
    r: Vec<f64>,
    c0: Vec<f64>,
    e: Vec<f64>,
    /// Final (2n × 2n) LU with row pivots.
    lu: Vec<f64>,
    piv: Vec<usize>,
    // scratch
    cw: Vec<f64>,
    dw: Vec<f64>,
    /// Work matrix, 2n rows × 3n columns [y₀ | yᵢ | yᵢ₊₁], row-major.
    w: Vec<f64>,
    /// Householder coefficients of the 3n columns of `w`.
    dots: Vec<f64>,
    v: Vec<f64>,
    g: Vec<f64>,
    wr: Vec<f64>,
    carried: Vec<f64>,
    z: Vec<f64>,
    t: Vec<f64>,
}

struct Singular;

fn resize(v: &mut Vec<f64>, len: usize) {
    v.clear();
    v.resize(len, 0.0);
}

impl BlockFactor {
    /// Factors into `self`. `a`, `b`: (m−1) blocks n×n row-major; `ba`, `bb`: n×n.
    fn factor(
        &mut self,
        n: usize,
        m: usize,
        a: &[f64],
        b: &[f64],
        ba: &[f64],
        bb: &[f64],
    ) -> Result<(), Singular> {
        // the common small dimensions get loops of constant length (unrolled,
        // no bounds checks); the arithmetic is the same in every instance
        match n {
            2 => self.factor_n::<2>(n, m, a, b, ba, bb),
            3 => self.factor_n::<3>(n, m, a, b, ba, bb),
            4 => self.factor_n::<4>(n, m, a, b, ba, bb),
            6 => self.factor_n::<6>(n, m, a, b, ba, bb),
            _ => self.factor_n::<0>(n, m, a, b, ba, bb),
        }
    }

    /// Solves J·x = rhs (rhs: (m−1)·n collocation rows, then n bc rows).
    fn solve(&mut self, rhs: &[f64], x: &mut [f64]) {
        match self.n {
            2 => self.solve_n::<2>(rhs, x),
            3 => self.solve_n::<3>(rhs, x),
            4 => self.solve_n::<4>(rhs, x),
            6 => self.solve_n::<6>(rhs, x),
            _ => self.solve_n::<0>(rhs, x),
        }
    }

    /// [`Self::factor`] with n = N when N > 0, else n = `n_rt`.
    #[allow(clippy::too_many_arguments)]
    fn factor_n<const N: usize>(
        &mut self,
        n_rt: usize,
        m: usize,
        a: &[f64],
        b: &[f64],
        ba: &[f64],
        bb: &[f64],
    ) -> Result<(), Singular> {
        let n = if N > 0 { N } else { n_rt };
        let nn = n * n;
        let steps = m - 2;
        let n2 = 2 * n;
        let w3 = 3 * n;
        self.n = n;
        self.m = m;
        // every entry below is written before it is read
        self.hv.resize(steps * 2 * nn, 0.0);
        self.beta.resize(steps * n, 0.0);
        self.r.resize(steps * nn, 0.0);
        self.c0.resize(steps * nn, 0.0);
        self.e.resize(steps * nn, 0.0);
        resize(&mut self.lu, 4 * nn);
        self.piv.clear();
        self.piv.resize(n2, 0);
        resize(&mut self.v, n2);
        resize(&mut self.w, n2 * w3);
        // Carried rows W = [C | D] on (y₀, yᵢ).
        self.cw.clear();
        self.cw.extend_from_slice(&a[..nn]);
        self.dw.clear();
        self.dw.extend_from_slice(&b[..nn]);
        resize(&mut self.dots, w3);
        let (cw, dw, w, v, dots) = (
            &mut self.cw,
            &mut self.dw,
            &mut self.w,
            &mut self.v,
            &mut self.dots,
        );
        for st in 0..steps {
            let i = st + 1;
            w.iter_mut().for_each(|x| *x = 0.0);
            let (ai, bi) = (&a[i * nn..(i + 1) * nn], &b[i * nn..(i + 1) * nn]);
            for r in 0..n {
                for c in 0..n {
                    w[r * w3 + c] = cw[r * n + c];
                    w[r * w3 + n + c] = dw[r * n + c];
                    w[(n + r) * w3 + n + c] = ai[r * n + c];
                    w[(n + r) * w3 + 2 * n + c] = bi[r * n + c];
                }
            }
            let mut maxnorm: f64 = 0.0;
            for c in 0..n {
                let s: f64 = (0..n2).map(|r| w[r * w3 + n + c].powi(2)).sum();
                maxnorm = maxnorm.max(s.sqrt());
            }
            let hv = &mut self.hv[st * 2 * nn..(st + 1) * 2 * nn];
            let beta = &mut self.beta[st * n..(st + 1) * n];
            for k in 0..n {
                let col = n + k;
                let norm: f64 = (k..n2).map(|r| w[r * w3 + col].powi(2)).sum::<f64>().sqrt();
                if !(norm > 4.0 * n as f64 * f64::EPSILON * maxnorm) {
                    return Err(Singular);
                }
                let x0 = w[k * w3 + col];
                let alpha = if x0 >= 0.0 { -norm } else { norm };
                for r in k..n2 {
                    v[r] = w[r * w3 + col];
                }
                v[k] -= alpha;
                let vv: f64 = v[k..].iter().map(|x| x * x).sum();
                let bt = if vv > 0.0 { 2.0 / vv } else { 0.0 };
                // w ← (I − bt·v·vᵀ)·w, row by row: every column's dot product
                // vᵀw_j still sums over the rows in order k..2n, but the
                // columns are processed side by side (contiguous, vectorizable)
                let dots = &mut dots[..w3];
                dots.iter_mut().for_each(|d| *d = 0.0);
                for r in k..n2 {
                    let vr = v[r];
                    let row = &w[r * w3..(r + 1) * w3];
                    for (d, &q) in dots.iter_mut().zip(row) {
                        *d += vr * q;
                    }
                }
                for d in dots.iter_mut() {
                    *d *= bt;
                }
                // the already-reduced columns n..col of the yᵢ block are left alone
                dots[n..col].iter_mut().for_each(|d| *d = 0.0);
                for r in k..n2 {
                    let vr = v[r];
                    let row = &mut w[r * w3..(r + 1) * w3];
                    for (q, &g) in row.iter_mut().zip(dots.iter()) {
                        *q -= g * vr;
                    }
                }
                let hk = &mut hv[k * n2..(k + 1) * n2];
                hk[..k].iter_mut().for_each(|x| *x = 0.0);
                hk[k..].copy_from_slice(&v[k..]);
                beta[k] = bt;
            }
            let base = st * nn;
            for r in 0..n {
                for c in 0..n {
                    self.c0[base + r * n + c] = w[r * w3 + c];
                    self.r[base + r * n + c] = if c >= r { w[r * w3 + n + c] } else { 0.0 };
                    self.e[base + r * n + c] = w[r * w3 + 2 * n + c];
                    cw[r * n + c] = w[(n + r) * w3 + c];
                    dw[r * n + c] = w[(n + r) * w3 + 2 * n + c];
                }
            }
        }
        // Final system [[C, D], [Ba, Bb]] on (y₀, y_{m−1}).
        for r in 0..n {
            for c in 0..n {
                self.lu[r * n2 + c] = cw[r * n + c];
                self.lu[r * n2 + n + c] = dw[r * n + c];
                self.lu[(n + r) * n2 + c] = ba[r * n + c];
                self.lu[(n + r) * n2 + n + c] = bb[r * n + c];
            }
        }
        let maxabs = self.lu.iter().fold(0.0f64, |acc, v| acc.max(v.abs()));
        let lu = &mut self.lu;
        for k in 0..n2 {
            let (mut p, mut pv) = (k, lu[k * n2 + k].abs());
            for r in k + 1..n2 {
                if lu[r * n2 + k].abs() > pv {
                    p = r;
                    pv = lu[r * n2 + k].abs();
                }
            }
            if !(pv > 4.0 * n2 as f64 * f64::EPSILON * maxabs) {
                return Err(Singular);
            }
            self.piv[k] = p;
            if p != k {
                for c in 0..n2 {
                    lu.swap(k * n2 + c, p * n2 + c);
                }
            }
            let d = lu[k * n2 + k];
            for r in k + 1..n2 {
                let l = lu[r * n2 + k] / d;
                lu[r * n2 + k] = l;
                if l != 0.0 {
                    for c in k + 1..n2 {
                        lu[r * n2 + c] -= l * lu[k * n2 + c];
                    }
                }
            }
        }
        Ok(())
    }

    /// [`Self::solve`] with n = N when N > 0, else n = `self.n`.
    fn solve_n<const N: usize>(&mut self, rhs: &[f64], x: &mut [f64]) {
        let n = if N > 0 { N } else { self.n };
        let m = self.m;
        let nn = n * n;
        let n2 = 2 * n;
        let steps = m - 2;
        resize(&mut self.g, steps * n);
        resize(&mut self.wr, n2);
        resize(&mut self.t, n);
        resize(&mut self.z, n2);
        self.carried.clear();
        self.carried.extend_from_slice(&rhs[..n]);
        let (g, wr, carried) = (&mut self.g, &mut self.wr, &mut self.carried);
        for st in 0..steps {
            let i = st + 1;
            wr[..n].copy_from_slice(carried);
            wr[n..].copy_from_slice(&rhs[i * n..(i + 1) * n]);
            let hv = &self.hv[st * 2 * nn..(st + 1) * 2 * nn];
            for k in 0..n {
                let bt = self.beta[st * n + k];
                let hk = &hv[k * n2 + k..(k + 1) * n2];
                let wk = &mut wr[k..];
                let dot: f64 = hk.iter().zip(wk.iter()).map(|(p, q)| p * q).sum();
                let gm = bt * dot;
                for (q, p) in wk.iter_mut().zip(hk) {
                    *q -= gm * p;
                }
            }
            g[st * n..(st + 1) * n].copy_from_slice(&wr[..n]);
            carried.copy_from_slice(&wr[n..]);
        }
        // Final 2n system.
        let z = &mut self.z;
        z[..n].copy_from_slice(carried);
        z[n..].copy_from_slice(&rhs[(m - 1) * n..m * n]);
        for k in 0..n2 {
            z.swap(k, self.piv[k]);
        }
        for r in 0..n2 {
            let mut s = z[r];
            for c in 0..r {
                s -= self.lu[r * n2 + c] * z[c];
            }
            z[r] = s;
        }
        for r in (0..n2).rev() {
            let mut s = z[r];
            for c in r + 1..n2 {
                s -= self.lu[r * n2 + c] * z[c];
            }
            z[r] = s / self.lu[r * n2 + r];
        }
        x[..n].copy_from_slice(&z[..n]);
        x[(m - 1) * n..m * n].copy_from_slice(&z[n..]);
        // Back substitution: R yᵢ = gᵢ − C₀ y₀ − E yᵢ₊₁.
        let t = &mut self.t;
        for st in (0..steps).rev() {
            let i = st + 1;
            let base = st * nn;
            for r in 0..n {
                let mut s = g[st * n + r];
                for c in 0..n {
                    s -= self.c0[base + r * n + c] * x[c]
                        + self.e[base + r * n + c] * x[(i + 1) * n + c];
                }
                t[r] = s;
            }
            for r in (0..n).rev() {
                let mut s = t[r];
                for c in r + 1..n {
                    s -= self.r[base + r * n + c] * t[c];
                }
                t[r] = s / self.r[base + r * n + r];
            }
            x[i * n..(i + 1) * n].copy_from_slice(t);
        }
    }
}

/// Buffers of the global Jacobian, kept across Newton iterations and meshes.
#[derive(Default)]
struct JacWork {
    /// ∂f/∂y at the nodes, m × (n × n).
    jn: Vec<f64>,
    /// ∂Φᵢ/∂yᵢ, ∂Φᵢ/∂yᵢ₊₁, (m−1) × (n × n).
    a: Vec<f64>,
    b: Vec<f64>,
    jm: Vec<f64>,
    ba: Vec<f64>,
    bb: Vec<f64>,
    fac: BlockFactor,
}

/// Builds the global Jacobian blocks (scipy's `construct_global_jac`) and
/// factors it into `w.fac`; Ok(false) when it is singular.
fn jacobian_factor<P: BvpProblem + ?Sized>(
    ev: &mut Eval<'_, P>,
    x: &[f64],
    y: &[f64],
    c: &Colloc,
    w: &mut JacWork,
) -> Result<bool, BvpError> {
    let n = ev.n;
    let nn = n * n;
    let m = x.len();
    w.jn.resize(m * nn, 0.0);
    w.a.resize((m - 1) * nn, 0.0);
    w.b.resize((m - 1) * nn, 0.0);
    resize(&mut w.jm, nn);
    resize(&mut w.ba, nn);
    resize(&mut w.bb, nn);
    for i in 0..m {
        ev.jac(
            x[i],
            &y[i * n..(i + 1) * n],
            &mut w.jn[i * nn..(i + 1) * nn],
        )?;
    }
    let jm = &mut w.jm;
    for i in 0..m - 1 {
        let h = x[i + 1] - x[i];
        ev.jac(x[i] + 0.5 * h, &c.y_mid[i * n..(i + 1) * n], jm)?;
        let j0 = &w.jn[i * nn..(i + 1) * nn];
        let j1 = &w.jn[(i + 1) * nn..(i + 2) * nn];
        let ai = &mut w.a[i * nn..(i + 1) * nn];
        let bi = &mut w.b[i * nn..(i + 1) * nn];
        for r in 0..n {
            for col in 0..n {
                let mut t0 = 0.0;
                let mut t1 = 0.0;
                for k in 0..n {
                    t0 += jm[r * n + k] * j0[k * n + col];
                    t1 += jm[r * n + k] * j1[k * n + col];
                }
                let id = if r == col { 1.0 } else { 0.0 };
                let q = r * n + col;
                ai[q] = -id - h / 6.0 * (j0[q] + 2.0 * jm[q]) - h * h / 12.0 * t0;
                bi[q] = id - h / 6.0 * (j1[q] + 2.0 * jm[q]) + h * h / 12.0 * t1;
            }
        }
    }
    ev.bc_jac(x[0], &y[..n], &y[(m - 1) * n..], &mut w.ba, &mut w.bb)?;
    Ok(w.fac
        .factor(
            n,
            m,
            &w.a[..(m - 1) * nn],
            &w.b[..(m - 1) * nn],
            &w.ba,
            &w.bb,
        )
        .is_ok())
}

// ---------------------------------------------------------------------------
// Damped Newton (scipy's `solve_newton`).

struct NewtonOut {
    singular: bool,
    iterations: usize,
    jacobians: usize,
    converged: bool,
}

fn first_nonfinite_t(x: &[f64], n: usize, v: &[f64]) -> f64 {
    let m = x.len();
    match v.iter().position(|a| !a.is_finite()) {
        Some(p) => x[(p / n).min(m - 1)],
        None => x[0],
    }
}

fn converged(x: &[f64], n: usize, c: &Colloc, tol: f64, bc_tol: f64) -> bool {
    let m = x.len();
    for i in 0..m - 1 {
        let h = x[i + 1] - x[i];
        let tol_r = 2.0 / 3.0 * h * 5e-2 * tol;
        for k in 0..n {
            if !(c.res[i * n + k].abs() < tol_r * (1.0 + c.f_mid[i * n + k].abs())) {
                return false;
            }
        }
    }
    c.bc.iter().all(|r| r.abs() < bc_tol)
}

#[allow(clippy::too_many_arguments)]
fn newton<P: BvpProblem + ?Sized>(
    ev: &mut Eval<'_, P>,
    x: &[f64],
    y: &mut Vec<f64>,
    c: &mut Colloc,
    tol: f64,
    bc_tol: f64,
    max_iter: usize,
    max_njev: usize,
    work: &mut JacWork,
) -> Result<NewtonOut, BvpError> {
    const SIGMA: f64 = 0.2;
    const TAU: f64 = 0.5;
    const N_TRIAL: usize = 4;
    const N_DOMAIN: usize = 24;
    let n = ev.n;
    let m = x.len();
    let len = m * n;
    collocation(ev, x, y, c)?;
    let mut res = vec![0.0; len];
    let pack = |c: &Colloc, res: &mut [f64]| {
        res[..(m - 1) * n].copy_from_slice(&c.res);
        res[(m - 1) * n..].copy_from_slice(&c.bc);
    };
    pack(c, &mut res);
    let mut out = NewtonOut {
        singular: false,
        iterations: 0,
        jacobians: 0,
        converged: false,
    };
    let mut step = vec![0.0; len];
    let mut step_new = vec![0.0; len];
    let mut y_new = vec![0.0; len];
    let mut c_new = Colloc::new(n, m);
    let mut cost = 0.0;
    let mut recompute = true;
    for _ in 0..max_iter {
        if recompute {
            if !jacobian_factor(ev, x, y, c, work)? {
                out.singular = true;
                out.jacobians += 1;
                break;
            }
            out.jacobians += 1;
            work.fac.solve(&res, &mut step);
            cost = step.iter().map(|s| s * s).sum();
        }
        let fac = &mut work.fac;
        out.iterations += 1;
        let mut alpha = 1.0;
        let mut ok;
        let mut cost_new = f64::INFINITY;
        let mut bad_t = x[0];
        let mut trial = 0;
        loop {
            for q in 0..len {
                y_new[q] = y[q] - alpha * step[q];
            }
            match collocation(ev, x, &y_new, &mut c_new) {
                Ok(()) => {
                    pack(&c_new, &mut res);
                    fac.solve(&res, &mut step_new);
                    cost_new = step_new.iter().map(|s| s * s).sum();
                    ok = cost_new.is_finite();
                    if !ok {
                        bad_t = first_nonfinite_t(x, n, &step_new);
                    }
                }
                Err(BvpError::NonFinite { t, .. }) => {
                    ok = false;
                    bad_t = t;
                }
                Err(e) => return Err(e),
            }
            if ok && cost_new < (1.0 - 2.0 * alpha * SIGMA) * cost {
                break;
            }
            // Armijo backtracking ends after N_TRIAL halvings; a step that
            // leaves the domain of f (non-finite values) is halved further,
            // down to 2^-N_DOMAIN, so iterates stay where f is defined.
            let limit = if ok { N_TRIAL } else { N_DOMAIN };
            if trial >= limit {
                break;
            }
            trial += 1;
            alpha *= TAU;
        }
        if !ok {
            return Err(BvpError::NewtonDiverged { nodes: m, t: bad_t });
        }
        std::mem::swap(y, &mut y_new);
        std::mem::swap(c, &mut c_new);
        if converged(x, n, c, tol, bc_tol) {
            out.converged = true;
            break;
        }
        if out.jacobians == max_njev {
            break;
        }
        if alpha == 1.0 {
            std::mem::swap(&mut step, &mut step_new);
            cost = cost_new;
            recompute = false;
        } else {
            recompute = true;
        }
    }
    Ok(out)
}

// ---------------------------------------------------------------------------
// Residual estimate (scipy's `estimate_rms_residuals`).

fn rms_residuals<P: BvpProblem + ?Sized>(
    ev: &mut Eval<'_, P>,
    x: &[f64],
    y: &[f64],
    c: &Colloc,
) -> Result<Vec<f64>, BvpError> {
    let n = ev.n;
    let m = x.len();
    let mut out = vec![0.0; m - 1];
    let mut ys = vec![0.0; n];
    let mut dys = vec![0.0; n];
    let mut fs = vec![0.0; n];
    let d = 0.5 * (3.0f64 / 7.0).sqrt();
    for i in 0..m - 1 {
        let h = x[i + 1] - x[i];
        let mut rm = 0.0;
        for k in 0..n {
            let r = 1.5 * c.res[i * n + k] / h / (1.0 + c.f_mid[i * n + k].abs());
            rm += r * r;
        }
        let mut r12 = 0.0;
        for s in [0.5 + d, 0.5 - d] {
            hermite(
                s,
                h,
                &y[i * n..(i + 1) * n],
                &c.f[i * n..(i + 1) * n],
                &y[(i + 1) * n..(i + 2) * n],
                &c.f[(i + 1) * n..(i + 2) * n],
                &mut ys,
                &mut dys,
            );
            ev.rhs(x[i] + s * h, &ys, &mut fs)?;
            for k in 0..n {
                let r = (dys[k] - fs[k]) / (1.0 + fs[k].abs());
                r12 += r * r;
            }
        }
        out[i] = (0.5 * (32.0 / 45.0 * rm + 49.0 / 90.0 * r12)).sqrt();
    }
    Ok(out)
}

// ---------------------------------------------------------------------------
// Driver.

struct Prepared<'a, P: ?Sized> {
    ev: Eval<'a, P>,
    x: Vec<f64>,
    y: Vec<f64>,
    tol: f64,
    bc_tol: f64,
}

fn prepare<'a, P: BvpProblem + ?Sized>(
    problem: &'a P,
    t: &[f64],
    y: &[Vec<f64>],
    opts: &BvpOptions,
) -> Result<Prepared<'a, P>, BvpError> {
    let n = problem.dim();
    let m = t.len();
    let bad = |s: String| Err(BvpError::InvalidInput(s));
    if n == 0 {
        return bad("the problem has dimension 0".into());
    }
    if m < 2 {
        return bad(format!("the initial mesh needs at least 2 nodes, got {m}"));
    }
    if let Some(i) = t.iter().position(|v| !v.is_finite()) {
        return bad(format!("mesh node {i} is not finite ({})", t[i]));
    }
    if let Some(i) = (0..m - 1).find(|&i| !(t[i + 1] > t[i])) {
        return bad(format!(
            "the mesh must be strictly increasing: t[{i}] = {} ≥ t[{}] = {}",
            t[i],
            i + 1,
            t[i + 1]
        ));
    }
    if y.len() != m {
        return bad(format!("{} guess vectors for {m} mesh nodes", y.len()));
    }
    for (i, yi) in y.iter().enumerate() {
        if yi.len() != n {
            return bad(format!(
                "guess at node {i} has {} components, expected {n}",
                yi.len()
            ));
        }
        if !all_finite(yi) {
            return bad(format!(
                "guess at node {i} (t = {}) is not finite: {yi:?}",
                t[i]
            ));
        }
    }
    let check_scale = |name: &str, s: &Option<Vec<f64>>| -> Result<Vec<f64>, BvpError> {
        match s {
            None => Ok(vec![1.0; n]),
            Some(v) if v.len() == n && v.iter().all(|a| a.is_finite() && *a > 0.0) => Ok(v.clone()),
            Some(v) => Err(BvpError::InvalidInput(format!(
                "{name} must have {n} positive finite entries, got {v:?}"
            ))),
        }
    };
    let s = check_scale("scale", &opts.scale)?;
    let bs = check_scale("bc_scale", &opts.bc_scale)?;
    if !(opts.tol > 0.0) || !opts.tol.is_finite() {
        return bad(format!("tol must be positive, got {}", opts.tol));
    }
    let tol = opts.tol.max(100.0 * f64::EPSILON);
    let bc_tol = opts.bc_tol.unwrap_or(tol);
    if !(bc_tol > 0.0) {
        return bad(format!("bc_tol must be positive, got {bc_tol}"));
    }
    if opts.max_newton == 0 || opts.max_jacobians == 0 {
        return bad("max_newton and max_jacobians must be ≥ 1".into());
    }
    let mut yh = vec![0.0; m * n];
    for i in 0..m {
        for k in 0..n {
            yh[i * n + k] = y[i][k] / s[k];
        }
    }
    Ok(Prepared {
        ev: Eval {
            p: problem,
            n,
            s,
            bs,
            ya: vec![0.0; n],
            yb: vec![0.0; n],
            ja: vec![0.0; n * n],
            jb: vec![0.0; n * n],
            nfev: 0,
        },
        x: t.to_vec(),
        y: yh,
        tol,
        bc_tol,
    })
}

struct Counters {
    newton: usize,
    jac: usize,
    passes: usize,
}

fn build_solution<P: BvpProblem + ?Sized>(
    ev: &Eval<'_, P>,
    x: &[f64],
    y: &[f64],
    c: &Colloc,
    rms: Vec<f64>,
    k: &Counters,
) -> BvpSolution {
    let n = ev.n;
    let m = x.len();
    let unscale =
        |v: &[f64], i: usize| -> Vec<f64> { (0..n).map(|q| v[i * n + q] * ev.s[q]).collect() };
    BvpSolution {
        t: x.to_vec(),
        y: (0..m).map(|i| unscale(y, i)).collect(),
        yp: (0..m).map(|i| unscale(&c.f, i)).collect(),
        max_residual: rms.iter().cloned().fold(0.0, f64::max),
        rms_residuals: rms,
        bc_residual: c.bc.iter().fold(0.0f64, |a, r| a.max(r.abs())),
        newton_iterations: k.newton,
        jacobian_evaluations: k.jac,
        mesh_refinements: k.passes,
        rhs_evaluations: ev.nfev,
    }
}

/// Solves the BVP with residual control and mesh refinement (scipy's
/// `solve_bvp`): `t` is the initial mesh (strictly increasing, t[0] = a,
/// t[last] = b), `y[i]` the initial guess at `t[i]`.
pub fn solve_bvp<P: BvpProblem + ?Sized>(
    problem: &P,
    t: &[f64],
    y: &[Vec<f64>],
    opts: &BvpOptions,
) -> Result<BvpSolution, BvpError> {
    let Prepared {
        mut ev,
        mut x,
        mut y,
        tol,
        bc_tol,
    } = prepare(problem, t, y, opts)?;
    let n = ev.n;
    let mut k = Counters {
        newton: 0,
        jac: 0,
        passes: 0,
    };
    let mut work = JacWork::default();
    loop {
        let m = x.len();
        let mut c = Colloc::new(n, m);
        let nw = newton(
            &mut ev,
            &x,
            &mut y,
            &mut c,
            tol,
            bc_tol,
            opts.max_newton,
            opts.max_jacobians,
            &mut work,
        )?;
        k.newton += nw.iterations;
        k.jac += nw.jacobians;
        k.passes += 1;
        // `c` holds the collocation data of the final y.
        let rms = rms_residuals(&mut ev, &x, &y, &c)?;
        let max_res = rms.iter().cloned().fold(0.0, f64::max);
        if nw.singular {
            return Err(BvpError::SingularJacobian {
                nodes: m,
                iteration: k.passes,
                max_residual: max_res,
            });
        }
        let bc_res = c.bc.iter().fold(0.0f64, |a, r| a.max(r.abs()));
        let added: usize = rms
            .iter()
            .map(|&r| {
                if r >= 100.0 * tol {
                    2
                } else if r > tol {
                    1
                } else {
                    0
                }
            })
            .sum();
        if m + added > opts.max_nodes {
            let best = build_solution(&ev, &x, &y, &c, rms, &k);
            return Err(BvpError::MaxNodesExceeded {
                nodes: m,
                needed: m + added,
                max_nodes: opts.max_nodes,
                max_residual: max_res,
                tol,
                bc_residual: bc_res,
                best: Box::new(best),
            });
        }
        if added > 0 {
            // New mesh, initialized from the cubic.
            let mut nx = Vec::with_capacity(m + added);
            let mut ny = Vec::with_capacity((m + added) * n);
            let mut ys = vec![0.0; n];
            let mut dys = vec![0.0; n];
            for i in 0..m - 1 {
                nx.push(x[i]);
                ny.extend_from_slice(&y[i * n..(i + 1) * n]);
                let h = x[i + 1] - x[i];
                let fracs: &[f64] = if rms[i] >= 100.0 * tol {
                    &[1.0 / 3.0, 2.0 / 3.0]
                } else if rms[i] > tol {
                    &[0.5]
                } else {
                    &[]
                };
                for &s in fracs {
                    let xs = if s == 0.5 {
                        0.5 * (x[i] + x[i + 1])
                    } else if s < 0.5 {
                        (2.0 * x[i] + x[i + 1]) / 3.0
                    } else {
                        (x[i] + 2.0 * x[i + 1]) / 3.0
                    };
                    hermite(
                        (xs - x[i]) / h,
                        h,
                        &y[i * n..(i + 1) * n],
                        &c.f[i * n..(i + 1) * n],
                        &y[(i + 1) * n..(i + 2) * n],
                        &c.f[(i + 1) * n..(i + 2) * n],
                        &mut ys,
                        &mut dys,
                    );
                    nx.push(xs);
                    ny.extend_from_slice(&ys);
                }
            }
            nx.push(x[m - 1]);
            ny.extend_from_slice(&y[(m - 1) * n..]);
            x = nx;
            y = ny;
            continue;
        }
        if bc_res <= bc_tol {
            return Ok(build_solution(&ev, &x, &y, &c, rms, &k));
        }
        if k.passes >= opts.max_iterations {
            let best = build_solution(&ev, &x, &y, &c, rms, &k);
            return Err(BvpError::BcTolerance {
                iterations: k.passes,
                bc_residual: bc_res,
                bc_tol,
                max_residual: max_res,
                best: Box::new(best),
            });
        }
    }
}

/// Solves the collocation equations on the given mesh only (no residual
/// control, no refinement): repeated damped-Newton passes until the
/// collocation and boundary residuals meet `tol`/`bc_tol` (the Newton
/// criterion of [`solve_bvp`]). For convergence studies and continuation.
pub fn solve_collocation<P: BvpProblem + ?Sized>(
    problem: &P,
    t: &[f64],
    y: &[Vec<f64>],
    opts: &BvpOptions,
) -> Result<BvpSolution, BvpError> {
    let Prepared {
        mut ev,
        x,
        mut y,
        tol,
        bc_tol,
    } = prepare(problem, t, y, opts)?;
    let n = ev.n;
    let m = x.len();
    let mut k = Counters {
        newton: 0,
        jac: 0,
        passes: 0,
    };
    let mut work = JacWork::default();
    let mut c = Colloc::new(n, m);
    for _ in 0..opts.max_iterations.max(1) {
        let nw = newton(
            &mut ev,
            &x,
            &mut y,
            &mut c,
            tol,
            bc_tol,
            opts.max_newton,
            opts.max_jacobians,
            &mut work,
        )?;
        k.newton += nw.iterations;
        k.jac += nw.jacobians;
        k.passes += 1;
        if nw.singular {
            return Err(BvpError::SingularJacobian {
                nodes: m,
                iteration: k.passes,
                max_residual: f64::NAN,
            });
        }
        if nw.converged {
            let rms = rms_residuals(&mut ev, &x, &y, &c)?;
            return Ok(build_solution(&ev, &x, &y, &c, rms, &k));
        }
    }
    let rms = rms_residuals(&mut ev, &x, &y, &c)?;
    let best = build_solution(&ev, &x, &y, &c, rms, &k);
    Err(BvpError::NotConverged {
        nodes: m,
        collocation_residual: c.res.iter().fold(0.0f64, |a, r| a.max(r.abs())),
        bc_residual: best.bc_residual,
        best: Box::new(best),
    })
}

/// Largest entry-wise discrepancy between `problem.jacobian` at (t, y) and a
/// central finite difference, relative to max(1, |J|): a check for hand-written
/// Jacobians.
pub fn jacobian_discrepancy<P: BvpProblem + ?Sized>(problem: &P, t: f64, y: &[f64]) -> f64 {
    let n = problem.dim();
    let mut j = vec![0.0; n * n];
    problem.jacobian(t, y, &mut j);
    let mut yp = y.to_vec();
    let mut fp = vec![0.0; n];
    let mut fm = vec![0.0; n];
    let mut worst: f64 = 0.0;
    for c in 0..n {
        let h = f64::EPSILON.cbrt() * (1.0 + y[c].abs());
        yp[c] = y[c] + h;
        problem.rhs(t, &yp, &mut fp);
        yp[c] = y[c] - h;
        problem.rhs(t, &yp, &mut fm);
        yp[c] = y[c];
        for r in 0..n {
            let fd = (fp[r] - fm[r]) / (2.0 * h);
            let e = (fd - j[r * n + c]).abs() / j[r * n + c].abs().max(1.0);
            worst = worst.max(if e.is_nan() { f64::INFINITY } else { e });
        }
    }
    worst
}
