//! Symbolic differentiation.
//!
//! Input: a node and a variable. Output: the partial derivative, built through the
//! graph's constructors (so it is canonical in a canonical graph). Results are memoised
//! per `(node, variable)`; nodes that structurally cannot depend on the variable's kind
//! (see [`Deps`]) short-circuit to 0. The per-operation rules live in `op.rs`; this file
//! is only the chain rule.

use super::graph::{Deps, ExprId, Graph, Node, Var};
use super::op::partials;

fn kind(v: Var) -> Deps {
    match v {
        Var::Time => Deps::TIME,
        Var::Q(_) => Deps::Q,
        Var::Qd(_) => Deps::QD,
        Var::Delta(_) => Deps::DELTA,
        Var::Param(_) => Deps::PARAM,
        Var::Input(_) => Deps::INPUT,
    }
}

/// `∂e/∂v`.
pub fn differentiate(g: &mut Graph, e: ExprId, v: Var) -> ExprId {
    if !g.deps(e).has(kind(v)) {
        return g.constant(0.0);
    }
    if let Some(&d) = g.diff_memo.get(&(e, v)) {
        return d;
    }
    let d = match g.node(e).clone() {
        Node::Const(_) => g.constant(0.0),
        Node::Var(w) => g.constant(if w == v { 1.0 } else { 0.0 }),
        _ => {
            let mut terms = Vec::new();
            for (arg, partial) in partials(g, e) {
                let da = differentiate(g, arg, v);
                if g.is_canonical() && g.is_zero(da) {
                    continue;
                }
                terms.push(g.mul(vec![partial, da]));
            }
            g.add(terms)
        }
    };
    g.diff_memo.insert((e, v), d);
    d
}

/// The directional derivative `Σ_i ∂e/∂x_i · w_i` for pairs `(x_i, w_i)`.
pub fn directional(g: &mut Graph, e: ExprId, pairs: &[(Var, ExprId)]) -> ExprId {
    let mut terms = Vec::new();
    for &(v, w) in pairs {
        let d = differentiate(g, e, v);
        if g.is_canonical() && g.is_zero(d) {
            continue;
        }
        terms.push(g.mul(vec![d, w]));
    }
    g.add(terms)
}
