//! Physical constants by name: the model builds μ0 and the McLyman
//! regularisation Z_EPS as numbers, and the symbolic core folds them into
//! the coefficients (1/(2μ0) = 397887.36…), where a reader cannot recognise
//! them. The lowering writes every constant c = k·μ0ᵉ (e = ±1, ±2, k a short
//! decimal such as 0.5 or −2) as `k / MU0`, `k * MU0`, … and ±Z_EPS as
//! `Z_EPS` ([`recognise`]). The compiler folds `0.5 / MU0 * …` back into one
//! constant, and the graph is left as it is (same `let`s, same evaluation
//! order), so this costs nothing at run time.
//!
//! `MU0` and `Z_EPS` are declared once per file, in its `params!` macro,
//! when the model's equations use them ([`of_model`]); a function whose
//! caller passes them as parameters ([`in_scope`]) refers to those, any
//! other declares the ones it uses as local consts.
//!
//! A short decimal k has at most 3 significant digits and matches c/μ0ᵉ to
//! 10⁻¹² relative: a coincidence would need a coefficient that is neither
//! short itself nor unrelated to μ0 to within 12 digits.

use designer::model::{Model, MU0, Z_EPS};
use designer::sym::{Graph, Id, Node};

use crate::param::Param;

/// One named physical constant.
#[derive(Debug, PartialEq)]
pub(crate) struct Constant {
    /// Symbol name (the const is its upper snake case).
    pub symbol: &'static str,
    /// Its const name.
    pub name: &'static str,
    pub value: f64,
    /// Its definition in the `params!` macro (`$f` the float type).
    pub definition: &'static str,
    /// Doc of the emitted const.
    pub doc: &'static str,
}

pub(crate) const MU0_CONST: Constant = Constant {
    symbol: "mu0",
    name: "MU0",
    value: MU0,
    definition: "4e-7 * ::core::$f::consts::PI",
    doc: "μ0 = 4π·10⁻⁷ H/m, the vacuum permeability",
};

pub(crate) const Z_EPS_CONST: Constant = Constant {
    symbol: "z_eps",
    name: "Z_EPS",
    value: Z_EPS,
    definition: "1e-9",
    doc: "Z_EPS [m], the regularisation of the McLyman logarithm ln(k/(z + Z_EPS))",
};

/// How a constant is written by name.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Named {
    /// c = k·μ0ᵉ
    Mu0 { k: f64, e: i32 },
    /// c = sign·Z_EPS
    ZEps { sign: f64 },
}

impl Named {
    pub fn constant(self) -> &'static Constant {
        match self {
            Named::Mu0 { .. } => &MU0_CONST,
            Named::ZEps { .. } => &Z_EPS_CONST,
        }
    }
}

/// `c` as a short decimal times a power of μ0, or as ±Z_EPS.
pub(crate) fn recognise(c: f64) -> Option<Named> {
    if c.abs() == Z_EPS {
        return Some(Named::ZEps { sign: c.signum() });
    }
    if !c.is_finite() || c == 0.0 || short(c).is_some() {
        return None;
    }
    [1, -1, 2, -2]
        .into_iter()
        .find_map(|e| short(c / MU0.powi(e)).map(|k| Named::Mu0 { k, e }))
}

/// `x` as a decimal of at most 3 significant digits, if it is one (to 10⁻¹²).
fn short(x: f64) -> Option<f64> {
    let r: f64 = format!("{x:.2e}").parse().ok()?;
    ((x - r).abs() <= 1e-12 * r.abs() && r != 0.0).then_some(r)
}

/// The physical constants the model's equations (ẋ = f, the coil current)
/// use, in a fixed order: what the file's `params!` declares. A constant
/// whose const name a model parameter already has is left out (its
/// multiples then stay numbers, see [`available`]).
pub(crate) fn of_model(model: &Model) -> Vec<&'static Constant> {
    let mut roots = model.f.clone();
    roots.push(model.current);
    let params: Vec<Param> = model.params.iter().map(Param::from).collect();
    let used = constants_under(&model.graph, &roots);
    [&MU0_CONST, &Z_EPS_CONST]
        .into_iter()
        .filter(|&c| used.contains(&c) && available(c, &params))
        .collect()
}

/// Whether `c` may be written by name among `params`: no parameter but its
/// own (see [`in_scope`]) has its const name.
pub(crate) fn available(c: &Constant, params: &[Param]) -> bool {
    !params
        .iter()
        .any(|p| p.name != c.symbol && p.name.eq_ignore_ascii_case(c.name))
}

/// Whether `params` hold `c` (its const is in scope).
pub(crate) fn provided(c: &Constant, params: &[Param]) -> bool {
    params.iter().any(|p| p.name == c.symbol)
}

/// Symbols in `graph` for `constants`, as parameters: passed to the
/// expression emitter, they tell it that the consts are in scope.
pub(crate) fn in_scope(graph: &mut Graph, constants: &[&'static Constant]) -> Vec<Param<'static>> {
    constants
        .iter()
        .map(|c| Param::from((c.symbol, graph.symbol(c.symbol), c.value)))
        .collect()
}

/// The physical constants written by name under `roots`.
fn constants_under(graph: &Graph, roots: &[Id]) -> Vec<&'static Constant> {
    let mut found: Vec<&'static Constant> = Vec::new();
    for id in graph.postorder(roots) {
        if let Node::Const(bits) = graph.node(id) {
            if let Some(c) = recognise(f64::from_bits(*bits)).map(Named::constant) {
                if !found.contains(&c) {
                    found.push(c);
                }
            }
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mu0_multiples_and_z_eps_are_recognised_other_constants_are_not() {
        let half_inv = 0.5 / MU0;
        assert_eq!(recognise(half_inv), Some(Named::Mu0 { k: 0.5, e: -1 }));
        assert_eq!(recognise(-MU0), Some(Named::Mu0 { k: -1.0, e: 1 }));
        assert_eq!(
            recognise(2.0 * MU0 * MU0),
            Some(Named::Mu0 { k: 2.0, e: 2 })
        );
        assert_eq!(recognise(1e-9), Some(Named::ZEps { sign: 1.0 }));
        assert_eq!(recognise(-1e-9), Some(Named::ZEps { sign: -1.0 }));
        for c in [
            0.0,
            1.0,
            -0.5,
            2.0,
            1e-6,
            397887.0,
            1.234567,
            f64::NAN,
            0.1 / 3.0,
        ] {
            assert!(recognise(c).is_none(), "{c}");
        }
    }

    #[test]
    fn a_parameter_with_the_const_name_makes_it_unavailable() {
        let mut g = Graph::new();
        let own = in_scope(&mut g, &[&MU0_CONST]);
        assert!(provided(&MU0_CONST, &own) && available(&MU0_CONST, &own));
        let other = [Param::from(("Mu0", g.symbol("Mu0"), 1.0))];
        assert!(!provided(&MU0_CONST, &other) && !available(&MU0_CONST, &other));
        assert!(available(&Z_EPS_CONST, &other));
    }
}
