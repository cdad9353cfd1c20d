//! A fringing fit that ends on a bound of the gap's range, tried again with
//! the flux as a guide.
//!
//! The ranking fits the current alone (a drifting resistance would corrupt
//! the flux integrated from v − R·i). On the current alone McLyman's gap has
//! a second basin: the winding length on its lower bound and the area
//! several times the truth's, the core's reluctance standing in for the gap
//! (6.4–7.3 % wNRMSE left where the truth leaves the noise, 0.19 %; blind
//! class 2, unseen seed 246). The flux, [JA 80]'s second term, ties φ to
//! i through the reluctance itself and leads the same start to the truth.
//! So where the fit ends with a gap parameter on a bound and leaves the
//! record beyond the noise (within it, the lower bound of the winding
//! length is fringing's null, a record without fringing), the candidate's
//! starts are fitted with the flux term, and the current alone is fitted
//! again from the best of them; the better current fit is kept (the same
//! weights, the candidate's start's). A fit whose bound is real keeps its
//! answer, at the cost of the retry.

use super::candidate::{on_bound, Candidate};
use super::Cause;
use crate::{fit, FitOptions, FitParam, FitReport, Measured};

/// Whether `c`'s fit `report` is in fringing's second basin: a gap
/// parameter on a bound of its range (as the report's "on the bound of its
/// range") and the record left beyond `beyond_the_floor` (within it, the
/// bound is fringing's null).
pub(super) fn in_second_basin(c: &Candidate, report: &FitReport, beyond_the_floor: f64) -> bool {
    c.cause == Cause::Fringing
        && gap_on_a_bound(&c.params, &report.values)
        && report.wnrmse_current > beyond_the_floor
}

/// Whether a gap parameter of the fitted `values` (of `params`, in their
/// order) ended on a bound of its range.
fn gap_on_a_bound(params: &[FitParam], values: &[(String, f64)]) -> bool {
    (params.iter().zip(values))
        .filter(|(p, _)| p.path.starts_with("gap."))
        .any(|(p, (_, v))| on_bound(*v, p))
}

/// `report`, or the current fit continued from the flux-guided fit of the
/// candidate's starts where that leaves less (ranking `options`).
pub(super) fn retried(
    c: &Candidate,
    report: FitReport,
    data: &Measured,
    options: &FitOptions,
) -> FitReport {
    // (no give-up: the waves' bar is a current-only cost, and this fit's
    // cost counts the flux as well)
    let guided = FitOptions {
        use_flux: true,
        only_start: None,
        give_up: None,
        ..options.clone()
    };
    let Ok(guide) = fit(&c.start, data, &c.params, &guided, &|_| {}) else {
        return report;
    };
    let theta: Vec<f64> = guide.values.iter().map(|(_, v)| *v).collect();
    // (the start's weights: the continuation is the candidate's own fit
    // from one more starting point)
    let continued = FitOptions {
        starts: 2,
        also_from: vec![theta],
        only_start: Some(1),
        ..options.clone()
    };
    match fit(&c.start, data, &c.params, &continued, &|_| {}) {
        Ok(mut r) if r.cost < report.cost => {
            r.iterations += report.iterations + guide.iterations;
            r.simulations += report.simulations + guide.simulations;
            r
        }
        _ => report,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn param(path: &str, lower: f64, upper: f64) -> FitParam {
        FitParam {
            path: path.into(),
            lower,
            upper,
        }
    }

    fn values(v: &[(&str, f64)]) -> Vec<(String, f64)> {
        v.iter().map(|(p, x)| (p.to_string(), *x)).collect()
    }

    #[test]
    fn a_gap_parameter_on_either_bound_counts_and_others_do_not() {
        let params = [
            param("coil.resistance", 10.0, 1000.0),
            param("gap.area", 1e-6, 1e-3),
            param("gap.winding_length", 3.45e-4, 1.0),
        ];
        let inside = values(&[
            ("coil.resistance", 126.0),
            ("gap.area", 5e-5),
            ("gap.winding_length", 0.055),
        ]);
        assert!(!gap_on_a_bound(&params, &inside));
        let lower = values(&[
            ("coil.resistance", 126.0),
            ("gap.area", 1.9e-4),
            ("gap.winding_length", 3.45e-4),
        ]);
        assert!(gap_on_a_bound(&params, &lower));
        let upper = values(&[
            ("coil.resistance", 126.0),
            ("gap.area", 1e-3),
            ("gap.winding_length", 0.05),
        ]);
        assert!(gap_on_a_bound(&params, &upper));
        // (the resistance on its bound is not the gap's second basin)
        let resistance = values(&[
            ("coil.resistance", 10.0),
            ("gap.area", 5e-5),
            ("gap.winding_length", 0.055),
        ]);
        assert!(!gap_on_a_bound(&params, &resistance));
    }
}
