//! How long a diagnosis takes on records nobody timed it on (issue 36 §2):
//! records drawn fresh from the generator (unseen devices of family
//! `blind::FAMILY`; the four blind classes, every single cause, `none`, and
//! effects outside the vocabulary; 2 000–50 000 samples, log-uniform), each
//! diagnosed as the CLI does (every candidate, forward selection, joint fit,
//! `unexplained`), wall time per record and per 10 000 samples printed as a
//! distribution. `benches/diagnose_fresh.sh` runs it; `SPEED_SEED` draws
//! another set, `SPEED_RECORDS` sets its size (default 40), `SPEED_PICK=k`
//! times record `k` alone (for a profile).

use std::time::Instant;

use reldesign_identify::diagnose::{diagnose_causes, Cause, Options};
use reldesign_tests::blind::{at_least, Blind, FAMILY};
use reldesign_tests::devices::device;
use reldesign_tests::hidden::{baseline, hidden_case_of, Excitation, HiddenCase};
use reldesign_tests::outside::{outside_case_of, Outside};
use reldesign_tests::Rng;

/// Effects outside the vocabulary the set draws from.
const OUTSIDE: [Outside; 5] = [
    Outside::ProbeGain(1.08),
    Outside::DriverDelay(120e-6),
    Outside::ProbeLag(100e-6),
    Outside::Spring(1.3),
    Outside::Friction(0.3),
];

/// Record `k` of the set drawn from `seed`: its label and case.
fn record(seed: u64, k: u64) -> (String, HiddenCase) {
    let mut rng = Rng::new(seed.wrapping_mul(0x9E37_79B9) ^ k);
    let samples = (rng.uniform(2_000f64.ln(), 50_000f64.ln())).exp() as usize;
    let draw = seed.wrapping_mul(1000) + k;
    match k % 10 {
        0..=3 => {
            let class = Blind::ALL[(k % 10) as usize];
            (format!("{class:?}"), class.case_of_length(draw, samples))
        }
        kind => {
            let index = 200 + (draw % 15);
            let d = device(FAMILY, index, false);
            let file = format!("{}.toml", d.name);
            let base = baseline(&d.description());
            let drive = if draw % 2 == 0 {
                Excitation::square_wave(&base)
            } else {
                Excitation::pulses(&base)
            };
            let drive = at_least(drive, samples);
            if kind == 9 {
                let effect = OUTSIDE[((draw / 10) % OUTSIDE.len() as u64) as usize];
                let case = outside_case_of(&d.toml, &file, effect, &drive, false, draw);
                (format!("outside {effect:?}"), case)
            } else {
                let causes: Vec<Cause> =
                    [Cause::None].into_iter().chain(Cause::EXTENSIONS).collect();
                let cause = causes[(draw % causes.len() as u64) as usize];
                let case = hidden_case_of(&d.toml, &file, cause, &drive, false, draw);
                (format!("{cause}"), case)
            }
        }
    }
}

/// The value at quantile `q` of sorted `x`.
fn quantile(x: &[f64], q: f64) -> f64 {
    let k = ((x.len() - 1) as f64 * q).round() as usize;
    x[k]
}

#[test]
#[ignore = "a benchmark: bash benches/diagnose_fresh.sh"]
fn diagnosis_time_on_fresh_records() {
    let env = |key: &str, default: u64| {
        std::env::var(key)
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(default)
    };
    let seed = env("SPEED_SEED", 1);
    let n = env("SPEED_RECORDS", 40);
    let picked: Option<u64> = std::env::var("SPEED_PICK")
        .ok()
        .and_then(|s| s.parse().ok());
    let (mut per_record, mut per_10k) = (Vec::new(), Vec::new());
    for k in (0..n).filter(|k| picked.is_none_or(|p| p == *k)) {
        let (label, case) = record(seed, k);
        let (model, data) = case.inputs();
        let rows = data.t.len();
        let start = Instant::now();
        let answer =
            diagnose_causes(&model, &data, &Options::default()).unwrap_or_else(|e| panic!("{e}"));
        let wall = start.elapsed().as_secs_f64();
        let names: Vec<_> = answer.names().iter().map(|c| c.name()).collect();
        println!(
            "record {k:2} {label:<28} {rows:6} rows {wall:6.2} s {:6.2} s/10k → {}",
            1e4 * wall / rows as f64,
            names.join(" + ")
        );
        per_record.push(wall);
        per_10k.push(1e4 * wall / rows as f64);
    }
    for x in [&mut per_record, &mut per_10k] {
        x.sort_by(f64::total_cmp);
    }
    let line = |name: &str, x: &[f64]| {
        println!(
            "{name}: median {:.2} s, 90 % {:.2} s, slowest {:.2} s",
            quantile(x, 0.5),
            quantile(x, 0.9),
            x[x.len() - 1]
        )
    };
    println!("{} records of seed {seed}:", per_record.len());
    line("per record", &per_record);
    line("per 10 000 samples", &per_10k);
    let scaled: Vec<f64> = per_10k.iter().map(|x| 4.0 * x).collect();
    line("scaled to 40 000 samples", &scaled);
}
