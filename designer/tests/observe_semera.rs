//! SEMERA (semera Algorithm 1), the integral estimator (Algorithm 2) and the
//! observability determinant (32): hand-computed steps, convergence on a
//! constant-inductance RL circuit, the behaviour at zero current, and the
//! `[observer]` section of the description.

use designer::description::{
    parse_file, parse_str, Estimator, FloatType, IntegralSettings, SemeraSettings,
};
use designer::observe::integral::{Integral, IntegralConfig};
use designer::observe::observability::{
    analyse, determinant, noise_std, polynomial, ObservabilitySettings, Status,
};
use designer::observe::semera::{Semera, SemeraConfig};
use support::{assert_close, example_path, Tol};

/// Δ = 0.5, σ_v = 1, σ_i = 0.1, n_σ = 1, r̄₀ = 2, σ_r0 = 1, l̄₀ = 1, σ_l0 = 1,
/// N = 2, no process noise: numbers a hand can follow.
fn small_semera(rate: f64, accel: f64) -> SemeraConfig {
    SemeraConfig {
        sample_period: 0.5,
        voltage_noise: 1.0,
        current_noise: 0.1,
        turns: 2.0,
        filter: SemeraSettings {
            initial_resistance: 2.0,
            initial_resistance_std: 1.0,
            initial_inductance: 1.0,
            initial_inductance_std: 1.0,
            resistance_rate_std: rate,
            inductance_accel_std: accel,
            ci_sigmas: 1.0,
        },
    }
}

fn assert_matrix(got: [[f64; 3]; 3], want: [[f64; 3]; 3], what: &str) {
    for i in 0..3 {
        for j in 0..3 {
            assert_close(
                got[i][j],
                want[i][j],
                Tol::rel(1e-15),
                format!("{what}[{i}][{j}]"),
            );
        }
    }
}

/// Two steps of Algorithm 1 by hand (x̄₀ = [2, 1, 1], P₀ of (26) with
/// σ²_r0 = 1, σ²_l0 = 1 in the l block, ι₀ = 0):
///
/// k = 1, u = 3, ι = 1: H = [1, 2, 0]; g = Σ Hᵀ = [1, 2, 2];
/// s = H g + σ_v² = 1 + 4 + 1 = 6; ν = 3 − (2 + 2) = −1; K̂ = g/6;
/// x̂_{1/1} = [2 − 1/6, 1 − 1/3, 1 − 1/3] = [11/6, 2/3, 2/3];
/// Σ_{1/1} = Σ − g gᵀ/6 = [[5/6, −1/3, −1/3], [−1/3, 1/3, 1/3], [−1/3, 1/3, 1/3]].
/// |ι₀| = 0 is inside ±n_σσ_i = ±0.1: expert rule r̂ = 2, l̂ = 1, λ̂ = 1,
/// φ̂ = 1/2, R̂ = 4. Prediction: x̂_{2/1} = [11/6, 2·2/3 − 2/3, 2/3] =
/// [11/6, 2/3, 2/3]; Σ_{2/1} = F Σ Fᵀ = Σ_{1/1} (its l block is [[d, d], [d, d]]).
///
/// k = 2, u = 2, ι = 2: H = [2, 4, −2]; g = [5/3 − 4/3 + 2/3, −2/3 + 4/3 − 2/3,
/// −2/3 + 4/3 − 2/3] = [1, 0, 0]; s = 2 + 1 = 3; ν = 2 − (11/3 + 8/3 − 4/3) = −3;
/// K̂ = [1/3, 0, 0]; x̂_{2/2} = [5/6, 2/3, 2/3]; Σ_{2/2}(1,1) = 5/6 − 1/3 = 1/2.
/// Both currents are outside ±0.1: r̂ = 5/6, l̂ = 2/3, λ̂ = 4/3, φ̂ = 2/3, R̂ = 6.
#[test]
fn algorithm_1_by_hand() {
    let mut s = Semera::new(&small_semera(0.0, 0.0));
    assert_eq!(s.state(), [2.0, 1.0, 1.0]);
    assert_matrix(
        s.covariance(),
        [[1.0, 0.0, 0.0], [0.0, 1.0, 1.0], [0.0, 1.0, 1.0]],
        "P0",
    );

    let e = s.step(3.0, 1.0);
    assert!(!e.valid);
    assert_eq!(
        (e.r, e.l, e.lambda, e.phi, e.reluctance),
        (2.0, 1.0, 1.0, 0.5, 4.0)
    );
    let x = s.state();
    for (g, w) in x.iter().zip([11.0 / 6.0, 2.0 / 3.0, 2.0 / 3.0]) {
        assert_close(*g, w, Tol::rel(1e-15), "x̂_{2/1}");
    }
    let third = 1.0 / 3.0;
    assert_matrix(
        s.covariance(),
        [
            [5.0 / 6.0, -third, -third],
            [-third, third, third],
            [-third, third, third],
        ],
        "Σ_{2/1}",
    );

    let e = s.step(2.0, 2.0);
    assert!(e.valid);
    assert_close(e.r, 5.0 / 6.0, Tol::rel(1e-15), "r̂_2");
    assert_close(e.l, 2.0 / 3.0, Tol::rel(1e-15), "l̂_2");
    assert_close(e.lambda, 4.0 / 3.0, Tol::rel(1e-15), "λ̂_2");
    assert_close(e.phi, 2.0 / 3.0, Tol::rel(1e-15), "φ̂_2");
    assert_close(e.reluctance, 6.0, Tol::rel(1e-15), "R̂_2");
    assert_matrix(
        s.covariance(),
        [
            [0.5, -third, -third],
            [-third, third, third],
            [-third, third, third],
        ],
        "Σ_{3/2}",
    );
}

/// At zero current H = 0: no update (K̂ = 0), the prediction adds
/// G Q Gᵀ = diag((σ_ṙΔ)², (σ_l̈Δ²)², 0) (F P₀ Fᵀ = P₀), and the expert rule
/// gives r̂ = r̄₀, l̂ = l̄₀, λ̂ = 0 — all finite, for as long as it lasts.
#[test]
fn zero_current_keeps_the_expert_rule_and_grows_the_covariance() {
    // σ_ṙ = 2, σ_l̈ = 4, Δ = 0.5: q_r = 1, q_l = (4·0.25)² = 1
    let mut s = Semera::new(&small_semera(2.0, 4.0));
    let e = s.step(0.0, 0.0);
    assert!(!e.valid);
    assert_eq!(
        (e.r, e.l, e.lambda, e.phi, e.reluctance),
        (2.0, 1.0, 0.0, 0.0, 4.0)
    );
    assert_eq!(s.state(), [2.0, 1.0, 1.0]);
    assert_matrix(
        s.covariance(),
        [[2.0, 0.0, 0.0], [0.0, 2.0, 1.0], [0.0, 1.0, 1.0]],
        "Σ after a step at zero current",
    );
    for _ in 0..10_000 {
        let e = s.step(0.0, 0.0);
        assert!(!e.valid && e.r == 2.0 && e.l == 1.0 && e.lambda == 0.0);
    }
    assert!(s.covariance().iter().flatten().all(|p| p.is_finite()));

    // Currents inside ±n_σσ_i (here ±0.1) are noise: the expert rule holds.
    let mut s = Semera::new(&small_semera(0.0, 0.0));
    for (v, i) in [(0.3, 0.05), (5.0, 0.09), (1.0, -0.1), (2.0, 1.0)] {
        let e = s.step(v, i);
        assert!(!e.valid, "|ι| ≤ 0.1 now or at the previous sample");
        assert_eq!((e.r, e.l), (2.0, 1.0));
        assert_eq!(e.lambda, i);
    }
}

/// A NaN or infinite sample is a missing measurement: no update, the
/// estimate follows the expert rule, and so does the next one (whose H
/// would use the missing current); the filter stays finite and resumes.
#[test]
fn non_finite_samples_are_missing_measurements() {
    let mut s = Semera::new(&small_semera(0.0, 0.0));
    s.step(3.0, 1.0);
    let before = (s.state(), s.covariance());
    // (v, i, whether the next sample can be used: it needs a finite ι_{k−1})
    for (v, i, next) in [
        (f64::NAN, 1.0, true),
        (1.0, f64::INFINITY, false),
        (f64::NEG_INFINITY, f64::NAN, false),
    ] {
        let mut t = s.clone();
        let e = t.step(v, i);
        assert!(!e.valid);
        assert!(e.r.is_finite() && e.l.is_finite() && e.reluctance.is_finite());
        assert_eq!((e.r, e.l), (2.0, 1.0), "the expert rule");
        // only the prediction (identity on this state: l = l_prev, no process noise)
        assert_eq!((t.state(), t.covariance()), before);
        let e = t.step(2.0, 2.0);
        assert_eq!(e.valid, next, "after ({v}, {i})");
        assert!(t.state().iter().all(|x| x.is_finite()));
        let e = t.step(2.0, 2.0);
        assert!(e.valid && e.r.is_finite() && e.l.is_finite());
    }
}

/// R_k of (15) is the variance of the observation noise (12),
/// v_v − v_i,k·(r + l/Δ) + v_i,k−1·l_prev/Δ: checked by sampling it.
#[test]
fn observation_noise_variance_is_that_of_12() {
    let s = Semera::new(&small_semera(0.0, 0.0));
    let [r, l, lp] = s.state();
    let (dt, sv, si) = (0.5, 1.0, 0.1);
    let mut rng = Lcg(7);
    let n = 200_000;
    let mut sum2 = 0.0;
    for _ in 0..n {
        let (a, b, c) = (rng.gauss(), rng.gauss(), rng.gauss());
        let v = sv * a - si * b * (r + l / dt) + si * c * lp / dt;
        sum2 += v * v;
    }
    let want = s.observation_noise_variance();
    assert_close(
        want,
        1.0 + 0.01 * ((2.0 + 2.0f64).powi(2) + 4.0),
        Tol::rel(1e-15),
        "R (15)",
    );
    assert!(((sum2 / n as f64) - want).abs() < 0.02 * want);
}

/// u_k = r·i_k + l·(i_k − i_{k−1})/Δ exactly (2)–(3) with constant r, l: a
/// 0/24 V square wave through an RL circuit, sampled by the recursion
/// i_k = (u_k + l·i_{k−1}/Δ)/(r + l/Δ). Both estimators find r and l.
#[test]
fn a_constant_inductance_rl_circuit_gives_its_r_and_l() {
    // l/r = 1.7 ms: the current decays to e⁻¹² of its peak in the off-phase
    let (r, l, dt) = (12.0, 0.02, 1e-4);
    let period = 40e-3;
    let n = (4.0 * period / dt) as usize;
    let mut u = Vec::with_capacity(n);
    let mut i = Vec::with_capacity(n);
    let mut prev = 0.0;
    for k in 1..=n {
        let mid = (k as f64 - 0.5) * dt;
        let v = if (mid / period).fract() < 0.5 {
            24.0
        } else {
            0.0
        };
        let cur = (v + l * prev / dt) / (r + l / dt);
        u.push(v);
        i.push(cur);
        prev = cur;
    }
    let config = SemeraConfig {
        sample_period: dt,
        voltage_noise: 1e-3,
        current_noise: 1e-5,
        turns: 100.0,
        filter: SemeraSettings {
            initial_resistance: 10.0,
            initial_resistance_std: 3.0,
            initial_inductance: 0.1,
            initial_inductance_std: 0.05,
            resistance_rate_std: 0.1,
            inductance_accel_std: 1e3,
            ci_sigmas: 3.29,
        },
    };
    let mut s = Semera::new(&config);
    let est: Vec<_> = u.iter().zip(&i).map(|(&v, &c)| s.step(v, c)).collect();
    // the end of the last on-phase and of the last decay (current still above the CI)
    for k in [n / 4 * 3 + n / 8 - 1, n - n / 8 + 10] {
        let e = est[k];
        assert!(e.valid, "sample {k}");
        assert_close(e.r, r, Tol::rel(1e-4), format!("SEMERA r̂ at sample {k}"));
        assert_close(e.l, l, Tol::rel(1e-4), format!("SEMERA l̂ at sample {k}"));
        assert_close(
            e.lambda,
            l * i[k],
            Tol::rel(1e-4),
            format!("SEMERA λ̂ at sample {k}"),
        );
        assert_close(e.phi, l * i[k] / 100.0, Tol::rel(1e-4), "φ̂ = λ̂/N");
        assert_close(e.reluctance, 1e4 / l, Tol::rel(1e-4), "R̂ = N²/l̂");
    }

    let mut g = Integral::new(&IntegralConfig {
        sample_period: dt,
        current_noise: 1e-5,
        turns: 100.0,
        settings: IntegralSettings {
            initial_resistance: 10.0,
            initial_inductance: 0.1,
            initial_flux_linkage: 0.0,
            ci_sigmas: 3.29,
            energize_threshold: 12.0,
        },
    });
    let est: Vec<_> = u.iter().zip(&i).map(|(&v, &c)| g.step(v, c)).collect();
    // (47) over the first whole operation: Σu = r·Σi + (λ_end − λ_start)/Δ,
    // with λ_end = l·i_end ≈ 0
    let ops = n / 4;
    let (su, si): (f64, f64) = (u[..ops].iter().sum(), i[..ops].iter().sum());
    assert_close(est[ops].r, su / si, Tol::rel(1e-14), "r̄ of (47)");
    assert_close(est[ops].r, r, Tol::rel(1e-4), "r̄ after one operation");
    let k = 3 * ops + ops / 4;
    assert_close(est[k].lambda, l * i[k], Tol::rel(1e-3), "integral λ̂");
    assert_close(est[k].l, l, Tol::rel(1e-3), "integral l̂");
}

/// Algorithm 2 by hand: Δ = 0.5, λ₀ = 0.1, r̄₀ = 2, l̄₀ = 1, σ_i = 0.1,
/// n_σ = 1, threshold 5 V, N = 2.
///
/// k = 1, u = 10, ι = 1: the voltage rises (reset; the sums are empty, r̄
/// kept); S_u = 10, S_ι = 1; λ̂ = 0.1 + 0.5·(10 − 2) = 4.1; |ι₀| = 0: l̂ = 1.
/// k = 2, u = 10, ι = 3: S_u = 20, S_ι = 4, λ̂ = 0.1 + 0.5·(20 − 8) = 6.1, l̂ = 6.1/3.
/// k = 3, u = 0, ι = 2: S_u = 20, S_ι = 6, λ̂ = 4.1, l̂ = 2.05.
/// k = 4, u = 10, ι = 0.05: the voltage rises again: r̄ = 20/6 (47), since
/// S_ι² = 36 exceeds (n_σσ_i)²·3; reset; S_u = 10, S_ι = 0.05,
/// λ̂ = 0.1 + 0.5·(10 − 1/6); |ι| < 0.1: l̂ = 1; r̂ = 10/3.
#[test]
fn algorithm_2_by_hand() {
    let mut g = Integral::new(&IntegralConfig {
        sample_period: 0.5,
        current_noise: 0.1,
        turns: 2.0,
        settings: IntegralSettings {
            initial_resistance: 2.0,
            initial_inductance: 1.0,
            initial_flux_linkage: 0.1,
            ci_sigmas: 1.0,
            energize_threshold: 5.0,
        },
    });
    let e = g.step(10.0, 1.0);
    assert_eq!((e.r, e.l, e.valid), (2.0, 1.0, false));
    assert_close(e.lambda, 4.1, Tol::rel(1e-15), "λ̂_1");
    assert_close(e.phi, 2.05, Tol::rel(1e-15), "φ̂_1");
    let e = g.step(10.0, 3.0);
    assert!(e.valid);
    assert_close(e.lambda, 6.1, Tol::rel(1e-15), "λ̂_2");
    assert_close(e.l, 6.1 / 3.0, Tol::rel(1e-15), "l̂_2");
    assert_close(e.reluctance, 4.0 / (6.1 / 3.0), Tol::rel(1e-15), "R̂_2");
    let e = g.step(0.0, 2.0);
    assert_close(e.lambda, 4.1, Tol::rel(1e-15), "λ̂_3");
    assert_close(e.l, 2.05, Tol::rel(1e-15), "l̂_3");
    assert_eq!(e.r, 2.0);
    let e = g.step(10.0, 0.05);
    assert_close(e.r, 10.0 / 3.0, Tol::rel(1e-15), "r̄ of (47)");
    assert_close(
        e.lambda,
        0.1 + 0.5 * (10.0 - 1.0 / 6.0),
        Tol::rel(1e-15),
        "λ̂_4",
    );
    assert_eq!((e.l, e.valid), (1.0, false));
}

/// At rest (no current, no voltage) the integral estimator keeps r̄₀ and the
/// expert rule; a record that starts at rest and energizes later does not
/// update r̄ from noise; NaN samples are skipped.
#[test]
fn integral_estimator_at_rest_and_with_missing_samples() {
    let config = IntegralConfig {
        sample_period: 1e-4,
        current_noise: 1e-3,
        turns: 100.0,
        settings: IntegralSettings {
            initial_resistance: 50.0,
            initial_inductance: 0.05,
            initial_flux_linkage: 0.0,
            ci_sigmas: 3.29,
            energize_threshold: 12.0,
        },
    };
    let mut g = Integral::new(&config);
    let mut rng = Lcg(3);
    for _ in 0..1000 {
        let e = g.step(1e-2 * rng.gauss(), 1e-3 * rng.gauss());
        assert!(e.l == 0.05 || e.valid);
        assert!(e.r == 50.0 && e.lambda.is_finite());
    }
    let e = g.step(24.0, 0.0);
    assert_eq!(e.r, 50.0, "noise over noise is not a resistance");
    let e = g.step(f64::NAN, 0.1);
    assert!(e.lambda.is_finite() && e.r == 50.0);
    let e = g.step(24.0, f64::NAN);
    assert!(!e.valid && e.l == 0.05 && e.lambda.is_finite());
    // the NaN voltage did not count as a fall: no new operation, no reset, so
    // S_u = 24 + 24 and S_ι = 0 + 0.2 (the missing samples add nothing)
    let e = g.step(24.0, 0.2);
    assert_close(
        e.lambda,
        1e-4 * (48.0 - 50.0 * 0.2),
        Tol::rel(1e-14),
        "λ̂ without a reset",
    );
}

/// (32) against the 3×3 determinant of (31) built from C_k Fʲ, and its
/// zeros: constant (steady state), linear (35) and geometric currents.
#[test]
fn observability_determinant_32() {
    let dt = 5e-5;
    let f = [[1.0, 0.0, 0.0], [0.0, 2.0, -1.0], [0.0, 1.0, 0.0]];
    let row = |c: [f64; 3], m: [[f64; 3]; 3]| {
        [0, 1, 2].map(|j| c[0] * m[0][j] + c[1] * m[1][j] + c[2] * m[2][j])
    };
    let mut rng = Lcg(11);
    for _ in 0..100 {
        let i = [0; 4].map(|_| rng.gauss());
        let c = |k: usize| [i[k], i[k] / dt, -i[k - 1] / dt];
        let f2 = [0, 1, 2].map(|a| row(f[a], f));
        let o = [c(1), row(c(2), f), row(c(3), f2)];
        let det = o[0][0] * (o[1][1] * o[2][2] - o[1][2] * o[2][1])
            - o[0][1] * (o[1][0] * o[2][2] - o[1][2] * o[2][0])
            + o[0][2] * (o[1][0] * o[2][1] - o[1][1] * o[2][0]);
        assert_close(
            determinant(i, dt),
            det,
            // the terms of (31) are of order 1e9: 1e-9 of that is rounding
            Tol::rel(1e-9).or_abs(1.0),
            "(32) vs (31)",
        );
    }
    for (what, i) in [
        ("constant", [0.4, 0.4, 0.4, 0.4]),
        ("linear (35)", [0.1, 0.2, 0.3, 0.4]),
        ("geometric", [0.5, 0.4, 0.32, 0.256]),
    ] {
        let scale = 0.4f64.powi(3);
        assert!(
            polynomial(i).abs() < 1e-15 * scale,
            "{what}: {}",
            polynomial(i)
        );
    }
    // a current with curvature (not linear, not geometric) is observable
    assert!(polynomial([0.0, 0.1, 0.4, 0.9]).abs() > 1e-3);

    // on a noisy constant current the noise level explains the determinant
    let sigma = 1e-3;
    let settings = ObservabilitySettings {
        sample_period: dt,
        current_noise: sigma,
        n_sigma: 3.29,
        stride: 1,
    };
    let steady: Vec<f64> = (0..2000).map(|_| 0.4 + sigma * rng.gauss()).collect();
    let obs = analyse(&steady, &settings);
    let k_obs = obs
        .status
        .iter()
        .filter(|&&s| s == Status::Observable)
        .count();
    assert!(
        k_obs <= 20,
        "{k_obs} of 2000 noisy steady samples look observable"
    );
    assert_eq!(obs.status[0], Status::Edge);
    let quiet: Vec<f64> = (0..100).map(|_| sigma * rng.gauss()).collect();
    let obs = analyse(&quiet, &settings);
    assert!(obs.status[1..97].iter().all(|&s| s == Status::NoCurrent));
}

/// The noise level of (32) against sampling, at a steady and a moving current.
#[test]
fn observability_noise_level_matches_sampling() {
    let sigma = 1e-3;
    let mut rng = Lcg(5);
    for i in [
        [0.4, 0.4, 0.4, 0.4],
        [0.1, 0.15, 0.25, 0.3],
        [0.02, 0.01, 0.03, 0.02],
    ] {
        let n = 40_000;
        let samples: Vec<f64> = (0..n)
            .map(|_| polynomial(i.map(|x| x + sigma * rng.gauss())) - polynomial(i))
            .collect();
        let mean = samples.iter().sum::<f64>() / n as f64;
        let var = samples.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / n as f64;
        let want = noise_std(i, sigma);
        let got = var.sqrt();
        assert!(
            (got / want - 1.0).abs() < 0.35,
            "at {i:?}: sampled {got:e}, formula {want:e}"
        );
    }
}

/// The `[observer]` section: the example carries Table II; defaults.
#[test]
fn observer_section_parses() {
    let path = example_path("semera-valve.toml");
    let d = parse_file(&path).unwrap();
    let o = d.observer.as_ref().unwrap();
    assert_eq!(o.estimators, [Estimator::Semera, Estimator::Integral]);
    assert_eq!(o.floats, [FloatType::F32, FloatType::F64]);
    assert_eq!(
        (o.sample_period, o.voltage_noise, o.current_noise),
        (50e-6, 15e-3, 1e-3)
    );
    let c = SemeraConfig::from_description(&d).unwrap();
    assert_eq!(
        c.filter,
        SemeraSettings {
            initial_resistance: 77.5,
            initial_resistance_std: 1.0,
            initial_inductance: 50e-3,
            initial_inductance_std: 5e-3,
            resistance_rate_std: 1.0,
            inductance_accel_std: 1e8,
            ci_sigmas: 3.29,
        }
    );
    assert_eq!(c.turns, 1200.0);
    let g = IntegralConfig::from_description(&d).unwrap();
    assert_eq!(g.settings.energize_threshold, 15.0);
    assert!(o.kalman.is_none());

    // defaults: float both, λ₀ = 0, threshold u_max/2; the kalman section's UKF defaults
    let text = std::fs::read_to_string(&path).unwrap();
    let physics = &text[..text.find("\n[observer]").unwrap()];
    let with = format!(
        "{physics}\n[observer]\nestimators = [\"ukf\", \"integral\", \"ekf\"]\nsample_period = 1e-4\n\
         voltage_noise = 0.01\ncurrent_noise = 0.002\nfloat = [\"f64\"]\n\n[observer.integral]\n\
         initial_resistance = 70.0\ninitial_inductance = 0.05\nci_sigmas = 3.0\n\n\
         [observer.kalman]\nprocess_z = 1e-7\nprocess_phi = 1e-9\ninitial_z_std = 1e-5\n\
         initial_phi_std = 1e-7\n"
    );
    let d = parse_str(&with, "t.toml").unwrap_or_else(|e| panic!("{e}"));
    let o = d.observer.unwrap();
    assert_eq!(
        o.estimators,
        [Estimator::Ukf, Estimator::Integral, Estimator::Ekf]
    );
    assert_eq!(o.floats, [FloatType::F64]);
    let i = o.integral.unwrap();
    assert_eq!((i.initial_flux_linkage, i.energize_threshold), (0.0, 15.0));
    let k = o.kalman.unwrap();
    assert_eq!((k.ukf_alpha, k.ukf_beta, k.ukf_kappa), (1.0, 2.0, 0.0));
    assert_eq!((k.process_hc, k.initial_hc_std), (None, None));
    assert!(o.semera.is_none());
}

/// A small Gaussian generator (LCG + Box–Muller) for these tests.
struct Lcg(u64);

impl Lcg {
    fn uniform(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    fn gauss(&mut self) -> f64 {
        let (a, b) = (self.uniform(), self.uniform());
        (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
    }
}
