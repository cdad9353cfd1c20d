//! The calibration's model on tapes: f(x, u; θ), i(x, u; θ) and their
//! Jacobians derived symbolically from the design's model with the adapted
//! parameters θ left as tape inputs (every other parameter bound to its
//! value), so that the designer runs the runtime's own update
//! (`reldesign_runtime::calibrate`) where the emitted file has code.

use std::cell::RefCell;
use std::collections::HashMap;

use reldesign_runtime::calibrate::{Current, Derivative, Predictor};

use crate::model::Model;
use crate::sym::{Id, Tape};

/// The tape of [f, ∂f/∂x, ∂f/∂θ, i, ∂i/∂x, ∂i/∂θ] over (z, v, φ, u, t, θ).
pub struct TapePredictor<const P: usize> {
    tape: Tape,
    scratch: RefCell<Vec<f64>>,
    outputs: RefCell<Vec<f64>>,
}

impl<const P: usize> TapePredictor<P> {
    /// The predictor of `model` (three states: no Jiles–Atherton core) with
    /// the parameters `theta` (the model's symbols) adapted.
    pub fn new(model: &Model, theta: &[Id; P]) -> TapePredictor<P> {
        let mut model = model.clone();
        let exprs = expressions(&mut model, theta);
        let bindings: HashMap<Id, Id> = model
            .params
            .clone()
            .iter()
            .filter(|(_, id, _)| !theta.contains(id))
            .map(|(_, id, value)| (id, model.graph.constant(value)))
            .collect();
        let bound = model.graph.substitute_all(&exprs, &bindings);
        let mut inputs = model.tape_inputs();
        inputs.extend_from_slice(theta);
        let tape = Tape::compile(&model.graph, &inputs, &bound)
            .expect("the model's expressions use states, u, t and parameters only");
        let scratch = RefCell::new(tape.scratch());
        let outputs = RefCell::new(vec![0.0; bound.len()]);
        TapePredictor {
            tape,
            scratch,
            outputs,
        }
    }

    /// Every output at (x, u; θ).
    fn eval(&self, theta: &[f64; P], x: &[f64; 3], u: f64) -> std::cell::Ref<'_, Vec<f64>> {
        let mut inputs = Vec::with_capacity(5 + P);
        inputs.extend_from_slice(x);
        inputs.extend([u, 0.0]);
        inputs.extend_from_slice(theta);
        {
            let mut out = self.outputs.borrow_mut();
            self.tape
                .eval(&inputs, &mut self.scratch.borrow_mut(), &mut out);
        }
        self.outputs.borrow()
    }
}

/// The replay's model and its Jacobians in the model's graph: what the
/// tapes evaluate and the emitted `predictor!` writes as code.
pub struct PredictorExpressions {
    /// f(x, u; θ) of the free motion, x = [z, v, φ].
    pub f: Vec<Id>,
    /// ∂f/∂x and ∂f/∂θ, by rows.
    pub f_x: Vec<Vec<Id>>,
    pub f_theta: Vec<Vec<Id>>,
    /// i(x, u; θ), ∂i/∂x and ∂i/∂θ.
    pub current: Id,
    pub i_x: Vec<Id>,
    pub i_theta: Vec<Id>,
}

impl PredictorExpressions {
    /// The expressions of `model` (three states: no Jiles–Atherton core)
    /// with the parameters `theta` adapted.
    ///
    /// # Panics
    /// Where the model has other than three states.
    pub fn derive(model: &mut Model, theta: &[Id]) -> PredictorExpressions {
        let x = model.states.clone();
        assert_eq!(x.len(), 3, "the calibration's model has three states");
        let graph = &mut model.graph;
        let f = model.f.clone();
        let f_x = graph.jacobian(&f, &x);
        let f_theta = graph.jacobian(&f, theta);
        let current = model.current;
        let i_x = graph.jacobian(&[current], &x).concat();
        let i_theta = graph.jacobian(&[current], theta).concat();
        PredictorExpressions {
            f,
            f_x,
            f_theta,
            current,
            i_x,
            i_theta,
        }
    }
}

/// f, ∂f/∂x and ∂f/∂θ (by rows), i, ∂i/∂x, ∂i/∂θ: 3 + 9 + 3·P + 1 + 3 + P outputs.
fn expressions<const P: usize>(model: &mut Model, theta: &[Id; P]) -> Vec<Id> {
    let e = PredictorExpressions::derive(model, theta);
    let mut out = e.f;
    out.extend(e.f_x.into_iter().flatten());
    out.extend(e.f_theta.into_iter().flatten());
    out.push(e.current);
    out.extend(e.i_x);
    out.extend(e.i_theta);
    out
}

impl<const P: usize> Predictor<f64, P> for TapePredictor<P> {
    fn derivative(&self, theta: &[f64; P], x: &[f64; 3], u: f64) -> Derivative<f64, P> {
        let out = self.eval(theta, x, u);
        let mut d = Derivative {
            dx: [0.0; 3],
            f_x: [[0.0; 3]; 3],
            f_theta: [[0.0; P]; 3],
        };
        d.dx.copy_from_slice(&out[0..3]);
        for (r, row) in d.f_x.iter_mut().enumerate() {
            row.copy_from_slice(&out[3 + 3 * r..6 + 3 * r]);
        }
        for (r, row) in d.f_theta.iter_mut().enumerate() {
            row.copy_from_slice(&out[12 + P * r..12 + P * (r + 1)]);
        }
        d
    }

    fn current(&self, theta: &[f64; P], x: &[f64; 3], u: f64) -> Current<f64, P> {
        let out = self.eval(theta, x, u);
        let base = 12 + 3 * P;
        let mut c = Current {
            i: out[base],
            i_x: [0.0; 3],
            i_theta: [0.0; P],
        };
        c.i_x.copy_from_slice(&out[base + 1..base + 4]);
        c.i_theta.copy_from_slice(&out[base + 4..base + 4 + P]);
        c
    }
}
