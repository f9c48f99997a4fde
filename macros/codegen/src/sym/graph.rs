//! The hash-consed expression DAG.
//!
//! Input: calls to the smart constructors. Output: a [`Graph`] in which structurally
//! equal subexpressions are one node ([`ExprId`]).
//!
//! A graph is *canonical* (the default) or *raw*. In a canonical graph every constructor
//! returns a simplified node, so every node ever created is simplified and the
//! derivatives built from them stay simplified:
//! - constants are folded (including through the functions of the op table);
//! - sums and products are flattened, their operands sorted by id, like terms collected
//!   (`2x + 3x = 5x`, `x − x = 0`, `x · x = x²`, `x / x = 1`);
//! - `sin²u + cos²u = 1` (with equal coefficients and cofactors);
//! - integer powers are merged and distributed over products, `(√x)² = x`;
//! - a constant coefficient is distributed over a sum, `c(a + b) = ca + cb`;
//! - signs are pulled out of odd functions and dropped inside even ones.
//!
//! A raw graph only hash-conses: it keeps exactly what was written. Rebuilding a raw
//! graph into a canonical one (`simplify::rebuild`) is the simplification pass; the
//! property tests compare the two numerically.
//!
//! Negation, subtraction and division are not nodes: `−x = (−1)·x`, `a − b = a + (−1)·b`,
//! `a / b = a · b⁻¹`. The emitter turns them back into `-`, `-` and `/`.

use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

use super::op::Func;

/// Index of a node in a [`Graph`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ExprId(u32);

impl ExprId {
    /// The position of the node in creation order.
    pub fn index(self) -> usize {
        self.0 as usize
    }

    /// The id of the `i`-th node (for walks over a whole graph).
    pub fn from_index(i: usize) -> ExprId {
        ExprId(u32::try_from(i).expect("expression graph too large"))
    }
}

/// A leaf variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Var {
    /// Time `t`.
    Time,
    /// Generalized coordinate `q_i`.
    Q(u32),
    /// Generalized velocity `q̇_i`.
    Qd(u32),
    /// Virtual displacement `δq_i` (only inside virtual-work expressions).
    Delta(u32),
    /// Model parameter `p_i`.
    Param(u32),
    /// Entry `i` of a vector the caller passes at run time (the accelerations and
    /// multipliers at which the linearization Jacobian is evaluated).
    Input(u32),
    /// Entry `i` of the model's run-time data (its slots one after the other); a
    /// constant of the motion, like a parameter.
    Data(u32),
}

/// A node of the DAG.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Node {
    /// A constant, stored as `f64::to_bits`. `-0.0` is normalised to `0.0`: signed
    /// zeros are not preserved (only `atan2` on its branch cut could tell).
    Const(u64),
    /// A leaf variable.
    Var(Var),
    /// `Σ terms` (at least two).
    Add(Box<[ExprId]>),
    /// `Π factors` (at least two).
    Mul(Box<[ExprId]>),
    /// `x^n`, integer `n`.
    Powi(ExprId, i32),
    /// `x^y`, real `y`.
    Powf(ExprId, ExprId),
    /// A unary function of the op table.
    Call(Func, ExprId),
    /// `atan2(y, x)`.
    Atan2(ExprId, ExprId),
}

impl Node {
    /// The operands of the node, in order.
    pub fn args(&self) -> Vec<ExprId> {
        match self {
            Node::Const(_) | Node::Var(_) => Vec::new(),
            Node::Add(a) | Node::Mul(a) => a.to_vec(),
            Node::Powi(x, _) | Node::Call(_, x) => vec![*x],
            Node::Powf(a, b) | Node::Atan2(a, b) => vec![*a, *b],
        }
    }
}

/// Which kinds of variables a node depends on (a conservative structural summary).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Deps(u8);

impl Deps {
    pub const TIME: Deps = Deps(1);
    pub const Q: Deps = Deps(2);
    pub const QD: Deps = Deps(4);
    pub const DELTA: Deps = Deps(8);
    pub const PARAM: Deps = Deps(16);
    pub const INPUT: Deps = Deps(32);
    pub const DATA: Deps = Deps(64);

    /// The kind of a variable.
    pub fn of(v: Var) -> Deps {
        match v {
            Var::Time => Deps::TIME,
            Var::Q(_) => Deps::Q,
            Var::Qd(_) => Deps::QD,
            Var::Delta(_) => Deps::DELTA,
            Var::Param(_) => Deps::PARAM,
            Var::Input(_) => Deps::INPUT,
            Var::Data(_) => Deps::DATA,
        }
    }
    /// Whether any of the kinds in `other` is present.
    pub fn has(self, other: Deps) -> bool {
        self.0 & other.0 != 0
    }
    fn union(self, other: Deps) -> Deps {
        Deps(self.0 | other.0)
    }
    /// The bit of a single kind (for per-kind flags).
    pub(crate) fn bits(self) -> u8 {
        self.0
    }
}

/// The set of variables a node depends on: sorted, without repeats, shared between
/// nodes whose sets are equal to an operand's.
pub type VarSet = Arc<[Var]>;

/// The expression DAG.
#[derive(Debug)]
pub struct Graph {
    nodes: Vec<Node>,
    deps: Vec<Deps>,
    lookup: HashMap<Node, ExprId>,
    canonical: bool,
    pub(crate) diff_memo: HashMap<(ExprId, Var), ExprId>,
    /// Memo of `diff::rate`.
    pub(crate) rate_memo: HashMap<ExprId, ExprId>,
    /// Per node, its variable set once computed (lazily, by [`Graph::var_set`]).
    vars: Vec<Option<VarSet>>,
    /// Per node, the kinds ([`Deps`] bits) for which differentiation has visited the
    /// node and, through it, every operand of that kind (see `diff::differentiate`).
    pub(crate) primed: Vec<u8>,
    /// Whether differentiation skips absent variables (see `diff`); off only to compare
    /// with the full walk.
    pub(crate) skip_absent: bool,
}

/// The union of sorted variable sets, sharing an operand's set when it is the union.
fn union_sets(sets: &[VarSet]) -> VarSet {
    let Some(largest) = sets.iter().max_by_key(|s| s.len()) else {
        return Arc::from(Vec::new());
    };
    let mut all: Vec<Var> = sets.iter().flat_map(|s| s.iter().copied()).collect();
    all.sort_unstable();
    all.dedup();
    if all.len() == largest.len() {
        largest.clone()
    } else {
        Arc::from(all)
    }
}

impl Default for Graph {
    fn default() -> Self {
        Graph::new()
    }
}

impl Graph {
    /// A canonical (simplifying) graph.
    pub fn new() -> Graph {
        Graph {
            nodes: Vec::new(),
            deps: Vec::new(),
            lookup: HashMap::new(),
            canonical: true,
            diff_memo: HashMap::new(),
            rate_memo: HashMap::new(),
            vars: Vec::new(),
            primed: Vec::new(),
            skip_absent: true,
        }
    }

    /// A raw graph that only hash-conses.
    pub fn raw() -> Graph {
        Graph {
            canonical: false,
            ..Graph::new()
        }
    }

    /// A canonical graph whose differentiation walks every node of the variable's kind,
    /// as before variable sets existed: the reference the skipping walk must reproduce
    /// node for node.
    #[cfg(test)]
    pub(crate) fn full_walk() -> Graph {
        Graph {
            skip_absent: false,
            ..Graph::new()
        }
    }

    /// Whether differentiation may skip the nodes a variable is absent from.
    pub(crate) fn skips_absent(&self) -> bool {
        self.canonical && self.skip_absent
    }

    /// Whether constructors simplify.
    pub fn is_canonical(&self) -> bool {
        self.canonical
    }

    /// The node behind an id.
    pub fn node(&self, id: ExprId) -> &Node {
        &self.nodes[id.index()]
    }

    /// Dependency summary of a node.
    pub fn deps(&self, id: ExprId) -> Deps {
        self.deps[id.index()]
    }

    /// The variables node `id` depends on, sorted (computed once per node, on demand).
    /// Structural: a variable is in the set when a leaf of the node's subgraph is that
    /// variable, so `∂e/∂v` is the constant 0 (in a canonical graph) when `v` is absent.
    pub fn var_set(&mut self, id: ExprId) -> VarSet {
        if let Some(s) = &self.vars[id.index()] {
            return s.clone();
        }
        // Iterative post-order over the nodes whose sets are missing.
        let mut stack = vec![(id, false)];
        while let Some((x, expanded)) = stack.pop() {
            if self.vars[x.index()].is_some() {
                continue;
            }
            let args = self.nodes[x.index()].args();
            if !expanded {
                stack.push((x, true));
                for &a in args.iter().rev() {
                    if self.vars[a.index()].is_none() {
                        stack.push((a, false));
                    }
                }
                continue;
            }
            let set: VarSet = match &self.nodes[x.index()] {
                Node::Const(_) => Arc::from(Vec::new()),
                Node::Var(v) => Arc::from(vec![*v]),
                _ => {
                    let sets: Vec<VarSet> = args
                        .iter()
                        .map(|a| self.vars[a.index()].clone().expect("operand's set first"))
                        .collect();
                    union_sets(&sets)
                }
            };
            self.vars[x.index()] = Some(set);
        }
        self.vars[id.index()].clone().expect("set computed")
    }

    /// Whether node `id` depends on the variable `v` (see [`Graph::var_set`]).
    pub fn depends_on(&mut self, id: ExprId, v: Var) -> bool {
        if !self.deps(id).has(Deps::of(v)) {
            return false;
        }
        self.var_set(id).binary_search(&v).is_ok()
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the graph is empty.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The constant value of a node, if it is a constant.
    pub fn as_const(&self, id: ExprId) -> Option<f64> {
        match self.node(id) {
            Node::Const(b) => Some(f64::from_bits(*b)),
            _ => None,
        }
    }

    /// Whether the node is the constant 0.
    pub fn is_zero(&self, id: ExprId) -> bool {
        self.as_const(id) == Some(0.0)
    }

    /// Interns `node` exactly as given, without simplification (operands must exist).
    /// Only for passes over finished expressions (`share`): a canonical graph's
    /// constructors assume canonical operands.
    pub(crate) fn intern_as_is(&mut self, node: Node) -> ExprId {
        self.intern(node)
    }

    fn intern(&mut self, node: Node) -> ExprId {
        if let Some(&id) = self.lookup.get(&node) {
            return id;
        }
        let deps = match &node {
            Node::Const(_) => Deps::default(),
            Node::Var(v) => Deps::of(*v),
            other => other
                .args()
                .iter()
                .fold(Deps::default(), |d, a| d.union(self.deps[a.index()])),
        };
        let id = ExprId(u32::try_from(self.nodes.len()).expect("expression graph too large"));
        self.nodes.push(node.clone());
        self.deps.push(deps);
        self.vars.push(None);
        self.primed.push(0);
        self.lookup.insert(node, id);
        id
    }

    /// A constant.
    pub fn constant(&mut self, v: f64) -> ExprId {
        let v = if v == 0.0 { 0.0 } else { v };
        self.intern(Node::Const(v.to_bits()))
    }

    /// A leaf variable.
    pub fn var(&mut self, v: Var) -> ExprId {
        self.intern(Node::Var(v))
    }

    /// `−x`.
    pub fn neg(&mut self, x: ExprId) -> ExprId {
        let m = self.constant(-1.0);
        self.mul(vec![m, x])
    }

    /// `a − b`.
    pub fn sub(&mut self, a: ExprId, b: ExprId) -> ExprId {
        let nb = self.neg(b);
        self.add(vec![a, nb])
    }

    /// `a / b`.
    pub fn div(&mut self, a: ExprId, b: ExprId) -> ExprId {
        let ib = self.powi(b, -1);
        self.mul(vec![a, ib])
    }

    /// `Σ terms`. Canonical sums hold the constant term first, then the other terms
    /// sorted by id.
    pub fn add(&mut self, terms: Vec<ExprId>) -> ExprId {
        if !self.canonical {
            return match terms.len() {
                0 => self.constant(0.0),
                1 => terms[0],
                _ => self.intern(Node::Add(terms.into())),
            };
        }
        // Flatten, then group terms by their non-constant part, summing coefficients.
        let mut constant = 0.0;
        let mut groups: BTreeMap<ExprId, f64> = BTreeMap::new();
        let mut stack = terms;
        while let Some(t) = stack.pop() {
            match self.node(t).clone() {
                Node::Const(b) => constant += f64::from_bits(b),
                Node::Add(inner) => stack.extend(inner.iter().copied()),
                _ => {
                    let (c, rest) = self.split_coefficient(t);
                    *groups.entry(rest).or_insert(0.0) += c;
                }
            }
        }
        groups.retain(|_, c| *c != 0.0);
        self.pythagoras(&mut groups, &mut constant);
        let mut out = Vec::with_capacity(groups.len() + 1);
        for (rest, c) in groups {
            out.push(self.scale(c, rest));
        }
        out.sort();
        if constant != 0.0 {
            out.insert(0, self.constant(constant));
        }
        match out.len() {
            0 => self.constant(0.0),
            1 => out[0],
            _ => self.intern(Node::Add(out.into())),
        }
    }

    /// `c · x` for a non-constant canonical `x` that carries no coefficient.
    fn scale(&mut self, c: f64, x: ExprId) -> ExprId {
        if c == 1.0 {
            return x;
        }
        let k = self.constant(c);
        let mut factors = match self.node(x) {
            Node::Mul(f) => f.to_vec(),
            _ => vec![x],
        };
        factors.insert(0, k);
        self.intern(Node::Mul(factors.into()))
    }

    /// Splits a canonical term into `(coefficient, rest)`.
    fn split_coefficient(&mut self, t: ExprId) -> (f64, ExprId) {
        if let Node::Mul(f) = self.node(t) {
            if let Some(c) = self.as_const(f[0]) {
                let rest: Vec<ExprId> = f[1..].to_vec();
                let rest = if rest.len() == 1 {
                    rest[0]
                } else {
                    self.intern(Node::Mul(rest.into()))
                };
                return (c, rest);
            }
        }
        (1.0, t)
    }

    /// `c·R·sin²u + c·R·cos²u → c·R`, applied to grouped terms.
    fn pythagoras(&mut self, groups: &mut BTreeMap<ExprId, f64>, constant: &mut f64) {
        let candidates: Vec<(ExprId, f64)> = groups.iter().map(|(&r, &c)| (r, c)).collect();
        for (rest, c) in candidates {
            if !groups.contains_key(&rest) {
                continue;
            }
            let factors = match self.node(rest) {
                Node::Mul(f) => f.to_vec(),
                _ => vec![rest],
            };
            for (k, &f) in factors.iter().enumerate() {
                let Node::Powi(base, 2) = *self.node(f) else {
                    continue;
                };
                let Node::Call(Func::Sin, u) = *self.node(base) else {
                    continue;
                };
                let cos = self.call(Func::Cos, u);
                let cos2 = self.powi(cos, 2);
                let mut partner: Vec<ExprId> = factors.clone();
                partner[k] = cos2;
                let mut others: Vec<ExprId> = factors.clone();
                others.remove(k);
                let partner = self.mul(partner);
                if groups.get(&partner) == Some(&c) {
                    groups.remove(&rest);
                    groups.remove(&partner);
                    let r = self.mul(others);
                    if let Some(v) = self.as_const(r) {
                        *constant += c * v;
                    } else {
                        let (c2, r2) = self.split_coefficient(r);
                        *groups.entry(r2).or_insert(0.0) += c * c2;
                    }
                    break;
                }
            }
        }
        groups.retain(|_, c| *c != 0.0);
    }

    /// `Π factors`. Canonical products hold the coefficient first, then the other
    /// factors sorted by id.
    pub fn mul(&mut self, factors: Vec<ExprId>) -> ExprId {
        if !self.canonical {
            return match factors.len() {
                0 => self.constant(1.0),
                1 => factors[0],
                _ => self.intern(Node::Mul(factors.into())),
            };
        }
        let mut coefficient = 1.0;
        // Exponents are summed in `i64`: a sum of `i32` exponents can leave `i32`.
        let mut powers: BTreeMap<ExprId, i64> = BTreeMap::new();
        let mut stack = factors;
        while let Some(f) = stack.pop() {
            match self.node(f).clone() {
                Node::Const(b) => coefficient *= f64::from_bits(b),
                Node::Mul(inner) => stack.extend(inner.iter().copied()),
                Node::Powi(base, n) => *powers.entry(base).or_insert(0) += i64::from(n),
                _ => *powers.entry(f).or_insert(0) += 1,
            }
        }
        if coefficient == 0.0 {
            return self.constant(0.0);
        }
        // `c · (a + b) = c·a + c·b`: distributing a lone coefficient lets like terms
        // meet (`½(2a + 2b) − a = b`).
        if coefficient != 1.0 && powers.len() == 1 {
            let (&base, &n) = powers.iter().next().expect("one factor");
            if n == 1 {
                if let Node::Add(terms) = self.node(base).clone() {
                    let c = self.constant(coefficient);
                    let scaled = terms.iter().map(|&t| self.mul(vec![c, t])).collect();
                    return self.add(scaled);
                }
            }
        }
        let mut out = Vec::with_capacity(powers.len() + 1);
        for (base, n) in powers {
            if let Ok(n) = i32::try_from(n) {
                if n != 0 {
                    out.push(self.powi_node(base, n));
                }
                continue;
            }
            // Beyond `i32`: `xⁿ = (x^MAX)^k · xʳ` with `n = k·MAX + r`, `|k| < 2³¹`.
            let m = i64::from(i32::MAX);
            let k = i32::try_from(n / m).expect("a product has fewer than 2^31 factors");
            let r = i32::try_from(n % m).expect("|n mod MAX| < MAX");
            let whole = self.powi_node(base, i32::MAX);
            out.push(if k == 1 {
                whole
            } else {
                self.intern(Node::Powi(whole, k))
            });
            if r != 0 {
                out.push(self.powi_node(base, r));
            }
        }
        out.sort();
        if coefficient != 1.0 {
            out.insert(0, self.constant(coefficient));
        }
        match out.len() {
            0 => self.constant(coefficient),
            1 => out[0],
            _ => self.intern(Node::Mul(out.into())),
        }
    }

    /// `x^n` for a base that is neither a constant nor a product nor a power.
    fn powi_node(&mut self, x: ExprId, n: i32) -> ExprId {
        match n {
            1 => x,
            _ => {
                if let Node::Call(Func::Sqrt, inner) = *self.node(x) {
                    if n % 2 == 0 {
                        return self.powi(inner, n / 2);
                    }
                }
                self.intern(Node::Powi(x, n))
            }
        }
    }

    /// `x^n`.
    pub fn powi(&mut self, x: ExprId, n: i32) -> ExprId {
        if !self.canonical {
            return self.intern(Node::Powi(x, n));
        }
        if n == 0 {
            return self.constant(1.0);
        }
        if n == 1 {
            return x;
        }
        match self.node(x).clone() {
            Node::Const(b) => self.constant(f64::from_bits(b).powi(n)),
            Node::Powi(base, m) => match m.checked_mul(n) {
                Some(k) => self.powi(base, k),
                None => self.intern(Node::Powi(x, n)),
            },
            Node::Mul(f) => {
                let parts: Vec<ExprId> = f.iter().map(|&a| self.powi(a, n)).collect();
                self.mul(parts)
            }
            _ => self.powi_node(x, n),
        }
    }

    /// `x^y`.
    pub fn powf(&mut self, x: ExprId, y: ExprId) -> ExprId {
        if !self.canonical {
            return self.intern(Node::Powf(x, y));
        }
        if let Some(e) = self.as_const(y) {
            if e.fract() == 0.0 && e.abs() <= f64::from(i32::MAX) {
                #[allow(clippy::cast_possible_truncation)]
                return self.powi(x, e as i32);
            }
            if e == 0.5 {
                return self.call(Func::Sqrt, x);
            }
            if let Some(b) = self.as_const(x) {
                return self.constant(b.powf(e));
            }
        }
        self.intern(Node::Powf(x, y))
    }

    /// `f(x)` for a function of the op table.
    pub fn call(&mut self, f: Func, x: ExprId) -> ExprId {
        if !self.canonical {
            return self.intern(Node::Call(f, x));
        }
        if let Some(v) = self.as_const(x) {
            return self.constant(f.eval(v));
        }
        // Pull a negative coefficient out of odd functions, drop it inside even ones.
        if f.is_odd() || f.is_even() {
            if let Node::Mul(fs) = self.node(x) {
                if self.as_const(fs[0]).is_some_and(|c| c < 0.0) {
                    let nx = self.neg(x);
                    let r = self.call(f, nx);
                    return if f.is_odd() { self.neg(r) } else { r };
                }
            }
        }
        match (f, self.node(x).clone()) {
            (Func::Exp, Node::Call(Func::Ln, y)) | (Func::Ln, Node::Call(Func::Exp, y)) => y,
            (Func::Abs, Node::Call(Func::Abs, _)) => x,
            (Func::Signum, Node::Call(Func::Signum, _)) => x,
            _ => self.intern(Node::Call(f, x)),
        }
    }

    /// `atan2(y, x)`.
    pub fn atan2(&mut self, y: ExprId, x: ExprId) -> ExprId {
        if self.canonical {
            if let (Some(a), Some(b)) = (self.as_const(y), self.as_const(x)) {
                return self.constant(a.atan2(b));
            }
        }
        self.intern(Node::Atan2(y, x))
    }

    /// Rebuilds `node` (whose operands have been mapped already) through the
    /// constructors of this graph.
    pub fn rebuild(&mut self, node: &Node, map: &impl Fn(ExprId) -> ExprId) -> ExprId {
        match node {
            Node::Const(b) => self.constant(f64::from_bits(*b)),
            Node::Var(v) => self.var(*v),
            Node::Add(a) => {
                let a = a.iter().map(|&x| map(x)).collect();
                self.add(a)
            }
            Node::Mul(a) => {
                let a = a.iter().map(|&x| map(x)).collect();
                self.mul(a)
            }
            Node::Powi(x, n) => self.powi(map(*x), *n),
            Node::Powf(x, y) => self.powf(map(*x), map(*y)),
            Node::Call(f, x) => self.call(*f, map(*x)),
            Node::Atan2(y, x) => self.atan2(map(*y), map(*x)),
        }
    }
}
