//! Symbolic differentiation.
//!
//! Input: a node and a variable. Output: the partial derivative, built through the
//! graph's constructors (so it is canonical in a canonical graph). Results are memoised
//! per `(node, variable)`; nodes that structurally cannot depend on the variable's kind
//! (see [`Deps`]) short-circuit to 0. The per-operation rules live in `op.rs`; this file
//! is only the chain rule.
//!
//! **Sparse models.** In a canonical graph a node whose variable set
//! ([`Graph::var_set`]) lacks `v` has the derivative 0, so differentiation skips it —
//! once the node is *primed* for `v`'s kind. The first differentiation by a variable of a
//! kind that reaches a node walks it and every operand of that kind, creating the
//! operation's partials ([`partials`]) as the walk goes, whether `v` occurs or not;
//! later ones enter only the operands that hold `v`, which creates no node the full walk
//! would not have created, in the same order. So the graph (node ids, hence the order of
//! canonical sums and the emitted code) is exactly that of the walk without the skip,
//! while the cost of `∂e/∂v` over all `v` of a sparse expression falls from
//! `O(n · |e|)` to about `|e|` times the few variables per node. A raw graph (which
//! keeps the products by zero) always takes the full walk.

use super::graph::{Deps, ExprId, Graph, Node, Var};
use super::op::{partials, partials_where};

/// `∂e/∂v`.
pub fn differentiate(g: &mut Graph, e: ExprId, v: Var) -> ExprId {
    let kind = Deps::of(v);
    if !g.deps(e).has(kind) {
        return g.constant(0.0);
    }
    let canonical = g.is_canonical();
    let skipping = g.skips_absent();
    let primed = skipping && g.primed[e.index()] & kind.bits() != 0;
    if primed && !g.depends_on(e, v) {
        return g.constant(0.0);
    }
    if let Some(&d) = g.diff_memo.get(&(e, v)) {
        return d;
    }
    let d = match g.node(e).clone() {
        Node::Const(_) => g.constant(0.0),
        Node::Var(w) => g.constant(if w == v { 1.0 } else { 0.0 }),
        _ => {
            // Primed: only the operands holding `v` (their partials exist already).
            let pairs = if primed {
                let args = g.node(e).args();
                let keep: Vec<bool> = args.iter().map(|&a| g.depends_on(a, v)).collect();
                partials_where(g, e, &|k| keep[k])
            } else {
                partials(g, e)
            };
            let mut terms = Vec::new();
            for (arg, partial) in pairs {
                let da = differentiate(g, arg, v);
                if canonical && g.is_zero(da) {
                    continue;
                }
                terms.push(g.mul(vec![partial, da]));
            }
            g.add(terms)
        }
    };
    if skipping {
        g.primed[e.index()] |= kind.bits();
    }
    g.diff_memo.insert((e, v), d);
    d
}

/// The rate of `e` along the motion at `q̈ = 0`: `Σ_i ∂e/∂q_i · q̇_i + ∂e/∂t`, with the
/// velocities (and every other variable) held fixed.
///
/// Forward mode: each node's rate is built from its operands' rates and the operation's
/// partials (`op.rs`), memoised per node, so the result is one pass over `e`'s DAG. The
/// same sum by [`directional`] builds a partial derivative per coordinate, each a walk of
/// the expression, and adds them: for the velocities and accelerations of a spatial
/// mechanism, whose positions depend on many coordinates through shared rotations, that
/// is several times larger (see docs/decisions/0006-rigid-bodies-by-kanes-method.md).
pub fn rate(g: &mut Graph, e: ExprId) -> ExprId {
    let moving = Deps::Q.bits() | Deps::TIME.bits();
    if g.deps(e).bits() & moving == 0 {
        return g.constant(0.0);
    }
    if let Some(&d) = g.rate_memo.get(&e) {
        return d;
    }
    let d = match g.node(e).clone() {
        Node::Const(_) => g.constant(0.0),
        Node::Var(Var::Q(i)) => g.var(Var::Qd(i)),
        Node::Var(Var::Time) => g.constant(1.0),
        Node::Var(_) => g.constant(0.0),
        _ => {
            let args = g.node(e).args();
            let keep: Vec<bool> = args
                .iter()
                .map(|&a| g.deps(a).bits() & moving != 0)
                .collect();
            let pairs = partials_where(g, e, &|k| keep[k]);
            let mut terms = Vec::new();
            for (arg, partial) in pairs {
                if g.deps(arg).bits() & moving == 0 {
                    continue;
                }
                let da = rate(g, arg);
                if g.is_canonical() && g.is_zero(da) {
                    continue;
                }
                terms.push(g.mul(vec![partial, da]));
            }
            g.add(terms)
        }
    };
    g.rate_memo.insert(e, d);
    d
}

/// Declares `r` the rate of `e` (as [`rate`] would return it, at `q̈ = 0`) when `e` has
/// none yet: a caller that knows a cheaper expression of the same function (a rotation
/// matrix's `Ȧ = A ω̃`) gives it, and every later rate through `e` uses it. `r` must
/// equal the rate for every state, or the derivatives built on it are wrong.
pub fn declare_rate(g: &mut Graph, e: ExprId, r: ExprId) {
    let moving = Deps::Q.bits() | Deps::TIME.bits();
    if g.deps(e).bits() & moving == 0 || matches!(g.node(e), Node::Var(_)) {
        return;
    }
    g.rate_memo.entry(e).or_insert(r);
}

/// The directional derivative `Σ_i ∂e/∂x_i · w_i` for pairs `(x_i, w_i)`.
///
/// Variables absent from `e` are skipped once `e` is primed for their kind (the first
/// pair of each kind is always differentiated, which primes `e` as the full loop would).
pub fn directional(g: &mut Graph, e: ExprId, pairs: &[(Var, ExprId)]) -> ExprId {
    let mut terms = Vec::new();
    for &(v, w) in pairs {
        if g.skips_absent() && g.primed[e.index()] & Deps::of(v).bits() != 0 && !g.depends_on(e, v)
        {
            continue;
        }
        let d = differentiate(g, e, v);
        if g.is_canonical() && g.is_zero(d) {
            continue;
        }
        terms.push(g.mul(vec![d, w]));
    }
    g.add(terms)
}

/// Calls `f(g, j, ∂e/∂x_j)` for the non-zero partial derivatives by `x_j = var(j)`,
/// `j = 0 … n−1`, in increasing `j`: the same calls, with the graph in the same state
/// (nodes `f` creates included), as differentiating by every `x_j` in turn and skipping
/// zeros, but visiting only the variables that occur in `e` once `e` is primed by the
/// first.
pub fn for_each_partial(
    g: &mut Graph,
    e: ExprId,
    n: usize,
    var: impl Fn(u32) -> Var,
    f: &mut dyn FnMut(&mut Graph, u32, ExprId),
) {
    let index = |j: usize| u32::try_from(j).expect("variable index fits u32");
    if n == 0 {
        return;
    }
    if !g.skips_absent() {
        for j in 0..n {
            let d = differentiate(g, e, var(index(j)));
            if !g.is_zero(d) {
                f(g, index(j), d);
            }
        }
        return;
    }
    // The first variable primes `e` for its kind, as the loop over every `j` would.
    let first = var(0);
    let d0 = differentiate(g, e, first);
    if !g.is_zero(d0) {
        f(g, 0, d0);
    }
    let set = g.var_set(e);
    for &v in set.iter() {
        let j = match (first, v) {
            (Var::Q(_), Var::Q(j))
            | (Var::Qd(_), Var::Qd(j))
            | (Var::Delta(_), Var::Delta(j))
            | (Var::Param(_), Var::Param(j))
            | (Var::Input(_), Var::Input(j))
            | (Var::Data(_), Var::Data(j)) => j,
            _ => continue,
        };
        if j == 0 || j as usize >= n || var(j) != v {
            continue;
        }
        let d = differentiate(g, e, v);
        if !g.is_zero(d) {
            f(g, j, d);
        }
    }
}

/// The non-zero `(j, ∂e/∂x_j)` of [`for_each_partial`], in increasing `j`.
pub fn gradient(
    g: &mut Graph,
    e: ExprId,
    n: usize,
    var: impl Fn(u32) -> Var,
) -> Vec<(u32, ExprId)> {
    let mut out = Vec::new();
    for_each_partial(g, e, n, var, &mut |_, j, d| out.push((j, d)));
    out
}
