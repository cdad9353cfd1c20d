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
use reldesign_identify::diagnose::localise::Localisation;
use reldesign_identify::diagnose::report::{percent, report, Paths};
use reldesign_identify::diagnose::{diagnose_causes, Cause, Diagnosis, Options};
use reldesign_identify::{flux_from_data, Measured};
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
    let outputs = Paths::new(out, data_path);
    let r = report(description, data, data_path, &outputs, &answer).map_err(fail)?;
    let plots = plots(
        answer.last(),
        answer.first(),
        &r.label,
        data,
        &r.localisation,
        description,
    )?;
    crate::atomic::write_all(&[
        (&outputs.extended, r.extended_toml.as_bytes()),
        (&outputs.current, plots[0].as_bytes()),
        (&outputs.residual, plots[1].as_bytes()),
        (&outputs.flux_loop, plots[2].as_bytes()),
    ])
    .map_err(fail)?;
    Ok(One {
        json: r.json,
        text: r.text,
        cause: r.cause,
        gain: r.gain,
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
