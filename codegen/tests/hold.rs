//! The emitted position hold of the model-based sliding mode
//! (`codegen/src/hold.rs`, jiles-atherton-actuator-model [JA §6.2]) on the
//! Jiles–Atherton valve: it compiles as a `#![no_std]` crate against the
//! runtime, passes clippy with the panic lints denied, gives an input in
//! [0, u_max] for any input (NaN, ±∞, 0, φ = 0, z at both stops and beyond
//! them) and keeps the stop rules [JA 94] there, is byte-deterministic, and
//! one changed parameter is one changed line per place it is stated.
//!
//! The check crate is the scratch crate `target/codegen-check-hold/`
//! (`support::ScratchCrate`, built in the scratch crates' shared target dir).

use std::fmt::Write as _;

use designer::description::parse_str;
use designer::design::Design;
use reldesign_build::emit;
use support::{example_path, ScratchCrate, ODD_FLOATS as ODD};

fn example_text() -> String {
    std::fs::read_to_string(example_path("jiles-atherton-valve.toml")).unwrap()
}

fn design(text: &str) -> Design {
    let d = parse_str(text, "jiles-atherton-valve.toml").unwrap_or_else(|e| panic!("{e}"));
    Design::new(&d).unwrap_or_else(|e| panic!("{e}"))
}

fn emitted(text: &str) -> String {
    emit(&design(text)).unwrap_or_else(|e| panic!("{e}"))
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
    // the law's functions written once, invoked by each float module; the
    // mode rules, the guard and the saturation are the runtime's
    assert_eq!(a.matches("macro_rules! law {").count(), 1);
    for f in ["f32", "f64"] {
        assert_eq!(a.matches(&format!("law!({f});")).count(), 1, "{f}");
        assert_eq!(
            a.matches(&format!(
                "pub type Controller = hold::PositionHold<Design, {f}>;"
            ))
            .count(),
            1,
            "{f}"
        );
        assert_eq!(
            a.matches(&format!("impl hold::Hold<{f}> for Design"))
                .count(),
            1,
            "{f}"
        );
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
    // a physical parameter: the source hash and its one line in `params!`
    let r = emitted(&changed(&text, "resistance = 50.0", "resistance = 51.5"));
    let diff = support::changed_lines(&base, &r);
    assert_eq!(diff.len(), 2, "the source hash and R: {diff:#?}");
    assert!(diff[1].1.contains("pub const R: $f = 51.5;"), "{diff:?}");
    // the position: the hash, then POSITION once per float module (the
    // guard, 10⁻³ of the holding flux rounded down, stays 1e-8 Wb)
    let z = emitted(&changed(&text, "position = 4.5e-4", "position = 5e-4"));
    let diff = support::changed_lines(&base, &z);
    assert_eq!(diff.len(), 3, "{diff:#?}");
    assert!(
        diff[1..]
            .iter()
            .all(|(_, new)| new.contains("pub const POSITION: f") && new.contains("= 0.0005;")),
        "{diff:#?}"
    );
    // p: the hash, then per float module p and the three gains of [PT 48]
    // it states (K·p², p² + 2pK, 2p + K with K = 10⁴): nothing else
    let p = emitted(&changed(&text, "p = 1e3", "p = 1.5e3"));
    let diff = support::changed_lines(&base, &p);
    assert_eq!(diff.len(), 9, "{diff:#?}");
    for (k, (_, new)) in diff[1..].iter().enumerate() {
        let want = [
            "pub const SURFACE_P: f{} = 1500.0;",
            "pub const GAIN_K1: f{} = 22500000000.0;",
            "pub const GAIN_K2: f{} = 32250000.0;",
            "pub const GAIN_K3: f{} = 13000.0;",
        ][k % 4];
        let float = if k < 4 { "32" } else { "64" };
        assert!(
            new.contains(&want.replace("{}", float)),
            "{new:?}: {want} ({float})"
        );
    }
}

#[test]
fn emitted_module_compiles_passes_clippy_and_is_total() {
    let krate = ScratchCrate::new("codegen-check-hold");
    krate.write(
        "src/lib.rs",
        "//! Emitted by codegen/tests/hold.rs.\n#![no_std]\n#![forbid(unsafe_code)]\n\npub mod valve;\n",
    );
    krate.write("src/valve.rs", &emitted(&example_text()));
    // every combination of: z at the stops, their band's edges, the
    // position, mid-stroke, outside the stroke and odd; v, φ, H_c odd or
    // plausible (φ at the guard, at the holding flux and negative)
    let mut main = String::from("use codegen_check_hold::valve;\n\nfn main() {\n");
    for module in ["f64", "f32"] {
        let odd = ODD.join(", ");
        writeln!(
            main,
            "    {{
        use valve::{module}::*;
        type F = {module};
        let c = Controller::new();
        let zs = [Z_MIN, Z_MAX, Z_MIN + LANDED_BAND, Z_MAX - LANDED_BAND, POSITION, 2e-4, {odd}];
        let vs = [0.1, {odd}];
        let phis = [PHI_GUARD, 1.2e-5, -1e-5, {odd}];
        let hcs = [250.0, {odd}];
        for z in zs {{
            for v in vs {{
                for phi in phis {{
                    for hc in hcs {{
                        let u = c.step(z, v, phi, hc);
                        println!(\"{module} {{z:e}} {{v:e}} {{phi:e}} {{hc:e}} {{u:e}}\");
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
    let d = design(&example_text());
    let h = d.hold.as_ref().unwrap();
    let (mut n, mut at_stops, mut guarded, mut law) = (0, 0, 0, 0);
    for line in text.lines() {
        let f: Vec<&str> = line.split(' ').collect();
        let [_module, z, v, phi, hc, u] = f[..] else {
            panic!("{line}")
        };
        let [z, _v, phi, _hc, u] = [z, v, phi, hc, u].map(|x| x.parse::<f64>().unwrap());
        assert!(u.is_finite() && (0.0..=h.u_max).contains(&u), "{line}");
        // [JA 94] with z_ref = z_max/2: 0 at (or below) z_min, u_max at (or
        // beyond) z_max, whatever the rest of the state; the rounding of
        // z_max − band to f32 is z_max, at the stop too
        let band = h.landed_band;
        if z <= h.z_min + band {
            assert_eq!(u, 0.0, "{line}");
            at_stops += 1;
        } else if z >= h.z_max - band {
            assert_eq!(u, h.u_max, "{line}");
            at_stops += 1;
        } else if phi <= h.phi_guard * (1.0 + 1e-6) {
            // φ → 0 (and φ ≤ 0, z NaN included): the flux is built with u_max
            assert_eq!(u, h.u_max, "{line}");
            guarded += 1;
        } else {
            law += 1;
        }
        n += 1;
    }
    let per_module = (6 + 9) * 10 * 12 * 10;
    assert_eq!(n, 2 * per_module);
    assert!(
        at_stops > 0 && guarded > 0 && law > 0,
        "{at_stops} {guarded} {law}"
    );
}

/// The feedback-linearizing controller on the Jiles–Atherton core (a
/// polynomial `[trajectory]`): the emitted law takes H_c, `guarded_law`
/// passes it to the runtime, and the module compiles `no_std`, passes
/// clippy's panic-free gate, and `step_with_field` is total.
#[test]
fn the_tracking_law_on_the_hysteretic_core_takes_the_field() {
    let physics = example_text();
    let physics = &physics[..physics.find("\n[controller]").unwrap()];
    let text = format!(
        "{physics}\n[trajectory]\noperations = [\"closing\", \"opening\"]\ntakeoff = 2e-3\nlanding = 8e-3\nshape = \"polynomial\"\nu_bound = 24.0\n\n[controller]\nlaw = \"feedback-linearization\"\nsettling_time = 1e-3\nsample_period = 1e-5\n"
    );
    let code = emitted(&text);
    assert!(code.contains("hc: $f,") && code.contains("law_terms(z, v, phi, hc, zr, vr, ar, jr)"));
    assert!(code.contains("control::guarded_law(&Design, [z, v, phi, hc], [zr, vr, ar, jr])"));
    let krate = ScratchCrate::new("codegen-check-ja-tracking");
    krate.write(
        "src/lib.rs",
        "//! Emitted by codegen/tests/hold.rs.\n#![no_std]\n#![forbid(unsafe_code)]\n\npub mod valve;\n",
    );
    krate.write("src/valve.rs", &code);
    let odd = ODD.join(", ");
    let main = format!(
        "use codegen_check_ja_tracking::valve::f64::*;\n\ntype F = f64;\n\nfn main() {{
    let mut n = 0;
    for t in [0.0, 3e-3, 9e-3, {odd}] {{
        for z in [Z_MIN, Z_MAX, 4e-4, {odd}] {{
            for phi in [0.0, 1e-5, {odd}] {{
                for hc in [300.0, {odd}] {{
                    let mut c = Controller::new(Operation::Closing);
                    let u = c.step_with_field(t, z, 0.1, phi, hc);
                    assert!(u.is_finite() && (U_MIN..=U_MAX).contains(&u), \"{{t}} {{z}} {{phi}} {{hc}} {{u}}\");
                    n += 1;
                }}
            }}
        }}
    }}
    println!(\"{{n}}\");
}}\n"
    );
    krate.write("src/main.rs", &main);
    let n: usize = krate.run_panic_free(&[]).trim().parse().unwrap();
    assert_eq!(n, (3 + 9) * (3 + 9) * (2 + 9) * (1 + 9));
}
