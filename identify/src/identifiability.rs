//! What the data can and cannot separate.
//!
//! **Sensitivity.** At the optimum, the Jacobian of the residuals with
//! respect to ln θ (relative sensitivities: each column times |θ_j|) is
//! decomposed by SVD. A right singular vector v_k with a small singular value
//! s_k is a combination of parameters the data hardly sees: moving all θ_j
//! by factors exp(t·v_kj) leaves the residuals unchanged to first order. It
//! is reported as weak when s_k < [`WEAK_RELATIVE`]·s_max, or when the
//! residual scale σ = ‖r‖/√(n − p) makes its standard error σ/s_k exceed
//! [`WEAK_STD`] (a combination known only to ±10 %).
//!
//! **Reduced model.** jiles-atherton-actuator-model [JA §4.1] shows that ten
//! parameters of the full electromagnetic model enter the electrical
//! behaviour only through seven auxiliary ones, [JA 55], [JA 57], [JA 60]:
//! k_e* = k_e/N², R*_g0 = (R_g0 + l_c/(μ0·A_c))/N², R'*_g0 = R'_g0/N²,
//! M*_sat = M_sat·l_c/N, b* = b·N·A_c, κ* = κ·N·A_c,
//! α* = (1 − α)·N²·A_c/l_c (with R, c, k_1, k_2 unchanged). Descriptions
//! with equal reduced parameters give equal currents and motions.

use std::fmt;

use nalgebra::DMatrix;

use crate::description::{Core, Description, Gap};
use crate::model::MU0;

/// A combination is weak below this fraction of the largest singular value.
pub const WEAK_RELATIVE: f64 = 1e-3;
/// A combination is weak when its relative standard error exceeds this.
pub const WEAK_STD: f64 = 0.1;

/// The identifiability report of a fit.
#[derive(Debug, Clone, PartialEq)]
pub struct Sensitivity {
    pub names: Vec<String>,
    /// Singular values of ∂r/∂ln θ, largest first.
    pub singular_values: Vec<f64>,
    /// Largest over smallest singular value (∞ when one is 0).
    pub condition: f64,
    /// The weak combinations: (name, component of the unit vector in ln θ),
    /// largest components first, negligible ones (< 0.05) left out.
    pub weak_directions: Vec<Vec<(String, f64)>>,
    /// Singular value of each weak direction, relative to the largest.
    pub weak_singular_values: Vec<f64>,
    /// Linearised standard error of ln θ_j (≈ relative standard error),
    /// from σ² = ‖r‖²/(n − p); 0 when the residuals are 0, ∞ when singular.
    pub relative_std_errors: Vec<f64>,
}

impl Sensitivity {
    /// From ∂r/∂θ (one column per parameter), θ and the residuals at θ.
    pub fn from_jacobian(
        names: &[String],
        jacobian: &DMatrix<f64>,
        theta: &[f64],
        residuals: &[f64],
    ) -> Sensitivity {
        let p = names.len();
        let mut scaled = jacobian.clone();
        for (j, t) in theta.iter().enumerate().take(p.min(scaled.ncols())) {
            let s = if *t != 0.0 { t.abs() } else { 1.0 };
            scaled.column_mut(j).scale_mut(s);
        }
        if scaled.nrows() < p {
            // Zero rows change nothing but give p singular values (and the
            // null space in Vᵀ) when there are fewer residuals than parameters.
            scaled = scaled.resize_vertically(p, 0.0);
        }
        let svd = scaled.svd(false, true);
        let mut order: Vec<usize> = (0..svd.singular_values.len()).collect();
        order.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
        let s: Vec<f64> = order.iter().map(|&k| svd.singular_values[k]).collect();
        let v_t = svd.v_t.unwrap_or_else(|| DMatrix::zeros(0, p));
        let s_max = s.first().copied().unwrap_or(0.0);
        let s_min = s.last().copied().unwrap_or(0.0);
        let n = residuals.len();
        let sigma = (residuals.iter().map(|r| r * r).sum::<f64>()
            / n.saturating_sub(p).max(1) as f64)
            .sqrt();
        let relative_std_errors = (0..p)
            .map(|j| {
                let var: f64 = order
                    .iter()
                    .map(|&k| {
                        let sk = svd.singular_values[k];
                        let v = v_t[(k, j)];
                        if v == 0.0 || sigma == 0.0 {
                            0.0
                        } else {
                            (sigma * v / sk).powi(2)
                        }
                    })
                    .sum();
                var.sqrt()
            })
            .collect();
        let mut weak_directions = Vec::new();
        let mut weak_singular_values = Vec::new();
        for (&k, &sk) in order.iter().zip(&s) {
            let weak = sk < WEAK_RELATIVE * s_max || (sigma > 0.0 && sigma / sk > WEAK_STD);
            if weak {
                weak_directions.push(direction(names, &v_t, k));
                weak_singular_values.push(if s_max > 0.0 { sk / s_max } else { 0.0 });
            }
        }
        Sensitivity {
            names: names.to_vec(),
            condition: if s_min > 0.0 {
                s_max / s_min
            } else {
                f64::INFINITY
            },
            singular_values: s,
            weak_directions,
            weak_singular_values,
            relative_std_errors,
        }
    }

    /// Whether every fitted combination is pinned down by the data.
    pub fn identifiable(&self) -> bool {
        self.weak_directions.is_empty()
    }
}

/// Row k of Vᵀ as (name, component), sign fixed so the largest is positive.
fn direction(names: &[String], v_t: &DMatrix<f64>, k: usize) -> Vec<(String, f64)> {
    let mut d: Vec<(String, f64)> = names
        .iter()
        .enumerate()
        .map(|(j, n)| (n.clone(), v_t[(k, j)]))
        .filter(|(_, c)| c.abs() >= 0.05)
        .collect();
    d.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
    if d.first().is_some_and(|(_, c)| *c < 0.0) {
        d.iter_mut().for_each(|(_, c)| *c = -*c);
    }
    d
}

impl fmt::Display for Sensitivity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "identifiability (SVD of the relative sensitivities ∂r/∂ln θ):"
        )?;
        let s_max = self.singular_values.first().copied().unwrap_or(0.0);
        let rel: Vec<String> = self
            .singular_values
            .iter()
            .map(|s| format!("{:.2e}", if s_max > 0.0 { s / s_max } else { 0.0 }))
            .collect();
        writeln!(f, "  singular values / largest: {}", rel.join(", "))?;
        writeln!(f, "  condition number: {:.3e}", self.condition)?;
        writeln!(f, "  relative standard errors:")?;
        for (name, e) in self.names.iter().zip(&self.relative_std_errors) {
            writeln!(f, "    {name:<28} {:.3} %", 100.0 * e)?;
        }
        if self.weak_directions.is_empty() {
            return writeln!(f, "  every fitted parameter is separated by the data");
        }
        writeln!(
            f,
            "  the data cannot separate these combinations (moving the parameters"
        )?;
        writeln!(f, "  by factors exp(t·c_j) leaves the fit unchanged):")?;
        for (dir, s) in self.weak_directions.iter().zip(&self.weak_singular_values) {
            let terms: Vec<String> = dir.iter().map(|(n, c)| format!("{c:+.3}·ln {n}")).collect();
            writeln!(
                f,
                "    {}   (singular value {s:.1e} of the largest)",
                terms.join(" ")
            )?;
        }
        Ok(())
    }
}

/// The reduced model's parameters [JA 55], [JA 57], [JA 60], plus those the
/// reduction keeps (R, c, k_1, k_2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReducedParameters {
    pub resistance: f64,
    /// [JA 55] k_e* = k_e/N²
    pub k_e: f64,
    /// [JA 57] R*_g0 = (R_g0 + l_c/(μ0·A_c))/N²
    pub r_g0: f64,
    /// [JA 57] R'*_g0 = R'_g0/N²
    pub r_g0_prime: f64,
    pub k1: f64,
    pub k2: f64,
    /// [JA 60] M*_sat = M_sat·l_c/N
    pub m_sat: f64,
    /// [JA 60] b* = b·N·A_c
    pub b: f64,
    pub c: f64,
    /// [JA 60] κ* = κ·N·A_c
    pub kappa: f64,
    /// [JA 60] α* = (1 − α)·N²·A_c/l_c
    pub alpha: f64,
}

/// The reduced parameters of a Jiles–Atherton description with an analytic
/// gap (`mclyman-fit`, `mclyman` or `linear`, all of the form [JA 11]); `None`
/// otherwise.
pub fn reduced_parameters(d: &Description) -> Option<ReducedParameters> {
    let Core::JilesAtherton(ja) = &d.core else {
        return None;
    };
    // [JA 11]: R_g = R_g0 + R'_g0·z/(1 + k1·z·ln(k2/z)).
    let (r0, r0_prime, k1, k2) = match d.gap {
        Gap::McLymanFit {
            r0,
            r0_prime,
            k1,
            k2,
        } => (r0, r0_prime, k1, k2),
        Gap::McLyman {
            area,
            winding_length,
        } => (
            0.0,
            1.0 / (MU0 * area),
            1.0 / area.sqrt(),
            2.0 * winding_length,
        ),
        Gap::Linear { slope, offset } => (offset, slope, 0.0, 1.0),
        Gap::Table { .. } => return None,
    };
    let n = d.coil.turns;
    let n2 = n * n;
    Some(ReducedParameters {
        resistance: d.coil.resistance,
        k_e: d.coil.eddy / n2,
        r_g0: (r0 + ja.length / (MU0 * ja.area)) / n2,
        r_g0_prime: r0_prime / n2,
        k1,
        k2,
        m_sat: ja.m_sat * ja.length / n,
        b: ja.b * n * ja.area,
        c: ja.c,
        kappa: ja.kappa * n * ja.area,
        alpha: (1.0 - ja.alpha) * n2 * ja.area / ja.length,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_exact_null_direction_is_reported() {
        // r = [θ0·θ1 − 2, θ0·θ1 − 2 + 1e-3·θ2]: only θ0·θ1 and θ2 are seen.
        let theta = [2.0, 0.5, 1.0];
        let jac = DMatrix::from_row_slice(2, 3, &[0.5, 2.0, 0.0, 0.5, 2.0, 1e-3]);
        let names: Vec<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
        let s = Sensitivity::from_jacobian(&names, &jac, &theta, &[0.0, 0.0]);
        assert_eq!(s.weak_directions.len(), 2, "{s}");
        // The exactly invisible combination: ln a − ln b (a·b fixed).
        let null = s
            .weak_directions
            .iter()
            .find(|d| d.len() == 2 && d.iter().all(|(n, _)| n != "c"))
            .unwrap();
        assert!(
            (null[0].1.abs() - 0.5f64.sqrt()).abs() < 1e-9 && null[0].1 * null[1].1 < 0.0,
            "{s}"
        );
        assert!(s.condition.is_infinite());
        assert!(s.to_string().contains("cannot separate"));
    }
}
