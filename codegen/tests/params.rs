//! "One parameter, one line" (ARCHITECTURE.md): an emitted file declares
//! every model parameter and the stroke limits `Z_MIN`, `Z_MAX` on exactly
//! one line, the file's one `params!` macro, whatever the number of float
//! modules; changing one parameter changes that line and the source hash.
//! The controller, the filters and the estimators all invoke `params!`, so
//! the whole file is checked, observer sections included.

use designer::description::parse_str;
use designer::design::Design;
use reldesign_build::{const_name, emit};
use support::root;

/// Top-level modules that declare the parameters themselves: none.
const NOT_YET_ON_PARAMS: &[&str] = &[];

/// A description's whole text (controller and observer sections).
fn description_text(path: &str) -> String {
    std::fs::read_to_string(root().join(path)).unwrap()
}

/// The emitted file and the (const name, value text) of every parameter.
fn build(text: &str, file: &str) -> (String, Vec<(String, String)>) {
    let d = parse_str(text, file).unwrap_or_else(|e| panic!("{e}"));
    let design = Design::new(&d).unwrap_or_else(|e| panic!("{e}"));
    let code = emit(&design).unwrap_or_else(|e| panic!("{e}"));
    let m = &d.mechanics;
    let limits = [("z_min", m.z_min), ("z_max", m.z_max)];
    let params = design
        .model
        .params
        .iter()
        .map(|(name, _, value)| (name, value))
        .chain(limits)
        .map(|(name, value)| (const_name(name).unwrap(), format!("{value:?}")))
        .collect();
    (code, params)
}

/// The file without the top-level `pub mod NAME { … }` of `skipped`.
fn without_modules(code: &str, skipped: &[&str]) -> String {
    let mut out = String::new();
    let mut skipping = false;
    for line in code.lines() {
        if let Some(name) = line.strip_prefix("pub mod ") {
            skipping = skipped.iter().any(|s| name == format!("{s} {{"));
        }
        if !skipping {
            out.push_str(line);
            out.push('\n');
        }
        if skipping && line == "}" {
            skipping = false;
        }
    }
    out
}

/// Asserts that each parameter is declared on exactly one line, holding its value.
fn assert_one_line_each(code: &str, params: &[(String, String)], what: &str) {
    assert_eq!(
        code.matches("macro_rules! params").count(),
        1,
        "{what}: one params! macro"
    );
    for (name, value) in params {
        let lines: Vec<&str> = code
            .lines()
            .filter(|l| l.contains(&format!("const {name}: ")))
            .collect();
        assert_eq!(lines.len(), 1, "{what}: `{name}` declared on {lines:#?}");
        assert!(
            lines[0].ends_with(&format!(" = {value};")),
            "{what}: `{name}` = {value}: {}",
            lines[0]
        );
    }
}

#[test]
fn a_freshly_emitted_file_declares_each_parameter_once() {
    for path in [
        "examples/perfect-tracking-valve.toml",
        "tests/data/relay-12v.toml",
    ] {
        let (code, params) = build(&description_text(path), path);
        assert!(code.contains("pub mod f32 {") && code.contains("pub mod f64 {"));
        assert_one_line_each(&code, &params, path);
    }
}

#[test]
fn the_checked_in_file_declares_each_parameter_once() {
    let path = "examples/perfect-tracking-valve.toml";
    let (_, params) = build(&description_text(path), path);
    let checked_in =
        std::fs::read_to_string(root().join("generated/src/perfect_tracking_valve.rs")).unwrap();
    let code = without_modules(&checked_in, NOT_YET_ON_PARAMS);
    assert!(code.len() < checked_in.len() || NOT_YET_ON_PARAMS.is_empty());
    assert_one_line_each(&code, &params, "generated/src/perfect_tracking_valve.rs");
}

/// The coil resistance enters the energy-optimal reference (its cost is the
/// copper loss), so the tables change with it: the polynomial reference does
/// not depend on it, and then only its line does.
#[test]
fn one_parameter_change_is_one_changed_line_of_the_file() {
    let path = "tests/data/relay-12v.toml";
    let text =
        description_text(path).replacen("shape = \"energy-optimal\"", "shape = \"polynomial\"", 1);
    assert!(text.contains("shape = \"polynomial\""));
    let changed = text.replacen("resistance = 160.0", "resistance = 161.5", 1);
    assert_ne!(text, changed);
    let ((a, _), (b, _)) = (build(&text, path), build(&changed, path));
    let diff = support::changed_lines(&a, &b);
    assert_eq!(diff.len(), 2, "{diff:#?}");
    assert!(diff[0].0.starts_with("// source sha256: "), "{diff:?}");
    assert_eq!(
        diff[1],
        (
            "        pub const R: $f = 160.0;",
            "        pub const R: $f = 161.5;"
        )
    );
}
