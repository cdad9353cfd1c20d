//! The discretised model as the filters see it (jiles-atherton-actuator-model
//! [JA §6.1], [JA 84–87]): the traits a model implements (generated code with
//! straight-line functions on a zero-sized type, the designer with tapes)
//! and the settings the filters read (noise, x₀, P₀, the stops, the
//! unscented transform's weights) as plain data.
//!
//! The state is x = [z, z_prev, φ, …] with N entries: z and z_prev (the
//! position one sample earlier) first, φ third, then H_c and/or R at the
//! indices [`Settings::field`] and [`Settings::resistance`] give.

use crate::linalg::{Matrix, Scalar};

/// What the filters need besides the model functions, for N states.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings<T, const N: usize> {
    /// T_s [s]: the sample period.
    pub sample_period: T,
    /// z_min [m]: the lower stop.
    pub z_min: T,
    /// z_max [m]: the upper stop.
    pub z_max: T,
    /// [JA 86]: the estimate rests on a stop within this distance [m] of it.
    pub mode_band: T,
    /// σ_u²: variance of the measured input's noise (Q gets σ_u²·g·gᵀ,
    /// g = ∂F/∂u; the measurement σ_u²·(∂h/∂u)²).
    pub input_variance: T,
    /// σ_y²: variance of the measured output's noise.
    pub measurement_variance: T,
    /// diag(q_z², 0, q_φ², …): the part of Q that does not come from the input.
    pub process_variance: [T; N],
    /// x₀.
    pub initial_state: [T; N],
    /// P₀ (positive definite).
    pub initial_covariance: Matrix<T, N>,
    /// Index of H_c in x (the Jiles–Atherton core), if it is a state.
    pub field: Option<usize>,
    /// Index of R in x, if the coil resistance is estimated.
    pub resistance: Option<usize>,
    /// The unscented transform's constants (UKF).
    pub unscented: Weights<T>,
    /// chol P₀, the factor a reset of the UKF's covariance starts from (P₀
    /// rounded to f32 may not factor).
    pub initial_factor: Matrix<T, N>,
}

/// Weights of the unscented transform (Julier's scaled form): sigma points
/// x̄ ± γ·(columns of chol P), γ = √(n + λ), λ = α²·(n + κ) − n.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Weights<T> {
    /// γ = √(n + λ).
    pub gamma: T,
    /// W₀ᵐ = λ/(n + λ): the centre point's weight in means.
    pub mean0: T,
    /// W₀ᶜ = W₀ᵐ + 1 − α² + β: the centre point's weight in covariances.
    pub cov0: T,
    /// Wᵢ = 1/(2·(n + λ)): every other point's weight.
    pub other: T,
}

/// F(x, u) of [JA 84] and f_v of [JA 87] at x: a prediction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Prediction<T, const N: usize> {
    /// x_{k+1} = F(x_k, u).
    pub next: [T; N],
    /// [JA 87] f_v(z, v, φ) at x_k, v of [JA 85]: where the armature is pushed.
    pub accel: T,
}

/// A prediction with its derivatives (the EKF's linearisation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Linearisation<T, const N: usize> {
    pub prediction: Prediction<T, N>,
    /// ∂F/∂x (rows).
    pub f_x: Matrix<T, N>,
    /// g = ∂F/∂u: maps the input's noise into Q.
    pub g: [T; N],
}

/// The measured quantity y = h(x, u) and ∂h/∂u.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reading<T> {
    /// The coil current (voltage drive) or voltage (current drive).
    pub y: T,
    /// ∂h/∂u: the input's noise in the measurement variance.
    pub dy_du: T,
}

/// The discretised model of one actuator with N states. `t` is the time of
/// x [s] from the first sample (only a model whose resistance drifts reads
/// it).
pub trait DiscreteModel<T: Scalar, const N: usize>: Configured<T, N> {
    /// [JA 87] f_v(z, v, φ) at x, v of [JA 85]: the estimate's acceleration.
    fn acceleration(&mut self, x: &[T; N], u: T, t: T) -> T;
}

/// The model functions of the extended Kalman filter: F and h with their
/// symbolic Jacobians.
pub trait Linearised<T: Scalar, const N: usize>: DiscreteModel<T, N> {
    /// [JA 84–85] with ∂F/∂x and ∂F/∂u at (x, u).
    fn transition(&mut self, x: &[T; N], u: T, t: T) -> Linearisation<T, N>;

    /// h, ∂h/∂u and ∂h/∂x at (x, u).
    fn measurement(&mut self, x: &[T; N], u: T, t: T) -> (Reading<T>, [T; N]);
}

/// The model functions of the unscented Kalman filter: F and h at the
/// sigma points, and g = ∂F/∂u for the input's noise.
pub trait Sampled<T: Scalar, const N: usize>: DiscreteModel<T, N> {
    /// [JA 84–85] at (x, u).
    fn transition(&mut self, x: &[T; N], u: T, t: T) -> Prediction<T, N>;

    /// h and ∂h/∂u at (x, u).
    fn measurement(&mut self, x: &[T; N], u: T, t: T) -> Reading<T>;

    /// g = ∂F/∂u at (x, u).
    fn input_gain(&mut self, x: &[T; N], u: T, t: T) -> [T; N];
}

/// A model without run-time state whose settings are constants (the
/// generated ones: a zero-sized type), so that a filter on it is built by
/// a `const fn`.
pub trait Stateless<T, const N: usize>: Sized {
    /// The model.
    const MODEL: Self;
    /// Its settings.
    const SETTINGS: Settings<T, N>;
}

/// Where a model's settings come from: a stateless model's constant
/// (implemented for every [`Stateless`] model), or a run-time value (the
/// designer's tapes).
pub trait Configured<T, const N: usize> {
    /// The filters' settings.
    fn settings(&self) -> Settings<T, N>;
}

/// A stateless model's settings are its constant.
impl<T, const N: usize, M: Stateless<T, N>> Configured<T, N> for M {
    #[inline]
    fn settings(&self) -> Settings<T, N> {
        M::SETTINGS
    }
}
