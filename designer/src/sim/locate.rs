//! Event location: the Illinois (modified regula falsi) bracketing root
//! finder that places impacts, lift-offs and branch switches on the dense
//! output. Its own module so that the automaton (`hybrid.rs`) and the branch
//! switching (`switching.rs`) share it without importing each other.

/// Illinois root finder on `[a, b]` with `g(a) ≤ 0 < g(b)`: returns a time
/// within `tol` of the crossing on its triggered side (`g > 0`).
pub(crate) fn locate<G: FnMut(f64) -> f64>(
    mut g: G,
    mut a: f64,
    mut ga: f64,
    mut b: f64,
    mut gb: f64,
    tol: f64,
) -> f64 {
    let mut side = 0i8;
    let mut same_side = 0;
    for _ in 0..300 {
        if b - a <= tol {
            break;
        }
        let mut t = b - gb * (b - a) / (gb - ga);
        if same_side >= 3 || !(t > a && t < b) {
            t = 0.5 * (a + b);
            same_side = 0;
        }
        if !(t > a && t < b) {
            break; // a and b are adjacent floats
        }
        let gt = g(t);
        if gt > 0.0 {
            if side == 1 {
                ga *= 0.5;
                same_side += 1;
            } else {
                same_side = 0;
            }
            (b, gb, side) = (t, gt, 1);
        } else {
            if side == -1 {
                gb *= 0.5;
                same_side += 1;
            } else {
                same_side = 0;
            }
            (a, ga, side) = (t, gt, -1);
        }
    }
    b
}
