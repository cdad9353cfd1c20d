//! The shortest pre-movement stage the supply allows (issue 37, §2): a
//! design whose lift-off the supply can only make so late that the motion
//! starts with errors beyond the robustness analysis's bounds [SM 52] is
//! refused with that time and the key to change; a marginally late one is
//! designed, with a warning in the report; every report gives the takeoff
//! needed against the one planned.

use designer::description::parse_str;
use designer::design::{Design, PlanError, Shortest, Verdict};
use support::{example_path, root};

fn design(path: std::path::PathBuf, replacements: &[(&str, &str)]) -> Result<Design, PlanError> {
    let mut text = std::fs::read_to_string(path).unwrap();
    for (from, to) in replacements {
        assert!(text.contains(from), "{from}");
        text = text.replacen(from, to, 1);
    }
    let d = parse_str(&text, "valve.toml").unwrap_or_else(|e| panic!("{e}"));
    Design::new(&d)
}

fn valve(replacements: &[(&str, &str)]) -> Result<Design, PlanError> {
    design(example_path("perfect-tracking-valve.toml"), replacements)
}

/// The milliseconds of `needed` ("after 1.9804 ms").
fn needed_ms(err: &PlanError) -> f64 {
    let PlanError::TakeoffTooShort { needed, .. } = err else {
        panic!("{err}");
    };
    needed
        .trim_start_matches("after ")
        .trim_end_matches(" ms")
        .parse()
        .unwrap_or_else(|_| panic!("{needed}"))
}

#[test]
fn a_takeoff_stage_shorter_than_the_supply_allows_is_refused_with_the_time_needed() {
    // at 24 V the valve's flux reaches takeoff after 0.83 ms; from 0.5 ms the
    // energy-optimal closing has reached 27 % of its largest
    // acceleration by then, beyond the 20 % of [SM 52]
    let err = valve(&[("takeoff = 1e-3", "takeoff = 0.5e-3")])
        .err()
        .expect("refused");
    let text = err.to_string();
    assert!(matches!(err, PlanError::TakeoffTooShort { .. }), "{text}");
    assert!(
        text.contains("closing")
            && text.contains("trajectory.takeoff")
            && text.contains("supply.u_max")
            && text.contains("after 0.8")
            && text.contains("beyond the 20 % the design assumes [SM 52]"),
        "{text}"
    );
}

#[test]
fn strong_eddy_currents_need_a_longer_takeoff() {
    // k_e ×20: the flux needs ~2 ms of the 1 ms stage (u_bound raised to the
    // 21.8 V the 5 ms motion then needs, so that the reference exists)
    let err = valve(&[
        ("eddy = 1500.0", "eddy = 30000.0"),
        ("u_bound = 20.0", "u_bound = 23.0"),
    ])
    .err()
    .expect("refused");
    let ms = needed_ms(&err);
    assert!((1.5..2.5).contains(&ms), "{err}");
}

#[test]
fn a_lift_off_after_the_landing_is_refused_before_the_reference() {
    // k_e ×200: the flux needs longer than the whole operation (t_f = 6 ms);
    // refused whatever the reference, although u_bound = 20 V could not
    // carry its motion either
    let err = valve(&[("eddy = 1500.0", "eddy = 300000.0")])
        .err()
        .expect("refused");
    assert!(needed_ms(&err) > 6.0, "{err}");
    assert!(err.to_string().contains("100.0 % of max|v_r|"), "{err}");
}

#[test]
fn a_marginally_late_takeoff_is_designed_with_a_warning() {
    // the 12 V relay needs 1.0143 ms of its 1 ms: 3 % of max|a_r| by then
    let relay = design(root().join("tests/data/relay-12v.toml"), &[]).expect("designed");
    let c = relay.controller.as_ref().unwrap();
    let closing = c.operations[0].takeoff.unwrap();
    assert_eq!(closing.verdict(), Verdict::Late);
    let Shortest::After(t) = closing.shortest else {
        panic!("{closing:?}");
    };
    assert!((1.01e-3..1.02e-3).contains(&t), "{t}");
    assert!(closing.acceleration_error < 0.05 && closing.velocity_error < 1e-3);
    let report = relay.report();
    assert!(
        report.contains("takeoff: needs 1.0143 ms at the supply limit, has 1.0000 ms"),
        "{report}"
    );
    assert!(
        report.contains("warning: the armature can leave its stop only 0.0143 ms after"),
        "{report}"
    );
    // the opening drains the flux of the hold (t₀ at 12 V after landing
    // [SM 45]) in 0.88 ms; its energy-optimal motion rests until 3.6 ms first
    let opening = c.operations[1].takeoff.unwrap();
    assert_eq!(opening.verdict(), Verdict::InTime, "{opening:?}");
    assert!(opening.planned > opening.t0, "{opening:?}");
    assert!(
        (0.8e-3..0.95e-3).contains(&opening.shortest.at_least()),
        "{opening:?}"
    );
    assert!(
        report.contains("has 3.6156 ms (supply.u_min = -12; the motion rests from"),
        "{report}"
    );
    assert_eq!(report.matches("warning:").count(), 1, "{report}");
}

#[test]
fn the_bundled_designs_take_off_in_time() {
    for file in [
        "perfect-tracking-valve.toml",
        "sliding-mode-valve.toml",
        "self-calibrating-valve.toml",
    ] {
        let d = designer::description::parse_file(&example_path(file)).unwrap();
        let design = Design::new(&d).unwrap_or_else(|e| panic!("{file}: {e}"));
        for o in &design.controller.as_ref().unwrap().operations {
            let takeoff = o.takeoff.unwrap();
            assert_eq!(takeoff.verdict(), Verdict::InTime, "{file}: {takeoff:?}");
        }
        let report = design.report();
        assert!(report.contains("takeoff: needs "), "{file}: {report}");
        assert!(!report.contains("warning:"), "{file}: {report}");
    }
}
