//! The drivers: [`solve_bvp`] (Newton on a mesh refined until the residuals
//! meet the tolerances) and [`solve_collocation`] (Newton on a fixed mesh).

use super::collocation::Colloc;
use super::jacobian::JacWork;
use super::mesh::{nodes_added, refine, rms_residuals};
use super::newton::{newton, NewtonOut};
use super::scaled::{prepare, Eval, Prepared};
use super::{BvpError, BvpOptions, BvpProblem, BvpSolution};

/// Work over all meshes.
#[derive(Default)]
struct Counters {
    newton: usize,
    jac: usize,
    passes: usize,
}

impl Counters {
    /// One Newton pass on the mesh `x` (see [`newton`]), counted.
    #[allow(clippy::too_many_arguments)]
    fn pass<P: BvpProblem + ?Sized>(
        &mut self,
        ev: &mut Eval<'_, P>,
        x: &[f64],
        y: &mut Vec<f64>,
        c: &mut Colloc,
        (tol, bc_tol): (f64, f64),
        opts: &BvpOptions,
        work: &mut JacWork,
    ) -> Result<NewtonOut, BvpError> {
        let nw = newton(
            ev,
            x,
            y,
            c,
            tol,
            bc_tol,
            opts.max_newton,
            opts.max_jacobians,
            work,
        )?;
        self.newton += nw.iterations;
        self.jac += nw.jacobians;
        self.passes += 1;
        Ok(nw)
    }
}

/// The solution of the (scaled) iterate `y`, unscaled.
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
    let mut k = Counters::default();
    let mut work = JacWork::default();
    loop {
        let m = x.len();
        let mut c = Colloc::new(n, m);
        let nw = k.pass(&mut ev, &x, &mut y, &mut c, (tol, bc_tol), opts, &mut work)?;
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
        let added = nodes_added(&rms, tol);
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
            (x, y) = refine(&x, &y, &c, &rms, tol, n);
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
    let mut k = Counters::default();
    let mut work = JacWork::default();
    let mut c = Colloc::new(n, m);
    for _ in 0..opts.max_iterations.max(1) {
        let nw = k.pass(&mut ev, &x, &mut y, &mut c, (tol, bc_tol), opts, &mut work)?;
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
