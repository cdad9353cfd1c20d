//! The probability-based energy-optimal reference: the stop is not exactly
//! at z_f (Moya-Lasheras, Ramirez-Laboreo, Sagues, *Probability-Based Optimal
//! Control Design for Soft Landing of Short-Stroke Actuators*, IEEE TCST
//! 28(5), 2020).
//!
//! The stop lies d ≥ 0 into the stroke from the nominal z_f, d half-normal of
//! scale σ (`[trajectory] contact_uncertainty`): ρ(d) = 2/(σ√(2π))·e^(−d²/2σ²).
//! A monotone motion meets the stop at d when it passes z_f + d, with the
//! speed it has there; over the stops, E[v_c²] = ∫ρ(d)·v(z_f + d)² dd =
//! ∫ρ(d(z(t)))·|v|³ dt, a running cost of the state alone. The cost is then
//!
//!   J = ∫u² dt + W·E[v_c²],  W = K·J₀/v̄²,
//!
//! J₀ the deterministic optimum's ∫u² dt and v̄ = stroke/(arc duration), so
//! K = [`CONTACT_WEIGHT`] says how much energy (in J₀) an expected squared
//! contact speed of v̄² is worth. The problem stays a two-point BVP: u* is
//! the deterministic one (the contact term does not depend on u), ṗ gains
//! −∂L_c/∂x and H gains L_c (`problem.rs`, derived symbolically). It is solved
//! on the deterministic optimum's arc by continuation in W from the
//! deterministic solution, each step warm-started from the last (a step that
//! fails is halved).
//!
//! Only the expected squared contact *speed* is weighed: the acceleration at
//! contact is zero on both designs at the nominal stop and follows the speed
//! elsewhere on these slow final approaches.

use super::problem::{ContactCost, HamiltonianSystem, OptimalError, OptimalSpec};
use super::search::{Arc, ArcSolver};
use crate::design::derive::linearization::Linearization;
use crate::design::trajectory::reference::Reference;
use crate::model::Model;

/// K: the weight of E[v_c²] in units of J₀/v̄² (module docs).
pub const CONTACT_WEIGHT: f64 = 100.0;
/// The continuation's first weight, relative to the final one.
const FIRST_STEP: f64 = 1e-3;
/// Steps of the continuation (geometric in W) before halving.
const STEPS: usize = 6;
/// Halvings of a failed step before giving up.
const HALVINGS: usize = 6;
/// Samples of a reference for its contact figures.
const SAMPLES: usize = 40_000;

/// The figures of a reference against the stop's distribution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactFigures {
    /// E[|v_c|] over the stops [m/s].
    pub expected_speed: f64,
    /// √E[v_c²] [m/s].
    pub rms_speed: f64,
    /// The largest |v| over the stops within 3σ (99.7 % of them) [m/s].
    pub worst_speed: f64,
    /// |v| where the reference first passes a stop σ, 2σ, 3σ in [m/s].
    pub speed_at: [f64; 3],
}

/// The probability-based design beside the deterministic one.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactDesign {
    /// σ [m].
    pub sigma: f64,
    /// W of the cost [V²·s³/m²] (A² with a current drive).
    pub weight: f64,
    /// ∫u² dt + W·E[v_c²] of the robust reference (the cost it minimises).
    pub cost: f64,
    /// The same cost of the deterministic reference.
    pub deterministic_cost: f64,
    /// ∫u² dt of the deterministic reference (J₀).
    pub deterministic_energy: f64,
    pub robust: ContactFigures,
    pub deterministic: ContactFigures,
    /// Steps of the continuation in W.
    pub steps: usize,
}

/// The density of the stop's distance d ≥ 0 into the stroke.
pub fn density(d: f64, sigma: f64) -> f64 {
    2.0 / (sigma * (2.0 * std::f64::consts::PI).sqrt()) * (-0.5 * (d / sigma).powi(2)).exp()
}

/// E[v_c], √E[v_c²], the worst and the speeds at σ, 2σ, 3σ of `r` (a motion
/// from z₀ to z_f on its motion interval) for a stop of scale σ, and
/// E[v_c²] itself (trapezoids on the motion, sampled uniformly in time).
pub fn contact_figures(r: &dyn Reference, z0: f64, zf: f64, sigma: f64) -> (ContactFigures, f64) {
    let (t0, tf) = r.motion();
    let inward = (z0 - zf).signum();
    let n = SAMPLES;
    // (t, d, v, ρv², ρ|v|³) of the previous sample
    let mut prev: Option<[f64; 5]> = None;
    let (mut e1, mut e2, mut worst) = (0.0, 0.0, 0.0f64);
    let mut speed_at = [f64::NAN; 3];
    for k in 0..=n {
        let t = t0 + (tf - t0) * k as f64 / n as f64;
        let f = r.at(t);
        let d = (f.z - zf) * inward;
        let rho = if d >= 0.0 { density(d, sigma) } else { 0.0 };
        let (g1, g2) = (rho * f.v * f.v, rho * f.v.abs().powi(3));
        if d <= 3.0 * sigma {
            worst = worst.max(f.v.abs());
        }
        if let Some([tp, dp, vp, p1, p2]) = prev {
            for (j, s) in speed_at.iter_mut().enumerate() {
                let level = (j + 1) as f64 * sigma;
                if s.is_nan() && dp > level && d <= level {
                    let w = (dp - level) / (dp - d);
                    *s = (vp + w * (f.v - vp)).abs();
                }
            }
            let h = t - tp;
            e1 += 0.5 * h * (p1 + g1);
            e2 += 0.5 * h * (p2 + g2);
        }
        prev = Some([t, d, f.v, g1, g2]);
    }
    let figures = ContactFigures {
        expected_speed: e1,
        rms_speed: e2.max(0.0).sqrt(),
        worst_speed: worst,
        speed_at: speed_at.map(|s| if s.is_nan() { 0.0 } else { s }),
    };
    (figures, e2)
}

/// The contact term of `spec` for a deterministic optimum of energy J₀ on an
/// arc of `duration`.
pub(super) fn contact_cost(spec: &OptimalSpec, j0: f64, duration: f64) -> ContactCost {
    let stroke = (spec.zf - spec.z0).abs();
    let mean_speed = stroke / duration;
    ContactCost {
        weight: CONTACT_WEIGHT * j0 / (mean_speed * mean_speed),
        sigma: spec.contact_uncertainty,
        z_stop: spec.zf,
    }
}

/// The robust arc on the deterministic arc's interval, by continuation in W
/// from `det` up to `target.weight`; the system of the last step with it.
pub(super) fn continuation(
    model: &mut Model,
    lin: &Linearization,
    base: &ArcSolver,
    det: &Arc,
    target: ContactCost,
) -> Result<(Arc, HamiltonianSystem, usize), OptimalError> {
    let spec = base.spec;
    let ratio = (1.0 / FIRST_STEP).powf(1.0 / (STEPS - 1) as f64);
    let mut weights: Vec<f64> = (0..STEPS)
        .map(|k| target.weight * FIRST_STEP * ratio.powi(k as i32))
        .collect();
    weights.reverse(); // popped from the end: smallest first
    let mut current = det.clone();
    let mut done = 0.0;
    let mut steps = 0;
    let mut halvings = 0;
    let mut last: Option<HamiltonianSystem> = None;
    while let Some(w) = weights.pop() {
        let cost = ContactCost {
            weight: w,
            ..target
        };
        let sys = HamiltonianSystem::derive_with(model, lin, spec.u_min, spec.u_max, Some(&cost))?;
        let solver = ArcSolver {
            sys: &sys,
            tapes: base.tapes,
            spec,
            x0: base.x0,
            xf: base.xf,
            scale: base.scale.clone(),
            max_nodes: base.max_nodes,
        };
        match solver.solve(current.a, current.b, Some(&current)) {
            Ok(arc) if solver.within_stroke(&arc) => {
                current = arc;
                done = w;
                steps += 1;
                last = Some(sys);
            }
            result => {
                halvings += 1;
                if halvings > HALVINGS {
                    let source = Box::new(match result {
                        Err(e) => e,
                        Ok(arc) => OptimalError::OutsideStroke {
                            z_range: arc.z_range,
                            duration: arc.b - arc.a,
                        },
                    });
                    return Err(OptimalError::Contact {
                        reached: done / target.weight,
                        sigma: target.sigma,
                        source,
                    });
                }
                weights.push(w);
                // the geometric midpoint between the last weight solved and w
                let mid = if done > 0.0 {
                    (done * w).sqrt()
                } else {
                    0.1 * w
                };
                weights.push(mid);
            }
        }
    }
    let sys = last.ok_or_else(|| {
        OptimalError::InvalidSpec("the continuation in the contact weight took no step".into())
    })?;
    Ok((current, sys, steps))
}
