//! The sparse augmented matrix $K = \begin{bmatrix}M & J^\mathsf{T}\\ J & 0\end{bmatrix}$,
//! $J = [C_q; G]$, in compressed-column form, with a sparse $LU$.
//!
//! Input: the patterns of [`Info`] (structure, once) and the pattern values of $M$,
//! $C_q$ and $G$ (numbers, each call). The structure, the scatter maps from pattern
//! entries to stored values, and the symbolic factorization (COLAMD ordering, elimination
//! tree) are computed once in [`SparseKkt::new`]; [`SparseKkt::fill`] and
//! [`SparseKkt::factor`] only touch numbers. Row pivoting is partial (by magnitude) in
//! the numeric factorization, which the zero $(2,2)$ block requires.
//!
//! Invariant: after the first numeric factorization (which sizes the factors) no call
//! allocates as long as the fill stays the same.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::amd;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LdltRef, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::lu::{
    factorize_symbolic_lu, LuRef, LuSymbolicParams, NumericLu, SymbolicLu,
};
use faer::sparse::linalg::{LuError, SupernodalThreshold};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

use crate::Info;

/// Sparse augmented matrix with its symbolic and numeric $LU$.
pub(crate) struct SparseKkt {
    dim: usize,
    /// The structure of $K$ in compressed columns (checked once, here).
    structure: SymbolicSparseColMat<usize>,
    values: Vec<f64>,
    mass_map: Vec<usize>,
    cq_map: Vec<[usize; 2]>,
    g_map: Vec<[usize; 2]>,
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    mem: MemBuffer,
}

impl std::fmt::Debug for SparseKkt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SparseKkt")
            .field("dim", &self.dim)
            .field("nnz", &self.values.len())
            .finish_non_exhaustive()
    }
}

impl SparseKkt {
    /// Builds the structure and the symbolic factorization from the patterns of `info`.
    pub fn new(info: &Info) -> Result<Self, LuError> {
        let n = info.nq();
        let mh = info.nh();
        let dim = n + mh + info.nnh();
        // (column, row) of every entry: M's, and J's in both of its blocks.
        let j: Vec<(usize, usize)> = info
            .holonomic_pattern
            .iter()
            .map(|&(r, c)| (n + r as usize, c as usize))
            .chain(
                info.nonholonomic_pattern
                    .iter()
                    .map(|&(r, c)| (n + mh + r as usize, c as usize)),
            )
            .collect();
        let entries = info
            .mass_pattern
            .iter()
            .map(|&(r, c)| (c as usize, r as usize))
            .chain(j.iter().flat_map(|&(r, c)| [(c, r), (r, c)]))
            .collect();
        let (col_ptr, row_idx) = compressed(entries, dim);
        let at = |r: usize, c: usize| find(&col_ptr, &row_idx, r, c).expect("a stored entry");
        let mass_map = info
            .mass_pattern
            .iter()
            .map(|&(r, c)| at(r as usize, c as usize))
            .collect();
        let mut j_map = j.iter().map(|&(r, c)| [at(c, r), at(r, c)]);
        let cq_map = j_map.by_ref().take(info.holonomic_pattern.len()).collect();
        let g_map = j_map.collect();
        let structure = SymbolicSparseColMat::new_checked(dim, dim, col_ptr, None, row_idx);
        let symbolic = factorize_symbolic_lu(
            structure.as_ref(),
            LuSymbolicParams {
                // The augmented matrices of mechanisms are very sparse (banded for
                // chains); supernodes buy nothing and their numeric phase allocates.
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
                ..Default::default()
            },
        )
        .map_err(LuError::Generic)?;
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        Ok(Self {
            dim,
            values: vec![0.0; structure.row_idx().len()],
            structure,
            mass_map,
            cq_map,
            g_map,
            symbolic,
            numeric: NumericLu::new(),
            mem: MemBuffer::new(req),
        })
    }

    /// Stored entries of $K$.
    pub fn nnz(&self) -> usize {
        self.values.len()
    }

    /// Writes the pattern values of $M$, $C_q$ and $G$ into $K$.
    pub fn fill(&mut self, mass: &[f64], cq: &[f64], g: &[f64]) -> &mut Self {
        for (&p, &v) in self.mass_map.iter().zip(mass) {
            self.values[p] = v;
        }
        for (p, &v) in self.cq_map.iter().zip(cq) {
            self.values[p[0]] = v;
            self.values[p[1]] = v;
        }
        for (p, &v) in self.g_map.iter().zip(g) {
            self.values[p[0]] = v;
            self.values[p[1]] = v;
        }
        self
    }

    fn matrix(&self) -> SparseColMatRef<'_, usize, f64> {
        SparseColMatRef::new(self.structure.as_ref(), &self.values)
    }

    /// Numeric factorization of the current values.
    pub fn factor(&mut self) -> Result<(), LuError> {
        let a = SparseColMatRef::new(self.structure.as_ref(), &self.values);
        self.symbolic
            .factorize_numeric_lu(
                &mut self.numeric,
                a,
                Par::Seq,
                MemStack::new(&mut self.mem),
                Default::default(),
            )
            .map(|_| ())
    }

    /// Solves $K x = b$ in place with the last factorization.
    pub fn solve_in_place(&mut self, b: &mut [f64]) {
        let lu = LuRef::new_unchecked(&self.symbolic, &self.numeric);
        lu.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(b, self.dim, 1),
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }

    /// $\lVert Kx - b\rVert_\infty$ and the scale $\max|K_{ij}|\,\lVert x\rVert_\infty +
    /// \lVert b\rVert_\infty$ against which to judge it.
    pub fn residual(&self, x: &[f64], b: &[f64], r: &mut [f64]) -> (f64, f64) {
        r.copy_from_slice(b);
        let a = self.matrix();
        let mut kmax = 0.0_f64;
        for (j, &xj) in x.iter().enumerate() {
            for (i, &v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
                r[i] -= v * xj;
                kmax = kmax.max(v.abs());
            }
        }
        let scale = kmax * super::inf_norm(x) + super::inf_norm(b);
        (super::inf_norm(r), scale)
    }
}

/// The smallest accepted ratio of a pivot of [`SparseLdlt`] to the diagonal it started
/// from (the generated solve's test, `pfaff_codegen::emit::solve::PIVOT_RATIO`).
const PIVOT_RATIO: f64 = 1e-8;

/// An entry of $\rho\, J_r^\mathsf{T} J_r$ added to $M$ (see [`SparseLdlt`]): the
/// positions in the row's entries of its two factors and where it is added.
#[derive(Clone, Copy, Debug)]
struct Added {
    a: usize,
    b: usize,
    at: usize,
}

/// A holonomic row added to $M$ in the augmented-Lagrangian way.
#[derive(Clone, Debug)]
struct AddedRow {
    /// The row of $C_q$.
    row: usize,
    /// Its entries: `(column, index in the pattern of C_q)`.
    entries: Vec<(usize, usize)>,
    /// The products of its entries that land in the lower triangle of $M$.
    products: Vec<Added>,
    /// $\rho$ of the last fill.
    rho: f64,
}

/// The sparse $LDL^\mathsf{T}$ of the augmented matrix without pivoting, in the
/// generated solve's order: every coordinate before every multiplier, an approximate
/// minimum degree order within each group.
///
/// Eliminating the coordinates first makes the first $n$ pivots those of $M$ (positive)
/// and the last $m$ those of $-J M^{-1} J^\mathsf{T}$ (negative), so no pivoting is
/// needed while $M$ is positive definite and $J$ has full rank; and since $M$ couples
/// only the coordinates of one body, the Schur complement couples only the constraints
/// that share a body: the factor stays as sparse as the mechanism's graph (a chain's is
/// banded), where the general $LU$ with partial pivoting (COLAMD order, rows swapped
/// by magnitude) fills more and spends its time on the pivot search.
///
/// A holonomic row whose columns form a block of $M$'s pattern (Euler parameters'
/// normalization, along whose gradient $M$ is singular) is added to $M$ as
/// $\tilde M = M + \rho J_r^\mathsf{T} J_r$, $\tilde Q = Q + \rho J_r^\mathsf{T}
/// \gamma_r$, which changes neither the pattern nor the solution ($J_r \ddot q =
/// \gamma_r$), with $\rho = \sum_c M_{cc} / \sum_c J_{rc}^2$ over the row's columns (no
/// dependence on units), as the generated solve does.
///
/// Every pivot is checked, relative to the diagonal it started from: $d_k > \epsilon
/// \tilde M_{kk}$ for a coordinate, $-d_k > \epsilon \sum_c J_{kc}^2 / \tilde M_{cc}$ for
/// a multiplier ($\epsilon$ = [`PIVOT_RATIO`]; both invariant under a change of units).
/// A failed pivot (redundant or nearly dependent constraints, a mass matrix singular
/// off the constraints) hands the system to the $LU$.
pub(crate) struct SparseLdlt {
    n: usize,
    dim: usize,
    /// The upper triangle of $\tilde K$ in compressed columns, rows and columns already
    /// in elimination order (so that neither the factorization nor the solve permutes
    /// or transposes anything per call), checked once.
    structure: SymbolicSparseColMat<usize>,
    values: Vec<f64>,
    /// Position of each entry of the pattern of $M$ (`None`: the mirror of a stored
    /// entry).
    mass_map: Vec<Option<usize>>,
    /// Position of each entry of $C_q$ and $G$.
    cq_map: Vec<usize>,
    g_map: Vec<usize>,
    /// `(row, column)` of each entry of $C_q$ and $G$, rows of $G$ after those of $C_q$.
    j_entries: Vec<(usize, usize)>,
    /// Position of the diagonal entry of each coordinate.
    diagonal: Vec<usize>,
    added: Vec<AddedRow>,
    /// Elimination position → node.
    order: Vec<usize>,
    /// Node → elimination position.
    position: Vec<usize>,
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    /// The pivot scale of each multiplier, $\sum_c J_{kc}^2 / \tilde M_{cc}$.
    scale: Vec<f64>,
    /// The right-hand side in elimination order.
    permuted: Vec<f64>,
    mem: MemBuffer,
}

impl std::fmt::Debug for SparseLdlt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SparseLdlt")
            .field("dim", &self.dim)
            .field("nnz_l", &self.l_values.len())
            .finish_non_exhaustive()
    }
}

/// Compressed columns of the entries `(column, row)` (sorted and deduplicated here)
/// and the position of an entry in them.
fn compressed(mut entries: Vec<(usize, usize)>, dim: usize) -> (Vec<usize>, Vec<usize>) {
    entries.sort_unstable();
    entries.dedup();
    let mut col_ptr = vec![0usize; dim + 1];
    let mut row_idx = Vec::with_capacity(entries.len());
    for &(c, r) in &entries {
        col_ptr[c + 1] += 1;
        row_idx.push(r);
    }
    for c in 0..dim {
        col_ptr[c + 1] += col_ptr[c];
    }
    (col_ptr, row_idx)
}

/// The position of entry `(row, col)` in compressed columns, if stored.
fn find(col_ptr: &[usize], row_idx: &[usize], row: usize, col: usize) -> Option<usize> {
    let column = &row_idx[col_ptr[col]..col_ptr[col + 1]];
    column.binary_search(&row).ok().map(|k| col_ptr[col] + k)
}

impl SparseLdlt {
    /// The structure, the order and the symbolic factorization from the patterns of
    /// `info`; `None` when a coordinate has no diagonal mass entry (then $M$ is
    /// singular for every value) or the symbolic factorization fails.
    pub fn new(info: &Info) -> Option<Self> {
        Self::with_patterns(
            info.nq(),
            info.mass_pattern,
            (info.holonomic_pattern, info.nh()),
            (info.nonholonomic_pattern, info.nnh()),
        )
    }

    /// [`new`](Self::new) for the patterns of $M$ (`n × n`), $C_q$ (`mh` rows) and $G$
    /// (`mnh` rows) given apart from a model's [`Info`].
    pub fn with_patterns(
        n: usize,
        mass_pattern: &[(u32, u32)],
        (holonomic_pattern, mh): (&[(u32, u32)], usize),
        (nonholonomic_pattern, mnh): (&[(u32, u32)], usize),
    ) -> Option<Self> {
        let dim = n + mh + mnh;
        // Every entry of K̃ as (node, node), M's and J's, in the original numbering.
        let j_entries: Vec<(usize, usize)> = holonomic_pattern
            .iter()
            .map(|&(r, c)| (r as usize, c as usize))
            .chain(
                nonholonomic_pattern
                    .iter()
                    .map(|&(r, c)| (mh + r as usize, c as usize)),
            )
            .collect();
        let pairs: Vec<(usize, usize)> = mass_pattern
            .iter()
            .map(|&(r, c)| (r as usize, c as usize))
            .chain(j_entries.iter().map(|&(r, c)| (n + r, c)))
            .collect();
        // An approximate minimum degree order of the whole pattern (AMD reads the upper
        // triangle), then every coordinate before every multiplier, each group in that
        // order.
        let (up_ptr, up_idx) = compressed(
            pairs.iter().map(|&(a, b)| (a.max(b), a.min(b))).collect(),
            dim,
        );
        let mut fwd = vec![0usize; dim];
        let mut inv = vec![0usize; dim];
        {
            let mut mem = MemBuffer::new(amd::order_scratch::<usize>(dim, up_idx.len()));
            amd::order(
                &mut fwd,
                &mut inv,
                SymbolicSparseColMatRef::new_checked(dim, dim, &up_ptr, None, &up_idx),
                amd::Control::default(),
                MemStack::new(&mut mem),
            )
            .ok()?;
        }
        let order: Vec<usize> = fwd
            .iter()
            .copied()
            .filter(|&v| v < n)
            .chain(fwd.iter().copied().filter(|&v| v >= n))
            .collect();
        for (p, &v) in order.iter().enumerate() {
            inv[v] = p;
        }
        // The upper triangle in elimination order: (column, row) = (max, min) of the
        // positions.
        let at = |a: usize, b: usize| {
            let (pa, pb) = (inv[a], inv[b]);
            (pa.max(pb), pa.min(pb))
        };
        let (col_ptr, row_idx) = compressed(pairs.iter().map(|&(a, b)| at(a, b)).collect(), dim);
        let position = |a: usize, b: usize| {
            let (c, r) = at(a, b);
            find(&col_ptr, &row_idx, r, c)
        };
        let mut diagonal = Vec::with_capacity(n);
        for c in 0..n {
            diagonal.push(position(c, c)?);
        }
        // One of each mirror pair of M writes the stored entry.
        let mass_map = mass_pattern
            .iter()
            .map(|&(r, c)| (r >= c).then(|| position(r as usize, c as usize)).flatten())
            .collect();
        let j_map = j_entries
            .iter()
            .map(|&(r, c)| position(n + r, c))
            .collect::<Option<Vec<_>>>()?;
        let (cq_map, g_map) = (
            j_map[..holonomic_pattern.len()].to_vec(),
            j_map[holonomic_pattern.len()..].to_vec(),
        );
        // Rows whose columns are a block of M's pattern: ρ JᵣᵀJᵣ adds no entry.
        let mut added = Vec::new();
        for row in 0..mh {
            let entries: Vec<(usize, usize)> = holonomic_pattern
                .iter()
                .enumerate()
                .filter(|(_, &(r, _))| r as usize == row)
                .map(|(k, &(_, c))| (c as usize, k))
                .collect();
            let mut products = Vec::new();
            let block = entries.iter().enumerate().all(|(a, &(ca, _))| {
                entries.iter().enumerate().all(|(b, &(cb, _))| {
                    if ca < cb {
                        return true;
                    }
                    position(ca, cb).is_some_and(|at| {
                        products.push(Added { a, b, at });
                        true
                    })
                })
            });
            if block && entries.len() > 1 {
                added.push(AddedRow {
                    row,
                    entries,
                    products,
                    rho: 0.0,
                });
            }
        }
        let structure = SymbolicSparseColMat::new_checked(dim, dim, col_ptr, None, row_idx);
        let symbolic = factorize_symbolic_cholesky(
            structure.as_ref(),
            Side::Upper,
            SymmetricOrdering::Identity,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
                ..Default::default()
            },
        )
        .ok()?;
        // The simplicial factor stores each column's diagonal (D) first.
        let SymbolicCholeskyRaw::Simplicial(s) = symbolic.raw() else {
            return None;
        };
        if !(0..dim).all(|j| s.row_idx()[s.col_ptr()[j]] == j) {
            return None;
        }
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        Some(Self {
            n,
            dim,
            values: vec![0.0; structure.row_idx().len()],
            structure,
            mass_map,
            cq_map,
            g_map,
            j_entries,
            diagonal,
            added,
            order,
            position: inv,
            l_values: vec![0.0; symbolic.len_val()],
            symbolic,
            scale: vec![0.0; dim - n],
            permuted: vec![0.0; dim],
            mem: MemBuffer::new(req),
        })
    }

    /// Factors $\tilde K$ from the pattern values of $M$, $C_q$ and $G$; `false` when a
    /// pivot fails its test (see the type's docs).
    pub fn factor(&mut self, mass: &[f64], cq: &[f64], g: &[f64]) -> bool {
        for (p, &v) in self.mass_map.iter().zip(mass) {
            if let Some(p) = *p {
                self.values[p] = v;
            }
        }
        for (&p, &v) in self.cq_map.iter().zip(cq) {
            self.values[p] = v;
        }
        for (&p, &v) in self.g_map.iter().zip(g) {
            self.values[p] = v;
        }
        for row in &mut self.added {
            let (mut trace, mut norm) = (0.0, 0.0);
            for &(c, k) in &row.entries {
                trace += self.values[self.diagonal[c]];
                norm += cq[k] * cq[k];
            }
            row.rho = trace / norm;
            if !(row.rho.is_finite() && row.rho > 0.0) {
                return false;
            }
            for e in &row.products {
                let (ja, jb) = (cq[row.entries[e.a].1], cq[row.entries[e.b].1]);
                self.values[e.at] += row.rho * ja * jb;
            }
        }
        // The multipliers' pivot scales Σ_c J_kc² / M̃_cc.
        self.scale.fill(0.0);
        for (&(r, c), &v) in self.j_entries.iter().zip(cq.iter().chain(g)) {
            self.scale[r] += v * v / self.values[self.diagonal[c]];
        }
        let a = SparseColMatRef::new(self.structure.as_ref(), &self.values);
        let factored = self.symbolic.factorize_numeric_ldlt(
            &mut self.l_values,
            a,
            Side::Upper,
            LdltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        );
        if factored.is_err() {
            return false;
        }
        let SymbolicCholeskyRaw::Simplicial(s) = self.symbolic.raw() else {
            return false;
        };
        let (n, col_ptr) = (self.n, s.col_ptr());
        self.order.iter().enumerate().all(|(k, &v)| {
            let d = self.l_values[col_ptr[k]];
            if v < n {
                d > PIVOT_RATIO * self.values[self.diagonal[v]]
            } else {
                -d > PIVOT_RATIO * self.scale[v - n]
            }
        })
    }

    /// The ratio of the smallest to the largest multiplier pivot of the last
    /// factorization, each relative to its diagonal ($-d_k / \sum_c J_{kc}^2 / \tilde
    /// M_{cc}$): with $M = I$ the pivot ratio of the equilibrated $J J^\mathsf{T}$.
    pub fn schur_ratio(&self) -> f64 {
        let SymbolicCholeskyRaw::Simplicial(s) = self.symbolic.raw() else {
            return 0.0;
        };
        let (mut min, mut max) = (f64::INFINITY, 0.0_f64);
        for (k, &v) in self.order.iter().enumerate().skip(self.n) {
            let p = -self.l_values[s.col_ptr()[k]] / self.scale[v - self.n];
            min = min.min(p);
            max = max.max(p);
        }
        if max > 0.0 && min.is_finite() {
            min / max
        } else {
            0.0
        }
    }

    /// Solves $K x = b$ with the last factorization: `b` holds $[Q; \gamma]$ (the
    /// system's own right-hand side; the terms of the rows added to $M$ are added
    /// here), `x` receives $[\ddot q; \lambda]$.
    pub fn solve(&mut self, b: &[f64], cq: &[f64], x: &mut [f64]) {
        let n = self.n;
        for (p, &v) in self.permuted.iter_mut().zip(&self.order) {
            *p = b[v];
        }
        for row in &self.added {
            let gamma = b[n + row.row];
            for &(c, k) in &row.entries {
                self.permuted[self.position[c]] += row.rho * cq[k] * gamma;
            }
        }
        let lu = LdltRef::new(&self.symbolic, &self.l_values);
        lu.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut self.permuted, self.dim, 1),
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
        for (p, &v) in self.permuted.iter().zip(&self.order) {
            x[v] = *p;
        }
    }
}
