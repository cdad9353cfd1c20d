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

/// How emitted code writes its float type: one type per copy of the code, or
/// the `$f` of a `macro_rules!` written once and instantiated per float type
/// (`law!(f32)`, `law!(f64)`).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(crate) enum Scalar {
    /// `f64` or `f32`, with typed literals (`1.5_f32`).
    One(Float),
    /// The macro's `$f` (a placeholder until the body is formatted, see
    /// [`MACRO_FLOAT`]), with unsuffixed literals that `$f` types; `f32`
    /// when the macro is instantiated for f32 too (the literals must then
    /// read as the f32 code's).
    Macro { f32: bool },
}

/// The identifier standing for a macro's `$f` while its body is formatted:
/// as long as `$f`, so that the formatter breaks the lines where it would
/// break them around `$f`, and replaced as a whole word afterwards
/// (`format::macro_rules`).
pub(crate) const MACRO_FLOAT: &str = "Ft";

/// What a macro's doc says of its literals (`Scalar::Macro`).
pub(crate) const MACRO_LITERALS: &str =
    "Its literals are unsuffixed and `$f` types them: an f32 module reads each as the\n\
     nearest f32, the value an f32 literal of its own would hold.";

impl Scalar {
    /// For the messages of errors.
    pub(crate) fn name(self) -> &'static str {
        match self {
            Scalar::One(f) => f.name(),
            Scalar::Macro { f32: true } => "f32",
            Scalar::Macro { f32: false } => "f64",
        }
    }

    pub(crate) fn ty(self) -> Ident {
        match self {
            Scalar::One(f) => f.ty(),
            Scalar::Macro { .. } => Ident::new(MACRO_FLOAT, Span::call_site()),
        }
    }

    /// A literal of `value` ≥ 0 in an expression: `1.5_f32`, or `1.5` in a macro.
    pub(crate) fn literal(self, value: f64) -> Option<TokenStream> {
        match self {
            Scalar::One(f) => f.suffixed(value),
            Scalar::Macro { f32 } => {
                let lit: Literal = shared_magnitude(value, f32)?.parse().ok()?;
                Some(quote!(#lit))
            }
        }
    }

    /// An unsuffixed literal with its sign, `-0.75` (for typed consts).
    pub(crate) fn signed_literal(self, value: f64) -> Option<TokenStream> {
        match self {
            Scalar::One(f) => f.unsuffixed_signed(value),
            Scalar::Macro { f32 } => {
                let lit: Literal = shared_magnitude(value, f32)?.parse().ok()?;
                Some(if value.is_sign_negative() && value != 0.0 {
                    quote!(-#lit)
                } else {
                    quote!(#lit)
                })
            }
        }
    }

    /// Whether the literal of `value` carries more digits than an f32
    /// holds (clippy's `excessive_precision` in the f32 instantiation).
    pub(crate) fn excessive(self, value: f64) -> bool {
        match self {
            Scalar::One(_) | Scalar::Macro { f32: false } => false,
            Scalar::Macro { f32: true } => {
                shared_magnitude(value, true) != Float::F32.magnitude_text(value)
            }
        }
    }
}

/// The unsigned literal text a macro writes once for `value`, `None` if it
/// is not finite in an instantiated type.
///
/// Written once, a literal is typed by `$f`: rustc rounds its decimal text to
/// f64 or to f32 directly. The shortest round-trip f64 text reads as the
/// value in f64. In f32 it reads as the nearest f32 to the decimal, within
/// ½ ulp of f32 of it, which is the f32 code's literal (the f64 value rounded
/// to f32) except where the decimal and the f64 value, less than ½ ulp of
/// f64 apart, lie on two sides of an f32 rounding midpoint (double
/// rounding): the two would then be one f32 ulp apart. So that the f32
/// instantiation holds exactly the constants the f32 code held, the text is
/// checked against both and, where f32 reads it otherwise, lengthened to
/// more significant digits until both read it right (at worst the exact
/// decimal expansion of the f64 value, which both round as they round the
/// value).
fn shared_magnitude(value: f64, f32: bool) -> Option<String> {
    let v = value.abs();
    let shortest = Float::F64.magnitude_text(v)?;
    if !f32 {
        return Some(shortest);
    }
    let single = v as f32; // the f32 code's value: f64 → f32 rounds to nearest
    if !single.is_finite() {
        return None;
    }
    let reads = |text: &str| {
        text.parse::<f64>().is_ok_and(|x| x == v) && text.parse::<f32>().is_ok_and(|x| x == single)
    };
    if reads(&shortest) {
        return Some(shortest);
    }
    // 767 significant digits hold the exact expansion of every f64
    (0..767).map(|p| format!("{v:.p$e}")).find(|t| reads(t))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_macro_literal_is_the_shortest_f64_text_where_f32_reads_it_as_its_own() {
        let both = Scalar::Macro { f32: true };
        for (value, text) in [
            (2.0, "2.0"),
            (1e-9, "1e-9"),
            (0.5, "0.5"),
            (223.60679774997894, "223.60679774997894"),
        ] {
            assert_eq!(shared_magnitude(value, true).as_deref(), Some(text));
            assert_eq!(text.parse::<f32>(), Ok(value as f32), "{text}");
        }
        assert!(!both.excessive(1e-9) && both.excessive(223.60679774997894));
        assert!(!Scalar::Macro { f32: false }.excessive(223.60679774997894));
        // an f64 only macro: any finite f64
        assert_eq!(shared_magnitude(1e300, false).as_deref(), Some("1e300"));
        assert_eq!(shared_magnitude(1e300, true), None);
    }

    #[test]
    fn a_double_rounding_case_gets_a_text_both_types_read_as_before() {
        // 1 + 2⁻²⁴ lies on an f32 rounding midpoint: the f64 rounds to the even
        // f32 1.0, its shortest text 1.0000000596046448 (above the midpoint)
        // would read as the f32 above
        let v = 1.0 + f64::powi(2.0, -24);
        let shortest = format!("{v:?}");
        assert_ne!(shortest.parse::<f32>(), Ok(v as f32));
        let text = shared_magnitude(v, true).unwrap_or_default();
        assert_eq!(text.parse::<f64>(), Ok(v), "{text}");
        assert_eq!(text.parse::<f32>(), Ok(v as f32), "{text}");
        assert_eq!(text.parse::<f32>(), Ok(1.0), "{text}");
        // f64 alone: the shortest text
        assert_eq!(shared_magnitude(v, false), Some(shortest));
    }

    #[test]
    fn signed_literals_of_a_macro_are_unsuffixed() {
        let both = Scalar::Macro { f32: true };
        let text = |t: Option<TokenStream>| t.map(|t| t.to_string()).unwrap_or_default();
        assert_eq!(text(both.signed_literal(-0.75)), "- 0.75");
        assert_eq!(text(both.literal(2.0)), "2.0");
        assert_eq!(text(Scalar::One(Float::F32).literal(2.0)), "2.0_f32");
        assert_eq!(both.ty().to_string(), MACRO_FLOAT);
    }
}
