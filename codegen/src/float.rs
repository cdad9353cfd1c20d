//! The scalar type of emitted code and its literals.
//!
//! Literals are written in shortest round-trip form (`{:?}` of the value
//! rounded to the target type), so the same value always gives the same bytes
//! and reading the literal back gives the same number.

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::quote;

/// The float type of an emitted function (the same expressions give both).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Float {
    F32,
    F64,
}

impl Float {
    /// `f32` or `f64`.
    pub fn name(self) -> &'static str {
        match self {
            Float::F32 => "f32",
            Float::F64 => "f64",
        }
    }

    pub(crate) fn ty(self) -> Ident {
        Ident::new(self.name(), Span::call_site())
    }

    /// Shortest round-trip text of `value` in this type, without suffix and
    /// without sign; `None` if it is not finite in this type.
    pub(crate) fn magnitude_text(self, value: f64) -> Option<String> {
        let v = value.abs();
        let text = match self {
            Float::F64 => format!("{v:?}"),
            Float::F32 => {
                // f64 → f32 rounds to nearest; overflow gives ∞, caught below.
                let v32 = v as f32;
                if !v32.is_finite() {
                    return None;
                }
                format!("{v32:?}")
            }
        };
        v.is_finite().then_some(text)
    }

    /// The text of [`Float::unsuffixed_signed`], `-0.75`.
    pub(crate) fn literal_text(self, value: f64) -> Option<String> {
        let magnitude = self.magnitude_text(value)?;
        Some(if value.is_sign_negative() && value != 0.0 {
            format!("-{magnitude}")
        } else {
            magnitude
        })
    }

    /// A typed literal `1.5_f64` (non-negative `value`).
    pub(crate) fn suffixed(self, value: f64) -> Option<TokenStream> {
        let text = format!("{}_{}", self.magnitude_text(value)?, self.name());
        let lit: Literal = text.parse().ok()?;
        Some(quote!(#lit))
    }

    /// An unsuffixed literal with its sign, `-0.75` (for typed consts).
    pub(crate) fn unsuffixed_signed(self, value: f64) -> Option<TokenStream> {
        let lit: Literal = self.magnitude_text(value)?.parse().ok()?;
        Some(if value.is_sign_negative() && value != 0.0 {
            quote!(-#lit)
        } else {
            quote!(#lit)
        })
    }
}
