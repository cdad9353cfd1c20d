//! `reldesign observe MODEL.toml DATA.csv [--out OUT.csv] [--stride S]`: runs
//! the description's model-free estimators (`[observer].estimators`:
//! "semera", [SE Alg. 1], and/or "integral", [SE Alg. 2] of
//! semera-electromagnetic-estimation) over a recording in the measured-data
//! format (columns `t`, `v`, `i`; uniform sampling at `observer.sample_period`
//! within 1 %), writes per sample `t` and, per estimator, r̂, l̂, λ̂, φ̂ and the
//! CI detector's verdict, and reports where the recording is unobservable by
//! the determinant [SE 32] (`designer::observe::observability`).
//!
//! The CSV goes to `--out` (written atomically) or to stdout; the report goes
//! to stdout with `--out`, else to stderr. On any error nothing is written.

use std::fmt::Write as _;
use std::path::PathBuf;

use designer::description::Estimator;
use designer::observe::integral::{Integral, IntegralConfig};
use designer::observe::observability::{analyse, blind_intervals, ObservabilitySettings, Status};
use designer::observe::semera::{Estimate, Semera, SemeraConfig};
use designer::record::Record;
use miette::Report;

use crate::fail;

#[derive(clap::Args)]
pub struct Args {
    /// The actuator description with an [observer] section (valve.toml)
    model: PathBuf,
    /// The recording: CSV with columns t, v, i (the measured-data format)
    data: PathBuf,
    /// Output CSV (written atomically); stdout when absent
    #[arg(long)]
    out: Option<PathBuf>,
    /// Observability test [SE 32] on every S-th sample (time scale S·Δ); 1 is the window of [SE 31]
    #[arg(long, default_value_t = 1)]
    stride: usize,
}

/// Column prefix and the estimator's per-sample estimates.
type Run = (&'static str, Vec<Estimate>);

pub fn run(args: &Args) -> Result<(), Report> {
    let description = crate::load(&args.model)?;
    let model = args.model.display();
    let Some(observer) = &description.observer else {
        return Err(fail(format!(
            "{model}: no [observer] section: `observe` runs the estimators it lists \
             (estimators = [\"semera\", \"integral\"], with [observer.semera] / \
             [observer.integral]; see docs/reference/description.md)"
        )));
    };
    let semera = observer
        .estimators
        .contains(&Estimator::Semera)
        .then(|| SemeraConfig::from_description(&description))
        .flatten();
    let integral = observer
        .estimators
        .contains(&Estimator::Integral)
        .then(|| IntegralConfig::from_description(&description))
        .flatten();
    if semera.is_none() && integral.is_none() {
        return Err(fail(format!(
            "{model}: observer.estimators lists neither \"semera\" nor \"integral\": `observe` \
             runs the model-free estimators only (the model-based \"ekf\" and \"ukf\" are \
             emitted by `build`)"
        )));
    }
    if args.stride == 0 {
        return Err(fail("--stride must be at least 1"));
    }

    let record = Record::read(&args.data).map_err(fail)?;
    let t = record.time(4).map_err(fail)?;
    let dt = record.check_uniform(&t).map_err(fail)?;
    let period = observer.sample_period;
    if (dt - period).abs() > 0.01 * period {
        return Err(fail(format!(
            "{}: column `t`: the sampling period is {dt:e} s, but observer.sample_period = \
             {period:e} s in {model} (the estimators assume Δ; resample the recording or \
             change observer.sample_period)",
            args.data.display()
        )));
    }
    let v = record.column("v").map_err(fail)?;
    let i = record.column("i").map_err(fail)?;

    let mut runs: Vec<Run> = Vec::new();
    if let Some(config) = &semera {
        let mut s = Semera::new(config);
        runs.push((
            "semera",
            v.iter().zip(&i).map(|(&v, &i)| s.step(v, i)).collect(),
        ));
    }
    if let Some(config) = &integral {
        let mut g = Integral::new(config);
        runs.push((
            "integral",
            v.iter().zip(&i).map(|(&v, &i)| g.step(v, i)).collect(),
        ));
    }
    let csv = to_csv(&t, &runs);

    let n_sigma = semera
        .map(|c| c.filter.ci_sigmas)
        .or(integral.map(|c| c.settings.ci_sigmas))
        .unwrap_or(3.29);
    let settings = ObservabilitySettings {
        sample_period: period,
        current_noise: observer.current_noise,
        n_sigma,
        stride: args.stride,
    };
    let obs = analyse(&i, &settings);
    let report = report(args, &t, &runs, &obs, &settings);

    if let Some(path) = &args.out {
        crate::atomic::write_all(&[(path, csv.as_bytes())]).map_err(fail)?;
        print!("{report}");
    } else {
        print!("{csv}");
        eprint!("{report}");
    }
    Ok(())
}

fn to_csv(t: &[f64], runs: &[Run]) -> String {
    let mut s = String::from("t");
    for (name, _) in runs {
        for q in ["r", "l", "lambda", "phi", "valid"] {
            let _ = write!(s, ",{name}_{q}");
        }
    }
    s.push('\n');
    for (k, tk) in t.iter().enumerate() {
        let _ = write!(s, "{tk:?}");
        for (_, est) in runs {
            let e = &est[k];
            let _ = write!(
                s,
                ",{:?},{:?},{:?},{:?},{}",
                e.r,
                e.l,
                e.lambda,
                e.phi,
                u8::from(e.valid)
            );
        }
        s.push('\n');
    }
    s
}

fn report(
    args: &Args,
    t: &[f64],
    runs: &[Run],
    obs: &designer::observe::observability::Observability,
    settings: &ObservabilitySettings,
) -> String {
    let mut s = String::new();
    let n = t.len();
    let _ = writeln!(
        s,
        "{}: {n} samples, Δ = {:e} s",
        args.data.display(),
        settings.sample_period
    );
    for (name, est) in runs {
        let valid = est.iter().filter(|e| e.valid).count();
        let last = est.last().map_or(f64::NAN, |e| e.r);
        let _ = writeln!(
            s,
            "{name}: {valid} of {n} samples valid (CI detector, n_σ = {}); final r̂ = {last:.6} Ω",
            settings.n_sigma
        );
    }
    let observable = obs
        .status
        .iter()
        .filter(|&&x| x == Status::Observable)
        .count();
    let blind = blind_intervals(t, obs);
    let _ = writeln!(
        s,
        "observability (32), window i[k−S], i[k], i[k+S], i[k+2S] with S = {}: {observable} of \
         {n} samples observable; {} unobservable intervals (start, end [s], samples, why):",
        settings.stride,
        blind.len()
    );
    for b in &blind {
        let why = match b.why {
            Status::NoCurrent => "no current (within ±n_σ·σ_i)",
            Status::NoExcitation => "no excitation (det (32) within noise)",
            Status::Edge => "record edge",
            Status::Observable => "observable",
        };
        let _ = writeln!(
            s,
            "  {} {} {} {why}",
            seconds(b.start),
            seconds(b.end),
            b.samples
        );
    }
    s
}

/// A time in seconds, rounded to the nanosecond (no `1.5000000000000001e-4`).
fn seconds(t: f64) -> f64 {
    (t * 1e9).round() / 1e9
}
