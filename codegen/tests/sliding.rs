//! The emitted model-free sliding-mode module (`codegen/src/sliding.rs`): it
//! compiles as a `#![no_std]` crate against the runtime, passes clippy with
//! the panic lints denied, gives a finite, saturated input for any input, is
//! byte-deterministic, and one changed parameter or gain is one changed line
//! per place it is stated.

use std::fmt::Write as _;

use designer::description::parse_str;
use designer::design::Design;
use reldesign_build::emit;
use support::{example_path, ScratchCrate};

fn example_text() -> String {
    std::fs::read_to_string(example_path("sliding-mode-valve.toml")).unwrap()
}

fn emitted(text: &str) -> String {
    let d = parse_str(text, "sliding-mode-valve.toml").unwrap_or_else(|e| panic!("{e}"));
    emit(&Design::new(&d).unwrap_or_else(|e| panic!("{e}"))).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn emission_is_deterministic_and_small() {
    let (a, b) = (emitted(&example_text()), emitted(&example_text()));
    assert_eq!(a, b);
    assert!(a.lines().count() <= 400, "{} lines", a.lines().count());
    let code: Vec<&str> = a
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect();
    for word in [" as ", "unwrap", "expect(", "panic", "[0]"] {
        assert!(
            code.iter().all(|l| !l.contains(word)),
            "`{word}` in the emitted code"
        );
    }
    // the law is the runtime's: no model function is emitted
    assert!(!a.contains("fn law") && a.contains("sliding::SlidingMode<Design, f32>"));
}

#[test]
fn one_change_is_one_line_where_it_is_stated() {
    let text = example_text();
    let base = emitted(&text);
    let r = emitted(&text.replacen("resistance = 50.0", "resistance = 51.5", 1));
    let diff = support::changed_lines(&base, &r);
    assert_eq!(diff.len(), 2, "the source hash and R: {diff:#?}");
    assert!(diff[1].1.contains("pub const R: $f = 51.5;"), "{diff:?}");
    let l = emitted(&text.replacen("lambda1 = 2000.0", "lambda1 = 2500.0", 1));
    let diff = support::changed_lines(&base, &l);
    // the hash, then LAMBDA1 once per float module
    assert_eq!(diff.len(), 3, "{diff:#?}");
    assert!(diff[1..]
        .iter()
        .all(|(_, new)| new.contains("pub const LAMBDA1: f") && new.contains("= 2500.0;")));
}

#[test]
fn emitted_module_compiles_passes_clippy_and_is_total() {
    let krate = ScratchCrate::new("codegen-check-sliding");
    krate.write(
        "src/lib.rs",
        "//! Emitted by codegen/tests/sliding.rs.\n#![no_std]\n#![forbid(unsafe_code)]\n\npub mod valve;\n",
    );
    krate.write("src/valve.rs", &emitted(&example_text()));
    let odd = [
        "0.0",
        "-0.0",
        "1e-3",
        "-1e-3",
        "1e30",
        "-1e30",
        "INFINITY",
        "NEG_INFINITY",
        "NAN",
    ];
    let mut main = String::from("use codegen_check_sliding::valve;\n\nfn main() {\n");
    for module in ["f64", "f32"] {
        for op in ["Closing", "Opening"] {
            writeln!(
                main,
                "    let mut c = valve::{module}::Controller::new(valve::{module}::Operation::{op});\n    c.start(0.0);"
            )
            .unwrap();
            for t in ["0.5e-3", "2e-3", "4.5e-3", "5.5e-3", "NAN"] {
                for x in odd {
                    let x = if x.chars().next().is_some_and(char::is_alphabetic) {
                        format!("{module}::{x}")
                    } else {
                        format!("{x}_{module}")
                    };
                    let t = if t == "NAN" {
                        format!("{module}::NAN")
                    } else {
                        format!("{t}_{module}")
                    };
                    for args in [
                        format!("{t}, {x}, 0.0, 0.0, 1e-5"),
                        format!("{t}, 5e-4, {x}, 0.0, 1e-5"),
                        format!("{t}, 5e-4, 0.0, {x}, 1e-5"),
                        format!("{t}, 5e-4, 0.0, 0.0, {x}"),
                    ] {
                        writeln!(main, "    println!(\"{{:?}}\", c.step({args}));").unwrap();
                    }
                }
            }
        }
    }
    main.push_str("}\n");
    krate.write("src/main.rs", &main);
    let text = krate.run_panic_free(&[]);
    let mut n = 0;
    for line in text.lines() {
        let u: f64 = line.parse().unwrap();
        assert!(u.is_finite() && (-40.0..=40.0).contains(&u), "{u}");
        n += 1;
    }
    assert_eq!(n, 2 * 2 * 5 * 9 * 4);
}
