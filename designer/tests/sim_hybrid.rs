//! The hybrid automaton against analytic solutions: a bouncing ball, a
//! spring-mass between two stops, lift-off times and energy balances.

use designer::sim::{
    simulate, simulate_with, EventKind, Limit, Limits, Mode, Options, PiecewiseLinear, Plant,
    QuadState, Quadrature, SimError, State,
};

const G: f64 = 9.81;

/// Ball of unit mass: ż = v, v̇ = −g − c·v + u (u an upward force).
struct Ball {
    c: f64,
    lim: Limits,
}

impl Ball {
    fn new(z_min: f64, z_max: f64, gamma: f64, v_eps: f64) -> Self {
        Self {
            c: 0.0,
            lim: Limits {
                z_min,
                z_max,
                restitution: gamma,
                bounce_threshold: v_eps,
            },
        }
    }
}

impl Plant for Ball {
    fn dim(&self) -> usize {
        2
    }
    fn deriv(&self, _t: f64, x: &State, u: f64, dx: &mut State) {
        dx[0] = x[1];
        dx[1] = -G - self.c * x[1] + u;
    }
    fn scale(&self) -> State {
        [1.0, 1.0, 0.0, 0.0]
    }
    fn limits(&self) -> Limits {
        self.lim
    }
}

/// Spring towards `z_eq` (below the lower stop): v̇ = −ω²(z − z_eq).
struct Spring {
    omega: f64,
    z_eq: f64,
    lim: Limits,
}

impl Plant for Spring {
    fn dim(&self) -> usize {
        2
    }
    fn deriv(&self, _t: f64, x: &State, _u: f64, dx: &mut State) {
        dx[0] = x[1];
        dx[1] = -self.omega * self.omega * (x[0] - self.z_eq);
    }
    fn scale(&self) -> State {
        [1.0, 1.0, 0.0, 0.0]
    }
    fn limits(&self) -> Limits {
        self.lim
    }
}

fn grid(t0: f64, t1: f64, n: usize) -> Vec<f64> {
    (0..=n)
        .map(|k| t0 + (t1 - t0) * k as f64 / n as f64)
        .collect()
}

fn tight() -> Options {
    Options {
        rtol: 1e-12,
        ..Options::default()
    }
}

/// Impacts of a ball dropped from `z0` at rest onto `z_min = 0`:
/// (time, speed before, speed after); the last one sticks.
fn analytic_bounces(z0: f64, gamma: f64, v_eps: f64) -> Vec<(f64, f64, f64)> {
    let mut t = (2.0 * z0 / G).sqrt();
    let mut s = G * t;
    let mut out = Vec::new();
    loop {
        if s <= v_eps {
            out.push((t, s, 0.0));
            return out;
        }
        out.push((t, s, gamma * s));
        t += 2.0 * gamma * s / G;
        s *= gamma;
    }
}

#[test]
fn bouncing_ball_matches_analytic_sequence_and_sticks() {
    let ball = Ball::new(0.0, 1.0, 0.8, 0.05);
    let times = grid(0.0, 5.0, 500);
    let tr = simulate(
        &ball,
        &0.0,
        [0.8, 0.0, 0.0, 0.0],
        Mode::Free,
        &times,
        &Options::default(),
    )
    .unwrap();
    let expected = analytic_bounces(0.8, 0.8, 0.05);
    assert_eq!(tr.events.len(), expected.len(), "{:#?}", tr.events);
    assert_eq!(expected.len(), 21);
    for (ev, &(t, s, s_after)) in tr.events.iter().zip(&expected) {
        let EventKind::Impact {
            limit,
            v_before,
            v_after,
            zeno,
        } = ev.kind
        else {
            panic!("expected an impact, got {ev:?}");
        };
        assert_eq!(limit, Limit::Min);
        assert!(!zeno);
        assert!((ev.t - t).abs() < 1e-10, "impact at {} vs {t}", ev.t);
        assert!(
            (v_before + s).abs() < 1e-10,
            "v_before {v_before} vs {}",
            -s
        );
        assert!((v_after - s_after).abs() < 1e-10);
        let stuck = s_after == 0.0;
        assert_eq!(
            ev.mode_after,
            if stuck { Mode::StuckMin } else { Mode::Free }
        );
    }
    // Parabolic flights are integrated exactly: a few steps per flight.
    assert!(
        tr.stats.evaluations < 1500 && tr.stats.rejected < 10,
        "{:?}",
        tr.stats
    );
    // After the sticking impact the ball rests at z_min.
    let t_stick = expected.last().unwrap().0;
    for k in 0..tr.len() {
        if tr.t[k] > t_stick {
            assert_eq!(tr.mode[k], Mode::StuckMin);
            assert_eq!(tr.x[k][0], 0.0);
            assert_eq!(tr.x[k][1], 0.0);
        } else {
            assert!(tr.x[k][0] >= 0.0 && tr.x[k][0] <= 1.0);
        }
    }
    // Between impacts the trajectory is the analytic parabola.
    let (t1, s1, _) = expected[0];
    let (t2, _, _) = expected[1];
    for k in 0..tr.len() {
        let t = tr.t[k];
        let z = if t <= t1 {
            0.8 - 0.5 * G * t * t
        } else if t < t2 {
            let d = t - t1;
            0.8 * s1 * d - 0.5 * G * d * d
        } else {
            continue;
        };
        assert!(
            (tr.x[k][0] - z).abs() < 1e-10,
            "t {t}: z {} vs {z}",
            tr.x[k][0]
        );
    }
}

#[test]
fn zeno_bounce_sequence_sticks_at_the_accumulation_time() {
    // v_ε = 0: infinitely many bounces accumulating at t_∞.
    for (z_min, gamma) in [(0.0, 0.5), (0.3, 0.5), (0.3, 0.9), (-2.0, 0.8)] {
        let ball = Ball::new(z_min, z_min + 1.0, gamma, 0.0);
        let h0 = 0.5;
        let t1 = (2.0 * h0 / G).sqrt();
        let t_inf = t1 + 2.0 * gamma * G * t1 / G / (1.0 - gamma);
        let times = [0.0, t_inf + 1.0];
        let tr = simulate(
            &ball,
            &0.0,
            [z_min + h0, 0.0, 0.0, 0.0],
            Mode::Free,
            &times,
            &Options::default(),
        )
        .unwrap_or_else(|e| panic!("z_min {z_min}, γ {gamma}: {e}"));
        let last = tr.events.last().unwrap();
        let EventKind::Impact { v_after, zeno, .. } = last.kind else {
            panic!("{last:?}");
        };
        assert!(zeno && v_after == 0.0, "{last:?}");
        assert_eq!(last.mode_after, Mode::StuckMin);
        // With z_min ≠ 0 the bounces whose apex is below a few ulp of z_min
        // cannot be represented: the sequence is cut short by at most the
        // remaining flight time from that speed on.
        let ulp = z_min.abs() * f64::EPSILON;
        let v_res = (2.0 * G * 16.0 * (1.0 + 1.0 / (1.0 - gamma * gamma)) * ulp).sqrt();
        let tol = 1e-9 + 2.0 * v_res / (G * (1.0 - gamma));
        assert!(
            last.t - t_inf < 1e-9 && t_inf - last.t < tol,
            "z_min {z_min}, γ {gamma}: stuck at {} vs {t_inf}",
            last.t
        );
        assert!(tr.events.len() < 1000, "{} events", tr.events.len());
        assert_eq!(tr.x[1][0], z_min);
        assert_eq!(tr.mode[1], Mode::StuckMin);
    }
}

#[test]
fn step_force_lifts_off_exactly_at_the_step() {
    // Resting at z_min; an upward force 15 > g switches on at t = 2.
    let ball = Ball::new(0.0, 10.0, 0.5, 0.01);
    let u = PiecewiseLinear::steps(&[(0.0, 0.0), (2.0, 15.0)]).unwrap();
    let times = [0.0, 1.0, 2.0 - 1e-9, 2.0, 2.5, 3.0];
    let tr = simulate(&ball, &u, [0.0; 4], Mode::StuckMin, &times, &tight()).unwrap();
    assert_eq!(tr.events.len(), 1, "{:?}", tr.events);
    assert_eq!(tr.events[0].t, 2.0);
    assert_eq!(tr.events[0].kind, EventKind::LiftOff { limit: Limit::Min });
    // Output convention: at the event time the post-event values.
    assert_eq!(
        tr.mode,
        [
            Mode::StuckMin,
            Mode::StuckMin,
            Mode::StuckMin,
            Mode::Free,
            Mode::Free,
            Mode::Free
        ]
    );
    assert_eq!(tr.u, [0.0, 0.0, 0.0, 15.0, 15.0, 15.0]);
    for k in 3..6 {
        let d = tr.t[k] - 2.0;
        assert!((tr.x[k][0] - 0.5 * (15.0 - G) * d * d).abs() < 1e-12);
        assert!((tr.x[k][1] - (15.0 - G) * d).abs() < 1e-12);
    }
}

#[test]
fn ramp_force_lifts_off_at_the_analytic_time() {
    // u = 10·(t − 1) from t = 1 on: a = u − g crosses 0 at t = 1 + g/10, then
    // z = 10·(t − t_lo)³/6 until the upper stop at z_max = 1.
    let ball = Ball::new(0.0, 1.0, 0.5, 0.01);
    let u = PiecewiseLinear::new(vec![0.0, 1.0, 5.0], vec![0.0, 0.0, 40.0]).unwrap();
    let t_lo = 1.0 + G / 10.0;
    let t_hit = t_lo + 0.6f64.cbrt();
    let times = grid(0.0, 2.9, 290);
    let tr = simulate(&ball, &u, [0.0; 4], Mode::StuckMin, &times, &tight()).unwrap();
    let ev = &tr.events[0];
    assert_eq!(ev.kind, EventKind::LiftOff { limit: Limit::Min });
    assert!(
        (ev.t - t_lo).abs() < 1e-12,
        "lift-off at {} vs {t_lo}",
        ev.t
    );
    let hit = &tr.events[1];
    let EventKind::Impact {
        limit,
        v_before,
        v_after,
        ..
    } = hit.kind
    else {
        panic!("{hit:?}")
    };
    assert_eq!(limit, Limit::Max);
    assert!(
        (hit.t - t_hit).abs() < 1e-11,
        "impact at {} vs {t_hit}",
        hit.t
    );
    let v_hit = 5.0 * (t_hit - t_lo).powi(2);
    assert!((v_before - v_hit).abs() < 1e-10);
    assert!((v_after + 0.5 * v_hit).abs() < 1e-10);
    for k in 0..tr.len() {
        let t = tr.t[k];
        if t < t_lo {
            assert_eq!(tr.mode[k], Mode::StuckMin);
        } else if t < t_hit {
            let z = 10.0 * (t - t_lo).powi(3) / 6.0;
            assert!(
                (tr.x[k][0] - z).abs() < 1e-11,
                "t {t}: {} vs {z}",
                tr.x[k][0]
            );
        }
    }
}

#[test]
fn spring_mass_released_from_z_max_hits_z_min() {
    let omega = std::f64::consts::TAU;
    let z_eq = -0.5;
    let plant = Spring {
        omega,
        z_eq,
        lim: Limits {
            z_min: 0.0,
            z_max: 1.0,
            restitution: 0.5,
            bounce_threshold: 0.01,
        },
    };
    let amp = 1.0 - z_eq;
    let t_hit = (-z_eq / amp).acos() / omega;
    let times = grid(0.0, t_hit + 0.01, 200);
    let tr = simulate(&plant, &0.0, [0.0; 4], Mode::StuckMax, &times, &tight()).unwrap();
    // Initial consistency: the spring pulls away from z_max at t0 → Free.
    assert_eq!(tr.events[0].t, 0.0);
    assert_eq!(tr.events[0].kind, EventKind::LiftOff { limit: Limit::Max });
    assert_eq!(tr.mode[0], Mode::Free);
    assert_eq!(tr.x[0][0], 1.0);
    let hit = &tr.events[1];
    let EventKind::Impact {
        limit,
        v_before,
        v_after,
        ..
    } = hit.kind
    else {
        panic!("{hit:?}")
    };
    assert_eq!(limit, Limit::Min);
    let v_exact = -amp * omega * (omega * t_hit).sin();
    assert!((hit.t - t_hit).abs() < 1e-10, "{} vs {t_hit}", hit.t);
    assert!((v_before - v_exact).abs() < 1e-9 * v_exact.abs());
    assert_eq!(v_after, -0.5 * v_before);
    for k in 0..tr.len() {
        let t = tr.t[k];
        if t < t_hit {
            let z = z_eq + amp * (omega * t).cos();
            assert!(
                (tr.x[k][0] - z).abs() < 1e-10,
                "t {t}: {} vs {z}",
                tr.x[k][0]
            );
        } else {
            assert!(tr.x[k][1] > 0.0, "bounced upwards");
        }
    }
}

#[test]
fn pinned_at_z_max_falls_when_the_force_is_removed() {
    // Held at z_max by u = 20 > g until t = 1, then free fall to z_min = 0.
    let ball = Ball::new(0.0, 0.5, 0.0, 0.0);
    let u = PiecewiseLinear::steps(&[(0.0, 20.0), (1.0, 0.0)]).unwrap();
    let t_fall = 1.0 + (2.0 * 0.5 / G).sqrt();
    let tr = simulate(
        &ball,
        &u,
        [0.0; 4],
        Mode::StuckMax,
        &[0.0, 0.5, 1.0, 2.0],
        &tight(),
    )
    .unwrap();
    let kinds: Vec<_> = tr
        .events
        .iter()
        .map(|e| (e.t, e.kind, e.mode_after))
        .collect();
    assert_eq!(
        kinds[0],
        (1.0, EventKind::LiftOff { limit: Limit::Max }, Mode::Free)
    );
    assert!((kinds[1].0 - t_fall).abs() < 1e-12);
    // γ = 0: every impact sticks.
    assert!(matches!(
        kinds[1].1,
        EventKind::Impact {
            limit: Limit::Min,
            v_after: 0.0,
            zeno: false,
            ..
        }
    ));
    assert_eq!(kinds[1].2, Mode::StuckMin);
    assert_eq!(
        tr.mode,
        [Mode::StuckMax, Mode::StuckMax, Mode::Free, Mode::StuckMin]
    );
    assert_eq!(tr.x[0][0], 0.5);
}

#[test]
fn never_steps_across_input_kinks_or_jumps() {
    // v̇ = u − g with a triangle pulse and a jump: the exact z is a piecewise
    // cubic, which DOPRI5 reproduces to rounding error on every segment — but
    // only if no step spans a kink. A loose tolerance makes crossing visible.
    let ball = Ball::new(-1e3, 1e3, 0.0, 0.0);
    let u = PiecewiseLinear::new(
        vec![0.0, 0.3, 0.7, 1.1, 1.1, 2.0],
        vec![0.0, 0.0, 40.0, 0.0, 25.0, 25.0],
    )
    .unwrap();
    let opts = Options {
        rtol: 1e-3,
        ..Options::default()
    };
    let times = grid(0.0, 2.0, 40);
    let tr = simulate(&ball, &u, [0.0; 4], Mode::Free, &times, &opts).unwrap();
    // Exact: integrate u − g twice, piecewise.
    let exact = |t: f64| -> (f64, f64) {
        let ramp = |t: f64, t0: f64, s: f64| -> (f64, f64) {
            let d = (t - t0).max(0.0);
            (s * d * d * d / 6.0, s * d * d / 2.0)
        };
        // u = 100(t−0.3)⁺ − 200(t−0.7)⁺ + 100(t−1.1)⁺ + 25·H(t−1.1)
        let mut z = -0.5 * G * t * t;
        let mut v = -G * t;
        for (t0, s) in [(0.3, 100.0), (0.7, -200.0), (1.1, 100.0)] {
            let (a, b) = ramp(t, t0, s);
            z += a;
            v += b;
        }
        let d = (t - 1.1).max(0.0);
        (z + 12.5 * d * d, v + 25.0 * d)
    };
    for k in 0..tr.len() {
        let (z, v) = exact(tr.t[k]);
        assert!(
            (tr.x[k][0] - z).abs() < 1e-12,
            "t {}: z {} vs {z}",
            tr.t[k],
            tr.x[k][0]
        );
        assert!(
            (tr.x[k][1] - v).abs() < 1e-12,
            "t {}: v {} vs {v}",
            tr.t[k],
            tr.x[k][1]
        );
    }
    assert!(tr.events.is_empty());
}

/// ∫u·v dt (work of the force) and ∫c·v² dt (viscous loss) for the ball.
struct Work {
    c: f64,
}

impl Quadrature for Work {
    fn len(&self) -> usize {
        2
    }
    fn integrand(&self, _t: f64, x: &State, _dx: &State, u: f64, _mode: Mode, out: &mut QuadState) {
        out[0] = u * x[1];
        out[1] = self.c * x[1] * x[1];
    }
}

#[test]
fn energy_balance_with_quadratures_and_impact_losses() {
    // E = ½v² + g·z; dE/dt = u·v − c·v²; impacts remove ½(v_b² − v_a²).
    let mut ball = Ball::new(0.0, 1.0, 0.7, 0.05);
    ball.c = 0.3;
    let u = PiecewiseLinear::pulses(0.0, &[(0.5, 0.4, 30.0), (2.0, 0.3, 25.0), (3.0, 1.0, -5.0)])
        .unwrap();
    let times = grid(0.0, 5.0, 1000);
    let work = Work { c: 0.3 };
    let tr = simulate_with(
        &ball,
        &u,
        [0.5, 0.0, 0.0, 0.0],
        Mode::Free,
        &times,
        &work,
        &tight(),
    )
    .unwrap();
    assert_eq!(tr.q.len(), tr.len());
    let impacts = tr
        .events
        .iter()
        .filter(|e| matches!(e.kind, EventKind::Impact { .. }))
        .count();
    assert!(impacts >= 4, "{:?}", tr.events);
    let energy = |x: &State| 0.5 * x[1] * x[1] + G * x[0];
    let mut lost = 0.0;
    let mut next_event = 0;
    for k in 0..tr.len() {
        while next_event < tr.events.len() && tr.events[next_event].t <= tr.t[k] {
            if let EventKind::Impact {
                v_before, v_after, ..
            } = tr.events[next_event].kind
            {
                lost += 0.5 * (v_before * v_before - v_after * v_after);
            }
            next_event += 1;
        }
        let balance = energy(&tr.x[k]) - energy(&tr.x[0]) - tr.q[k][0] + tr.q[k][1] + lost;
        assert!(
            balance.abs() < 1e-9,
            "t {}: energy balance off by {balance}",
            tr.t[k]
        );
    }
    // The quadratures start at 0 and the loss integral never decreases.
    assert_eq!(tr.q[0][..2], [0.0, 0.0]);
    assert!(tr.q.windows(2).all(|w| w[1][1] >= w[0][1]));
}

#[test]
fn outputs_between_events_and_repeated_times() {
    let ball = Ball::new(0.0, 1.0, 0.8, 0.05);
    let times = [0.0, 0.1, 0.1, 0.2, 3.0, 3.0];
    let tr = simulate(
        &ball,
        &0.0,
        [0.8, 0.0, 0.0, 0.0],
        Mode::Free,
        &times,
        &Options::default(),
    )
    .unwrap();
    assert_eq!(tr.t, times);
    assert_eq!(tr.x[1], tr.x[2]);
    assert!((tr.x[1][0] - (0.8 - 0.5 * G * 0.01)).abs() < 1e-12);
    assert_eq!(tr.x[4], tr.x[5]);
    // Single output time: just the initial state.
    let tr = simulate(
        &ball,
        &0.0,
        [0.3, 0.1, 0.0, 0.0],
        Mode::Free,
        &[1.0],
        &Options::default(),
    )
    .unwrap();
    assert_eq!(tr.len(), 1);
    assert_eq!(tr.x[0][..2], [0.3, 0.1]);
}

#[test]
fn resting_on_a_limit_in_free_mode_sticks() {
    let ball = Ball::new(0.0, 1.0, 0.8, 0.05);
    let tr = simulate(
        &ball,
        &0.0,
        [0.0; 4],
        Mode::Free,
        &[0.0, 1.0],
        &Options::default(),
    )
    .unwrap();
    assert_eq!(tr.events.len(), 1);
    assert_eq!(tr.events[0].kind, EventKind::Stick { limit: Limit::Min });
    assert_eq!(tr.mode, [Mode::StuckMin, Mode::StuckMin]);
    // Moving into the limit at t0 is an impact at t0.
    let tr = simulate(
        &ball,
        &0.0,
        [0.0, -1.0, 0.0, 0.0],
        Mode::Free,
        &[0.0, 0.1],
        &Options::default(),
    )
    .unwrap();
    assert_eq!(tr.events[0].t, 0.0);
    assert!(matches!(
        tr.events[0].kind,
        EventKind::Impact { v_before: -1.0, .. }
    ));
    assert_eq!(tr.x[0][1], 0.8);
}

#[test]
fn bad_arguments_are_rejected() {
    let ball = Ball::new(0.0, 1.0, 0.8, 0.05);
    let opts = Options::default();
    let run = |x0: State, times: &[f64], opts: &Options| {
        simulate(&ball, &0.0, x0, Mode::Free, times, opts)
    };
    assert!(matches!(
        run([0.5; 4], &[], &opts),
        Err(SimError::OutputTimes(_))
    ));
    assert!(matches!(
        run([0.5; 4], &[1.0, 0.5], &opts),
        Err(SimError::OutputTimes(_))
    ));
    assert!(matches!(
        run([1.5, 0.0, 0.0, 0.0], &[0.0, 1.0], &opts),
        Err(SimError::InitialState(_))
    ));
    assert!(matches!(
        run([f64::NAN; 4], &[0.0, 1.0], &opts),
        Err(SimError::InitialState(_))
    ));
    let bad = Options { rtol: -1.0, ..opts };
    assert!(matches!(
        run([0.5; 4], &[0.0, 1.0], &bad),
        Err(SimError::Options(_))
    ));
    let bad = Options {
        max_steps: 10,
        ..opts
    };
    assert!(matches!(
        run([0.5; 4], &[0.0, 5.0], &bad),
        Err(SimError::TooManySteps { .. })
    ));
}

/// A plant whose domain ends at z = 0.5 (like |φ| < φ_sat).
struct Bounded;

impl Plant for Bounded {
    fn dim(&self) -> usize {
        2
    }
    fn deriv(&self, _t: f64, x: &State, _u: f64, dx: &mut State) {
        dx[0] = x[1];
        dx[1] = 1.0;
    }
    fn in_domain(&self, x: &State) -> bool {
        x[0] < 0.5
    }
    fn scale(&self) -> State {
        [1.0; 4]
    }
    fn limits(&self) -> Limits {
        Limits {
            z_min: 0.0,
            z_max: 1.0,
            restitution: 0.5,
            bounce_threshold: 0.0,
        }
    }
}

#[test]
fn leaving_the_domain_is_reported_with_its_time() {
    let err = simulate(
        &Bounded,
        &0.0,
        [0.0; 4],
        Mode::Free,
        &[0.0, 2.0],
        &Options::default(),
    )
    .unwrap_err();
    let SimError::Integrator(designer::sim::RkError::LeftDomain { t, .. }) = err else {
        panic!("{err:?}")
    };
    assert!((t - 1.0).abs() < 1e-6, "t = {t}");
}
