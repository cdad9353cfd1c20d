//! The shortest pre-movement stage the supply allows (issue 37, §2): a
//! design whose takeoff stage is shorter is refused with that time and the
//! key to change; the bundled designs pass.

use designer::description::parse_str;
use designer::design::{Design, PlanError};
use support::example_path;

fn valve(replacements: &[(&str, &str)]) -> Result<Design, PlanError> {
    let mut text = std::fs::read_to_string(example_path("perfect-tracking-valve.toml")).unwrap();
    for (from, to) in replacements {
        assert!(text.contains(from), "{from}");
        text = text.replacen(from, to, 1);
    }
    let d = parse_str(&text, "valve.toml").unwrap_or_else(|e| panic!("{e}"));
    Design::new(&d)
}

#[test]
fn a_takeoff_stage_shorter_than_the_supply_allows_is_refused_with_the_time_needed() {
    // at 24 V the valve's flux reaches takeoff after 0.86 ms
    let err = valve(&[("takeoff = 1e-3", "takeoff = 0.5e-3")])
        .err()
        .expect("refused");
    let text = err.to_string();
    assert!(matches!(err, PlanError::TakeoffTooShort { .. }), "{text}");
    assert!(
        text.contains("closing")
            && text.contains("trajectory.takeoff")
            && text.contains("supply.u_max")
            && text.contains("after 0.8"),
        "{text}"
    );
}

#[test]
fn strong_eddy_currents_need_a_longer_takeoff() {
    // k_e ×20: the flux builds ~8× slower than the 1 ms stage allows
    let err = valve(&[("eddy = 1500.0", "eddy = 30000.0")])
        .err()
        .expect("refused");
    let PlanError::TakeoffTooShort { needed, .. } = &err else {
        panic!("{err}");
    };
    let ms: f64 = needed
        .trim_start_matches("after ")
        .trim_end_matches(" ms")
        .parse()
        .unwrap_or_else(|_| panic!("{needed}"));
    assert!(ms > 1.0, "{err}");
}

#[test]
fn the_bundled_designs_take_off_in_time() {
    for file in [
        "perfect-tracking-valve.toml",
        "sliding-mode-valve.toml",
        "self-calibrating-valve.toml",
    ] {
        let d = designer::description::parse_file(&example_path(file)).unwrap();
        Design::new(&d).unwrap_or_else(|e| panic!("{file}: {e}"));
    }
}
