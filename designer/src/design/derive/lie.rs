//! Input-affine systems and Lie derivatives, generically: any output h of any
//! vector fields f, g over named states. Nothing here knows about actuators.
//!
//! For ẋ = f(x) + g(x)·u and an output y = h(x):
//! L_f h = ∇h·f, L_f^k h = L_f(L_f^{k−1} h), L_g L_f^k h = ∇(L_f^k h)·g.
//! The relative degree r is the first k + 1 with L_g L_f^k h ≢ 0
//! (perfect-tracking-soft-landing [PT 23–25]).

use crate::sym::{Graph, Id, Node};

/// ẋ = f(x) + g(x)·u, as expressions over `states`.
#[derive(Debug, Clone, PartialEq)]
pub struct AffineSystem {
    pub states: Vec<Id>,
    /// Drift f(x).
    pub drift: Vec<Id>,
    /// Input field g(x).
    pub input_field: Vec<Id>,
}

/// Lie derivative ∇h·field.
pub fn lie(g: &mut Graph, field: &[Id], states: &[Id], h: Id) -> Id {
    let terms: Vec<Id> = states
        .iter()
        .zip(field)
        .map(|(&x, &fx)| {
            let dh = g.diff(h, x);
            g.mul(dh, fx)
        })
        .collect();
    g.sum(&terms)
}

/// The chain of Lie derivatives of one output.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputDerivatives {
    /// Relative degree r.
    pub degree: usize,
    /// L_f^k h for k = 0..=r (h itself first, L_f^r h last).
    pub lf: Vec<Id>,
    /// L_g L_f^{r−1} h: the gain of the input in y^(r).
    pub gain: Id,
}

impl AffineSystem {
    /// Splits ẋ = F(x, u) into drift and input field, if F is affine in `u`
    /// (∂²F/∂u² ≡ 0 and ∂F/∂u free of u); `None` otherwise.
    pub fn split(g: &mut Graph, states: &[Id], field: &[Id], u: Id) -> Option<AffineSystem> {
        let zero = g.zero();
        let mut drift = Vec::new();
        let mut input_field = Vec::new();
        for &fk in field {
            let gk = g.diff(fk, u);
            if g.depends_on(gk, u) {
                return None;
            }
            let subst = std::iter::once((u, zero)).collect();
            drift.push(g.substitute(fk, &subst));
            input_field.push(gk);
        }
        Some(AffineSystem {
            states: states.to_vec(),
            drift,
            input_field,
        })
    }

    /// L_f^k h for k = 0..=r and the gain L_g L_f^{r−1} h, where r ≤ `max`
    /// is the relative degree; `None` if L_g L_f^k h ≡ 0 for all k < max.
    pub fn output_derivatives(
        &self,
        g: &mut Graph,
        h: Id,
        max: usize,
    ) -> Option<OutputDerivatives> {
        let zero = g.zero();
        let mut lf = vec![h];
        for k in 0..max {
            let current = lf[k];
            let gain = lie(g, &self.input_field, &self.states, current);
            let next = lie(g, &self.drift, &self.states, current);
            lf.push(next);
            if gain != zero {
                return Some(OutputDerivatives {
                    degree: k + 1,
                    lf,
                    gain,
                });
            }
        }
        None
    }
}

/// The state symbols that appear as factors of a product (e.g. `phi` in
/// −phi·R_gap'(z)/(m·k)): where the expression vanishes identically.
pub fn vanishing_factors(g: &Graph, e: Id, states: &[Id]) -> Vec<Id> {
    let factors: Vec<Id> = match g.node(e) {
        Node::Mul(xs) => xs.to_vec(),
        _ => vec![e],
    };
    factors
        .into_iter()
        .filter_map(|f| match g.node(f) {
            Node::Pow(b, exp) if g.as_const(*exp).is_some_and(|p| p > 0.0) => Some(*b),
            _ => Some(f),
        })
        .filter(|f| states.contains(f))
        .collect()
}
