//! Whole-graph transformations: numeric evaluation, substitution of variables, and the
//! simplification pass that rebuilds nodes of one graph through the canonical
//! constructors of another.
//!
//! All walks are iterative post-order traversals with memo tables indexed by node id,
//! so shared subexpressions are visited once.

use super::graph::{ExprId, Graph, Node, Var};

/// Post-order of the nodes reachable from `roots` (operands before users), each once.
pub fn post_order(g: &Graph, roots: &[ExprId]) -> Vec<ExprId> {
    post_order_by(g, roots, |_, node| node.args())
}

/// [`post_order`] with the operands of each node given by `operands(id, node)` (a
/// schedule that reads some nodes through others).
pub fn post_order_by(
    g: &Graph,
    roots: &[ExprId],
    mut operands: impl FnMut(ExprId, &Node) -> Vec<ExprId>,
) -> Vec<ExprId> {
    let mut seen = vec![false; g.len()];
    let mut order = Vec::new();
    let mut stack: Vec<(ExprId, bool)> = roots.iter().rev().map(|&r| (r, false)).collect();
    while let Some((id, expanded)) = stack.pop() {
        if expanded {
            order.push(id);
            continue;
        }
        if seen[id.index()] {
            continue;
        }
        seen[id.index()] = true;
        stack.push((id, true));
        for a in operands(id, g.node(id)).into_iter().rev() {
            if !seen[a.index()] {
                stack.push((a, false));
            }
        }
    }
    order
}

/// Evaluates the `roots` numerically with the variable values given by `env`.
pub fn eval(g: &Graph, roots: &[ExprId], env: &dyn Fn(Var) -> f64) -> Vec<f64> {
    let mut val = vec![f64::NAN; g.len()];
    for id in post_order(g, roots) {
        let v = |a: ExprId| val[a.index()];
        val[id.index()] = match g.node(id) {
            Node::Const(b) => f64::from_bits(*b),
            Node::Var(x) => env(*x),
            Node::Add(a) => a.iter().map(|&x| v(x)).sum(),
            Node::Mul(a) => a.iter().map(|&x| v(x)).product(),
            Node::Powi(x, n) => v(*x).powi(*n),
            Node::Powf(x, y) => v(*x).powf(v(*y)),
            Node::Call(f, x) => f.eval(v(*x)),
            Node::Atan2(y, x) => v(*y).atan2(v(*x)),
        };
    }
    roots.iter().map(|r| val[r.index()]).collect()
}

/// Copies the expressions `roots` of `src` into `dst`, rebuilding every node through
/// `dst`'s constructors and replacing variables by `subst(var)` (built in `dst`).
/// With `dst` canonical this is the simplification pass.
pub fn rebuild(
    src: &Graph,
    dst: &mut Graph,
    roots: &[ExprId],
    subst: &mut dyn FnMut(&mut Graph, Var) -> ExprId,
) -> Vec<ExprId> {
    let mut map: Vec<Option<ExprId>> = vec![None; src.len()];
    for id in post_order(src, roots) {
        let new = match src.node(id) {
            Node::Var(v) => subst(dst, *v),
            node => {
                let lookup = |a: ExprId| map[a.index()].expect("operand rebuilt first");
                dst.rebuild(node, &lookup)
            }
        };
        map[id.index()] = Some(new);
    }
    roots
        .iter()
        .map(|r| map[r.index()].expect("root rebuilt"))
        .collect()
}

/// Substitutes variables inside one graph: `e[v := subst(v)]`.
pub fn substitute(
    g: &mut Graph,
    e: ExprId,
    subst: &mut dyn FnMut(&mut Graph, Var) -> Option<ExprId>,
) -> ExprId {
    let order = post_order(g, &[e]);
    let mut map: Vec<Option<ExprId>> = vec![None; g.len()];
    for id in order {
        let node = g.node(id).clone();
        let new = match node {
            Node::Var(v) => subst(g, v).unwrap_or(id),
            Node::Const(_) => id,
            node => {
                let lookup = |a: ExprId| map[a.index()].expect("operand substituted first");
                g.rebuild(&node, &lookup)
            }
        };
        if map.len() < g.len() {
            map.resize(g.len(), None);
        }
        map[id.index()] = Some(new);
    }
    map[e.index()].expect("root substituted")
}

/// Number of arithmetic operations to evaluate `roots` as trees (no sharing), counted
/// the way [`op_count`] counts a node. Saturates instead of overflowing.
pub fn tree_op_count(g: &Graph, roots: &[ExprId]) -> u128 {
    tree_op_counts(g, roots)
        .into_iter()
        .fold(0u128, u128::saturating_add)
}

/// [`tree_op_count`] of each root separately, in one pass over the graph.
pub fn tree_op_counts(g: &Graph, roots: &[ExprId]) -> Vec<u128> {
    let mut cost = vec![0u128; g.len()];
    for id in post_order(g, roots) {
        let own = node_ops(g.node(id));
        let sub: u128 = g
            .node(id)
            .args()
            .iter()
            .fold(0u128, |s, a| s.saturating_add(cost[a.index()]));
        cost[id.index()] = sub.saturating_add(own);
    }
    roots.iter().map(|r| cost[r.index()]).collect()
}

/// Number of arithmetic operations to evaluate `roots` with every shared node computed
/// once (the cost of the straight-line code the emitter writes).
pub fn op_count(g: &Graph, roots: &[ExprId]) -> u64 {
    post_order(g, roots)
        .iter()
        .map(|&id| node_ops(g.node(id)) as u64)
        .sum()
}

/// Operations of one node: `k − 1` for a sum or product of `k` operands, one per call or
/// power (a negation or a reciprocal folded into a product is counted as one operation
/// of the product).
fn node_ops(n: &Node) -> u128 {
    match n {
        Node::Const(_) | Node::Var(_) => 0,
        Node::Add(a) | Node::Mul(a) => a.len() as u128 - 1,
        Node::Powi(..) | Node::Powf(..) | Node::Call(..) | Node::Atan2(..) => 1,
    }
}
