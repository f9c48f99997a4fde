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

use std::collections::{BTreeSet, HashMap};

use proc_macro2::{Literal, TokenStream};
use quote::quote;

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
        (mass, cq, gm): (&[Entry], &[Entry], &[Entry]),
        added: &[usize],
    ) -> Option<Plan> {
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

    /// The trait method.
    pub fn emit(&self) -> TokenStream {
        let n = self.n;
        let dim = self.order.len();
        // Index of the entry (i, k), i > k, of L in the arrays `w` (L D) and `l`.
        let mut index = HashMap::new();
        for (k, c) in self.columns.iter().enumerate() {
            for &i in c {
                let next = index.len();
                index.insert((i, k), next);
            }
        }
        let lit = Literal::usize_unsuffixed;
        let entry = |i: usize, k: usize| lit(index[&(i, k)]);
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
        let source = |i: usize, k: usize| {
            let (vi, vk) = (self.order[i], self.order[k]);
            self.entries.get(&(vi, vk)).map(|s| match *s {
                Source::Mass(e) => {
                    let e = lit(e);
                    match added.get(&(vi, vk)) {
                        Some(t) => quote!((mass[#e] #t)),
                        None => quote!(mass[#e]),
                    }
                }
                Source::Holonomic(e) => {
                    let e = lit(e);
                    quote!(cq[#e])
                }
                Source::Nonholonomic(e) => {
                    let e = lit(e);
                    quote!(g[#e])
                }
            })
        };
        // a − Σ l[ij] w[kj] (`a` absent: a structural zero).
        let update = |a: Option<TokenStream>, i: usize, k: usize, js: &[usize]| {
            let mut e = a.unwrap_or_default();
            for (t, &j) in js.iter().enumerate() {
                let (ij, kj) = (entry(i, j), entry(k, j));
                e = if t == 0 && e.is_empty() {
                    quote!(-(l[#ij] * w[#kj]))
                } else {
                    quote!(#e - l[#ij] * w[#kj])
                };
            }
            e
        };
        let ratio: TokenStream = format!("{PIVOT_RATIO:e}").parse().expect("a literal");
        for (k, terms) in self.updates().iter().enumerate() {
            let v = self.order[k];
            let kl = lit(k);
            if v < n {
                let mut a = source(k, k).expect("a diagonal mass entry");
                if let Some(t) = added.get(&(v, v)) {
                    let e = match self.entries[&(v, v)] {
                        Source::Mass(e) => lit(e),
                        _ => unreachable!("a diagonal mass entry"),
                    };
                    code.extend(quote!(let a = mass[#e] #t;));
                    a = quote!(a);
                }
                let d = update(Some(a.clone()), k, k, &terms[&k]);
                code.extend(quote! {
                    let d = #d;
                    if !(d > #ratio * #a) {
                        return ::pfaff::__private::AugmentedSolve::Declined;
                    }
                    r[#kl] = 1.0 / d;
                });
            } else {
                let (coordinates, multipliers): (Vec<usize>, Vec<usize>) =
                    terms[&k].iter().partition(|&&j| self.order[j] < n);
                // S_kk = Σ l w over the coordinates; −pivot = S_kk + Σ l w over the
                // earlier multipliers (each l w < 0 there).
                let products = |js: &[usize]| -> Vec<TokenStream> {
                    js.iter()
                        .map(|&j| {
                            let kj = entry(k, j);
                            quote!(l[#kj] * w[#kj])
                        })
                        .collect()
                };
                let (s, more) = (products(&coordinates), products(&multipliers));
                let s = if s.is_empty() {
                    quote!(0.0)
                } else {
                    quote!(#(#s)+*)
                };
                code.extend(if more.is_empty() {
                    quote! {
                        let s = #s;
                        if !(s > 0.0) {
                            return ::pfaff::__private::AugmentedSolve::Declined;
                        }
                        r[#kl] = -1.0 / s;
                    }
                } else {
                    quote! {
                        let s = #s;
                        let d = s #(+ #more)*;
                        if !(d > #ratio * s) {
                            return ::pfaff::__private::AugmentedSolve::Declined;
                        }
                        r[#kl] = -1.0 / d;
                    }
                });
            }
            for &i in &self.columns[k] {
                let e = entry(i, k);
                let w = update(source(i, k), i, k, &terms[&i]);
                code.extend(quote! {
                    w[#e] = #w;
                    l[#e] = w[#e] * r[#kl];
                });
            }
        }
        // L y = b, then x = D⁻¹ y − Lᵀ x (rows from the last).
        let mut rows: Vec<Vec<usize>> = vec![Vec::new(); dim];
        for (j, c) in self.columns.iter().enumerate() {
            for &i in c {
                rows[i].push(j);
            }
        }
        for (k, js) in rows.iter().enumerate() {
            if js.is_empty() {
                continue;
            }
            let v = lit(self.order[k]);
            let mut e = quote!(x[#v]);
            for &j in js {
                let (kj, vj) = (entry(k, j), lit(self.order[j]));
                e = quote!(#e - l[#kj] * x[#vj]);
            }
            code.extend(quote!(x[#v] = #e;));
        }
        for k in (0..dim).rev() {
            let (v, kl) = (lit(self.order[k]), lit(k));
            let mut e = quote!(x[#v] * r[#kl]);
            for &i in &self.columns[k] {
                let (ik, vi) = (entry(i, k), lit(self.order[i]));
                e = quote!(#e - l[#ik] * x[#vi]);
            }
            code.extend(quote!(x[#v] = #e;));
        }
        let dl = lit(dim);
        // The arrays of L D (`w`) and L (`l`) by entry, the inverse pivots (`r`) by
        // position; slices cut to their lengths so that the indices need no checks.
        let factors = if index.is_empty() {
            TokenStream::new()
        } else {
            let nl = lit(index.len());
            quote! {
                let mut w = [0.0_f64; #nl];
                let mut l = [0.0_f64; #nl];
            }
        };
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
        quote! {
            fn augmented_solve(
                &self,
                #mass: &[f64],
                #cq: &[f64],
                #g: &[f64],
                x: &mut [f64],
            ) -> ::pfaff::__private::AugmentedSolve {
                #mass_cut
                #cq_cut
                #g_cut
                let x = &mut x[..#dl];
                #factors
                let mut r = [0.0_f64; #dl];
                #code
                ::pfaff::__private::AugmentedSolve::Solved
            }
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
) -> TokenStream {
    let added = normalization_rows(g, mass, cq);
    match Plan::new(n, rows, (mass, cq, gm), &added) {
        Some(plan) if plan.operations <= BUDGET && n > 0 => plan.emit(),
        _ => TokenStream::new(),
    }
}
