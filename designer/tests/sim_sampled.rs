//! Sampled-data loop against the exact discrete-time solution.

use designer::sim::{
    simulate_sampled, simulate_sampled_with, EventKind, Limit, Limits, Measurement, Mode,
    NoQuadrature, Options, Plant, SimError, State,
};

/// Unit mass with viscous friction: ż = v, v̇ = −c·v + u.
struct Damped {
    c: f64,
    lim: Limits,
}

impl Damped {
    fn new(c: f64, z_min: f64, z_max: f64) -> Self {
        Self {
            c,
            lim: Limits {
                z_min,
                z_max,
                restitution: 0.5,
                bounce_threshold: 0.05,
            },
        }
    }
}

impl Plant for Damped {
    fn dim(&self) -> usize {
        2
    }
    fn deriv(&self, _t: f64, x: &State, u: f64, dx: &mut State) {
        dx[0] = x[1];
        dx[1] = -self.c * x[1] + u;
    }
    fn scale(&self) -> State {
        [1.0, 1.0, 0.0, 0.0]
    }
    fn limits(&self) -> Limits {
        self.lim
    }
}

fn tight() -> Options {
    Options {
        rtol: 1e-13,
        atol: Some([1e-14; 4]),
        ..Options::default()
    }
}

#[test]
fn p_controller_matches_the_discrete_time_solution() {
    // Velocity loop u_k = Kp·(v_ref − v_k) on the first-order plant v̇ = −c·v + u:
    // v_{k+1} = a·v_k + b·u_k with a = e^{−c·Ts}, b = (1 − a)/c; the position
    // z_{k+1} = z_k + b·v_k + (Ts − b)/c·u_k follows exactly too.
    let (c, ts, kp, v_ref) = (2.0, 0.01, 50.0, 1.0);
    let plant = Damped::new(c, -1e3, 1e3);
    let mut calls = Vec::new();
    let mut ctl = |t: f64, m: &Measurement| {
        calls.push(t);
        kp * (v_ref - m.x[1])
    };
    let n = 300;
    let t_end = n as f64 * ts;
    let tr = simulate_sampled(&plant, &mut ctl, ts, t_end, [0.0; 4], Mode::Free, &tight()).unwrap();
    assert_eq!(tr.len(), n + 1);
    assert_eq!(calls.len(), n + 1);
    let one_minus_a = -(-c * ts).exp_m1();
    let a = 1.0 - one_minus_a;
    let b = one_minus_a / c;
    let (mut z, mut v) = (0.0, 0.0);
    for (k, &call) in calls.iter().enumerate() {
        assert_eq!(tr.t[k], k as f64 * ts);
        assert_eq!(call, tr.t[k]);
        assert!(
            (tr.x[k][1] - v).abs() < 1e-10,
            "k {k}: v {} vs {v}",
            tr.x[k][1]
        );
        assert!(
            (tr.x[k][0] - z).abs() < 1e-10,
            "k {k}: z {} vs {z}",
            tr.x[k][0]
        );
        let u = kp * (v_ref - v);
        assert!(
            (tr.u[k] - u).abs() < 1e-8,
            "recorded input is the value computed at the sample"
        );
        (z, v) = (z + b * v + (ts - b) / c * u, a * v + b * u);
    }
    // Restarts at the samples keep the step size: about one step per sample
    // (1 restart evaluation + 6 stages) once the step size has settled.
    assert!(tr.stats.evaluations < 8 * n + 100, "{:?}", tr.stats);
    // The loop converges to v = Kp·v_ref/(c + Kp).
    assert!((tr.x[n][1] - kp * v_ref / (c + kp)).abs() < 1e-6);
}

#[test]
fn extra_output_grid_and_zero_order_hold() {
    let plant = Damped::new(1.0, -1e3, 1e3);
    let ts = 0.1;
    let mut k = 0;
    let mut ctl = |_t: f64, _m: &Measurement| {
        k += 1;
        k as f64
    };
    let extra = [0.05, 0.1, 0.15, 0.33];
    let tr = simulate_sampled_with(
        &plant,
        &mut ctl,
        ts,
        0.35,
        [0.0; 4],
        Mode::Free,
        &extra,
        &NoQuadrature,
        &tight(),
    )
    .unwrap();
    // Sample times 0, 0.1, 0.2, 0.3 merged with the extra times (0.1 once).
    let expect_t = [0.0, 0.05, 0.1, 0.15, 0.2, 0.1 * 3.0, 0.33];
    assert_eq!(tr.t, expect_t);
    // Held input, right-continuous at the samples.
    assert_eq!(tr.u, [1.0, 1.0, 2.0, 2.0, 3.0, 4.0, 4.0]);
    // Exact solution with u = 1 on [0, 0.1): v = 1 − e^{−t}.
    assert!((tr.x[1][1] + (-0.05f64).exp_m1()).abs() < 1e-12);
}

#[test]
fn t_end_between_samples_and_bad_period() {
    let plant = Damped::new(1.0, -1e3, 1e3);
    let mut ctl = |_t: f64, _m: &Measurement| 1.0;
    let tr = simulate_sampled(&plant, &mut ctl, 0.3, 1.0, [0.0; 4], Mode::Free, &tight()).unwrap();
    assert_eq!(tr.t, [0.0, 0.3, 0.6, 0.3 * 3.0]);
    assert!(matches!(
        simulate_sampled(&plant, &mut ctl, 0.0, 1.0, [0.0; 4], Mode::Free, &tight()),
        Err(SimError::Options(_))
    ));
    let mut nan = |_t: f64, _m: &Measurement| f64::NAN;
    assert!(matches!(
        simulate_sampled(&plant, &mut nan, 0.1, 1.0, [0.0; 4], Mode::Free, &tight()),
        Err(SimError::NonFiniteInput { .. })
    ));
}

#[test]
fn controller_sees_modes_and_limits() {
    // Push into z_max = 0.2 (bounces, then sticks), pull back from t = 1.5 on.
    let plant = Damped::new(0.5, 0.0, 0.2);
    let mut seen = Vec::new();
    let mut ctl = |t: f64, m: &Measurement| {
        seen.push(m.mode);
        assert!(m.x[0] >= 0.0 && m.x[0] <= 0.2);
        if t < 1.5 {
            3.0
        } else {
            -3.0
        }
    };
    let tr = simulate_sampled(
        &plant,
        &mut ctl,
        0.01,
        4.0,
        [0.0; 4],
        Mode::StuckMin,
        &Options::default(),
    )
    .unwrap();
    assert!(seen.contains(&Mode::StuckMax), "{seen:?}");
    assert_eq!(seen[0], Mode::StuckMin);
    assert_eq!(*seen.last().unwrap(), Mode::StuckMin);
    let first = tr.events[0];
    assert_eq!(first.t, 0.0);
    assert_eq!(first.kind, EventKind::LiftOff { limit: Limit::Min });
    // The pull-back at t = 1.5 lifts off from z_max exactly at that sample.
    assert!(tr
        .events
        .iter()
        .any(|e| e.t == 1.5 && e.kind == EventKind::LiftOff { limit: Limit::Max }));
    let k = tr.t.iter().position(|&t| t == 1.5).unwrap();
    assert_eq!(
        tr.mode[k],
        Mode::Free,
        "post-event convention at the sample"
    );
    assert_eq!(tr.u[k], -3.0);
}
