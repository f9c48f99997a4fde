//! Scheduling: output expressions → straight-line code.
//!
//! Input: a graph and the root expressions of one generated function, in output order.
//! Output: a [`Program`]: the variables it reads, the temporaries in evaluation order
//! and the roots. Only nodes used more than once (by other live nodes or as several
//! outputs) get a temporary; everything else is inlined at its single use. Temporaries
//! are numbered in schedule order, so the same input always gives the same program.

use std::collections::BTreeSet;

use crate::sym::{transform, ExprId, Graph, Node, Var};

/// Straight-line code for one function.
#[derive(Debug)]
pub struct Program {
    /// Variables read, sorted.
    pub vars: BTreeSet<Var>,
    /// Nodes bound to temporaries, in evaluation order (temporary `k` is `lets[k]`).
    pub lets: Vec<ExprId>,
    /// For each node id, its temporary number if it has one.
    pub temp_of: Vec<Option<usize>>,
    /// The outputs.
    pub roots: Vec<ExprId>,
}

impl Program {
    /// The temporary bound to `id`, if any.
    pub fn temp(&self, id: ExprId) -> Option<usize> {
        self.temp_of.get(id.index()).copied().flatten()
    }
}

/// Schedules `roots` into straight-line code.
pub fn schedule(g: &Graph, roots: &[ExprId]) -> Program {
    let order = transform::post_order(g, roots);
    let mut uses = vec![0u32; g.len()];
    let mut vars = BTreeSet::new();
    for &id in &order {
        match g.node(id) {
            Node::Var(v) => {
                vars.insert(*v);
            }
            node => {
                for a in node.args() {
                    uses[a.index()] += 1;
                }
            }
        }
    }
    for r in roots {
        uses[r.index()] += 1;
    }
    let mut temp_of = vec![None; g.len()];
    let mut lets = Vec::new();
    for &id in &order {
        let leaf = matches!(g.node(id), Node::Const(_) | Node::Var(_));
        if !leaf && uses[id.index()] >= 2 {
            temp_of[id.index()] = Some(lets.len());
            lets.push(id);
        }
    }
    Program {
        vars,
        lets,
        temp_of,
        roots: roots.to_vec(),
    }
}
