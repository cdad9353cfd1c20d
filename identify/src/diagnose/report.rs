//! A diagnosis as `reldesign diagnose` reports it: the JSON object of
//! `--json` (and of each `--batch` line), the text report, the extended
//! description's text. Written once here so that the command line and the
//! Python package (`python/`) give the same bytes; the plots and the writing
//! of files stay with their callers.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use super::localise::{localise, Localisation, Signals};
use super::{Cause, Causes, Diagnosis, FittedParameter};
use crate::description::Description;
use crate::edit::{annotate, write_physics};
use crate::lm::Status;
use crate::{Measured, SimOutputs};

/// Paths of everything `diagnose` writes for one record: named in the JSON
/// and the text report, whether or not the caller writes them.
#[derive(Debug, Clone, PartialEq)]
pub struct Paths {
    pub extended: PathBuf,
    pub current: PathBuf,
    pub residual: PathBuf,
    pub flux_loop: PathBuf,
}

impl Paths {
    /// `<stem>.extended.toml` and the plots `<stem>.{current,residual,loop}.svg`
    /// of the record `data` (its file's stem; `data` without one: `data`), in
    /// `out` or next to the record.
    pub fn new(out: Option<&Path>, data: &Path) -> Paths {
        let dir = match out {
            Some(dir) => dir.to_path_buf(),
            None => data.parent().map(Path::to_path_buf).unwrap_or_default(),
        };
        let stem = data
            .file_stem()
            .map_or_else(|| "data".to_owned(), |s| s.to_string_lossy().into_owned());
        let file = |suffix: &str| dir.join(format!("{stem}.{suffix}"));
        Paths {
            extended: file("extended.toml"),
            current: file("current.svg"),
            residual: file("residual.svg"),
            flux_loop: file("loop.svg"),
        }
    }
}

/// One record's diagnosis, reported.
#[derive(Debug, Clone)]
pub struct Report {
    /// The JSON object of `reldesign diagnose --json`.
    pub json: Value,
    /// The text report of `reldesign diagnose`.
    pub text: String,
    /// The extended description: the original text with the last model's
    /// physics written over it, comments kept, and a header line.
    pub extended_toml: String,
    /// The causes found, joined by ` + ` (or `unexplained…`): the plots' label.
    pub label: String,
    /// Where the error of the last step's baseline concentrates.
    pub localisation: Localisation,
    /// Every step's fitted values against the original description.
    pub parameters: Vec<FittedParameter>,
    /// The answer's first entry.
    pub cause: Cause,
    /// The whole selection's gain.
    pub gain: f64,
}

/// The report of `answer`, the diagnosis of `data` (read from `data_path`)
/// against `description`, its files named by `outputs`.
pub fn report(
    description: &Description,
    data: &Measured,
    data_path: &Path,
    outputs: &Paths,
    answer: &Causes,
) -> Result<Report, String> {
    let steps = &answer.steps;
    let (first, d) = (answer.first(), answer.last());
    let localisation = localisation(d, data, &d.baseline_replay);
    let named = if answer.unexplained() {
        unexplained_label(answer)
    } else {
        joined(&answer.names(), " + ")
    };
    let toml = extended_toml(description, d, answer)?;
    // every step's fitted values against the original description, a later
    // step's refit (the resistance, or every value after the joint fit)
    // replacing an earlier one's
    let mut parameters: Vec<FittedParameter> = Vec::new();
    for step in steps {
        for p in step.parameters(description, data) {
            parameters.retain(|q| q.path != p.path);
            parameters.push(p);
        }
    }
    let left = answer
        .unexplained()
        .then(|| localisation_left(d, data).to_string());
    let per_cause = per_cause(answer, &parameters, data, description);
    let mut json = json_report(d, outputs, &localisation, &parameters);
    let overall = answer.gain();
    let names: Vec<&str> = answer.names().iter().map(|c| c.name()).collect();
    if let Some(map) = json.as_object_mut() {
        map.insert("cause".into(), json!(names.first()));
        map.insert("causes".into(), json!(names));
        map.insert("baseline_wnrmse".into(), json!(first.whole.baseline_wnrmse));
        map.insert("gain".into(), json!(overall));
        map.insert(
            "steps".into(),
            json!(steps.iter().map(step_json).collect::<Vec<_>>()),
        );
        map.insert(
            "residual".into(),
            json!({
                "over_noise_floor": answer.residual.over_floor,
                "correlation_samples": answer.residual.correlation,
            }),
        );
        map.insert(
            "unexplained".into(),
            unexplained_json(answer, left.as_deref()),
        );
        map.insert("recalibration".into(), recalibration_json(answer));
        map.insert(
            "per_cause".into(),
            json!(per_cause
                .iter()
                .map(|c| json!({
                    "cause": c.cause.name(),
                    "named": !answer.unexplained(),
                    "gain": c.gain,
                    "identifiable": c.identifiable,
                    "why": c.why,
                    "at_bound": c.at_bound,
                    "values": c.values.iter().map(|p| (p.path.clone(), json!({
                        "value": p.value, "std_error": p.std_error, "baseline": p.baseline,
                    }))).collect::<serde_json::Map<_, _>>(),
                }))
                .collect::<Vec<_>>()),
        );
    }
    let mut text = text_report(
        &description.source.file_name,
        data_path,
        data,
        d,
        &localisation,
        outputs,
        &parameters,
        &verdict(answer, d),
    );
    // the answer first, then per cause, then the last step in detail
    let mut head = String::new();
    if let Some(left) = &left {
        head.push_str(&unexplained_text(answer, left));
    }
    if steps.len() > 1 {
        head.push_str(&steps_text(answer));
    }
    head.push_str(&per_cause_text(&per_cause, answer.unexplained()));
    if !head.is_empty() {
        head.push_str(&format!("\n{} in detail:\n", detail_title(answer)));
    }
    text = format!("{head}{text}");
    Ok(Report {
        json,
        text,
        extended_toml: toml,
        label: named,
        localisation,
        parameters,
        cause: names_first(answer),
        gain: overall,
    })
}

/// The cause line of the step `d`'s report.
fn verdict(answer: &Causes, d: &Diagnosis) -> String {
    let partial = answer.partial();
    if answer.unexplained() && !partial.is_empty() {
        format!(
            "unexplained ({} explain part of it only: not named)",
            joined(&partial, " + ")
        )
    } else if answer.unexplained() {
        "unexplained".to_owned()
    } else {
        d.cause.name().to_owned()
    }
}

/// One cause the selection found, as the report gives it.
struct CauseReport<'a> {
    cause: Cause,
    /// Its step's gain over the model before it.
    gain: f64,
    /// Whether its reported values still identify it (None: it has no effect
    /// parameter, as fringing; it was identified by the record's motion).
    identifiable: Option<bool>,
    /// Why the record identifies it (`evidence::why_identified`).
    why: String,
    /// Its own fitted values (the resistance, refitted by every step, left out).
    values: Vec<&'a FittedParameter>,
    /// Those of its values the fit left on a bound of their search range.
    at_bound: Vec<String>,
}

/// Every cause the selection found, strongest first.
fn per_cause<'a>(
    answer: &Causes,
    parameters: &'a [FittedParameter],
    data: &Measured,
    description: &Description,
) -> Vec<CauseReport<'a>> {
    use crate::diagnose::evidence::{identified, why_identified};
    (answer.steps.iter())
        .filter(|s| s.cause != Cause::None)
        .map(|step| {
            // the bounce threshold goes with every cause whose fit scanned it,
            // at the last step's value (a later step's replaces an earlier's)
            let scanned = |p: &FittedParameter| {
                p.path == super::BOUNCE_THRESHOLD
                    && (step.named_fit.as_ref()).is_some_and(|f| f.scanned_threshold.is_some())
            };
            let own = |p: &&FittedParameter| {
                p.path != "coil.resistance"
                    && ((step.named_candidate.as_ref())
                        .is_some_and(|c| c.params.iter().any(|q| q.path == p.path))
                        || scanned(p))
            };
            let values: Vec<&FittedParameter> = parameters.iter().filter(own).collect();
            let at_bound = (values.iter())
                .filter(|p| on_bound(step, p))
                .map(|p| p.path.clone())
                .collect();
            CauseReport {
                cause: step.cause,
                gain: step.whole.gain,
                identifiable: identified(step.cause, parameters),
                why: why_identified(step, parameters, data, description),
                values,
                at_bound,
            }
        })
        .collect()
}

/// Whether `p` ended within 0.1 % of `step`'s search range from a bound: the
/// data want it beyond what the fit allows, a sign the cause stands in for
/// something else.
fn on_bound(step: &Diagnosis, p: &FittedParameter) -> bool {
    let Some(range) =
        (step.named_candidate.as_ref()).and_then(|c| c.params.iter().find(|q| q.path == p.path))
    else {
        return false;
    };
    super::candidate::on_bound(p.value, range)
}

/// The report's section per cause: its gain, why the record identifies it,
/// its values with their standard errors.
fn per_cause_text(causes: &[CauseReport], unexplained: bool) -> String {
    if causes.is_empty() {
        return String::new();
    }
    let mut s = format!(
        "\nper cause ({}):\n",
        if unexplained {
            "partial, not named"
        } else {
            "strongest first"
        }
    );
    for c in causes {
        let _ = writeln!(
            s,
            "  {}: gain {} over the model before it\n    {}: {}",
            c.cause.name(),
            percent(c.gain),
            match c.identifiable {
                Some(false) => "NOT identifiable by its reported values",
                _ => "identifiable",
            },
            c.why
        );
        for p in &c.values {
            let bound = if c.at_bound.contains(&p.path) {
                " (on the bound of its range: the data want it further; the cause may stand in \
                 for something else)"
            } else {
                ""
            };
            let _ = writeln!(
                s,
                "    {:<24} = {:.4e} ± {:.2e}{bound}",
                p.path, p.value, p.std_error
            );
        }
    }
    s
}

/// "unexplained", with the partial causes where there are any.
fn unexplained_label(answer: &Causes) -> String {
    match answer.partial() {
        partial if partial.is_empty() => "unexplained".to_owned(),
        partial => format!("unexplained; partial: {}", joined(&partial, " + ")),
    }
}

/// The answer's first entry.
pub fn names_first(answer: &Causes) -> Cause {
    answer.names().first().copied().unwrap_or(Cause::None)
}

/// `causes`' names joined by `sep`.
fn joined(causes: &[Cause], sep: &str) -> String {
    causes
        .iter()
        .map(|c| c.name())
        .collect::<Vec<_>>()
        .join(sep)
}

/// `"unexplained"` of the JSON: null when the record is explained; else
/// what is left, the partial causes and their gain, and where the residual
/// left concentrates.
fn unexplained_json(answer: &Causes, left: Option<&str>) -> Value {
    let Some(left) = left else {
        return Value::Null;
    };
    json!({
        "over_noise_floor": answer.residual.over_floor,
        "correlation_samples": answer.residual.correlation,
        "partial_causes": answer.partial().iter().map(|c| c.name()).collect::<Vec<_>>(),
        "partial_gain": answer.gain(),
        "recalibrated": answer.recalibrated(),
        "localisation": left,
    })
}

/// What the detailed part of a report with a head covers.
fn detail_title(answer: &Causes) -> String {
    match answer.steps.len() {
        1 => format!("the diagnosis ({})", answer.last().cause),
        _ => format!("the last step ({})", answer.last().cause),
    }
}

/// `"recalibration"` of the JSON: the description refitted against the
/// causes found (null where it was not tried).
fn recalibration_json(answer: &Causes) -> Value {
    let Some(r) = &answer.recalibration else {
        return Value::Null;
    };
    let values: serde_json::Map<String, Value> = (r.values.iter())
        .map(|(k, v)| (k.clone(), json!(v)))
        .collect();
    json!({
        "values": values,
        "wnrmse": r.wnrmse,
        "bic": r.bic,
        "causes_wnrmse": r.causes_wnrmse,
        "causes_bic": r.causes_bic,
        "explains": r.explains(),
        "given_up": r.given_up,
    })
}

/// The report's verdict for an unexplained record.
fn unexplained_text(answer: &Causes, left: &str) -> String {
    let r = answer.residual;
    let partial = answer.partial();
    let mut s = format!(
        "answer: unexplained. The model leaves {:.1}× the noise floor (its residual correlated \
         over {:.0} samples), or a recalibration of the description does as well as the causes \
         found; the causes of the vocabulary leave 1–4× on the records they explain. Something \
         outside the vocabulary is at work: a measurement chain \
         (probe gain or lag, driver delay), or parameters of the description (the spring, the \
         mass, the reluctances) that no cause refits.\n",
        r.over_floor, r.correlation
    );
    if let Some(r) = answer.recalibration.as_ref().filter(|r| r.explains()) {
        let values: Vec<String> = (r.values.iter())
            .map(|(k, v)| format!("{k} = {v:.4e}"))
            .collect();
        let _ = writeln!(
            s,
            "the description recalibrated ({}) explains it as well as the causes found \
             (wNRMSE {} against {} on the fitted part, BIC {:.1} against {:.1}): a current probe's \
             gain, or reluctances other than the description's, not an effect of the vocabulary.",
            values.join(", "),
            percent(r.wnrmse),
            percent(r.causes_wnrmse),
            r.bic,
            r.causes_bic
        );
    }
    if partial.is_empty() {
        s.push_str("no extension of the vocabulary improves the record.\n");
    } else {
        let _ = writeln!(
            s,
            "partial, not named: {} explains {} of the baseline's error (the extended model \
             written holds it).",
            joined(&partial, " + "),
            percent(answer.gain())
        );
    }
    let _ = writeln!(
        s,
        "where the residual left concentrates:\n{}",
        left.trim_end()
    );
    s
}

/// The head of a report with several causes: the causes, each step's gain,
/// the whole selection's; the last step's report follows in detail.
fn steps_text(answer: &Causes) -> String {
    let (steps, overall) = (&answer.steps, answer.gain());
    let together = if answer.fitted_together {
        ", then all fitted together; the last step's figures are the joint fit's"
    } else {
        ""
    };
    let mut s = format!(
        "causes found: {} (strongest first; each fitted on top of the ones before{together})\n",
        steps
            .iter()
            .map(|s| s.cause.name())
            .collect::<Vec<_>>()
            .join(", ")
    );
    for (k, step) in steps.iter().enumerate() {
        let _ = writeln!(
            s,
            "  {}. {:<18} wNRMSE {} → {} on the whole record (gain {})",
            k + 1,
            step.cause.name(),
            percent(step.whole.baseline_wnrmse),
            percent(step.whole.extended_wnrmse),
            percent(step.whole.gain)
        );
    }
    if let (Some(first), Some(last)) = (steps.first(), steps.last()) {
        let _ = writeln!(
            s,
            "  together: {} → {} (gain {}); the extended model holds every cause",
            percent(first.whole.baseline_wnrmse),
            percent(last.whole.extended_wnrmse),
            percent(overall),
        );
    }
    s
}

/// One step of the forward selection: its cause and its gain over the model
/// before it.
fn step_json(step: &Diagnosis) -> Value {
    json!({
        "cause": step.cause.name(),
        "baseline_wnrmse": step.whole.baseline_wnrmse,
        "extended_wnrmse": step.whole.extended_wnrmse,
        "gain": step.whole.gain,
        "held_out_gain": step.held_out.map(|h| h.gain),
        "noise_floor": step.noise_floor,
    })
}

/// The winner written over the original text, comments kept.
fn extended_toml(
    description: &Description,
    d: &Diagnosis,
    answer: &Causes,
) -> Result<String, String> {
    let source = &description.source;
    let text =
        write_physics(&source.text, &source.file_name, &d.extended).map_err(|e| e.to_string())?;
    let cause = if answer.unexplained() {
        unexplained_label(answer)
    } else {
        joined(&answer.names(), " + ")
    };
    let first = answer.first();
    let header = format!(
        "extended by reldesign diagnose: cause = {cause}, current wNRMSE {:.3} % -> {:.3} % \
         (gain {:.1} %)",
        100.0 * first.whole.baseline_wnrmse,
        100.0 * d.whole.extended_wnrmse,
        100.0 * answer.gain()
    );
    Ok(annotate(&text, &header))
}

fn signals<'a>(
    d: &'a Diagnosis,
    data: &'a Measured,
    replay: &'a SimOutputs,
    moving: &'a [bool],
    impacts: &'a [f64],
) -> Signals<'a> {
    Signals {
        t: &data.t,
        v: &data.v,
        i_measured: &data.i,
        i_simulated: &replay.current,
        weight: &d.weights,
        z_simulated: &replay.z,
        moving,
        impacts,
        flux_simulated: &replay.phi,
        z_measured: data.z.as_deref(),
    }
}

/// Where the current error of `replay` (the step's baseline's) concentrates.
pub fn localisation(d: &Diagnosis, data: &Measured, replay: &SimOutputs) -> Localisation {
    let moving = crate::diagnose::moving(replay);
    let m = &d.extended.mechanics;
    let impacts = crate::diagnose::impacts(replay, m.z_min, m.z_max);
    localise(&signals(d, data, replay, &moving, &impacts))
}

/// Where the error the last model leaves concentrates.
fn localisation_left(d: &Diagnosis, data: &Measured) -> Localisation {
    localisation(d, data, &d.extended_replay)
}

/// How a candidate's fit that did not converge ended, for the ranking's
/// lines (its BIC is then an upper bound of the candidate's).
fn unfinished(status: Status) -> String {
    match status {
        _ if status.converged() => String::new(),
        Status::GaveUp => "  (given up far above the best fit: BIC an upper bound)".into(),
        Status::MaxIterations => "  (at the iteration cap: BIC an upper bound)".into(),
        other => format!("  (ended: {other:?}; BIC an upper bound)"),
    }
}

pub fn percent(x: f64) -> String {
    format!("{:.3} %", 100.0 * x)
}

fn text_report(
    model: &str,
    data_path: &Path,
    data: &Measured,
    d: &Diagnosis,
    loc: &Localisation,
    out: &Paths,
    parameters: &[FittedParameter],
    verdict: &str,
) -> String {
    let mut s = String::new();
    let n = data.t.len();
    let _ = writeln!(
        s,
        "diagnose {} against {} ({n} samples, Δ = {:e} s)",
        model,
        data_path.display(),
        data.dt
    );
    let _ = writeln!(
        s,
        "noise σ_i ≈ {:.3} mA, σ_v ≈ {:.1} mV: noise floor of the weighted error {} ({} from the voltage noise the replay integrates)",
        1e3 * d.current_noise,
        1e3 * d.voltage_noise,
        percent(d.noise_floor),
        percent(d.voltage_floor)
    );
    if !d.edges.is_empty() {
        let placed = d.edges.iter().filter(|e| e.located).count();
        let _ = writeln!(
            s,
            "voltage steps between samples: {}, {placed} placed inside their sample interval \
             (the rest at mid-interval)",
            d.edges.len()
        );
    }
    let _ = writeln!(
        s,
        "baseline current wNRMSE (eq. 81): {}",
        percent(d.whole.baseline_wnrmse)
    );
    let _ = writeln!(s, "where the error concentrates:\n{loc}");
    let _ = writeln!(
        s,
        "candidates (fitted on the first {} samples, ranked by BIC):",
        d.ranked_samples
    );
    for c in &d.ranking {
        match &c.fit {
            Ok(f) => {
                let values: Vec<String> = f
                    .values
                    .iter()
                    .map(|(k, v)| format!("{k} = {v:.4e}"))
                    .collect();
                let _ = writeln!(
                    s,
                    "  {:<17} k = {}  wNRMSE {:>9}  BIC {:>12.1}  {}{}",
                    c.cause.name(),
                    c.parameters,
                    percent(c.wnrmse_fit),
                    c.bic,
                    values.join(", "),
                    unfinished(f.status)
                );
            }
            Err(e) => {
                let _ = writeln!(s, "  {:<17} fit failed: {e}", c.cause.name());
            }
        }
    }
    for na in &d.not_applicable {
        let _ = writeln!(s, "  {:<17} not tried: {}", na.cause.name(), na.reason);
    }
    for (cause, reason) in &d.not_identifiable {
        let _ = writeln!(
            s,
            "  {:<17} not identifiable from this record: {reason}",
            cause.name()
        );
    }
    for r in &d.rejected {
        let _ = writeln!(s, "  {:<17} not named: {}", r.cause.name(), r.reason());
    }
    let _ = writeln!(s, "cause: {verdict}");
    for p in parameters {
        let baseline = p
            .baseline
            .map_or("(new)".to_string(), |b| format!("{b:.4e}"));
        let _ = writeln!(
            s,
            "  {:<24} = {:.4e} ± {:.2e} (standard error; baseline {baseline})",
            p.path, p.value, p.std_error
        );
    }
    let _ = writeln!(s, "extended model: {}", out.extended.display());
    let _ = writeln!(
        s,
        "gain = 1 − extended/baseline: {:.1} % on the whole record ({} → {})",
        100.0 * d.whole.gain,
        percent(d.whole.baseline_wnrmse),
        percent(d.whole.extended_wnrmse)
    );
    if let Some(h) = d.held_out {
        let _ = writeln!(
            s,
            "held-out last {} samples: {:.1} % ({} → {})",
            n - d.fitted_samples,
            100.0 * h.gain,
            percent(h.baseline_wnrmse),
            percent(h.extended_wnrmse)
        );
    }
    let _ = writeln!(
        s,
        "plots: {}, {}, {}",
        out.current.display(),
        out.residual.display(),
        out.flux_loop.display()
    );
    s
}

fn json_report(
    d: &Diagnosis,
    out: &Paths,
    loc: &Localisation,
    parameters: &[FittedParameter],
) -> Value {
    let parameters: serde_json::Map<String, Value> = parameters
        .iter()
        .map(|p| {
            let v = json!({"value": p.value, "std_error": p.std_error, "baseline": p.baseline});
            (p.path.clone(), v)
        })
        .collect();
    let candidates: Vec<Value> = d
        .ranking
        .iter()
        .map(|c| match &c.fit {
            Ok(f) => json!({
                "cause": c.cause.name(),
                "parameters": c.parameters,
                "wnrmse": c.wnrmse_fit,
                "bic": c.bic,
                "status": format!("{:?}", f.status),
                "values": f.values.iter().map(|(k, v)| (k.clone(), json!(v))).collect::<serde_json::Map<_, _>>(),
            }),
            Err(e) => json!({"cause": c.cause.name(), "error": e}),
        })
        .collect();
    let not_tried: Vec<Value> = d
        .not_applicable
        .iter()
        .map(|n| json!({"cause": n.cause.name(), "reason": n.reason}))
        .collect();
    json!({
        "cause": d.cause.name(),
        "baseline_wnrmse": d.whole.baseline_wnrmse,
        "extended_wnrmse": d.whole.extended_wnrmse,
        "gain": d.whole.gain,
        "extended_model": out.extended.display().to_string(),
        "held_out": d.held_out.map(|h| json!({
            "baseline_wnrmse": h.baseline_wnrmse,
            "extended_wnrmse": h.extended_wnrmse,
            "gain": h.gain,
        })),
        "parameters": parameters,
        "not_identifiable": d.not_identifiable.iter().map(|(c, why)| json!({
            "cause": c.name(), "reason": why,
        })).collect::<Vec<_>>(),
        "rejected": d.rejected.iter().map(|r| json!({
            "cause": r.cause.name(),
            "whole_gain": r.whole.gain,
            "held_out_gain": r.held_out.map(|h| h.gain),
        })).collect::<Vec<_>>(),
        "voltage_steps": d.edges.iter().map(|e| json!({
            "after_sample": e.k, "t": e.tau, "placed": e.located,
        })).collect::<Vec<_>>(),
        "noise_floor": d.noise_floor,
        "current_noise": d.current_noise,
        "voltage_noise": d.voltage_noise,
        "voltage_floor": d.voltage_floor,
        "fitted_samples": d.fitted_samples,
        "ranked_samples": d.ranked_samples,
        "candidates": candidates,
        "not_tried": not_tried,
        "localisation": loc.to_string(),
        "plots": [out.current.display().to_string(), out.residual.display().to_string(), out.flux_loop.display().to_string()],
    })
}
