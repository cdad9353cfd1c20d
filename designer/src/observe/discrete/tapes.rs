//! The discretised model compiled to tapes for f64 evaluation, and the
//! tape-backed model the runtime's filters run on as the designer's
//! reference ([`TapeModel`]).

use reldesign_runtime::observe::{self as rt, Configured, Linearisation, Reading, Settings};

use crate::sym::{Id, Tape};

use super::{DiscreteModel, MAX_DIM};

/// The discretised model compiled for f64 evaluation (parameters bound),
/// with scratch buffers: evaluations do not allocate.
#[derive(Clone, Debug)]
pub struct DiscreteTapes {
    n: usize,
    /// F(x, u) (n), then f_v (the acceleration).
    prediction: Tape,
    /// ∂F/∂x row by row (n²), then ∂F/∂u (n).
    jacobian: Tape,
    /// h, ∂h/∂u, then ∂h/∂x (n).
    measurement: Tape,
    /// ∂F/∂u (n).
    input_gain: Tape,
    /// f_v [JA 87].
    acceleration: Tape,
    scratch: [Vec<f64>; 5],
    /// x (n), u, t, then θ (the adapted parameters, if any).
    inputs: Vec<f64>,
}

/// F(x, u) and the acceleration f_v at x.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prediction {
    /// x_{k+1} (first n entries used).
    pub next: [f64; MAX_DIM],
    /// f_v(z, v, φ) at x_k.
    pub acceleration: f64,
}

/// h(x, u) and its derivatives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasurementEval {
    pub y: f64,
    /// ∂h/∂u
    pub dy_du: f64,
    /// ∂h/∂x (first n used)
    pub dy_dx: [f64; MAX_DIM],
}

impl DiscreteTapes {
    /// `discrete` compiled.
    pub fn new(discrete: &DiscreteModel) -> DiscreteTapes {
        Self::adaptive(discrete, &[])
    }

    /// `discrete` compiled with the parameters `free` as inputs θ (at their
    /// model values until [`DiscreteTapes::set_theta`]).
    pub fn adaptive(discrete: &DiscreteModel, free: &[Id]) -> DiscreteTapes {
        let dm = discrete;
        let mut prediction = dm.transition.clone();
        prediction.push(dm.acceleration);
        let mut jacobian: Vec<_> = dm.transition_jacobian.iter().flatten().copied().collect();
        jacobian.extend(&dm.input_gain);
        let mut measurement = vec![dm.measurement, dm.measurement_input_gain];
        measurement.extend(&dm.measurement_jacobian);
        let (prediction, jacobian, measurement, input_gain, acceleration) = (
            dm.compile_adaptive(&prediction, free),
            dm.compile_adaptive(&jacobian, free),
            dm.compile_adaptive(&measurement, free),
            dm.compile_adaptive(&dm.input_gain, free),
            dm.compile_adaptive(&[dm.acceleration], free),
        );
        let mut inputs = vec![0.0; dm.dim() + 2];
        // θ at the model's values
        inputs.extend(free.iter().map(|&f| {
            let value = dm.params.iter().find(|&(_, id, _)| id == f);
            value.map_or(f64::NAN, |(_, _, v)| v)
        }));
        DiscreteTapes {
            n: dm.dim(),
            scratch: [
                prediction.scratch(),
                jacobian.scratch(),
                measurement.scratch(),
                input_gain.scratch(),
                acceleration.scratch(),
            ],
            prediction,
            jacobian,
            measurement,
            input_gain,
            acceleration,
            inputs,
        }
    }

    /// The adapted parameters' values θ (in the order they were freed).
    ///
    /// # Panics
    /// Where θ's length is not the number of freed parameters.
    pub fn set_theta(&mut self, theta: &[f64]) {
        let first = self.n + 2;
        assert_eq!(
            self.inputs.len() - first,
            theta.len(),
            "one value per adapted parameter"
        );
        self.inputs[first..].copy_from_slice(theta);
    }

    pub fn dim(&self) -> usize {
        self.n
    }

    fn set_inputs(&mut self, x: &[f64; MAX_DIM], u: f64, t: f64) -> usize {
        let n = self.n;
        self.inputs[..n].copy_from_slice(&x[..n]);
        self.inputs[n] = u;
        self.inputs[n + 1] = t;
        self.inputs.len()
    }

    /// [JA 84], and f_v at x.
    pub fn predict(&mut self, x: &[f64; MAX_DIM], u: f64, t: f64) -> Prediction {
        let m = self.set_inputs(x, u, t);
        let mut out = [0.0; MAX_DIM + 1];
        let n = self.n;
        self.prediction
            .eval(&self.inputs[..m], &mut self.scratch[0], &mut out[..n + 1]);
        let mut next = [0.0; MAX_DIM];
        next[..n].copy_from_slice(&out[..n]);
        Prediction {
            next,
            acceleration: out[n],
        }
    }

    /// ∂F/∂x and g = ∂F/∂u at (x, u).
    pub fn jacobian(
        &mut self,
        x: &[f64; MAX_DIM],
        u: f64,
        t: f64,
    ) -> ([[f64; MAX_DIM]; MAX_DIM], [f64; MAX_DIM]) {
        let m = self.set_inputs(x, u, t);
        let n = self.n;
        let mut out = [0.0; MAX_DIM * MAX_DIM + MAX_DIM];
        self.jacobian.eval(
            &self.inputs[..m],
            &mut self.scratch[1],
            &mut out[..n * n + n],
        );
        let mut f = [[0.0; MAX_DIM]; MAX_DIM];
        for (i, row) in f.iter_mut().enumerate().take(n) {
            row[..n].copy_from_slice(&out[i * n..(i + 1) * n]);
        }
        let mut gain = [0.0; MAX_DIM];
        gain[..n].copy_from_slice(&out[n * n..n * n + n]);
        (f, gain)
    }

    /// g = ∂F/∂u at (x, u).
    pub fn input_gain(&mut self, x: &[f64; MAX_DIM], u: f64, t: f64) -> [f64; MAX_DIM] {
        let m = self.set_inputs(x, u, t);
        let n = self.n;
        let mut gain = [0.0; MAX_DIM];
        self.input_gain
            .eval(&self.inputs[..m], &mut self.scratch[3], &mut gain[..n]);
        gain
    }

    /// f_v(z, v, φ) of [JA 87] at x (v of [JA 85]).
    pub fn acceleration(&mut self, x: &[f64; MAX_DIM], u: f64, t: f64) -> f64 {
        let m = self.set_inputs(x, u, t);
        let mut out = [0.0; 1];
        self.acceleration
            .eval(&self.inputs[..m], &mut self.scratch[4], &mut out);
        out[0]
    }

    /// h, ∂h/∂u, ∂h/∂x at (x, u).
    pub fn measure(&mut self, x: &[f64; MAX_DIM], u: f64, t: f64) -> MeasurementEval {
        let m = self.set_inputs(x, u, t);
        let n = self.n;
        let mut out = [0.0; MAX_DIM + 2];
        self.measurement
            .eval(&self.inputs[..m], &mut self.scratch[2], &mut out[..n + 2]);
        let mut dy_dx = [0.0; MAX_DIM];
        dy_dx[..n].copy_from_slice(&out[2..n + 2]);
        MeasurementEval {
            y: out[0],
            dy_du: out[1],
            dy_dx,
        }
    }
}

/// The discretised model on its tapes with N states, for the runtime's
/// filters: the designer's f64 reference runs the same filter code as the
/// generated one, on the same model evaluated from tapes instead of
/// straight-line code.
#[derive(Clone, Debug)]
pub struct TapeModel<const N: usize> {
    tapes: DiscreteTapes,
    settings: Settings<f64, N>,
}

impl<const N: usize> TapeModel<N> {
    /// `discrete` with N = `discrete.dim()` states (panics on another N).
    pub fn new(discrete: &DiscreteModel) -> TapeModel<N> {
        TapeModel {
            tapes: discrete.tapes(),
            settings: discrete.filter_settings(),
        }
    }

    /// `discrete` with the parameters `free` read at run time, θ of
    /// [`reldesign_runtime::calibrate::Adaptive`] (the emitted self-calibrating model's).
    pub fn adaptive(discrete: &DiscreteModel, free: &[Id]) -> TapeModel<N> {
        TapeModel {
            tapes: DiscreteTapes::adaptive(discrete, free),
            settings: discrete.filter_settings(),
        }
    }
}

impl<const N: usize, const P: usize> reldesign_runtime::calibrate::Adaptive<f64, N, P>
    for TapeModel<N>
{
    fn with_theta(&self, theta: &[f64; P]) -> Self {
        let mut model = self.clone();
        model.tapes.set_theta(theta);
        model
    }
}

/// x in the tapes' MAX_DIM-array (entries past N are 0).
fn padded<const N: usize>(x: &[f64; N]) -> [f64; MAX_DIM] {
    let mut p = [0.0; MAX_DIM];
    p[..N].copy_from_slice(x);
    p
}

/// The leading N entries.
fn leading<const N: usize>(x: &[f64; MAX_DIM]) -> [f64; N] {
    std::array::from_fn(|i| x[i])
}

impl<const N: usize> Configured<f64, N> for TapeModel<N> {
    fn settings(&self) -> Settings<f64, N> {
        self.settings
    }
}

impl<const N: usize> rt::DiscreteModel<f64, N> for TapeModel<N> {
    fn acceleration(&mut self, x: &[f64; N], u: f64, t: f64) -> f64 {
        self.tapes.acceleration(&padded(x), u, t)
    }
}

impl<const N: usize> rt::Linearised<f64, N> for TapeModel<N> {
    fn transition(&mut self, x: &[f64; N], u: f64, t: f64) -> Linearisation<f64, N> {
        let x = padded(x);
        let p = self.tapes.predict(&x, u, t);
        let (f, g) = self.tapes.jacobian(&x, u, t);
        Linearisation {
            prediction: rt::Prediction {
                next: leading(&p.next),
                accel: p.acceleration,
            },
            f_x: std::array::from_fn(|i| leading(&f[i])),
            g: leading(&g),
        }
    }

    fn measurement(&mut self, x: &[f64; N], u: f64, t: f64) -> (Reading<f64>, [f64; N]) {
        let m = self.tapes.measure(&padded(x), u, t);
        let reading = Reading {
            y: m.y,
            dy_du: m.dy_du,
        };
        (reading, leading(&m.dy_dx))
    }
}

impl<const N: usize> rt::Sampled<f64, N> for TapeModel<N> {
    fn transition(&mut self, x: &[f64; N], u: f64, t: f64) -> rt::Prediction<f64, N> {
        let p = self.tapes.predict(&padded(x), u, t);
        rt::Prediction {
            next: leading(&p.next),
            accel: p.acceleration,
        }
    }

    fn measurement(&mut self, x: &[f64; N], u: f64, t: f64) -> Reading<f64> {
        let m = self.tapes.measure(&padded(x), u, t);
        Reading {
            y: m.y,
            dy_du: m.dy_du,
        }
    }

    fn input_gain(&mut self, x: &[f64; N], u: f64, t: f64) -> [f64; N] {
        leading(&self.tapes.input_gain(&padded(x), u, t))
    }
}
