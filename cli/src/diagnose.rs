//! `reldesign diagnose MODEL.toml DATA.csv [--json] [--out DIR]`
//! (`shared/spec/measured-data.md`): replays the recording through the model,
//! shows where the current error concentrates, names the cause from the
//! vocabulary, writes the extended description and plots, and reports the
//! gain on the whole record and on its held-out end.
//!
//! Files (written together, atomically): `<DATA>.extended.toml` and the
//! plots `<DATA>.current.svg`, `<DATA>.residual.svg`, `<DATA>.loop.svg`,
//! next to the data or in `--out DIR`. With `--json`, stdout carries exactly
//! one JSON object; otherwise a readable report.
//!
//! `reldesign diagnose MODEL.toml --batch DIR [--out DIR]`: every `*.csv` of
//! DIR (one unit each, the same model), diagnosed in parallel across records
//! (rayon); per record its files as above and one JSON line on stdout, in
//! file-name order (`"file"` added; a record that cannot be read or
//! diagnosed gives `{"file", "error"}` and the others go on); progress and a
//! summary table per cause on stderr; exit status 1 when any record failed.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use designer::description::Description;
use miette::Report;
use reldesign_identify::diagnose::localise::{localise, Localisation, Signals};
use reldesign_identify::diagnose::{
    diagnose_causes, Cause, Causes, Diagnosis, FittedParameter, Options,
};
use reldesign_identify::edit::{annotate, write_physics};
use reldesign_identify::lm::Status;
use reldesign_identify::{flux_from_data, Measured, SimOutputs};
use serde_json::{json, Value};

use crate::progress::Progress;
use crate::{diagnose_plot, fail};

#[derive(clap::Args)]
pub struct Args {
    /// The actuator description (valve.toml)
    model: PathBuf,
    /// The recording: CSV with columns t, v, i and optionally z, phi, lambda
    #[arg(required_unless_present = "batch", conflicts_with = "batch")]
    data: Option<PathBuf>,
    /// Diagnose every *.csv of this directory (one unit each, the same model): one JSON
    /// line per record on stdout, in file-name order; progress and a summary on stderr
    #[arg(long)]
    batch: Option<PathBuf>,
    /// Print one JSON object on stdout (the spec's fields and more)
    #[arg(long)]
    json: bool,
    /// Directory for the extended model and the plots (default: next to the data)
    #[arg(long)]
    out: Option<PathBuf>,
    /// Fraction of the record, at its end, kept out of every fit
    #[arg(long, default_value_t = 0.25)]
    holdout: f64,
    /// Try only these causes (comma-separated names of the vocabulary)
    #[arg(long, value_delimiter = ',')]
    causes: Vec<Cause>,
}

/// Paths of everything `diagnose` writes.
struct Outputs {
    extended: PathBuf,
    current: PathBuf,
    residual: PathBuf,
    flux_loop: PathBuf,
}

impl Outputs {
    fn new(out: Option<&Path>, data: &Path) -> Outputs {
        let dir = match out {
            Some(dir) => dir.to_path_buf(),
            None => data.parent().map(Path::to_path_buf).unwrap_or_default(),
        };
        let stem = data
            .file_stem()
            .map_or_else(|| "data".to_owned(), |s| s.to_string_lossy().into_owned());
        let file = |suffix: &str| dir.join(format!("{stem}.{suffix}"));
        Outputs {
            extended: file("extended.toml"),
            current: file("current.svg"),
            residual: file("residual.svg"),
            flux_loop: file("loop.svg"),
        }
    }
}

pub fn run(args: &Args) -> Result<(), Report> {
    if !(0.0..=0.5).contains(&args.holdout) {
        return Err(fail(format!(
            "--holdout {}: expected a fraction in [0, 0.5]",
            args.holdout
        )));
    }
    let description = crate::load(&args.model)?;
    let mut options = Options {
        holdout: args.holdout,
        ..Options::default()
    };
    if !args.causes.is_empty() {
        options.causes = args.causes.clone();
    }
    if let Some(dir) = &args.batch {
        return batch(&description, dir, args.out.as_deref(), &options);
    }
    let Some(data_path) = &args.data else {
        return Err(fail("diagnose needs DATA.csv or --batch DIR"));
    };
    let data = Measured::read(data_path).map_err(fail)?;
    let one = diagnose_one(
        &description,
        &data,
        args.out.as_deref(),
        data_path,
        &options,
    )?;
    if args.json {
        println!("{}", one.json);
    } else {
        print!("{}", one.text);
    }
    Ok(())
}

/// One record's diagnosis: its files written, its JSON and its report.
struct One {
    json: Value,
    text: String,
    /// The answer's first entry.
    cause: Cause,
    gain: f64,
}

fn diagnose_one(
    description: &Description,
    data: &Measured,
    out: Option<&Path>,
    data_path: &Path,
    options: &Options,
) -> Result<One, Report> {
    let answer = diagnose_causes(description, data, options).map_err(fail)?;
    let steps = &answer.steps;
    let (first, d) = (answer.first(), answer.last());
    let localisation = localisation(d, data, &d.baseline_replay);
    let outputs = Outputs::new(out, data_path);
    let named = if answer.unexplained() {
        unexplained_label(&answer)
    } else {
        joined(&answer.names(), " + ")
    };
    let toml = extended_toml(description, d, &answer)?;
    let plots = plots(d, first, &named, data, &localisation, description)?;
    crate::atomic::write_all(&[
        (&outputs.extended, toml.as_bytes()),
        (&outputs.current, plots[0].as_bytes()),
        (&outputs.residual, plots[1].as_bytes()),
        (&outputs.flux_loop, plots[2].as_bytes()),
    ])
    .map_err(fail)?;
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
    let per_cause = per_cause(&answer, &parameters, data, description);
    let mut json = json_report(d, &outputs, &localisation, &parameters);
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
            unexplained_json(&answer, left.as_deref()),
        );
        map.insert("recalibration".into(), recalibration_json(&answer));
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
        &outputs,
        &parameters,
        &verdict(&answer, d),
    );
    // the answer first, then per cause, then the last step in detail
    let mut head = String::new();
    if let Some(left) = &left {
        head.push_str(&unexplained_text(&answer, left));
    }
    if steps.len() > 1 {
        head.push_str(&steps_text(&answer));
    }
    head.push_str(&per_cause_text(&per_cause, answer.unexplained()));
    if !head.is_empty() {
        head.push_str(&format!("\n{} in detail:\n", detail_title(&answer)));
    }
    text = format!("{head}{text}");
    Ok(One {
        json,
        text,
        cause: names_first(&answer),
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
    use reldesign_identify::diagnose::evidence::{identified, why_identified};
    (answer.steps.iter())
        .filter(|s| s.cause != Cause::None)
        .map(|step| {
            let own = |p: &&FittedParameter| {
                p.path != "coil.resistance"
                    && (step.named_candidate.as_ref())
                        .is_some_and(|c| c.params.iter().any(|q| q.path == p.path))
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
    let near = |b: f64| (p.value - b).abs() <= 1e-3 * (range.upper - range.lower);
    near(range.lower) || near(range.upper)
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
fn names_first(answer: &Causes) -> Cause {
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

/// `--batch DIR`: every record of DIR, in parallel (module docs).
fn batch(
    description: &Description,
    dir: &Path,
    out: Option<&Path>,
    options: &Options,
) -> Result<(), Report> {
    use rayon::prelude::*;
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| fail(format!("--batch {}: {e}", dir.display())))?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(fail(format!(
            "--batch {}: no *.csv record in the directory",
            dir.display()
        )));
    }
    let total = files.len();
    let bar = Progress::new(total as u64, "records");
    let done = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<Result<One, String>> = files
        .par_iter()
        .map(|path| {
            let one = Measured::read(path)
                .map_err(|e| e.to_string())
                .and_then(|data| {
                    diagnose_one(description, &data, out, path, options).map_err(|e| e.to_string())
                });
            let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            let what = match &one {
                Ok(o) => format!("{} (gain {})", o.cause.name(), percent(o.gain)),
                Err(_) => "failed".to_owned(),
            };
            bar.println(&format!("[{k}/{total}] {}: {what}", path.display()));
            bar.inc();
            one
        })
        .collect();
    bar.finish();
    let mut failed = 0;
    let mut by_cause: Vec<(String, usize, f64)> = Vec::new();
    for (path, result) in files.iter().zip(&results) {
        let file = path.display().to_string();
        match result {
            Ok(one) => {
                let mut line = one.json.clone();
                if let Some(map) = line.as_object_mut() {
                    map.insert("file".into(), json!(file));
                }
                println!("{line}");
                let name = one.cause.name().to_owned();
                match by_cause.iter_mut().find(|(c, _, _)| *c == name) {
                    Some(row) => {
                        row.1 += 1;
                        row.2 += one.gain;
                    }
                    None => by_cause.push((name, 1, one.gain)),
                }
            }
            Err(e) => {
                failed += 1;
                println!("{}", json!({"file": file, "error": e}));
            }
        }
    }
    eprint!("{}", batch_summary(&by_cause, failed, total));
    if failed > 0 {
        return Err(fail(format!(
            "{failed} of {total} records could not be diagnosed (their lines say why)"
        )));
    }
    Ok(())
}

/// The batch's summary table: per cause the records and their mean gain.
fn batch_summary(by_cause: &[(String, usize, f64)], failed: usize, total: usize) -> String {
    let mut rows = by_cause.to_vec();
    rows.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    let mut s = format!(
        "\n{total} records\n  {:<18} {:>7} {:>10}\n",
        "cause", "records", "mean gain"
    );
    for (cause, n, gain) in rows {
        let _ = writeln!(s, "  {cause:<18} {n:>7} {:>10}", percent(gain / n as f64));
    }
    if failed > 0 {
        let _ = writeln!(s, "  {:<18} {failed:>7}", "(failed)");
    }
    s
}

/// The winner written over the original text, comments kept.
fn extended_toml(
    description: &Description,
    d: &Diagnosis,
    answer: &Causes,
) -> Result<String, Report> {
    let source = &description.source;
    let text = write_physics(&source.text, &source.file_name, &d.extended).map_err(fail)?;
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
fn localisation(d: &Diagnosis, data: &Measured, replay: &SimOutputs) -> Localisation {
    let moving = reldesign_identify::diagnose::moving(replay);
    let m = &d.extended.mechanics;
    let impacts = reldesign_identify::diagnose::impacts(replay, m.z_min, m.z_max);
    localise(&signals(d, data, replay, &moving, &impacts))
}

/// Where the error the last model leaves concentrates.
fn localisation_left(d: &Diagnosis, data: &Measured) -> Localisation {
    localisation(d, data, &d.extended_replay)
}

/// The three plots: measured vs simulated, residual, λ–i loop.
/// The three plots of the last step `d`; the comparison shows the original
/// baseline (`first`'s) against the model with every cause (`causes`).
fn plots(
    d: &Diagnosis,
    first: &Diagnosis,
    causes: &str,
    data: &Measured,
    localisation: &Localisation,
    description: &Description,
) -> Result<[String; 3], Report> {
    let base = &d.baseline_replay;
    let ext = &d.extended_replay;
    let original = &first.baseline_replay;
    let mut measured: Vec<(&str, &[f64])> = vec![("current i [A]", &data.i)];
    let mut simulated: Vec<(&str, &[f64])> = vec![("current i [A]", &original.current)];
    let extended_label = format!("current i [A], extended ({causes})");
    simulated.push((&extended_label, &ext.current));
    if let Some(z) = &data.z {
        measured.push(("position z [m]", z));
        simulated.push(("position z [m]", &original.z));
    }
    let title = format!("{}: measured vs simulated", data.file_name);
    let comparison =
        diagnose_plot::comparison_svg(&title, &data.t, &measured, &simulated).map_err(fail)?;

    let residual: Vec<f64> = base
        .current
        .iter()
        .zip(&data.i)
        .map(|(s, m)| s - m)
        .collect();
    let regions = localisation.marked_windows();
    let marked: Vec<(f64, f64, &str)> = regions
        .iter()
        .map(|(a, b, l)| (*a, *b, l.as_str()))
        .collect();
    let residual_title = if std::ptr::eq(d, first) {
        "current residual (baseline − measured)".to_string()
    } else {
        format!(
            "current residual before the last cause, {} (model − measured)",
            d.cause
        )
    };
    let residual_svg =
        diagnose_plot::residual_svg(&residual_title, &data.t, &residual, &marked).map_err(fail)?;

    let turns = description.coil.turns;
    let lambda_data: Vec<f64> = flux_from_data(data, turns, description.coil.resistance)
        .iter()
        .map(|phi| turns * phi)
        .collect();
    let lambda_sim: Vec<f64> = base.phi.iter().map(|phi| turns * phi).collect();
    let flux_loop = diagnose_plot::flux_current_loop_svg(
        "flux linkage vs current",
        &data.i,
        &lambda_data,
        &base.current,
        &lambda_sim,
    )
    .map_err(fail)?;
    Ok([comparison, residual_svg, flux_loop])
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

fn percent(x: f64) -> String {
    format!("{:.3} %", 100.0 * x)
}

fn text_report(
    model: &str,
    data_path: &Path,
    data: &Measured,
    d: &Diagnosis,
    loc: &Localisation,
    out: &Outputs,
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
        d.fitted_samples
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
    out: &Outputs,
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
        "candidates": candidates,
        "not_tried": not_tried,
        "localisation": loc.to_string(),
        "plots": [out.current.display().to_string(), out.residual.display().to_string(), out.flux_loop.display().to_string()],
    })
}
