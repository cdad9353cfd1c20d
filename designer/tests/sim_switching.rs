//! Discontinuity locking (`sim/switching.rs`) on toy plants with known
//! solutions: the located switch times, the accuracy and the work against
//! integrating the same field with the live sign, a switching function that
//! starts at zero, and chattering (a sliding motion) falling back to the live
//! sign.

use designer::sim::{
    simulate, Branches, Limits, Mode, Options, PiecewiseLinear, Plant, State, Trajectory,
    MAX_CHATTER,
};

/// States (z, v, y, w) with z, v at rest between far stops and, for the
/// input u = t,
///   ẏ = u − y,  ẇ = sign(u − y)·(u − y) = |ẏ|:
/// w is the total variation of y. From y(0) = 1: y = t − 1 + 2e^{−t}, and ẏ
/// changes sign at t* = ln 2, where ẇ has a kink.
struct Variation {
    /// Expose the switching function (else the field uses the live sign).
    locked: bool,
}

impl Variation {
    fn y(t: f64) -> f64 {
        t - 1.0 + 2.0 * (-t).exp()
    }
    fn w(t: f64) -> f64 {
        let y_star = Self::y(2f64.ln());
        if t < 2f64.ln() {
            1.0 - Self::y(t)
        } else {
            (1.0 - y_star) + (Self::y(t) - y_star)
        }
    }
}

fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

impl Plant for Variation {
    fn dim(&self) -> usize {
        4
    }
    fn deriv(&self, t: f64, x: &State, u: f64, dx: &mut State) {
        let mut s = [0.0; 4];
        Plant::switching(self, t, x, u, &mut s);
        self.deriv_branch(t, x, u, &[sign(s[0]), 0.0, 0.0, 0.0], dx);
    }
    fn switches(&self) -> usize {
        usize::from(self.locked)
    }
    fn switching(&self, _t: f64, x: &State, u: f64, s: &mut Branches) {
        s[0] = u - x[2];
    }
    fn deriv_branch(&self, _t: f64, x: &State, u: f64, branch: &Branches, dx: &mut State) {
        let ydot = u - x[2];
        *dx = [0.0, 0.0, ydot, branch[0] * ydot];
    }
    fn scale(&self) -> State {
        [1.0; 4]
    }
    fn limits(&self) -> Limits {
        Limits {
            z_min: -1.0,
            z_max: 1.0,
            restitution: 0.0,
            bounce_threshold: 0.0,
        }
    }
}

fn ramp(t_end: f64) -> PiecewiseLinear {
    PiecewiseLinear::new(vec![0.0, t_end], vec![0.0, t_end]).unwrap()
}

fn run(plant: &impl Plant, x0: State, t_end: f64, rtol: f64) -> Trajectory {
    let times: Vec<f64> = (0..=300).map(|k| t_end * k as f64 / 300.0).collect();
    let opts = Options {
        rtol,
        ..Options::default()
    };
    simulate(plant, &ramp(t_end), x0, Mode::Free, &times, &opts).unwrap()
}

/// Largest error of w against the exact total variation.
fn w_error(tr: &Trajectory) -> f64 {
    tr.t.iter()
        .zip(&tr.x)
        .map(|(&t, x)| (x[3] - Variation::w(t)).abs())
        .fold(0.0, f64::max)
}

#[test]
fn the_switch_is_located_and_the_solution_stays_accurate() {
    let tr = run(
        &Variation { locked: true },
        [0.0, 0.0, 1.0, 0.0],
        3.0,
        1e-10,
    );
    assert_eq!(tr.switches.len(), 1, "{:?}", tr.switches);
    let sw = tr.switches[0];
    assert_eq!(sw.index, 0);
    assert!((sw.t - 2f64.ln()).abs() < 1e-9, "switch at {}", sw.t);
    assert!(w_error(&tr) < 1e-8, "error {}", w_error(&tr));
    assert!(tr.events.is_empty());
}

#[test]
fn locking_is_more_accurate_per_step_than_the_live_sign() {
    let x0 = [0.0, 0.0, 1.0, 0.0];
    for rtol in [1e-5, 1e-7] {
        let locked = run(&Variation { locked: true }, x0, 3.0, rtol);
        let live = run(&Variation { locked: false }, x0, 3.0, rtol);
        let (el, ev) = (w_error(&locked), w_error(&live));
        assert!(live.switches.is_empty());
        assert!(el < 10.0 * rtol, "rtol {rtol}: locked error {el}");
        // Across the kink the live sign costs rejected steps, accuracy, or both.
        let (sl, sv) = (locked.stats, live.stats);
        assert!(
            sl.rejected < sv.rejected || el < ev,
            "{sl:?} {el} vs {sv:?} {ev}"
        );
        assert!(sl.evaluations <= sv.evaluations + 10, "{sl:?} vs {sv:?}");
    }
}

#[test]
fn a_switching_function_starting_at_zero_takes_the_branch_ahead() {
    // y(0) = u(0) = 0: s = 0 at the start, positive right after. Here
    // y = t − 1 + e^{−t}, ẏ = 1 − e^{−t} > 0, w = y.
    let tr = run(&Variation { locked: true }, [0.0; 4], 2.0, 1e-10);
    assert!(tr.switches.is_empty(), "{:?}", tr.switches);
    for (&t, x) in tr.t.iter().zip(&tr.x) {
        let y = t - 1.0 + (-t).exp();
        assert!(
            (x[2] - y).abs() < 1e-9 && (x[3] - y).abs() < 1e-9,
            "t {t}: {x:?}"
        );
    }
}

/// ẏ = −sign(y)·(1 + u): both branches drive y to 0, where it slides.
struct Sliding;

impl Plant for Sliding {
    fn dim(&self) -> usize {
        3
    }
    fn deriv(&self, t: f64, x: &State, u: f64, dx: &mut State) {
        self.deriv_branch(t, x, u, &[sign(x[2]), 0.0, 0.0, 0.0], dx);
    }
    fn switches(&self) -> usize {
        1
    }
    fn switching(&self, _t: f64, x: &State, _u: f64, s: &mut Branches) {
        s[0] = x[2];
    }
    fn deriv_branch(&self, _t: f64, _x: &State, u: f64, branch: &Branches, dx: &mut State) {
        *dx = [0.0, 0.0, -branch[0] * (1.0 + u), 0.0];
    }
    fn scale(&self) -> State {
        [1.0; 4]
    }
    fn limits(&self) -> Limits {
        Variation { locked: true }.limits()
    }
}

#[test]
fn chattering_falls_back_to_the_live_sign() {
    // The live sign makes the integrator crawl along y = 0 (as without
    // locking): keep the sliding phase short.
    let tr = run(&Sliding, [0.0, 0.0, 0.5, 0.0], 0.45, 1e-8);
    // y reaches 0 where 0.5 = t + t²/2 (u = t): t = √2 − 1.
    let t_hit = 2f64.sqrt() - 1.0;
    let first = tr.switches[0].t;
    assert!((first - t_hit).abs() < 1e-9, "first switch at {first}");
    // Every later switch comes at most one step after the previous: after
    // MAX_CHATTER of them the field uses the live sign, and none is located.
    assert_eq!(tr.switches.len(), 1 + MAX_CHATTER, "{:?}", tr.switches);
    for (&t, x) in tr.t.iter().zip(&tr.x) {
        let exact = if t < t_hit {
            0.5 - t - 0.5 * t * t
        } else {
            0.0
        };
        assert!((x[2] - exact).abs() < 1e-6, "t {t}: y {} vs {exact}", x[2]);
    }
}
