//! The reference filters' shape: a runtime filter (`reldesign_runtime::observe`)
//! on the tape-backed model ([`TapeModel`]) at the model's number of states
//! (3, 4 with H_c or R, 5 with both, known only when the description is
//! read), with the designer's [`Estimate`] and [`MAX_DIM`]-arrays.

use reldesign_runtime::linalg::Matrix;
use reldesign_runtime::observe as rt;

use crate::model::Model;

use super::discrete::{DiscreteModel, Estimate, KalmanError, KalmanSettings, TapeModel, MAX_DIM};

/// A runtime filter on N states, as the reference wrapper calls it.
pub trait Runtime<const N: usize>: Sized {
    fn build(model: TapeModel<N>) -> Self;
    fn step(&mut self, u: f64, y: f64) -> rt::Estimate<f64>;
    fn state(&self) -> [f64; N];
    fn covariance(&self) -> Matrix<f64, N>;
    fn skipped(&self) -> u32;
    fn repairs(&self) -> u32;
    fn innovation(&self) -> (f64, f64);
}

macro_rules! runtime_impl {
    ($filter:ty, $($points:ident)?) => {
        impl<const N: usize $(, const $points: usize)?> Runtime<N> for $filter {
            fn build(model: TapeModel<N>) -> Self {
                let settings = rt::Configured::settings(&model);
                <$filter>::with_model(model, &settings)
            }
            fn step(&mut self, u: f64, y: f64) -> rt::Estimate<f64> {
                <$filter>::step(self, u, y)
            }
            fn state(&self) -> [f64; N] {
                <$filter>::state(self)
            }
            fn covariance(&self) -> Matrix<f64, N> {
                <$filter>::covariance(self)
            }
            fn skipped(&self) -> u32 {
                <$filter>::skipped(self)
            }
            fn repairs(&self) -> u32 {
                <$filter>::repairs(self)
            }
            fn innovation(&self) -> (f64, f64) {
                <$filter>::innovation(self)
            }
        }
    };
}

runtime_impl!(rt::Ekf<TapeModel<N>, f64, N>,);
runtime_impl!(rt::Ukf<TapeModel<N>, f64, N, P>, P);

/// A reference filter: `A` on 3 states, `B` on 4, `C` on 5.
#[derive(Clone, Debug)]
pub struct Reference<A, B, C>(ByDim<A, B, C>);

#[derive(Clone, Debug)]
enum ByDim<A, B, C> {
    Three(A),
    Four(B),
    Five(C),
}

/// `a` in the leading entries of a [`MAX_DIM`]-array.
fn padded<const N: usize>(a: [f64; N]) -> [f64; MAX_DIM] {
    let mut p = [0.0; MAX_DIM];
    p[..N].copy_from_slice(&a);
    p
}

/// A covariance in the leading block of a [`MAX_DIM`]-square.
fn padded_square<const N: usize>(p: Matrix<f64, N>) -> [[f64; MAX_DIM]; MAX_DIM] {
    let mut out = [[0.0; MAX_DIM]; MAX_DIM];
    for (o, row) in out.iter_mut().zip(p) {
        *o = padded(row);
    }
    out
}

/// Calls `$body` with the filter of whichever size.
macro_rules! each {
    ($self:expr, $f:ident => $body:expr) => {
        match $self {
            ByDim::Three($f) => $body,
            ByDim::Four($f) => $body,
            ByDim::Five($f) => $body,
        }
    };
}

impl<A: Runtime<3>, B: Runtime<4>, C: Runtime<5>> Reference<A, B, C> {
    /// A filter at its initial state (at rest at z_max, φ = 0, H_c = 0).
    pub fn new(discrete: &DiscreteModel) -> Self {
        Reference(match discrete.dim() {
            3 => ByDim::Three(A::build(TapeModel::new(discrete))),
            4 => ByDim::Four(B::build(TapeModel::new(discrete))),
            _ => ByDim::Five(C::build(TapeModel::new(discrete))),
        })
    }

    /// Discretises `model` and builds the filter.
    pub fn from_model(model: &Model, settings: &KalmanSettings) -> Result<Self, KalmanError> {
        Ok(Self::new(&DiscreteModel::new(model, settings)?))
    }

    /// One sample: predict with u (held over the last sample), update with
    /// y (measured now), report the posterior.
    pub fn step(&mut self, u: f64, y: f64) -> Estimate {
        each!(&mut self.0, f => f.step(u, y).into())
    }

    /// The posterior mean x_{k|k} (first `dim` entries).
    pub fn state(&self) -> [f64; MAX_DIM] {
        each!(&self.0, f => padded(f.state()))
    }

    /// The posterior covariance (leading `dim`×`dim` block).
    pub fn covariance(&self) -> [[f64; MAX_DIM]; MAX_DIM] {
        each!(&self.0, f => padded_square(f.covariance()))
    }

    pub fn dim(&self) -> usize {
        match &self.0 {
            ByDim::Three(_) => 3,
            ByDim::Four(_) => 4,
            ByDim::Five(_) => 5,
        }
    }

    /// The last step's innovation y − ŷ and its variance S.
    pub fn innovation(&self) -> (f64, f64) {
        each!(&self.0, f => f.innovation())
    }

    /// Samples whose measurement update was skipped (non-finite data).
    pub fn skipped(&self) -> usize {
        each!(&self.0, f => f.skipped() as usize)
    }

    /// Restarts after a non-finite prediction (the UKF: and repaired
    /// factorisations).
    pub fn repairs(&self) -> usize {
        each!(&self.0, f => f.repairs() as usize)
    }
}
