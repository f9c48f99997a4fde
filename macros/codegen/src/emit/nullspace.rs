//! The augmented solve by a partition of the coordinates (the null-space method), tried
//! before the range-space factorization of [`solve`](super::solve) inside the same
//! trait method.
//!
//! Input: the patterns of $M$ (or the identity metric), $C_q$ and $G$, and the values
//! of $J = [C_q; G]$ at the model's declared initial state when the generator can
//! evaluate them. Output: straight-line code of the solve of
//! $[M\ J^\mathsf{T}; J\ 0][\ddot q; \lambda] = [Q; \gamma]$ on a partition of the
//! coordinates into $m$ dependent ones $d$ (one per row of $J$) and $n - m$ independent
//! ones $u$, fixed here, or nothing when it would not be cheaper than the range-space
//! code.
//!
//! **Method.** Gaussian elimination of $J$ with the pivots of the partition, fixed at
//! compile time: $P J_d = L U$, applied to $J_u$ and $\gamma$ on the way. Then
//! $\ddot q_d = p + X \ddot q_u$ with $J_d p = \gamma$, $J_d X = -J_u$ (the back
//! substitutions), the null-space basis $N = [X; I]$, and the reduced system
//! $(N^\mathsf{T} M N)\,\ddot q_u = N^\mathsf{T}(Q - M \tilde p)$, $\tilde p = [p; 0]$,
//! of size $n - m$ (one for a mechanism with one degree of freedom), factored by
//! $LDL^\mathsf{T}$. The multipliers come from the dependent columns of
//! $J^\mathsf{T}\lambda = Q - M\ddot q$: $J_d^\mathsf{T}\lambda = (Q - M\ddot q)_d$, two
//! triangular solves with the same factors. Every structural zero is known here, so
//! the code touches only non-zero entries (a zero stays out of every sum, a one out of
//! every product).
//!
//! **Why it pays.** The range-space code eliminates the coordinates first and factors
//! the Schur complement $J M^{-1} J^\mathsf{T}$, dense wherever one coordinate (a
//! crank angle) enters every loop closure: andrews' six rows make a full 6 × 6. The
//! partition instead factors $J_d$ with its own sparsity (andrews: 2 × 2 blocks on an
//! arrow) and leaves a system of the size of the degrees of freedom.
//!
//! **Which partition, and when it declines.** The pivots are chosen by Markowitz' rule
//! (least fill) among the entries within [`CHOICE_THRESHOLD`] of the largest of their
//! row at the initial state, eliminated numerically as they are chosen, so the
//! partition is a well-conditioned one there. Without values (a run-time datum in
//! $J$, no declared initial state) nothing is emitted: a partition chosen by the
//! pattern alone is a guess (see `solve::partitioned`). At run time every pivot must
//! reach [`PIVOT_THRESHOLD`] of the largest entry left in its row (threshold pivoting:
//! bounded growth) and of the largest entry the row had before elimination (a row
//! that elimination nearly cancelled: $J_d$ near singular, as at a lock, where the
//! range-space code and the general path decide), and every pivot of
//! the reduced system [`PIVOT_RATIO`] of its diagonal entry;
//! a failed check (a configuration where the partition degrades, a non-finite entry)
//! leaves the block before anything is written, and the range-space code solves.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use super::solve::PIVOT_RATIO;
use crate::derive::Entry;

/// At run time, the smallest accepted ratio of a pivot of $J_d$ to the largest entry
/// left in its row (over the dependent and independent columns not yet eliminated) and
/// to the largest of the row's own entries before elimination.
pub const PIVOT_THRESHOLD: f64 = 1e-2;

/// At compile time, the ratio to the largest entry of its row an entry must reach at
/// the initial state to be a pivot of the partition.
pub const CHOICE_THRESHOLD: f64 = 0.5;

/// A value of the emitted code: a known zero or one, or a named `f64`.
#[derive(Clone, Debug)]
enum V {
    Zero,
    One,
    Var(Ident),
}

impl V {
    fn is_zero(&self) -> bool {
        matches!(self, V::Zero)
    }

    fn code(&self) -> TokenStream {
        match self {
            V::Zero => quote!(0.0),
            V::One => quote!(1.0),
            V::Var(id) => quote!(#id),
        }
    }
}

/// The statements being emitted and their operation count.
#[derive(Default)]
struct Code {
    stmts: TokenStream,
    next: usize,
    ops: usize,
}

impl Code {
    fn bind(&mut self, expr: TokenStream, ops: usize) -> V {
        let id = format_ident!("n{}", self.next);
        self.next += 1;
        self.stmts.extend(quote!(let #id = #expr;));
        self.ops += ops;
        V::Var(id)
    }

    /// $\sum_i \pm a_i b_i$, zeros left out, ones folded; a lone unscaled value is
    /// passed on without a new binding.
    fn sum(&mut self, terms: &[(bool, &V, &V)]) -> V {
        let live: Vec<(bool, &V, &V)> = terms
            .iter()
            .copied()
            .filter(|(_, a, b)| !a.is_zero() && !b.is_zero())
            .collect();
        match live.as_slice() {
            [] => return V::Zero,
            [(false, V::One, x)] | [(false, x, V::One)] => return (*x).clone(),
            _ => {}
        }
        let mut code = TokenStream::new();
        let mut ops = 0;
        for (count, &(negative, a, b)) in live.iter().enumerate() {
            let product = match (a, b) {
                (V::One, x) | (x, V::One) => x.code(),
                (x, y) => {
                    ops += 1;
                    let (x, y) = (x.code(), y.code());
                    quote!(#x * #y)
                }
            };
            code.extend(match (count, negative) {
                (0, false) => product,
                (0, true) => quote!(-#product),
                (_, false) => quote!(+ #product),
                (_, true) => quote!(- #product),
            });
            if count > 0 {
                ops += 1;
            }
        }
        self.bind(code, ops)
    }

    fn product(&mut self, a: &V, b: &V) -> V {
        self.sum(&[(false, a, b)])
    }
}

/// A pivot candidate of [`Jacobian::partition`]: its ordering key and place.
struct Candidate {
    key: (usize, i64, usize, usize),
    at: (usize, usize),
}

/// The partition: the pivot `(row, coordinate)` of each step, in elimination order.
#[derive(Debug)]
pub struct Partition {
    pub pivots: Vec<(usize, usize)>,
    pub independent: Vec<usize>,
}

/// The pattern of $J$ (`rows[r]`: coordinate → where its entry is read) and, where the
/// generator could evaluate them, its values.
#[derive(Debug)]
pub struct Jacobian {
    pub n: usize,
    pub rows: Vec<BTreeMap<usize, TokenStream>>,
    pub values: Option<Vec<BTreeMap<usize, f64>>>,
}

impl Jacobian {
    /// From the entries of $C_q$ (read from `cq`) and $G$ (from `g`), `mh + mnh` rows.
    pub fn new(
        n: usize,
        (mh, mnh): (usize, usize),
        (cq, gm): (&[Entry], &[Entry]),
        values: Option<(&[f64], &[f64])>,
    ) -> Self {
        let mut rows = vec![BTreeMap::new(); mh + mnh];
        let mut vals = vec![BTreeMap::new(); mh + mnh];
        let blocks = [(cq, 0, quote!(cq)), (gm, mh, quote!(g))];
        for (b, (pattern, offset, array)) in blocks.into_iter().enumerate() {
            for (k, e) in pattern.iter().enumerate() {
                let kk = Literal::usize_unsuffixed(k);
                let (r, c) = (e.row as usize + offset, e.col as usize);
                rows[r].insert(c, quote!(#array[#kk]));
                if let Some((vc, vg)) = values {
                    let v = if b == 0 { vc[k] } else { vg[k] };
                    vals[r].insert(c, v);
                }
            }
        }
        let finite = vals.iter().all(|r| r.values().all(|v| v.is_finite()));
        Jacobian {
            n,
            rows,
            values: (values.is_some() && finite).then_some(vals),
        }
    }

    /// Markowitz' pivots among the acceptable entries (see the module docs); `None` when
    /// the pattern leaves a row without a pivot.
    pub fn partition(&self) -> Option<Partition> {
        let m = self.rows.len();
        let mut pattern: Vec<BTreeSet<usize>> = self
            .rows
            .iter()
            .map(|r| r.keys().copied().collect())
            .collect();
        let mut values = self.values.clone();
        let mut row_done = vec![false; m];
        let mut col_done = vec![false; self.n];
        let mut pivots = Vec::with_capacity(m);
        for _ in 0..m {
            let mut col_count = vec![0usize; self.n];
            for (r, p) in pattern.iter().enumerate() {
                if !row_done[r] {
                    for &c in p {
                        col_count[c] += 1;
                    }
                }
            }
            // (fill, larger first, row, column) of the best candidate so far.
            let mut best: Option<Candidate> = None;
            for r in (0..m).filter(|&r| !row_done[r]) {
                let largest = values.as_ref().map(|v| {
                    v[r].iter()
                        .filter(|(c, _)| !col_done[**c])
                        .map(|(_, x)| x.abs())
                        .fold(0.0, f64::max)
                });
                for &c in pattern[r].iter().filter(|&&c| !col_done[c]) {
                    // Relative size in thousandths (larger first on a tie of fill).
                    let size = match (&values, largest) {
                        (Some(v), Some(l)) => {
                            let x = v[r].get(&c).copied().unwrap_or(0.0).abs();
                            if x < CHOICE_THRESHOLD * l || x == 0.0 {
                                continue;
                            }
                            (1000.0 * x / l) as i64
                        }
                        _ => 0,
                    };
                    let fill = (pattern[r].len() - 1) * (col_count[c] - 1);
                    let key = (fill, -size, r, c);
                    if best.as_ref().is_none_or(|b| key < b.key) {
                        best = Some(Candidate { key, at: (r, c) });
                    }
                }
            }
            let (r, c) = best?.at;
            // Eliminate c from the other rows (pattern and values).
            let pivot_row: Vec<usize> = pattern[r].iter().copied().collect();
            for i in (0..m).filter(|&i| !row_done[i] && i != r) {
                if !pattern[i].contains(&c) {
                    continue;
                }
                for &j in &pivot_row {
                    pattern[i].insert(j);
                }
                pattern[i].remove(&c);
                if let Some(v) = values.as_mut() {
                    let l = v[i][&c] / v[r][&c];
                    let source: Vec<(usize, f64)> = v[r].iter().map(|(&j, &x)| (j, x)).collect();
                    for (j, x) in source {
                        *v[i].entry(j).or_insert(0.0) -= l * x;
                    }
                    v[i].remove(&c);
                }
            }
            row_done[r] = true;
            col_done[c] = true;
            pivots.push((r, c));
        }
        let independent = (0..self.n).filter(|&c| !col_done[c]).collect();
        Some(Partition {
            pivots,
            independent,
        })
    }
}

/// The metric block: entries of $M$ read from `mass` (either triangle), or the
/// identity.
#[derive(Debug)]
pub enum MetricEntries {
    Mass(HashMap<(usize, usize), TokenStream>),
    Identity,
}

/// What the null-space block computes and how it ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ending {
    /// The whole solution, $\ddot q$ (or $\Delta$) and the multipliers, then
    /// `return Solved` (the block at the top of `augmented_solve`, `orthogonal_solve`).
    Solve,
    /// The coordinates' part of the solution alone, written to `x[..n]`, then
    /// `break 'solve` (the block at the top of `orthogonal_projection`, which reads
    /// $\Delta$ only: the multipliers' two triangular solves are left out).
    Coordinates,
}

/// The statements of the null-space solve (a labelled block that ends as `ending`
/// says or breaks out to the range-space code) and their operation count.
pub fn emit(
    jac: &Jacobian,
    part: &Partition,
    metric: &MetricEntries,
    ending: Ending,
) -> (TokenStream, usize) {
    let n = jac.n;
    let m = jac.rows.len();
    let mut code = Code::default();
    let lit = Literal::usize_unsuffixed;
    // Inputs.
    let identity = matches!(metric, MetricEntries::Identity);
    let forces: Vec<V> = (0..n)
        .map(|i| {
            if identity {
                V::Zero
            } else {
                let k = lit(i);
                code.bind(quote!(x[#k]), 0)
            }
        })
        .collect();
    let mut rhs: Vec<V> = (0..m)
        .map(|r| {
            let k = lit(n + r);
            code.bind(quote!(x[#k]), 0)
        })
        .collect();
    let mut a: Vec<BTreeMap<usize, V>> = jac
        .rows
        .iter()
        .map(|row| {
            row.iter()
                .map(|(&c, src)| (c, code.bind(src.clone(), 0)))
                .collect()
        })
        .collect();
    let original = a.clone();
    let mut mass_cache: HashMap<(usize, usize), V> = HashMap::new();
    let mut mass = |code: &mut Code, i: usize, j: usize| -> V {
        match metric {
            MetricEntries::Identity => {
                if i == j {
                    V::One
                } else {
                    V::Zero
                }
            }
            MetricEntries::Mass(entries) => {
                let key = (i.min(j), i.max(j));
                if let Some(v) = mass_cache.get(&key) {
                    return v.clone();
                }
                let v = match entries.get(&(i, j)).or_else(|| entries.get(&(j, i))) {
                    Some(src) => code.bind(src.clone(), 0),
                    None => V::Zero,
                };
                mass_cache.insert(key, v.clone());
                v
            }
        }
    };
    let threshold = Literal::f64_unsuffixed(PIVOT_THRESHOLD);
    let ratio = Literal::f64_unsuffixed(PIVOT_RATIO);
    // Elimination: position of each row, L by (row position, step), reciprocals.
    let mut position = vec![usize::MAX; m];
    let mut ell: HashMap<(usize, usize), V> = HashMap::new();
    let mut recip = Vec::with_capacity(m);
    let mut upper: Vec<BTreeMap<usize, V>> = Vec::with_capacity(m);
    let mut col_done = vec![false; n];
    for (k, &(r, c)) in part.pivots.iter().enumerate() {
        let pivot = a[r].get(&c).cloned().unwrap_or(V::Zero);
        let p = pivot.code();
        // The entries left in the row, and the row's own entries where elimination
        // changed them (a pivot that cancelled, a row that became nearly dependent on
        // the earlier ones: the singular configurations, where J_d degrades while the
        // entries left beside the pivot may be few or none).
        let left: Vec<&V> = a[r]
            .iter()
            .filter(|(&j, v)| j != c && !col_done[j] && !v.is_zero())
            .map(|(_, v)| v)
            .collect();
        let names = |v: &V| v.code().to_string();
        let current: BTreeSet<String> = a[r].values().map(names).collect();
        let others: Vec<TokenStream> = left
            .into_iter()
            .chain(
                original[r]
                    .values()
                    .filter(|v| !current.contains(&names(v))),
            )
            .map(|v| {
                let x = v.code();
                quote!(#x.abs())
            })
            .collect();
        code.ops += 3 + 2 * others.len();
        code.stmts.extend(if others.is_empty() {
            quote! {
                if !(#p.abs() > 0.0) || !(#p.abs() < f64::INFINITY) {
                    break 'partitioned;
                }
            }
        } else {
            let mut largest = TokenStream::new();
            for (i, o) in others.iter().enumerate() {
                largest = if i == 0 {
                    o.clone()
                } else {
                    quote!(#largest.max(#o))
                };
            }
            quote! {
                if !(#p.abs() >= #threshold * #largest)
                    || !(#p.abs() > 0.0)
                    || !(#p.abs() < f64::INFINITY)
                {
                    break 'partitioned;
                }
            }
        });
        let inv = code.bind(quote!(1.0 / #p), 1);
        position[r] = k;
        let pivot_row: Vec<(usize, V)> = a[r]
            .iter()
            .filter(|(&j, _)| j != c && !col_done[j])
            .map(|(&j, v)| (j, v.clone()))
            .collect();
        for i in 0..m {
            if position[i] != usize::MAX {
                continue;
            }
            let Some(aic) = a[i].remove(&c) else { continue };
            if aic.is_zero() {
                continue;
            }
            let l = code.product(&aic, &inv);
            for (j, arj) in &pivot_row {
                let aij = a[i].get(j).cloned().unwrap_or(V::Zero);
                let v = code.sum(&[(false, &aij, &V::One), (true, &l, arj)]);
                a[i].insert(*j, v);
            }
            let bi = code.sum(&[(false, &rhs[i], &V::One), (true, &l, &rhs[r])]);
            rhs[i] = bi;
            ell.insert((i, k), l);
        }
        col_done[c] = true;
        recip.push(inv);
        let mut row = BTreeMap::new();
        row.insert(c, pivot);
        for (j, v) in pivot_row {
            row.insert(j, v);
        }
        upper.push(row);
    }
    // Back substitution: p (from γ) and X (from -J_u), by dependent coordinate.
    let mut p_d: HashMap<usize, V> = HashMap::new();
    let mut x_d: HashMap<(usize, usize), V> = HashMap::new();
    for k in (0..m).rev() {
        let (r, c) = part.pivots[k];
        let row = &upper[k];
        let later: Vec<(usize, V)> = row
            .iter()
            .filter(|(&j, _)| j != c && !part.independent.contains(&j))
            .map(|(&j, v)| (j, v.clone()))
            .collect();
        let mut terms: Vec<(bool, &V, &V)> = vec![(false, &rhs[r], &V::One)];
        for (j, v) in &later {
            terms.push((true, v, &p_d[j]));
        }
        let s = code.sum(&terms);
        let pc = code.product(&s, &recip[k]);
        p_d.insert(c, pc);
        for &u in &part.independent {
            let zero = V::Zero;
            let aru = row.get(&u).unwrap_or(&zero);
            let mut terms: Vec<(bool, &V, &V)> = vec![(true, aru, &V::One)];
            for (j, v) in &later {
                terms.push((true, v, &x_d[&(*j, u)]));
            }
            let s = code.sum(&terms);
            let xc = code.product(&s, &recip[k]);
            x_d.insert((c, u), xc);
        }
    }
    // N (n × n_u) and p̃.
    let nu = part.independent.len();
    let basis = |i: usize, b: usize| -> V {
        let u = part.independent[b];
        if let Some(v) = x_d.get(&(i, u)) {
            v.clone()
        } else if i == u {
            V::One
        } else {
            V::Zero
        }
    };
    let p_tilde = |i: usize| -> V { p_d.get(&i).cloned().unwrap_or(V::Zero) };
    // M N and M p̃, and Q - M p̃.
    let mut mn: Vec<Vec<V>> = vec![Vec::with_capacity(nu); n];
    let mut residual: Vec<V> = Vec::with_capacity(n);
    for i in 0..n {
        let row: Vec<V> = (0..n).map(|j| mass(&mut code, i, j)).collect();
        for b in 0..nu {
            let cols: Vec<V> = (0..n).map(|j| basis(j, b)).collect();
            let terms: Vec<(bool, &V, &V)> = row
                .iter()
                .zip(&cols)
                .map(|(mij, nj)| (false, mij, nj))
                .collect();
            let v = code.sum(&terms);
            mn[i].push(v);
        }
        let ps: Vec<V> = (0..n).map(p_tilde).collect();
        let mut terms: Vec<(bool, &V, &V)> = vec![(false, &forces[i], &V::One)];
        for (mij, pj) in row.iter().zip(&ps) {
            terms.push((true, mij, pj));
        }
        residual.push(code.sum(&terms));
    }
    // The reduced system H a = b, H = Nᵀ M N, b = Nᵀ (Q - M p̃), by LDLᵀ.
    let mut h: Vec<Vec<V>> = vec![vec![V::Zero; nu]; nu];
    let mut b_red: Vec<V> = Vec::with_capacity(nu);
    for b1 in 0..nu {
        let ncol: Vec<V> = (0..n).map(|i| basis(i, b1)).collect();
        for b2 in 0..=b1 {
            let terms: Vec<(bool, &V, &V)> = ncol
                .iter()
                .zip(&mn)
                .map(|(ni, mni)| (false, ni, &mni[b2]))
                .collect();
            h[b1][b2] = code.sum(&terms);
        }
        let terms: Vec<(bool, &V, &V)> = ncol
            .iter()
            .zip(&residual)
            .map(|(ni, ri)| (false, ni, ri))
            .collect();
        b_red.push(code.sum(&terms));
    }
    // LDLᵀ: l[i][j] (j < i), d[j], reciprocal of d.
    let mut lh: Vec<Vec<V>> = vec![vec![V::Zero; nu]; nu];
    let mut dinv: Vec<V> = Vec::with_capacity(nu);
    let mut w: Vec<Vec<V>> = vec![vec![V::Zero; nu]; nu]; // l[i][j] d[j]
    for j in 0..nu {
        let mut terms: Vec<(bool, &V, &V)> = vec![(false, &h[j][j], &V::One)];
        for k in 0..j {
            terms.push((true, &lh[j][k], &w[j][k]));
        }
        let d = code.sum(&terms);
        let (dc, hc) = (d.code(), h[j][j].code());
        code.ops += 3;
        code.stmts.extend(quote! {
            if !(#dc > #ratio * #hc) || !(#dc < f64::INFINITY) {
                break 'partitioned;
            }
        });
        let di = code.bind(quote!(1.0 / #dc), 1);
        for i in j + 1..nu {
            let mut terms: Vec<(bool, &V, &V)> = vec![(false, &h[i][j], &V::One)];
            for k in 0..j {
                terms.push((true, &lh[i][k], &w[j][k]));
            }
            let wij = code.sum(&terms);
            let lij = code.product(&wij, &di);
            w[i][j] = wij;
            lh[i][j] = lij;
        }
        dinv.push(di);
    }
    // Forward, diagonal, backward.
    let mut y: Vec<V> = Vec::with_capacity(nu);
    for i in 0..nu {
        let mut terms: Vec<(bool, &V, &V)> = vec![(false, &b_red[i], &V::One)];
        for k in 0..i {
            terms.push((true, &lh[i][k], &y[k]));
        }
        let v = code.sum(&terms);
        y.push(v);
    }
    let mut acc: Vec<V> = vec![V::Zero; nu];
    for i in (0..nu).rev() {
        let z = code.product(&y[i], &dinv[i]);
        let mut terms: Vec<(bool, &V, &V)> = vec![(false, &z, &V::One)];
        for k in i + 1..nu {
            terms.push((true, &lh[k][i], &acc[k]));
        }
        acc[i] = code.sum(&terms);
    }
    // The accelerations: q̈_u = a, q̈_d = p + X a.
    let mut qdd: Vec<V> = vec![V::Zero; n];
    for (b, &u) in part.independent.iter().enumerate() {
        qdd[u] = acc[b].clone();
    }
    for &(_, c) in &part.pivots {
        let mut terms: Vec<(bool, &V, &V)> = vec![(false, &p_d[&c], &V::One)];
        let xs: Vec<V> = (0..nu).map(|b| basis(c, b)).collect();
        for (b, xb) in xs.iter().enumerate() {
            terms.push((false, xb, &acc[b]));
        }
        qdd[c] = code.sum(&terms);
    }
    let mut out = TokenStream::new();
    for (i, v) in qdd.iter().enumerate() {
        let (k, v) = (lit(i), v.code());
        out.extend(quote!(x[#k] = #v;));
    }
    if ending == Ending::Coordinates {
        let stmts = code.stmts;
        let block = quote! {
            'partitioned: {
                #stmts
                #out
                break 'solve;
            }
        };
        return (block, code.ops);
    }
    // The multipliers: J_dᵀ λ = (Q - M q̈)_d = (Q - M p̃ - M N a)_d, by Uᵀ z = s, Lᵀ y = z
    // over positions.
    let s: Vec<V> = part
        .pivots
        .iter()
        .map(|&(_, c)| {
            let mut terms: Vec<(bool, &V, &V)> = vec![(false, &residual[c], &V::One)];
            for (b, ab) in acc.iter().enumerate() {
                terms.push((true, &mn[c][b], ab));
            }
            code.sum(&terms)
        })
        .collect();
    let zero = V::Zero;
    let mut z: Vec<V> = Vec::with_capacity(m);
    for l in 0..m {
        let cl = part.pivots[l].1;
        let mut terms: Vec<(bool, &V, &V)> = vec![(false, &s[l], &V::One)];
        for k in 0..l {
            let ukl = upper[k].get(&cl).unwrap_or(&zero);
            terms.push((true, ukl, &z[k]));
        }
        let t = code.sum(&terms);
        let zl = code.product(&t, &recip[l]);
        z.push(zl);
    }
    let mut lambda_pos: Vec<V> = vec![V::Zero; m];
    for k in (0..m).rev() {
        let mut terms: Vec<(bool, &V, &V)> = vec![(false, &z[k], &V::One)];
        for (i, &(ri, _)) in part.pivots.iter().enumerate().skip(k + 1) {
            if let Some(l) = ell.get(&(ri, k)) {
                terms.push((true, l, &lambda_pos[i]));
            }
        }
        lambda_pos[k] = code.sum(&terms);
    }
    for (k, &(r, _)) in part.pivots.iter().enumerate() {
        let (idx, v) = (lit(n + r), lambda_pos[k].code());
        out.extend(quote!(x[#idx] = #v;));
    }
    let stmts = code.stmts;
    let block = quote! {
        'partitioned: {
            #stmts
            #out
            return ::pfaff::__private::AugmentedSolve::Solved;
        }
    };
    (block, code.ops)
}
