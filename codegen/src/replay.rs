//! The replay self-calibration as emitted Rust, for a design whose law reads
//! measured states (`[controller] self_calibration` without an `estimator`):
//! `macro_rules! predictor`, the model the runtime's
//! `reldesign_runtime::calibrate::calibrate` replays, with its symbolic
//! Jacobians as straight-line code (`designer::calibrate::PredictorExpressions`,
//! which the designer's `TapePredictor` evaluates on tapes):
//!
//! - `flow_terms`: f(x, u; θ), ∂f/∂x and ∂f/∂θ of the free motion;
//! - `current_terms`: i(x, u; θ), ∂i/∂x and ∂i/∂θ;
//! - `Model`, the runtime's `calibrate::Predictor` over them; `Record` (one
//!   operation's decimated samples), `Calibration` and `calibrate`.
//!
//! Declared in each controller float module as `predictor!(f64)` /
//! `predictor!(f32)` after `params!` and `calibration!`. The update itself
//! is the runtime's, written once.

use std::collections::HashMap;

use designer::calibrate::PredictorExpressions;
use designer::model::Model;
use designer::sym::Id;
use quote::quote;

use crate::calibration::theta_symbols;
use crate::emit::{function_tokens_as, FunctionSpec, Inline, Theta};
use crate::error::EmitError;
use crate::float::{Float, Scalar, MACRO_LITERALS};
use crate::format::{comment_lets, format_items, macro_rules, space_items};
use crate::param::Param;
use crate::physical::{in_scope, of_model};

/// The state's names in the Jacobians' field names.
const STATES: [&str; 3] = ["z", "v", "phi"];

/// `macro_rules! predictor` of `model` with the adapted parameters `theta`,
/// its literals typed for `f32` too if asked.
pub fn predictor_macro_text(model: &Model, theta: &Theta, f32: bool) -> Result<String, EmitError> {
    if model.states.len() != 3 {
        return Err(EmitError::Unsupported(
            "the replay calibration's model has three states (no Jiles–Atherton core)".to_owned(),
        ));
    }
    let adapted = theta_symbols(theta);
    // the designer's expressions, which its tapes evaluate
    let mut derived = model.clone();
    let e = PredictorExpressions::derive(&mut derived, &adapted);
    let mut graph = derived.graph;
    let physical = in_scope(&mut graph, &of_model(model));
    let mut params: Vec<Param> = (model.params.iter())
        .filter(|p| !adapted.contains(&p.1))
        .map(Param::from)
        .collect();
    params.extend_from_slice(&physical);
    // the replay's model is autonomous in t (the tapes' t = 0)
    let zero = graph.constant(0.0);
    let bindings: HashMap<Id, Id> = std::iter::once((model.time, zero)).collect();
    let mut at_rest_in_time = |exprs: &[Id]| graph.substitute_all(exprs, &bindings);
    let f = at_rest_in_time(&e.f);
    let f_x: Vec<Vec<Id>> = e.f_x.iter().map(|row| at_rest_in_time(row)).collect();
    let f_theta: Vec<Vec<Id>> = e.f_theta.iter().map(|row| at_rest_in_time(row)).collect();
    let current = at_rest_in_time(&[e.current]);
    let i_x = at_rest_in_time(&e.i_x);
    let i_theta = at_rest_in_time(&e.i_theta);
    let x = &model.states;
    let scalar = Scalar::Macro { f32 };
    let mut inputs: Vec<(&str, Id)> = STATES.iter().copied().zip(x.iter().copied()).collect();
    inputs.push(("u", model.input));

    // field names: f_z, f_z_z (∂f_z/∂z), f_z_r (∂f_z/∂θ_r), i, i_z, i_r
    let theta_names: Vec<&str> = theta.iter().map(|t| t.0.as_str()).collect();
    let mut flow_names = Vec::new();
    for (r, row) in STATES.iter().enumerate() {
        flow_names.push((
            format!("f_{row}"),
            f[r],
            format!("ẋ_{row} = f_{row}(x, u; θ)"),
        ));
        for (c, col) in STATES.iter().enumerate() {
            flow_names.push((
                format!("f_{row}_{col}"),
                f_x[r][c],
                format!("∂f_{row}/∂{col}"),
            ));
        }
        for (c, col) in theta_names.iter().enumerate() {
            flow_names.push((
                format!("f_{row}_{col}"),
                f_theta[r][c],
                format!("∂f_{row}/∂{col}"),
            ));
        }
    }
    let mut current_names = vec![("i".to_owned(), current[0], "i(x, u; θ)".to_owned())];
    for (c, col) in STATES.iter().enumerate() {
        current_names.push((format!("i_{col}"), i_x[c], format!("∂i/∂{col}")));
    }
    for (c, col) in theta_names.iter().enumerate() {
        current_names.push((format!("i_{col}"), i_theta[c], format!("∂i/∂{col}")));
    }
    let function = |name: &str, doc: &str, outputs: &[(String, Id, String)]| {
        let spec = FunctionSpec {
            name,
            doc,
            inputs: inputs.clone(),
            outputs: outputs
                .iter()
                .map(|(n, e, d)| (n.as_str(), *e, d.as_str()))
                .collect(),
            named: model.named.clone(),
            output_symbols: Vec::new(),
            // written in `scalar` (function_tokens_as)
            float: Float::F64,
        };
        function_tokens_as(&graph, &spec, &params, Inline::Always, scalar, theta)
    };
    let flow = function(
        "flow_terms",
        "f(x, u; θ) of the free motion at x = [z, v, φ] and its Jacobians ∂f/∂x,\n∂f/∂θ (the model the replay integrates, with its sensitivities).",
        &flow_names,
    )?;
    let current_fn = function(
        "current_terms",
        "The coil current i(x, u; θ) at x = [z, v, φ] and its gradients ∂i/∂x, ∂i/∂θ.",
        &current_names,
    )?;
    let items = predictor_items(&flow_names, &current_names, theta.len());
    let tokens = quote! {
        #flow
        #current_fn
        #items
    };
    let mut text = space_items(&format_items(tokens)?);
    for (name, outputs) in [
        ("flow_terms", &flow_names),
        ("current_terms", &current_names),
    ] {
        let comments: Vec<(&str, &str)> = (outputs.iter())
            .map(|(n, _, d)| (n.as_str(), d.as_str()))
            .collect();
        text = comment_lets(&text, name, &comments);
    }
    let doc = format!(
        "The replay self-calibration of `{}` over the float type `$f`, written once:\n\
         `flow_terms`, `current_terms`, the runtime's `calibrate::Predictor` over them\n\
         (`Model`), `Record`, `Calibration` and `calibrate`, declared in each controller\n\
         float module as `predictor!(f64)` / `predictor!(f32)` after `calibration!`.\n{MACRO_LITERALS}",
        model.description.name
    );
    Ok(macro_rules("predictor", &doc, &text))
}

/// `Model` (the runtime's `Predictor` over `flow_terms` and `current_terms`),
/// `Record`, `Calibration`, `calibrate`.
fn predictor_items(
    flow: &[(String, Id, String)],
    current: &[(String, Id, String)],
    p: usize,
) -> proc_macro2::TokenStream {
    let ty = crate::names::ident(crate::float::MACRO_FLOAT);
    let field = |n: &str| crate::names::ident(n);
    let n = p + 4;
    // flow: per state row, f, then 3 ∂/∂x, then P ∂/∂θ
    let rows: Vec<&[(String, Id, String)]> = flow.chunks(n).collect();
    let dx = rows.iter().map(|r| field(&r[0].0));
    let f_x = rows.iter().map(|r| {
        let cols = r[1..4].iter().map(|c| field(&c.0));
        quote!([#(f.#cols),*])
    });
    let f_theta = rows.iter().map(|r| {
        let cols = r[4..].iter().map(|c| field(&c.0));
        quote!([#(f.#cols),*])
    });
    let i = field(&current[0].0);
    let i_x = current[1..4].iter().map(|c| field(&c.0));
    let i_theta = current[4..].iter().map(|c| field(&c.0));
    let p = proc_macro2::Literal::usize_unsuffixed(p);
    quote! {
        /// The model the replay integrates (`reldesign_runtime::calibrate::Predictor`).
        #[derive(Clone, Copy, Debug, Default, PartialEq)]
        pub struct Model;

        impl reldesign_runtime::calibrate::Predictor<#ty, #p> for Model {
            #[inline]
            fn derivative(
                &self,
                theta: &[#ty; #p],
                [z, v, phi]: &[#ty; 3],
                u: #ty,
            ) -> reldesign_runtime::calibrate::Derivative<#ty, #p> {
                let f = flow_terms(*z, *v, *phi, u, theta);
                reldesign_runtime::calibrate::Derivative {
                    dx: [#(f.#dx),*],
                    f_x: [#(#f_x),*],
                    f_theta: [#(#f_theta),*],
                }
            }

            #[inline]
            fn current(
                &self,
                theta: &[#ty; #p],
                [z, v, phi]: &[#ty; 3],
                u: #ty,
            ) -> reldesign_runtime::calibrate::Current<#ty, #p> {
                let c = current_terms(*z, *v, *phi, u, theta);
                reldesign_runtime::calibrate::Current {
                    i: c.#i,
                    i_x: [#(c.#i_x),*],
                    i_theta: [#(c.#i_theta),*],
                }
            }
        }

        /// What the firmware keeps of one operation for the self-calibration: every
        /// `CALIBRATION.decimation`-th sample's commanded and measured voltage and
        /// current (`Record::start(z)` at the operation's start with the stop it rests
        /// on, `push` once per sample). RAM: 2·RECORD_CAPACITY floats.
        pub type Record = reldesign_runtime::calibrate::Record<#ty, RECORD_CAPACITY>;

        /// θ carried from operation to operation (`Calibration::new(&CALIBRATION)`
        /// at θ_d, `reset` back to it).
        pub type Calibration = reldesign_runtime::calibrate::Calibration<#ty, #p>;

        /// The self-calibration after an operation (between operations, never inside
        /// one): θ updated from the operation's `record` so that the model, replayed
        /// over the measured voltage, predicts the measured current
        /// (`reldesign_runtime::calibrate::calibrate`: the sensitivities integrated
        /// beside the state, bounded Levenberg–Marquardt steps, θ kept in
        /// [THETA_LOWER, THETA_UPPER], a record that does not look like an operation
        /// refused). Then hand `calibration.theta` to the controller's `Design`.
        pub fn calibrate(
            calibration: &mut Calibration,
            record: &Record,
        ) -> reldesign_runtime::calibrate::Outcome<#ty> {
            calibration.update(&Model, &CALIBRATION, record)
        }
    }
}
