//! The energy-optimal motion under the stroke limits: rest, move, rest.
//!
//! Pontryagin's two-point problem [PT 58–66] knows nothing of the stops, but
//! the motion must stay in [z_min, z_max] [PT 57]. For a slow motion the free
//! extremal wants to arrive early and hover at the stop (holding there costs
//! less than moving slowly): it leaves [z_min, z_max], or comes within the
//! regularisation length of the gap's logarithm, and Newton fails. The optimum
//! with the limits is then a free arc of duration τ* < t_f − t₀ followed by
//! rest at the end stop (or preceded by rest at the start, whichever end is
//! cheaper to hold): rest costs c = u_rest² per second (u_rest = α at rest).
//!
//! With Φ(τ) = J*(τ) + c·(t_f − t₀ − τ) and ∂J*/∂τ = H at the moving end (the
//! value function's time derivative, HJB), Φ′(τ) = H − c: the full motion is
//! optimal when H ≤ c at τ = t_f − t₀; otherwise τ* solves H(τ*) = c (the
//! Hamiltonian is continuous at the junction with the rest arc, where
//! H = u_rest²). τ* is bracketed by arcs that are too short (H < c) and arcs
//! that are too long (H > c, outside the stroke, or not found), and refined
//! by safeguarded regula falsi, each arc warm-started from the nearest one
//! found (continuation in τ).

use super::guess::GuessTapes;
use super::problem::{HamiltonianSystem, OptimalError, OptimalSpec, AUX_H, AUX_U};
use crate::design::trajectory::bvp::{solve_bvp, BvpOptions, BvpProblem, BvpSolution};
use crate::design::trajectory::reference::Polynomial;

/// The Hamiltonian BVP of one arc: rest states at both ends.
struct Problem<'a> {
    sys: &'a HamiltonianSystem,
    x0: [f64; 3],
    xf: [f64; 3],
}

impl BvpProblem for Problem<'_> {
    fn dim(&self) -> usize {
        6
    }

    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) {
        self.sys.rhs_at(t, y, dy);
    }

    fn jacobian(&self, t: f64, y: &[f64], j: &mut [f64]) {
        self.sys.jacobian_at(t, y, j);
    }

    fn bc(&self, ya: &[f64], yb: &[f64], r: &mut [f64]) {
        for k in 0..3 {
            r[k] = ya[k] - self.x0[k];
            r[3 + k] = yb[k] - self.xf[k];
        }
    }

    fn bc_jacobian(&self, _ya: &[f64], _yb: &[f64], ja: &mut [f64], jb: &mut [f64]) {
        ja.iter_mut().for_each(|v| *v = 0.0);
        jb.iter_mut().for_each(|v| *v = 0.0);
        for k in 0..3 {
            ja[k * 6 + k] = 1.0;
            jb[(3 + k) * 6 + k] = 1.0;
        }
    }
}

/// One converged free arc on [a, b].
#[derive(Debug, Clone)]
pub(crate) struct Arc {
    pub a: f64,
    pub b: f64,
    pub sol: BvpSolution,
    /// H at a and at b.
    pub hamiltonian: [f64; 2],
    /// min and max of z at the nodes.
    pub z_range: [f64; 2],
    /// ∫u*² dt by the trapezoid rule on the nodes (for stopping rules).
    pub cost: f64,
}

impl Arc {
    fn duration(&self) -> f64 {
        self.b - self.a
    }
}

/// Solves single arcs between the rest states.
pub(crate) struct ArcSolver<'a> {
    pub sys: &'a HamiltonianSystem,
    pub tapes: &'a GuessTapes,
    pub spec: &'a OptimalSpec,
    pub x0: [f64; 3],
    pub xf: [f64; 3],
    /// Per-component scale of [x; p] for the BVP solver.
    pub scale: Vec<f64>,
    /// Mesh cap of one arc.
    pub max_nodes: usize,
}

impl ArcSolver<'_> {
    /// The free arc on [a, b], from the polynomial guess or stretched from `warm`.
    pub fn solve(&self, a: f64, b: f64, warm: Option<&Arc>) -> Result<Arc, OptimalError> {
        let (t, y) = match warm {
            Some(w) => stretch(w, a, b),
            None => {
                let poly = Polynomial {
                    z0: self.spec.z0,
                    zf: self.spec.zf,
                    t0: a,
                    tf: b,
                };
                let g = self
                    .tapes
                    .polynomial(&poly, self.spec.nodes, self.spec.costate_guess)?;
                (g.t, g.y)
            }
        };
        let s = &self.scale;
        let opts = BvpOptions {
            tol: self.spec.tol,
            max_nodes: self.max_nodes,
            scale: Some(s.clone()),
            bc_scale: Some(vec![s[0], s[1], s[2], s[0], s[1], s[2]]),
            ..BvpOptions::default()
        };
        let problem = Problem {
            sys: self.sys,
            x0: self.x0,
            xf: self.xf,
        };
        let sol =
            solve_bvp(&problem, &t, &y, &opts).map_err(|source| OptimalError::Bvp { source })?;
        let h = |k: usize| self.sys.aux_at(sol.t[k], &sol.y[k])[AUX_H];
        let last = sol.t.len() - 1;
        // z at the nodes and on the interpolant between them
        let between = sol
            .t
            .windows(2)
            .flat_map(|w| [0.25, 0.5, 0.75].map(|s| sol.eval(w[0] + s * (w[1] - w[0]))[0]));
        let z = sol.y.iter().map(|y| y[0]).chain(between);
        let z_range = z.fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], z| {
            [lo.min(z), hi.max(z)]
        });
        let u2: Vec<f64> = (0..=last)
            .map(|k| self.sys.aux_at(sol.t[k], &sol.y[k])[AUX_U].powi(2))
            .collect();
        let cost = sol
            .t
            .windows(2)
            .zip(u2.windows(2))
            .map(|(t, u)| 0.5 * (t[1] - t[0]) * (u[0] + u[1]))
            .sum();
        Ok(Arc {
            a,
            b,
            hamiltonian: [h(0), h(last)],
            z_range,
            cost,
            sol,
        })
    }

    /// Whether the arc stays within the stroke (to 1e-10 of it, tighter
    /// than the feasibility check's 1e-9).
    pub fn within_stroke(&self, arc: &Arc) -> bool {
        self.within_stroke_by(arc, 1e-10)
    }

    /// Whether the arc stays within the stroke to `margin` of it.
    fn within_stroke_by(&self, arc: &Arc, margin: f64) -> bool {
        let (lo, hi) = (
            self.spec.z0.min(self.spec.zf),
            self.spec.z0.max(self.spec.zf),
        );
        let margin = margin * (hi - lo);
        arc.z_range[0] >= lo - margin && arc.z_range[1] <= hi + margin
    }
}

/// [x; p] of `w` on [a, b]: the mesh mapped affinely, velocities rescaled.
fn stretch(w: &Arc, a: f64, b: f64) -> (Vec<f64>, Vec<Vec<f64>>) {
    let k = (b - a) / w.duration();
    let t = w.sol.t.iter().map(|&t| a + (t - w.a) * k).collect();
    let y = w
        .sol
        .y
        .iter()
        .map(|y| {
            let mut y = y.clone();
            y[1] /= k;
            y
        })
        .collect();
    (t, y)
}

/// The chosen motion: the free arc and where the rest goes.
#[derive(Debug, Clone)]
pub(crate) struct Plan {
    pub arc: Arc,
    /// Φ′ = H − c at the arc's moving end (≤ 0 up to the search tolerance;
    /// negative with the full duration: more time would not help).
    pub slope: f64,
}

/// Where the motion rests when it is shorter than the interval.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Rest {
    /// true: rest after the arc at z_f; false: before it at z₀.
    pub at_end: bool,
    /// c = u_rest² of that end [V²] (or A²).
    pub rate: f64,
}

/// An arc tried at one duration.
enum Probe {
    /// Within the stroke with H ≤ c: the optimum is this long or longer.
    Short(Arc),
    /// Within the stroke with H > c: the optimum is shorter.
    Long(Arc),
    /// Outside the stroke or not found: treated as too long.
    Failed(OptimalError),
}

/// Mesh cap of a search's probes: converged arcs of the test grid need
/// < 1 000 nodes at the search tolerance; a Newton that diverges keeps
/// refining up to the cap, which bounds the cost of a failed probe.
pub(crate) const PROBE_MAX_NODES: usize = 4000;
/// Collocation tolerance of the search's probes; the chosen arc is then
/// solved again at the design's tolerance (`polish`).
pub(crate) const SEARCH_TOL: f64 = 1e-4;
/// Relative width of the final bracket on τ.
const TAU_TOL: f64 = 1e-9;
/// Bound on the J still to gain by refining τ, relative to J.
const GAIN_TOL: f64 = 1e-8;
/// Durations tried below t_f − t₀ when the full motion fails: (0.85)^k.
const SHRINK: f64 = 0.85;
const SHRINK_STEPS: i32 = 14;
const MAX_REFINE: usize = 60;

impl ArcSolver<'_> {
    fn span(&self, rest: Rest, tau: f64) -> (f64, f64) {
        if rest.at_end {
            (self.spec.t0, self.spec.t0 + tau)
        } else {
            (self.spec.tf - tau, self.spec.tf)
        }
    }

    pub(crate) fn slope(arc: &Arc, rest: Rest) -> f64 {
        let h = if rest.at_end {
            arc.hamiltonian[1]
        } else {
            arc.hamiltonian[0]
        };
        h - rest.rate
    }

    fn probe(&self, rest: Rest, tau: f64, warm: Option<&Arc>) -> Probe {
        let (a, b) = self.span(rest, tau);
        let r = self.solve(a, b, warm);
        match r {
            Ok(arc) if !self.within_stroke(&arc) => Probe::Failed(OptimalError::OutsideStroke {
                z_range: arc.z_range,
                duration: tau,
            }),
            Ok(arc) if Self::slope(&arc, rest) <= 0.0 => Probe::Short(arc),
            Ok(arc) => Probe::Long(arc),
            Err(e) => Probe::Failed(e),
        }
    }

    /// The optimal duration and its arc (module docs): the whole interval by
    /// `precise`; if that is not optimal, the search by `self` (coarser), and
    /// the arc found solved again by `precise`.
    pub fn plan(&self, rest: Rest, precise: &ArcSolver) -> Result<Plan, OptimalError> {
        let total = self.spec.tf - self.spec.t0;
        let first = match precise.probe(rest, total, None) {
            Probe::Short(arc) => return Ok(self.finish(arc, rest)),
            // the polynomial of the whole interval leaves the domain of T⁻¹:
            // a shorter one would need more acceleration still
            Probe::Failed(e @ OptimalError::Guess { .. }) => return Err(e),
            other => other,
        };
        let mut hi: (f64, Option<Arc>) = (total, long_arc(first_arc(&first)));
        let first_error = match first {
            Probe::Failed(e) => Some(e),
            _ => None,
        };
        let mut lo: Option<(f64, Arc)> = None;
        let mut warm: Option<Arc> = hi.1.clone();
        for k in 1..=SHRINK_STEPS {
            let tau = total * SHRINK.powi(k);
            let mut probe = self.probe(rest, tau, None);
            let solver_failed = matches!(&probe, Probe::Failed(e) if !matches!(e, OptimalError::OutsideStroke { .. }));
            if let (true, Some(w)) = (solver_failed, warm.as_ref()) {
                probe = self.probe(rest, tau, Some(w));
            }
            if let Probe::Failed(OptimalError::Guess { .. }) = probe {
                break;
            }
            match probe {
                Probe::Short(arc) => {
                    lo = Some((tau, arc));
                    break;
                }
                Probe::Long(arc) => {
                    warm = Some(arc.clone());
                    hi = (tau, Some(arc));
                }
                Probe::Failed(_) => hi = (tau, None),
            }
        }
        let Some(mut lo) = lo else {
            return Err(first_error.unwrap_or(OptimalError::NoShortArc { total }));
        };
        self.refine(rest, &mut lo, &mut hi, total);
        let (a, b) = (lo.1.a, lo.1.b);
        // from the polynomial guess first (as an independent solver would),
        // from the search's arc where that fails
        // (to the feasibility check's slack, 1e-9 of the stroke)
        let arc = match precise.solve(a, b, None) {
            Ok(arc) if precise.within_stroke_by(&arc, 1e-9) => arc,
            _ => precise.solve(a, b, Some(&lo.1))?,
        };
        if !precise.within_stroke_by(&arc, 1e-9) {
            return Err(OptimalError::OutsideStroke {
                z_range: arc.z_range,
                duration: b - a,
            });
        }
        Ok(self.finish(arc, rest))
    }

    /// Narrows [lo, hi] around H(τ) = c; keeps the short end's arc. Regula
    /// falsi between two found arcs, bisection when the long end was not found
    /// or the same end moved twice (so neither end stalls).
    fn refine(&self, rest: Rest, lo: &mut (f64, Arc), hi: &mut (f64, Option<Arc>), total: f64) {
        let mut tried_full = false;
        let mut last_moved_lo: Option<bool> = None;
        let mut repeated = false;
        for _ in 0..MAX_REFINE {
            let width = hi.0 - lo.0;
            let s_lo = Self::slope(&lo.1, rest);
            // Φ(lo) − Φ(τ*) ≲ |Φ′(lo)|·width: stop when that is negligible
            // against J (far below the 1e-6 the oracles hold J to)
            let gain_bound = s_lo.abs() * width;
            if width <= TAU_TOL * total || gain_bound <= GAIN_TOL * lo.1.cost {
                break;
            }
            let tau = match &hi.1 {
                // a failed full duration is retried once, warm from below
                None if !tried_full && hi.0 == total => {
                    tried_full = true;
                    hi.0
                }
                Some(arc) if !repeated => {
                    let s_hi = Self::slope(arc, rest);
                    let x = lo.0 + width * s_lo / (s_lo - s_hi);
                    x.clamp(lo.0 + 1e-3 * width, hi.0 - 1e-3 * width)
                }
                _ => 0.5 * (lo.0 + hi.0),
            };
            // the polynomial guess is cheaper where it converges; the
            // continuation from the short end where it does not
            let probe = match self.probe(rest, tau, None) {
                Probe::Failed(OptimalError::OutsideStroke { .. }) => {
                    Probe::Failed(OptimalError::NoShortArc { total: tau })
                }
                Probe::Failed(_) => self.probe(rest, tau, Some(&lo.1)),
                found => found,
            };
            let moved_lo = match probe {
                Probe::Short(arc) => {
                    *lo = (tau, arc);
                    true
                }
                Probe::Long(arc) => {
                    *hi = (tau, Some(arc));
                    false
                }
                Probe::Failed(_) => {
                    *hi = (tau, None);
                    false
                }
            };
            repeated = last_moved_lo == Some(moved_lo);
            last_moved_lo = Some(moved_lo);
        }
    }

    fn finish(&self, arc: Arc, rest: Rest) -> Plan {
        Plan {
            slope: Self::slope(&arc, rest),
            arc,
        }
    }
}

fn first_arc(p: &Probe) -> Option<&Arc> {
    match p {
        Probe::Short(a) | Probe::Long(a) => Some(a),
        Probe::Failed(_) => None,
    }
}

fn long_arc(a: Option<&Arc>) -> Option<Arc> {
    a.cloned()
}
