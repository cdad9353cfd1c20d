//! Which model functions an observer module holds and how the filter reads
//! them: the states' names, the functions' outputs (constant entries of a
//! Jacobian are not outputs), and the vectors and matrices the trait
//! implementation assembles from them.

use designer::description::Drive;
use designer::observe::discrete::{DiscreteModel, FluxStep, StateKind};
use designer::sym::{Graph, Id};
use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use std::collections::HashMap;

use crate::emit::{function_tokens_as, FunctionSpec, Inline, Theta};
use crate::error::EmitError;
use crate::float::{Float, Scalar};
use crate::param::Param;

use super::{lit, Kind, ObserverError};

/// How a state is named: the Rust name (function arguments), its short form
/// (in output names) and how it reads in docs.
pub(super) struct StateName {
    pub(super) name: &'static str,
    pub(super) short: &'static str,
    pub(super) doc: &'static str,
}

pub(super) fn state_name(kind: StateKind) -> StateName {
    let (name, short, doc) = match kind {
        StateKind::Position => ("z", "z", "z"),
        StateKind::PreviousPosition => ("z_prev", "zp", "z_prev"),
        StateKind::Flux => ("phi", "phi", "φ"),
        StateKind::CoreField => ("hc", "hc", "H_c"),
        StateKind::Resistance => ("r", "r", "R"),
    };
    StateName { name, short, doc }
}

/// The names of the discretised model's states, in order.
pub(super) fn state_names(dm: &DiscreteModel) -> Vec<StateName> {
    dm.kinds.iter().map(|&k| state_name(k)).collect()
}

/// One model function: its outputs (name, expression, doc).
pub(super) struct Function {
    pub(super) name: &'static str,
    pub(super) doc: String,
    pub(super) outputs: Vec<(String, Id, String)>,
}

impl Function {
    /// The output struct and the function, written in `scalar`.
    pub(super) fn tokens(
        &self,
        graph: &Graph,
        dm: &DiscreteModel,
        params: &[Param],
        scalar: Scalar,
        theta: &Theta,
    ) -> Result<TokenStream, EmitError> {
        let mut inputs: Vec<(&str, Id)> = state_names(dm)
            .iter()
            .zip(&dm.states)
            .map(|(n, &id)| (n.name, id))
            .collect();
        inputs.push(("u", dm.input));
        if dm.uses_time {
            inputs.push(("t", dm.time));
        }
        let spec = FunctionSpec {
            name: self.name,
            doc: &self.doc,
            inputs,
            outputs: self
                .outputs
                .iter()
                .map(|(n, id, d)| (n.as_str(), *id, d.as_str()))
                .collect(),
            named: vec![],
            output_symbols: vec![],
            // written in `scalar` (function_tokens_as)
            float: Float::F64,
        };
        function_tokens_as(graph, &spec, params, Inline::Hint, scalar, theta)
    }

    /// This function with `map` applied to its outputs (in `graph`, the one
    /// they live in or a clone of it).
    pub(super) fn substituted(&self, graph: &mut Graph, map: &HashMap<Id, Id>) -> Function {
        let outputs = self
            .outputs
            .iter()
            .map(|(n, id, d)| (n.clone(), graph.substitute(*id, map), d.clone()))
            .collect();
        Function {
            name: self.name,
            doc: self.doc.clone(),
            outputs,
        }
    }

    pub(super) fn comments(&self) -> Vec<(&str, &str)> {
        self.outputs
            .iter()
            .map(|(n, _, d)| (n.as_str(), d.as_str()))
            .collect()
    }
}

/// An entry of a vector or matrix the filter assembles from a function's
/// outputs: a constant (0, 1 of the structure) or the output's field.
#[derive(Clone)]
pub(super) enum Entry {
    Const(f64),
    Field(String),
}

/// Adds `id` as an output called `name` unless it is a constant.
pub(super) fn entry(
    g: &Graph,
    outputs: &mut Vec<(String, Id, String)>,
    name: String,
    id: Id,
    doc: String,
) -> Entry {
    match g.as_const(id) {
        Some(c) => Entry::Const(c),
        None => {
            outputs.push((name.clone(), id, doc));
            Entry::Field(name)
        }
    }
}

/// The model functions and how the filter reads them.
pub(super) struct Layout {
    pub(super) n: usize,
    /// Name of the measured quantity (`i`, or `u_coil` with current drive).
    pub(super) y: String,
    pub(super) transition: Function,
    pub(super) measurement: Function,
    /// f_v of [JA 87] alone, for the estimate at the posterior.
    pub(super) acceleration: Function,
    /// UKF: g = ∂F/∂u (none if every entry is constant).
    pub(super) input_gain: Option<Function>,
    /// ∂F/∂x (EKF), from `transition`.
    pub(super) jacobian: Vec<Vec<Entry>>,
    /// g (from `transition` for the EKF, from `input_gain` for the UKF).
    pub(super) gain: Vec<Entry>,
    /// ∂h/∂x (EKF), from `measurement`.
    pub(super) h_row: Vec<Entry>,
}

/// `[JA 84a]`… : the doc of F's output for a state.
fn next_doc(k: StateKind, step: FluxStep) -> &'static str {
    match (k, step) {
        (StateKind::Flux, FluxStep::Exponential { .. }) => "φ_{k+1}: exponential Euler on the coil's total rate dφ̇/dφ at the mid-step position (flux_step = \"exponential\"; [JA 84c] is its Euler form)",
        (StateKind::CoreField, FluxStep::Exponential { .. }) => "H_c,{k+1}: the exponential step's share of T_s·f_Hc ([JA 84d] is its Euler form)",
        _ => euler_doc(k),
    }
}

/// The paper's doc of F's output for a state.
fn euler_doc(k: StateKind) -> &'static str {
    match k {
        StateKind::Position => "[JA 84a] z_{k+1} = sat_{z_min}^{z_max}(2·z − z_prev + T_s²·f_v(z, v, φ)), v = (z − z_prev)/T_s [JA 85]",
        StateKind::PreviousPosition => "[JA 84b] z_prev,{k+1} = sat_{z_min}^{z_max}(z)",
        StateKind::Flux => "[JA 84c] φ_{k+1} = φ + T_s·f_φ(z, φ, H_c, u)",
        StateKind::CoreField => "[JA 84d] H_c,{k+1} = H_c + T_s·f_Hc(z, φ, H_c, u)",
        StateKind::Resistance => "R_{k+1} = R (random walk)",
    }
}

const ACCEL_DOC: &str = "[JA 87] a = f_v(z, v, φ), the free-motion acceleration at v of [JA 85]";

/// `transition` (with ∂F/∂x and g for the EKF), the entries of ∂F/∂x (EKF)
/// and of g, and the UKF's `input_gain` (none when g is constant).
fn transition(
    dm: &DiscreteModel,
    kind: Kind,
) -> (Function, Vec<Vec<Entry>>, Vec<Entry>, Option<Function>) {
    let g = &dm.graph;
    let names = state_names(dm);
    let mut outputs: Vec<(String, Id, String)> = names
        .iter()
        .zip(&dm.transition)
        .zip(&dm.kinds)
        .map(|((s, &id), &k)| {
            (
                format!("{}_next", s.short),
                id,
                next_doc(k, dm.settings.flux_step).to_owned(),
            )
        })
        .collect();
    outputs.push(("accel".to_owned(), dm.acceleration, ACCEL_DOC.to_owned()));
    let mut jacobian = Vec::new();
    if kind == Kind::Ekf {
        for (si, row_ids) in names.iter().zip(&dm.transition_jacobian) {
            let row = names
                .iter()
                .zip(row_ids)
                .map(|(sj, &id)| {
                    let name = format!("d{}_d{}", si.short, sj.short);
                    let doc = format!("∂{}_{{k+1}}/∂{}", si.doc, sj.doc);
                    entry(g, &mut outputs, name, id, doc)
                })
                .collect();
            jacobian.push(row);
        }
    }
    // g: outputs of `transition` (EKF) or of `input_gain` (UKF)
    let mut gain_outputs = Vec::new();
    let target = match kind {
        Kind::Ekf => &mut outputs,
        Kind::Ukf => &mut gain_outputs,
    };
    let gain = names
        .iter()
        .zip(&dm.input_gain)
        .map(|(s, &id)| {
            let doc = format!("g = ∂{}_{{k+1}}/∂u (maps the input's noise into Q)", s.doc);
            entry(g, target, format!("d{}_du", s.short), id, doc)
        })
        .collect();
    let input_gain = (kind == Kind::Ukf && !gain_outputs.is_empty()).then(|| Function {
        name: "input_gain",
        doc: "g = ∂F/∂u of the transition [JA 84]: the input's noise σ_u enters the process\n\
              noise as σ_u²·g·gᵀ. Entries not listed are constant."
            .to_owned(),
        outputs: gain_outputs,
    });
    let doc = match kind {
        Kind::Ekf => {
            "The discretised model [JA 84–85] at x = [z, z_prev, φ(, H_c)] with the input u held\n\
             over the sample, the acceleration f_v of [JA 87], and the symbolic Jacobians\n\
             ∂F/∂x and g = ∂F/∂u (entries not listed are constant)."
        }
        Kind::Ukf => {
            "The discretised model [JA 84–85] at x = [z, z_prev, φ(, H_c)] with the input u held\n\
             over the sample, and the acceleration f_v of [JA 87]."
        }
    };
    let function = Function {
        name: "transition",
        doc: doc.to_owned(),
        outputs,
    };
    (function, jacobian, gain, input_gain)
}

/// `measurement` (y, ∂y/∂u, and ∂y/∂x for the EKF) and the entries of ∂h/∂x.
fn measurement(dm: &DiscreteModel, kind: Kind, y: &str) -> (Function, Vec<Entry>) {
    let y_doc = if dm.drive == Drive::Voltage {
        "i = (N·(R_gap(z)·φ + MMF_core) + k_e·u)/(N² + R·k_e), the coil current [JA 41]"
    } else {
        "u_coil = R·u + N·f_φ, the coil voltage [JA 1]"
    };
    let mut outputs = vec![
        (y.to_owned(), dm.measurement, y_doc.to_owned()),
        (
            format!("d{y}_du"),
            dm.measurement_input_gain,
            format!("∂{y}/∂u (the input's noise in the measurement variance)"),
        ),
    ];
    let mut h_row = Vec::new();
    if kind == Kind::Ekf {
        for (s, &id) in state_names(dm).iter().zip(&dm.measurement_jacobian) {
            let (name, doc) = (format!("d{y}_d{}", s.short), format!("H = ∂{y}/∂{}", s.doc));
            h_row.push(entry(&dm.graph, &mut outputs, name, id, doc));
        }
    }
    let doc = match kind {
        Kind::Ekf => {
            "The measured quantity y = h(x, u) on the model's domain and its derivatives\n\
             (entries of ∂h/∂x not listed are constant)."
        }
        Kind::Ukf => "The measured quantity y = h(x, u) on the model's domain and ∂h/∂u.",
    };
    let function = Function {
        name: "measurement",
        doc: doc.to_owned(),
        outputs,
    };
    (function, h_row)
}

impl Layout {
    pub(super) fn new(dm: &DiscreteModel, kind: Kind) -> Layout {
        let y = if dm.drive == Drive::Voltage {
            "i"
        } else {
            "u_coil"
        }
        .to_owned();
        let (transition, jacobian, gain, input_gain) = transition(dm, kind);
        let (measurement, h_row) = measurement(dm, kind, &y);
        let acceleration = Function {
            name: "acceleration",
            doc: "The acceleration f_v of [JA 87] at x = [z, z_prev, φ(, H_c)] (v of [JA 85]):\n\
                  the estimate's a, at the posterior."
                .to_owned(),
            outputs: vec![("accel".to_owned(), dm.acceleration, ACCEL_DOC.to_owned())],
        };
        Layout {
            n: dm.dim(),
            y,
            transition,
            measurement,
            acceleration,
            input_gain,
            jacobian,
            gain,
            h_row,
        }
    }
}

/// Tokens of an assembled entry (`out` is the struct holding the fields).
pub(super) fn entry_tokens(
    e: &Entry,
    out: &Ident,
    float: Float,
) -> Result<TokenStream, ObserverError> {
    Ok(match e {
        Entry::Const(c) => lit(float, "a constant entry", *c)?,
        Entry::Field(f) => {
            let f = format_ident!("{f}");
            quote!(#out.#f)
        }
    })
}

pub(super) fn vector_tokens(
    es: &[Entry],
    out: &Ident,
    float: Float,
) -> Result<TokenStream, ObserverError> {
    let items = es
        .iter()
        .map(|e| entry_tokens(e, out, float))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(quote!([#(#items),*]))
}
