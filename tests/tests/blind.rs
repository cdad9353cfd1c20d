//! The classes of blind records the diagnosis got wrong (issue 36 §1,
//! `reldesign_tests::blind`): each class drawn on unseen generated devices,
//! the answer counted per class on the tuning seeds and on the held-out ones.

use std::time::Instant;

use reldesign_identify::diagnose::{diagnose_causes, Cause, Causes, DiagnoseError, Options};
use reldesign_tests::blind::{
    evidence, stroke_covered, Blind, FRESH, HELD_OUT, ROUND_4, ROUND_5, TUNING,
};
use reldesign_tests::hidden::{visibility, HiddenCase};

/// The answer to a case (as the CLI reads the two files) and its wall time,
/// or why the diagnosis failed.
fn answer(case: &HiddenCase) -> Result<(Causes, f64), DiagnoseError> {
    let (model, data) = case.inputs();
    let start = Instant::now();
    let causes = diagnose_causes(&model, &data, &Options::default())?;
    Ok((causes, start.elapsed().as_secs_f64()))
}

/// One line per record: the answer, its gain, what is left, the partial
/// causes, the ranking.
fn line(class: Blind, seed: u64, causes: &Causes, seconds: f64, rows: usize) -> String {
    let names: Vec<_> = causes.names().iter().map(|c| c.name()).collect();
    let first = causes.first();
    format!(
        "{class:?} seed {seed} ({rows} rows, {seconds:.1} s): {} (gain {:.1} %, left {:.2}× the floor; partial {:?}; not identifiable {:?}; rejected {:?}; ranking {})",
        names.join(" + "),
        100.0 * causes.gain(),
        causes.residual.over_floor,
        causes.partial(),
        first.not_identifiable.iter().map(|(c, why)| format!("{c}: {why}")).collect::<Vec<_>>(),
        first.rejected.iter().map(|r| format!("{}: {}", r.cause, r.reason())).collect::<Vec<_>>(),
        reldesign_tests::hidden::ranking_summary(first),
    )
}

/// Right answers of `class` over `seeds`, each record's line printed.
fn score(class: Blind, seeds: impl Iterator<Item = u64>) -> (usize, usize, Vec<String>) {
    let (mut right, mut total, mut wrong) = (0, 0, Vec::new());
    for seed in seeds {
        let case = class.case(seed);
        let rows = case.data_csv.lines().count() - 2;
        total += 1;
        let (causes, seconds) = match answer(&case) {
            Ok(answer) => answer,
            Err(e) => {
                let line = format!("{class:?} seed {seed} ({rows} rows): {e}");
                eprintln!("{line}");
                wrong.push(line);
                continue;
            }
        };
        let line = line(class, seed, &causes, seconds, rows);
        eprintln!("{line}");
        if class.right(&causes.names()) {
            right += 1;
        } else {
            wrong.push(line);
        }
    }
    (right, total, wrong)
}

/// Every class on its tuning, held-out, fresh and later rounds' seeds;
/// `BLIND_CLASS=<name>` and
/// `BLIND_SEEDS=tuning|held-out|fresh|round-4|round-5` narrow it.
/// `cargo test --release -p reldesign-tests --test blind -- --ignored --nocapture`
#[test]
#[ignore = "slow: 320 records, every candidate"]
fn classes_on_unseen_devices() {
    let only = std::env::var("BLIND_CLASS").ok();
    let pick: Option<Vec<u64>> = std::env::var("BLIND_PICK")
        .ok()
        .map(|s| s.split(",").map(|x| x.parse().unwrap()).collect());
    let sets = std::env::var("BLIND_SEEDS").ok();
    let mut summary = Vec::new();
    let mut wrong = Vec::new();
    for class in Blind::ALL {
        if only.as_deref().is_some_and(|o| o != format!("{class:?}")) {
            continue;
        }
        let sets_of_seeds = [
            ("tuning", TUNING),
            ("held-out", HELD_OUT),
            ("fresh", FRESH),
            ("round-4", ROUND_4),
            ("round-5", ROUND_5),
        ];
        for (set, seeds) in sets_of_seeds {
            if sets.as_deref().is_some_and(|s| s != set) {
                continue;
            }
            let (right, total, w) = score(
                class,
                seeds.filter(|s| pick.as_ref().is_none_or(|p| p.contains(s))),
            );
            summary.push(format!("{class:?} {set}: {right} of {total} right"));
            wrong.extend(w);
        }
    }
    eprintln!("{}", summary.join("\n"));
    assert!(wrong.is_empty(), "wrong answers:\n{}", wrong.join("\n"));
}

/// The generator draws what each class says: the hysteretic record has no
/// motion and its effect shows; the others move and show theirs.
#[test]
fn each_class_shows_its_effect() {
    for class in Blind::ALL {
        let case = class.case(TUNING.start);
        let still = stroke_covered(&case.truth, &case.excitation);
        if class == Blind::HysteresisBelowPullIn {
            assert!(still <= 0.01, "{class:?}: the armature moves ({still})");
        } else {
            assert!(
                still > 0.5,
                "{class:?}: the armature does not switch ({still})"
            );
        }
        let seen = visibility(&case).ratio();
        assert!(
            seen > 3.0,
            "{class:?}: the effect hides in the noise ({seen:.2}×)"
        );
        let expected: Vec<Cause> = class.expected().to_vec();
        assert_eq!(case.cause, expected[0], "{class:?}");
    }
}

/// Every cause of a record leaves evidence: held-out seed 105 of the
/// warming relay first drew bounces that leave none (the truth without them
/// explained the record as well), so it is drawn again and its record now
/// shows both causes.
#[test]
fn every_cause_of_a_record_leaves_evidence() {
    let class = Blind::DriftWithBounce;
    let evidence = evidence(class, &class.case(105));
    assert!(
        evidence.iter().all(|&b| b > 0.0),
        "{class:?} seed 105: evidence {evidence:?}"
    );
}

/// Fringing with eddy currents on a generated valve (tuning seed 8), where
/// a Jiles–Atherton core wins the first ranking by mimicking part of both
/// and leaves 24× the floor whatever is added to it (2026-12-02): the
/// selection without it names both true causes, to the noise.
#[test]
fn a_cause_that_mimics_two_is_set_aside() {
    let (causes, line) = right_within(Blind::FringingWithEddy, 8, 1.5);
    // (the answer comes from the selection without the core)
    let ranked = causes.first().ranking.iter().map(|s| s.cause);
    assert!(!ranked.clone().any(|c| c == Cause::Hysteresis), "{line}");
}

/// The answer to `class`'s record of `seed`, which must be right and leave
/// less than `over_floor` noise floors; with its line.
fn right_within(class: Blind, seed: u64, over_floor: f64) -> (Causes, String) {
    let (causes, _) = answer(&class.case(seed)).unwrap_or_else(|e| panic!("{e}"));
    let line = line(class, seed, &causes, 0.0, 0);
    assert!(class.right(&causes.names()), "{line}");
    assert!(causes.residual.over_floor < over_floor, "{line}");
    (causes, line)
}

/// Fringing alone on a generated relay (held-out seed 102), whose
/// description's linear gap was drawn through the fringing gap's curve: its
/// offset is the line's, not a reluctance at z = 0. From the core shifted by
/// it the fringing fit ran to the winding length's bound and left 6.8× the
/// floor (`unexplained`, 2026-12-02); the start with the core as it was
/// reaches the truth.
#[test]
fn fringing_is_fitted_from_the_core_as_it_was_too() {
    right_within(Blind::LoneFringing, 102, 1.25);
}

/// A warming relay that bounces (held-out seed 100): after the bounce the
/// model is within the noise on the fitted head of the record and 6.8× the
/// floor on the held-out end, where the drift shows. The second step sees
/// it there (2026-12-02; before, `unexplained` with 6.1× left).
#[test]
fn a_drift_seen_on_the_held_out_end_is_named() {
    right_within(Blind::DriftWithBounce, 100, 1.25);
}

/// A warming relay whose bounces stop at 47 mm/s (tuning seed 4): fitted
/// with the description's threshold of 1 mm/s, γ and the drift came within
/// 0.1 % of the truth and 3.84× the floor was left, `unexplained`. The
/// threshold scanned between the fitted model's impact speeds names both
/// (2026-12-02, 1.16×). The scanned threshold is among the fitted values,
/// ± half the interval of thresholds that replay the same, which holds the
/// relay's own.
#[test]
fn the_bounce_threshold_is_scanned() {
    let class = Blind::DriftWithBounce;
    let (causes, line) = right_within(class, 4, 1.25);
    let case = class.case(4);
    let (model, data) = case.inputs();
    let listed: Vec<_> = (causes.steps.iter())
        .flat_map(|step| step.parameters(&model, &data))
        .filter(|p| p.path == "mechanics.bounce_threshold")
        .collect();
    let truth = case.truth.mechanics.bounce_threshold;
    assert!(
        listed.iter().any(|p| (p.value - truth).abs() <= p.std_error
            && p.baseline == Some(model.mechanics.bounce_threshold)),
        "{line}: the relay's v_ε {truth}, listed {listed:?}"
    );
}

/// A warming relay that bounces (fresh seed 209): the drift fitted jointly
/// on the record's first 12 000 of 60 001 samples stopped 4 % short of the
/// truth and left 2.03× the floor (`unexplained`, above the pair's 2×);
/// fitted together on all but the held-out end, 1.08× (2026-12-02).
#[test]
fn a_drift_is_fitted_together_on_the_whole_fitted_part() {
    let (causes, line) = right_within(Blind::DriftWithBounce, 209, 1.25);
    // the report tells the two apart: the candidates ranked on the head, the
    // joint fit on more
    let last = causes.last();
    assert!(
        last.ranked_samples < last.fitted_samples,
        "{line}: ranked on {}, the last model fitted on {} samples",
        last.ranked_samples,
        last.fitted_samples
    );
}

/// A warming relay that bounces (fresh seed 217): the drift fitted alone on
/// the record's head came out 12 % high and left 1.77× the floor, and the
/// bounce fitted on it lost on the held-out end. Fitted again on the whole
/// fitted part, the drift leaves 1.13×, within the floor on the whole
/// record but 2.1× in the windows after the model's impacts, where the
/// bounce is then found (2026-12-02, 1.03×).
#[test]
fn a_bounce_is_sought_after_the_impacts_of_an_explained_record() {
    right_within(Blind::DriftWithBounce, 217, 1.25);
}

/// Fringing with eddy currents on a generated valve (seed 226 of the fourth
/// round): fringing, fitted first without the eddy currents, came out with
/// R 7 % high and the gap's area 3.5×; refitted from there beside them it
/// ran the winding length to its bound and left 36× the floor
/// (`unexplained`). From fringing's own starting point, a further start of
/// the second step, the pair reaches the truth (2026-12-02, 1.04×).
#[test]
fn a_later_step_also_starts_the_earlier_cause_afresh() {
    right_within(Blind::FringingWithEddy, 226, 1.25);
}

/// Fringing with eddy currents on a generated relay (seed 246 of the fifth
/// round): fitted on the current alone from every start, the gap ran to the
/// winding length's lower bound, its area 4× the truth's (6.4 % wNRMSE
/// left, 33× the floor, `unexplained`); fitted with the flux term first, the
/// same start reaches the truth (2026-12-03, 1.0×).
#[test]
fn a_fringing_fit_on_a_bound_is_tried_again_with_the_flux() {
    right_within(Blind::FringingWithEddy, 246, 1.25);
}
