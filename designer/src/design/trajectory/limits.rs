//! The limits of a device for one operation (`reldesign limits`): the
//! shortest motion the energy-optimal solver finds within the input bounds,
//! its peak current and flux, and the energy J against the motion time.
//!
//! - **Shortest motion.** The free arc [PT 58–66] between the rest states, its
//!   duration bisected to 0.5 %: an arc exists if the collocation converges
//!   with the arc inside the stroke [PT 57] and the flux positive ([PT 56], the
//!   linearizable region). Near the limit the polynomial guess leaves the
//!   domain of T⁻¹ before the optimal motion stops existing, so each shorter
//!   arc is warm-started from the last one found (continuation in τ).
//! - **J against t_f − t₀.** Free arcs from the shortest up, each warm-started
//!   from the last, while they stay inside the stroke and H < u_rest²
//!   (`optimal/search.rs`); beyond, the optimal motion is that arc followed
//!   by rest, and J grows by u_rest² per second.

use crate::model::Model;
use crate::sym::Tape;

use super::optimal::guess::GuessTapes;
use super::optimal::problem::{HamiltonianSystem, OptimalError, OptimalSpec, AUX_U};
use super::optimal::search::{Arc, ArcSolver, PROBE_MAX_NODES};
use super::reference::Polynomial;
use crate::design::derive::linearization::Linearization;

/// One point of the J(t_f − t₀) curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CostPoint {
    /// Motion time t_f − t₀ [s].
    pub duration: f64,
    /// J = ∫u² dt of the energy-optimal motion of that time.
    pub cost: f64,
    /// Whether that motion rests part of the time (the free arc is shorter).
    pub rests: bool,
}

/// The limits of one operation within one pair of input bounds.
#[derive(Debug, Clone, PartialEq)]
pub struct MotionLimits {
    pub z0: f64,
    pub zf: f64,
    pub bounds: (f64, f64),
    /// The shortest motion time found [s].
    pub shortest: f64,
    /// J of that fastest motion.
    pub fastest_cost: f64,
    /// max |i| and max φ along the fastest motion.
    pub peak_current: f64,
    pub peak_flux: f64,
    /// The motion time from which on rest is cheaper than moving slower
    /// (None: not reached within the curve).
    pub resting_from: Option<f64>,
    pub curve: Vec<CostPoint>,
}

/// Relative accuracy of the shortest motion time.
const SHORTEST_TOL: f64 = 5e-3;
/// Motion times tried for a first arc, × the start.
const FIRST: [f64; 10] = [1.0, 0.7, 1.5, 0.5, 2.5, 0.35, 4.0, 0.25, 8.0, 16.0];
/// Collocation tolerance of the solves that only decide existence.
const EXISTENCE_TOL: f64 = 1e-4;
/// Curve: durations from the shortest up by this factor, up to `CURVE_SPAN`×.
const CURVE_STEP: f64 = 1.15;
/// Collocation tolerance of the curve's arcs (J to ~1e-6 relative).
const CURVE_TOL: f64 = 1e-5;
const CURVE_SPAN: f64 = 5.0;

/// The limits of the motion z0 → zf within `bounds`; `start` is a motion
/// time to begin the search from (e.g. the description's t_f − t₀).
pub fn motion_limits(
    model: &mut Model,
    lin: &Linearization,
    z0: f64,
    zf: f64,
    bounds: (f64, f64),
    start: f64,
) -> Result<MotionLimits, OptimalError> {
    match Model::c2_twin(&model.description) {
        Some((mut twin, _)) => {
            let twin_lin = Linearization::derive(&mut twin)
                .map_err(|e| OptimalError::InvalidSpec(format!("the C² gap twin: {e}")))?;
            limits_on(&mut twin, &twin_lin, z0, zf, bounds, start)
        }
        None => limits_on(model, lin, z0, zf, bounds, start),
    }
}

fn limits_on(
    model: &mut Model,
    lin: &Linearization,
    z0: f64,
    zf: f64,
    bounds: (f64, f64),
    start: f64,
) -> Result<MotionLimits, OptimalError> {
    let sys = HamiltonianSystem::derive(model, lin, bounds.0, bounds.1)?;
    let tapes = GuessTapes::new(model, lin)?;
    let x0 = tapes.rest_state(z0, "initial")?;
    let xf = tapes.rest_state(zf, "final")?;
    let current = model.compile(&[model.current]);
    let t0 = 0.0;
    let spec = OptimalSpec::new(z0, zf, t0, start, bounds.0, bounds.1);
    let coarse = OptimalSpec {
        tol: EXISTENCE_TOL,
        ..spec.clone()
    };
    let scale_of = |d: f64| -> Option<Vec<f64>> {
        let poly = Polynomial {
            z0,
            zf,
            t0,
            tf: t0 + d,
        };
        let g = tapes
            .polynomial(&poly, spec.nodes, spec.costate_guess)
            .ok()?;
        Some(super::optimal::scales(
            &OptimalSpec {
                tf: t0 + d,
                ..spec.clone()
            },
            &g,
        ))
    };
    let solver_with = |spec, scale| ArcSolver {
        sys: &sys,
        tapes: &tapes,
        spec,
        x0,
        xf,
        scale,
        max_nodes: PROBE_MAX_NODES,
    };
    // a first arc, around `start`
    let first = FIRST.iter().map(|k| k * start).find_map(|d| {
        let solver = solver_with(&coarse, scale_of(d)?);
        admissible(&solver, t0, d, None).map(|arc| (d, arc, solver.scale))
    });
    let Some((d_first, arc_first, scale)) = first else {
        return Err(OptimalError::NoShortArc {
            total: FIRST[FIRST.len() - 1] * start,
        });
    };
    let existence = solver_with(&coarse, scale.clone());
    let (shortest, coarse_fastest) = shortest(&existence, t0, d_first, arc_first);
    let curve_spec = OptimalSpec {
        tol: CURVE_TOL,
        ..spec.clone()
    };
    let precise = solver_with(&curve_spec, scale);
    let fastest =
        admissible(&precise, t0, shortest, Some(&coarse_fastest)).unwrap_or(coarse_fastest);
    let rest_rate = [tapes.rest_input(x0, t0), tapes.rest_input(xf, t0)]
        .map(|u| u * u)
        .into_iter()
        .fold(f64::INFINITY, f64::min);
    let (curve, resting_from) = cost_curve(&precise, t0, shortest, &fastest, rest_rate);
    let (peak_current, peak_flux) = peaks(&fastest, &sys, &current);
    Ok(MotionLimits {
        z0,
        zf,
        bounds,
        shortest,
        fastest_cost: fastest.cost,
        peak_current,
        peak_flux,
        resting_from,
        curve,
    })
}

/// The arc of duration d if it converges inside the stroke with φ > 0.
fn admissible(solver: &ArcSolver, t0: f64, d: f64, warm: Option<&Arc>) -> Option<Arc> {
    let arc = solver.solve(t0, t0 + d, warm).ok()?;
    let positive_flux = arc.sol.y.iter().all(|y| y[2] > 0.0);
    (solver.within_stroke(&arc) && positive_flux).then_some(arc)
}

/// Bisection on the duration with continuation from the shortest arc found.
fn shortest(solver: &ArcSolver, t0: f64, d_ok: f64, arc_ok: Arc) -> (f64, Arc) {
    let (mut hi, mut best) = (d_ok, arc_ok);
    // shrink while arcs exist, then bisect the last step
    let mut lo = None;
    while lo.is_none() {
        let d = 0.8 * hi;
        match admissible(solver, t0, d, None).or_else(|| admissible(solver, t0, d, Some(&best))) {
            Some(arc) => (hi, best) = (d, arc),
            None => lo = Some(d),
        }
        if hi < 1e-6 {
            break;
        }
    }
    let mut lo = lo.unwrap_or(0.0);
    while hi - lo > SHORTEST_TOL * hi {
        let d = 0.5 * (lo + hi);
        match admissible(solver, t0, d, Some(&best)) {
            Some(arc) => (hi, best) = (d, arc),
            None => lo = d,
        }
    }
    (hi, best)
}

/// J from the shortest motion up: free arcs while they are optimal, then
/// the rest's linear growth.
fn cost_curve(
    solver: &ArcSolver,
    t0: f64,
    shortest: f64,
    fastest: &Arc,
    rest_rate: f64,
) -> (Vec<CostPoint>, Option<f64>) {
    let mut curve = vec![CostPoint {
        duration: shortest,
        cost: fastest.cost,
        rests: false,
    }];
    let mut last = fastest.clone();
    let mut resting_from = None;
    let mut d = shortest;
    while d < CURVE_SPAN * shortest {
        let next = d * CURVE_STEP;
        let found = match resting_from {
            Some(_) => None,
            None => next_arc(solver, t0, d, next, &last),
        };
        match found {
            Some(arc) if arc.hamiltonian[1] < rest_rate => {
                curve.push(CostPoint {
                    duration: next,
                    cost: arc.cost,
                    rests: false,
                });
                last = arc;
            }
            _ => {
                let from = *resting_from.get_or_insert(last.b - last.a);
                let cost = last.cost + rest_rate * (next - from);
                curve.push(CostPoint {
                    duration: next,
                    cost,
                    rests: true,
                });
            }
        }
        d = next;
    }
    (curve, resting_from)
}

/// The arc of duration `to`, from `last` (duration `from`): cold, then warm,
/// then through intermediate durations (continuation).
fn next_arc(solver: &ArcSolver, t0: f64, from: f64, to: f64, last: &Arc) -> Option<Arc> {
    if let Some(arc) = admissible(solver, t0, to, None) {
        return Some(arc);
    }
    let mut warm = last.clone();
    let steps = 4;
    for k in 1..=steps {
        let d = from + (to - from) * k as f64 / steps as f64;
        warm = admissible(solver, t0, d, Some(&warm))?;
    }
    Some(warm)
}

/// max |i| and max φ at the nodes of the arc.
fn peaks(arc: &Arc, sys: &HamiltonianSystem, current: &Tape) -> (f64, f64) {
    let mut scratch = current.scratch();
    let (mut i_max, mut phi_max) = (0.0f64, 0.0f64);
    for (&t, y) in arc.sol.t.iter().zip(&arc.sol.y) {
        let u = sys.aux_at(t, y)[AUX_U];
        let mut i = [0.0];
        current.eval(&[y[0], y[1], y[2], u, t], &mut scratch, &mut i);
        i_max = i_max.max(i[0].abs());
        phi_max = phi_max.max(y[2]);
    }
    (i_max, phi_max)
}
