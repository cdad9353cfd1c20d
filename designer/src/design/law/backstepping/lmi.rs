//! Small semidefinite programs whose constraints are all 2×2 linear matrix
//! inequalities, written exactly as second-order cone programs and solved by
//! an interior-point method to 1e-10 (generic: nothing here knows about
//! actuators).
//!
//! A symmetric 2×2 matrix [[a, b], [b, c]] is positive semidefinite exactly
//! when a + c ≥ ‖(a − c, 2b)‖ (both eigenvalues ½(a + c ± ‖(a − c, 2b)‖) are
//! ≥ 0), a second-order cone of dimension 3. So an LMI M(x) = M₀ + Σ xᵢ·Mᵢ ⪰ 0
//! in 2×2 matrices is one cone constraint, and the program goes to
//! `clarabel`'s interior-point solver without its `sdp` feature, which would
//! bring a BLAS/LAPACK build into every firmware build that runs a design.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};

/// A symmetric 2×2 matrix as its entries [a, b, c] of [[a, b], [b, c]].
pub type Sym2 = [f64; 3];

/// M(x) = constant + Σ xᵢ·coefficients[i] ⪰ 0.
#[derive(Debug, Clone, PartialEq)]
pub struct Lmi2 {
    pub constant: Sym2,
    /// One matrix per variable.
    pub coefficients: Vec<Sym2>,
}

impl Lmi2 {
    /// M at `x`.
    pub fn at(&self, x: &[f64]) -> Sym2 {
        let mut m = self.constant;
        for (c, xi) in self.coefficients.iter().zip(x) {
            for (entry, ci) in m.iter_mut().zip(c) {
                *entry += xi * ci;
            }
        }
        m
    }
}

/// minimise cᵀx subject to LMIs and linear equalities aᵀx = b.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Sdp2 {
    pub objective: Vec<f64>,
    pub lmis: Vec<Lmi2>,
    pub equalities: Vec<(Vec<f64>, f64)>,
}

/// What the solver found.
#[derive(Debug, Clone, PartialEq)]
pub enum SdpOutcome {
    Optimal {
        x: Vec<f64>,
        objective: f64,
    },
    /// Certified infeasible (a dual certificate; "almost infeasible" is a
    /// failure, not a certificate).
    Infeasible,
    /// Anything else (unbounded, iteration limit, numerical trouble), named.
    Failed(String),
}

/// Relative and absolute gap and feasibility tolerances of the solve.
const TOLERANCE: f64 = 1e-10;

impl Sdp2 {
    /// Solves the program.
    pub fn solve(&self) -> SdpOutcome {
        let n = self.objective.len();
        // rows of A x + s = b: equalities (zero cone), then per LMI the cone
        // s = (a + c, a − c, 2b) = b₀ − A x
        let mut rows: Vec<Vec<f64>> = Vec::new();
        let mut rhs = Vec::new();
        for (a, b) in &self.equalities {
            rows.push(a.clone());
            rhs.push(*b);
        }
        for lmi in &self.lmis {
            let cone = |m: &Sym2| [m[0] + m[2], m[0] - m[2], 2.0 * m[1]];
            let constant = cone(&lmi.constant);
            for (k, value) in constant.iter().enumerate() {
                rows.push(
                    (0..n)
                        .map(|i| lmi.coefficients.get(i).map_or(0.0, |c| -cone(c)[k]))
                        .collect(),
                );
                rhs.push(*value);
            }
        }
        let mut cones: Vec<SupportedConeT<f64>> = Vec::new();
        if !self.equalities.is_empty() {
            cones.push(SupportedConeT::ZeroConeT(self.equalities.len()));
        }
        cones.extend(
            self.lmis
                .iter()
                .map(|_| SupportedConeT::SecondOrderConeT(3)),
        );
        let a = CscMatrix::from(&rows);
        let p = CscMatrix::zeros((n, n));
        let settings = match DefaultSettingsBuilder::default()
            .verbose(false)
            .tol_gap_abs(TOLERANCE)
            .tol_gap_rel(TOLERANCE)
            .tol_feas(TOLERANCE)
            .max_iter(200)
            .build()
        {
            Ok(s) => s,
            Err(e) => return SdpOutcome::Failed(format!("solver settings: {e}")),
        };
        let mut solver = match DefaultSolver::new(&p, &self.objective, &a, &rhs, &cones, settings) {
            Ok(s) => s,
            Err(e) => return SdpOutcome::Failed(format!("solver setup: {e:?}")),
        };
        solver.solve();
        match solver.solution.status {
            // an almost-solved program's solution is checked by its caller
            SolverStatus::Solved | SolverStatus::AlmostSolved => SdpOutcome::Optimal {
                objective: solver.solution.obj_val,
                x: solver.solution.x.clone(),
            },
            SolverStatus::PrimalInfeasible => SdpOutcome::Infeasible,
            other => SdpOutcome::Failed(format!("{other:?}")),
        }
    }
}

/// The eigenvalues of [[a, b], [b, c]], smaller first.
pub fn eigenvalues(m: Sym2) -> [f64; 2] {
    let [a, b, c] = m;
    let mean = 0.5 * (a + c);
    let radius = (0.25 * (a - c) * (a - c) + b * b).sqrt();
    [mean - radius, mean + radius]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_smallest_trace_above_a_matrix_is_that_matrix() {
        // min tr X s.t. X ⪰ M: X = M
        let m = [2.0, 0.5, 1.0];
        let sdp = Sdp2 {
            objective: vec![1.0, 0.0, 1.0],
            lmis: vec![Lmi2 {
                constant: [-m[0], -m[1], -m[2]],
                coefficients: vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            }],
            equalities: vec![],
        };
        let SdpOutcome::Optimal { x, objective } = sdp.solve() else {
            panic!("not solved");
        };
        assert!((objective - 3.0).abs() < 1e-7, "{objective}");
        // the minimiser is not unique in b alone; the trace is
        assert!(eigenvalues(sdp.lmis[0].at(&x))[0] > -1e-7);
    }

    #[test]
    fn contradictory_lmis_are_certified_infeasible() {
        // x ⪰ I and x ⪯ −I (x a scalar times I)
        let sdp = Sdp2 {
            objective: vec![1.0],
            lmis: vec![
                Lmi2 {
                    constant: [-1.0, 0.0, -1.0],
                    coefficients: vec![[1.0, 0.0, 1.0]],
                },
                Lmi2 {
                    constant: [-1.0, 0.0, -1.0],
                    coefficients: vec![[-1.0, 0.0, -1.0]],
                },
            ],
            equalities: vec![],
        };
        assert_eq!(sdp.solve(), SdpOutcome::Infeasible);
    }

    #[test]
    fn eigenvalues_of_a_rotation_invariant_pair() {
        let [lo, hi] = eigenvalues([2.0, 1.0, 2.0]);
        assert!((lo - 1.0).abs() < 1e-15 && (hi - 3.0).abs() < 1e-15);
    }
}
