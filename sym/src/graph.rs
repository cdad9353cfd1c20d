//! The expression DAG: hash-consed nodes in an arena.
//!
//! Every structurally equal expression is stored once ([`Id`] equality is
//! expression equality). Nodes are only created through the smart constructors
//! of `build.rs`, which keep them canonical. Lookup uses a hash map, but nothing
//! ever iterates it: node ids depend only on the order of construction, so the
//! same construction gives the same ids, the same printing and the same code on
//! every run and machine.

use std::collections::HashMap;

/// Handle of a node in a [`Graph`].
#[derive(Copy, Clone, PartialEq, Eq, Hash, PartialOrd, Ord, Debug)]
pub struct Id(pub(crate) u32);

impl Id {
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Unary functions.
#[derive(Copy, Clone, PartialEq, Eq, Hash, PartialOrd, Ord, Debug)]
pub enum Func {
    Sqrt,
    Exp,
    Ln,
    Abs,
    /// sign(0) = 0.
    Sign,
    Tanh,
    Coth,
}

impl Func {
    /// Every function, in declaration order.
    pub const ALL: [Func; 7] = [
        Func::Sqrt,
        Func::Exp,
        Func::Ln,
        Func::Abs,
        Func::Sign,
        Func::Tanh,
        Func::Coth,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Func::Sqrt => "sqrt",
            Func::Exp => "exp",
            Func::Ln => "ln",
            Func::Abs => "abs",
            Func::Sign => "sign",
            Func::Tanh => "tanh",
            Func::Coth => "coth",
        }
    }

    #[inline]
    pub fn apply(self, x: f64) -> f64 {
        match self {
            Func::Sqrt => x.sqrt(),
            Func::Exp => x.exp(),
            Func::Ln => x.ln(),
            Func::Abs => x.abs(),
            Func::Sign => sign(x),
            Func::Tanh => x.tanh(),
            Func::Coth => coth(x),
        }
    }
}

/// coth x: where 2|x| ≥ ln 2, as 1 + 2/(e^{2|x|} − 1) with the sign of x
/// (the subtraction is exact there and both terms are ≥ 0): an `exp`, where
/// `1/tanh` costs a `tanh` (an `expm1` and a division) and a division, and
/// closer to the exact value (0.07 ulp on average against 0.26, mpmath, 3000
/// points up to x = 25). Below, `1/tanh x`. Exactly odd, ±∞ at ±0.
pub fn coth(x: f64) -> f64 {
    let a = 2.0 * x.abs();
    if a >= std::f64::consts::LN_2 {
        (1.0 + 2.0 / (a.exp() - 1.0)).copysign(x)
    } else {
        1.0 / x.tanh()
    }
}

/// sign with sign(0) = 0 (and sign(NaN) = NaN).
pub fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        x * 0.0
    }
}

/// One node of the DAG. N-ary sums and products keep their operands sorted
/// (see `build.rs`), with at most one constant, which comes first.
#[derive(Clone, PartialEq, Eq, Hash, Debug)]
pub enum Node {
    /// A finite constant, stored as bits (−0.0 is normalised to 0.0).
    Const(u64),
    /// A named symbol (index into the graph's symbol table).
    Sym(u32),
    Add(Box<[Id]>),
    Mul(Box<[Id]>),
    Pow(Id, Id),
    Func(Func, Id),
    Min(Id, Id),
    Max(Id, Id),
    /// `Select(c, a, b)` = a if c ≥ 0, else b. Piecewise definitions, guards.
    Select(Id, Id, Id),
}

/// [`Graph::fresh_symbol`]: the name is taken.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("the symbol `{0}` already exists")]
pub struct SymbolTaken(pub String);

/// The arena of hash-consed expression nodes and the symbol table.
#[derive(Default, Clone)]
pub struct Graph {
    nodes: Vec<Node>,
    index: HashMap<Node, Id>,
    symbols: Vec<String>,
    symbol_index: HashMap<String, u32>,
}

impl Graph {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn node(&self, id: Id) -> &Node {
        &self.nodes[id.index()]
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Interns a node (no simplification: use the constructors of `build.rs`).
    pub(crate) fn intern(&mut self, node: Node) -> Id {
        if let Some(&id) = self.index.get(&node) {
            return id;
        }
        let id = Id(u32::try_from(self.nodes.len()).expect("expression graph exceeds 2^32 nodes"));
        self.nodes.push(node.clone());
        self.index.insert(node, id);
        id
    }

    /// The id of `node` if it is already interned (lookup only, no simplification).
    pub fn find(&self, node: &Node) -> Option<Id> {
        self.index.get(node).copied()
    }

    /// The symbol called `name` (created on first use).
    pub fn symbol(&mut self, name: &str) -> Id {
        let index = match self.symbol_index.get(name) {
            Some(&i) => i,
            None => {
                let i = self.symbols.len() as u32;
                self.symbols.push(name.to_owned());
                self.symbol_index.insert(name.to_owned(), i);
                i
            }
        };
        self.intern(Node::Sym(index))
    }

    /// The symbol `name`, which must not exist yet: for names that code built
    /// from the graph declares itself, where reusing a symbol of the model
    /// would silently bind two meanings to one name.
    pub fn fresh_symbol(&mut self, name: &str) -> Result<Id, SymbolTaken> {
        if self.symbol_index.contains_key(name) {
            return Err(SymbolTaken(name.to_owned()));
        }
        Ok(self.symbol(name))
    }

    /// The symbol node called `name`, if it exists.
    pub fn find_symbol(&self, name: &str) -> Option<Id> {
        let &i = self.symbol_index.get(name)?;
        self.index.get(&Node::Sym(i)).copied()
    }

    pub fn symbol_name(&self, index: u32) -> &str {
        &self.symbols[index as usize]
    }

    /// Name of a symbol node, `None` for other nodes.
    pub fn name_of(&self, id: Id) -> Option<&str> {
        match self.node(id) {
            Node::Sym(i) => Some(self.symbol_name(*i)),
            _ => None,
        }
    }

    pub fn constant(&mut self, value: f64) -> Id {
        assert!(
            value.is_finite(),
            "symbolic constants must be finite, got {value}"
        );
        let value = if value == 0.0 { 0.0 } else { value };
        self.intern(Node::Const(value.to_bits()))
    }

    /// The value of a constant node.
    pub fn as_const(&self, id: Id) -> Option<f64> {
        match self.node(id) {
            Node::Const(bits) => Some(f64::from_bits(*bits)),
            _ => None,
        }
    }

    /// Direct operands of a node, in order.
    pub fn children(&self, id: Id) -> Vec<Id> {
        match self.node(id) {
            Node::Const(_) | Node::Sym(_) => Vec::new(),
            Node::Add(xs) | Node::Mul(xs) => xs.to_vec(),
            Node::Pow(a, b) | Node::Min(a, b) | Node::Max(a, b) => vec![*a, *b],
            Node::Func(_, a) => vec![*a],
            Node::Select(c, a, b) => vec![*c, *a, *b],
        }
    }

    /// Whether `id` depends on the symbol node `sym`.
    pub fn depends_on(&self, id: Id, sym: Id) -> bool {
        let mut seen = vec![false; self.nodes.len()];
        let mut stack = vec![id];
        while let Some(n) = stack.pop() {
            if n == sym {
                return true;
            }
            if !std::mem::replace(&mut seen[n.index()], true) {
                stack.extend(self.children(n));
            }
        }
        false
    }

    /// Nodes reachable from `roots`, children before parents, in a
    /// deterministic depth-first post-order.
    pub fn postorder(&self, roots: &[Id]) -> Vec<Id> {
        let mut seen = vec![false; self.nodes.len()];
        let mut order = Vec::new();
        for &root in roots {
            // Iterative DFS: (node, children expanded?)
            let mut stack = vec![(root, false)];
            while let Some((n, expanded)) = stack.pop() {
                if expanded {
                    order.push(n);
                    continue;
                }
                if seen[n.index()] {
                    continue;
                }
                seen[n.index()] = true;
                stack.push((n, true));
                for c in self.children(n).into_iter().rev() {
                    if !seen[c.index()] {
                        stack.push((c, false));
                    }
                }
            }
        }
        order
    }

    /// Number of distinct nodes reachable from `roots` (the DAG size).
    pub fn dag_size(&self, roots: &[Id]) -> usize {
        self.postorder(roots).len()
    }
}
