//! The solve of the augmented system $[M\ J^\mathsf{T}; J\ 0][\ddot q; \lambda] = [Q;
//! \gamma]$ specialized to the model's patterns: the trait method `augmented_solve`.
//!
//! Input: the sizes and the patterns of $M$, $C_q$ and $G$ (values known only when the
//! generated code runs). Output: straight-line code of a sparse $LDL^\mathsf{T}$
//! factorization of the augmented matrix $K$ and the two triangular solves, or nothing
//! when the model does not profit from it (see [`BUDGET`]).
//!
//! **Method (range space).** The coordinates are eliminated first, then the
//! multipliers: the first $n$ pivots are those of a sparse Cholesky factorization of $M$,
//! the last $m$ those of the Schur complement $-S = -J M^{-1} J^\mathsf{T}$. Within each
//! group the order is a minimum-degree order of the elimination graph, and the fill of
//! $L$ is computed here, so the code touches only structurally non-zero entries. No
//! pivoting: every pivot is checked instead, relative to the diagonal it started from
//! ($d_k > \epsilon\, M_{kk}$ for a coordinate, $-d_k > \epsilon\, S_{kk}$ for a
//! multiplier, $\epsilon = $ [`PIVOT_RATIO`]), which is invariant under a change of units
//! (a scaling of the rows and columns). A pivot that fails (a massless coordinate, a
//! mass matrix singular off the constraints — Euler parameters —, redundant or
//! nearly dependent constraints, a singular configuration) makes the function return
//! `Declined`, and the runtime solves with its general path, which decides rank.
//!
//! **Euler parameters.** The kinetic energy of a body oriented by Euler parameters
//! $\theta$ does not depend on $\dot\theta$ along $\theta$: $M\theta = 0$, and only
//! the normalization row $C_r = \theta^\mathsf{T}\theta - 1$ (gradient $2\theta$)
//! makes $K$ regular. Such a row (every entry `k q_c` of its own column, the columns a
//! block of $M$'s pattern, so no fill) is added to $M$ in the augmented-Lagrangian way,
//! $\tilde M = M + \rho J_r^\mathsf{T} J_r$, $\tilde Q = Q + \rho J_r^\mathsf{T}
//! \gamma_r$, which leaves the solution unchanged ($J_r\ddot q = \gamma_r$) and makes
//! $\tilde M$ positive definite; $\rho = \sum_c M_{cc} / \sum_c J_{rc}^2$ gives the
//! added block the trace of $M$'s, so it does not depend on the units.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use proc_macro2::{Literal, TokenStream};
use quote::{quote, ToTokens};

use super::nullspace::{self, Ending, Jacobian, MetricEntries};
use crate::derive::Entry;
use crate::sym::{ExprId, Graph, Node, Var};

/// Largest operation count (multiplications and additions of the factorization and the
/// solves) for which the specialized solve is emitted. Above it the straight-line code
/// would be longer than the largest generated functions, and the runtime's sparse $LU$
/// (a reusable symbolic factorization) is within a small factor of it.
pub const BUDGET: usize = 20_000;

/// The smallest accepted ratio of a pivot to the diagonal entry it started from.
pub const PIVOT_RATIO: f64 = 1e-8;

/// Where an entry of the augmented matrix is read from.
#[derive(Clone, Copy, Debug)]
enum Source {
    Mass(usize),
    /// A diagonal entry 1 (the identity metric of [`orthogonal_solve`]).
    Unit,
    Holonomic(usize),
    Nonholonomic(usize),
}

/// The symbolic factorization: elimination order, pattern of $L$ and the operation
/// count.
#[derive(Debug)]
pub struct Plan {
    /// Node (0..n coordinates, n..n+m multipliers) eliminated at each position.
    pub order: Vec<usize>,
    /// Per position: the positions of the rows of its column of $L$ (ascending).
    pub columns: Vec<Vec<usize>>,
    /// Multiplications and additions of the factorization and the solves.
    pub operations: usize,
    n: usize,
    /// Entries `(node, node)` of $K$ (both orders stored) and their source.
    entries: HashMap<(usize, usize), Source>,
    /// The rows added to $M$ (see the module docs): per row, the holonomic row and its
    /// entries `(column, index in cq)`.
    added: Vec<(usize, Vec<(usize, usize)>)>,
    /// The metric is the identity (the orthogonal projection's system), and the
    /// right-hand side's coordinate block is zero (see [`orthogonal_solve`]).
    identity: bool,
}

/// The metric block of the augmented matrix.
#[derive(Clone, Copy, Debug)]
pub enum Metric<'a> {
    /// The mass matrix with this pattern.
    Mass(&'a [Entry]),
    /// The identity (orthogonal projection).
    Identity,
}

/// The holonomic rows $C_r = \tfrac k2 \sum_c q_c^2 + \dots$ whose columns form a block
/// of $M$'s pattern: rows `k q_c` in every column (Euler parameters' normalization).
pub fn normalization_rows(g: &Graph, mass: &[Entry], cq: &[Entry]) -> Vec<usize> {
    let in_mass: std::collections::HashSet<(u32, u32)> =
        mass.iter().map(|e| (e.row, e.col)).collect();
    // `k q_c` → k.
    let coefficient = |id: ExprId, c: u32| match g.node(id) {
        Node::Mul(f) if f.len() == 2 => match (g.node(f[0]), g.node(f[1])) {
            (Node::Const(k), Node::Var(Var::Q(v))) | (Node::Var(Var::Q(v)), Node::Const(k))
                if *v == c =>
            {
                Some(*k)
            }
            _ => None,
        },
        _ => None,
    };
    let rows = cq.iter().map(|e| e.row as usize + 1).max().unwrap_or(0);
    (0..rows)
        .filter(|&r| {
            let row: Vec<&Entry> = cq.iter().filter(|e| e.row as usize == r).collect();
            let k = row.first().and_then(|e| coefficient(e.expr, e.col));
            row.len() > 1
                && k.is_some()
                && row.iter().all(|e| coefficient(e.expr, e.col) == k)
                && row
                    .iter()
                    .all(|a| row.iter().all(|b| in_mass.contains(&(a.col, b.col))))
        })
        .collect()
}

impl Plan {
    /// The symbolic factorization of the augmented matrix with the given patterns;
    /// `None` when a coordinate has no diagonal mass entry (then $M$ is singular for
    /// every value and the general path must solve).
    pub fn new(
        n: usize,
        (mh, nnh): (usize, usize),
        (metric, cq, gm): (Metric<'_>, &[Entry], &[Entry]),
        added: &[usize],
    ) -> Option<Plan> {
        let (mass, identity) = match metric {
            Metric::Mass(mass) => (mass, false),
            Metric::Identity => (&[][..], true),
        };
        let added = added
            .iter()
            .map(|&r| {
                let row = cq
                    .iter()
                    .enumerate()
                    .filter(|(_, e)| e.row as usize == r)
                    .map(|(k, e)| (e.col as usize, k))
                    .collect();
                (r, row)
            })
            .collect();
        let mut entries = HashMap::new();
        let mut adjacent = vec![BTreeSet::new(); n];
        let mut diagonal = vec![false; n];
        for (k, e) in mass.iter().enumerate() {
            let (r, c) = (e.row as usize, e.col as usize);
            entries.insert((r, c), Source::Mass(k));
            if r == c {
                diagonal[r] = true;
            }
        }
        if identity {
            for (i, d) in diagonal.iter_mut().enumerate() {
                entries.insert((i, i), Source::Unit);
                *d = true;
            }
        }
        if diagonal.iter().any(|d| !d) {
            return None;
        }
        let dim = n + mh + nnh;
        adjacent.resize(dim, BTreeSet::new());
        for e in mass {
            let (r, c) = (e.row as usize, e.col as usize);
            if r != c {
                adjacent[r].insert(c);
                adjacent[c].insert(r);
            }
        }
        let blocks = [(cq, n, true), (gm, n + mh, false)];
        for (pattern, offset, holonomic) in blocks {
            for (k, e) in pattern.iter().enumerate() {
                let (r, c) = (e.row as usize + offset, e.col as usize);
                let source = if holonomic {
                    Source::Holonomic(k)
                } else {
                    Source::Nonholonomic(k)
                };
                entries.insert((r, c), source);
                entries.insert((c, r), source);
                adjacent[r].insert(c);
                adjacent[c].insert(r);
            }
        }
        // A constraint row with no entry: K is singular for every value.
        if adjacent[n..].iter().any(BTreeSet::is_empty) {
            return None;
        }
        // Minimum degree within the coordinates, then within the multipliers.
        let mut done = vec![false; dim];
        let mut order = Vec::with_capacity(dim);
        let mut neighbours: Vec<Vec<usize>> = vec![Vec::new(); dim];
        for group in [0..n, n..dim] {
            for _ in group.clone() {
                let v = group
                    .clone()
                    .filter(|&v| !done[v])
                    .min_by_key(|&v| (adjacent[v].len(), v))
                    .expect("a node left in the group");
                let near: Vec<usize> = adjacent[v].iter().copied().collect();
                for &a in &near {
                    adjacent[a].remove(&v);
                    for &b in &near {
                        if a != b {
                            adjacent[a].insert(b);
                        }
                    }
                }
                adjacent[v].clear();
                done[v] = true;
                neighbours[v] = near;
                order.push(v);
            }
        }
        let mut position = vec![0; dim];
        for (k, &v) in order.iter().enumerate() {
            position[v] = k;
        }
        let columns: Vec<Vec<usize>> = order
            .iter()
            .map(|&v| {
                let mut c: Vec<usize> = neighbours[v].iter().map(|&u| position[u]).collect();
                c.sort_unstable();
                c
            })
            .collect();
        let mut plan = Plan {
            order,
            columns,
            operations: 0,
            n,
            entries,
            added,
            identity,
        };
        let mut operations = 0;
        for (k, terms) in plan.updates().iter().enumerate() {
            operations += 2 * terms.values().map(Vec::len).sum::<usize>() + 2;
            operations += 5 * plan.columns[k].len() + 2;
        }
        for (_, row) in &plan.added {
            operations += 3 * row.len() * (row.len() + 2);
        }
        plan.operations = operations;
        Some(plan)
    }

    /// Per position `k`: for itself and each row `i` of its column, the earlier
    /// positions `j` whose columns hold both (the updates of left-looking $LDL^\mathsf{T}$).
    fn updates(&self) -> Vec<HashMap<usize, Vec<usize>>> {
        let dim = self.order.len();
        let mut rows: Vec<Vec<usize>> = vec![Vec::new(); dim];
        for (j, c) in self.columns.iter().enumerate() {
            for &i in c {
                rows[i].push(j);
            }
        }
        (0..dim)
            .map(|k| {
                let mut terms: HashMap<usize, Vec<usize>> = HashMap::new();
                terms.insert(k, Vec::new());
                for &i in &self.columns[k] {
                    terms.insert(i, Vec::new());
                }
                for &j in &rows[k] {
                    for &i in &self.columns[j] {
                        if i >= k {
                            terms.get_mut(&i).expect("the fill is closed").push(j);
                        }
                    }
                }
                terms
            })
            .collect()
    }

    /// The positions `j` with `k` in their column, per position `k` (ascending): the
    /// entries of row `k` of $L$.
    fn rows(&self) -> Vec<Vec<usize>> {
        let mut rows: Vec<Vec<usize>> = vec![Vec::new(); self.order.len()];
        for (j, c) in self.columns.iter().enumerate() {
            for &i in c {
                rows[i].push(j);
            }
        }
        rows
    }

    /// The pattern of $Y = I - L_{SS}^{-1}$, $L_{SS}$ the block of $L$ in the
    /// multipliers' rows and columns: per entry `(p, q)`, `p > q`, whether $l_{pq}$ is
    /// an entry and the positions `j` of its terms $l_{pj} Y_{jq}$, $q < j < p$.
    fn inverse(&self) -> BTreeMap<(usize, usize), (bool, Vec<usize>)> {
        let (n, dim) = (self.n, self.order.len());
        let rows = self.rows();
        let mut y: BTreeMap<(usize, usize), (bool, Vec<usize>)> = BTreeMap::new();
        for p in n..dim {
            for q in n..p {
                let direct = rows[p].binary_search(&q).is_ok();
                let terms: Vec<usize> = rows[p]
                    .iter()
                    .copied()
                    .filter(|&j| j > q && y.contains_key(&(j, q)))
                    .collect();
                if direct || !terms.is_empty() {
                    y.insert((p, q), (direct, terms));
                }
            }
        }
        y
    }

    /// The operations the explicit inverse of $L_{SS}$ adds to the solve (its entries
    /// and the products $Y^\mathsf{T}\zeta$, less the back substitution they replace).
    fn inverse_operations(&self) -> usize {
        let y = self.inverse();
        let made: usize = y.values().map(|(_, t)| 2 * t.len() + 1).sum();
        let used = 2 * y.len();
        let replaced: usize = self.columns[self.n..].iter().map(|c| 2 * c.len()).sum();
        (made + used).saturating_sub(replaced)
    }

    /// The trait method.
    ///
    /// **Emitted for the critical path.** The solve is a chain of dependent
    /// operations, not a flop count: each pivot's reciprocal (a division) is needed by
    /// the next pivot, and the substitutions are chains through the unknowns. The code
    /// is therefore built with a model of when each value is ready (additions and
    /// multiplications [`ADD`], [`MUL`] cycles, divisions [`DIV`], the inputs at 0), and
    /// every sum is combined as a tree, the two earliest ready operands first (which
    /// minimizes the time of the result; products the earliest factors first), a term
    /// $l_{ij} w_{kj}$ of an update is written $l_{kj} w_{ij}$ when that is ready
    /// earlier, the forward substitution is folded into the factorization
    /// (`y`, computed with the rows of $L$ as they appear), and when it is cheap enough
    /// (it adds at most half the operations of the rest, `Plan::inverse_operations`) the
    /// unit triangle of the multipliers' block is inverted alongside the factorization
    /// (its rows wait for no division), so that the multipliers are independent dot
    /// products after the last pivot instead of a chain of `m` substitutions. Writing
    /// the terms as $(w_{ij} w_{kj}) r_j$ (the product of the `w` waits for no
    /// division) shortens the modelled path further but was slower where measured
    /// (one multiplication more per term: andrews and bicycle, `perf` samples in the
    /// solve), so it is not done.
    ///
    /// **Pivots in pairs.** A pivot whose update holds its predecessor's term takes its
    /// reciprocal from the 2×2 block the two form, $r_k = d_p / (e\,d_p - w_{kp}^2)$
    /// (`e` its operand less that term), when the model has it ready earlier: the
    /// two divisions of the block then run side by side instead of one after the
    /// other, which removes about one division's latency per pair from the path (the
    /// andrews solve: a chain of 8 divisions becomes 4 pairs). Measured on andrews
    /// (`--repeat`, three alternated passes): projection + DOP853 261 → 240 µs a run,
    /// Baumgarte + DOP853 301 → 286 µs; other models and integrators within 1 %.
    /// With the identity metric (the orthogonal solve that projects partitioning's
    /// velocities) the pairs made partitioning + Adams 2.5 % slower (631 → 647 µs),
    /// so there every pivot divides alone.
    ///
    /// Sign convention: in the multipliers' block the code holds $-w$ and $-d$ (the
    /// positive Schur complement $S = J M^{-1} J^\mathsf{T}$ and its pivots), so that
    /// every reciprocal `r` is positive and $l = w r$ holds in both blocks; `z` is
    /// $y r$ ($D^{-1} y$ up to that sign) and `s` the solution ($-\lambda$ in the
    /// multipliers).
    pub fn emit(&self, prefix: TokenStream) -> TokenStream {
        let n = self.n;
        let dim = self.order.len();
        let lit = Literal::usize_unsuffixed;
        // Index of the entry (i, k), i > k, of L.
        let mut index = HashMap::new();
        for (k, c) in self.columns.iter().enumerate() {
            for &i in c {
                let next = index.len();
                index.insert((i, k), next);
            }
        }
        // The terms ρ J_ra J_rb of the rows added to M, by entry (a, b).
        let mut added: HashMap<(usize, usize), TokenStream> = HashMap::new();
        let mut code = TokenStream::new();
        for (a, (r, row)) in self.added.iter().enumerate() {
            let rho = quote::format_ident!("rho{}", a);
            let diagonal = row.iter().map(|&(c, _)| match self.entries[&(c, c)] {
                Source::Mass(e) => lit(e),
                _ => unreachable!("the row's columns are a block of M"),
            });
            let squares = row.iter().map(|&(_, e)| {
                let e = lit(e);
                quote!(cq[#e] * cq[#e])
            });
            code.extend(quote!(let #rho = (#(mass[#diagonal])+*) / (#(#squares)+*);));
            let xr = lit(n + r);
            for &(ca, ea) in row {
                let (xa, ea) = (lit(ca), lit(ea));
                code.extend(quote!(x[#xa] += #rho * cq[#ea] * x[#xr];));
                for &(cb, eb) in row {
                    let eb = lit(eb);
                    added
                        .entry((ca, cb))
                        .or_default()
                        .extend(quote!(+ #rho * cq[#ea] * cq[#eb]));
                }
            }
        }
        // The ready time of an entry with added terms (ρ: two sums and a division).
        let added_ready = DIV + 3 * ADD + MUL;
        let source = |i: usize, k: usize| -> Option<Operand> {
            let (vi, vk) = (self.order[i], self.order[k]);
            self.entries.get(&(vi, vk)).map(|s| match *s {
                Source::Mass(e) => {
                    let e = lit(e);
                    match added.get(&(vi, vk)) {
                        Some(t) => Operand::new(quote!((mass[#e] #t)), added_ready),
                        None => Operand::new(quote!(mass[#e]), 0),
                    }
                }
                Source::Holonomic(e) => {
                    let e = lit(e);
                    Operand::new(quote!(cq[#e]), 0)
                }
                Source::Nonholonomic(e) => {
                    let e = lit(e);
                    Operand::new(quote!(g[#e]), 0)
                }
                Source::Unit => Operand::new(quote!(1.0), 0),
            })
        };
        // With the identity metric a coordinate's pivot is 1 exactly (no earlier column
        // holds it), so it is neither tested nor inverted, and its column of L is its
        // column of W (l is written w); the right-hand side's coordinate block is zero,
        // and so are y and z at the coordinates' positions (their rows of L hold no
        // other coordinate): their terms are left out.
        let unit = |k: usize| self.identity && self.order[k] < n;
        let name = |prefix: &str, k: usize| quote::format_ident!("{}{}", prefix, k);
        // Ready times of the values: w (L D, by entry), l (by entry), d and r (pivot and
        // its reciprocal, by position), y, z and s (by position), t (Y, by entry).
        let mut w_at = vec![0; index.len()];
        let mut l_at = vec![0; index.len()];
        let (mut d_at, mut r_at) = (vec![0; dim], vec![0; dim]);
        let (mut y_at, mut z_at, mut s_at) = (vec![0; dim], vec![0; dim], vec![0; dim]);
        // V(i, k): w for i > k, d for i = k.
        let v = |i: usize, k: usize, w_at: &[u32], d_at: &[u32]| {
            if i == k {
                Operand::new(name("d", k).into_token_stream(), d_at[k])
            } else {
                let e = index[&(i, k)];
                Operand::new(name("w", e).into_token_stream(), w_at[e])
            }
        };
        let ell = |i: usize, k: usize, l_at: &[u32]| {
            let e = index[&(i, k)];
            let prefix = if unit(k) { "w" } else { "l" };
            Operand::new(name(prefix, e).into_token_stream(), l_at[e])
        };
        let ratio: TokenStream = format!("{PIVOT_RATIO:e}").parse().expect("a literal");
        let declined = quote!(return ::pfaff::__private::AugmentedSolve::Declined;);
        let rows = self.rows();
        let inverse = (self.inverse_operations() <= self.operations / 2
            && self.operations + self.inverse_operations() <= BUDGET)
            .then(|| self.inverse());
        let mut t_at: HashMap<(usize, usize), u32> = HashMap::new();
        // The positions whose reciprocal comes from a 2×2 determinant (no `d` variable).
        let mut paired = vec![false; dim];
        let t_name = |p: usize, q: usize| quote::format_ident!("t{}_{}", p, q);
        for (k, terms) in self.updates().iter().enumerate() {
            let multiplier = self.order[k] >= n;
            // The forward substitution's row k: y_k = b_k − Σ l_kj y_j.
            let b = lit(self.order[k]);
            let mut items = vec![(false, Operand::new(quote!(x[#b]), 0))];
            if unit(k) {
                items.clear();
            }
            for &j in rows[k].iter().filter(|&&j| !unit(j)) {
                let a = Operand::product(vec![
                    ell(k, j, &l_at),
                    Operand::new(name("y", j).into_token_stream(), y_at[j]),
                ]);
                let b = Operand::product(vec![
                    v(k, j, &w_at, &d_at),
                    Operand::new(name("z", j).into_token_stream(), z_at[j]),
                ]);
                items.push((true, Operand::earlier(a, b)));
            }
            if !items.is_empty() {
                let y = Operand::sum(items);
                y_at[k] = y.ready;
                let (yn, yc) = (name("y", k), y.code);
                code.extend(quote!(let #yn = #yc;));
            }
            // Row k of Y (the multipliers' block): Y_kq = l_kq − Σ l_kj Y_jq.
            if let Some(inverse) = &inverse {
                for q in n..k {
                    let Some((direct, js)) = inverse.get(&(k, q)) else {
                        continue;
                    };
                    let mut items = Vec::new();
                    if *direct {
                        items.push((false, ell(k, q, &l_at)));
                    }
                    for &j in js {
                        let t = Operand::new(t_name(j, q).into_token_stream(), t_at[&(j, q)]);
                        items.push((true, Operand::product(vec![ell(k, j, &l_at), t])));
                    }
                    let t = Operand::sum(items);
                    t_at.insert((k, q), t.ready);
                    let (tn, tc) = (t_name(k, q), t.code);
                    code.extend(quote!(let #tn = #tc;));
                }
            }
            // A term ± l_ij w_kj of the update of entry (i, k), the earlier of l_ij w_kj and
            // l_kj w_ij.
            let term = |i: usize, j: usize, at: (&[u32], &[u32], &[u32])| {
                let (w_at, l_at, d_at) = at;
                let (vi, vk) = (v(i, j, w_at, d_at), v(k, j, w_at, d_at));
                let mut term = Operand::product(vec![ell(i, j, l_at), vk]);
                if i != k {
                    term = Operand::earlier(term, Operand::product(vec![ell(k, j, l_at), vi]));
                }
                term
            };
            // The pivot, checked against the diagonal it started from.
            let dn = name("d", k);
            if unit(k) {
                assert!(terms[&k].is_empty(), "a unit pivot with updates");
                for &i in &self.columns[k] {
                    let e = index[&(i, k)];
                    let a = source(i, k).expect("an entry of J");
                    w_at[e] = a.ready;
                    l_at[e] = a.ready;
                    let (wn, ac) = (name("w", e), a.code);
                    code.extend(quote!(let #wn = #ac;));
                }
                continue;
            }
            // The pivot's first operand, the diagonal its test is relative to (none: the
            // test is d > 0), and the earlier positions whose terms it subtracts.
            let (base, relative, js): (Operand, Option<TokenStream>, Vec<usize>) = if !multiplier {
                let mut a = source(k, k).expect("a diagonal mass entry");
                if added.contains_key(&(self.order[k], self.order[k])) {
                    let an = name("a", k);
                    let ac = a.code;
                    code.extend(quote!(let #an = #ac;));
                    a = Operand::new(an.into_token_stream(), a.ready);
                }
                let relative = a.code.clone();
                (a, Some(relative), terms[&k].clone())
            } else {
                // S_kk = Σ l w over the coordinates; the pivot S_kk − Σ l w over the
                // earlier multipliers.
                let (coordinates, multipliers): (Vec<usize>, Vec<usize>) =
                    terms[&k].iter().partition(|&&j| self.order[j] < n);
                let items = coordinates
                    .iter()
                    .map(|&j| (false, term(k, j, (&w_at, &l_at, &d_at))))
                    .collect::<Vec<_>>();
                let s = if items.is_empty() {
                    Operand::new(quote!(0.0), 0)
                } else {
                    Operand::sum(items)
                };
                let (cn, sc) = (name("c", k), s.code);
                code.extend(quote!(let #cn = #sc;));
                let c = Operand::new(cn.to_token_stream(), s.ready);
                let relative = (!multipliers.is_empty()).then(|| cn.to_token_stream());
                (c, relative, multipliers)
            };
            let items = |skip: Option<usize>| {
                let mut items = vec![(false, base.clone())];
                for &j in js.iter().filter(|&&j| Some(j) != skip) {
                    items.push((true, term(k, j, (&w_at, &l_at, &d_at))));
                }
                items
            };
            let single = Operand::sum(items(None));
            // The pivot after its predecessor p, as the second of a 2×2 block: with e
            // the pivot's operand less every term but p's, d_k = e − w_kp² / d_p =
            // Δ / d_p, Δ = e d_p − w_kp², so r_k = d_p / Δ waits for d_p, not for r_p,
            // and the two divisions run side by side (the test d_k > ε a is Δ > ε a d_p,
            // d_p > 0). Taken when the model has r_k ready earlier, in pairs that do not
            // overlap, and only with the mass metric (see the method's docs).
            let pair = k
                .checked_sub(1)
                .filter(|&p| {
                    !self.identity
                        && !paired[p]
                        && !unit(p)
                        && relative.is_some()
                        && js.contains(&p)
                })
                .and_then(|p| {
                    let e = Operand::sum(items(Some(p)));
                    let wkp = v(k, p, &w_at, &d_at);
                    let det = e.ready.max(d_at[p]).max(wkp.ready) + MUL + ADD;
                    (det.max(d_at[p]) + DIV < single.ready + DIV).then_some((p, e, wkp, det))
                });
            let (rn, zn, yn) = (name("r", k), name("z", k), name("y", k));
            if let Some((p, e, wkp, det)) = pair {
                paired[k] = true;
                let (detn, dp) = (name("det", k), name("d", p));
                let (wc, rel) = (wkp.code, relative.expect("a relative test"));
                // e by name when it is a sum.
                let ec = if e.sum {
                    let (en, ec) = (name("e", k), e.code);
                    code.extend(quote!(let #en = #ec;));
                    en.into_token_stream()
                } else {
                    e.code
                };
                code.extend(quote! {
                    let #detn = #ec * #dp - #wc * #wc;
                    if !(#detn > #ratio * #rel * #dp) || !(#dp > 0.0) {
                        #declined
                    }
                });
                d_at[k] = det;
                if self.columns[k].is_empty() {
                    z_at[k] = (y_at[k].max(d_at[p]) + MUL).max(det) + DIV;
                    code.extend(quote!(let #zn = #yn * #dp / #detn;));
                    continue;
                }
                r_at[k] = det.max(d_at[p]) + DIV;
                code.extend(quote!(let #rn = #dp / #detn;));
            } else {
                d_at[k] = single.ready;
                let dc = single.code;
                code.extend(match relative {
                    Some(rel) => quote! {
                        let #dn = #dc;
                        if !(#dn > #ratio * #rel) {
                            #declined
                        }
                    },
                    None => quote! {
                        let #dn = #dc;
                        if !(#dn > 0.0) {
                            #declined
                        }
                    },
                });
                if self.columns[k].is_empty() {
                    // No column: the reciprocal would serve z alone.
                    z_at[k] = d_at[k].max(y_at[k]) + DIV;
                    code.extend(quote!(let #zn = #yn / #dn;));
                    continue;
                }
                r_at[k] = d_at[k] + DIV;
                code.extend(quote!(let #rn = 1.0 / #dn;));
            }
            z_at[k] = r_at[k].max(y_at[k]) + MUL;
            code.extend(quote!(let #zn = #yn * #rn;));
            // The column: w_ik = a_ik − Σ l_ij w_kj (the sign of the block in the
            // multipliers' rows and columns), l_ik = w_ik r_k.
            for &i in &self.columns[k] {
                let e = index[&(i, k)];
                let mut items: Vec<(bool, Operand)> =
                    source(i, k).map(|a| (false, a)).into_iter().collect();
                for &j in &terms[&i] {
                    // In a multiplier's column the coordinates' terms add (S), the
                    // multipliers' subtract.
                    let negative = !multiplier || self.order[j] >= n;
                    items.push((negative, term(i, j, (&w_at, &l_at, &d_at))));
                }
                let w = Operand::sum(items);
                w_at[e] = w.ready;
                l_at[e] = w.ready.max(r_at[k]) + MUL;
                let (wn, ln, wc) = (name("w", e), name("l", e), w.code);
                code.extend(quote! {
                    let #wn = #wc;
                    let #ln = #wn * #rn;
                });
            }
        }
        // The back substitution, from the last position: s_k = z_k − Σ l_ik x_i, with
        // s = −λ in the multipliers (x_i = −s_i there).
        let s_op = |k: usize, s_at: &[u32]| Operand::new(name("s", k).into_token_stream(), s_at[k]);
        let z_op = |k: usize| Operand::new(name("z", k).into_token_stream(), z_at[k]);
        for k in (0..dim).rev() {
            let mut items = vec![(false, z_op(k))];
            if unit(k) {
                items.clear();
            }
            match &inverse {
                Some(inverse) if k >= n => {
                    // s_k = z_k − Σ_p Y_pk z_p.
                    for p in k + 1..dim {
                        if inverse.contains_key(&(p, k)) {
                            let t = Operand::new(t_name(p, k).into_token_stream(), t_at[&(p, k)]);
                            items.push((true, Operand::product(vec![t, z_op(p)])));
                        }
                    }
                }
                _ => {
                    for &i in &self.columns[k] {
                        let negative = self.order[i] < n || k >= n;
                        let p = Operand::product(vec![ell(i, k, &l_at), s_op(i, &s_at)]);
                        items.push((negative, p));
                    }
                }
            }
            let sn = name("s", k);
            if items.is_empty() {
                // A coordinate in no constraint row, with the identity metric.
                code.extend(quote!(let #sn = 0.0;));
                continue;
            }
            let s = Operand::sum(items);
            s_at[k] = s.ready;
            let sc = s.code;
            code.extend(quote!(let #sn = #sc;));
        }
        for k in 0..dim {
            let (x, sn) = (lit(self.order[k]), name("s", k));
            code.extend(if k < n {
                quote!(x[#x] = #sn;)
            } else {
                quote!(x[#x] = -#sn;)
            });
        }
        let dl = lit(dim);
        let count = |f: fn(&Source) -> Option<usize>| {
            self.entries
                .values()
                .filter_map(f)
                .max()
                .map_or(0, |k| k + 1)
        };
        let slice = |name: &str, len: usize| {
            let ident = proc_macro2::Ident::new(name, proc_macro2::Span::call_site());
            if len == 0 {
                let unused = quote::format_ident!("_{}", name);
                (unused, TokenStream::new())
            } else {
                let len = lit(len);
                (ident.clone(), quote!(let #ident = &#ident[..#len];))
            }
        };
        let (mass, mass_cut) = slice(
            "mass",
            count(|s| match s {
                Source::Mass(k) => Some(*k),
                _ => None,
            }),
        );
        let (cq, cq_cut) = slice(
            "cq",
            count(|s| match s {
                Source::Holonomic(k) => Some(*k),
                _ => None,
            }),
        );
        let (g, g_cut) = slice(
            "g",
            count(|s| match s {
                Source::Nonholonomic(k) => Some(*k),
                _ => None,
            }),
        );
        // The orthogonal solve reads no mass matrix.
        let (name, mass_param) = if self.identity {
            (quote!(orthogonal_solve), TokenStream::new())
        } else {
            (quote!(augmented_solve), quote!(#mass: &[f64],))
        };
        quote! {
            fn #name(
                &self,
                #mass_param
                #cq: &[f64],
                #g: &[f64],
                x: &mut [f64],
            ) -> ::pfaff::__private::AugmentedSolve {
                #mass_cut
                #cq_cut
                #g_cut
                let x = &mut x[..#dl];
                #prefix
                #code
                ::pfaff::__private::AugmentedSolve::Solved
            }
        }
    }
}

/// Latency in cycles of an addition or subtraction, in the model the emitted code is
/// ordered by ([`Plan::emit`]).
pub const ADD: u32 = 4;
/// Latency of a multiplication.
pub const MUL: u32 = 4;
/// Latency of a division.
pub const DIV: u32 = 14;
/// Latency of a negation.
pub const NEG: u32 = 1;

/// A value of the emitted code: its expression and when it is ready.
#[derive(Clone, Debug)]
struct Operand {
    code: TokenStream,
    ready: u32,
    /// An unparenthesized sum (parenthesized where it is a right operand).
    sum: bool,
}

impl Operand {
    fn new(code: TokenStream, ready: u32) -> Operand {
        Operand {
            code,
            ready,
            sum: false,
        }
    }

    /// The one ready first (`a` on a tie).
    fn earlier(a: Operand, b: Operand) -> Operand {
        if b.ready < a.ready {
            b
        } else {
            a
        }
    }

    /// The product of the factors, the earliest ready first.
    fn product(mut factors: Vec<Operand>) -> Operand {
        factors.sort_by_key(|f| f.ready);
        let mut it = factors.into_iter();
        let mut acc = it.next().expect("a factor");
        for f in it {
            let (a, b) = (&acc.code, &f.code);
            acc = Operand::new(quote!(#a * #b), acc.ready.max(f.ready) + MUL);
        }
        acc
    }

    /// The sum of the items (`true`: subtracted) as a tree, the two operands ready
    /// first combined first; its sign carried until a positive operand absorbs it.
    fn sum(items: Vec<(bool, Operand)>) -> Operand {
        let mut pool: Vec<(bool, Operand)> = items;
        assert!(!pool.is_empty(), "a sum of something");
        while pool.len() > 1 {
            // The two earliest (the first of equals: a deterministic tree).
            let first = (0..pool.len())
                .min_by_key(|&i| pool[i].1.ready)
                .expect("two");
            let (na, a) = pool.remove(first);
            let second = (0..pool.len())
                .min_by_key(|&i| pool[i].1.ready)
                .expect("one");
            let (nb, b) = pool.remove(second);
            let ready = a.ready.max(b.ready) + ADD;
            let paren = |o: &Operand| {
                let c = &o.code;
                if o.sum {
                    quote!((#c))
                } else {
                    c.clone()
                }
            };
            let (negative, code) = match (na, nb) {
                (false, false) => {
                    let (ac, bc) = (&a.code, paren(&b));
                    (false, quote!(#ac + #bc))
                }
                (false, true) => {
                    let (ac, bc) = (&a.code, paren(&b));
                    (false, quote!(#ac - #bc))
                }
                (true, false) => {
                    let (bc, ac) = (&b.code, paren(&a));
                    (false, quote!(#bc - #ac))
                }
                (true, true) => {
                    let (ac, bc) = (&a.code, paren(&b));
                    (true, quote!(#ac + #bc))
                }
            };
            pool.insert(
                first.min(pool.len()),
                (
                    negative,
                    Operand {
                        code,
                        ready,
                        sum: true,
                    },
                ),
            );
        }
        let (negative, o) = pool.pop().expect("the sum");
        if negative {
            let c = &o.code;
            let c = if o.sum { quote!((#c)) } else { c.clone() };
            Operand::new(quote!(-#c), o.ready + NEG)
        } else {
            o
        }
    }
}

/// The trait method `augmented_solve` for the patterns, when the model profits from it:
/// $M$ has every diagonal entry and the operation count is within [`BUDGET`].
pub fn augmented_solve(
    g: &Graph,
    n: usize,
    rows: (usize, usize),
    (mass, cq, gm): (&[Entry], &[Entry], &[Entry]),
    values: Option<(&[f64], &[f64])>,
) -> TokenStream {
    let added = normalization_rows(g, mass, cq);
    match Plan::new(n, rows, (Metric::Mass(mass), cq, gm), &added) {
        Some(plan) if plan.operations <= BUDGET && n > 0 => {
            let entries = mass
                .iter()
                .enumerate()
                .map(|(k, e)| {
                    let k = Literal::usize_unsuffixed(k);
                    ((e.row as usize, e.col as usize), quote!(mass[#k]))
                })
                .collect();
            let mut blocks = partitioned(
                n,
                rows,
                (cq, gm),
                values,
                &MetricEntries::Mass(entries),
                plan.operations,
                &[Ending::Solve],
            )
            .into_iter();
            plan.emit(blocks.next().unwrap_or_default())
        }
        _ => TokenStream::new(),
    }
}

/// The null-space solve to try first ([`nullspace`](super::nullspace)), when the
/// pattern has a partition and its code is cheaper than the range-space code's
/// `operations`: for each of `endings` in order, its block; empty otherwise (one empty
/// stream per ending).
fn partitioned(
    n: usize,
    rows: (usize, usize),
    patterns: (&[Entry], &[Entry]),
    values: Option<(&[f64], &[f64])>,
    metric: &MetricEntries,
    operations: usize,
    endings: &[Ending],
) -> Vec<TokenStream> {
    let none = || vec![TokenStream::new(); endings.len()];
    if rows.0 + rows.1 == 0 || rows.0 + rows.1 > n {
        return none();
    }
    let jac = Jacobian::new(n, rows, patterns, values);
    // Without values the pattern alone would pick the pivots: a guess, whose checks
    // every evaluation would pay where it declines.
    if jac.values.is_none() {
        return none();
    }
    let Some(part) = jac.partition() else {
        return none();
    };
    // The whole solve decides, for every ending: the coordinates' block is the same
    // code short of the multipliers.
    let (solve, ops) = nullspace::emit(&jac, &part, metric, Ending::Solve);
    if ops >= operations {
        return none();
    }
    endings
        .iter()
        .map(|&ending| match ending {
            Ending::Solve => solve.clone(),
            Ending::Coordinates => nullspace::emit(&jac, &part, metric, ending).0,
        })
        .collect()
}

/// The trait method `orthogonal_solve` for the patterns of $C_q$ and $G$: the
/// solve of $[I\ J^\mathsf{T}; J\ 0][\Delta; \mu] = [0; r]$, so
/// $\Delta = J^\mathsf{T}(J J^\mathsf{T})^{-1} r$, the least change with
/// $J\Delta = r$ (with $r = -(J\dot q + c)$ the orthogonal projection of velocities),
/// by the same factorization as [`augmented_solve`] with the
/// identity in place of $M$. The coordinates' pivots are then 1 (the compiler folds
/// them), the multipliers' block is the Gram matrix $J J^\mathsf{T}$ formed from the
/// patterns, and the right-hand side's coordinate block is taken as zero (its terms
/// are left out). Emitted for models with constraint rows, every row with an entry,
/// within [`BUDGET`]; partitioning projects the velocities of every evaluation with it
/// (`runtime/src/sim/chart.rs`).
pub fn orthogonal_solve(
    n: usize,
    rows: (usize, usize),
    (cq, gm): (&[Entry], &[Entry]),
    values: Option<(&[f64], &[f64])>,
) -> TokenStream {
    if rows.0 + rows.1 == 0 {
        return TokenStream::new();
    }
    match Plan::new(n, rows, (Metric::Identity, cq, gm), &[]) {
        Some(plan) if plan.operations <= BUDGET && n > 0 => {
            let mut blocks = partitioned(
                n,
                rows,
                (cq, gm),
                values,
                &MetricEntries::Identity,
                plan.operations,
                &[Ending::Solve, Ending::Coordinates],
            )
            .into_iter();
            let mut fns = plan.emit(blocks.next().unwrap_or_default());
            let coordinates = blocks.next().unwrap_or_default();
            fns.extend(orthogonal_projection(n, rows, (cq, gm), coordinates));
            fns
        }
        _ => TokenStream::new(),
    }
}

/// The trait method `orthogonal_projection`, beside `orthogonal_solve`: the residuals
/// $r = J\dot q + [C_t; g]$ as straight-line sums over the patterns (each row's rate,
/// then its entries in the pattern's order, left to right: the sums of the runtime's
/// row-by-row loop, to the bit), the solve with $[0; -r]$ into a local array, and
/// $\dot q \mathrel{+}= \Delta$ when every entry of $\Delta$ is finite.
///
/// Where `orthogonal_solve` opens with a null-space block, `partitioned` is the same
/// block short of the multipliers, which the projection does not read (the two
/// triangular solves with $J_d^\mathsf{T}$): $\Delta$ by the same operations, to the
/// bit. Where it declines, `orthogonal_solve` solves (its own block declines there
/// too, and its range-space code serves).
fn orthogonal_projection(
    n: usize,
    (mh, mnh): (usize, usize),
    (cq, gm): (&[Entry], &[Entry]),
    partitioned: TokenStream,
) -> TokenStream {
    let dim = n + mh + mnh;
    let lit = Literal::usize_unsuffixed;
    let mut rows = TokenStream::new();
    for (i, sum) in residual_sums((mh, mnh), (cq, gm)).into_iter().enumerate() {
        let at = lit(n + i);
        rows.extend(quote!(x[#at] = -#sum;));
    }
    let Inputs {
        ct_param,
        bias_param,
        cuts,
    } = residual_inputs((mh, mnh), (cq, gm));
    let (n_lit, dim_lit) = (lit(n), lit(dim));
    let general = quote! {
        match self.orthogonal_solve(cq, g, &mut x) {
            ::pfaff::__private::AugmentedSolve::Solved => {}
            other => return other,
        }
    };
    let solve = if partitioned.is_empty() {
        general
    } else {
        quote! {
            'solve: {
                #partitioned
                #general
            }
        }
    };
    quote! {
        fn orthogonal_projection(
            &self,
            cq: &[f64],
            g: &[f64],
            #ct_param: &[f64],
            #bias_param: &[f64],
            qd: &mut [f64],
        ) -> ::pfaff::__private::AugmentedSolve {
            #cuts
            let qd = &mut qd[..#n_lit];
            let mut x = [0.0_f64; #dim_lit];
            #rows
            #solve
            let delta = &x[..#n_lit];
            if !delta.iter().all(|d| d.is_finite()) {
                return ::pfaff::__private::AugmentedSolve::Declined;
            }
            for (v, d) in qd.iter_mut().zip(delta) {
                *v += d;
            }
            ::pfaff::__private::AugmentedSolve::Solved
        }
    }
}

/// The residual of every constraint row, $[C_q\dot q + C_t;\ G\dot q + g]$, as the
/// expression over the slices `cq`, `g`, `ct`, `bias` and `qd`: row $i$'s rate, then its
/// entries in the pattern's order, added left to right (the sums of the runtime's
/// row-by-row loop, to the bit).
fn residual_sums((mh, mnh): (usize, usize), (cq, gm): (&[Entry], &[Entry])) -> Vec<TokenStream> {
    let lit = Literal::usize_unsuffixed;
    let mut sums = Vec::with_capacity(mh + mnh);
    for (entries, count, values, rates) in [
        (cq, mh, quote!(cq), quote!(ct)),
        (gm, mnh, quote!(g), quote!(bias)),
    ] {
        for i in 0..count {
            let li = lit(i);
            let mut sum = quote!(#rates[#li]);
            for (k, e) in entries
                .iter()
                .enumerate()
                .filter(|(_, e)| e.row as usize == i)
            {
                let (k, c) = (lit(k), lit(e.col as usize));
                sum = quote!((#sum + #values[#k] * qd[#c]));
            }
            sums.push(sum);
        }
    }
    sums
}

/// The parameters `ct` and `bias` of a method reading [`residual_sums`] (underscored
/// when the model has no such rows) and the statements that cut the input slices to
/// the patterns' lengths (no bounds checks in the sums).
struct Inputs {
    ct_param: TokenStream,
    bias_param: TokenStream,
    cuts: TokenStream,
}

fn residual_inputs((mh, mnh): (usize, usize), (cq, gm): (&[Entry], &[Entry])) -> Inputs {
    let lit = Literal::usize_unsuffixed;
    let (cq_len, g_len, mh_lit, mnh_lit) = (lit(cq.len()), lit(gm.len()), lit(mh), lit(mnh));
    let mut cuts = TokenStream::new();
    if mh > 0 {
        cuts.extend(quote!(let cq = &cq[..#cq_len];));
    }
    if mnh > 0 {
        cuts.extend(quote!(let g = &g[..#g_len];));
    }
    let ct_param = if mh == 0 {
        quote!(_ct)
    } else {
        cuts.extend(quote!(let ct = &ct[..#mh_lit];));
        quote!(ct)
    };
    let bias_param = if mnh == 0 {
        quote!(_bias)
    } else {
        cuts.extend(quote!(let bias = &bias[..#mnh_lit];));
        quote!(bias)
    };
    Inputs {
        ct_param,
        bias_param,
        cuts,
    }
}

/// The trait method `velocity_residuals`, for every model with constraint rows: each
/// row's residual sum (its rate, then its entries in the pattern's order) stored in
/// `out`, straight-line code where the runtime walks the patterns entry by entry
/// (Baumgarte's shift, the velocity stage of projection and the monitors read them).
pub fn velocity_residuals(
    n: usize,
    (mh, mnh): (usize, usize),
    (cq, gm): (&[Entry], &[Entry]),
) -> TokenStream {
    if mh + mnh == 0 || n == 0 {
        return TokenStream::new();
    }
    let lit = Literal::usize_unsuffixed;
    let mut rows = TokenStream::new();
    for (i, sum) in residual_sums((mh, mnh), (cq, gm)).into_iter().enumerate() {
        let at = lit(i);
        rows.extend(quote!(out[#at] = #sum;));
    }
    let Inputs {
        ct_param,
        bias_param,
        cuts,
    } = residual_inputs((mh, mnh), (cq, gm));
    let (n_lit, m_lit) = (lit(n), lit(mh + mnh));
    // A kind of row the model does not have leaves its slice unread.
    let cq_param = if mh == 0 { quote!(_cq) } else { quote!(cq) };
    let g_param = if mnh == 0 { quote!(_g) } else { quote!(g) };
    quote! {
        fn velocity_residuals(
            &self,
            #cq_param: &[f64],
            #g_param: &[f64],
            #ct_param: &[f64],
            #bias_param: &[f64],
            qd: &[f64],
            out: &mut [f64],
        ) -> bool {
            #cuts
            let qd = &qd[..#n_lit];
            let out = &mut out[..#m_lit];
            #rows
            true
        }
    }
}

/// The trait method `holonomic_row_norms`, for every model with holonomic rows: each
/// row's largest magnitude, from `0.0` over its entries in the pattern's order with the
/// runtime's rule (`norm_step`: a larger magnitude or a NaN replaces the norm, so a NaN
/// entry leaves it NaN), straight-line code where the runtime walks the pattern entry by
/// entry (the projections' convergence tests read the norms at every iterate).
pub fn holonomic_row_norms(mh: usize, cq: &[Entry]) -> TokenStream {
    // A pattern without entries (every row a constraint on time alone) is left to the
    // runtime's walk, which gives 0 (a row without entries here is written 0 too).
    if mh == 0 || cq.is_empty() {
        return TokenStream::new();
    }
    let lit = Literal::usize_unsuffixed;
    let mut rows = TokenStream::new();
    for i in 0..mh {
        let mut norm = quote!(0.0);
        for (k, _) in cq.iter().enumerate().filter(|(_, e)| e.row as usize == i) {
            let k = lit(k);
            norm = quote!(step(#norm, cq[#k].abs()));
        }
        let i = lit(i);
        rows.extend(quote!(out[#i] = #norm;));
    }
    let (cq_len, mh_lit) = (lit(cq.len()), lit(mh));
    quote! {
        fn holonomic_row_norms(&self, cq: &[f64], out: &mut [f64]) -> bool {
            let step = ::pfaff::__private::norm_step;
            let cq = &cq[..#cq_len];
            let out = &mut out[..#mh_lit];
            #rows
            true
        }
    }
}
