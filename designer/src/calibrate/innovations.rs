//! The prediction-error update: θ chosen to make the observer's own
//! one-step-ahead current predictions right, i.e. to minimise Σ νₖ², νₖ the
//! UKF's innovations over a run's measured voltage and current with the
//! model at θ. Unlike the open-loop replay (`reldesign_runtime::calibrate`),
//! whose lift-off from the pre-movement's force balance makes the error a
//! narrow valley in θ, the filter keeps its state near the valve's, so the
//! error is smooth and its minimum wide.
//!
//! A designer-side study: the Jacobian by forward differences (one filter
//! pass per parameter), bounded Levenberg–Marquardt steps in relative
//! coordinates, the same bounds as the runtime's update.

use crate::closed_loop::Measured;
use crate::description::params;
use crate::design::{design_kalman, Design};
use crate::model::Model;
use crate::observe::ukf::Ukf;

use super::Adapted;

/// The innovations of a UKF on `design`'s model at `values` over `measured`.
pub fn innovations(
    design: &Design,
    values: &[(&str, f64)],
    measured: &[Measured],
) -> Result<Vec<f64>, String> {
    let mut d = design.description.clone();
    for (key, value) in values {
        params::set(&mut d, key, *value).map_err(|e| e.to_string())?;
    }
    let model = Model::build(&d);
    let kalman = design_kalman(&d, &model)
        .map_err(|e| e.to_string())?
        .ok_or("the design has no Kalman filter")?;
    let mut ukf = Ukf::new(&kalman);
    Ok(measured
        .iter()
        .map(|m| {
            ukf.step(m.voltage, m.current);
            ukf.innovation().0
        })
        .collect())
}

/// What one update did: the RMS innovation before and after [A].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Update {
    pub before: f64,
    pub after: f64,
    pub accepted: bool,
}

/// Up to `iterations` bounded Levenberg–Marquardt steps on Σ νₖ² from
/// `theta` (the values of `adapted`, in order); θ changes only on a lower
/// error. Each run's update stands on its own data: carrying the earlier
/// runs' information as a prior (recursive least squares, forgetting 0.7)
/// was tried and kept the first, worst-linearised run's directions from
/// moving (three hand-made plants: no plant got softer).
pub fn update(
    design: &Design,
    adapted: &[Adapted],
    theta: &mut [f64],
    measured: &[Measured],
    max_step: f64,
    iterations: usize,
) -> Result<Update, String> {
    let keys: Vec<&str> = adapted.iter().map(|a| a.key).collect();
    let at = |t: &[f64]| -> Result<Vec<f64>, String> {
        let values: Vec<(&str, f64)> = keys.iter().copied().zip(t.iter().copied()).collect();
        innovations(design, &values, measured)
    };
    let cost = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>() / r.len().max(1) as f64;
    let mut r = at(theta)?;
    let before = cost(&r).sqrt();
    let mut damping = 1e-3;
    let mut accepted = false;
    for _ in 0..iterations {
        let jacobian = forward_differences(&at, theta, &r, adapted)?;
        let mut stepped = false;
        for _ in 0..5 {
            let Some(step) = lm_step(&jacobian, &r, damping) else {
                break;
            };
            let trial: Vec<f64> = theta
                .iter()
                .zip(&step)
                .zip(adapted)
                .map(|((t, s), a)| {
                    (t + s.clamp(-max_step, max_step) * a.nominal.abs()).clamp(a.lower, a.upper)
                })
                .collect();
            let rt = at(&trial)?;
            if cost(&rt) < cost(&r) {
                theta.copy_from_slice(&trial);
                r = rt;
                damping /= 4.0;
                stepped = true;
                accepted = true;
                break;
            }
            damping *= 8.0;
        }
        if !stepped {
            break;
        }
    }
    Ok(Update {
        before,
        after: cost(&r).sqrt(),
        accepted,
    })
}

/// JᵀJ (J by columns).
fn normal_matrix(columns: &[Vec<f64>]) -> Vec<Vec<f64>> {
    columns
        .iter()
        .map(|a| {
            columns
                .iter()
                .map(|b| a.iter().zip(b).map(|(x, y)| x * y).sum())
                .collect()
        })
        .collect()
}

/// ∂νₖ/∂δⱼ (δ relative to the design's values) by forward differences.
fn forward_differences(
    at: &dyn Fn(&[f64]) -> Result<Vec<f64>, String>,
    theta: &[f64],
    r: &[f64],
    adapted: &[Adapted],
) -> Result<Vec<Vec<f64>>, String> {
    let mut columns = Vec::with_capacity(theta.len());
    for (j, a) in adapted.iter().enumerate() {
        let h = 1e-4 * a.nominal.abs();
        let mut t = theta.to_vec();
        t[j] += h;
        let rj = at(&t)?;
        columns.push(
            rj.iter()
                .zip(r)
                .map(|(p, q)| (p - q) / h * a.nominal.abs())
                .collect(),
        );
    }
    Ok(columns)
}

/// (JᵀJ + μ·diag JᵀJ)·δ = −Jᵀr (J by columns).
fn lm_step(columns: &[Vec<f64>], r: &[f64], damping: f64) -> Option<Vec<f64>> {
    let p = columns.len();
    let mut a = normal_matrix(columns);
    let b: Vec<f64> = columns
        .iter()
        .map(|c| -c.iter().zip(r).map(|(x, y)| x * y).sum::<f64>())
        .collect();
    let floor = 1e-6 * (0..p).map(|i| a[i][i]).fold(0.0, f64::max);
    for (i, row) in a.iter_mut().enumerate() {
        row[i] = row[i] * (1.0 + damping) + floor;
    }
    super::choice::solve(&a, &b)
}
