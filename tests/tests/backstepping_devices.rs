//! The backstepping law (switched-force-backstepping) on devices nobody tuned
//! it for: the seeded generator's relays and valves, every gap model and
//! every core (linear, saturating, and Jiles–Atherton, whose H_c the law reads). Per device the same design (α₁ = α₂ = 200 s⁻¹,
//! α₃ = 3000 s⁻¹, the hybrid switching, the default decay, the armature held
//! at mid-stroke, 100 kHz): either the design is certified, and then the loop
//! from rest on the spring's stop converges to the position within 1 % of
//! the stroke in 100 ms with at most two switches of the input law, or it is
//! refused with a named reason (the position cannot be held within the
//! supply, or no quadratic V holds the spring's rest).
//! The family is seeded, so the outcome is asserted exactly: all 33 devices
//! certify and converge (to within 1.1e-6 of the stroke at worst, measured;
//! the 3 Jiles–Atherton ones to 9e-9–1.1e-6). (The generator's first
//! Jiles–Atherton cores had a relative permeability of 2–7 and were refused
//! here as needing 3–38× their supply to hold; tests/src/devices.rs.) The
//! bundled Jiles–Atherton valve is positioned in designer/tests/backstepping.rs.

use designer::backstepping_loop::run_backstepping;
use designer::closed_loop::Noise;
use designer::design::{Design, PlanError};
use designer::sim::Options;
use reldesign_tests::devices::{device, devices};

#[test]
fn backstepping_certifies_and_converges_on_generated_devices() {
    let (mut certified, mut refused) = (Vec::new(), Vec::new());
    let ja = (0..3).map(|i| device(2026_11_26, i, true));
    for device in devices(2026_11_26, 30).into_iter().chain(ja) {
        let d = device.description_with("");
        let y_r = d.mechanics.z_min + 0.5 * device.stroke;
        let design = format!(
            "[controller]\nlaw = \"backstepping\"\ngains = [200.0, 200.0, 3000.0]\n\
             switching = \"hybrid\"\nposition = {y_r:e}\nsample_period = 1e-5\n"
        );
        let d = device.description_with(&design);
        let design = match Design::new(&d) {
            Ok(design) => design,
            Err(e @ PlanError::HoldingInput { .. }) => {
                refused.push(format!("{}: {e}", device.name));
                continue;
            }
            Err(e) => panic!("{}: an unnamed refusal: {e}", device.name),
        };
        let run = run_backstepping(
            &design,
            None,
            1e-5,
            Some(0.1),
            Noise::seeded(0),
            None,
            &Options::default(),
        )
        .unwrap_or_else(|e| panic!("{}: the loop fails: {e}", device.name));
        let tr = &run.run.trajectory;
        let end = tr.x[tr.t.len() - 1][0];
        let error = (end - y_r).abs() / device.stroke;
        assert!(
            error < 1e-5,
            "{}: z(100 ms) off by {:.2e} of the stroke",
            device.name,
            error
        );
        let b = design.backstepping.as_ref().expect("backstepping");
        let after = run
            .after_entry(b.u_min, b.u_max)
            .expect("the law took over");
        assert_eq!(
            (after.pushing, after.bang_bang),
            (0, 0),
            "{}: {after:?}",
            device.name
        );
        assert!(
            run.switches() <= 2,
            "{}: {} switches",
            device.name,
            run.switches()
        );
        certified.push(format!(
            "{} ({:?}, {:?}, {:?}): error {:.1e} of the stroke",
            device.name, device.class, device.gap, device.core, error
        ));
    }
    eprintln!(
        "certified:\n  {}\nrefused:\n  {}",
        certified.join("\n  "),
        refused.join("\n  ")
    );
    assert_eq!(
        (certified.len(), refused.len()),
        (33, 0),
        "certified / refused"
    );
}
