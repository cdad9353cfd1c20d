//! The simulation study of semera-electromagnetic-estimation [SE §III-B]: the valve
//! of [SE Table I] (`examples/semera-valve.toml`) driven by a 0/30 V square wave
//! with 20 ms cycles (50 % duty) from rest, measured every Δ = 50 µs with
//! σ_v = 15 mV and σ_i = 1 mA of Gaussian noise, estimated by SEMERA
//! ([SE Alg. 1]) and the integral estimator ([SE Alg. 2]) with the filter
//! parameters of [SE Table II] (the example's `[observer]`), which start from
//! r̄₀ = 77.5 Ω while the simulated coil has another resistance.
//!
//! The paper does not print the simulated resistance. [SE Table III] gives it
//! away: during the first operation the integral estimator keeps r̄ = r̄₀, so
//! its RMSE(r̂) = 1.500 Ω is |r̄₀ − r|, i.e. r = 76 Ω (or 79 Ω; "less than
//! 2 %" fits both); 76 Ω is used here instead of the example's chosen 75 Ω.
//!
//! True values, as the paper defines them: r = 76 Ω; λ = N·φ of the
//! simulation; l = λ/i the apparent inductance, which with this model (no
//! eddy currents, N²i = λR [SE 49]) is N²/R(z, φ) = N²/(k_air·z + R_iron(φ)),
//! defined also at i = 0 (where λ/i is 0/0 and the expert rule's l̄₀ is meant
//! to approximate it).
//!
//! Measurements. The voltage sample u_k is the voltage over ((k−1)Δ, kΔ],
//! as the backward difference [SE 2] reads it (the square wave's edges lie on
//! the grid). Sampled instead at the instant of each rising edge, u_k would
//! claim 30 V over an interval in which none was applied; SEMERA's first
//! step then explains it by a jump of l̂ to ~0.9 H, and [SE Table III]'s SEMERA
//! RMSE(r̂) becomes 2.8 Ω (1.25 Ω here, 1.244 Ω in the paper). The current
//! ι_k is the coil current at kΔ ("instant" sampling, what an ADC reads),
//! or, in the "average" variant, its mean over ((k−1)Δ, kΔ], computed
//! exactly as (u_k − (λ_k − λ_{k−1})/Δ)/r, with which the data satisfy [SE 2]
//! exactly.
//!
//! The RMSE of each estimate over the samples of the first operation
//! (t < 20 ms, [SE Table III]) and after it (t > 20 ms, [SE Table IV]) is printed in
//! the paper's layout. Asserted (instant sampling unless said):
//!
//! - [SE Table III], both samplings, every seed: SEMERA beats the integral
//!   estimator in r̂, l̂ and λ̂ (the paper: ratios 0.83, 0.41, 0.78; here
//!   about 0.83, 0.43–0.53, 0.78).
//! - [SE Table IV], both samplings: every seed-mean error at least 10× (λ̂: 5×)
//!   below [SE Table III]'s. Instant sampling: SEMERA's seed-mean RMSE(r̂) below
//!   the integral estimator's (ratio 0.76; the paper's 0.41); l̂ and λ̂ at
//!   parity (seed-mean ratio within 0.8–1.25; here 1.10 and 1.03).
//!
//! What does not reproduce, and why: after the first operation the paper's
//! SEMERA wins l̂ and λ̂ too, but by little (ratios 0.97 and 0.79, one noise
//! realisation). Here, over seeds, the two estimators share those errors:
//! both have the same expert rule at rest (l̄₀ = 50 mH against the true
//! 52.3 mH), and with instant sampling both carry the O(Δ) bias of the
//! backward difference [SE 2], r·Δ/2·i ≈ 0.75 mWb on a 0.4 A steady current,
//! which is why [SE Table IV]'s RMSE(λ̂) is ~0.5 mWb here against the paper's
//! 0.11–0.14 mWb; the "average" variant, free of it, gives 0.09–0.10 mWb,
//! the paper's magnitude, so the paper's simulated data presumably
//! satisfied [SE 2] (e.g. a simulation stepped at Δ). SEMERA's l̂ is noisier as
//! the current decays below ~30 mA (SNR_ι < 30 dB, which the paper notes in
//! [SE §III-B]), which costs it its small edge in l̂ on some seeds.

use designer::description::{Core, Description, Gap};
use designer::model::Model;
use designer::observe::integral::{Integral, IntegralConfig};
use designer::observe::observability;
use designer::observe::semera::{Estimate, Semera, SemeraConfig};
use designer::replay::replay;
use designer::sim::{Options, PiecewiseLinear};
use reldesign_tests::{example_with, Rng};

/// The simulated coil resistance (see the module docs).
const R_TRUE: f64 = 76.0;
const SUPPLY: f64 = 30.0;
const PERIOD: f64 = 20e-3;

/// Standard normal samples by Box–Muller on the SplitMix64 generator.
struct Gauss {
    rng: Rng,
    spare: Option<f64>,
}

impl Gauss {
    fn new(seed: u64) -> Gauss {
        Gauss {
            rng: Rng::new(seed),
            spare: None,
        }
    }

    fn next(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        // u1 in (0, 1]: ln never sees 0
        let u1 = 1.0 - self.rng.uniform(0.0, 1.0);
        let u2 = self.rng.uniform(0.0, 1.0);
        let radius = (-2.0 * u1.ln()).sqrt();
        let angle = 2.0 * std::f64::consts::PI * u2;
        self.spare = Some(radius * angle.sin());
        radius * angle.cos()
    }
}

/// The noise-free simulation of `cycles` cycles, sampled every Δ.
struct Truth {
    dt: f64,
    t: Vec<f64>,
    /// the voltage over ((k−1)Δ, kΔ]
    v: Vec<f64>,
    /// i(kΔ)
    i: Vec<f64>,
    /// λ = N·φ
    lambda: Vec<f64>,
    /// l = N²/R(z, φ) (= λ/i)
    l: Vec<f64>,
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Sampling {
    /// ι_k = i(kΔ) + noise
    Instant,
    /// ι_k = mean of i over ((k−1)Δ, kΔ] + noise
    Average,
}

/// The measured record: u_k, ι_k.
struct Measured {
    u: Vec<f64>,
    iota: Vec<f64>,
}

fn description() -> Description {
    example_with(
        "semera-valve.toml",
        &[("resistance = 75.0", &format!("resistance = {R_TRUE:?}"))],
    )
}

/// `cycles` 20 ms cycles of the 0/30 V square wave from rest.
fn simulate(d: &Description, cycles: usize) -> Truth {
    let o = d.observer.as_ref().expect("the example has [observer]");
    let dt = o.sample_period;
    let t_end = PERIOD * cycles as f64;
    let n = (t_end / dt).round() as usize;
    let t: Vec<f64> = (0..=n).map(|k| k as f64 * dt).collect();
    let input = PiecewiseLinear::square_wave(SUPPLY, 0.0, PERIOD, 0.5, t_end).unwrap();
    let mut model = Model::build(d);
    let options = Options {
        rtol: 1e-9,
        ..Options::default()
    };
    let run = replay(&mut model, &input, &t, &options).unwrap();
    let turns = d.coil.turns;
    let Gap::Linear { slope, offset } = d.gap else {
        unreachable!("Table I: a linear gap")
    };
    let Core::Saturating { r0, phi_sat } = d.core else {
        unreachable!("Table I: a saturating core")
    };
    let mut truth = Truth {
        dt,
        t: t.clone(),
        v: Vec::new(),
        i: run.current.clone(),
        lambda: Vec::new(),
        l: Vec::new(),
    };
    for (k, &tk) in t.iter().enumerate() {
        let x = run.trajectory.x[k];
        let (z, phi) = (x[0], x[2]);
        // the square wave in the middle of ((k−1)Δ, kΔ] (0 before t = 0: at rest)
        let mid = tk - 0.5 * dt;
        let on = mid >= 0.0 && (mid / PERIOD).fract() < 0.5;
        truth.v.push(if on { SUPPLY } else { 0.0 });
        truth.lambda.push(turns * phi);
        let reluctance = offset + slope * z + r0 / (1.0 - phi.abs() / phi_sat);
        truth.l.push(turns * turns / reluctance);
    }
    truth
}

/// The truth with Gaussian noise σ_v, σ_i (seeded).
fn measure(d: &Description, truth: &Truth, sampling: Sampling, seed: u64) -> Measured {
    let o = d.observer.as_ref().unwrap();
    let mut gauss = Gauss::new(0x5E3E_4A00 + seed);
    let mut m = Measured {
        u: Vec::new(),
        iota: Vec::new(),
    };
    for k in 0..truth.t.len() {
        let i = match sampling {
            Sampling::Average if k > 0 => {
                (truth.v[k] - (truth.lambda[k] - truth.lambda[k - 1]) / truth.dt) / R_TRUE
            }
            _ => truth.i[k],
        };
        m.u.push(truth.v[k] + o.voltage_noise * gauss.next());
        m.iota.push(i + o.current_noise * gauss.next());
    }
    m
}

/// RMSE of r̂, l̂, λ̂ over the samples with t in the window.
fn rmse(truth: &Truth, est: &[Estimate], window: impl Fn(f64) -> bool) -> [f64; 3] {
    let mut sums = [0.0; 3];
    let mut n = 0usize;
    for (k, e) in est.iter().enumerate() {
        if !window(truth.t[k]) {
            continue;
        }
        sums[0] += (e.r - R_TRUE).powi(2);
        sums[1] += (e.l - truth.l[k]).powi(2);
        sums[2] += (e.lambda - truth.lambda[k]).powi(2);
        n += 1;
    }
    sums.map(|s| (s / n as f64).sqrt())
}

/// [SEMERA, integral] × [r, l, λ] in each window.
#[derive(Clone, Copy)]
struct Tables {
    first: [[f64; 3]; 2],
    after: [[f64; 3]; 2],
}

fn estimate(d: &Description, truth: &Truth, m: &Measured) -> Tables {
    let mut semera = Semera::new(&SemeraConfig::from_description(d).unwrap());
    let mut integral = Integral::new(&IntegralConfig::from_description(d).unwrap());
    let s: Vec<Estimate> = (0..m.u.len())
        .map(|k| semera.step(m.u[k], m.iota[k]))
        .collect();
    let g: Vec<Estimate> = (0..m.u.len())
        .map(|k| integral.step(m.u[k], m.iota[k]))
        .collect();
    // the paper's windows, t < 20 ms and t > 20 ms (the sample at 20 ms is in neither)
    let first = |t: f64| t < PERIOD;
    let after = |t: f64| t > PERIOD;
    Tables {
        first: [rmse(truth, &s, first), rmse(truth, &g, first)],
        after: [rmse(truth, &s, after), rmse(truth, &g, after)],
    }
}

fn print_table(title: &str, rows: &[[f64; 3]; 2], units: [(&str, f64); 3]) {
    println!("\n{title}");
    println!(
        "{:<12}{:>14}{:>14}{:>14}",
        "Algorithm", "RMSE(r̂)", "RMSE(l̂)", "RMSE(λ̂)"
    );
    for (name, row) in ["SEMERA", "Integral"].iter().zip(rows) {
        print!("{name:<12}");
        for (x, (unit, scale)) in row.iter().zip(units) {
            print!("{:>14}", format!("{:.4} {unit}", x / scale));
        }
        println!();
    }
    print!("{:<12}", "Ratio (S/I)");
    for (s, i) in rows[0].iter().zip(&rows[1]) {
        print!("{:>14}", format!("{:.4}", s / i));
    }
    println!();
}

fn report(title: &str, tables: &Tables) {
    println!("\n== {title}");
    print_table(
        "TABLE III  estimation errors during the first operation (t < 20 ms)",
        &tables.first,
        [("Ω", 1.0), ("H", 1.0), ("mWb", 1e-3)],
    );
    print_table(
        "TABLE IV  estimation errors after the first operation (t > 20 ms)",
        &tables.after,
        [("mΩ", 1e-3), ("mH", 1e-3), ("mWb", 1e-3)],
    );
}

const PAPER: &str = "\n== the paper (semera Tables III and IV)
TABLE III   SEMERA 1.244 Ω  0.1022 H  3.602 mWb | Integral 1.500 Ω  0.2512 H  4.645 mWb | ratio 0.8296 0.4069 0.7756
TABLE IV    SEMERA 4.199 mΩ 5.022 mH  0.1136 mWb | Integral 10.30 mΩ 5.158 mH  0.1445 mWb | ratio 0.4077 0.9735 0.7866";

const NAMES: [&str; 3] = ["r̂", "l̂", "λ̂"];

fn mean(tables: &[Tables], pick: impl Fn(&Tables) -> [[f64; 3]; 2]) -> [[f64; 3]; 2] {
    let mut m = [[0.0; 3]; 2];
    for t in tables {
        let x = pick(t);
        for a in 0..2 {
            for j in 0..3 {
                m[a][j] += x[a][j] / tables.len() as f64;
            }
        }
    }
    m
}

/// The paper's four cycles, instant and average current sampling, five noise
/// seeds each (one simulation; the noise differs).
#[test]
fn semera_beats_the_integral_estimator_like_tables_iii_and_iv() {
    let d = description();
    let truth = simulate(&d, 4);
    let seeds = 1..=5u64;
    let mut all = Vec::new();
    for sampling in [Sampling::Instant, Sampling::Average] {
        let tables: Vec<Tables> = seeds
            .clone()
            .map(|seed| estimate(&d, &truth, &measure(&d, &truth, sampling, seed)))
            .collect();
        report(
            &format!(
                "{sampling:?} current sampling, seed 1 (r = {R_TRUE} Ω, r̄₀ = 77.5 Ω, 4 cycles)"
            ),
            &tables[0],
        );
        let m = Tables {
            first: mean(&tables, |t| t.first),
            after: mean(&tables, |t| t.after),
        };
        report(
            &format!("{sampling:?} current sampling, mean over seeds 1–5"),
            &m,
        );
        all.push((sampling, tables, m));
    }
    println!("{PAPER}");

    for (sampling, tables, m) in &all {
        for (seed, t) in seeds.clone().zip(tables) {
            for (j, name) in NAMES.iter().enumerate() {
                assert!(
                    t.first[0][j] < t.first[1][j],
                    "{sampling:?}, seed {seed}, first operation: SEMERA's RMSE({name}) = {:e} is \
                     not below the integral estimator's {:e}",
                    t.first[0][j],
                    t.first[1][j]
                );
            }
        }
        for a in 0..2 {
            for (j, factor) in [10.0, 10.0, 5.0].into_iter().enumerate() {
                assert!(
                    m.after[a][j] * factor < m.first[a][j],
                    "{sampling:?}: the RMSE({}) after the first operation ({:e}) is not {factor}× \
                     below the first operation's ({:e})",
                    NAMES[j],
                    m.after[a][j],
                    m.first[a][j]
                );
            }
        }
    }
    let (_, _, m) = &all[0];
    assert!(
        m.after[0][0] < m.after[1][0],
        "after the first operation SEMERA's mean RMSE(r̂) {:e} is not below the integral \
         estimator's {:e}",
        m.after[0][0],
        m.after[1][0]
    );
    for (j, name) in NAMES.iter().enumerate().skip(1) {
        let ratio = m.after[0][j] / m.after[1][j];
        assert!(
            (0.8..1.25).contains(&ratio),
            "after the first operation, RMSE({name}) SEMERA/integral = {ratio}: not at parity"
        );
    }
}

/// The observability utility [SE 32] on the study's measured current: at rest
/// and where the current is steady the record is blind; the rise of the
/// current is observable at a 4-sample stride.
#[test]
fn the_study_current_is_blind_where_it_is_steady() {
    use observability::{analyse, blind_intervals, ObservabilitySettings, Status};
    let d = description();
    let o = d.observer.clone().unwrap();
    let truth = simulate(&d, 2);
    let m = measure(&d, &truth, Sampling::Instant, 7);
    let dt = o.sample_period;
    let run = |stride: usize| {
        let settings = ObservabilitySettings {
            sample_period: dt,
            current_noise: o.current_noise,
            n_sigma: 3.29,
            stride,
        };
        analyse(&m.iota, &settings)
    };
    let index = |t: f64| (t / dt).round() as usize;
    let share = |obs: &observability::Observability, t0: f64, t1: f64, s: Status| {
        let (k0, k1) = (index(t0), index(t1));
        obs.status[k0..k1].iter().filter(|&&x| x == s).count() as f64 / (k1 - k0) as f64
    };
    for stride in [1, 4] {
        let obs = run(stride);
        // at rest at the end of the second cycle: no current
        assert_eq!(share(&obs, 37e-3, 39.5e-3, Status::NoCurrent), 1.0);
        // the end of the on-phase: steady current, no excitation
        let steady = share(&obs, 7e-3, 9.5e-3, Status::NoExcitation);
        assert!(steady > 0.99, "stride {stride}: steady {steady}");
        // the voltage's fall at 30 ms: the current drops, observable
        assert!(obs.observable(index(30e-3)) || obs.observable(index(30e-3) - 1));
    }
    let obs = run(4);
    let rise = share(&obs, 20.1e-3, 22e-3, Status::Observable);
    assert!(rise > 0.3, "rise at stride 4: {rise}");
    // the noise-free current: [SE 32] is exactly ~0 where it is steady
    let exact =
        observability::determinant([truth.i[190], truth.i[191], truth.i[192], truth.i[193]], dt);
    let scale = truth.i[190].powi(3) / (dt * dt);
    assert!(exact.abs() < 1e-9 * scale, "steady: det = {exact:e}");
    let blind = blind_intervals(&truth.t, &obs);
    println!(
        "stride 4: {} blind intervals; longer than 1 ms:",
        blind.len()
    );
    for b in blind.iter().filter(|b| b.end - b.start > 1e-3) {
        println!(
            "  {:7.3} ms – {:7.3} ms  {:?}",
            b.start * 1e3,
            b.end * 1e3,
            b.why
        );
    }
}
