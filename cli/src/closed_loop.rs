//! `reldesign loop MODEL.toml --out OUT.csv [--plant PLANT.toml] [--sample-period S]
//! [--duration S] [--plot FILE.svg]`: the designed controller (whichever law) in a
//! sampled loop with zero-order hold on the hybrid model of the plant, the
//! operations of `[trajectory]` one after the other. Writes
//! `t,u,i,z,vz,phi[,Hc],mode,z_ref` at each sample, plus
//! `z_hat,v_hat,phi_hat[,Hc_hat]` where `[controller] estimator` names the
//! observer that drives the controller, and prints, per operation, the first
//! impact, RMSE_z during the motion and the bounces.

use std::fmt::Write as _;
use std::path::PathBuf;

use designer::closed_loop::{
    check_sample_period, loop_spacing, resample_observer, run_hold, run_spaced_loop, HoldOutcome,
    LoopRun, Noise, OperationOutcome, HOLD_DURATION, SETTLED_FRACTION, SETTLING_WINDOW,
};
use designer::description::{Law, ModelSurface};
use designer::design::Design;
use designer::sim::Options;
use miette::Report;
use plotters::prelude::*;

use crate::{atomic, fail};

#[derive(clap::Args)]
pub struct Args {
    /// The actuator description, with [trajectory] and [controller]
    pub(crate) model: PathBuf,
    /// Output CSV (written atomically; required without --runs; with --runs, the last run's)
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
    /// Run every operation N times in succession, the design's self-calibration
    /// (`[controller] self_calibration`) updated between runs as the emitted code does
    #[arg(long)]
    pub(crate) runs: Option<usize>,
    /// With --runs: print the runs as JSON (the contract of `loop --runs N --json`)
    #[arg(long)]
    pub(crate) json: bool,
    /// The plant's description (default: MODEL itself): a device other than the design's
    #[arg(long)]
    pub(crate) plant: Option<PathBuf>,
    /// Sample period T_s [s] (default: controller.sample_period)
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) sample_period: Option<f64>,
    /// Simulated time [s] (default: every operation once, takeoff + landing each; with an estimator or another --plant, 2·(takeoff + landing) + the motion time each, room for the no-hover push)
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) duration: Option<f64>,
    /// Also draw position and reference, input and current to this SVG file (with
    /// --runs: each run's first impact speeds and adapted parameters)
    #[arg(long)]
    pub(crate) plot: Option<PathBuf>,
    /// Seed of the measurement noise, where an observer drives the controller
    #[arg(long, default_value_t = 0)]
    pub(crate) seed: u64,
    /// The measurement noise σ_v,σ_i [V,A] the observer reads (default: the observer's own
    /// voltage_noise, current_noise)
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub(crate) noise: Option<Vec<f64>>,
    /// The plant's initial core field H_c [A/m] (a Jiles–Atherton plant; the observer
    /// still starts from 0)
    #[arg(long, allow_hyphen_values = true, default_value_t = 0.0)]
    pub(crate) initial_field: f64,
    /// The plant's initial state z,v,phi [m, m/s, Wb] (law = "backstepping"; default: at
    /// rest on the spring's stop without flux)
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub(crate) initial_state: Option<Vec<f64>>,
}

pub fn run(args: &Args) -> Result<(), Report> {
    if args.json {
        return Err(fail(
            "--json: only with --runs N (the other forms print a summary)",
        ));
    }
    let Some(out) = &args.out else {
        return Err(fail("--out OUT.csv is required (or --runs N --json)"));
    };
    let description = crate::load(&args.model)?;
    let file = args.model.display().to_string();
    let plant = args.plant.as_deref().map(crate::load).transpose()?;
    let Some(controller) = &description.controller else {
        return Err(fail(format!(
            "{file}: `loop` runs the designed controller: the description needs [trajectory] and [controller]"
        )));
    };
    let ts = positive("--sample-period", args.sample_period)?.unwrap_or(controller.sample_period);
    let duration = positive("--duration", args.duration)?;
    if !args.initial_field.is_finite() {
        return Err(fail(format!(
            "--initial-field: expected a finite number [A/m], found {}",
            args.initial_field
        )));
    }
    let noise = noise_of(args)?;
    let holds = matches!(
        controller.law,
        Law::ModelSlidingMode(ModelSurface {
            position: Some(_),
            ..
        })
    );
    let positions = matches!(controller.law, Law::Backstepping(_));
    let initial = match args.initial_state.as_deref() {
        None => None,
        Some(&[z, v, phi]) if positions && [z, v, phi].iter().all(|x| x.is_finite()) => {
            Some([z, v, phi])
        }
        Some(other) if positions => {
            return Err(fail(format!(
            "--initial-state: expected three finite numbers z,v,phi [m, m/s, Wb], found {other:?}"
        )))
        }
        Some(_) => return Err(fail(
            "--initial-state: only for law = \"backstepping\" (the other laws start at rest at \
                 the first operation's z₀)",
        )),
    };
    if !holds && !positions {
        check_sample_period(&description, ts).map_err(|e| fail(format!("{file}: {e}")))?;
    }
    let design = design_at(&description, args, ts, &file)?;
    if positions {
        let (run, summary) =
            crate::position_loop::run(&design, plant.as_ref(), ts, duration, noise, initial)
                .map_err(|e| fail(format!("{file}: {e}")))?;
        let extra = |k: usize| crate::position_loop::columns(&run, k);
        let csv = to_csv(
            &run.run,
            design.model.dim() > 3,
            Some((",switching,lyapunov,desired_force", &extra)),
        );
        write_outputs(args, out, &csv, &run.run, &description.name, ts)?;
        print!("{summary}");
        return Ok(());
    }
    let run = if holds {
        run_hold(
            &design,
            plant.as_ref(),
            ts,
            duration,
            noise,
            args.initial_field,
            &Options::default(),
        )
    } else {
        run_spaced_loop(
            &design,
            plant.as_ref(),
            ts,
            duration,
            loop_spacing(&design, plant.as_ref()),
            noise,
            &Options::default(),
        )
    }
    .map_err(|e| fail(format!("{file}: {e}")))?;
    let csv = to_csv(&run, design.model.dim() > 3, None);
    write_outputs(args, out, &csv, &run, &description.name, ts)?;
    if holds {
        let outcome = run.hold_outcome();
        print!("{}", hold_summary(&outcome, run.z_ref.first().copied(), ts));
        return Ok(());
    }
    let t = description
        .trajectory
        .as_ref()
        .map_or((0.0, 0.0), |t| (t.takeoff, t.landing));
    print!(
        "{}",
        summary(
            &run.outcomes(t.0, t.1),
            controller.law.name(),
            ts,
            designer::closed_loop::late_after(&design)
        )
    );
    Ok(())
}

/// The CSV and, with `--plot`, the run's SVG, written together atomically.
pub(crate) fn write_outputs(
    args: &Args,
    out: &std::path::Path,
    csv: &str,
    run: &LoopRun,
    name: &str,
    ts: f64,
) -> Result<(), Report> {
    let svg = match &args.plot {
        Some(_) => Some(plot(run, name, ts).map_err(fail)?),
        None => None,
    };
    let mut files: Vec<(&std::path::Path, &[u8])> = vec![(out, csv.as_bytes())];
    if let (Some(path), Some(svg)) = (&args.plot, &svg) {
        files.push((path.as_path(), svg.as_bytes()));
    }
    atomic::write_all(&files).map_err(fail)
}

/// `Some(x)` must be positive and finite.
pub(crate) fn positive(name: &str, x: Option<f64>) -> Result<Option<f64>, Report> {
    match x {
        Some(v) if !(v.is_finite() && v > 0.0) => Err(fail(format!(
            "{name}: expected a positive number of seconds, found {v}"
        ))),
        other => Ok(other),
    }
}

fn summary(outcomes: &[OperationOutcome], law: &str, ts: f64, late_after: f64) -> String {
    let mut s = format!("{law} at T_s = {ts:e} s\n");
    for o in outcomes {
        let impact = o
            .impact_velocity
            .map_or("never reached the stop".to_string(), |v| {
                format!("{v:+.4e} m/s")
            });
        let arrival = o
            .arrival
            .map_or(String::new(), |t| format!(" at {:.4} ms", t * 1e3));
        let verdict = o.verdict(late_after);
        let _ = writeln!(
            s,
            "  {:<8} first impact {impact}{arrival}, RMSE_z {} during the motion, {} bounce(s){verdict}",
            o.operation.name(),
            o.rmse_z
                .map_or("— (no sample)".into(), |r| format!("{r:.3e} m")),
            o.bounces
        );
    }
    s
}

fn hold_summary(o: &HoldOutcome, z_ref: Option<f64>, ts: f64) -> String {
    let mut s = format!(
        "model-sliding-mode hold at z_ref = {:e} m, T_s = {ts:e} s\n",
        z_ref.unwrap_or(f64::NAN)
    );
    let settled = o.settling_time.map_or(
        format!("never settled within the run (default {HOLD_DURATION:e} s: --duration)"),
        |t| {
            format!(
                "settled at {:.3} ms (the error's {} ms average within {} % of the initial error)",
                t * 1e3,
                SETTLING_WINDOW * 1e3,
                SETTLED_FRACTION * 100.0
            )
        },
    );
    let _ = writeln!(s, "  {settled}");
    let _ = writeln!(
        s,
        "  steady error {:+.3e} m (mean over the last fifth), ripple ±{:.3e} m",
        o.steady_error, o.steady_band
    );
    if let Some(e) = &o.observer {
        let hc = |x: Option<f64>| x.map_or(String::new(), |h| format!(", H_c {h:.3e} A/m"));
        let _ = writeln!(
            s,
            "  observer error: transient max |Δz| {:.3e} m{}; steady RMS |Δz| {:.3e} m{}",
            e.transient_z,
            hc(e.transient_hc),
            e.steady_z,
            hc(e.steady_hc)
        );
    }
    s
}

/// Extra columns: their header (with the leading comma) and each sample's.
type Extra<'a> = (&'a str, &'a dyn Fn(usize) -> String);

pub(crate) fn to_csv(run: &LoopRun, with_field: bool, extra: Option<Extra>) -> String {
    let tr = &run.trajectory;
    let mut s = String::from(if with_field {
        "t,u,i,z,vz,phi,Hc,mode,z_ref"
    } else {
        "t,u,i,z,vz,phi,mode,z_ref"
    });
    if run.estimates.is_some() {
        s.push_str(if with_field {
            ",z_hat,v_hat,phi_hat,Hc_hat"
        } else {
            ",z_hat,v_hat,phi_hat"
        });
    }
    if let Some((header, _)) = extra {
        s.push_str(header);
    }
    s.push('\n');
    for k in 0..tr.t.len() {
        let x = &tr.x[k];
        let _ = write!(
            s,
            "{:?},{:?},{:?},{:?},{:?},{:?}",
            tr.t[k], tr.u[k], run.current[k], x[0], x[1], x[2]
        );
        if with_field {
            let _ = write!(s, ",{:?}", x[3]);
        }
        let _ = write!(s, ",{},{:?}", tr.mode[k].number(), run.z_ref[k]);
        if let Some(e) = run.estimates.as_ref().and_then(|e| e.get(k)) {
            let _ = write!(s, ",{:?},{:?},{:?}", e.z, e.v, e.phi);
            if with_field {
                let _ = write!(s, ",{:?}", e.hc.unwrap_or(f64::NAN));
            }
        }
        if let Some((_, columns)) = extra {
            s.push_str(&columns(k));
        }
        s.push('\n');
    }
    s
}

fn plot(run: &LoopRun, name: &str, ts: f64) -> Result<String, String> {
    let mut out = String::new();
    {
        let e = |e: plotters::drawing::DrawingAreaErrorKind<std::io::Error>| e.to_string();
        let root = SVGBackend::with_string(&mut out, (900, 1000)).into_drawing_area();
        root.fill(&WHITE).map_err(e)?;
        let root = root
            .titled(
                &format!("{name}: closed loop at T_s = {ts:e} s"),
                ("sans-serif", 22),
            )
            .map_err(e)?;
        let tr = &run.trajectory;
        let t: Vec<f64> = tr.t.iter().map(|t| t * 1e3).collect();
        let z: Vec<f64> = tr.x.iter().map(|x| x[0] * 1e3).collect();
        let zr: Vec<f64> = run.z_ref.iter().map(|z| z * 1e3).collect();
        let phi: Vec<f64> = tr.x.iter().map(|x| x[2] * 1e6).collect();
        // the observer's estimates, where one drives the controller
        let (z_hat, phi_hat): (Vec<f64>, Vec<f64>) = (run.estimates.iter().flatten())
            .map(|e| (e.z * 1e3, e.phi * 1e6))
            .unzip();
        let mut position = vec![(zr.as_slice(), RED, "z_ref"), (z.as_slice(), BLACK, "z")];
        let mut flux = vec![(phi.as_slice(), MAGENTA, "φ")];
        if run.estimates.is_some() {
            position.push((z_hat.as_slice(), CYAN, "ẑ"));
            flux.push((phi_hat.as_slice(), CYAN, "φ̂"));
        }
        let series: [(&str, Vec<(&[f64], RGBColor, &str)>); 4] = [
            ("position [mm]", position),
            ("flux [µWb]", flux),
            ("input u", vec![(&tr.u, BLUE, "u")]),
            ("current i [A]", vec![(&run.current, GREEN, "i")]),
        ];
        let panels = root.split_evenly((4, 1));
        for (area, (label, lines)) in panels.iter().zip(series) {
            crate::plot::panel(area, &t, &lines, label)?;
        }
        root.present().map_err(e)?;
    }
    Ok(out)
}

/// `description` designed at the loop's sample period `ts` (the observer's
/// process noise rescaled where `--sample-period` moved it).
pub(crate) fn design_at(
    description: &designer::description::Description,
    args: &Args,
    ts: f64,
    file: &str,
) -> Result<Design, Report> {
    let mut designed = description.clone();
    if let Some(c) = &mut designed.controller {
        c.sample_period = ts;
    }
    if let (Some(o), Some(_)) = (&mut designed.observer, args.sample_period) {
        resample_observer(o, ts);
    }
    Design::new(&designed).map_err(|e| fail(format!("{file}: {e}")))
}

/// `--seed` and `--noise` as the loop's measurement noise.
pub(crate) fn noise_of(args: &Args) -> Result<Noise, Report> {
    let sigma = match args.noise.as_deref() {
        None => None,
        Some(&[v, i]) if v >= 0.0 && i >= 0.0 && v.is_finite() && i.is_finite() => Some([v, i]),
        Some(other) => {
            return Err(fail(format!(
                "--noise: expected two numbers σ_v,σ_i ≥ 0 [V,A], found {other:?}"
            )))
        }
    };
    Ok(Noise {
        seed: args.seed,
        sigma,
    })
}
