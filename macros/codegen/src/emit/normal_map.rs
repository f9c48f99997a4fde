//! The position map of coordinate partitioning's chart specialized to the pattern of
//! $C_q$: the trait method `holonomic_normal_map`.
//!
//! Input: the number of coordinates `n` and the pattern of the holonomic Jacobian
//! $N = C_q$ (`m_h × n`; values known only when the generated code runs). Output:
//! straight-line code that forms the Gram matrix $G = N N^\mathsf{T}$ from the products
//! the pattern leaves, factors it as $L D L^\mathsf{T}$ in the rows' order with the fill
//! computed here, and solves $G X = N$ column by column, every substitution restricted
//! to the structurally non-zero entries, writing $X = (N N^\mathsf{T})^{-1} N$
//! (row-major `m_h × n`): the map whose transpose moves a position onto the constraints
//! in the runtime's chord iteration (`runtime/src/sim/chart.rs`), made once per anchor.
//! Nothing is emitted when the operation count exceeds [`BUDGET`](super::solve::BUDGET)
//! (the runtime forms the map with its own Cholesky factorization, or a sparse factor
//! for large models).
//!
//! **Pivots.** $G$ is symmetric positive semi-definite; no pivoting is needed while it
//! is definite. The function returns the pivot ratio
//! $\min_k \rho_k / \max_k \rho_k$, $\rho_k = d_k / G_{kk}$ (the pivots of $G$ scaled to
//! a unit diagonal, so the ratio does not depend on the units of the rows), and 0
//! without finishing the map when a pivot is not positive (dependent rows, a row
//! without entries, a non-finite entry): the runtime then renews its rows or reports the
//! singular configuration, as it does from its own factorization's ratio.

use std::collections::HashMap;

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use super::solve::BUDGET;
use crate::derive::Entry;

/// The symbolic factorization of $N N^\mathsf{T}$.
struct Pattern {
    /// Per row `i`, per column `c`: the index of the entry $(i, c)$ in `cq`.
    at: Vec<HashMap<usize, usize>>,
    /// `fill[i][k]`, `k < i`: whether $L_{ik}$ is structurally non-zero.
    fill: Vec<Vec<bool>>,
    /// `gram[i][k]`, `k <= i`: the products $(e_i, e_k)$ of the entries that meet in a
    /// column (in column order).
    gram: Vec<Vec<Vec<(usize, usize)>>>,
}

impl Pattern {
    fn new(n: usize, mh: usize, cq: &[Entry]) -> Self {
        let mut at = vec![HashMap::new(); mh];
        for (k, e) in cq.iter().enumerate() {
            at[e.row as usize].insert(e.col as usize, k);
        }
        let gram: Vec<Vec<Vec<(usize, usize)>>> = (0..mh)
            .map(|i| {
                (0..=i)
                    .map(|k| {
                        (0..n)
                            .filter_map(|c| Some((*at[i].get(&c)?, *at[k].get(&c)?)))
                            .collect()
                    })
                    .collect()
            })
            .collect();
        // L_ik ≠ 0 when G_ik is, or an earlier column j holds both rows.
        let mut fill = vec![Vec::new(); mh];
        for i in 0..mh {
            for k in 0..i {
                let direct = !gram[i][k].is_empty();
                let through = (0..k).any(|j| fill[i][j] && fill[k][j]);
                fill[i].push(direct || through);
            }
        }
        Self { at, fill, gram }
    }

    fn nz(&self, i: usize, k: usize) -> bool {
        self.fill[i][k]
    }

    /// Multiplications and additions of the Gram matrix, the factorization and the
    /// `n` solves.
    fn operations(&self, n: usize) -> usize {
        let mh = self.fill.len();
        let mut ops: usize = self.gram.iter().flatten().map(|p| 2 * p.len()).sum();
        for k in 0..mh {
            ops += 2 + 2 * (0..k).filter(|&j| self.nz(k, j)).count();
            for i in k + 1..mh {
                if self.nz(i, k) {
                    ops += 2 + 2 * (0..k).filter(|&j| self.nz(i, j) && self.nz(k, j)).count();
                }
            }
        }
        // A column's substitutions touch L twice and D once.
        let l: usize = self.fill.iter().flatten().filter(|&&f| f).count();
        ops + n * (4 * l + mh)
    }
}

/// The trait method `holonomic_normal_map` for the pattern of $C_q$ (see the module
/// docs); nothing for a model without holonomic rows or above the budget.
pub fn holonomic_normal_map(n: usize, mh: usize, cq: &[Entry]) -> TokenStream {
    if mh == 0 || n == 0 || cq.is_empty() {
        return TokenStream::new();
    }
    let pattern = Pattern::new(n, mh, cq);
    if pattern.operations(n) > BUDGET {
        return TokenStream::new();
    }
    let lit = Literal::usize_unsuffixed;
    let g = |i: usize, k: usize| format_ident!("g{}_{}", i, k);
    let l = |i: usize, k: usize| format_ident!("l{}_{}", i, k);
    let w = |i: usize, k: usize| format_ident!("w{}_{}", i, k);
    let d = |k: usize| format_ident!("d{}", k);
    let r = |k: usize| format_ident!("r{}", k);
    let mut code = TokenStream::new();
    // G's entries: the diagonal always (a row without entries is 0, a zero pivot).
    for i in 0..mh {
        for k in 0..=i {
            let products = &pattern.gram[i][k];
            if products.is_empty() && k < i {
                continue;
            }
            let terms = products.iter().map(|&(a, b)| {
                let (a, b) = (lit(a), lit(b));
                quote!(cq[#a] * cq[#b])
            });
            let sum = if products.is_empty() {
                quote!(0.0)
            } else {
                quote!(#(#terms)+*)
            };
            let name = g(i, k);
            code.extend(quote!(let #name = #sum;));
        }
    }
    // L D Lᵀ, left-looking by columns: w_ik = G_ik − Σ_j l_ij w_kj (w = L D), the pivot
    // d_k = G_kk − Σ_j l_kj w_kj, l_ik = w_ik / d_k. A pivot that is not positive (NaN
    // included) ends the function with the ratio 0.
    let zero = quote!(return ::core::option::Option::Some(0.0););
    let mut rho = Vec::with_capacity(mh);
    for k in 0..mh {
        let terms: Vec<TokenStream> = (0..k)
            .filter(|&j| pattern.nz(k, j))
            .map(|j| {
                let (lk, wk) = (l(k, j), w(k, j));
                quote!(- #lk * #wk)
            })
            .collect();
        let (dk, rk, gk) = (d(k), r(k), g(k, k));
        code.extend(quote! {
            let #dk = #gk #(#terms)*;
            if !(#dk > 0.0) {
                #zero
            }
            let #rk = 1.0 / #dk;
        });
        let rho_k = format_ident!("rho{}", k);
        code.extend(quote!(let #rho_k = #dk / #gk;));
        rho.push(rho_k);
        for i in k + 1..mh {
            if !pattern.nz(i, k) {
                continue;
            }
            let base = if pattern.gram[i][k].is_empty() {
                quote!(0.0)
            } else {
                let gik = g(i, k);
                quote!(#gik)
            };
            let terms = (0..k)
                .filter(|&j| pattern.nz(i, j) && pattern.nz(k, j))
                .map(|j| {
                    let (li, wk) = (l(i, j), w(k, j));
                    quote!(- #li * #wk)
                });
            let (wi, li) = (w(i, k), l(i, k));
            code.extend(quote! {
                let #wi = #base #(#terms)*;
                let #li = #wi * #rk;
            });
        }
    }
    let (first, rest) = rho.split_first().expect("a row");
    let mut most = quote!(#first);
    let mut least = quote!(#first);
    for x in rest {
        most = quote!(#most.max(#x));
        least = quote!(#least.min(#x));
    }
    code.extend(quote!(let ratio = (#least) / (#most);));
    // The columns of X: L y = b (b the column of N), z = D⁻¹ y, Lᵀ x = z, over the
    // structurally non-zero entries of y and x only.
    for c in 0..n {
        let b: Vec<Option<usize>> = (0..mh).map(|i| pattern.at[i].get(&c).copied()).collect();
        let mut block = TokenStream::new();
        let mut y_nz = vec![false; mh];
        let y = |i: usize| format_ident!("y{}", i);
        let x = |i: usize| format_ident!("x{}", i);
        for i in 0..mh {
            let mut items: Vec<TokenStream> = Vec::new();
            if let Some(e) = b[i] {
                let e = lit(e);
                items.push(quote!(cq[#e]));
            }
            let terms: Vec<TokenStream> = (0..i)
                .filter(|&j| y_nz[j] && pattern.nz(i, j))
                .map(|j| {
                    let (lij, yj) = (l(i, j), y(j));
                    quote!(#lij * #yj)
                })
                .collect();
            if items.is_empty() && terms.is_empty() {
                continue;
            }
            y_nz[i] = true;
            let head = items.pop().unwrap_or_else(|| quote!(0.0));
            let yi = y(i);
            block.extend(quote!(let #yi = #head #(- #terms)*;));
        }
        let mut x_nz = vec![false; mh];
        for i in (0..mh).rev() {
            let terms: Vec<TokenStream> = (i + 1..mh)
                .filter(|&j| x_nz[j] && pattern.nz(j, i))
                .map(|j| {
                    let (lji, xj) = (l(j, i), x(j));
                    quote!(#lji * #xj)
                })
                .collect();
            let out = lit(i * n + c);
            if !y_nz[i] && terms.is_empty() {
                block.extend(quote!(map[#out] = 0.0;));
                continue;
            }
            x_nz[i] = true;
            let xi = x(i);
            let head = if y_nz[i] {
                let (yi, ri) = (y(i), r(i));
                quote!(#yi * #ri)
            } else {
                quote!(0.0)
            };
            block.extend(quote! {
                let #xi = #head #(- #terms)*;
                map[#out] = #xi;
            });
        }
        code.extend(quote!({ #block }));
    }
    let (cq_len, len) = (lit(cq.len()), lit(mh * n));
    quote! {
        fn holonomic_normal_map(&self, cq: &[f64], map: &mut [f64]) -> ::core::option::Option<f64> {
            let cq = &cq[..#cq_len];
            let map = &mut map[..#len];
            #code
            ::core::option::Option::Some(ratio)
        }
    }
}
