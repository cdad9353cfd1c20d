//! The user's problem in scaled variables, and the checks of the inputs.
//!
//! States of very different magnitudes (metres ~1e-3, webers ~1e-5) make the
//! relative residual 1 + |f| meaningless for the small ones.
//! [`BvpOptions::scale`] gives a per-component scale s: the solver works in
//! ŷ = y/s (tolerances, residuals, Newton norms are in ŷ), and
//! [`BvpOptions::bc_scale`] divides the boundary residuals. Results are
//! returned unscaled.

use super::{BvpError, BvpOptions, BvpProblem};

/// The user's problem seen in scaled variables ŷ = y/s, boundary residuals
/// divided by `bc_scale`, with buffers and the count of f evaluations.
pub(super) struct Eval<'a, P: ?Sized> {
    p: &'a P,
    pub(super) n: usize,
    pub(super) s: Vec<f64>,
    bs: Vec<f64>,
    ya: Vec<f64>,
    yb: Vec<f64>,
    ja: Vec<f64>,
    jb: Vec<f64>,
    pub(super) nfev: usize,
}

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

impl<'a, P: BvpProblem + ?Sized> Eval<'a, P> {
    /// f̂(t, ŷ) = f(t, s∘ŷ)/s.
    pub(super) fn rhs(&mut self, t: f64, yh: &[f64], out: &mut [f64]) -> Result<(), BvpError> {
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
    pub(super) fn jac(&mut self, t: f64, yh: &[f64], out: &mut [f64]) -> Result<(), BvpError> {
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

    pub(super) fn bc(
        &mut self,
        ta: f64,
        yah: &[f64],
        ybh: &[f64],
        out: &mut [f64],
    ) -> Result<(), BvpError> {
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

    pub(super) fn bc_jac(
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

/// A validated start: the scaled problem, the mesh, the scaled guess (m·n,
/// node after node) and the effective tolerances.
pub(super) struct Prepared<'a, P: ?Sized> {
    pub(super) ev: Eval<'a, P>,
    pub(super) x: Vec<f64>,
    pub(super) y: Vec<f64>,
    pub(super) tol: f64,
    pub(super) bc_tol: f64,
}

/// Checks the mesh, the guess and the options, and scales the guess.
pub(super) fn prepare<'a, P: BvpProblem + ?Sized>(
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
