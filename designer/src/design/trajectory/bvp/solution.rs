//! The solution of the solvers: the mesh, the nodal values and derivatives,
//! and the C¹ cubic Hermite interpolant through them (the collocation
//! polynomial), with the solver's counters.

use std::fmt;

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

/// The cubic Hermite interpolant on one interval of width `h` at the local
/// coordinate s ∈ [0, 1]: y = S and dy = S′ from the end values and slopes.
#[allow(clippy::too_many_arguments)]
pub(super) fn hermite(
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
