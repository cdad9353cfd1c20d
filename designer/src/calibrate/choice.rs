//! Which parameters the calibration adapts: the identifiability of the
//! planned operations, not a hand-picked list.
//!
//! The design's own closed loop is run once without noise; each
//! operation's record is replayed by the runtime's calibration
//! (`reldesign_runtime::calibrate::replay`) with every candidate parameter
//! free, which gives the Fisher information F = JᵀJ/σ_i² of the coil
//! current in relative coordinates (J's column j is ∂i/∂θ_j·θ_j). The
//! parameters are then taken greedily by the information no parameter
//! chosen before explains (the Schur complement of F on the chosen set), and
//! one is kept only where every chosen parameter's relative standard error
//! from one run, √(F⁻¹)_jj, stays within [`MAX_RELATIVE_ERROR`] and at least
//! [`MIN_NEW_INFORMATION`] of its information is new: a parameter the
//! current cannot tell apart from the chosen ones (or barely sees) is left
//! at its design value, with the reason in the report.

use reldesign_runtime::calibrate::{replay, Settings};

use crate::closed_loop::{run_spaced_loop, Noise};
use crate::description::{params, Core, Description};
use crate::design::Design;
use crate::sim::Options;

use super::{Adapted, CalibrationDesign, Method, TapePredictor};

/// A parameter is adapted only where one run tells it to 2 % (1 σ) …
pub const MAX_RELATIVE_ERROR: f64 = 0.02;

/// … and where at least a tenth of what the current says of it is new, not
/// explained by the parameters chosen before: a direction nearly collinear
/// with them is told only through the operations' most sensitive instants
/// (the lift-off from a force balance, [PT §4]), where the replay of a
/// mismatched model is least like the valve (measured on the generated
/// plants of `tests/tests/self_calibration.rs`: adapting such parameters
/// too left the landings no softer and moved them away from the plant).
pub const MIN_NEW_INFORMATION: f64 = 0.1;

/// The adapted parameters stay within ±30 % of their design values: the
/// tolerance of a production batch (±20 %) with a margin.
pub const TOLERANCE: f64 = 0.3;

/// The record's buffer holds at most this many samples per operation.
const CAPACITY: usize = 256;

/// A parameter the analysis considers.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    pub key: &'static str,
    pub symbol: &'static str,
    pub nominal: f64,
}

/// Why no calibration could be designed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ChoiceError {
    #[error(
        "self-calibration needs a designed soft-landing controller ([trajectory] and [controller])"
    )]
    NoController,
    #[error("self-calibration replays a model of three states: a Jiles–Atherton core is not supported yet")]
    FieldState,
    #[error("the planned operations: {0}")]
    Loop(String),
    #[error("no parameter is identifiable from the coil current of the planned operations")]
    NothingIdentifiable,
}

/// The physics parameters of `description` the calibration may adapt: every
/// model parameter but the turns (known exactly), the stops (the
/// references' frame) and a zero value (no relative change of it).
pub fn candidates(description: &Description) -> Vec<Candidate> {
    const FIXED: [&str; 3] = ["coil.turns", "mechanics.z_min", "mechanics.z_max"];
    params::available(description)
        .into_iter()
        .filter(|key| !FIXED.contains(key))
        .filter_map(|key| {
            let symbol = crate::description::schema::key(key).symbol?;
            let nominal = params::get(description, key).ok()?;
            (nominal != 0.0 && nominal.is_finite()).then_some(Candidate {
                key,
                symbol,
                nominal,
            })
        })
        .collect()
}

/// The innovations update's forward-difference step, relative to θ_d. The
/// innovations are rugged in θ at small scales (the filter's stop modes and
/// the plant's impacts switch with it), so a step of 10⁻³ measured ripples:
/// on 40 generated plants it left a quarter of them where they started (the
/// update took steps of 0.2 % that lowered one run's error and no other's).
/// A step of 5 %, the scale the update moves in (steps up to 20 %), measures
/// the slope. Chosen on the study's tuning seeds 0–19 (10⁻³, 2·10⁻², 5·10⁻²:
/// the worst closing of runs 6–10 at 12×, 20×, 20× median, 1.1×, 1.7×, 2.2×
/// at the least), seeds 20–39 held out (`docs/guide/self-calibration.md`).
pub const DIFFERENCE_STEP: f64 = 5e-2;

/// An innovations update whose fitted model leaves a mean squared current
/// error above this multiple of σ_i² has not explained the valve's current
/// (`Settings::unexplained`). On the self-calibration study's tuning plants
/// (seeds 0–19) the update after run 10 leaves 1.0–1.4·σ_i² on the
/// saturating-core plants and 1.9–3.1·σ_i² on the Jiles–Atherton ones, whose
/// remanence the description's core cannot follow (docs/guide/self-calibration.md,
/// "When the model cannot explain the valve").
pub const UNEXPLAINED: f64 = 2.0;

/// The calibration of `design` at `sample_period`: the identifiable
/// parameters of its planned operations and the runtime's settings.
pub fn choose(design: &Design, sample_period: f64) -> Result<CalibrationDesign, ChoiceError> {
    let d = &design.description;
    let (Some(_), Some(t)) = (&design.controller, &d.trajectory) else {
        return Err(ChoiceError::NoController);
    };
    if matches!(d.core, Core::JilesAtherton { .. }) {
        return Err(ChoiceError::FieldState);
    }
    let candidates: Vec<Candidate> = candidates(d)
        .into_iter()
        .filter(|c| design.model.params.symbol(c.symbol).is_some())
        .collect();
    let per_operation = (super::operation_window(t) / sample_period).ceil() as usize;
    let decimation = per_operation.div_ceil(CAPACITY - 1).max(1);
    let mut calibration = CalibrationDesign {
        method: Method::Replay,
        parameters: Vec::new(),
        rejected: Vec::new(),
        decimation: decimation as u32,
        capacity: per_operation.div_ceil(decimation) + 1,
        sample_period,
        z_min: d.mechanics.z_min,
        z_max: d.mechanics.z_max,
        max_step: 0.2,
        iterations: 8,
        min_samples: per_operation.div_ceil(decimation) / 2,
        current_limit: 2.0 * d.supply.u_max / d.coil.resistance,
        dip_tolerance: 0.1 * d.supply.u_max,
        dip_share: 0.05,
        motion_evidence: 1.0,
        difference_step: DIFFERENCE_STEP,
        unexplained: f64::INFINITY,
    };
    if design.kalman.is_some() && d.controller.as_ref().is_some_and(|c| c.estimator.is_some()) {
        // the prediction-error update through the observer: every candidate,
        // over a whole run (every operation) of every sample, as the filter
        // ran it
        let per_run = per_operation * t.operations.len().max(1);
        calibration.method = Method::Innovations;
        calibration.parameters = candidates.iter().map(|c| adapted(c, 1.0)).collect();
        calibration.decimation = 1;
        calibration.capacity = per_run + 1;
        calibration.min_samples = per_run / 2;
        let sigma = d
            .observer
            .as_ref()
            .map_or(f64::INFINITY, |o| o.current_noise);
        calibration.unexplained = UNEXPLAINED * sigma * sigma;
        return Ok(calibration);
    }
    let information = information(design, &candidates, &calibration, sample_period)?;
    let sigma = d.observer.as_ref().map_or(1e-3, |o| o.current_noise);
    let fisher: Vec<Vec<f64>> = information
        .iter()
        .map(|row| row.iter().map(|a| a / (sigma * sigma)).collect())
        .collect();
    let (chosen, rejected) = greedy(&fisher, &candidates);
    if chosen.is_empty() {
        return Err(ChoiceError::NothingIdentifiable);
    }
    calibration.parameters = chosen
        .into_iter()
        .map(|(k, share)| adapted(&candidates[k], share))
        .collect();
    calibration.rejected = rejected
        .into_iter()
        .map(|(k, why)| (candidates[k].key, why))
        .collect();
    Ok(calibration)
}

/// The domain an adapted parameter stays in: its design value ±[`TOLERANCE`]
/// (its sign kept, so within the physical domain).
fn adapted(c: &Candidate, new_information: f64) -> Adapted {
    // six significant digits: the emitted bounds read as written (0.0105, not
    // 0.010499999999999999)
    let round = |x: f64| format!("{x:.5e}").parse::<f64>().unwrap_or(x);
    let (a, b) = (
        round((1.0 - TOLERANCE) * c.nominal),
        round((1.0 + TOLERANCE) * c.nominal),
    );
    Adapted {
        key: c.key,
        symbol: c.symbol,
        nominal: c.nominal,
        lower: a.min(b),
        upper: a.max(b),
        new_information,
    }
}

/// JᵀJ of the current over the planned operations, every candidate free.
fn information(
    design: &Design,
    candidates: &[Candidate],
    calibration: &CalibrationDesign,
    sample_period: f64,
) -> Result<Vec<Vec<f64>>, ChoiceError> {
    let quiet = Noise {
        seed: 0,
        sigma: Some([0.0, 0.0]),
    };
    let window = design
        .description
        .trajectory
        .as_ref()
        .map(super::operation_window);
    let looped = run_spaced_loop(
        design,
        None,
        sample_period,
        None,
        window,
        quiet,
        &Options::default(),
    )
    .map_err(|e| ChoiceError::Loop(e.to_string()))?;
    macro_rules! with_p {
        ($($n:literal)*) => {
            match candidates.len() {
                $($n => information_with::<$n>(design, candidates, calibration, &looped),)*
                n => unreachable!("{n} candidate parameters"),
            }
        };
    }
    Ok(with_p!(1 2 3 4 5 6 7 8 9 10 11 12 13 14))
}

fn information_with<const P: usize>(
    design: &Design,
    candidates: &[Candidate],
    calibration: &CalibrationDesign,
    looped: &crate::closed_loop::LoopRun,
) -> Vec<Vec<f64>> {
    let mut settings: Settings<f64, P> = Settings {
        nominal: [0.0; P],
        lower: [0.0; P],
        upper: [0.0; P],
        max_step: calibration.max_step,
        sample_period: calibration.sample_period,
        decimation: calibration.decimation,
        z_min: calibration.z_min,
        z_max: calibration.z_max,
        iterations: calibration.iterations,
        min_samples: calibration.min_samples,
        current_limit: f64::INFINITY,
        dip_tolerance: f64::INFINITY,
        dip_share: 1.0,
        motion_evidence: calibration.motion_evidence,
        difference_step: calibration.difference_step,
        unexplained: f64::INFINITY,
    };
    for (n, c) in settings.nominal.iter_mut().zip(candidates) {
        *n = c.nominal;
    }
    let ids = super::symbols::<P>(&design.model, candidates.iter().map(|c| c.symbol));
    let predictor = TapePredictor::<P>::new(&design.model, &ids);
    let mut total = vec![vec![0.0; P]; P];
    for &(operation, start) in &looped.operations {
        let record = super::record(&settings, looped, operation, start, design);
        let r = replay(
            &predictor,
            &settings,
            &record,
            &settings.nominal,
            true,
            false,
        );
        for (t_row, r_row) in total.iter_mut().zip(&r.jtj) {
            for (t, a) in t_row.iter_mut().zip(r_row) {
                *t += a;
            }
        }
    }
    total
}

/// Greedy choice on the Fisher information `f`: by the largest information
/// not explained by the chosen ones; kept where every chosen relative
/// standard error stays within [`MAX_RELATIVE_ERROR`]. Returns the chosen
/// (index, share of new information) and the rejected (index, why).
fn greedy(f: &[Vec<f64>], candidates: &[Candidate]) -> (Vec<(usize, f64)>, Vec<(usize, String)>) {
    let n = f.len();
    let mut chosen: Vec<usize> = Vec::new();
    let mut shares = Vec::new();
    let mut rejected: Vec<(usize, String)> = Vec::new();
    loop {
        let remaining: Vec<usize> = (0..n)
            .filter(|k| !chosen.contains(k) && !rejected.iter().any(|(r, _)| r == k))
            .collect();
        let best = remaining
            .iter()
            .map(|&k| (k, schur(f, &chosen, k)))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let Some((k, new)) = best else { break };
        let mut trial = chosen.clone();
        trial.push(k);
        let errors = relative_errors(f, &trial);
        let worst = errors
            .iter()
            .zip(&trial)
            .max_by(|a, b| a.0.total_cmp(b.0))
            .map(|(e, &j)| (*e, j));
        let share = new / f[k][k].max(f64::MIN_POSITIVE);
        match worst {
            Some((e, _)) if e <= MAX_RELATIVE_ERROR && share >= MIN_NEW_INFORMATION => {
                chosen.push(k);
                shares.push(share);
            }
            Some(_) if share < MIN_NEW_INFORMATION => rejected.push((
                k,
                format!(
                    "{} of what the current says of it is not already said by {}",
                    percent(share),
                    chosen
                        .iter()
                        .map(|&i| candidates[i].key)
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            )),
            Some((e, j)) => rejected.push((
                k,
                format!(
                    "with {} adapted, one run would tell {} only to {:.1} % (1 σ; the limit is {:.0} %)",
                    trial
                        .iter()
                        .map(|&i| candidates[i].key)
                        .collect::<Vec<_>>()
                        .join(", "),
                    candidates[j].key,
                    100.0 * e,
                    100.0 * MAX_RELATIVE_ERROR
                ),
            )),
            None => break,
        }
    }
    (chosen.into_iter().zip(shares).collect(), rejected)
}

/// f_kk − f_kSᵀ·f_SS⁻¹·f_Sk: what k adds to the chosen set S.
fn schur(f: &[Vec<f64>], chosen: &[usize], k: usize) -> f64 {
    if chosen.is_empty() {
        return f[k][k];
    }
    let a: Vec<Vec<f64>> = chosen
        .iter()
        .map(|&i| chosen.iter().map(|&j| f[i][j]).collect())
        .collect();
    let b: Vec<f64> = chosen.iter().map(|&i| f[i][k]).collect();
    match solve(&a, &b) {
        Some(x) => f[k][k] - b.iter().zip(&x).map(|(p, q)| p * q).sum::<f64>(),
        None => 0.0,
    }
}

/// √(F_SS⁻¹)_jj for each j of `set`.
fn relative_errors(f: &[Vec<f64>], set: &[usize]) -> Vec<f64> {
    let a: Vec<Vec<f64>> = set
        .iter()
        .map(|&i| set.iter().map(|&j| f[i][j]).collect())
        .collect();
    (0..set.len())
        .map(|j| {
            let mut e = vec![0.0; set.len()];
            e[j] = 1.0;
            solve(&a, &e).map_or(f64::INFINITY, |x| x[j].max(0.0).sqrt())
        })
        .collect()
}

/// A·x = b by Gaussian elimination with partial pivoting (small, dense).
pub(crate) fn solve(a: &[Vec<f64>], b: &[f64]) -> Option<Vec<f64>> {
    let n = b.len();
    let mut m: Vec<Vec<f64>> = a
        .iter()
        .zip(b)
        .map(|(row, &r)| {
            let mut row = row.clone();
            row.push(r);
            row
        })
        .collect();
    for col in 0..n {
        let pivot = (col..n).max_by(|&i, &j| m[i][col].abs().total_cmp(&m[j][col].abs()))?;
        if m[pivot][col].abs() < 1e-300 || !m[pivot][col].is_finite() {
            return None;
        }
        m.swap(col, pivot);
        for row in col + 1..n {
            let factor = m[row][col] / m[col][col];
            for c in col..=n {
                m[row][c] -= factor * m[col][c];
            }
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|c| m[row][c] * x[c]).sum();
        x[row] = (m[row][n] - s) / m[row][row];
    }
    Some(x)
}

/// A share as a percentage, "< 0.1 %" below that.
fn percent(share: f64) -> String {
    if share < 1e-3 {
        "< 0.1 %".to_owned()
    } else {
        format!("{:.1} %", 100.0 * share)
    }
}
