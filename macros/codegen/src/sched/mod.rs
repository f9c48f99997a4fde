//! Scheduling: output expressions → straight-line code.
//!
//! Input: a graph and the root expressions of one generated function, in output order.
//! Output: a [`Program`]: the variables it reads, the temporaries in evaluation order
//! and the roots. Only nodes used more than once (by other live nodes or as several
//! outputs) get a temporary; everything else is inlined at its single use. Temporaries
//! are numbered in schedule order, so the same input always gives the same program.
//!
//! **Contractions.** With run-time data slots ([`schedule_with`]), a sum whose terms
//! include `c · D[d₀ + k s] · x_{i₀ + k}` for `k = 0 … L−1` (`L ≥` [`MIN_RUN`]: one data
//! slot read with a constant stride against consecutive coordinates or velocities, the
//! shape of every product of an invariant matrix of a deformable body with `q_f` or
//! `q̇_f`) keeps those terms as one [`Run`], which the emitter prints as a loop over the
//! slices. The absorbed products are not scheduled, so neither they nor the data
//! entries they read become statements: the code of a body of `n` modes grows like `n`
//! per contraction instead of `n²` overall.
//!
//! **Sine–cosine pairs.** Where both `sin u` and `cos u` of one argument are live, both
//! get a temporary (even when used once) and the pair is recorded in
//! [`Program::partner`]: the emitter defines the two with one call of
//! `::pfaff::math::sin_cos`, which reduces `u` once.

mod runs;

use std::collections::{BTreeSet, HashMap};
use std::ops::Range;

use crate::sym::{ExprId, Func, Graph, Node, Var};

pub use runs::{Run, MIN_RUN};

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
    /// Sums with contractions: the runs and the terms left to print one by one.
    pub runs: HashMap<ExprId, (Vec<Run>, Vec<ExprId>)>,
    /// The first coordinate or velocity of each run (what the runs read of `q`, `q̇`).
    pub run_vars: BTreeSet<Var>,
    /// For `sin u` its live `cos u` and the other way round: both are temporaries.
    pub partner: HashMap<ExprId, ExprId>,
}

impl Program {
    /// The temporary bound to `id`, if any.
    pub fn temp(&self, id: ExprId) -> Option<usize> {
        self.temp_of.get(id.index()).copied().flatten()
    }

    /// Whether the program reads a variable for which `pred` holds (as a leaf or
    /// through a run).
    pub fn reads(&self, pred: impl Fn(&Var) -> bool) -> bool {
        self.vars.iter().chain(&self.run_vars).any(pred)
    }

    /// The nodes and the variables (as leaves) that `roots`, some of this program's,
    /// need: what a function must compute when only those outputs are asked for. A
    /// sine needs its paired cosine and the other way round (one call defines both).
    /// Every other node is needed only by the remaining roots.
    pub fn needed(&self, g: &Graph, roots: &[ExprId]) -> (Vec<bool>, BTreeSet<Var>) {
        let mut needed = vec![false; g.len()];
        let mut vars = BTreeSet::new();
        let mut stack = roots.to_vec();
        while let Some(id) = stack.pop() {
            if needed[id.index()] {
                continue;
            }
            needed[id.index()] = true;
            if let Some(&other) = self.partner.get(&id) {
                stack.push(other);
            }
            match g.node(id) {
                Node::Var(v) => {
                    vars.insert(*v);
                }
                node => match self.runs.get(&id) {
                    Some((_, rest)) => stack.extend(rest.iter().copied()),
                    None => stack.extend(node.args()),
                },
            }
        }
        (needed, vars)
    }
}

/// Schedules `roots` into straight-line code.
pub fn schedule(g: &Graph, roots: &[ExprId]) -> Program {
    schedule_with(g, roots, &[])
}

/// Schedules `roots`, keeping contractions over the data `slots` (ranges of
/// `Var::Data` indices, one per slot) as runs.
pub fn schedule_with(g: &Graph, roots: &[ExprId], slots: &[Range<u32>]) -> Program {
    let mut runs = HashMap::new();
    // Post-order of the live nodes; a sum with runs has only its remaining terms as
    // operands.
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
        let kids = match g.node(id) {
            Node::Add(terms) if !slots.is_empty() => match runs::find(g, terms, slots) {
                Some((r, rest)) => {
                    let kids = rest.clone();
                    runs.insert(id, (r, rest));
                    kids
                }
                None => terms.to_vec(),
            },
            node => node.args(),
        };
        for a in kids.into_iter().rev() {
            if !seen[a.index()] {
                stack.push((a, false));
            }
        }
    }
    let mut uses = vec![0u32; g.len()];
    let mut vars = BTreeSet::new();
    for &id in &order {
        match g.node(id) {
            Node::Var(v) => {
                vars.insert(*v);
            }
            node => {
                let kids = match runs.get(&id) {
                    Some((_, rest)) => rest.clone(),
                    None => node.args(),
                };
                for a in kids {
                    uses[a.index()] += 1;
                }
            }
        }
    }
    for r in roots {
        uses[r.index()] += 1;
    }
    let partner = sin_cos_pairs(g, &order);
    let mut temp_of = vec![None; g.len()];
    let mut lets = Vec::new();
    for &id in &order {
        let leaf = matches!(g.node(id), Node::Const(_) | Node::Var(_));
        if !leaf && (uses[id.index()] >= 2 || partner.contains_key(&id)) {
            temp_of[id.index()] = Some(lets.len());
            lets.push(id);
        }
    }
    let run_vars = runs
        .values()
        .flat_map(|(r, _)| r.iter().map(|r| r.first))
        .collect();
    Program {
        vars,
        lets,
        temp_of,
        roots: roots.to_vec(),
        runs,
        run_vars,
        partner,
    }
}

/// The live `sin u` and `cos u` of a common argument `u`, each mapped to the other.
fn sin_cos_pairs(g: &Graph, order: &[ExprId]) -> HashMap<ExprId, ExprId> {
    let mut sines = HashMap::new();
    for &id in order {
        if let Node::Call(Func::Sin, u) = g.node(id) {
            sines.insert(*u, id);
        }
    }
    let mut partner = HashMap::new();
    for &id in order {
        if let Node::Call(Func::Cos, u) = g.node(id) {
            if let Some(&s) = sines.get(u) {
                partner.insert(s, id);
                partner.insert(id, s);
            }
        }
    }
    partner
}
