//! The backstepping switching rules (`reldesign_runtime::backstepping`) as
//! data: the mode after one sample for every strategy, previous mode, region
//! membership and sign of F_d (NaN included), against the cases of
//! switched-force-backstepping [SB 28] and [SB 31–33]; and the square
//! reference restarting the strategy at each change.

use reldesign_runtime::backstepping::{
    next_mode, Backstepping, BacksteppingSettings, Mode, SetPoint, SwitchedBackstepping, Switching,
    Target,
};

use Mode::{Approaching, Inside, Start, Waiting};

/// (strategy, mode before, V ≤ C, F_d, mode after).
const RULES: &[(Switching, Mode, bool, f64, Mode)] = &[
    // inside D: the law, whatever came before (case 1 of each strategy)
    (Switching::None, Start, true, -1.0, Inside),
    (Switching::Intuitive, Waiting, true, 1.0, Inside),
    (Switching::Hybrid, Approaching, true, -1.0, Inside),
    // once inside, the law stays (the latch)
    (Switching::Intuitive, Inside, false, -1.0, Inside),
    (Switching::Hybrid, Inside, false, f64::NAN, Inside),
    // none: the law everywhere
    (Switching::None, Start, false, -1.0, Approaching),
    (Switching::None, Approaching, false, f64::NAN, Approaching),
    // intuitive [SB 28]: u = 0 outside D, whatever F_d
    (Switching::Intuitive, Start, false, 1.0, Waiting),
    (Switching::Intuitive, Start, false, -1.0, Waiting),
    (Switching::Intuitive, Waiting, false, 1.0, Waiting),
    // hybrid [SB 31–33]: the law while F_d > 0 (case 3) …
    (Switching::Hybrid, Start, false, 1.0, Approaching),
    (Switching::Hybrid, Approaching, false, 0.5, Approaching),
    // … u = 0 from F_d ≤ 0 on (case 2, the token drops) …
    (Switching::Hybrid, Start, false, -1.0, Waiting),
    (Switching::Hybrid, Approaching, false, 0.0, Waiting),
    (Switching::Hybrid, Approaching, false, f64::NAN, Waiting),
    // … and it does not come back before D (at most two switches)
    (Switching::Hybrid, Waiting, false, 1.0, Waiting),
];

#[test]
fn the_strategies_rules_as_data() {
    for &(switching, before, inside, desired, after) in RULES {
        assert_eq!(
            next_mode(switching, before, inside, desired),
            after,
            "{switching:?} from {before:?}, inside {inside}, F_d {desired}"
        );
    }
}

/// A plan with V = z₁², C = 1, F_d = 1 and the law u = 5: the square
/// reference 0 ↔ 10 of period 2 restarts the strategy at each change.
struct Plan;

impl Backstepping<f64> for Plan {
    fn settings(&self) -> BacksteppingSettings<f64> {
        BacksteppingSettings {
            u_min: -24.0,
            u_max: 24.0,
            phi_guard: 1e-9,
            alpha1: 0.0,
            p: [1.0, 0.0, 0.0],
            switching: Switching::Intuitive,
            reference: SetPoint::Square {
                low: Target {
                    position: 0.0,
                    level: 1.0,
                },
                high: Target {
                    position: 10.0,
                    level: 1.0,
                },
                period: 2.0,
            },
        }
    }
    fn desired_force(&self, _z: f64, _v: f64, _y_r: f64) -> f64 {
        1.0
    }
    fn law(&self, _x: [f64; 4], _y_r: f64) -> f64 {
        5.0
    }
}

#[test]
fn a_change_of_the_square_reference_restarts_the_strategy() {
    let mut c = SwitchedBackstepping::with(Plan);
    // z = 0.5: inside D of y_r = 0, the law
    assert_eq!(c.step(0.0, 0.5, 0.0, 1e-3, 0.0), 5.0);
    assert_eq!(c.mode(), Inside);
    // at t = 1 the reference is 10: z = 0.5 is outside its D → intuitive waits
    assert_eq!(c.step(1.0, 0.5, 0.0, 1e-3, 0.0), 0.0);
    assert_eq!(c.mode(), Waiting);
    // inside the new D: the law again; back at t = 2 to y_r = 0: outside, waits
    assert_eq!(c.step(1.5, 9.5, 0.0, 1e-3, 0.0), 5.0);
    assert_eq!(c.step(2.0, 9.5, 0.0, 1e-3, 0.0), 0.0);
    // NaN states: the bound nearest 0 (u = 0), never a panic
    assert_eq!(c.step(2.5, f64::NAN, f64::NAN, f64::NAN, 0.0), 0.0);
    // below the flux guard inside D: u_max builds the flux
    let mut c = SwitchedBackstepping::with(Plan);
    assert_eq!(c.step(0.0, 0.5, 0.0, 0.0, 0.0), 24.0);
}
