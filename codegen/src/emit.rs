//! The public emitters: a parameter block and a function over named outputs.

use std::collections::{HashMap, HashSet};

use designer::sym::{Graph, Id};
use proc_macro2::TokenStream;
use quote::quote;

use crate::error::EmitError;
use crate::float::Float;
use crate::fold::{fold, Folded};
use crate::format::{comment_lets, format_items};
use crate::lower::Lowerer;
use crate::names::{camel, const_name, ident, Namer};
use crate::param::Param;
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
    function_tokens_inline(graph, spec, params, Inline::Hint)
}

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

/// [`function_tokens`] with the given inlining attribute.
pub(crate) fn function_tokens_inline(
    graph: &Graph,
    spec: &FunctionSpec,
    params: &[Param],
    inline: Inline,
) -> Result<TokenStream, EmitError> {
    crate::names::check_local(spec.name)?;
    let roots: Vec<Id> = spec
        .outputs
        .iter()
        .map(|o| o.1)
        .chain(spec.named.iter().map(|n| n.1))
        .collect();
    let folded = fold(graph, params, &roots)?;
    let (graph, roots, params) = match &folded {
        Some(f) => {
            let mut all = params.to_vec();
            all.extend(f.derived.iter().map(|d| Param {
                name: d.name.as_str(),
                symbol: d.symbol,
                value: d.value,
            }));
            (&f.graph, f.roots.clone(), all)
        }
        None => (graph, roots, params.to_vec()),
    };
    let params = params.as_slice();
    let const_by_id = const_names(graph, params)?;
    let mut namer = Namer::default();
    for &(name, _) in &spec.inputs {
        namer.reserve(name)?;
    }
    for &(name, _, _) in &spec.outputs {
        namer.reserve(name)?;
    }
    for &(name, _) in &spec.named {
        namer.reserve(name)?;
    }
    let inputs: Vec<(String, Id)> = spec
        .inputs
        .iter()
        .map(|&(n, id)| (n.to_owned(), id))
        .collect();
    let outputs: Vec<(String, Id)> = spec
        .outputs
        .iter()
        .zip(&roots)
        .map(|(&(n, _, _), &id)| (n.to_owned(), id))
        .collect();
    let named: Vec<(String, Id)> = spec
        .named
        .iter()
        .zip(&roots[spec.outputs.len()..])
        .map(|(&(n, _), &id)| (n.to_owned(), id))
        .collect();
    let output_symbols: Vec<(String, Id)> = spec
        .output_symbols
        .iter()
        .map(|&(n, id)| (n.to_owned(), id))
        .collect();
    let request = PlanRequest {
        inputs: &inputs,
        params: &const_by_id,
        outputs: &outputs,
        named: &named,
        output_symbols: &output_symbols,
    };
    let plan = plan(graph, &request, &mut namer)?;

    let param_ids: HashSet<Id> = const_by_id.keys().copied().collect();
    let mut lower = Lowerer {
        graph,
        bound: &plan.bound,
        float: spec.float,
        uses_real: false,
        params: &param_ids,
        statics: HashMap::new(),
        defined: HashSet::new(),
    };
    let mut body = derived_consts(folded.as_ref(), spec.float)?;
    for b in &plan.lets {
        let name = ident(&b.name);
        let rhs = lower.definition(b.id)?;
        lower.defined.insert(b.id);
        body.extend(quote!(let #name = #rhs;));
    }
    for (name, id) in &outputs {
        if plan.bound.get(id) == Some(name) {
            continue; // bound above under the output's own name
        }
        let rhs = lower.operand(*id)?;
        let name = ident(name);
        body.extend(quote!(let #name = #rhs;));
    }
    let prelude = if lower.uses_real {
        quote!(
            use reldesign_runtime::math::Real;
        )
    } else {
        quote!()
    };

    let ty = spec.float.ty();
    let out_ty = ident(&format!("{}Output", camel(spec.name)));
    let fn_name = ident(spec.name);
    let args = inputs.iter().zip(&plan.input_used).map(|((n, _), &used)| {
        let n = if used {
            ident(n)
        } else {
            ident(&format!("_{n}"))
        };
        quote!(#n: #ty)
    });
    let fields = spec.outputs.iter().map(|&(n, _, doc)| {
        let n = ident(n);
        let docs = doc_attrs(doc);
        quote!(#docs pub #n: #ty)
    });
    let field_names = outputs.iter().map(|(n, _)| ident(n));
    let fn_doc = doc_attrs(spec.doc);
    let struct_doc = format!(" Outputs of [`{}`].", spec.name);
    let allow = if inputs.len() > 7 {
        quote!(#[allow(clippy::too_many_arguments)])
    } else {
        quote!()
    };
    let inline = match inline {
        Inline::Hint => quote!(#[inline]),
        Inline::Always => quote!(#[inline(always)]),
    };
    Ok(quote! {
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
            #prelude
            #body
            #out_ty { #(#field_names),* }
        }
    })
}

/// `const NAME: f32 = value;` per derived const of `folded` (see `fold.rs`),
/// documented with the expression it stands for.
fn derived_consts(folded: Option<&Folded>, float: Float) -> Result<TokenStream, EmitError> {
    let mut items = TokenStream::new();
    let ty = float.ty();
    for d in folded.map_or(&[][..], |f| &f.derived) {
        let cname = const_name(&d.name)?;
        let lit = float
            .unsuffixed_signed(d.value)
            .ok_or_else(|| EmitError::NonFinite {
                name: cname.clone(),
                value: format!("{:?}", d.value),
                float: float.name(),
            })?;
        let doc = format!(
            " {} (parameters only: evaluated when generated, so it changes with them)",
            d.formula
        );
        let cname = ident(&cname);
        items.extend(quote!(#[doc = #doc] const #cname: #ty = #lit;));
    }
    Ok(items)
}

/// `#[doc = " line"]` per line (an empty text gives none).
fn doc_attrs(text: &str) -> TokenStream {
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
