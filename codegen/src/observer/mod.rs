//! The model-based observers as emitted code: the extended and the unscented
//! Kalman filter on the discretised model of jiles-atherton-actuator-model
//! [JA §6.1] ([JA 84–87]), built by `designer::observe::discrete::DiscreteModel`.
//!
//! The filters themselves are the runtime's (`reldesign_runtime::observe`:
//! `Ekf`, `Ukf`, generic over the float and the model), written once; the
//! emitted code holds only what is the model's. [`emit_ekf`] and
//! [`emit_ukf`] return `macro_rules! model { ($f:ty) => { … } }`, the model
//! functions written once over the float type, and one `pub mod f64 { … }` /
//! `pub mod f32 { … }` per requested float type (the caller wraps them, e.g.
//! in `pub mod ekf { … }`, which [`wrap_module`] does, so that each filter's
//! `model!` is its own), each with:
//!
//! - `params!(f64)` and `kalman!(f64)`: the model's parameters and the
//!   filters' settings, written once per file ([`emit_observer_params`],
//!   [`emit_kalman_macro`]);
//! - `model!(f64)`: the model functions, written by the expression emitter as
//!   straight-line code with CSE'd `let`s and equation numbers in comments
//!   (unsuffixed literals that `$f` types, see `float::Scalar`): `transition`
//!   [JA 84–85] with the acceleration f_v of [JA 87] (the EKF's also returns the
//!   symbolic Jacobian ∂F/∂x and g = ∂F/∂u), `measurement` h and ∂h/∂u (and
//!   ∂h/∂x for the EKF), `acceleration`, `input_gain` g (UKF);
//! - the zero-sized `Model` implementing the runtime's model traits with
//!   them, and `Filter` (the runtime's filter on it: `Filter::new()`,
//!   `step(u, y) -> Estimate`, `state`, `covariance`, `skipped`, `repairs`).
//!
//! The designer's reference filters are the same runtime filters on tapes of
//! the same model. The emitted code is `no_std`, allocation-free, panic-free
//! (no indexing, no `unwrap`, no `as`) and deterministic.

mod layout;
mod settings;

use designer::description::Drive;
use designer::observe::discrete::DiscreteModel;
use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use crate::calibration::{theta_args, theta_symbols};
use crate::emit::doc_attrs;
use crate::emit::Theta;
use crate::error::EmitError;
use crate::float::{Float, Scalar, MACRO_LITERALS};
use crate::format::{comment_lets, format_items, macro_rules, space_items};
use crate::names::const_name;
use crate::param::Param;
use std::collections::HashMap;

use layout::{state_names, vector_tokens, Function, Layout};
pub use settings::{emit_kalman_macro, emit_observer_params};

/// Everything [`emit_ekf`] and [`emit_ukf`] need.
#[derive(Clone)]
pub struct ObserverInput<'a> {
    /// The description name (for docs).
    pub name: &'a str,
    /// The discretised model with its settings
    /// (`DiscreteModel::new(&model, &settings)`).
    pub discrete: &'a DiscreteModel,
    /// Emitted float types, in this order (duplicates dropped).
    pub floats: Vec<Float>,
    /// The self-calibration (`[controller] self_calibration`): the model
    /// reads the adapted parameters θ at run time, and the UKF module holds
    /// the update.
    pub calibration: Option<&'a designer::calibrate::CalibrationDesign>,
}

/// Why an observer could not be emitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ObserverError {
    #[error(transparent)]
    Emit(#[from] EmitError),
    #[error("no float type to emit")]
    NoFloat,
    #[error("the observer value `{name}` = {value:e} is not finite in {float}")]
    BadValue {
        name: String,
        value: f64,
        float: &'static str,
    },
    #[error("the parameter const `{0}` collides with a constant of the observer")]
    NameTaken(String),
}

/// The extended Kalman filter: formatted `macro_rules! model` and
/// `pub mod f64 { … }` / `pub mod f32 { … }` items.
pub fn emit_ekf(input: &ObserverInput) -> Result<String, ObserverError> {
    emit(input, Kind::Ekf)
}

/// The unscented Kalman filter: formatted `macro_rules! model` and
/// `pub mod f64 { … }` / `pub mod f32 { … }` items.
pub fn emit_ukf(input: &ObserverInput) -> Result<String, ObserverError> {
    emit(input, Kind::Ukf)
}

/// `items` (the text of [`emit_ekf`] or [`emit_ukf`]) as a module `name`
/// with a doc line: `/// doc` `pub mod name {` the items indented by four
/// spaces `}` (the emitted text has no multi-line literals, so indenting
/// every non-empty line keeps it valid and formatted).
pub fn wrap_module(name: &str, doc: &str, items: &str) -> String {
    let mut out = String::with_capacity(items.len() + items.len() / 8 + 64);
    for line in doc.lines() {
        out.push_str("/// ");
        out.push_str(line);
        out.push('\n');
    }
    out.push_str(&format!("pub mod {name} {{\n"));
    for line in items.lines() {
        if !line.is_empty() {
            out.push_str("    ");
            out.push_str(line);
        }
        out.push('\n');
    }
    out.push_str("}\n");
    out
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Ekf,
    Ukf,
}

fn emit(input: &ObserverInput, kind: Kind) -> Result<String, ObserverError> {
    let mut floats: Vec<Float> = Vec::new();
    for &f in &input.floats {
        if !floats.contains(&f) {
            floats.push(f);
        }
    }
    if floats.is_empty() {
        return Err(ObserverError::NoFloat);
    }
    for (name, _, _) in input.discrete.model_params.iter() {
        let c = const_name(name)?;
        if settings::KALMAN_CONSTS.contains(&c.as_str()) {
            return Err(ObserverError::NameTaken(c));
        }
    }
    let layout = Layout::new(input.discrete, kind);
    let f32 = floats.contains(&Float::F32);
    let theta = match input.calibration {
        Some(c) => theta_args(&input.discrete.params, c)?,
        None => Vec::new(),
    };
    let mut out = model_macro(input, &layout, Scalar::Macro { f32 }, &theta)?;
    for float in floats {
        out.push('\n');
        out.push_str(&float_module(input, &layout, kind, float, theta.len())?);
    }
    Ok(out)
}

/// Typed literal of `value` in `float`.
fn lit(float: Float, name: &str, value: f64) -> Result<TokenStream, ObserverError> {
    float
        .unsuffixed_signed(value)
        .ok_or_else(|| ObserverError::BadValue {
            name: name.to_owned(),
            value,
            float: float.name(),
        })
}

/// The model functions `layout` holds, in the order they are emitted.
fn functions(layout: &Layout) -> Vec<&Function> {
    let mut functions = vec![
        &layout.transition,
        &layout.measurement,
        &layout.acceleration,
    ];
    functions.extend(&layout.input_gain);
    functions
}

/// `macro_rules! model`: the model functions, written once over the float
/// type `$f` with their `//` equation comments.
fn model_macro(
    input: &ObserverInput,
    layout: &Layout,
    scalar: Scalar,
    theta: &Theta,
) -> Result<String, ObserverError> {
    let dm = input.discrete;
    let adapted = theta_symbols(theta);
    let params: Vec<Param> = (dm.param_list().into_iter())
        .filter(|p| !adapted.contains(&p.1))
        .map(Param::from)
        .collect();
    // the flux domain follows an adapted φ_sat, as the designer's tapes'
    let mut graph = dm.graph.clone();
    let follows: HashMap<_, _> = (dm.flux_limit_following(&mut graph, &adapted))
        .into_iter()
        .collect();
    let mut items = TokenStream::new();
    for f in functions(layout) {
        let f = f.substituted(&mut graph, &follows);
        items.extend(f.tokens(&graph, dm, &params, scalar, theta)?);
    }
    let mut text = space_items(&format_items(items)?);
    for f in functions(layout) {
        text = comment_lets(&text, f.name, &f.comments());
    }
    let doc = format!(
        "The model functions of `{}` over the float type `$f`, written once\n\
         and declared in each float module below as `model!(f64)` / `model!(f32)`.\n\
         {MACRO_LITERALS}",
        input.name
    );
    Ok(macro_rules("model", &doc, &text))
}

/// One `pub mod f64 { … }` / `pub mod f32 { … }`, formatted.
fn float_module(
    input: &ObserverInput,
    layout: &Layout,
    kind: Kind,
    float: Float,
    adapted: usize,
) -> Result<String, ObserverError> {
    let dm = input.discrete;
    let ty = float.ty();
    let module = format_ident!("{}", float.name());
    let items = model_impl(dm, layout, kind, float, adapted)?;
    let calibration = (adapted > 0).then(|| quote!(calibration!(#ty);));

    let state_doc = state_names(dm)
        .iter()
        .map(|s| s.doc)
        .collect::<Vec<_>>()
        .join(", ");
    let (what, filter) = match kind {
        Kind::Ekf => (
            "extended",
            "`reldesign_runtime::observe::Ekf` (update with the symbolic ∂h/∂x in\n\
             Joseph form, prediction with the symbolic ∂F/∂x)",
        ),
        Kind::Ukf => (
            "unscented",
            "`reldesign_runtime::observe::Ukf` (sigma points x̄ ± γ·(columns of chol P)\n\
             through h and F; failed factorisations are repaired and counted)",
        ),
    };
    let module_doc = doc_attrs(&format!(
        "The {what} Kalman filter of `{name}` in {float}, on the discretised model of\n\
         jiles-atherton-actuator-model [JA §6.1] [JA 84–87] with x = [{state_doc}]: the model functions\n\
         of `model!` in {filter}.\n\
         The model is evaluated at z in [z_min, z_max]; the posterior z, z_prev are projected onto it.",
        name = input.name,
        float = float.name(),
    ));
    let imports = match kind {
        Kind::Ekf => quote!(
            use reldesign_runtime::observe::{self, Linearisation, Prediction, Reading};
        ),
        Kind::Ukf => quote!(
            use reldesign_runtime::observe::{self, Prediction, Reading};
        ),
    };
    let tokens = quote! {
        #module_doc
        pub mod #module {
            #imports

            params!(#ty);
            #calibration
            kalman!(#ty);
            model!(#ty);

            #items
        }
    };
    Ok(space_items(&format_items(tokens)?))
}

/// The pieces every trait method of the emitted `Model` is written with.
struct Method {
    ty: Ident,
    dim: Literal,
    /// `&mut self, x: &[f32; 3], u: f32, t: f32` (`_t` when the model does
    /// not read t).
    args: TokenStream,
    /// `let [z, z_prev, phi] = *x;`
    states: TokenStream,
    /// The model function's arguments: `z, z_prev, phi, u(, t)`.
    call: TokenStream,
    /// `Prediction { … }` from the transition's outputs `o`.
    prediction: TokenStream,
    /// `Reading { … }` from the measurement's outputs `m`.
    reading: TokenStream,
}

impl Method {
    /// `adapted`: the model functions take θ (`&self.theta`).
    fn new(dm: &DiscreteModel, layout: &Layout, float: Float, adapted: bool) -> Method {
        let ty = float.ty();
        let dim = Literal::usize_unsuffixed(layout.n);
        let names: Vec<Ident> = state_names(dm)
            .iter()
            .map(|s| format_ident!("{}", s.name))
            .collect();
        let (t, t_arg) = if dm.uses_time {
            (format_ident!("t"), quote!(, t))
        } else {
            (format_ident!("_t"), quote!())
        };
        let next = state_names(dm).into_iter().map(|s| {
            let f = format_ident!("{}_next", s.short);
            quote!(o.#f)
        });
        let (y, dy_du) = (
            format_ident!("{}", layout.y),
            format_ident!("d{}_du", layout.y),
        );
        Method {
            args: quote!(&mut self, x: &[#ty; #dim], u: #ty, #t: #ty),
            states: quote!(let [#(#names),*] = *x;),
            call: if adapted {
                quote!(#(#names),*, u #t_arg, &self.theta)
            } else {
                quote!(#(#names),*, u #t_arg)
            },
            prediction: quote!(Prediction { next: [#(#next),*], accel: o.accel }),
            reading: quote!(Reading { y: m.#y, dy_du: m.#dy_du }),
            ty,
            dim,
        }
    }
}

/// The zero-sized `Model` implementing the runtime's traits with the model
/// functions, and the `Filter` and `Estimate` types.
fn model_impl(
    dm: &DiscreteModel,
    layout: &Layout,
    kind: Kind,
    float: Float,
    adapted: usize,
) -> Result<TokenStream, ObserverError> {
    let f = Method::new(dm, layout, float, adapted > 0);
    let (ty, dim) = (&f.ty, &f.dim);
    let (filter, model_trait, what) = match kind {
        Kind::Ekf => (
            quote!(observe::Ekf<Model, #ty, #dim>),
            linearised_impl(&f, layout, float)?,
            "extended",
        ),
        Kind::Ukf => {
            let points = Literal::usize_unsuffixed(2 * layout.n + 1);
            (
                quote!(observe::Ukf<Model, #ty, #dim, #points>),
                sampled_impl(&f, layout, float)?,
                "unscented",
            )
        }
    };
    let kind_doc = format!(" The {what} Kalman filter on [`Model`] (see the module docs).");
    let y_doc = if dm.drive == Drive::Voltage {
        " the measured coil voltage held over the last sample, y = i the coil current now."
    } else {
        " the measured coil current held over the last sample, y = u_coil the coil voltage now."
    };
    let step_doc = format!(" `Filter::step(u, y)`: u is{y_doc}");
    let Method {
        args, states, call, ..
    } = &f;
    let model = model_type(ty, dim, adapted);
    let update =
        (kind == Kind::Ukf && adapted > 0).then(|| update_items(ty, dim, layout.n, adapted));
    Ok(quote! {
        #model

        impl observe::DiscreteModel<#ty, #dim> for Model {
            #[inline] fn acceleration(#args) -> #ty {
                #states
                acceleration(#call).accel
            }
        }

        #model_trait

        #[doc = #kind_doc]
        #[doc = #step_doc]
        pub type Filter = #filter;

        /// What [`Filter`] reports at each sample.
        pub type Estimate = observe::Estimate<#ty>;

        #update
    })
}

/// `Model` and its `observe::Stateless`: zero-sized, or (a self-calibrating
/// design) carrying θ, θ_d its `const` default.
fn model_type(ty: &Ident, dim: &Literal, adapted: usize) -> TokenStream {
    if adapted == 0 {
        return quote! {
            /// The discretised model: the functions of `model!`, for the runtime's filter.
            #[derive(Clone, Copy, Debug, PartialEq)]
            pub struct Model;

            impl observe::Stateless<#ty, #dim> for Model {
                const MODEL: Self = Model;
                const SETTINGS: observe::Settings<#ty, #dim> = SETTINGS;
            }
        };
    }
    let p = Literal::usize_unsuffixed(adapted);
    quote! {
        /// The discretised model: the functions of `model!` at the adapted parameters
        /// θ, for the runtime's filter.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Model {
            /// θ: the adapted parameters, in the order of `ADAPTED`.
            pub theta: [#ty; #p],
        }

        impl observe::Stateless<#ty, #dim> for Model {
            const MODEL: Self = Model { theta: THETA_DESIGN };
            const SETTINGS: observe::Settings<#ty, #dim> = SETTINGS;
        }
    }
}

/// The self-calibration's update in the UKF module: `Model` at θ, the run's
/// `Record`, the carried `Calibration` and `calibrate`.
fn update_items(ty: &Ident, dim: &Literal, n: usize, adapted: usize) -> TokenStream {
    let p = Literal::usize_unsuffixed(adapted);
    let points = Literal::usize_unsuffixed(2 * n + 1);
    quote! {
        impl reldesign_runtime::calibrate::Adaptive<#ty, #dim, #p> for Model {
            #[inline]
            fn with_theta(&self, theta: &[#ty; #p]) -> Self {
                Model { theta: *theta }
            }
        }

        /// What the firmware keeps of a run for the self-calibration: every sample's
        /// measured voltage and current (`Record::start` at the run's start, `push`
        /// once per sample). RAM: 2·RECORD_CAPACITY floats.
        pub type Record = reldesign_runtime::calibrate::Record<#ty, RECORD_CAPACITY>;

        /// θ carried from run to run (`Calibration::new(&CALIBRATION)` at θ_d,
        /// `reset` back to it).
        pub type Calibration = reldesign_runtime::calibrate::Calibration<#ty, #p>;

        /// The self-calibration after a run (between operations, never inside one):
        /// θ updated from the run's `record` so that the filter's one-step current
        /// predictions are right (`reldesign_runtime::calibrate::innovations`: P + 1
        /// filter passes per Levenberg–Marquardt step, bounded steps, θ kept in
        /// [THETA_LOWER, THETA_UPPER], a record that does not look like a run refused).
        /// Then hand `calibration.theta` to the controller's `Design` and this `Model`.
        pub fn calibrate(
            calibration: &mut Calibration,
            record: &Record,
        ) -> reldesign_runtime::calibrate::Outcome<#ty> {
            calibration.update_innovations::<Model, #dim, #points, RECORD_CAPACITY>(
                &<Model as observe::Stateless<#ty, #dim>>::MODEL,
                &CALIBRATION,
                record,
            )
        }
    }
}

/// The EKF's model: F with ∂F/∂x and g, h with ∂h/∂x (constant entries as
/// literals).
fn linearised_impl(
    f: &Method,
    layout: &Layout,
    float: Float,
) -> Result<TokenStream, ObserverError> {
    let (o, m) = (format_ident!("o"), format_ident!("m"));
    let rows = layout
        .jacobian
        .iter()
        .map(|row| vector_tokens(row, &o, float))
        .collect::<Result<Vec<_>, _>>()?;
    let g = vector_tokens(&layout.gain, &o, float)?;
    let h = vector_tokens(&layout.h_row, &m, float)?;
    let Method {
        ty,
        dim,
        args,
        states,
        call,
        prediction,
        reading,
    } = f;
    Ok(quote! {
        impl observe::Linearised<#ty, #dim> for Model {
            #[inline] fn transition(#args) -> Linearisation<#ty, #dim> {
                #states
                let o = transition(#call);
                let prediction = #prediction;
                Linearisation { prediction, f_x: [#(#rows),*], g: #g }
            }

            #[inline] fn measurement(#args) -> (Reading<#ty>, [#ty; #dim]) {
                #states
                let m = measurement(#call);
                (#reading, #h)
            }
        }
    })
}

/// The UKF's model: F, h and g (a constant g without a function).
fn sampled_impl(f: &Method, layout: &Layout, float: Float) -> Result<TokenStream, ObserverError> {
    let g = vector_tokens(&layout.gain, &format_ident!("g"), float)?;
    let Method {
        ty,
        dim,
        args,
        states,
        call,
        prediction,
        reading,
    } = f;
    let input_gain = match &layout.input_gain {
        Some(_) => quote! {
            #[inline] fn input_gain(#args) -> [#ty; #dim] {
                #states
                let g = input_gain(#call);
                #g
            }
        },
        // every entry constant
        None => quote! {
            fn input_gain(&mut self, _: &[#ty; #dim], _: #ty, _: #ty) -> [#ty; #dim] {
                #g
            }
        },
    };
    Ok(quote! {
        impl observe::Sampled<#ty, #dim> for Model {
            #[inline] fn transition(#args) -> Prediction<#ty, #dim> {
                #states
                let o = transition(#call);
                #prediction
            }

            #[inline] fn measurement(#args) -> Reading<#ty> {
                #states
                let m = measurement(#call);
                #reading
            }

            #input_gain
        }
    })
}
