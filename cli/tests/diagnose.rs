//! `reldesign diagnose` end to end (`shared/spec/measured-data.md`, `cli.md`):
//! records with a known hidden effect (`reldesign_tests::hidden`: the SEMERA
//! valve stripped to its baseline, one extension added in secret, a noisy
//! simulated experiment) are diagnosed through the real binary.
//!
//! Checked: the `--json` contract (one object, the spec's fields,
//! `gain = 1 − extended/baseline`, the extended model valid for `reldesign
//! check` and carrying the drawn parameter), `none` on baseline data, where
//! the extended model and the three plots go (`--out` or next to the data),
//! the text report, and clean rejections of bad records, bad models and bad
//! options, after which nothing is written.
//!
//! The saturation case runs every candidate (about 8 s in the test profile,
//! most of it the hysteresis fit); the other runs restrict the candidates
//! with `--causes` to stay fast.

use std::path::{Path, PathBuf};

use designer::description::{parse_file, parse_str, Core, Description};
use reldesign_identify::diagnose::Cause;
use reldesign_tests::hidden::{baseline, hidden_case, write_case, Excitation, HiddenCase};
use serde_json::Value;
use support::{example_path, files_in, rd, Cli, TempDir};

const CLI: Cli = Cli::new(env!("CARGO_BIN_EXE_reldesign"));

const EXAMPLE: &str = "semera-valve.toml";

/// Every cause of the vocabulary but hysteresis (the slow fit).
const QUICK_CAUSES: &str = "eddy-currents,saturation,fringing,resistance-drift,bouncing";

/// Relative error allowed on a parameter recovered from noisy data.
const RECOVERY_TOLERANCE: f64 = 0.1;

// ---------------------------------------------------------------------------
// helpers
// ---------------------------------------------------------------------------

/// The SEMERA valve's case for `cause`: three square-wave cycles, 40 µs
/// sampling, σ_v = 15 mV, σ_i = 1 mA, no `z` column.
fn semera_case(cause: Cause, seed: u64) -> HiddenCase {
    hidden_case(EXAMPLE, cause, &square_wave(EXAMPLE), false, seed)
}

/// The square wave the generator makes of `example`'s baseline.
fn square_wave(example: &str) -> Excitation {
    let text = std::fs::read_to_string(example_path(example)).unwrap();
    let desc = parse_str(&text, example).unwrap_or_else(|e| panic!("{e}"));
    Excitation::square_wave(&baseline(&desc))
}

/// The drawn value of `key` in a case.
fn drawn(case: &HiddenCase, key: &str) -> f64 {
    case.drawn
        .iter()
        .find(|(k, _)| k == key)
        .unwrap_or_else(|| panic!("{key} not drawn: {:?}", case.drawn))
        .1
}

/// stdout as exactly one JSON object (trailing text fails the parse).
fn one_object(stdout: &str) -> serde_json::Map<String, Value> {
    match serde_json::from_str::<Value>(stdout) {
        Ok(Value::Object(m)) => m,
        other => panic!("expected one JSON object on stdout, got {other:?}:\n{stdout}"),
    }
}

fn number(m: &serde_json::Map<String, Value>, key: &str) -> f64 {
    m.get(key)
        .and_then(Value::as_f64)
        .unwrap_or_else(|| panic!("`{key}` is not a number in {m:?}"))
}

/// The spec's fields, `gain = 1 − extended/baseline`; returns the cause and
/// the extended model's path.
fn spec_fields(m: &serde_json::Map<String, Value>) -> (String, PathBuf) {
    let cause = m["cause"].as_str().expect("`cause` is a string").to_owned();
    let base = number(m, "baseline_wnrmse");
    let ext = number(m, "extended_wnrmse");
    let gain = number(m, "gain");
    assert!(base > 0.0 && ext > 0.0, "{m:?}");
    assert!(
        (gain - (1.0 - ext / base)).abs() < 1e-12,
        "gain {gain} ≠ 1 − {ext}/{base}"
    );
    let path = m["extended_model"]
        .as_str()
        .expect("`extended_model` is a string");
    (cause, PathBuf::from(path))
}

/// The extended model passes `reldesign check` and parses.
fn checked_model(path: &Path) -> Description {
    assert!(path.is_file(), "{} was not written", path.display());
    rd!("check", path).ok();
    parse_file(path).unwrap_or_else(|e| panic!("{e}"))
}

const PLOTS: [&str; 3] = ["current.svg", "residual.svg", "loop.svg"];

/// `<stem>.extended.toml` and the three plots, as SVG, in `dir`.
fn assert_outputs(dir: &Path, stem: &str) {
    let model = dir.join(format!("{stem}.extended.toml"));
    assert!(model.is_file(), "{} missing", model.display());
    for plot in PLOTS {
        let p = dir.join(format!("{stem}.{plot}"));
        let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        assert!(text.contains("<svg"), "{} is not SVG", p.display());
    }
}

// ---------------------------------------------------------------------------
// the contract on hidden effects
// ---------------------------------------------------------------------------

#[test]
fn json_names_hidden_saturation_and_writes_the_extended_model_in_out_dir() {
    let case = semera_case(Cause::Saturation, 21);
    let dir = TempDir::new("saturation");
    let (model, data) = write_case(&dir.path().join("case"), &case);
    let out = dir.path().join("out");
    let r = rd!("diagnose", model, data, "--json", "--out", out);
    let m = one_object(&r.ok());
    let (cause, extended) = spec_fields(&m);
    assert_eq!(cause, "saturation", "{}", r.context());
    assert!(number(&m, "gain") >= 0.5, "{}", r.context());
    assert_eq!(extended, out.join("data.extended.toml"));
    assert_outputs(&out, "data");
    // Nothing next to the data when --out is given.
    assert_eq!(
        files_in(&dir.path().join("case")),
        ["baseline.toml", "data.csv"]
    );
    // The extension, with the hidden φ_sat recovered.
    let truth = drawn(&case, "core.phi_sat");
    match checked_model(&extended).core {
        Core::Saturating { phi_sat, .. } => assert!(
            (phi_sat / truth - 1.0).abs() < RECOVERY_TOLERANCE,
            "φ_sat {phi_sat:e} vs hidden {truth:e}"
        ),
        other => panic!("expected a saturating core, got {other:?}"),
    }
    let text = std::fs::read_to_string(&extended).unwrap();
    assert!(text.contains("model = \"saturating\""), "{text}");
    // `parameters` (measured-data.md): value, standard error and baseline by
    // key path. (The hidden φ_sat lies 4.4 standard errors from the fitted
    // one here: the white-noise standard error misses a 0.2 % bias; issue 12
    // §3 asks for 3, still open.)
    let p = &m["parameters"]["core.phi_sat"];
    let (value, se) = (
        p["value"].as_f64().unwrap(),
        p["std_error"].as_f64().unwrap(),
    );
    assert!(se > 0.0 && se < 0.01 * value, "{p}");
    assert!(
        (value / truth - 1.0).abs() < 0.15,
        "φ_sat {value:e} ± {se:e} vs hidden {truth:e}"
    );
    assert!(
        p["baseline"].is_null(),
        "the linear baseline has no φ_sat: {p}"
    );
    let r = &m["parameters"]["coil.resistance"];
    assert_eq!(r["baseline"].as_f64(), Some(75.0), "{r}");
    assert!(m["rejected"].as_array().is_some());
    // how each candidate's fit ended (a fit given up far above the best
    // counts with an upper bound of its BIC); the named one's converged
    let ended = [
        "CostConverged",
        "StepConverged",
        "GradientConverged",
        "MaxIterations",
        "GaveUp",
    ];
    let candidates = m["candidates"].as_array().unwrap();
    for c in candidates {
        assert!(ended.contains(&c["status"].as_str().unwrap()), "{c}");
    }
    let named = candidates
        .iter()
        .find(|c| c["cause"] == "saturation")
        .unwrap();
    assert!(
        named["status"].as_str().unwrap().ends_with("Converged"),
        "{named}"
    );
}

#[test]
fn baseline_data_gives_none() {
    let case = semera_case(Cause::None, 22);
    let dir = TempDir::new("none");
    let (model, data) = write_case(dir.path(), &case);
    let r = rd!("diagnose", model, data, "--json", "--causes", QUICK_CAUSES);
    let m = one_object(&r.ok());
    let (cause, extended) = spec_fields(&m);
    assert_eq!(cause, "none", "{}", r.context());
    // The baseline already sits on the noise floor: nothing to gain.
    assert!(number(&m, "gain").abs() < 0.1, "{}", r.context());
    let ext = checked_model(&extended);
    let base = parse_file(&model).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(ext.core, base.core);
    assert_eq!(ext.coil.eddy, 0.0);
}

#[test]
fn text_report_and_files_next_to_the_data() {
    let case = semera_case(Cause::EddyCurrents, 23);
    let dir = TempDir::new("text");
    let model = dir.path().join("valve.toml");
    let data = dir.path().join("bench-run.csv");
    std::fs::write(&model, &case.baseline_toml).unwrap();
    std::fs::write(&data, &case.data_csv).unwrap();
    let r = rd!(
        "diagnose",
        model,
        data,
        "--causes",
        "eddy-currents,resistance-drift"
    );
    let text = r.ok();
    for needle in [
        "cause: eddy-currents",
        "gain = 1 − extended/baseline",
        "held-out last",
        "candidates",
        "resistance-drift",
        "bench-run.extended.toml",
    ] {
        assert!(text.contains(needle), "no {needle:?} in\n{}", r.context());
    }
    assert!(
        serde_json::from_str::<Value>(&text).is_err(),
        "text mode printed JSON"
    );
    assert_outputs(dir.path(), "bench-run");
    let truth = drawn(&case, "coil.eddy");
    let eddy = checked_model(&dir.path().join("bench-run.extended.toml"))
        .coil
        .eddy;
    assert!(
        (eddy / truth - 1.0).abs() < RECOVERY_TOLERANCE,
        "k_e {eddy:e} vs hidden {truth:e}"
    );
}

// ---------------------------------------------------------------------------
// rejections: nothing written
// ---------------------------------------------------------------------------

/// Replaces field `col` (0-based) of 1-based line `line` of a CSV text.
fn set_field(csv: &str, line: usize, col: usize, value: &str) -> String {
    let mut lines: Vec<String> = csv.lines().map(str::to_owned).collect();
    let mut fields: Vec<&str> = lines[line - 1].split(',').collect();
    fields[col] = value;
    lines[line - 1] = fields.join(",");
    lines.join("\n") + "\n"
}

fn field(csv: &str, line: usize, col: usize) -> f64 {
    csv.lines()
        .nth(line - 1)
        .unwrap()
        .split(',')
        .nth(col)
        .unwrap()
        .parse()
        .unwrap()
}

/// Runs diagnose on (model text, data text) in a fresh directory, with
/// `--out` to a directory that does not exist yet, and asserts a rejection
/// with `needles` after which neither directory holds anything new.
fn rejected_without_output(model_toml: &str, data_csv: &str, extra: &[&str], needles: &[&str]) {
    let dir = TempDir::new("bad");
    let model = dir.path().join("valve.toml");
    let data = dir.path().join("bad-record.csv");
    std::fs::write(&model, model_toml).unwrap();
    std::fs::write(&data, data_csv).unwrap();
    let out = dir.path().join("out");
    let mut args = vec![
        "diagnose".as_ref(),
        model.as_os_str(),
        data.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ];
    args.extend(extra.iter().map(std::ffi::OsStr::new));
    CLI.run(&args).rejected(needles);
    assert_eq!(dir.files(), ["bad-record.csv", "valve.toml"]);
    // Without --out: nothing next to the data either.
    args.truncate(3);
    args.extend(extra.iter().map(std::ffi::OsStr::new));
    CLI.run(&args).rejected(needles);
    assert_eq!(dir.files(), ["bad-record.csv", "valve.toml"]);
}

#[test]
fn bad_records_are_rejected_naming_file_line_and_column() {
    let case = semera_case(Cause::None, 24);
    let csv = &case.data_csv;
    let model = &case.baseline_toml;
    // Line 1 is a comment, line 2 the header `t,v,i`.
    assert!(csv.lines().nth(1) == Some("t,v,i"), "{csv:.200}");
    let dt = field(csv, 4, 0) - field(csv, 3, 0);

    let no_current = csv.replacen("\nt,v,i\n", "\nt,v,current\n", 1);
    rejected_without_output(
        model,
        &no_current,
        &[],
        &["bad-record.csv", "missing column `i`"],
    );

    let text_cell = set_field(csv, 100, 1, "abc");
    rejected_without_output(
        model,
        &text_cell,
        &[],
        &["bad-record.csv:100", "`v`", "`abc`"],
    );

    let nan = set_field(csv, 120, 2, "NaN");
    rejected_without_output(model, &nan, &[], &["bad-record.csv:120", "`i`", "NaN"]);

    let repeated_time = set_field(csv, 150, 0, &format!("{:e}", field(csv, 149, 0)));
    rejected_without_output(
        model,
        &repeated_time,
        &[],
        &["bad-record.csv:150", "`t`", "increase"],
    );

    // A 5 % jitter on one sample time: steps of 1.05 Δ and 0.95 Δ.
    let jitter = set_field(
        csv,
        200,
        0,
        &format!("{:e}", field(csv, 200, 0) + 0.05 * dt),
    );
    rejected_without_output(
        model,
        &jitter,
        &[],
        &["bad-record.csv:200", "`t`", "uniform"],
    );
}

#[test]
fn bad_model_is_rejected_naming_the_key() {
    let case = semera_case(Cause::None, 25);
    let model = case
        .baseline_toml
        .replacen("\nresistance = 75.0", "\nresistance = -75.0", 1);
    assert_ne!(model, case.baseline_toml, "the example changed");
    rejected_without_output(
        &model,
        &case.data_csv,
        &[],
        &["valve.toml", "coil.resistance"],
    );
}

#[test]
fn bad_options_are_rejected() {
    let case = semera_case(Cause::None, 26);
    let (model, data) = (&case.baseline_toml, &case.data_csv);
    rejected_without_output(model, data, &["--holdout", "0.9"], &["--holdout", "0.9"]);
    let mut names = vec!["`eddy`"];
    names.extend(Cause::EXTENSIONS.iter().map(|c| c.name()));
    names.push("none");
    rejected_without_output(model, data, &["--causes", "saturation,eddy"], &names);
}

// ---------------------------------------------------------------------------
// --batch: a production line's records
// ---------------------------------------------------------------------------

/// `--batch DIR`: one JSON line per record in file-name order, each the
/// single-record diagnosis plus `"file"`; a broken record gives an error
/// line naming it while the others are diagnosed; the files of each record
/// go to `--out`; a summary per cause on stderr; exit status 1 for the
/// broken one.
#[test]
fn batch_diagnoses_every_record_and_reports_the_broken_one() {
    let dir = TempDir::new("batch");
    let eddy = semera_case(Cause::EddyCurrents, 31);
    let none = semera_case(Cause::None, 32);
    let records = dir.path().join("records");
    std::fs::create_dir_all(&records).unwrap();
    let (model, _) = write_case(&dir.path().join("model"), &eddy);
    std::fs::write(records.join("unit-1.csv"), &eddy.data_csv).unwrap();
    std::fs::write(records.join("unit-2.csv"), &none.data_csv).unwrap();
    let broken = set_field(&none.data_csv, 5, 1, "x");
    std::fs::write(records.join("unit-3.csv"), broken).unwrap();
    std::fs::write(records.join("notes.txt"), "not a record").unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    let run = rd!(
        "diagnose",
        model,
        "--batch",
        records,
        "--out",
        out,
        "--causes",
        QUICK_CAUSES
    );
    assert!(
        !run.succeeded(),
        "a broken record fails the batch: {}",
        run.context()
    );
    let lines: Vec<Value> = run
        .stdout()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .collect();
    assert_eq!(lines.len(), 3, "{}", run.context());
    let file = |v: &Value| v["file"].as_str().unwrap_or_default().to_owned();
    assert!(file(&lines[0]).ends_with("unit-1.csv") && file(&lines[2]).ends_with("unit-3.csv"));
    assert_eq!(lines[0]["cause"], "eddy-currents", "{}", run.context());
    assert_eq!(lines[1]["cause"], "none", "{}", run.context());
    let error = lines[2]["error"].as_str().unwrap_or_default();
    assert!(
        error.contains("unit-3.csv:5:") && error.contains("column `v`"),
        "{error}"
    );
    // the same answer as the record diagnosed alone
    let alone = dir.path().join("alone");
    std::fs::create_dir_all(&alone).unwrap();
    let single = rd!(
        "diagnose",
        model,
        records.join("unit-1.csv"),
        "--json",
        "--out",
        alone,
        "--causes",
        QUICK_CAUSES
    );
    let single = one_object(&single.ok());
    for key in [
        "cause",
        "baseline_wnrmse",
        "extended_wnrmse",
        "gain",
        "parameters",
    ] {
        assert_eq!(lines[0][key], single[key], "{key}");
    }
    for stem in ["unit-1", "unit-2"] {
        assert_outputs(&out, stem);
    }
    let stderr = run.context();
    assert!(
        stderr.contains("[3/3]") && stderr.contains("mean gain") && stderr.contains("(failed)"),
        "{stderr}"
    );
}

// ---------------------------------------------------------------------------
// several causes at once (forward selection)
// ---------------------------------------------------------------------------

/// Two hidden effects at once, on two actuators, with and without `z`: both
/// are named (`causes`, strongest first, `cause` its first), each step gains
/// at least `MIN_STEP_GAIN` over the model before it, the extended model
/// carries both, and `gain` is the whole selection's. A single effect stays
/// single (no cause is added on a model at the noise). Seeds apart from the
/// ones the step gate was chosen on.
#[test]
fn several_causes_are_named_strongest_first() {
    use reldesign_identify::diagnose::MIN_STEP_GAIN;
    use reldesign_tests::hidden::hidden_pair;
    let cases = [
        (
            EXAMPLE,
            false,
            [Cause::EddyCurrents, Cause::ResistanceDrift],
            71,
        ),
        (
            EXAMPLE,
            false,
            [Cause::Saturation, Cause::ResistanceDrift],
            72,
        ),
        (
            "perfect-tracking-valve.toml",
            true,
            [Cause::Saturation, Cause::Bouncing],
            73,
        ),
        (
            "perfect-tracking-valve.toml",
            true,
            [Cause::Fringing, Cause::EddyCurrents],
            74,
        ),
    ];
    for (example, with_z, pair, seed) in cases {
        let excitation = square_wave(example);
        let case = hidden_pair(example, pair, &excitation, with_z, seed);
        let dir = TempDir::new("pair");
        let (model, data) = write_case(dir.path(), &case);
        let r = rd!("diagnose", model, data, "--json", "--causes", QUICK_CAUSES);
        let m = one_object(&r.ok());
        let named: Vec<&str> = m["causes"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(Value::as_str)
            .collect();
        let mut want: Vec<&str> = pair.iter().map(|c| c.name()).collect();
        let mut got = named.clone();
        want.sort_unstable();
        got.sort_unstable();
        assert_eq!(
            got,
            want,
            "{example} (z: {with_z}) {pair:?}: {}",
            r.context()
        );
        assert_eq!(m["cause"].as_str(), named.first().copied());
        let steps = m["steps"].as_array().unwrap();
        assert_eq!(steps.len(), 2);
        for step in steps {
            assert!(step["gain"].as_f64().unwrap() >= MIN_STEP_GAIN, "{step}");
        }
        let overall = number(&m, "gain");
        assert!(overall >= steps[0]["gain"].as_f64().unwrap(), "{overall}");
        // fitted together, the pair explains the record to the noise
        assert!(m["unexplained"].is_null(), "{}", r.context());
        let left = m["residual"]["over_noise_floor"].as_f64().unwrap();
        assert!(left < 1.5, "{pair:?}: {left}× the floor left");
        let extended = checked_model(&PathBuf::from(m["extended_model"].as_str().unwrap()));
        for cause in pair {
            let has = match cause {
                Cause::EddyCurrents => extended.coil.eddy > 0.0,
                Cause::ResistanceDrift => extended.coil.resistance_drift != 0.0,
                Cause::Saturation => matches!(extended.core, Core::Saturating { .. }),
                Cause::Bouncing => extended.mechanics.restitution > 0.0,
                Cause::Fringing => {
                    !matches!(extended.gap, designer::description::Gap::Linear { .. })
                }
                _ => true,
            };
            assert!(has, "{pair:?}: the extended model lacks {cause:?}");
        }
    }
    // the text report leads with the causes and each step
    let case = hidden_pair(
        EXAMPLE,
        [Cause::EddyCurrents, Cause::ResistanceDrift],
        &square_wave(EXAMPLE),
        false,
        71,
    );
    let dir = TempDir::new("pair-text");
    let (model, data) = write_case(dir.path(), &case);
    let text = rd!("diagnose", model, data, "--causes", QUICK_CAUSES).ok();
    assert!(
        text.starts_with("causes found: eddy-currents, resistance-drift")
            || text.starts_with("causes found: resistance-drift, eddy-currents"),
        "{text}"
    );
    assert!(
        text.contains("  2. ") && text.contains("together: ") && text.contains("the last step"),
        "{text}"
    );
    let single = semera_case(Cause::EddyCurrents, 75);
    let dir = TempDir::new("single");
    let (model, data) = write_case(dir.path(), &single);
    let m = one_object(&rd!("diagnose", model, data, "--json", "--causes", QUICK_CAUSES).ok());
    assert_eq!(m["causes"], serde_json::json!(["eddy-currents"]));
}

/// Effects outside the vocabulary (issue 17 §2; `reldesign_tests::outside`):
/// a current probe reading 8 % high or low, a driver 120 µs late, a probe
/// lagging by 100 µs, a spring 30 % stiffer or softer, Coulomb friction of
/// 30 % of the spring's force over the stroke. Each is answered
/// `unexplained` (no cause of the vocabulary named, whatever part of the
/// error one of them absorbs: fringing takes 37–96 % of these), with the
/// partial causes, their gain and where the residual left concentrates.
/// Seeds apart from the ones the thresholds were read from.
#[test]
fn effects_outside_the_vocabulary_are_unexplained() {
    use reldesign_tests::outside::{outside_case, Outside};
    const TRACKING: &str = "perfect-tracking-valve.toml";
    // (actuator, effect, with z, seed, decided by the recalibration)
    let cases = [
        (EXAMPLE, Outside::ProbeGain(1.08), false, 81, false),
        (TRACKING, Outside::DriverDelay(120e-6), true, 82, false),
        (TRACKING, Outside::ProbeLag(100e-6), false, 83, false),
        (EXAMPLE, Outside::Spring(1.3), true, 84, false),
        (EXAMPLE, Outside::Spring(0.7), false, 85, false),
        // absorbed by a McLyman gap to 2.6× the floor: the recalibration
        (TRACKING, Outside::ProbeGain(0.92), false, 87, true),
        // a small trace in the current (< 2× the floor), which a refitted
        // mass and spring follow as well as any cause
        (TRACKING, Outside::Friction(0.3), false, 88, true),
    ];
    for (k, (example, effect, with_z, seed, by_recalibration)) in cases.into_iter().enumerate() {
        let excitation = square_wave(example);
        let case = outside_case(example, effect, &excitation, with_z, seed);
        let dir = TempDir::new("outside");
        let (model, data) = write_case(dir.path(), &case);
        // the whole vocabulary on the first (the hysteresis fit is the slow one)
        let r = if k == 0 {
            rd!("diagnose", model, data, "--json")
        } else {
            rd!("diagnose", model, data, "--json", "--causes", QUICK_CAUSES)
        };
        let m = one_object(&r.ok());
        let what = format!("{example} {effect:?} (z: {with_z}): {}", r.context());
        assert_eq!(m["cause"], "unexplained", "{what}");
        assert_eq!(m["causes"], serde_json::json!(["unexplained"]), "{what}");
        let u = &m["unexplained"];
        // which test decides it: the probe 8 % low leaves less than the
        // threshold and is caught by the recalibration alone
        let left = u["over_noise_floor"].as_f64().unwrap();
        let recalibrated = u["recalibrated"].as_bool().unwrap();
        let over = left > reldesign_identify::diagnose::unexplained::OVER_FLOOR;
        assert_eq!(
            (over, recalibrated),
            (!by_recalibration, by_recalibration),
            "{what}"
        );
        if recalibrated {
            let r = &m["recalibration"];
            let bic = |k: &str| r[k].as_f64().unwrap();
            assert!(bic("bic") <= bic("causes_bic"), "{what}");
            assert_eq!(r["given_up"].as_bool(), Some(false), "{what}");
            assert!(
                r["values"]["coil.resistance"].as_f64().unwrap() > 0.0,
                "{what}"
            );
        }
        let partial_gain = u["partial_gain"].as_f64().unwrap();
        assert!((partial_gain - number(&m, "gain")).abs() < 1e-12, "{what}");
        let partial = u["partial_causes"].as_array().unwrap();
        assert!(partial.len() <= 2, "{what}");
        assert!(
            partial.is_empty() == (partial_gain == 0.0),
            "partial causes go with a partial gain: {what}"
        );
        assert!(!u["localisation"].as_str().unwrap().is_empty(), "{what}");
        checked_model(&PathBuf::from(m["extended_model"].as_str().unwrap()));
    }
    // the text report says so, and names no cause
    let excitation = square_wave(EXAMPLE);
    let case = outside_case(
        EXAMPLE,
        Outside::DriverDelay(120e-6),
        &excitation,
        false,
        86,
    );
    let dir = TempDir::new("outside-text");
    let (model, data) = write_case(dir.path(), &case);
    let report = rd!("diagnose", model, data, "--causes", QUICK_CAUSES).ok();
    assert!(report.starts_with("answer: unexplained."), "{report}");
    assert!(
        report.contains("where the residual left concentrates:"),
        "{report}"
    );
    assert!(report.contains("cause: unexplained"), "{report}");
}
