//! Deterministic infix printing.
//!
//! Printing walks the expression as a tree, so it is meant for small
//! expressions, tests and messages; large DAGs are printed through
//! [`super::cse`] (one line per shared temporary). Constants print in
//! shortest round-trip form, so the text is byte-identical across runs.

use super::graph::{Graph, Id, Node};

const SUM: u8 = 1;
const PRODUCT: u8 = 2;
const POWER: u8 = 3;
const ATOM: u8 = 4;

impl Graph {
    /// Infix text of an expression, e.g. `2.0*x*y^(-1) - ln(z)`.
    pub fn display(&self, id: Id) -> String {
        let mut out = String::new();
        self.write(id, 0, &mut out);
        out
    }

    fn precedence(&self, id: Id) -> u8 {
        match self.node(id) {
            Node::Add(_) => SUM,
            Node::Mul(_) => PRODUCT,
            Node::Pow(..) => POWER,
            Node::Const(bits) if f64::from_bits(*bits) < 0.0 => SUM,
            _ => ATOM,
        }
    }

    fn write(&self, id: Id, min_precedence: u8, out: &mut String) {
        let parens = self.precedence(id) < min_precedence;
        if parens {
            out.push('(');
        }
        match self.node(id) {
            Node::Const(bits) => out.push_str(&format!("{:?}", f64::from_bits(*bits))),
            Node::Sym(i) => out.push_str(self.symbol_name(*i)),
            Node::Add(xs) => self.write_sum(xs, out),
            Node::Mul(xs) => self.write_product(xs, out),
            Node::Pow(b, e) => {
                self.write(*b, ATOM, out);
                out.push('^');
                self.write(*e, ATOM, out);
            }
            Node::Func(f, a) => self.write_call(f.name(), &[*a], out),
            Node::Min(a, b) => self.write_call("min", &[*a, *b], out),
            Node::Max(a, b) => self.write_call("max", &[*a, *b], out),
            Node::Select(c, a, b) => self.write_call("select", &[*c, *a, *b], out),
        }
        if parens {
            out.push(')');
        }
    }

    fn write_call(&self, name: &str, args: &[Id], out: &mut String) {
        out.push_str(name);
        out.push('(');
        for (k, &a) in args.iter().enumerate() {
            if k > 0 {
                out.push_str(", ");
            }
            self.write(a, 0, out);
        }
        out.push(')');
    }

    /// Terms with a negative coefficient print as subtractions; the constant last.
    fn write_sum(&self, xs: &[Id], out: &mut String) {
        let mut ordered: Vec<Id> = xs
            .iter()
            .copied()
            .filter(|&x| self.as_const(x).is_none())
            .collect();
        ordered.extend(xs.iter().copied().filter(|&x| self.as_const(x).is_some()));
        for (k, &t) in ordered.iter().enumerate() {
            let (negative, magnitude) = self.negated_text(t);
            match (k, negative) {
                (0, true) => out.push('-'),
                (0, false) => {}
                (_, true) => out.push_str(" - "),
                (_, false) => out.push_str(" + "),
            }
            out.push_str(&magnitude);
        }
    }

    /// (is the term negative?, text of its magnitude)
    fn negated_text(&self, t: Id) -> (bool, String) {
        match self.node(t) {
            Node::Const(bits) if f64::from_bits(*bits) < 0.0 => {
                (true, format!("{:?}", -f64::from_bits(*bits)))
            }
            Node::Mul(xs) if self.as_const(xs[0]).is_some_and(|c| c < 0.0) => {
                let c = -self.as_const(xs[0]).unwrap_or(-1.0);
                let mut s = String::new();
                self.write_factors(c, &xs[1..], &mut s);
                (true, s)
            }
            _ => {
                let mut s = String::new();
                self.write(t, PRODUCT, &mut s);
                (false, s)
            }
        }
    }

    fn write_product(&self, xs: &[Id], out: &mut String) {
        match self.as_const(xs[0]) {
            Some(c) => self.write_factors(c, &xs[1..], out),
            None => self.write_factors(1.0, xs, out),
        }
    }

    /// `c*a*b/(d*e)`, with factors x^(-n) moved to the denominator.
    fn write_factors(&self, c: f64, factors: &[Id], out: &mut String) {
        let mut num: Vec<String> = Vec::new();
        let mut den: Vec<String> = Vec::new();
        if c != 1.0 {
            num.push(format!("{c:?}"));
        }
        for &f in factors {
            if let Node::Pow(b, e) = self.node(f) {
                if let Some(ev) = self.as_const(*e).filter(|&e| e < 0.0) {
                    let mut s = String::new();
                    self.write(*b, ATOM, &mut s);
                    if ev != -1.0 {
                        s.push_str(&format!("^{:?}", -ev));
                    }
                    den.push(s);
                    continue;
                }
            }
            let mut s = String::new();
            self.write(f, POWER, &mut s);
            num.push(s);
        }
        if num.is_empty() {
            num.push("1.0".to_owned());
        }
        if c < 0.0 && num.len() > 1 {
            num[0] = format!("({})", num[0]);
        }
        out.push_str(&num.join("*"));
        match den.len() {
            0 => {}
            1 => {
                out.push('/');
                out.push_str(&den[0]);
            }
            _ => {
                out.push_str("/(");
                out.push_str(&den.join("*"));
                out.push(')');
            }
        }
    }
}
