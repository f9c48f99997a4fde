//! Sharing partial products between finished expressions.
//!
//! Input: a canonical graph and the roots of the functions a simulation evaluates.
//! Output: the roots rebuilt so that a pair of factors common to several products is
//! computed once. Canonical products are flat and sorted (`a·b·c·d`), so hash-consing
//! shares a product only when it is whole: `r·s·c·x` and `r·s·c·y` compute `r·s·c`
//! twice. This pass is greedy pairwise common-subexpression elimination on the
//! products (the n-ary form of what CSE does on binary trees): while some pair of
//! factors occurs in two or more products, the most frequent pair becomes a node of
//! its own and replaces the two factors in every product that holds both (the value is
//! the same, only the grouping changes, so the result agrees to rounding).
//!
//! The rebuilt nodes are interned as they are, without canonical simplification (a
//! product of a product is kept): the pass runs last, after every derivative and check,
//! and its results are only evaluated.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};

use super::graph::{ExprId, Graph, Node};
use super::transform::post_order;

/// Symbols at or above this index stand for extracted pairs.
const PAIR: u64 = 1 << 40;

/// Products with more factors are left as they are: the pairs of a product are the
/// square of its length (a nest of 400 `sin` has derivatives with 400 factors).
const MAX_FACTORS: usize = 12;

/// The pass is skipped when the products hold more pairs than this in all (time and
/// memory stay bounded; a mechanism's products are far below it).
const MAX_PAIRS: usize = 4_000_000;

/// Rebuilds `roots` (in place) with common pairs of product factors shared.
pub fn share_products(g: &mut Graph, roots: &mut [ExprId]) {
    let order = post_order(g, roots);
    let mut sets: Vec<Vec<u64>> = Vec::new();
    let mut set_of: HashMap<ExprId, usize> = HashMap::new();
    for &id in &order {
        if let Node::Mul(f) = g.node(id) {
            if f.len() > MAX_FACTORS {
                continue;
            }
            set_of.insert(id, sets.len());
            sets.push(f.iter().map(|x| x.index() as u64).collect());
        }
    }
    let total: usize = sets.iter().map(|s| s.len() * (s.len() - 1) / 2).sum();
    if total > MAX_PAIRS {
        return;
    }
    let key = |a: u64, b: u64| if a < b { (a, b) } else { (b, a) };
    let mut count: HashMap<(u64, u64), usize> = HashMap::new();
    let mut occurs: HashMap<(u64, u64), Vec<usize>> = HashMap::new();
    for (si, s) in sets.iter().enumerate() {
        for i in 0..s.len() {
            for j in i + 1..s.len() {
                let p = key(s[i], s[j]);
                *count.entry(p).or_default() += 1;
                occurs.entry(p).or_default().push(si);
            }
        }
    }
    // Most frequent first; ties by the smaller pair, so the result is deterministic.
    let mut heap: BinaryHeap<(usize, Reverse<(u64, u64)>)> = count
        .iter()
        .filter(|(_, &c)| c >= 2)
        .map(|(&p, &c)| (c, Reverse(p)))
        .collect();
    let mut pairs: Vec<(u64, u64)> = Vec::new();
    while let Some((c, Reverse(p))) = heap.pop() {
        if count.get(&p) != Some(&c) || c < 2 {
            continue;
        }
        let sym = PAIR + pairs.len() as u64;
        pairs.push(p);
        let mut sites = occurs.remove(&p).unwrap_or_default();
        sites.sort_unstable();
        sites.dedup();
        for si in sites {
            let s = &sets[si];
            if !(s.contains(&p.0) && s.contains(&p.1)) {
                continue;
            }
            let old = s.clone();
            for i in 0..old.len() {
                for j in i + 1..old.len() {
                    let q = key(old[i], old[j]);
                    if let Some(n) = count.get_mut(&q) {
                        *n -= 1;
                        if *n >= 2 {
                            heap.push((*n, Reverse(q)));
                        }
                    }
                }
            }
            let mut new: Vec<u64> = old.into_iter().filter(|&x| x != p.0 && x != p.1).collect();
            new.push(sym);
            for i in 0..new.len() {
                for j in i + 1..new.len() {
                    let q = key(new[i], new[j]);
                    let n = count.entry(q).or_default();
                    *n += 1;
                    occurs.entry(q).or_default().push(si);
                    if *n >= 2 {
                        heap.push((*n, Reverse(q)));
                    }
                }
            }
            sets[si] = new;
        }
        count.remove(&p);
    }
    if pairs.is_empty() {
        return;
    }
    // Rebuild in post-order: operands first, extracted pairs on first use.
    let mut new_id: HashMap<ExprId, ExprId> = HashMap::new();
    let mut pair_node: Vec<Option<ExprId>> = vec![None; pairs.len()];
    for &id in &order {
        let node = g.node(id).clone();
        let rebuilt = match (&node, set_of.get(&id)) {
            (Node::Mul(_), Some(&si)) => {
                let syms = sets[si].clone();
                let mut f: Vec<ExprId> = syms
                    .iter()
                    .map(|&s| resolve(g, s, &pairs, &mut pair_node, &new_id))
                    .collect();
                if f.len() == 1 {
                    f[0]
                } else {
                    f.sort_unstable();
                    g.intern_as_is(Node::Mul(f.into()))
                }
            }
            _ => {
                let m = |x: &ExprId| new_id[x];
                let n = match &node {
                    Node::Const(_) | Node::Var(_) => node.clone(),
                    Node::Add(a) => Node::Add(a.iter().map(m).collect()),
                    Node::Mul(a) => Node::Mul(a.iter().map(m).collect()),
                    Node::Powi(x, k) => Node::Powi(m(x), *k),
                    Node::Powf(x, y) => Node::Powf(m(x), m(y)),
                    Node::Call(f, x) => Node::Call(*f, m(x)),
                    Node::Atan2(y, x) => Node::Atan2(m(y), m(x)),
                };
                if n == node {
                    id
                } else {
                    g.intern_as_is(n)
                }
            }
        };
        new_id.insert(id, rebuilt);
    }
    for r in roots.iter_mut() {
        *r = new_id[r];
    }
}

/// The node of symbol `s`: an original node's rebuilt id, or an extracted pair's
/// product (built on first use).
fn resolve(
    g: &mut Graph,
    s: u64,
    pairs: &[(u64, u64)],
    pair_node: &mut [Option<ExprId>],
    new_id: &HashMap<ExprId, ExprId>,
) -> ExprId {
    if s < PAIR {
        let id = ExprId::from_index(usize::try_from(s).expect("node index fits usize"));
        return new_id[&id];
    }
    let k = usize::try_from(s - PAIR).expect("pair index fits usize");
    if let Some(id) = pair_node[k] {
        return id;
    }
    let (a, b) = pairs[k];
    let x = resolve(g, a, pairs, pair_node, new_id);
    let y = resolve(g, b, pairs, pair_node, new_id);
    let mut f = vec![x, y];
    f.sort_unstable();
    let id = g.intern_as_is(Node::Mul(f.into()));
    pair_node[k] = Some(id);
    id
}
