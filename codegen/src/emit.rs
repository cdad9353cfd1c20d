//! The public emitters: a parameter block and a function over named outputs.

use std::collections::{HashMap, HashSet};

use designer::description::schema;
use designer::model::Model;
use designer::sym::{Graph, Id};
use proc_macro2::TokenStream;
use quote::quote;

use crate::error::EmitError;
use crate::float::{Float, Scalar};
use crate::fold::{fold, Folded};
use crate::format::{comment_lets, format_items};
use crate::lower::Lowerer;
use crate::names::{camel, const_name, ident, Namer};
use crate::param::Param;
use crate::physical::{self, Constant, MU0_CONST, Z_EPS_CONST};
use crate::plan::{plan, PlanRequest};

/// What to emit as one function.
#[derive(Debug, Clone)]
pub struct FunctionSpec<'a> {
    /// Function name (lower snake case); the output struct is its UpperCamel
    /// form + `Output`.
    pub name: &'a str,
    /// Doc comment of the function (may span lines).
    pub doc: &'a str,
    /// (Rust argument name, symbol), in signature order.
    pub inputs: Vec<(&'a str, Id)>,
    /// (field name, expression, doc such as "(32) α(x)"), in field order.
    pub outputs: Vec<(&'a str, Id, &'a str)>,
    /// Subexpressions the caller names: each reachable one becomes
    /// `let name = …;` and is referenced by that name.
    pub named: Vec<(&'a str, Id)>,
    /// (output name, symbol): the symbol stands for that output's value in
    /// the outputs listed after it, so a later output can be written in
    /// terms of an earlier one (u = β·(w − L_f³h) rather than β's and w's
    /// expressions multiplied out). The output then gets a `let` of its own.
    pub output_symbols: Vec<(&'a str, Id)>,
    /// The scalar type (the crate's own emitters write the functions of
    /// their float-generic macros over the macro's `$f` instead).
    pub float: Float,
}

/// `pub const NAME: f64 = value;` per parameter, in the given order, each
/// value in shortest round-trip form (one parameter change = one changed
/// line). A parameter whose const name differs from its symbol gets the
/// symbol as a doc line (`/// \`k_e\``).
pub fn emit_params(graph: &Graph, params: &[Param], float: Float) -> Result<String, EmitError> {
    format_items(params_tokens(graph, params, float)?)
}

/// Tokens of [`emit_params`] (to assemble larger files).
pub fn params_tokens(
    graph: &Graph,
    params: &[Param],
    float: Float,
) -> Result<TokenStream, EmitError> {
    const_names(graph, params)?;
    let ty = float.ty();
    let mut items = TokenStream::new();
    for &Param { name, value, .. } in params {
        let cname = ident(&const_name(name)?);
        let lit = float
            .unsuffixed_signed(value)
            .ok_or_else(|| EmitError::NonFinite {
                name: name.to_owned(),
                value: format!("{value:?}"),
                float: float.name(),
            })?;
        if cname != name {
            let doc = format!(" `{name}`");
            items.extend(quote!(#[doc = #doc]));
        }
        items.extend(quote!(pub const #cname: #ty = #lit;));
    }
    Ok(items)
}

/// `macro_rules! params`: the file's one declaration of `model`'s
/// parameters, the stroke limits `Z_MIN`, `Z_MAX` [m] and the physical
/// constants its equations use (`MU0`, `Z_EPS`), one `pub const NAME: $f =
/// value;` line each (shortest round-trip f64 text: in an `f32` module the
/// literal rounds to the nearest `f32`). Every float module that needs them
/// invokes `params!(f64)` / `params!(f32)`, so one parameter change is one
/// changed line of the file.
pub fn params_macro(model: &Model) -> Result<String, EmitError> {
    let d = &model.description;
    let m = &d.mechanics;
    let mut lines: Vec<(&str, String, Option<&str>)> = Vec::new();
    let given = model.params.iter().map(|(name, _, value)| (name, value));
    for (name, value) in given.chain([("z_min", m.z_min), ("z_max", m.z_max)]) {
        lines.push((name, macro_literal(name, value)?, None));
    }
    for c in physical::of_model(model) {
        lines.push((c.symbol, c.definition.to_owned(), Some(c.doc)));
    }
    let mut seen: Vec<String> = Vec::new();
    let mut body = String::new();
    for (name, value, doc) in lines {
        let cname = const_name(name)?;
        if seen.contains(&cname) {
            return Err(EmitError::DuplicateName(cname));
        }
        match doc.map(str::to_owned).or_else(|| schema_doc(name)) {
            Some(doc) => body.push_str(&format!("        /// {doc}\n")),
            None if cname != name => body.push_str(&format!("        /// `{name}`\n")),
            None => {}
        }
        body.push_str(&format!("        pub const {cname}: $f = {value};\n"));
        seen.push(cname);
    }
    Ok(format!(
        "/// The model parameters of `{}` (SI units), one per line, declared in\n\
         /// each float module as `params!(f64)` / `params!(f32)`.\n\
         macro_rules! params {{\n    ($f:ident) => {{\n{body}    }};\n}}\n",
        d.name
    ))
}

/// The f64 text of `value` (named `name` in the error) for a macro over
/// `$f`, which an f32 module reads rounded to the nearest f32: the
/// `params!` and `calibration!` macros' literals.
pub(crate) fn macro_literal(name: &str, value: f64) -> Result<String, EmitError> {
    Float::F64
        .literal_text(value)
        .ok_or_else(|| EmitError::NonFinite {
            name: name.to_owned(),
            value: format!("{value:?}"),
            float: "f64",
        })
}

/// The doc of a parameter const from the description schema: its TOML
/// key, symbol, unit and meaning (`coil.resistance: R [Ω], coil resistance`).
fn schema_doc(symbol: &str) -> Option<String> {
    let key = schema::by_symbol(symbol)?;
    let unit = match key.unit {
        "-" | "" => String::new(),
        u => format!(" [{u}]"),
    };
    Some(format!("`{}`: `{symbol}`{unit}, {}", key.path, key.meaning))
}

/// parameter symbol → const name; checks symbols and uniqueness.
fn const_names(graph: &Graph, params: &[Param]) -> Result<HashMap<Id, String>, EmitError> {
    let mut by_id = HashMap::new();
    let mut seen: Vec<String> = Vec::new();
    for &Param {
        name, symbol: id, ..
    } in params
    {
        if graph.name_of(id).is_none() {
            return Err(EmitError::NotASymbol(name.to_owned()));
        }
        let c = const_name(name)?;
        if seen.contains(&c) {
            return Err(EmitError::DuplicateName(c));
        }
        seen.push(c.clone());
        by_id.insert(id, c);
    }
    Ok(by_id)
}

/// The formatted function (preceded by its output struct): parameters are
/// referenced as the consts of [`emit_params`] (which must be in scope),
/// math goes through `reldesign_runtime::math::Real`, shared subexpressions
/// become `let`s in the deterministic CSE order, and every output's `let`
/// carries its doc as a `//` comment.
pub fn emit_function(
    graph: &Graph,
    spec: &FunctionSpec,
    params: &[Param],
) -> Result<String, EmitError> {
    let tokens = function_tokens(graph, spec, params)?;
    let text = format_items(tokens)?;
    let comments: Vec<(&str, &str)> = spec.outputs.iter().map(|&(n, _, d)| (n, d)).collect();
    Ok(comment_lets(&text, spec.name, &comments))
}

/// Tokens of [`emit_function`], without the `//` comments (which are not tokens).
pub fn function_tokens(
    graph: &Graph,
    spec: &FunctionSpec,
    params: &[Param],
) -> Result<TokenStream, EmitError> {
    function_tokens_as(
        graph,
        spec,
        params,
        Inline::Hint,
        Scalar::One(spec.float),
        &[],
    )
}

/// The adapted parameters θ of a self-calibrating design as a function
/// reads them: one `theta: &[f; P]` argument, destructured into locals
/// (`let [r, k_e, …] = *theta;`, `_` where unused), one (local name,
/// symbol) each in θ's order. Their symbols are not among the function's
/// `params`: nothing is folded from them.
pub(crate) type Theta = [(String, Id)];

/// How an emitted function is offered to the inliner.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(crate) enum Inline {
    /// `#[inline]`: callers in other crates may inline it.
    Hint,
    /// `#[inline(always)]`: for a function whose callers (several, in the
    /// same module) each want it inlined, where a plain hint would let the
    /// compiler keep one out-of-line copy and pay a call and a store of every
    /// output.
    Always,
}

/// [`function_tokens`] with the given inlining attribute, in `scalar` (which
/// takes the place of `spec.float`: a macro's `$f` for a function written
/// once for every float type): parameter-only calls folded (`fold.rs`), then
/// the plan (`plan.rs`), the lowering (`lower.rs`, physical constants by
/// name) and the function's tokens.
pub(crate) fn function_tokens_as(
    graph: &Graph,
    spec: &FunctionSpec,
    params: &[Param],
    inline: Inline,
    scalar: Scalar,
    theta: &Theta,
) -> Result<TokenStream, EmitError> {
    crate::names::check_local(spec.name)?;
    let roots: Vec<Id> = spec
        .outputs
        .iter()
        .map(|o| o.1)
        .chain(spec.named.iter().map(|n| n.1))
        .collect();
    let mut all_params = params.to_vec();
    let folded = fold(graph, &all_params, &roots)?;
    let (graph, roots) = match &folded {
        Some(f) => {
            all_params.extend(f.derived.iter().map(|d| Param {
                name: d.name.as_str(),
                symbol: d.symbol,
                value: d.value,
            }));
            (&f.graph, f.roots.clone())
        }
        None => (graph, roots),
    };
    let const_by_id = const_names(graph, &all_params)?;
    let request = Request::new(spec, &roots, &const_by_id, theta);
    let plan = plan(graph, &request.plan(), &mut request.namer()?)?;

    let param_ids: HashSet<Id> = const_by_id.keys().copied().collect();
    let mut lower = Lowerer {
        graph,
        bound: &plan.bound,
        float: scalar,
        uses_real: false,
        excessive: false,
        params: &param_ids,
        statics: HashMap::new(),
        defined: HashSet::new(),
        available: [&MU0_CONST, &Z_EPS_CONST]
            .into_iter()
            .filter(|c| physical::available(c, params))
            .collect(),
        named: Vec::new(),
    };
    let mut lets = theta_prologue(spec.inputs.len(), theta, &plan.input_used);
    for b in &plan.lets {
        let name = ident(&b.name);
        let rhs = lower.definition(b.id)?;
        lower.defined.insert(b.id);
        lets.extend(quote!(let #name = #rhs;));
    }
    for (name, id) in &request.outputs {
        if plan.bound.get(id) == Some(name) {
            continue; // bound above under the output's own name
        }
        let rhs = lower.operand(*id)?;
        let name = ident(name);
        lets.extend(quote!(let #name = #rhs;));
    }
    let local: Vec<&Constant> = lower
        .named
        .iter()
        .copied()
        .filter(|c| !physical::provided(c, params))
        .collect();
    let mut body = if lower.uses_real {
        quote!(
            use reldesign_runtime::math::Real;
        )
    } else {
        quote!()
    };
    let (consts, excessive) = local_consts(&local, folded.as_ref(), scalar)?;
    body.extend(consts);
    body.extend(lets);
    let excessive = excessive || lower.excessive;
    let attrs = Attributes {
        inline,
        scalar,
        excessive,
    };
    Ok(assemble(spec, &request, &plan.input_used, body, attrs))
}

/// `let [r, _, k_s] = *theta;`: the adapted parameters the function reads
/// (`input_used` past the `plain` inputs), nothing where it reads none.
fn theta_prologue(plain: usize, theta: &Theta, input_used: &[bool]) -> TokenStream {
    let used = input_used.iter().skip(plain);
    if !used.clone().any(|&u| u) {
        return TokenStream::new();
    }
    let names = theta.iter().zip(used).map(|((n, _), &u)| {
        if u {
            let n = ident(n);
            quote!(#n)
        } else {
            quote!(_)
        }
    });
    quote!(let [#(#names),*] = *theta;)
}

/// The names of one function's plan: inputs, outputs (as mapped by the
/// rewrites), caller-named subexpressions and output symbols.
struct Request<'a> {
    spec: &'a FunctionSpec<'a>,
    const_by_id: &'a HashMap<Id, String>,
    inputs: Vec<(String, Id)>,
    outputs: Vec<(String, Id)>,
    named: Vec<(String, Id)>,
    output_symbols: Vec<(String, Id)>,
}

impl<'a> Request<'a> {
    /// `roots`: the images of the outputs, then of the named subexpressions.
    fn new(
        spec: &'a FunctionSpec,
        roots: &[Id],
        const_by_id: &'a HashMap<Id, String>,
        theta: &Theta,
    ) -> Self {
        let (output_roots, named_roots) = roots.split_at(spec.outputs.len());
        let theta = theta.iter().map(|(n, id)| (n.as_str(), *id));
        Request {
            spec,
            const_by_id,
            inputs: owned(spec.inputs.iter().copied().chain(theta)),
            outputs: owned(
                spec.outputs
                    .iter()
                    .zip(output_roots)
                    .map(|(o, &id)| (o.0, id)),
            ),
            named: owned(spec.named.iter().zip(named_roots).map(|(n, &id)| (n.0, id))),
            output_symbols: owned(spec.output_symbols.iter().copied()),
        }
    }

    fn plan(&self) -> PlanRequest<'_> {
        PlanRequest {
            inputs: &self.inputs,
            params: self.const_by_id,
            outputs: &self.outputs,
            named: &self.named,
            output_symbols: &self.output_symbols,
        }
    }

    /// A namer with every caller-given name reserved.
    fn namer(&self) -> Result<Namer, EmitError> {
        let mut namer = Namer::default();
        let given = (self.inputs.iter().map(|i| i.0.as_str()))
            .chain(self.spec.outputs.iter().map(|o| o.0))
            .chain(self.spec.named.iter().map(|n| n.0));
        for name in given {
            namer.reserve(name)?;
        }
        Ok(namer)
    }
}

fn owned<'s>(names: impl Iterator<Item = (&'s str, Id)>) -> Vec<(String, Id)> {
    names.map(|(n, id)| (n.to_owned(), id)).collect()
}

/// How the function is written besides its body.
struct Attributes {
    inline: Inline,
    scalar: Scalar,
    /// A literal or const has more digits than f32 holds: the f32
    /// instantiation of a macro reads it rounded (`Scalar::excessive`).
    excessive: bool,
}

/// The output struct and the function around `body`.
fn assemble(
    spec: &FunctionSpec,
    request: &Request,
    input_used: &[bool],
    body: TokenStream,
    attrs: Attributes,
) -> TokenStream {
    let ty = attrs.scalar.ty();
    let out_ty = ident(&format!("{}Output", camel(spec.name)));
    let fn_name = ident(spec.name);
    let plain = spec.inputs.len();
    let mut args: Vec<TokenStream> = request
        .inputs
        .iter()
        .zip(input_used)
        .take(plain)
        .map(|((n, _), &used)| {
            let n = if used {
                ident(n)
            } else {
                ident(&format!("_{n}"))
            };
            quote!(#n: #ty)
        })
        .collect();
    let adapted = request.inputs.len() - plain;
    if adapted > 0 {
        let used = input_used.iter().skip(plain).any(|&u| u);
        let name = ident(if used { "theta" } else { "_theta" });
        let p = proc_macro2::Literal::usize_unsuffixed(adapted);
        args.push(quote!(#name: &[#ty; #p]));
    }
    let fields = spec.outputs.iter().map(|&(n, _, doc)| {
        let n = ident(n);
        let docs = doc_attrs(doc);
        quote!(#docs pub #n: #ty)
    });
    let field_names = request.outputs.iter().map(|(n, _)| ident(n));
    let fn_doc = doc_attrs(spec.doc);
    let struct_doc = format!(" Outputs of [`{}`].", spec.name);
    let mut allow = if args.len() > 7 {
        quote!(#[allow(clippy::too_many_arguments)])
    } else {
        quote!()
    };
    let inline = match attrs.inline {
        Inline::Hint => quote!(#[inline]),
        Inline::Always => quote!(#[inline(always)]),
    };
    if attrs.excessive {
        allow.extend(quote!(#[allow(clippy::excessive_precision)]));
    }
    quote! {
        #[doc = #struct_doc]
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct #out_ty {
            #(#fields,)*
        }

        #fn_doc
        #inline
        #[must_use]
        #allow
        pub fn #fn_name(#(#args),*) -> #out_ty {
            #body
            #out_ty { #(#field_names),* }
        }
    }
}

/// The function's own consts: the physical constants it writes by name and
/// nobody declared for it (`physical.rs`), then its derived consts
/// (`fold.rs`), each documented; and whether one of them has more digits
/// than f32 holds (`Scalar::excessive`).
fn local_consts(
    physical: &[&Constant],
    folded: Option<&Folded>,
    scalar: Scalar,
) -> Result<(TokenStream, bool), EmitError> {
    let physical = physical
        .iter()
        .map(|c| (c.symbol, c.value, c.doc.to_owned()));
    let derived = folded.map_or(&[][..], |f| &f.derived).iter().map(|d| {
        let doc = format!(
            "{} (parameters only: evaluated when generated, so it changes with them)",
            d.formula
        );
        (d.name.as_str(), d.value, doc)
    });
    let mut items = TokenStream::new();
    let mut excessive = false;
    let ty = scalar.ty();
    for (name, value, doc) in physical.chain(derived) {
        let cname = const_name(name)?;
        let lit = scalar
            .signed_literal(value)
            .ok_or_else(|| EmitError::NonFinite {
                name: cname.clone(),
                value: format!("{value:?}"),
                float: scalar.name(),
            })?;
        excessive |= scalar.excessive(value);
        let doc = format!(" {doc}");
        let cname = ident(&cname);
        items.extend(quote!(#[doc = #doc] const #cname: #ty = #lit;));
    }
    Ok((items, excessive))
}

/// `#[doc = " line"]` per line (an empty text gives none).
pub(crate) fn doc_attrs(text: &str) -> TokenStream {
    let mut out = TokenStream::new();
    if text.is_empty() {
        return out;
    }
    for line in text.lines() {
        let line = if line.is_empty() {
            String::new()
        } else {
            format!(" {line}")
        };
        out.extend(quote!(#[doc = #line]));
    }
    out
}
