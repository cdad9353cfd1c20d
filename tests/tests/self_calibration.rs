//! The self-calibrating valve (`examples/self-calibrating-valve.toml`,
//! sensorless at 50 µs) on plants within ±10–20 % of its description in
//! every parameter (`reldesign_tests::variants`), run after run with the
//! runtime's update between runs.
//!
//! In CI: a few plants, a few runs: every operation of every run reaches its
//! stop (no hover, run 1 included). The whole study, with the distribution of
//! the landings over 60 plants, is `#[ignore]`d (seeds 20–39 were never looked
//! at while the calibration's settings were chosen, and seeds 40–59 never
//! while the example's standoff and filter settings were):
//! `cargo test --release -p reldesign-tests --test self_calibration -- --ignored --nocapture`
//! (both: the update on the designer's tapes in f64, and the emitted file's
//! own in f32).

use designer::calibrate::{
    choose, run_runs, run_runs_updated_by, CalibrationDesign, Outcome, Run, Update,
};
use designer::closed_loop::switching_baseline;
use designer::closed_loop::{Measured, Noise};
use designer::description::{parse_str, Description, Operation};
use designer::design::Design;
use rayon::prelude::*;
use reldesign_generated::self_calibrating_valve::ukf::f32 as emitted;
use reldesign_tests::variants::{physics_of, variant, Variant};
use reldesign_tests::{example_path, quantiles};

const EXAMPLE: &str = "self-calibrating-valve.toml";
const STROKE: f64 = 1e-3;

/// The example, or the description `SELF_CALIBRATION_DESCRIPTION` names (a
/// variant of its design to compare in the studies).
fn example() -> (String, Description, Design) {
    let path = std::env::var_os("SELF_CALIBRATION_DESCRIPTION")
        .map_or_else(|| example_path(EXAMPLE), std::path::PathBuf::from);
    let text = std::fs::read_to_string(path).expect("the example");
    let d = parse_str(&text, EXAMPLE).unwrap_or_else(|e| panic!("{e}"));
    let design = Design::new(&d).unwrap_or_else(|e| panic!("{e}"));
    (text, d, design)
}

/// Which update runs between runs.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Updater {
    /// The runtime's, on the designer's tapes in f64 (`loop --runs`).
    Tapes,
    /// The emitted file's own in f32 (`ukf::f32::calibrate` on its `Record`).
    EmittedF32,
}

/// The emitted f32 update of θ from a run's measured samples.
fn emitted_f32(measured: &[Measured], theta: &mut [f64]) -> Result<Outcome<f64>, String> {
    let mut record = emitted::Record::new();
    record.start(emitted::Z_MAX);
    for m in measured {
        let (c, v, i) = (m.commanded as f32, m.voltage as f32, m.current as f32);
        record.push(&emitted::CALIBRATION, c, v, i);
    }
    let mut calibration = emitted::Calibration::new(&emitted::CALIBRATION);
    for (t, x) in calibration.theta.iter_mut().zip(theta.iter()) {
        *t = *x as f32;
    }
    let outcome = emitted::calibrate(&mut calibration, &record);
    for (x, t) in theta.iter_mut().zip(calibration.theta) {
        *x = f64::from(t);
    }
    Ok(match outcome {
        Outcome::Updated { before, after } => Outcome::Updated {
            before: f64::from(before),
            after: f64::from(after),
        },
        Outcome::Refused(why) => Outcome::Refused(why),
    })
}

fn calibration_of(design: &Design) -> CalibrationDesign {
    let ts = design
        .controller
        .as_ref()
        .expect("controller")
        .sample_period;
    choose(design, ts).unwrap_or_else(|e| panic!("{e}"))
}

/// Whether each run's update left the valve's current unexplained.
fn unexplained(calibration: &CalibrationDesign, runs: &[Run]) -> Vec<Option<bool>> {
    let update = |run: &Run| {
        run.operations.iter().find_map(|o| match &o.update {
            Some(Update::Innovations(outcome)) => Some(*outcome),
            _ => None,
        })
    };
    runs.iter()
        .map(|run| update(run).and_then(|o| calibration.leaves_unexplained(&o)))
        .collect()
}

/// The runtime's count: unexplained updates in a row, refusals skipped.
fn in_a_row(flags: &[Option<bool>]) -> u32 {
    flags.iter().fold(0, |count, flag| match flag {
        Some(true) => count + 1,
        Some(false) => 0,
        None => count,
    })
}

/// The measurement noise of `plant`'s runs: seeded by the plant, and by
/// `SELF_CALIBRATION_NOISE=K` (default 0) for another draw of the study.
fn noise(plant: &Variant) -> Noise {
    let draw: u64 = (std::env::var("SELF_CALIBRATION_NOISE").ok())
        .and_then(|k| k.parse().ok())
        .unwrap_or(0);
    Noise::seeded(plant.seed.wrapping_add(draw.wrapping_mul(1_000_003)))
}

fn runs_by(design: &Design, plant: &Variant, n: usize, updater: Updater) -> Vec<Run> {
    let calibration = calibration_of(design);
    let ts = calibration.sample_period;
    let done = match updater {
        Updater::Tapes => run_runs(
            design,
            Some(&calibration),
            Some(&plant.description),
            n,
            ts,
            noise(plant),
            &Default::default(),
        ),
        Updater::EmittedF32 => run_runs_updated_by(
            design,
            &calibration,
            Some(&plant.description),
            n,
            ts,
            noise(plant),
            &Default::default(),
            &mut emitted_f32,
        ),
    };
    done.unwrap_or_else(|e| panic!("plant {}: {e}", plant.seed))
}

fn runs(design: &Design, plant: &Variant, n: usize) -> Vec<Run> {
    runs_by(design, plant, n, Updater::Tapes)
}

#[test]
fn no_operation_hovers_on_plants_within_twenty_per_cent() {
    let (text, _, design) = example();
    for seed in [1, 3, 6] {
        let plant = variant(physics_of(&text), seed);
        for run in runs(&design, &plant, 3) {
            for o in &run.operations {
                assert!(
                    o.outcome.impact_velocity.is_some(),
                    "plant {seed} (factors {:?}), run {}: the {:?} never reached its stop",
                    plant.factors,
                    run.run,
                    o.outcome.operation
                );
            }
        }
    }
}

/// The controller's own "late" (what the firmware reports) agrees with the
/// plant on the design's own valve: every operation lands in time, and none
/// is flagged, though the filter's estimate creeps onto its clamp at the open
/// stop and never reaches the 1 pm contact band (before `ARRIVAL_BAND`,
/// every opening was flagged at t_f + the arrival margin).
#[test]
fn an_operation_in_time_is_not_flagged_late() {
    let (_, d, design) = example();
    let done = run_runs(
        &design,
        None,
        Some(&d),
        2,
        design.controller.as_ref().map_or(5e-5, |c| c.sample_period),
        Noise::seeded(1),
        &Default::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    // the plant's verdict: on its stop by t_f + the arrival margin (t_f − t₀)
    let late_after = d
        .trajectory
        .as_ref()
        .map_or(f64::NAN, |t| 2.0 * t.landing - t.takeoff);
    for run in &done {
        for o in &run.operations {
            let arrival = o.outcome.arrival.unwrap_or(f64::INFINITY);
            assert!(
                arrival <= late_after,
                "run {}: {:?} arrived at {arrival}",
                run.run,
                o.outcome.operation
            );
            assert!(
                !o.outcome.flagged_late,
                "run {}: {:?} flagged late",
                run.run, o.outcome.operation
            );
        }
    }
}

/// The update says when the adapted model still does not explain a valve's
/// current: on a Jiles–Atherton plant (whose remanence the description's
/// saturating core cannot follow) most updates leave more than
/// `UNEXPLAINED`·σ_i², and the runtime's count of them in a row reaches the
/// firmware example's flag (three) within eight runs; on a saturating one no
/// update after the first does (a refused update says neither, and the
/// count skips it). Not every update on the hysteretic plant: its closed
/// loop is chaotic in its last bits (the core's branch follows the sign of
/// φ̇), and a run whose landing happened to suit the model leaves 1.6·σ_i².
/// Tuning seeds (the threshold was chosen on seeds 0–19).
#[test]
fn the_update_flags_a_valve_its_model_cannot_explain() {
    const RUNS: usize = 8;
    const FLAG_AT: u32 = 3; // examples/firmware: `SelfCalibratingValve::unexplained`
    let (text, _, design) = example();
    let calibration = calibration_of(&design);
    for (seed, hysteretic) in [(1, false), (11, true)] {
        let plant = variant(physics_of(&text), seed);
        assert_eq!(plant.hysteretic, hysteretic);
        let flags = unexplained(&calibration, &runs(&design, &plant, RUNS));
        let updates: Vec<bool> = flags[1..].iter().flatten().copied().collect();
        let flagged = updates.iter().filter(|&&f| f).count();
        let longest = (1..=flags.len()).map(|k| in_a_row(&flags[..k])).max();
        let verdict = match hysteretic {
            true => 2 * flagged > updates.len() && longest >= Some(FLAG_AT),
            false => updates.len() >= RUNS / 2 && flagged == 0,
        };
        assert!(
            verdict,
            "plant {seed} (hysteretic: {hysteretic}): unexplained after runs 1–{RUNS} {flags:?}"
        );
    }
}

/// What one plant's study gave, per operation: softness (switching
/// impact / first impact) at run 1, at the last run and the worst of the
/// last five, the highest bounce over the last five [m], and whether any run
/// never reached the stop.
#[derive(Debug, Clone)]
struct Study {
    seed: u64,
    first: [f64; 2],
    last: [f64; 2],
    worst_late: [f64; 2],
    bounce_late: [f64; 2],
    /// The first run from which every later run lands ≥ 20× softer than
    /// switching (`None`: the last run does not).
    settled: [Option<usize>; 2],
    hovered: bool,
    /// The uncontrolled switching reaches both stops (a valve that works).
    switches: bool,
    /// A Jiles–Atherton core (the description's is saturating).
    hysteretic: bool,
    /// Updates in a row up to the last run's that left the valve's current
    /// unexplained (the runtime's `Calibration::unexplained`; the firmware
    /// example flags the valve at 3).
    unexplained: u32,
}

fn study(design: &Design, d: &Description, plant: &Variant, n: usize, updater: Updater) -> Study {
    let baseline = switching_baseline(d, Some(&plant.description), &Default::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let switching = |op: Operation| {
        baseline
            .iter()
            .find(|(o, _)| *o == op)
            .and_then(|(_, v)| *v)
            .map_or(f64::NAN, f64::abs)
    };
    let done = runs_by(design, plant, n, updater);
    let softness = |run: &Run, k: usize| {
        let o = &run.operations[k].outcome;
        o.impact_velocity
            .map_or(0.0, |v| switching(o.operation) / v.abs().max(1e-6))
    };
    let mut s = Study {
        seed: plant.seed,
        first: [0.0; 2],
        last: [0.0; 2],
        worst_late: [f64::INFINITY; 2],
        bounce_late: [0.0; 2],
        settled: [None; 2],
        hovered: false,
        switches: baseline.iter().all(|(_, v)| v.is_some()),
        hysteretic: plant.hysteretic,
        unexplained: in_a_row(&unexplained(&calibration_of(design), &done)),
    };
    for k in 0..2 {
        s.first[k] = softness(&done[0], k);
        s.last[k] = softness(&done[n - 1], k);
        for run in &done[n.saturating_sub(5)..] {
            s.worst_late[k] = s.worst_late[k].min(softness(run, k));
            s.bounce_late[k] = s.bounce_late[k].max(run.operations[k].outcome.highest_bounce);
        }
        let unsettled = done.iter().rposition(|run| softness(run, k) < 20.0);
        s.settled[k] = match unsettled {
            None => Some(1),
            Some(last) if last + 1 < n => Some(last + 2),
            Some(_) => None,
        };
    }
    s.hovered = done
        .iter()
        .flat_map(|r| &r.operations)
        .any(|o| o.outcome.impact_velocity.is_none());
    s
}

#[test]
#[ignore = "the whole study: 60 plants × 10 runs; run with --ignored --nocapture"]
fn the_self_calibration_study_over_sixty_plants() {
    sixty_plants(Updater::Tapes);
}

/// The same study with the emitted file's own f32 update between runs (what
/// a Cortex-M4F firmware runs).
#[test]
#[ignore = "the whole study in f32: 60 plants × 10 runs; run with --ignored --nocapture"]
fn the_emitted_f32_update_over_sixty_plants() {
    sixty_plants(Updater::EmittedF32);
}

fn sixty_plants(updater: Updater) {
    let (text, d, design) = example();
    let physics = physics_of(&text);
    let n = 10;
    let studies: Vec<Study> = (0..60u64)
        .into_par_iter()
        .map(|seed| study(&design, &d, &variant(physics, seed), n, updater))
        .collect();
    for (name, range) in [
        ("tuning seeds 0–19", 0..20),
        ("held-out seeds 20–39", 20..40),
        ("fresh seeds 40–59", 40..60),
    ] {
        let drawn = range.len();
        let part: Vec<&Study> = studies[range].iter().filter(|s| s.switches).collect();
        println!(
            "{name}: {} plants that switch ({} whose uncontrolled switching misses a stop left out), {n} runs each",
            part.len(),
            drawn - part.len()
        );
        summarise(&part, n);
        for (core, hysteretic) in [("saturating", false), ("Jiles–Atherton", true)] {
            let class: Vec<&Study> = (part.iter().copied())
                .filter(|s| s.hysteretic == hysteretic)
                .collect();
            println!("  of which the {} plants with a {core} core:", class.len());
            summarise(&class, n);
        }
    }
    for s in &studies {
        println!("plant {}: {s:?}", s.seed);
    }
    assert!(
        studies.iter().filter(|s| s.switches).all(|s| !s.hovered),
        "an operation hovered"
    );
}

/// The distributions over `part`'s plants.
fn summarise(part: &[&Study], n: usize) {
    for (k, op) in ["closing", "opening"].iter().enumerate() {
        println!(
            "  {op}: softness ×switching at run 1   {}",
            quantiles(part.iter().map(|s| s.first[k]).collect())
        );
        println!(
            "  {op}: softness ×switching at run {n}  {}",
            quantiles(part.iter().map(|s| s.last[k]).collect())
        );
        println!(
            "  {op}: worst of runs {}–{n}          {}",
            n - 4,
            quantiles(part.iter().map(|s| s.worst_late[k]).collect())
        );
        let settled: Vec<f64> = (part.iter())
            .filter_map(|s| s.settled[k].map(|r| r as f64))
            .collect();
        println!(
            "  {op}: ≥ 20× from run r on, for good: {} of {} plants, r {}",
            settled.len(),
            part.len(),
            if settled.is_empty() {
                "—".to_string()
            } else {
                quantiles(settled)
            }
        );
        println!(
            "  {op}: highest bounce of runs {}–{n} [% stroke] {}",
            n - 4,
            quantiles(
                part.iter()
                    .map(|s| 100.0 * s.bounce_late[k] / STROKE)
                    .collect()
            )
        );
    }
    let met = part
        .iter()
        .filter(|s| (0..2).all(|k| s.worst_late[k] >= 20.0 && s.bounce_late[k] <= 0.01 * STROKE))
        .count();
    let hovered = part.iter().filter(|s| s.hovered).count();
    println!(
        "  plants meeting ≥ 20× and bounces ≤ 1 % over runs {}–{n}: {met} of {}",
        n - 4,
        part.len()
    );
    println!("  plants with an operation that never reached its stop: {hovered}");
    let flagged = part.iter().filter(|s| s.unexplained >= 3).count();
    println!(
        "  plants flagged after run {n} (its update and the two before it each left > {}·σ_i² of the current unexplained): {flagged} of {}",
        designer::calibrate::UNEXPLAINED,
        part.len()
    );
}
