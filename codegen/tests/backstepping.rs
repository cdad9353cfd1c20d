//! The emitted backstepping position controller (`codegen/src/backstepping.rs`,
//! switched-force-backstepping [SB]) on the bundled backstepping valve: it
//! compiles as a `#![no_std]` crate against the runtime, passes clippy with
//! the panic lints denied, gives an input in [u_min, u_max] for any input
//! (NaN, ±∞, 0, φ = 0, z at both stops and beyond them, any time), keeps the
//! switching state (the token M) in the controller, is byte-deterministic,
//! and one changed value is one changed line per place it is stated.
//!
//! The check crate is the scratch crate `target/codegen-check-backstepping/`.

use std::fmt::Write as _;

use designer::description::parse_str;
use designer::design::Design;
use reldesign_build::emit;
use support::{example_path, ScratchCrate, ODD_FLOATS as ODD};

fn example_text() -> String {
    std::fs::read_to_string(example_path("backstepping-valve.toml")).unwrap()
}

fn emitted(text: &str) -> String {
    let d = parse_str(text, "backstepping-valve.toml").unwrap_or_else(|e| panic!("{e}"));
    emit(&Design::new(&d).unwrap_or_else(|e| panic!("{e}"))).unwrap_or_else(|e| panic!("{e}"))
}

/// `text` with `from` replaced once (which must be there).
fn changed(text: &str, from: &str, to: &str) -> String {
    support::replaced_once(text, from, to)
}

#[test]
fn emission_is_deterministic_and_holds_the_law_once() {
    let (a, b) = (emitted(&example_text()), emitted(&example_text()));
    assert_eq!(a, b);
    let code = support::code_only(&a);
    for word in [
        " as ", "unwrap", "expect(", "panic", "[0]", "unsafe", "alloc",
    ] {
        assert!(
            code.iter().all(|l| !l.contains(word)),
            "`{word}` in the emitted code"
        );
    }
    assert_eq!(a.matches("macro_rules! law {").count(), 1);
    for f in ["f32", "f64"] {
        assert_eq!(a.matches(&format!("law!({f});")).count(), 1, "{f}");
        let controller =
            format!("pub type Controller = backstepping::SwitchedBackstepping<Design, {f}>;");
        assert_eq!(a.matches(&controller).count(), 1, "{f}");
        assert_eq!(
            a.matches(&format!("impl backstepping::Backstepping<{f}> for Design"))
                .count(),
            1
        );
    }
    // the equations are cited where they are computed
    for tag in [
        "[SB 9]",
        "[SB Theorem 1]",
        "[SB 19]",
        "[SB Theorem 3]",
        "[SB lemma 1]",
    ] {
        assert!(a.contains(tag), "{tag} not cited");
    }
    assert!(
        !a.contains("fn step"),
        "a step was emitted: it is the runtime's"
    );
}

#[test]
fn one_change_is_one_line_where_it_is_stated() {
    let text = example_text();
    let base = emitted(&text);
    // R enters the law, not the region: the source hash and R in `params!`
    let r = emitted(&changed(&text, "resistance = 75.0", "resistance = 80.0"));
    let diff = support::changed_lines(&base, &r);
    assert_eq!(diff.len(), 2, "the source hash and R: {diff:#?}");
    assert!(diff[1].1.contains("pub const R: $f = 80.0;"), "{diff:?}");
    // α₃ enters the law, not the region: the hash, GAIN_A3 per float module
    let a3 = emitted(&changed(&text, "2000.0]", "2500.0]"));
    let diff = support::changed_lines(&base, &a3);
    assert_eq!(diff.len(), 3, "{diff:#?}");
    assert!(
        diff[1..]
            .iter()
            .all(|(_, new)| new.contains("pub const GAIN_A3: f") && new.contains("= 2500.0;")),
        "{diff:#?}"
    );
    // the period: the hash, PERIOD per float module
    let p = emitted(&changed(&text, "0.7e-3, 0.2]", "0.7e-3, 0.25]"));
    let diff = support::changed_lines(&base, &p);
    assert_eq!(diff.len(), 3, "{diff:#?}");
    assert!(
        diff[1..]
            .iter()
            .all(|(_, new)| new.contains("pub const PERIOD: f") && new.contains("= 0.25;")),
        "{diff:#?}"
    );
}

#[test]
fn emitted_module_compiles_passes_clippy_and_is_total() {
    let krate = ScratchCrate::new("codegen-check-backstepping");
    krate.write(
        "src/lib.rs",
        "//! Emitted by codegen/tests/backstepping.rs.\n#![no_std]\n#![forbid(unsafe_code)]\n\npub mod valve;\n",
    );
    krate.write("src/valve.rs", &emitted(&example_text()));
    let mut main = String::from("use codegen_check_backstepping::valve;\n\nfn main() {\n");
    for module in ["f64", "f32"] {
        let odd = ODD.join(", ");
        writeln!(
            main,
            "    {{
        use valve::{module}::*;
        type F = {module};
        let ts = [0.0, 0.15, {odd}];
        let zs = [Z_MIN, Z_MAX, POSITION_LOW, 5e-4, {odd}];
        let vs = [0.05, {odd}];
        let phis = [PHI_GUARD, 8e-6, -1e-5, {odd}];
        for t in ts {{
            for z in zs {{
                for v in vs {{
                    for phi in phis {{
                        let mut c = Controller::new();
                        let u = c.step(t, z, v, phi, 0.0);
                        let again = c.step(t, z, v, phi, 0.0);
                        println!(\"{module} {{u:e}} {{again:e}} {{:?}}\", c.mode());
                    }}
                }}
            }}
        }}
    }}"
        )
        .unwrap();
    }
    main.push_str("}\n");
    krate.write("src/main.rs", &main);
    let text = krate.run_panic_free(&[]);
    let (mut n, mut waiting) = (0, 0);
    for line in text.lines() {
        let f: Vec<&str> = line.split(' ').collect();
        let [_module, u, again, mode] = f[..] else {
            panic!("{line}")
        };
        for u in [u, again] {
            let u: f64 = u.parse().unwrap();
            assert!(u.is_finite() && (-24.0..=24.0).contains(&u), "{line}");
        }
        waiting += usize::from(mode == "Waiting");
        n += 1;
    }
    assert_eq!(n, 2 * (2 + 9) * (4 + 9) * (1 + 9) * (3 + 9));
    assert!(waiting > 0, "the hybrid strategy never waited");
}
