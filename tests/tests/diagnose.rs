//! Tests that hide an effect (issue 5 §3): a bundled example, one extension of
//! the vocabulary added in secret (`reldesign_tests::hidden`), a simulated
//! noisy experiment; `diagnose` sees only the baseline model and the data
//! and must name the cause, with gain ≥ 50 % on the whole record and on its
//! held-out end, and recover the hidden value of its effect parameter within
//! 3 standard errors and 15 % (issue 12 §3). Data from the baseline itself
//! must give `none`.
//!
//! The CI matrix covers every cause on at least two actuators, both
//! excitations, with and without the `z` column; `full_matrix` (ignored:
//! `cargo test --release -p reldesign-tests --test diagnose -- --ignored`)
//! runs every cause × actuator × excitation × column combination.

use designer::description::parse_str;
use reldesign_identify::diagnose::{
    diagnose, diagnose_causes, Cause, Causes, Diagnosis, FittedParameter, Options,
};
use reldesign_tests::hidden::{hidden_case, Excitation, HiddenCase};
use reldesign_tests::outside::Outside;

#[derive(Debug, Clone, Copy)]
enum Drive {
    Square,
    Pulses,
}

use Cause::{Bouncing, EddyCurrents, Fringing, Hysteresis, ResistanceDrift, Saturation};
use Drive::{Pulses, Square};

/// One hidden-effect record to diagnose.
#[derive(Debug, Clone, Copy)]
struct Case<A> {
    /// The actuator: a bundled example's file name, or the index of a
    /// generated device.
    actuator: A,
    /// The effect hidden in the data.
    cause: Cause,
    drive: Drive,
    /// Whether the record carries the `z` column.
    with_z: bool,
    seed: u64,
}

impl<A: std::fmt::Display> std::fmt::Display for Case<A> {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        let Case { cause, drive, .. } = self;
        let (z, seed) = (self.with_z, self.seed);
        write!(f, "{} {cause} {drive:?} z={z} seed={seed}", self.actuator)
    }
}

impl Case<&str> {
    /// The record of the case on its bundled example.
    fn record(&self) -> HiddenCase {
        let excitation = excitation(self.actuator, self.drive);
        hidden_case(
            self.actuator,
            self.cause,
            &excitation,
            self.with_z,
            self.seed,
        )
    }
}

impl Case<u64> {
    /// The record of the case on its generated device.
    fn record(&self) -> HiddenCase {
        device_case_with(
            self.actuator,
            self.cause,
            self.with_z,
            self.seed,
            |base| match self.drive {
                Square => Excitation::square_wave(base),
                Pulses => Excitation::pulses(base),
            },
        )
    }
}

const SEMERA: &str = "semera-valve.toml";
const TRACKING: &str = "perfect-tracking-valve.toml";
const SLIDING: &str = "sliding-mode-valve.toml";
const TABLE: &str = "table-gap-valve.toml";

#[rustfmt::skip]
const CI_CASES: &[Case<&str>] = &[
    Case { actuator: SEMERA,   cause: EddyCurrents,    drive: Square, with_z: false, seed: 1 },
    Case { actuator: TRACKING, cause: EddyCurrents,    drive: Pulses, with_z: true,  seed: 2 },
    Case { actuator: SEMERA,   cause: Saturation,      drive: Pulses, with_z: false, seed: 3 },
    Case { actuator: SLIDING,  cause: Saturation,      drive: Square, with_z: true,  seed: 4 },
    Case { actuator: TABLE,    cause: Hysteresis,      drive: Pulses, with_z: false, seed: 5 },
    Case { actuator: SEMERA,   cause: Hysteresis,      drive: Square, with_z: true,  seed: 6 },
    Case { actuator: SLIDING,  cause: Fringing,        drive: Square, with_z: false, seed: 7 },
    Case { actuator: SEMERA,   cause: Fringing,        drive: Pulses, with_z: true,  seed: 8 },
    Case { actuator: TRACKING, cause: ResistanceDrift, drive: Square, with_z: false, seed: 9 },
    Case { actuator: SLIDING,  cause: ResistanceDrift, drive: Pulses, with_z: true,  seed: 10 },
    Case { actuator: SEMERA,   cause: Bouncing,        drive: Square, with_z: true,  seed: 11 },
    Case { actuator: TRACKING, cause: Bouncing,        drive: Pulses, with_z: false, seed: 12 },
    Case { actuator: SEMERA,   cause: Cause::None,     drive: Square, with_z: false, seed: 13 },
    Case { actuator: SLIDING,  cause: Cause::None,     drive: Pulses, with_z: true,  seed: 14 },
];

fn excitation(example: &str, drive: Drive) -> Excitation {
    let path = reldesign_tests::example_path(example);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let desc = parse_str(&text, example).unwrap_or_else(|e| panic!("{e}"));
    let base = reldesign_tests::hidden::baseline(&desc);
    match drive {
        Drive::Square => Excitation::square_wave(&base),
        Drive::Pulses => Excitation::pulses(&base),
    }
}

/// Diagnoses a case from its two texts only (as the CLI would read the
/// files), with the named cause's fitted parameters.
fn run(case: &HiddenCase) -> (Diagnosis, Vec<FittedParameter>) {
    let (model, data) = case.inputs();
    let d = diagnose(&model, &data, &Options::default()).unwrap_or_else(|e| panic!("{e}"));
    let parameters = d.parameters(&model, &data);
    (d, parameters)
}

/// The key whose hidden value the named cause must recover (issue 12 §3).
fn recovered_key(cause: Cause) -> Option<&'static str> {
    match cause {
        Cause::EddyCurrents => Some("coil.eddy"),
        Cause::Saturation => Some("core.phi_sat"),
        Cause::ResistanceDrift => Some("coil.resistance_drift"),
        Cause::Bouncing => Some("mechanics.restitution"),
        Cause::Fringing => Some("gap.area"),
        Cause::Hysteresis | Cause::None | Cause::Unexplained => None,
    }
}

/// Standard errors and relative distance within which the hidden value
/// must lie from the fitted one.
const RECOVERY_SE: f64 = 3.0;
const RECOVERY_RELATIVE: f64 = 0.15;

/// Why the fitted value of the hidden parameter misses the truth, if it does.
fn recovery(case: &HiddenCase, parameters: &[FittedParameter]) -> Option<String> {
    let key = recovered_key(case.cause)?;
    let truth = case.drawn.iter().find(|(k, _)| k == key)?.1;
    let Some(p) = parameters.iter().find(|p| p.path == key) else {
        return Some(format!("{key}: not among the fitted parameters"));
    };
    let off = (p.value - truth).abs();
    eprintln!(
        "  recovered {key}: {:+.2} % of the hidden value, {:.1} standard errors",
        100.0 * (p.value / truth - 1.0),
        off / p.std_error
    );
    let ok = off <= RECOVERY_SE * p.std_error && off <= RECOVERY_RELATIVE * truth.abs();
    (!ok).then(|| {
        format!(
            "{key} = {:.4e} ± {:.2e} vs hidden {truth:.4e} ({:.1} SE, {:+.1} %)",
            p.value,
            p.std_error,
            off / p.std_error,
            100.0 * (p.value / truth - 1.0)
        )
    })
}

/// The held-out part carries the effect when the baseline's error there
/// exceeds this multiple of the noise floor.
const HELD_OUT_VISIBLE: f64 = 3.0;

/// What went wrong with one case, or nothing.
fn check(c: &Case<&str>) -> Option<String> {
    let case = c.record();
    let (d, parameters) = run(&case);
    let missed = (d.cause == c.cause)
        .then(|| recovery(&case, &parameters))
        .flatten();
    let held = d.held_out.map_or(f64::NAN, |h| h.gain);
    let summary = format!(
        "{c}: answered {} (gain {:.1} %, held-out {:.1} %; \
         baseline {:.3} %, extended {:.3} %, floor {:.3} %; ranking {}; not identifiable {:?}; rejected {:?})",
        d.cause,
        100.0 * d.whole.gain,
        100.0 * held,
        100.0 * d.whole.baseline_wnrmse,
        100.0 * d.whole.extended_wnrmse,
        100.0 * d.noise_floor,
        reldesign_tests::hidden::ranking_summary(&d),
        d.not_identifiable,
        d.rejected
            .iter()
            .map(|r| (r.cause, r.reason()))
            .collect::<Vec<_>>()
    );
    eprintln!("{summary}");
    let right = d.cause == c.cause;
    // The held-out end shows the effect only when the baseline misses it
    // there (a bounce or a fringing error may fall in the fitted part only).
    let held_shows_effect = d
        .held_out
        .is_some_and(|h| h.baseline_wnrmse > HELD_OUT_VISIBLE * d.noise_floor);
    let held_ok = !held_shows_effect || held >= 0.5;
    let gained = c.cause == Cause::None || (d.whole.gain >= 0.5 && held_ok);
    if let Some(m) = &missed {
        eprintln!("  recovery: {m}");
    }
    (!right || !gained || missed.is_some())
        .then(|| format!("{summary}\n  {}", missed.unwrap_or_default()))
}

fn check_all(cases: &[Case<&str>]) {
    check_all_but(cases, 0);
}

/// Every case right but at most `allowed`.
fn check_all_but(cases: &[Case<&str>], allowed: usize) {
    let cases: Vec<&Case<&str>> = cases.iter().filter(picked).collect();
    let failures: Vec<String> = cases.iter().filter_map(|c| check(c)).collect();
    assert!(
        failures.len() <= allowed,
        "{} of {} cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

#[test]
fn every_cause_is_found_on_two_actuators() {
    check_all(CI_CASES);
}

#[test]
#[ignore = "slow: every cause × actuator × excitation × z column"]
fn full_matrix() {
    let mut cases = Vec::new();
    let mut seed = 100;
    for example in [SEMERA, TRACKING, SLIDING, TABLE] {
        for cause in Cause::EXTENSIONS.into_iter().chain([Cause::None]) {
            if example == TRACKING && cause == Cause::Hysteresis {
                // Its [controller] needs a core the design supports (not JA).
                continue;
            }
            for drive in [Square, Pulses] {
                for with_z in [false, true] {
                    seed += 1;
                    cases.push(Case {
                        actuator: example,
                        cause,
                        drive,
                        with_z,
                        seed,
                    });
                }
            }
        }
    }
    check_all_but(&cases, FULL_MATRIX_MISSES);
}

/// Misses the whole matrix allows: the one nested confusion it has
/// (a saturation on the perfect-tracking valve's pulses with `z`, answered
/// hysteresis: docs/validation/diagnose.md). Every recovered value lies
/// within 3 standard errors (measured: at most 2.3; one at 3.1 before the
/// polish fitted the edges' instants).
const FULL_MATRIX_MISSES: usize = 1;

/// Writes the CI cases as files for the command line:
/// `DIAGNOSE_CASES=/tmp/cases cargo test -p reldesign-tests --test diagnose write_cases -- --ignored`.
#[test]
#[ignore = "writes files for manual runs of `reldesign diagnose`"]
fn write_cases() {
    let Ok(dir) = std::env::var("DIAGNOSE_CASES") else {
        return;
    };
    for c in CI_CASES {
        let case = c.record();
        let example = c.actuator.trim_end_matches(".toml");
        let name = format!("{example}-{}-{}", c.cause, c.seed);
        reldesign_tests::hidden::write_case(&std::path::Path::new(&dir).join(name), &case);
    }
}

/// Samples of the benchmark's long records (issue 5 §5: 40 000).
const LONG_SAMPLES: usize = 40_000;

/// Writes one long record per cause (and one of the baseline itself) of the
/// SEMERA valve for `benches/diagnose.sh`: the square-wave preset repeated
/// until the record has at least [`LONG_SAMPLES`] samples at
/// `hidden::SAMPLE_PERIOD`, default noise, no `z` column:
/// `DIAGNOSE_LONG_CASES=/tmp/long cargo test --release -p reldesign-tests --test diagnose write_long_case -- --ignored`.
#[test]
#[ignore = "writes files for the diagnose benchmark"]
fn write_long_case() {
    let Ok(dir) = std::env::var("DIAGNOSE_LONG_CASES") else {
        return;
    };
    let once = excitation(SEMERA, Drive::Square);
    let per_run = once.duration() / reldesign_tests::hidden::SAMPLE_PERIOD;
    let long = once.repeated((LONG_SAMPLES as f64 / per_run).ceil() as usize);
    for (k, cause) in Cause::EXTENSIONS
        .into_iter()
        .chain([Cause::None])
        .enumerate()
    {
        let case = hidden_case(SEMERA, cause, &long, false, 500 + k as u64);
        let rows = case
            .data_csv
            .lines()
            .filter(|l| !l.starts_with('#'))
            .count()
            - 1;
        assert!(rows >= LONG_SAMPLES, "{cause}: only {rows} samples");
        let name = format!("{}-{cause}-long", SEMERA.trim_end_matches(".toml"));
        let case_dir = std::path::Path::new(&dir).join(name);
        reldesign_tests::hidden::write_case(&case_dir, &case);
        // the hidden values, for the benchmark to report how near it came
        let hidden: String = (case.drawn.iter())
            .map(|(key, value)| format!("{key} {value:e}\n"))
            .collect();
        let path = case_dir.join("hidden.txt");
        std::fs::write(&path, hidden).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    }
}

/// Device families of the generator (`reldesign_tests::devices`) whose
/// hidden-effect records the confusion matrix is drawn from.
const DEVICE_SEED: u64 = 12;

/// A hidden-effect case on generated device `index` under the excitation
/// `drive` makes of its baseline.
fn device_case_with(
    index: u64,
    cause: Cause,
    with_z: bool,
    seed: u64,
    drive: impl Fn(&designer::description::Description) -> Excitation,
) -> HiddenCase {
    let device = reldesign_tests::devices::device(DEVICE_SEED, index, false);
    let file = format!("{}.toml", device.name);
    let base = reldesign_tests::hidden::baseline(&device.description());
    let excitation = drive(&base);
    reldesign_tests::hidden::hidden_case_of(&device.toml, &file, cause, &excitation, with_z, seed)
}

/// Rows: the hidden cause; columns: the answer; and the failures.
struct Confusion {
    counts: Vec<(Cause, Cause, usize)>,
    failures: Vec<String>,
    /// Answered `unexplained` with the hidden cause as the partial one: its
    /// fit stops far from the truth (not a failure: the spec's answer).
    unexplained_right: Vec<String>,
}

impl Confusion {
    fn new() -> Confusion {
        Confusion {
            counts: Vec::new(),
            failures: Vec::new(),
            unexplained_right: Vec::new(),
        }
    }

    fn add(&mut self, hidden: Cause, answered: Cause) {
        match self
            .counts
            .iter_mut()
            .find(|(h, a, _)| *h == hidden && *a == answered)
        {
            Some(c) => c.2 += 1,
            None => self.counts.push((hidden, answered, 1)),
        }
    }

    /// The matrix as a Markdown table.
    fn table(&self) -> String {
        let causes: Vec<Cause> = (Cause::EXTENSIONS.into_iter())
            .chain([Cause::None, Cause::Unexplained])
            .collect();
        let mut s = format!(
            "| hidden ↓ answered → | {} |\n|---|{}\n",
            causes
                .iter()
                .map(|c| c.name())
                .collect::<Vec<_>>()
                .join(" | "),
            "---|".repeat(causes.len())
        );
        for h in causes
            .iter()
            .filter(|h| self.counts.iter().any(|c| c.0 == **h))
        {
            let row: Vec<String> = causes
                .iter()
                .map(|a| {
                    let n = self
                        .counts
                        .iter()
                        .find(|(x, y, _)| x == h && y == a)
                        .map_or(0, |c| c.2);
                    n.to_string()
                })
                .collect();
            s.push_str(&format!("| {} | {} |\n", h.name(), row.join(" | ")));
        }
        s
    }
}

/// Diagnoses hidden-effect cases on generated devices: the confusion matrix
/// and what went wrong (a wrong cause, or a named cause without gain).
/// Whether `DIAGNOSE_SEEDS` (e.g. `367,381`) picks the case, to run those
/// records of a matrix alone (all where it is not set).
fn picked<A>(case: &&Case<A>) -> bool {
    let seeds: Option<Vec<u64>> = std::env::var("DIAGNOSE_SEEDS")
        .ok()
        .map(|s| s.split(',').filter_map(|x| x.trim().parse().ok()).collect());
    seeds.is_none_or(|p| p.contains(&case.seed))
}

fn confusion(cases: &[Case<u64>]) -> Confusion {
    let mut m = Confusion::new();
    for c in cases.iter().filter(picked) {
        let case = c.record();
        let (answer, parameters) = run_causes(&case);
        let d = answer.first();
        let names = answer.names();
        let cause = c.cause;
        let answered = names.first().copied().unwrap_or(Cause::None);
        m.add(cause, answered);
        let summary = format!(
            "device_{DEVICE_SEED}_{c}: answered {} \
             (gain {:.1} %; baseline {:.3} %, extended {:.3} %, floor {:.3} %, left {:.2}× the floor)",
            names.iter().map(|c| c.name()).collect::<Vec<_>>().join(" + "),
            100.0 * answer.gain(),
            100.0 * d.whole.baseline_wnrmse,
            100.0 * answer.last().whole.extended_wnrmse,
            100.0 * d.noise_floor,
            answer.residual.over_floor,
        );
        eprintln!("{summary}");
        // the spec's answer where the best extension leaves the residual
        // well above the noise, with the hidden cause found as partial
        if answered == Cause::Unexplained && answer.partial() == [cause] {
            m.unexplained_right.push(summary);
            continue;
        }
        let missed = (answered == cause)
            .then(|| recovery(&case, &parameters))
            .flatten();
        let gained = cause == Cause::None || answer.gain() >= 0.5;
        if answered != cause || names.len() > 1 || !gained || missed.is_some() {
            m.failures
                .push(format!("{summary} {}", missed.unwrap_or_default()));
        }
    }
    eprintln!("{}", m.table());
    eprintln!(
        "unexplained, the hidden cause the partial one ({}):\n{}",
        m.unexplained_right.len(),
        m.unexplained_right.join("\n")
    );
    m
}

/// The CLI's answer for a case (forward selection, joint fit, `unexplained`)
/// with the first cause's fitted parameters.
fn run_causes(case: &HiddenCase) -> (Causes, Vec<FittedParameter>) {
    let (model, data) = case.inputs();
    let answer =
        diagnose_causes(&model, &data, &Options::default()).unwrap_or_else(|e| panic!("{e}"));
    let parameters = answer.first().parameters(&model, &data);
    (answer, parameters)
}

/// The measurement chain's effects and a wrong spring, outside the
/// vocabulary (`reldesign_tests::outside`).
const CHAIN_AND_SPRING: [Outside; 6] = [
    Outside::ProbeGain(1.08),
    Outside::ProbeGain(0.92),
    Outside::DriverDelay(120e-6),
    Outside::ProbeLag(100e-6),
    Outside::Spring(1.3),
    Outside::Spring(0.7),
];

/// Coulomb friction of 10 % and 30 % of the spring's force over the stroke.
const FRICTIONS: [Outside; 2] = [Outside::Friction(0.1), Outside::Friction(0.3)];

/// Answers to records of effects outside the vocabulary, counted.
#[derive(Default)]
struct Tally {
    total: usize,
    unexplained: usize,
    /// `none` where the record shows no trace above the noise (the
    /// description leaves less than `NONE_ABOVE_FLOOR` floors).
    unseen: usize,
    /// The lines of a cause named with a gain below [`LOW_GAIN`], the
    /// residual left below the `unexplained` test's floors (the spec's
    /// `unexplained` is a residual well above the noise).
    low_gain: Vec<String>,
    /// The lines of the other answers (a cause named with a higher gain, or
    /// a `none` that leaves a trace).
    other: Vec<String>,
}

/// A named cause's gain below which an answer to an effect outside the
/// vocabulary is not a misdiagnosis: it explains next to nothing, and says
/// so.
const LOW_GAIN: f64 = 0.05;

impl Tally {
    /// Counts `answer`, reported by `line`.
    fn add(&mut self, answer: &Causes, line: String) {
        use reldesign_identify::diagnose::recalibration::NONE_ABOVE_FLOOR;
        self.total += 1;
        if answer.unexplained() {
            self.unexplained += 1;
        } else if answer.names() == [Cause::None] && answer.residual.over_floor < NONE_ABOVE_FLOOR {
            self.unseen += 1;
        } else if answer.names() != [Cause::None] && answer.gain() < LOW_GAIN {
            self.low_gain.push(line);
        } else {
            self.other.push(line);
        }
    }
}

impl std::fmt::Display for Tally {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        let (n, total, unseen) = (self.unexplained, self.total, self.unseen);
        let (low, other) = (self.low_gain.len(), self.other.len());
        write!(
            f,
            "{n} of {total} unexplained, {unseen} none below the noise, \
             {low} a cause with a gain below {:.0} %, {other} otherwise",
            100.0 * LOW_GAIN
        )
    }
}

/// The answer for a record of an effect outside the vocabulary, and the
/// line that reports it (printed).
fn outside_answer(label: &str, case: &HiddenCase) -> (Causes, String) {
    let (answer, _) = run_causes(case);
    let names: Vec<_> = answer.names().iter().map(|c| c.name()).collect();
    let line = format!(
        "{label}: {} (gain {:.1} %, left {:.2}× the floor, correlated over {:.1} samples; partial {:?})",
        names.join(" + "),
        100.0 * answer.gain(),
        answer.residual.over_floor,
        answer.residual.correlation,
        answer.partial(),
    );
    eprintln!("{line}");
    (answer, line)
}

/// Effects outside the vocabulary (issue 17 §2, `reldesign_tests::outside`)
/// on four actuators, with and without `z`, every candidate tried: how often
/// the answer is `unexplained`, and what else is named (the table of
/// docs/validation/diagnose.md). Every record is `unexplained` but 4
/// frictions answered `none` that leave at most 1.31× the floor (below
/// `NONE_ABOVE_FLOOR`: no trace above the noise); the 2 frictions with `z`
/// that beat no candidate and leave 2.7–2.8× the floor (below the residual
/// test's 3.5×) are caught by the recalibration of `none` (they were
/// answered `none` before it). Never a cause with a high gain; one with a
/// low gain once: the sliding-mode valve's 10 % friction without `z` (seed
/// 609) is answered eddy-currents, gain 2.6 %, 1.21× the floor left. Since
/// the polish fits the edges' instants with the values, its eddy-current
/// model beats the recalibration there by 10.7 BIC units (before, it lost
/// by 3.3, gain 2.0 %, `unexplained`).
#[test]
#[ignore = "slow: 64 records, every candidate"]
fn outside_matrix() {
    use reldesign_tests::outside::outside_case;
    // (effects, the first seed): the measurement chain's and the spring's
    // first, their seeds as when the matrix had only them
    let effects: [(&[Outside], u64); 2] = [(&CHAIN_AND_SPRING, 500), (&FRICTIONS, 600)];
    let mut tally = Tally::default();
    for (effects, first_seed) in effects {
        let mut seed = first_seed;
        for example in [SEMERA, TRACKING, SLIDING, TABLE] {
            for &effect in effects {
                for with_z in [false, true] {
                    seed += 1;
                    let e = excitation(example, Square);
                    let case = outside_case(example, effect, &e, with_z, seed);
                    let label = format!("{example} {effect:?} z={with_z} seed={seed}");
                    let (answer, line) = outside_answer(&label, &case);
                    tally.add(&answer, line);
                }
            }
        }
    }
    eprintln!("{tally}");
    assert!(
        tally.other.is_empty(),
        "a cause named, or `none`:\n{}",
        tally.other.join("\n")
    );
    assert!(
        tally.low_gain.len() <= 1,
        "causes named with a low gain:\n{}",
        tally.low_gain.join("\n")
    );
}

/// The effects outside the vocabulary on devices nobody tuned the diagnosis
/// to (family 12, devices 0–14: every class × gap model), one effect per
/// device in turn, without `z`: no cause of the vocabulary may be named
/// (but with a gain below [`LOW_GAIN`]: none when written); the
/// answer is `unexplained`, or `none` where the record shows no trace above
/// the noise (none when written: device_12_10's probe lag, 3.36× the floor
/// left, below the residual test, was answered `none` before `none` answers
/// were recalibrated).
#[test]
#[ignore = "slow: 60 records, every candidate (450 s)"]
fn outside_on_generated_devices() {
    use reldesign_tests::outside::outside_case_of;
    let effects = [CHAIN_AND_SPRING.as_slice(), &FRICTIONS].concat();
    let mut tally = Tally::default();
    let mut seed = 700;
    for index in 0..15u64 {
        let device = reldesign_tests::devices::device(DEVICE_SEED, index, false);
        let file = format!("{}.toml", device.name);
        let base = reldesign_tests::hidden::baseline(&device.description());
        let excitation = Excitation::square_wave(&base);
        for k in 0..4 {
            seed += 1;
            let effect = effects[(4 * index as usize + k) % effects.len()];
            let case = outside_case_of(&device.toml, &file, effect, &excitation, false, seed);
            let (answer, line) = outside_answer(&format!("{file} {effect:?} seed={seed}"), &case);
            tally.add(&answer, line);
        }
    }
    eprintln!("{tally}");
    assert!(
        tally.other.is_empty() && tally.low_gain.is_empty(),
        "a vocabulary cause named, or `none`:\n{}",
        [&tally.other[..], &tally.low_gain[..]].concat().join("\n")
    );
}

/// A diagnosis does not depend on its threads (ARCHITECTURE.md): on a
/// long hysteresis record (the benchmark's), where the ranking races
/// starts and gives fits up in its second wave, the second hysteresis
/// start is held and the polish's sensitivity passes are split in halves,
/// the answer and every value are the same bits on 1 and 3 threads.
#[test]
fn the_answer_does_not_depend_on_the_threads() {
    let once = excitation(SEMERA, Square);
    let per_run = once.duration() / reldesign_tests::hidden::SAMPLE_PERIOD;
    let long = once.repeated((LONG_SAMPLES as f64 / per_run).ceil() as usize);
    let case = hidden_case(SEMERA, Hysteresis, &long, false, 503);
    let on = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| format!("{:?}", run_causes(&case)))
    };
    let one = on(1);
    assert!(one.contains("cause: Hysteresis"), "{one}");
    assert!(one.contains("status: GaveUp"), "no fit given up: {one}");
    assert_eq!(one, on(3));
}

#[test]
fn causes_are_found_on_generated_devices() {
    #[rustfmt::skip]
    let m = confusion(&[
        Case { actuator: 1, cause: EddyCurrents, drive: Square, with_z: false, seed: 201 },
        Case { actuator: 2, cause: Saturation,   drive: Pulses, with_z: false, seed: 202 },
        Case { actuator: 4, cause: Cause::None,  drive: Square, with_z: false, seed: 203 },
    ]);
    assert!(m.failures.is_empty(), "{}", m.failures.join("\n"));
    assert!(
        m.unexplained_right.is_empty(),
        "{}",
        m.unexplained_right.join("\n")
    );
}

/// Every cause on 15 generated devices (every class × gap model), both
/// excitations alternating: the confusion matrix of docs/validation/diagnose.md.
#[test]
#[ignore = "slow: 105 hidden-effect records on generated devices"]
fn confusion_matrix_on_generated_devices() {
    let mut cases = Vec::new();
    let mut seed = 300;
    for index in 0..15 {
        for cause in Cause::EXTENSIONS.into_iter().chain([Cause::None]) {
            seed += 1;
            let drive = if seed % 2 == 0 {
                Drive::Square
            } else {
                Drive::Pulses
            };
            cases.push(Case {
                actuator: index,
                cause,
                drive,
                with_z: false,
                seed,
            });
        }
    }
    let m = confusion(&cases);
    // fits that stop far from the truth (4 of 105, 2026-11-26)
    assert!(
        m.unexplained_right.len() <= 5,
        "{}",
        m.unexplained_right.join("\n")
    );
    assert!(
        m.failures.len() * 10 <= cases.len(),
        "{} of {} cases failed:\n{}",
        m.failures.len(),
        cases.len(),
        m.failures.join("\n")
    );
}

/// Identifiability from the record, on generated devices (issue 12 §2, §5):
/// a hysteretic core under one held step (the flux never turns) and fringing
/// under a drive too weak to move the armature (the gap is seen at one
/// length) are never named; the record says why where they would have won.
#[test]
fn effects_the_record_cannot_show_are_not_named() {
    let cases: [(
        u64,
        Cause,
        fn(&designer::description::Description) -> Excitation,
    ); 4] = [
        (0, Cause::Hysteresis, Excitation::step),
        (7, Cause::Hysteresis, Excitation::step),
        (1, Cause::Fringing, |b| {
            Excitation::square_wave(b).scaled(0.2)
        }),
        (8, Cause::Fringing, |b| {
            Excitation::square_wave(b).scaled(0.2)
        }),
    ];
    let mut failures = Vec::new();
    for (k, &(index, cause, drive)) in cases.iter().enumerate() {
        let case = device_case_with(index, cause, false, 400 + k as u64, drive);
        let (d, _) = run(&case);
        let why = d.not_identifiable.iter().find(|(c, _)| *c == cause);
        eprintln!(
            "device_{DEVICE_SEED}_{index} {cause} hidden: answered {} (ranking {}); not identifiable: {why:?}",
            d.cause,
            reldesign_tests::hidden::ranking_summary(&d)
        );
        if d.cause == cause {
            failures.push(format!("device_{DEVICE_SEED}_{index}: {cause} named"));
        }
        // The effect must show in the record, or the test proves nothing.
        if d.whole.baseline_wnrmse < HELD_OUT_VISIBLE * d.noise_floor {
            failures.push(format!(
                "device_{DEVICE_SEED}_{index}: hidden {cause} does not show ({:.3} % vs floor {:.3} %)",
                100.0 * d.whole.baseline_wnrmse,
                100.0 * d.noise_floor
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
