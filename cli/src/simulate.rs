//! `reldesign simulate MODEL.toml --input IN.csv --out OUT.csv`: replays a
//! recorded or generated input through the hybrid model from rest at z_max.
//! Output columns `t,v,i,z,vz,phi[,Hc],mode` at the input's time points (or a
//! uniform grid for generated inputs).

use std::fmt::Write;
use std::path::PathBuf;
use std::time::Instant;

use designer::description::Drive;
use designer::model::{Model, ModelPlant};
use designer::record::Record;
use designer::replay::{replay_plant, Replay};
use designer::sim::{Options, PiecewiseLinear};
use miette::Report;

use crate::fail;

#[derive(clap::Args)]
pub struct Args {
    /// The actuator description (valve.toml)
    model: PathBuf,
    /// Input record (CSV with columns t and v — or i for current drive); linear between samples
    #[arg(long, conflicts_with_all = ["pulse", "square"])]
    input: Option<PathBuf>,
    /// Output CSV (written atomically); stdout when absent
    #[arg(long)]
    out: Option<PathBuf>,
    /// A rectangular pulse AMPLITUDE:START:END (V or A, s, s); repeatable, 0 elsewhere
    #[arg(long, value_parser = parse_pulse, allow_hyphen_values = true)]
    pulse: Vec<(f64, f64, f64)>,
    /// A square wave HIGH:LOW:PERIOD:DUTY starting high at t = 0
    #[arg(long, allow_hyphen_values = true)]
    square: Option<String>,
    /// End time of a generated input [s] (default: 5 ms after the last pulse edge)
    #[arg(long)]
    t_end: Option<f64>,
    /// Output step of a generated input [s]
    #[arg(long, default_value_t = 1e-5)]
    dt: f64,
    /// Also draw current, flux and position to this SVG file
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Relative tolerance of the integrator
    #[arg(long, default_value_t = 1e-9)]
    rtol: f64,
    /// Run N times and print the median `elapsed_per_run_s=` (and the mean) on stderr (benchmarks)
    #[arg(long, default_value_t = 1)]
    repeat: usize,
}

fn parse_pulse(s: &str) -> Result<(f64, f64, f64), String> {
    let v = numbers(s, 3, "AMPLITUDE:START:END")?;
    if v[2] < v[1] {
        return Err(format!("pulse `{s}`: END must not be before START"));
    }
    Ok((v[0], v[1], v[2]))
}

fn numbers(s: &str, n: usize, form: &str) -> Result<Vec<f64>, String> {
    let v: Vec<f64> = s
        .split(':')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("`{s}`: expected {form} (numbers)"))?;
    if v.len() != n || v.iter().any(|x| !x.is_finite()) {
        return Err(format!(
            "`{s}`: expected {form} ({n} finite numbers separated by `:`)"
        ));
    }
    Ok(v)
}

pub fn run(args: &Args) -> Result<(), Report> {
    let description = crate::load(&args.model)?;
    let drive = description.supply.drive;
    let mut model = Model::build(&description);
    let (input, times) = input_signal(args, drive)?;
    let options = Options {
        rtol: args.rtol,
        ..Options::default()
    };
    let plant = ModelPlant::new(&mut model);
    // Each run is timed on its own: `elapsed_per_run_s` is the median (the
    // statistic the scipy side of benches/simulate_vs_scipy.py uses), and the
    // mean, which includes the cold first run, is printed beside it.
    let mut result = None;
    let mut seconds = Vec::with_capacity(args.repeat.max(1));
    for _ in 0..args.repeat.max(1) {
        drop(result.take()); // free the previous run's buffers before timing the next
        let start = Instant::now();
        result = Some(
            replay_plant(&plant, &model, &input, &times, &options)
                .map_err(|e| fail(format!("{}: simulation failed: {e}", args.model.display())))?,
        );
        seconds.push(start.elapsed().as_secs_f64());
    }
    if args.repeat > 1 {
        let mean = seconds.iter().sum::<f64>() / seconds.len() as f64;
        seconds.sort_by(f64::total_cmp);
        eprintln!(
            "elapsed_per_run_s={:e} elapsed_mean_s={mean:e}",
            seconds[seconds.len() / 2]
        );
    }
    let replay = result.ok_or_else(|| fail("nothing simulated"))?;
    let csv = to_csv(&replay, model.has_field_state());
    // Render everything before writing anything, then write the files
    // together: a failure leaves every existing output untouched.
    let svg = match &args.plot {
        Some(path) => Some((
            path,
            crate::plot::svg(&replay, &description.name).map_err(fail)?,
        )),
        None => None,
    };
    let mut files: Vec<(&std::path::Path, &[u8])> = Vec::new();
    if let Some(path) = &args.out {
        files.push((path, csv.as_bytes()));
    }
    if let Some((path, svg)) = &svg {
        files.push((path, svg.as_bytes()));
    }
    crate::atomic::write_all(&files).map_err(fail)?;
    if args.out.is_none() {
        print!("{csv}");
    }
    Ok(())
}

/// The input signal and the output times.
fn input_signal(args: &Args, drive: Drive) -> Result<(PiecewiseLinear, Vec<f64>), Report> {
    if let Some(path) = &args.input {
        let record = Record::read(path).map_err(fail)?;
        let t = record.time(2).map_err(fail)?;
        let column = match drive {
            Drive::Voltage => "v",
            Drive::Current => "i",
        };
        let u = record.column(column).map_err(fail)?;
        let input = PiecewiseLinear::new(t.clone(), u)
            .map_err(|e| fail(format!("{}: {e}", path.display())))?;
        return Ok((input, t));
    }
    let input = if let Some(sq) = &args.square {
        let v = numbers(sq, 4, "HIGH:LOW:PERIOD:DUTY").map_err(fail)?;
        let t_end = args.t_end.ok_or_else(|| fail("--square needs --t-end"))?;
        PiecewiseLinear::square_wave(v[0], v[1], v[2], v[3], t_end)
    } else if !args.pulse.is_empty() {
        let mut pulses: Vec<(f64, f64, f64)> = args.pulse.iter().map(|&(a, s, e)| (s, e - s, a)).collect();
        pulses.sort_by(|a, b| a.0.total_cmp(&b.0));
        PiecewiseLinear::pulses(0.0, &pulses)
    } else {
        return Err(fail("give the input: --input IN.csv, --pulse AMPLITUDE:START:END, or --square HIGH:LOW:PERIOD:DUTY --t-end T"));
    }
    .map_err(|e| fail(format!("input: {e}")))?;
    let last_edge = args.pulse.iter().map(|p| p.2).fold(0.0, f64::max);
    let t_end = args.t_end.unwrap_or(last_edge + 5e-3);
    if !(args.dt > 0.0) || !(t_end > 0.0) {
        return Err(fail("--dt and --t-end must be positive"));
    }
    // a uniform grid ending at the last whole step within t_end (a shorter
    // last step would make the record non-uniform, which `diagnose` and `fit`
    // reject as measured data)
    let n = (t_end / args.dt * (1.0 + 1e-12)).floor() as usize;
    let times = (0..=n).map(|k| (k as f64 * args.dt).min(t_end)).collect();
    Ok((input, times))
}

fn to_csv(r: &Replay, with_field: bool) -> String {
    let mut s = String::from(if with_field {
        "t,v,i,z,vz,phi,Hc,mode\n"
    } else {
        "t,v,i,z,vz,phi,mode\n"
    });
    let tr = &r.trajectory;
    for k in 0..tr.t.len() {
        let x = &tr.x[k];
        let _ = write!(
            s,
            "{:?},{:?},{:?},{:?},{:?},{:?}",
            tr.t[k], r.voltage[k], r.current[k], x[0], x[1], x[2]
        );
        if with_field {
            let _ = write!(s, ",{:?}", x[3]);
        }
        let _ = writeln!(s, ",{}", tr.mode[k].number());
    }
    s
}
