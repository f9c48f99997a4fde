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
//! `::pfaff::math::sin_cos`, which reduces `u` once. Pairs of plain variables (a
//! joint angle), or of sums and products of variables read by the pair alone (an
//! absolute angle as a sum of relative ones, printed inside the call), go two by two,
//! in schedule order and apart for arguments that read velocities, into
//! [`Program::twins`]: the emitter
//! defines two such pairs with one call of `::pfaff::math::sin_cos2`, which computes
//! both in the two lanes of a register (bitwise the results of two calls).

mod runs;

use std::collections::{BTreeSet, HashMap};
use std::ops::Range;

use crate::sym::transform::post_order_by;
use crate::sym::{Deps, ExprId, Func, Graph, Node, Var};

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
    /// The pairs defined from the pairs of two angles they sum, by sine and by cosine.
    pub angle_sums: HashMap<ExprId, AngleSum>,
    /// For the defining member (the earlier temporary) of a [`partner`](Self::partner)
    /// pair of a plain variable or of a sum or product of variables read by the pair
    /// alone, that of the pair it shares a `sin_cos2` call with, and the other way
    /// round: the earlier of the two defines both. Both arguments read velocities, or
    /// neither does.
    pub twins: HashMap<ExprId, ExprId>,
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
    /// sine needs its paired cosine and the other way round (one call defines both),
    /// and a pair its twin.
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
            if let Some(&other) = self.twins.get(&id) {
                stack.push(other);
            }
            if let Some(sum) = self.angle_sums.get(&id) {
                stack.extend(sum.operands());
                continue;
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
    let order = live_order(g, roots, slots, &mut runs, &HashMap::new());
    let mut partner = sin_cos_pairs(g, &order);
    let mut angle_sums = angle_sums(g, &partner);
    // The pairs of a sum of angles read the pairs of its terms, not the sum: schedule
    // again with those operands. A pair live only through a sum no longer read is
    // then dead, so the pairs are taken again from the live nodes.
    let order = if angle_sums.is_empty() {
        order
    } else {
        let order = live_order(g, roots, slots, &mut runs, &angle_sums);
        partner = sin_cos_pairs(g, &order);
        angle_sums.retain(|id, _| partner.contains_key(id));
        order
    };
    let mut uses = vec![0u32; g.len()];
    let mut vars = BTreeSet::new();
    for &id in &order {
        match g.node(id) {
            Node::Var(v) => {
                vars.insert(*v);
            }
            node => {
                let kids = match (runs.get(&id), angle_sums.get(&id)) {
                    (_, Some(sum)) => sum.operands().to_vec(),
                    (Some((_, rest)), None) => rest.clone(),
                    (None, None) => node.args(),
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
    let inline = inline_arguments(g, &partner, &angle_sums, &uses);
    let mut temp_of = vec![None; g.len()];
    let mut lets = Vec::new();
    for &id in &order {
        let leaf = matches!(g.node(id), Node::Const(_) | Node::Var(_));
        if !leaf && !inline.contains(&id) && (uses[id.index()] >= 2 || partner.contains_key(&id)) {
            temp_of[id.index()] = Some(lets.len());
            lets.push(id);
        }
    }
    let run_vars = runs
        .values()
        .flat_map(|(r, _)| r.iter().map(|r| r.first))
        .collect();
    let twins = twins(g, &lets, &temp_of, &partner, &angle_sums, &inline);
    Program {
        vars,
        lets,
        temp_of,
        roots: roots.to_vec(),
        runs,
        run_vars,
        partner,
        angle_sums,
        twins,
    }
}

/// The arguments of sine–cosine pairs (not defined from a sum's pairs) that are sums
/// or products of variables and constants read by the pair alone, with no other node
/// in them read twice: printed inline in the pair's call rather than bound to a
/// temporary, they read only variables, so they are available wherever a call of
/// `sin_cos2` defines their pair with another (a joint's absolute angle as the sum of
/// relative angles, `2 q`).
fn inline_arguments(
    g: &Graph,
    partner: &HashMap<ExprId, ExprId>,
    angle_sums: &HashMap<ExprId, AngleSum>,
    uses: &[u32],
) -> BTreeSet<ExprId> {
    // Leaves, or sums and products of them and of such nodes read once.
    fn of_variables(g: &Graph, id: ExprId, uses: &[u32]) -> bool {
        match g.node(id) {
            Node::Const(_) | Node::Var(_) => true,
            Node::Add(a) | Node::Mul(a) => a
                .iter()
                .all(|&x| is_leaf(g, x) || (uses[x.index()] == 1 && of_variables(g, x, uses))),
            _ => false,
        }
    }
    fn is_leaf(g: &Graph, id: ExprId) -> bool {
        matches!(g.node(id), Node::Const(_) | Node::Var(_))
    }
    partner
        .keys()
        .filter(|id| !angle_sums.contains_key(id))
        .filter_map(|&id| match g.node(id) {
            Node::Call(Func::Sin, u) => Some(*u),
            _ => None,
        })
        .filter(|&u| {
            matches!(g.node(u), Node::Add(_) | Node::Mul(_))
                && uses[u.index()] == 2
                && of_variables(g, u, uses)
        })
        .collect()
}

/// [`Program::twins`]: the defining members of the sine–cosine pairs whose argument is
/// a variable or one of the [`inline_arguments`] (read at the top of the function or
/// computed from what is, so available wherever the earlier of two is defined), two by
/// two in schedule order among those whose argument reads no velocity and among those
/// whose argument does, each mapped to the other.
fn twins(
    g: &Graph,
    lets: &[ExprId],
    temp_of: &[Option<usize>],
    partner: &HashMap<ExprId, ExprId>,
    angle_sums: &HashMap<ExprId, AngleSum>,
    inline: &BTreeSet<ExprId>,
) -> HashMap<ExprId, ExprId> {
    let defining = lets.iter().enumerate().filter_map(|(k, &id)| {
        let other = *partner.get(&id)?;
        let first = temp_of[other.index()].is_some_and(|j| j > k);
        let u = match g.node(id) {
            Node::Call(Func::Sin | Func::Cos, u) => *u,
            _ => return None,
        };
        let available = matches!(g.node(u), Node::Var(_)) || inline.contains(&u);
        (first && !angle_sums.contains_key(&id) && available).then_some(id)
    });
    // Pairs of positions and pairs that read velocities apart: a function that corrects
    // the velocities midway (`emit::corrected`) defines the first before the
    // correction and the second after it.
    let (moving, fixed): (Vec<ExprId>, Vec<ExprId>) = defining.partition(|&id| {
        g.node(id)
            .args()
            .first()
            .is_some_and(|&u| g.deps(u).has(Deps::QD))
    });
    let mut twins = HashMap::new();
    for two in fixed.chunks_exact(2).chain(moving.chunks_exact(2)) {
        twins.insert(two[0], two[1]);
        twins.insert(two[1], two[0]);
    }
    twins
}

/// The post-order of the live nodes of `roots`. A sum with runs (found over `slots`
/// and recorded in `runs`) has only its remaining terms as operands, and the sine and
/// cosine of a sum of angles in `sums` the pairs of its terms instead of the sum.
fn live_order(
    g: &Graph,
    roots: &[ExprId],
    slots: &[Range<u32>],
    runs: &mut HashMap<ExprId, (Vec<Run>, Vec<ExprId>)>,
    sums: &HashMap<ExprId, AngleSum>,
) -> Vec<ExprId> {
    post_order_by(g, roots, |id, node| match node {
        _ if sums.contains_key(&id) => sums[&id].operands().to_vec(),
        Node::Add(terms) if !slots.is_empty() => match runs.get(&id) {
            Some((_, rest)) => rest.clone(),
            None => match runs::find(g, terms, slots) {
                Some((r, rest)) => {
                    let kids = rest.clone();
                    runs.insert(id, (r, rest));
                    kids
                }
                None => terms.to_vec(),
            },
        },
        node => node.args(),
    })
}

/// `sin(a ± b)` and `cos(a ± b)` from the pairs of `a` and `b`:
/// $\sin(a \pm b) = \sin a \cos b \pm \cos a \sin b$,
/// $\cos(a \pm b) = \cos a \cos b \mp \sin a \sin b$.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AngleSum {
    /// `[sin a, cos a, sin b, cos b]`.
    pub pairs: [ExprId; 4],
    /// Whether the sum is `a − b`.
    pub minus: bool,
}

impl AngleSum {
    /// The temporaries it reads.
    pub fn operands(&self) -> &[ExprId; 4] {
        &self.pairs
    }
}

/// The live sine–cosine pairs whose argument is a sum `a + b` or `a − b` of two terms
/// whose own pairs are live: each maps (sine and cosine alike) to the [`AngleSum`]
/// that defines it with four products instead of a call of `sin_cos`. A linkage's
/// absolute angles are sums of its joint angles, whose sines and cosines the same
/// function evaluates anyway.
fn angle_sums(g: &Graph, partner: &HashMap<ExprId, ExprId>) -> HashMap<ExprId, AngleSum> {
    let mut pair_of = HashMap::new();
    for (&s, &c) in partner {
        if let (Node::Call(Func::Sin, u), Node::Call(Func::Cos, _)) = (g.node(s), g.node(c)) {
            pair_of.insert(*u, (s, c));
        }
    }
    let negated = |t: ExprId| match g.node(t) {
        Node::Mul(f) if f.len() == 2 => match g.node(f[0]) {
            Node::Const(b) if f64::from_bits(*b) == -1.0 => Some(f[1]),
            _ => None,
        },
        _ => None,
    };
    let mut sums = HashMap::new();
    for (&u, &(s, c)) in &pair_of {
        let Node::Add(terms) = g.node(u) else {
            continue;
        };
        let [x, y] = terms[..] else {
            continue;
        };
        // `a − b` with `b` the negated term; `x + y` otherwise.
        let (a, b, minus) = match (negated(x), negated(y)) {
            (None, Some(b)) => (x, b, true),
            (Some(a), None) => (y, a, true),
            _ => (x, y, false),
        };
        if let (Some(&(sa, ca)), Some(&(sb, cb))) = (pair_of.get(&a), pair_of.get(&b)) {
            let sum = AngleSum {
                pairs: [sa, ca, sb, cb],
                minus,
            };
            sums.insert(s, sum);
            sums.insert(c, sum);
        }
    }
    sums
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

#[cfg(test)]
mod tests {
    use super::*;

    /// `sin(a + b)`, `cos(a + b)`, `sin(a − b)` and `cos(a − b)` beside the pairs of
    /// `a` and `b` are defined from those pairs, after them, and the sums themselves
    /// are not computed; without `cos b` the sum's pair is one call of `sin_cos` again.
    #[test]
    fn sums_of_angles_read_the_pairs_of_their_terms() {
        let mut g = Graph::new();
        let (a, b) = (g.var(Var::Q(0)), g.var(Var::Q(1)));
        let (sa, ca) = (g.call(Func::Sin, a), g.call(Func::Cos, a));
        let (sb, cb) = (g.call(Func::Sin, b), g.call(Func::Cos, b));
        let (sum, diff) = (g.add(vec![a, b]), g.sub(a, b));
        let (ss, cs) = (g.call(Func::Sin, sum), g.call(Func::Cos, sum));
        let (sd, cd) = (g.call(Func::Sin, diff), g.call(Func::Cos, diff));
        let p = schedule(&g, &[sa, ca, sb, cb, ss, cs, sd, cd]);
        let pairs = [sa, ca, sb, cb];
        for (id, minus) in [(ss, false), (cs, false), (sd, true), (cd, true)] {
            assert_eq!(p.angle_sums.get(&id), Some(&AngleSum { pairs, minus }));
            let k = p.temp(id).expect("a pair is a temporary");
            for o in pairs {
                assert!(p.temp(o).expect("an operand is a temporary") < k);
            }
        }
        assert!(!p.lets.contains(&sum) && !p.lets.contains(&diff));
        let (needed, vars) = p.needed(&g, &[ss]);
        assert!(pairs.iter().all(|o| needed[o.index()]) && !needed[sum.index()]);
        assert_eq!(vars, BTreeSet::from([Var::Q(0), Var::Q(1)]));

        let p = schedule(&g, &[sa, ca, sb, ss, cs]);
        assert!(p.angle_sums.is_empty());
        assert_eq!(p.partner.get(&ss), Some(&cs));
    }

    /// The pairs of variables, and of sums and products of variables read by the pair
    /// alone (printed inline, with no temporary), go two by two into one `sin_cos2`
    /// (the earlier defines both); an odd one out stays a `sin_cos`, a pair of an
    /// expression read elsewhere too or of a sum of angles is never a twin, a pair of a
    /// velocity is not a position's twin (`emit::corrected` defines them on either side
    /// of the correction of the velocities), and a twin is needed with its twin.
    #[test]
    fn pairs_of_variables_are_twinned_in_schedule_order() {
        let mut g = Graph::new();
        let v: Vec<ExprId> = (0..3).map(|i| g.var(Var::Q(i))).collect();
        let pair = |g: &mut Graph, u| (g.call(Func::Sin, u), g.call(Func::Cos, u));
        let (s0, c0) = pair(&mut g, v[0]);
        let (s1, c1) = pair(&mut g, v[1]);
        let (s2, c2) = pair(&mut g, v[2]);
        let two = g.constant(2.0);
        let doubled = g.mul(vec![two, v[2]]);
        let (sx, cx) = pair(&mut g, doubled);
        let three = g.constant(3.0);
        let tripled = g.mul(vec![three, v[2]]);
        let (st, ct) = pair(&mut g, tripled);
        let sum = g.add(vec![v[0], v[1]]);
        let (ss, cs) = pair(&mut g, sum);
        let w = g.var(Var::Qd(0));
        let (sw, cw) = pair(&mut g, w);
        let roots = [
            s0, c0, s1, c1, s2, sw, cw, c2, sx, cx, st, ct, tripled, ss, cs,
        ];
        let p = schedule(&g, &roots);
        let defining = |s: ExprId, c: ExprId| {
            if p.temp(s) < p.temp(c) {
                s
            } else {
                c
            }
        };
        let (d0, d1, d2) = (defining(s0, c0), defining(s1, c1), defining(s2, c2));
        let dx = defining(sx, cx);
        assert_eq!(p.twins.get(&d0), Some(&d1));
        assert_eq!(p.twins.get(&d1), Some(&d0));
        assert_eq!(p.twins.get(&d2), Some(&dx));
        assert_eq!(p.twins.get(&dx), Some(&d2));
        assert_eq!(p.twins.len(), 4, "{:?}", p.twins);
        assert!(p.temp(doubled).is_none(), "2 q2 is printed in the call");
        assert!(p.temp(tripled).is_some(), "3 q2 is an output too");
        for id in [st, ct, ss, cs, sw, cw] {
            assert!(
                !p.twins.contains_key(&id),
                "a velocity's pair is not a position's twin"
            );
        }
        let (needed, vars) = p.needed(&g, &[c1]);
        assert!([s0, c0, s1, c1].iter().all(|o| needed[o.index()]));
        assert!(!needed[s2.index()] && !needed[sx.index()]);
        assert_eq!(vars, BTreeSet::from([Var::Q(0), Var::Q(1)]));
    }
}
