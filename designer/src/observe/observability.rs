//! Where SEMERA is blind: the observability of its model over a recorded
//! current (semera-electromagnetic-estimation [SE §II-B], [SE 30–35]).
//!
//! The state x = [r, l, l_prev] is observable on [kΔ, (k+2)Δ] iff the
//! observability matrix O_[k,k+2] of [SE 31], built from i_{k−1}, i_k, i_{k+1},
//! i_{k+2}, is regular. Its determinant [SE 32], derived again from [SE 31] (the
//! text prints the term −i_{k−1}·i_{k+1}·i_{k+2} twice; the second one is
//! −i_{k−1}·i_k·i_{k+2}, without which [SE 35] — a current linear in time is
//! unobservable — would not hold), with a = i_{k−1}, b = i_k, c = i_{k+1},
//! d = i_{k+2}:
//!
//! det O_[k,k+2] = (2b²d − b²c − bc² − acd + 2ac² − abd)/Δ².
//!
//! It vanishes for a constant current, a current linear in time [SE 35] and also
//! for a geometric one, i_k = A·ρᵏ (an exponential decay at zero voltage with
//! constant l: r and l then only appear through l/r).
//!
//! On a *recorded* current the determinant is never exactly zero: noise makes
//! it small but not null. [`analyse`] therefore calls sample k observable when
//!
//! - the four currents are outside the noise interval [−n_σ σ_i, n_σ σ_i]
//!   (the confidence-interval detector of SEMERA), and
//! - |P| > n_σ·s, where P = Δ²·det is the polynomial above and s the standard
//!   deviation that measurement noise of variance σ_i² alone gives it around
//!   the recorded values: s² = σ_i²·|∇P|² + ½σ_i⁴·‖∇²P‖²_F + 32·σ_i⁶ (the
//!   linear, quadratic and cubic terms of P(i + ε), ε ~ N(0, σ_i² I), taken
//!   as uncorrelated; the cubic term's 32 is the sum of its squared
//!   coefficients times the fourth and second moments).

/// P(a, b, c, d) = Δ²·det O_[k,k+2] [SE 32] of a = i_{k−1}, b = i_k, c = i_{k+1},
/// d = i_{k+2} [A³].
pub fn polynomial(i: [f64; 4]) -> f64 {
    let [a, b, c, d] = i;
    2.0 * b * b * d - b * b * c - b * c * c - a * c * d + 2.0 * a * c * c - a * b * d
}

/// det O_[k,k+2] of [SE 31–32] from i_{k−1}, i_k, i_{k+1}, i_{k+2} and Δ.
pub fn determinant(i: [f64; 4], sample_period: f64) -> f64 {
    polynomial(i) / (sample_period * sample_period)
}

/// The standard deviation of [`polynomial`] that current noise of standard
/// deviation `sigma` alone produces around `i` (see the module docs).
pub fn noise_std(i: [f64; 4], sigma: f64) -> f64 {
    let [a, b, c, d] = i;
    let grad = [
        -c * d + 2.0 * c * c - b * d,
        4.0 * b * d - 2.0 * b * c - c * c - a * d,
        -b * b - 2.0 * b * c - a * d + 4.0 * a * c,
        2.0 * b * b - a * c - a * b,
    ];
    // ∇²P: [aa, ab, ac, ad, bb, bc, bd, cc, cd, dd]; off-diagonals count twice in ‖·‖_F
    let (hab, hac, had) = (-d, 4.0 * c - d, -b - c);
    let (hbb, hbc, hbd) = (4.0 * d - 2.0 * c, -2.0 * b - 2.0 * c, 4.0 * b - a);
    let (hcc, hcd) = (4.0 * a - 2.0 * b, -a);
    let frob2 = hbb * hbb
        + hcc * hcc
        + 2.0 * (hab * hab + hac * hac + had * had + hbc * hbc + hbd * hbd + hcd * hcd);
    let g2: f64 = grad.iter().map(|g| g * g).sum();
    let s2 = sigma * sigma;
    (s2 * g2 + 0.5 * s2 * s2 * frob2 + 32.0 * s2 * s2 * s2).sqrt()
}

/// How [`analyse`] reads a record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObservabilitySettings {
    /// Δ [s] between samples.
    pub sample_period: f64,
    /// σ_i [A]: standard deviation of the current measurement noise.
    pub current_noise: f64,
    /// n_σ: the confidence of both tests.
    pub n_sigma: f64,
    /// S ≥ 1: [SE 32] is evaluated on i_{k−S}, i_k, i_{k+S}, i_{k+2S}, i.e. on
    /// the record sampled every S·Δ. S = 1 is the window of [SE 31]; on noisy
    /// records the slow parts of a transient only rise above the noise over
    /// a few samples (the module docs of [`analyse`]).
    pub stride: usize,
}

/// The state of one sample's window.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// det O_[k,k+2] is distinguishable from noise: the window is observable.
    Observable,
    /// A current of the window lies inside the noise interval ±n_σ·σ_i
    /// (SEMERA's expert rule holds; nothing can be observed).
    NoCurrent,
    /// The current is there, but det O_[k,k+2] is within what noise gives
    /// (constant, linear or geometric current: [SE 35]).
    NoExcitation,
    /// The window leaves the record (its first and last samples).
    Edge,
}

/// The observability of each sample of a recorded current.
#[derive(Debug, Clone, PartialEq)]
pub struct Observability {
    /// det O_[k,k+2] [SE 32] [A³/s²] per sample k (with Δ → S·Δ); NaN at the edges.
    pub determinant: Vec<f64>,
    /// Its noise standard deviation (same units); NaN at the edges.
    pub noise: Vec<f64>,
    pub status: Vec<Status>,
}

impl Observability {
    /// Whether sample k's window is observable.
    pub fn observable(&self, k: usize) -> bool {
        self.status.get(k) == Some(&Status::Observable)
    }
}

/// The observability of SEMERA's model along `current` (one sample every
/// `settings.sample_period`). Sample k is [`Status::Observable`] when its
/// four currents lie outside ±n_σ·σ_i and |det O_[k,k+2]| exceeds n_σ times
/// its noise standard deviation ([`noise_std`]).
///
/// With σ_i = 1 mA and Δ = 50 µs ([SE Table II]), a 4-sample window sees
/// only the fastest transients above the noise; the rise of the current after
/// a voltage step becomes visible at S ≈ 4 (200 µs), while a steady current
/// stays blind at any S, as it should.
pub fn analyse(current: &[f64], settings: &ObservabilitySettings) -> Observability {
    let n = current.len();
    let s = settings.stride.max(1);
    let dt = settings.sample_period * s as f64;
    let ci = settings.n_sigma * settings.current_noise;
    let mut out = Observability {
        determinant: vec![f64::NAN; n],
        noise: vec![f64::NAN; n],
        status: vec![Status::Edge; n],
    };
    for k in s..n.saturating_sub(2 * s) {
        let w = [
            current[k - s],
            current[k],
            current[k + s],
            current[k + 2 * s],
        ];
        let p = polynomial(w);
        let noise = noise_std(w, settings.current_noise);
        out.determinant[k] = p / (dt * dt);
        out.noise[k] = noise / (dt * dt);
        out.status[k] = if !w.iter().all(|x| x.abs() > ci) {
            Status::NoCurrent
        } else if p.abs() > settings.n_sigma * noise {
            Status::Observable
        } else {
            Status::NoExcitation
        };
    }
    out
}

/// A maximal run of samples with the same blind status.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlindInterval {
    /// Time of its first and last sample [s].
    pub start: f64,
    pub end: f64,
    /// Its samples.
    pub samples: usize,
    /// [`Status::NoCurrent`], [`Status::NoExcitation`] or [`Status::Edge`].
    pub why: Status,
}

/// The maximal runs of samples that are not observable, in order, split where
/// the reason changes.
///
/// # Panics
/// If `t` and `observability.status` differ in length.
pub fn blind_intervals(t: &[f64], observability: &Observability) -> Vec<BlindInterval> {
    let status = &observability.status;
    assert_eq!(t.len(), status.len(), "one time per sample");
    let mut out: Vec<BlindInterval> = Vec::new();
    let mut run: Option<(usize, Status)> = None;
    for k in 0..=status.len() {
        let here = status.get(k).copied();
        if let Some((start, why)) = run {
            if here != Some(why) {
                out.push(BlindInterval {
                    start: t[start],
                    end: t[k - 1],
                    samples: k - start,
                    why,
                });
                run = None;
            }
        }
        match here {
            Some(Status::Observable) | None => {}
            Some(why) => {
                if run.is_none() {
                    run = Some((k, why));
                }
            }
        }
    }
    out
}
