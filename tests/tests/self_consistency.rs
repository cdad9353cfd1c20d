//! Records simulated from a description and diagnosed against that same
//! description have no cause (issue 12 §1, §5): `none`, and not
//! `unexplained` (issue 17 §2), on every bundled example and on generated
//! devices nobody tuned the diagnosis to, with the voltage edges on the
//! sample instants (as `reldesign simulate` writes) and between them (as a
//! DAQ samples), at several output steps and seeds.
//!
//! CI runs a representative part; the whole set is
//! `cargo test --release -p reldesign-tests --test self_consistency -- --ignored`.

use designer::record::Record;
use reldesign_identify::diagnose::{diagnose, Cause, Diagnosis, Options, Residual};
use reldesign_identify::Measured;
use reldesign_tests::devices::device;
use reldesign_tests::hidden::{experiment, Excitation, Noise, Sampling};
use reldesign_tests::Rng;

/// Where the voltage edges fall.
#[derive(Debug, Clone, Copy)]
enum Edges {
    /// On sample instants.
    OnGrid,
    /// At a random point between samples (the same delay for every edge).
    Between,
}

/// A description's text and its file name.
struct Subject {
    name: String,
    text: String,
}

fn example(file: &str) -> Subject {
    let path = reldesign_tests::example_path(file);
    Subject {
        name: file.to_string(),
        text: std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())),
    }
}

fn generated(seed: u64, index: u64) -> Subject {
    let d = device(seed, index, false);
    Subject {
        name: format!("{}.toml", d.name),
        text: d.toml,
    }
}

/// Diagnoses a record of `subject` simulated from `subject` itself; with
/// what its model leaves (it must not be `unexplained` either).
fn run(subject: &Subject, period: f64, edges: Edges, seed: u64) -> (Diagnosis, Residual, String) {
    let desc = designer::description::parse_str(&subject.text, &subject.name)
        .unwrap_or_else(|e| panic!("{e}"));
    let excitation = Excitation::square_wave(&desc).on_grid(period);
    let mut rng = Rng::new(seed);
    let delay = match edges {
        Edges::OnGrid => 0.0,
        Edges::Between => rng.uniform(0.05, 0.95) * period,
    };
    let noise = Noise::for_device(&desc, &excitation);
    let sampling = Sampling { period, delay };
    let csv = experiment(&desc, &excitation, sampling, noise, false, &mut rng);
    let record = Record::parse(&csv, "data.csv").unwrap_or_else(|e| panic!("{e}"));
    let data = Measured::from_record(&record).unwrap_or_else(|e| panic!("{e}"));
    let d = diagnose(&desc, &data, &Options::default()).unwrap_or_else(|e| panic!("{e}"));
    let left = Residual::of(std::slice::from_ref(&d), &data);
    let summary = format!(
        "{} Δ={:.0} µs {edges:?} seed={seed}: {} (gain {:.1} %, baseline {:.3} %, floor {:.3} %, \
         left {:.2}× the floor correlated over {:.1} samples; ranking {})",
        subject.name,
        period * 1e6,
        d.cause,
        100.0 * d.whole.gain,
        100.0 * d.whole.baseline_wnrmse,
        100.0 * d.noise_floor,
        left.over_floor,
        left.correlation,
        reldesign_tests::hidden::ranking_summary(&d)
    );
    eprintln!("{summary}");
    (d, left, summary)
}

type Case = (Subject, f64, Edges, u64);

fn check_all(cases: &[Case]) {
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|(s, period, edges, seed)| {
            let (d, left, summary) = run(s, *period, *edges, *seed);
            (d.cause != Cause::None || left.unexplained()).then_some(summary)
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} records named a cause or were unexplained:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

#[test]
fn records_of_the_description_itself_have_no_cause() {
    check_all(&[
        (example("semera-valve.toml"), 20e-6, Edges::OnGrid, 1),
        (example("sliding-mode-valve.toml"), 40e-6, Edges::Between, 2),
        (example("table-gap-valve.toml"), 20e-6, Edges::Between, 3),
        (generated(12, 0), 20e-6, Edges::OnGrid, 4),
        (generated(12, 4), 40e-6, Edges::Between, 5),
        (generated(12, 8), 20e-6, Edges::Between, 6),
        // Found by the whole set: a saturated relay, whose replay passes
        // the voltage noise on to the current (the floor counts it), and a
        // device where the best extension was worse on the whole record.
        (generated(12, 3), 20e-6, Edges::OnGrid, 157),
        (generated(12, 12), 20e-6, Edges::Between, 212),
    ]);
}

#[test]
#[ignore = "slow: every example and 15 devices × output steps × edge placement"]
fn whole_set() {
    let mut cases = Vec::new();
    let mut seed = 100;
    let subjects = [
        "semera-valve.toml",
        "perfect-tracking-valve.toml",
        "sliding-mode-valve.toml",
        "table-gap-valve.toml",
        "jiles-atherton-valve.toml",
        "msl-solenoid.toml",
    ]
    .into_iter()
    .map(example)
    .chain((0..15).map(|i| generated(12, i)));
    for s in subjects {
        for period in [7e-6, 20e-6, 40e-6] {
            for edges in [Edges::OnGrid, Edges::Between] {
                seed += 1;
                cases.push((
                    Subject {
                        name: s.name.clone(),
                        text: s.text.clone(),
                    },
                    period,
                    edges,
                    seed,
                ));
            }
        }
    }
    check_all(&cases);
}
