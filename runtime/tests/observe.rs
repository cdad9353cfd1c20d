//! `reldesign_runtime::observe` on a linear toy model, where the extended
//! and the unscented filter are both the Kalman filter: against a textbook
//! Kalman filter written here with index loops over `Vec`s (the oracle), and
//! the rules around the algebra — non-finite data skipped and the input
//! held, a non-finite prediction restarting from (x₀, P₀), the stop rule,
//! the UKF's repair of a covariance that does not factor, the mode (86) and
//! the estimate (85)–(87).

// the oracle is plain index loops on purpose
#![allow(clippy::needless_range_loop)]

use reldesign_runtime::observe::{
    DiscreteModel, Ekf, Estimate, Linearisation, Linearised, Prediction, Reading, Sampled,
    Settings, Stateless, Ukf, Weights,
};

/// T_s [s].
const TS: f64 = 1e-3;
/// a = −K·z − C·v + B·φ, v = (z − z_prev)/T_s.
const K: f64 = 400.0;
const C: f64 = 8.0;
const B: f64 = 2e3;
/// φ̇ = u − RHO·φ.
const RHO: f64 = 50.0;
/// y = H_PHI·φ + H_Z·z + E·u.
const H_PHI: f64 = 40.0;
const H_Z: f64 = 3.0;
const E: f64 = 0.02;

const P0: [[f64; 3]; 3] = [
    [1e-4 + 1e-8, 1e-4, 0.0],
    [1e-4, 1e-4 + 1e-8, 0.0],
    [0.0, 0.0, 1e-6],
];

/// chol P0, by hand: l00 = √(1e-4 + 1e-8), l10 = 1e-4/l00, l11 = √(p11 − l10²).
fn chol_p0() -> [[f64; 3]; 3] {
    let l00 = (1e-4f64 + 1e-8).sqrt();
    let l10 = 1e-4 / l00;
    let l11 = (1e-4 + 1e-8 - l10 * l10).sqrt();
    [[l00, 0.0, 0.0], [l10, l11, 0.0], [0.0, 0.0, 1e-3]]
}

const SETTINGS: Settings<f64, 3> = Settings {
    sample_period: TS,
    z_min: -1.0,
    z_max: 1.0,
    mode_band: 1e-6,
    input_variance: 1e-2,
    measurement_variance: 1e-4,
    process_variance: [1e-8, 0.0, 1e-6],
    initial_state: [0.1, 0.1, 0.0],
    initial_covariance: P0,
    field: None,
    resistance: None,
    // α = 1, β = 2, κ = 0: λ = 0, γ = √3, W₀ᵐ = 0, W₀ᶜ = 2, Wᵢ = 1/6
    unscented: Weights {
        gamma: 1.7320508075688772,
        mean0: 0.0,
        cov0: 2.0,
        other: 1.0 / 6.0,
    },
    // replaced in `Toy` (a const cannot take square roots)
    initial_factor: [[0.0; 3]; 3],
};

/// The linear toy; `blow_up`: F is NaN for u above it.
#[derive(Clone, Debug, PartialEq)]
struct Toy {
    settings: Settings<f64, 3>,
    blow_up: f64,
}

impl Toy {
    fn new() -> Toy {
        let mut settings = SETTINGS;
        settings.initial_factor = chol_p0();
        Toy {
            settings,
            blow_up: f64::INFINITY,
        }
    }

    fn accel(x: &[f64; 3]) -> f64 {
        let [z, zp, phi] = *x;
        -K * z - C * (z - zp) / TS + B * phi
    }

    fn next(&self, x: &[f64; 3], u: f64) -> [f64; 3] {
        let [z, zp, phi] = *x;
        let nan = if u > self.blow_up { f64::NAN } else { 0.0 };
        [
            2.0 * z - zp + TS * TS * Toy::accel(x) + nan,
            z,
            phi + TS * (u - RHO * phi),
        ]
    }

    fn jacobian() -> [[f64; 3]; 3] {
        [
            [2.0 - TS * TS * K - TS * C, -1.0 + TS * C, TS * TS * B],
            [1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0 - TS * RHO],
        ]
    }

    const G: [f64; 3] = [0.0, 0.0, TS];
    const H: [f64; 3] = [H_Z, 0.0, H_PHI];

    fn y(x: &[f64; 3], u: f64) -> f64 {
        H_PHI * x[2] + H_Z * x[0] + E * u
    }
}

impl reldesign_runtime::observe::Configured<f64, 3> for Toy {
    fn settings(&self) -> Settings<f64, 3> {
        self.settings
    }
}

impl DiscreteModel<f64, 3> for Toy {
    fn acceleration(&mut self, x: &[f64; 3], _: f64, _: f64) -> f64 {
        Toy::accel(x)
    }
}

impl Linearised<f64, 3> for Toy {
    fn transition(&mut self, x: &[f64; 3], u: f64, _: f64) -> Linearisation<f64, 3> {
        Linearisation {
            prediction: Sampled::transition(self, x, u, 0.0),
            f_x: Toy::jacobian(),
            g: Toy::G,
        }
    }

    fn measurement(&mut self, x: &[f64; 3], u: f64, _: f64) -> (Reading<f64>, [f64; 3]) {
        (Sampled::measurement(self, x, u, 0.0), Toy::H)
    }
}

impl Sampled<f64, 3> for Toy {
    fn transition(&mut self, x: &[f64; 3], u: f64, _: f64) -> Prediction<f64, 3> {
        Prediction {
            next: self.next(x, u),
            accel: Toy::accel(x),
        }
    }

    fn measurement(&mut self, x: &[f64; 3], u: f64, _: f64) -> Reading<f64> {
        Reading {
            y: Toy::y(x, u),
            dy_du: E,
        }
    }

    fn input_gain(&mut self, _: &[f64; 3], _: f64, _: f64) -> [f64; 3] {
        Toy::G
    }
}

/// The textbook Kalman filter (the oracle): prediction x = F(x, u),
/// P = F·P·Fᵀ + Q + σ_u²·g·gᵀ; update K = P·Hᵀ/S, Joseph form.
struct Kalman {
    x: Vec<f64>,
    p: Vec<Vec<f64>>,
}

impl Kalman {
    fn new() -> Kalman {
        Kalman {
            x: SETTINGS.initial_state.to_vec(),
            p: P0.iter().map(|r| r.to_vec()).collect(),
        }
    }

    fn predict(&mut self, u: f64) {
        let f = Toy::jacobian();
        let x: [f64; 3] = self.x.clone().try_into().unwrap();
        self.x = Toy::new().next(&x, u).to_vec();
        let mut fp = vec![vec![0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                for k in 0..3 {
                    fp[i][j] += f[i][k] * self.p[k][j];
                }
            }
        }
        for i in 0..3 {
            for j in 0..3 {
                let mut s = 0.0;
                for k in 0..3 {
                    s += fp[i][k] * f[j][k];
                }
                self.p[i][j] = s + SETTINGS.input_variance * Toy::G[i] * Toy::G[j];
            }
            self.p[i][i] += SETTINGS.process_variance[i];
        }
    }

    fn update(&mut self, u: f64, y: f64) {
        let h = Toy::H;
        let r = SETTINGS.measurement_variance + SETTINGS.input_variance * E * E;
        let ph: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| self.p[i][j] * h[j]).sum())
            .collect();
        let s: f64 = (0..3).map(|i| h[i] * ph[i]).sum::<f64>() + r;
        let k: Vec<f64> = ph.iter().map(|v| v / s).collect();
        let x: [f64; 3] = self.x.clone().try_into().unwrap();
        let innovation = y - Toy::y(&x, u);
        for i in 0..3 {
            self.x[i] += k[i] * innovation;
        }
        let a: Vec<Vec<f64>> = (0..3)
            .map(|i| {
                (0..3)
                    .map(|j| f64::from(u8::from(i == j)) - k[i] * h[j])
                    .collect()
            })
            .collect();
        let mut ap = vec![vec![0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                for l in 0..3 {
                    ap[i][j] += a[i][l] * self.p[l][j];
                }
            }
        }
        for i in 0..3 {
            for j in 0..3 {
                let mut v = r * k[i] * k[j];
                for l in 0..3 {
                    v += ap[i][l] * a[j][l];
                }
                self.p[i][j] = v;
            }
        }
    }
}

/// SplitMix64 with Box–Muller normals.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        ((z >> 11) + 1) as f64 / (1u64 << 53) as f64
    }

    fn normal(&mut self) -> f64 {
        let (a, b) = (self.uniform(), self.uniform());
        (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
    }
}

/// (u, y) of the toy driven by a square wave, with noise.
fn record(n: usize) -> Vec<(f64, f64)> {
    let (mut rng, toy) = (Rng(7), Toy::new());
    let mut x = SETTINGS.initial_state;
    (0..n)
        .map(|k| {
            let u = if (k / 50) % 2 == 0 { 1.0 } else { -0.5 };
            x = toy.next(&x, u);
            (u + 0.1 * rng.normal(), Toy::y(&x, u) + 0.01 * rng.normal())
        })
        .collect()
}

fn relative(a: f64, b: f64, scale: f64) -> f64 {
    (a - b).abs() / scale
}

fn ekf() -> Ekf<Toy, f64, 3> {
    let toy = Toy::new();
    let s = toy.settings;
    Ekf::with_model(toy, &s)
}

fn ukf() -> Ukf<Toy, f64, 3, 7> {
    let toy = Toy::new();
    let s = toy.settings;
    Ukf::with_model(toy, &s)
}

#[test]
fn ekf_and_ukf_are_the_kalman_filter_on_a_linear_model() {
    let rec = record(300);
    let (mut e, mut u, mut kf) = (ekf(), ukf(), Kalman::new());
    let (mut worst_ekf, mut worst_ukf) = (0.0f64, 0.0f64);
    for (k, &(uk, yk)) in rec.iter().enumerate() {
        kf.predict(uk);
        kf.update(uk, yk);
        let (ee, eu) = (e.step(uk, yk), u.step(uk, yk));
        let scale = [0.1, 0.1, 1e-3];
        for (f, est, worst) in [
            (e.state(), ee, &mut worst_ekf),
            (u.state(), eu, &mut worst_ukf),
        ] {
            for i in 0..3 {
                *worst = worst.max(relative(f[i], kf.x[i], scale[i]));
            }
            // the estimate (85)–(87) of the posterior
            assert_eq!((est.z, est.phi, est.mode), (f[0], f[2], 2), "sample {k}");
            assert_eq!(est.v, (f[0] - f[1]) / TS);
            assert_eq!(est.a, Toy::accel(&f));
            assert_eq!((est.hc, est.r), (None, None));
        }
        for (p, which) in [(e.covariance(), "EKF"), (u.covariance(), "UKF")] {
            for i in 0..3 {
                for j in 0..3 {
                    let s = (kf.p[i][i] * kf.p[j][j]).sqrt();
                    let d = relative(p[i][j], kf.p[i][j], s);
                    assert!(d < 1e-8, "{which} P[{i}][{j}] at {k}: {d:e}");
                }
            }
        }
    }
    // the EKF is the same algebra in the same order, the UKF reaches the
    // same numbers through sigma points
    assert!(worst_ekf < 1e-12, "EKF: {worst_ekf:e}");
    assert!(worst_ukf < 1e-8, "UKF: {worst_ukf:e}");
    assert_eq!(
        (e.skipped(), e.repairs(), u.skipped(), u.repairs()),
        (0, 0, 0, 0)
    );
}

/// A NaN or ∞ measurement skips the update (counted) and leaves the
/// prediction; a non-finite input skips it too and the last finite input
/// drives the prediction.
#[test]
fn non_finite_data_are_skipped_and_the_input_held() {
    let rec = record(100);
    for ukf_filter in [false, true] {
        let (mut e, mut u) = (ekf(), ukf());
        let mut step = |uk: f64, yk: f64| -> Estimate<f64> {
            if ukf_filter {
                u.step(uk, yk)
            } else {
                e.step(uk, yk)
            }
        };
        let mut kf = Kalman::new();
        let mut last_u = 0.0;
        for (k, &(uk, yk)) in rec.iter().enumerate() {
            let (uk, yk) = match k {
                10 => (uk, f64::NAN),
                11 => (f64::NAN, yk),
                12 => (f64::INFINITY, f64::NEG_INFINITY),
                _ => (uk, yk),
            };
            let held = if uk.is_finite() { uk } else { last_u };
            last_u = held;
            kf.predict(held);
            if uk.is_finite() && yk.is_finite() {
                kf.update(held, yk);
            }
            let est = step(uk, yk);
            let tol = if ukf_filter { 1e-8 } else { 1e-12 };
            assert!(
                relative(est.z, kf.x[0], 0.1) < tol,
                "UKF {ukf_filter} at {k}"
            );
            assert!(
                relative(est.phi, kf.x[2], 1e-3) < tol,
                "UKF {ukf_filter} at {k}"
            );
        }
        let skipped = if ukf_filter { u.skipped() } else { e.skipped() };
        assert_eq!(skipped, 3, "UKF {ukf_filter}");
    }
}

/// A prediction that is not finite restarts the filter from x₀, P₀
/// (counted); the next samples proceed from there.
#[test]
fn a_non_finite_prediction_restarts_from_the_initial_state() {
    for ukf_filter in [false, true] {
        let mut toy = Toy::new();
        toy.blow_up = 5.0;
        let s = toy.settings;
        let (mut e, mut u) = (
            Ekf::with_model(toy.clone(), &s),
            Ukf::<_, _, 3, 7>::with_model(toy, &s),
        );
        let mut step = |uk: f64, yk: f64| {
            if ukf_filter {
                (u.step(uk, yk), u.state(), u.covariance(), u.repairs())
            } else {
                (e.step(uk, yk), e.state(), e.covariance(), e.repairs())
            }
        };
        step(1.0, 0.5);
        // u = 6 > 5: F is NaN; the measurement then updates x₀, P₀, which a
        // NaN y leaves as they are
        let (est, x, p, repairs) = step(6.0, f64::NAN);
        assert_eq!(repairs, 1, "UKF {ukf_filter}");
        assert_eq!(x, SETTINGS.initial_state, "UKF {ukf_filter}");
        assert_eq!(p, P0, "UKF {ukf_filter}");
        assert!(est.z.is_finite() && est.v == 0.0);
        let (est, _, _, repairs) = step(1.0, 0.5);
        assert!(est.z.is_finite() && est.phi.is_finite());
        assert_eq!(repairs, 1);
    }
}

/// At z_max with the free acceleration into the stop, the prediction keeps
/// z = z_max (mode 3, a = 0, the EKF's z row of F zeroed); pulled away
/// (f_v < 0), the armature leaves it.
#[test]
fn on_a_stop_the_prediction_keeps_z() {
    let mut toy = Toy::new();
    toy.settings.initial_state = [1.0, 1.0, 0.0];
    // φ pulls towards z_max: a = −K + B·φ > 0 for φ > K/B = 0.2
    toy.settings.initial_state[2] = 0.5;
    let s = toy.settings;
    let mut e = Ekf::with_model(toy.clone(), &s);
    let mut u = Ukf::<_, _, 3, 7>::with_model(toy, &s);
    // u = RHO·φ holds φ; no measurement
    let est = e.step(25.0, f64::NAN);
    assert_eq!((est.z, est.v, est.a, est.mode), (1.0, 0.0, 0.0, 3));
    // the UKF's mean of points all at z_max: z_max up to the weights' rounding
    let est = u.step(25.0, f64::NAN);
    assert!(
        (est.z - 1.0).abs() <= 1e-15 && est.v.abs() <= 1e-12,
        "{est:?}"
    );
    assert_eq!((est.a, est.mode), (0.0, 3));
    // the z row of F is zero: P_zz is P₀'s z row through nothing but q_z²
    assert_eq!(e.covariance()[0][0], SETTINGS.process_variance[0]);
    assert_eq!(e.covariance()[0][2], 0.0);
    // φ released: a < 0, the prediction leaves the stop
    for est in [e.step(-1e3, f64::NAN), u.step(-1e3, f64::NAN)] {
        assert!(est.z <= 1.0 && est.mode == 3, "{est:?}");
    }
    let mut left = false;
    for _ in 0..20 {
        let est = e.step(-1e3, f64::NAN);
        left |= est.mode == 2 && est.z < 1.0 && est.v < 0.0 && est.a != 0.0;
    }
    assert!(left, "the EKF never left the stop");
}

/// A covariance that does not factor is repaired (counted): here P₀ is
/// indefinite, jitter does not help, and the reset factor is used.
#[test]
fn the_ukf_repairs_a_covariance_that_does_not_factor() {
    let mut toy = Toy::new();
    toy.settings.initial_covariance[2][2] = -1e-6;
    let s = toy.settings;
    let mut u = Ukf::<_, _, 3, 7>::with_model(toy, &s);
    let est = u.step(1.0, 0.5);
    assert!(est.z.is_finite() && est.phi.is_finite(), "{est:?}");
    // both factorisations (prediction, update) fail on P₀ and use chol P₀
    assert!(u.repairs() >= 1, "{}", u.repairs());
    assert_eq!(u.skipped(), 0);
}

/// A stateless model builds its filter in a `const`, in f32 as in f64.
#[test]
fn stateless_models_build_filters_in_const_context() {
    #[derive(Clone, Copy, Debug, PartialEq)]
    struct Still;
    impl Stateless<f32, 3> for Still {
        const MODEL: Self = Still;
        const SETTINGS: Settings<f32, 3> = Settings {
            sample_period: 1e-3,
            z_min: 0.0,
            z_max: 1e-3,
            mode_band: 1e-6,
            input_variance: 1e-4,
            measurement_variance: 1e-6,
            process_variance: [1e-12, 0.0, 1e-12],
            initial_state: [1e-3, 1e-3, 0.0],
            initial_covariance: [[2e-10, 1e-10, 0.0], [1e-10, 2e-10, 0.0], [0.0, 0.0, 1e-12]],
            field: Some(2),
            resistance: None,
            unscented: Weights {
                gamma: 1.7320508,
                mean0: 0.0,
                cov0: 2.0,
                other: 0.16666667,
            },
            initial_factor: [
                [1.4142135e-5, 0.0, 0.0],
                [7.071068e-6, 1.2247449e-5, 0.0],
                [0.0, 0.0, 1e-6],
            ],
        };
    }
    impl DiscreteModel<f32, 3> for Still {
        fn acceleration(&mut self, _: &[f32; 3], _: f32, _: f32) -> f32 {
            0.0
        }
    }
    impl Sampled<f32, 3> for Still {
        fn transition(&mut self, x: &[f32; 3], _: f32, _: f32) -> Prediction<f32, 3> {
            Prediction {
                next: *x,
                accel: 0.0,
            }
        }
        fn measurement(&mut self, x: &[f32; 3], _: f32, _: f32) -> Reading<f32> {
            Reading {
                y: x[2],
                dy_du: 0.0,
            }
        }
        fn input_gain(&mut self, _: &[f32; 3], _: f32, _: f32) -> [f32; 3] {
            [0.0; 3]
        }
    }
    const FILTER: Ukf<Still, f32, 3, 7> = Ukf::new();
    let mut f = FILTER;
    assert_eq!(f.state(), [1e-3, 1e-3, 0.0]);
    let est = f.step(0.0, 1e-6);
    // at rest on z_max (mode 3); φ moves towards the measurement; H_c is
    // state 2 here, so the estimate reports it
    assert_eq!((est.z, est.mode), (1e-3, 3));
    assert!(est.phi > 0.0 && est.phi < 1e-6, "{est:?}");
    assert_eq!(est.hc, Some(est.phi));
    assert_eq!(f, {
        let mut g = Ukf::<Still, f32, 3, 7>::default();
        g.step(0.0, 1e-6);
        g
    });
}
