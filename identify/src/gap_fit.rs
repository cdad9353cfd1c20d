//! The gap model fitted to a reluctance table (z, R_gap[, R_gap']), as in
//! jiles-atherton-actuator-model [JA §5.1]: minimise [JA 76]
//! NRMSE²(R_gap) + NRMSE²(R_gap'), each normalised as [JA 77].
//!
//! Both analytic models have the form [JA 11], R_gap = r0 + r0'·z/D(z) with
//! D = 1 + k1·z·ln(k2/z) and [JA 13] R_gap' = r0'·(1 + k1·z)/D²:
//! `mclyman-fit` fits (r0, r0', k1, k2) directly; `mclyman` is [JA 11] with
//! r0 = 0, r0' = 1/(μ0·A), k1 = 1/√A, k2 = 2·l_w and fits (A, l_w). The
//! logarithm is regularised as the model's (`ln(k/(z + Z_EPS))`, see
//! `model/gap.rs`); its derivative is then (1 + k1·z)/D² up to terms of
//! order Z_EPS/z, and the exact derivative of the regularised form is used.
//!
//! Initial guesses come from the table: a least-squares line through the
//! points of smallest z gives r0 and r0' (where D ≈ 1); k1 and k2 start on a
//! small grid (the best start is kept).

use crate::description::Gap;
use crate::model::{MU0, Z_EPS};
use crate::record::{Record, RecordError};

use super::lm;

/// Which gap model to fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GapModel {
    /// r0, r0_prime, k1, k2
    McLymanFit,
    /// area, winding_length
    McLyman,
}

/// A reluctance table: strictly increasing z > 0 ... (z = 0 allowed).
#[derive(Debug, Clone, PartialEq)]
pub struct GapTable {
    pub z: Vec<f64>,
    pub r: Vec<f64>,
    pub r_prime: Option<Vec<f64>>,
    pub file_name: String,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GapFitError {
    #[error(transparent)]
    Record(#[from] RecordError),
    #[error("{file}:{line}: column `z`: expected a gap length >= 0, found {z:e}")]
    NegativeZ { file: String, line: usize, z: f64 },
    #[error("{file}: the reluctances are all zero: NRMSE (77) has no scale")]
    NoScale { file: String },
    #[error("{file}: the fit failed: {message}")]
    Solver { file: String, message: String },
}

/// The fitted gap and its errors [JA 77].
#[derive(Debug, Clone, PartialEq)]
pub struct GapFit {
    pub gap: Gap,
    /// (name, value) of the fitted parameters (TOML keys of `[gap]`).
    pub values: Vec<(String, f64)>,
    pub nrmse_r: f64,
    /// When the table has R_gap'.
    pub nrmse_r_prime: Option<f64>,
    pub iterations: usize,
}

impl GapTable {
    /// Columns `z`, `r`, optional `r_prime`; z strictly increasing, ≥ 0.
    pub fn from_record(record: &Record) -> Result<GapTable, GapFitError> {
        let zi = record.column_index("z")?;
        let z: Vec<f64> = record.rows.iter().map(|r| r[zi]).collect();
        let too_short = || RecordError::TooShort {
            file: record.file_name.clone(),
            needed: 4,
            found: z.len(),
        };
        if z.len() < 4 {
            return Err(too_short().into());
        }
        for k in 0..z.len() {
            if z[k] < 0.0 {
                return Err(GapFitError::NegativeZ {
                    file: record.file_name.clone(),
                    line: record.lines[k],
                    z: z[k],
                });
            }
            if k > 0 && z[k] <= z[k - 1] {
                return Err(RecordError::NotIncreasing {
                    file: record.file_name.clone(),
                    line: record.lines[k],
                    t: z[k],
                    previous: z[k - 1],
                }
                .into());
            }
        }
        let r_prime = record
            .column_index("r_prime")
            .ok()
            .map(|j| record.rows.iter().map(|r| r[j]).collect());
        Ok(GapTable {
            r: record.column("r")?,
            r_prime,
            z,
            file_name: record.file_name.clone(),
        })
    }
}

/// [JA 11] and [JA 13] with the regularised logarithm: (R_gap, R_gap').
pub fn reluctance_and_slope(theta: [f64; 4], z: f64) -> (f64, f64) {
    let [r0, r0p, k1, k2] = theta;
    let ze = z + Z_EPS;
    let log = (k2 / ze).ln();
    let den = 1.0 + k1 * z * log;
    // d/dz [k1·z·ln(k2/(z + ε))] = k1·(log − z/(z + ε))
    let dden = k1 * (log - z / ze);
    (r0 + r0p * z / den, r0p * (den - z * dden) / (den * den))
}

/// The [JA 11] parameters of a McLyman gap (A, l_w).
fn mclyman_theta(area: f64, winding_length: f64) -> [f64; 4] {
    [
        0.0,
        1.0 / (MU0 * area),
        1.0 / area.sqrt(),
        2.0 * winding_length,
    ]
}

/// √(Σ (sim − exp)²/Σ exp²), [JA 77].
fn nrmse(sim: &[f64], exp: &[f64]) -> f64 {
    let num: f64 = sim.iter().zip(exp).map(|(s, e)| (s - e).powi(2)).sum();
    let den: f64 = exp.iter().map(|e| e * e).sum();
    (num / den).sqrt()
}

/// Fits `model` to `table` by minimising [JA 76].
pub fn fit_gap(table: &GapTable, model: GapModel) -> Result<GapFit, GapFitError> {
    let norm_r = table.r.iter().map(|r| r * r).sum::<f64>().sqrt();
    if !(norm_r > 0.0) {
        return Err(GapFitError::NoScale {
            file: table.file_name.clone(),
        });
    }
    let norm_rp = table
        .r_prime
        .as_ref()
        .map(|rp| rp.iter().map(|r| r * r).sum::<f64>().sqrt())
        .filter(|n| *n > 0.0);
    let to_theta = |x: &[f64]| match model {
        GapModel::McLymanFit => [x[0], x[1], x[2], x[3]],
        GapModel::McLyman => mclyman_theta(x[0], x[1]),
    };
    // Residuals (R − R_exp)/‖R_exp‖ and (R' − R'_exp)/‖R'_exp‖: ‖r‖² is [JA 76].
    let residual = |x: &[f64]| {
        let theta = to_theta(x);
        let mut r = Vec::with_capacity(2 * table.z.len());
        let eval: Vec<(f64, f64)> = table
            .z
            .iter()
            .map(|&z| reluctance_and_slope(theta, z))
            .collect();
        r.extend(eval.iter().zip(&table.r).map(|(e, x)| (e.0 - x) / norm_r));
        if let (Some(rp), Some(n)) = (&table.r_prime, norm_rp) {
            r.extend(eval.iter().zip(rp).map(|(e, x)| (e.1 - x) / n));
        }
        r.iter().all(|v| v.is_finite()).then_some(r)
    };
    let (starts, bounds) = starts_and_bounds(table, model);
    let options = lm::Options {
        max_iterations: 200,
        ..lm::Options::default()
    };
    let mut best: Option<lm::Report> = None;
    let mut iterations = 0;
    for x0 in &starts {
        if let Ok(rep) = lm::minimize(residual, x0, &bounds, &options, &mut |_| {}) {
            iterations += rep.iterations;
            if best.as_ref().is_none_or(|b| rep.cost < b.cost) {
                best = Some(rep);
            }
        }
    }
    let best = best.ok_or_else(|| GapFitError::Solver {
        file: table.file_name.clone(),
        message: "no start point gave a finite reluctance on the table".into(),
    })?;
    let x = &best.theta;
    let theta = to_theta(x);
    let eval: Vec<(f64, f64)> = table
        .z
        .iter()
        .map(|&z| reluctance_and_slope(theta, z))
        .collect();
    let r_sim: Vec<f64> = eval.iter().map(|e| e.0).collect();
    let rp_sim: Vec<f64> = eval.iter().map(|e| e.1).collect();
    let (gap, names): (Gap, &[&str]) = match model {
        GapModel::McLymanFit => (
            Gap::McLymanFit {
                r0: x[0],
                r0_prime: x[1],
                k1: x[2],
                k2: x[3],
            },
            &["r0", "r0_prime", "k1", "k2"],
        ),
        GapModel::McLyman => (
            Gap::McLyman {
                area: x[0],
                winding_length: x[1],
            },
            &["area", "winding_length"],
        ),
    };
    Ok(GapFit {
        gap,
        values: names
            .iter()
            .map(|n| n.to_string())
            .zip(x.iter().copied())
            .collect(),
        nrmse_r: nrmse(&r_sim, &table.r),
        nrmse_r_prime: table.r_prime.as_ref().map(|rp| nrmse(&rp_sim, rp)),
        iterations,
    })
}

/// Start points and bounds, from a line through the smallest-z points.
fn starts_and_bounds(table: &GapTable, model: GapModel) -> (Vec<Vec<f64>>, Vec<(f64, f64)>) {
    let (r0, slope) = initial_line(table);
    let z_max = table.z.last().copied().unwrap_or(1e-3).max(1e-9);
    let slope = slope.abs().max(1e-300);
    match model {
        GapModel::McLymanFit => {
            let r_scale = table.r.iter().fold(0.0f64, |m, r| m.max(r.abs()));
            let bounds = vec![
                (0.0, 10.0 * r_scale.max(r0.abs())),
                (slope * 1e-3, slope * 1e3),
                (0.0, 1e3 / z_max),
                (z_max * 1.01, z_max * 1e4),
            ];
            let mut starts = vec![];
            for k1 in [0.1 / z_max, 1.0 / z_max] {
                for k2 in [3.0 * z_max, 30.0 * z_max] {
                    starts.push(vec![r0.max(0.0), slope, k1, k2]);
                }
            }
            (starts, bounds)
        }
        GapModel::McLyman => {
            // r0' = 1/(μ0·A) ⇒ A ≈ 1/(μ0·slope).
            let area = 1.0 / (MU0 * slope);
            let bounds = vec![(area * 1e-3, area * 1e3), (z_max * 0.51, z_max * 1e4)];
            let starts = [1.5, 15.0].iter().map(|f| vec![area, f * z_max]).collect();
            (starts, bounds)
        }
    }
}

/// Least-squares line R ≈ a + b·z through the first third of the table
/// (at least 2 points), where the fringing denominator is nearly 1.
fn initial_line(table: &GapTable) -> (f64, f64) {
    let m = (table.z.len() / 3).max(2);
    let (z, r) = (&table.z[..m], &table.r[..m]);
    let n = m as f64;
    let zm = z.iter().sum::<f64>() / n;
    let rm = r.iter().sum::<f64>() / n;
    let szz: f64 = z.iter().map(|z| (z - zm).powi(2)).sum();
    let szr: f64 = z.iter().zip(r).map(|(z, r)| (z - zm) * (r - rm)).sum();
    let b = if szz > 0.0 { szr / szz } else { 0.0 };
    (rm - b * zm, b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slope_is_the_derivative_of_the_reluctance() {
        let theta = [2.41e6, 7.94e10, 1350.0, 9.95e-3];
        for z in [1e-6, 1e-4, 5e-4, 9e-4] {
            let h = 1e-7 * z;
            let fd = (reluctance_and_slope(theta, z + h).0 - reluctance_and_slope(theta, z - h).0)
                / (2.0 * h);
            let (_, slope) = reluctance_and_slope(theta, z);
            assert!(
                (slope - fd).abs() < 1e-6 * slope.abs(),
                "z = {z}: {slope} vs {fd}"
            );
        }
        // [JA 14]: the limits at z → 0⁺.
        let (r, rp) = reluctance_and_slope(theta, 0.0);
        assert_eq!(r, theta[0]);
        assert!((rp - theta[1]).abs() < 1e-12 * theta[1]);
    }
}
