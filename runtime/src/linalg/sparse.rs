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
use faer::sparse::linalg::lu::{
    factorize_symbolic_lu, LuRef, LuSymbolicParams, NumericLu, SymbolicLu,
};
use faer::sparse::linalg::{LuError, SupernodalThreshold};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};

use crate::Info;

/// Sparse augmented matrix with its symbolic and numeric $LU$.
pub(crate) struct SparseKkt {
    dim: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
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
            .field("nnz", &self.row_idx.len())
            .finish_non_exhaustive()
    }
}

/// Where a stored entry of $K$ takes its value from.
#[derive(Clone, Copy)]
enum Source {
    Mass(usize),
    Cq(usize, usize),
    G(usize, usize),
}

impl SparseKkt {
    /// Builds the structure and the symbolic factorization from the patterns of `info`.
    pub fn new(info: &Info) -> Result<Self, LuError> {
        let n = info.nq();
        let mh = info.nh();
        let dim = n + mh + info.nnh();
        // (column, row, source): sorting gives the compressed-column order.
        let mut entries: Vec<(usize, usize, Source)> = Vec::new();
        for (k, &(r, c)) in info.mass_pattern.iter().enumerate() {
            entries.push((c as usize, r as usize, Source::Mass(k)));
        }
        for (k, &(r, c)) in info.holonomic_pattern.iter().enumerate() {
            let (r, c) = (r as usize, c as usize);
            entries.push((c, n + r, Source::Cq(k, 0)));
            entries.push((n + r, c, Source::Cq(k, 1)));
        }
        for (k, &(r, c)) in info.nonholonomic_pattern.iter().enumerate() {
            let (r, c) = (r as usize, c as usize);
            entries.push((c, n + mh + r, Source::G(k, 0)));
            entries.push((n + mh + r, c, Source::G(k, 1)));
        }
        entries.sort_by_key(|e| (e.0, e.1));
        let mut col_ptr = vec![0usize; dim + 1];
        let mut row_idx = Vec::with_capacity(entries.len());
        let mut mass_map = vec![0; info.mass_pattern.len()];
        let mut cq_map = vec![[0; 2]; info.holonomic_pattern.len()];
        let mut g_map = vec![[0; 2]; info.nonholonomic_pattern.len()];
        for (pos, &(c, r, src)) in entries.iter().enumerate() {
            col_ptr[c + 1] += 1;
            row_idx.push(r);
            match src {
                Source::Mass(k) => mass_map[k] = pos,
                Source::Cq(k, s) => cq_map[k][s] = pos,
                Source::G(k, s) => g_map[k][s] = pos,
            }
        }
        for c in 0..dim {
            col_ptr[c + 1] += col_ptr[c];
        }
        let symbolic = factorize_symbolic_lu(
            SymbolicSparseColMatRef::new_checked(dim, dim, &col_ptr, None, &row_idx),
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
            values: vec![0.0; row_idx.len()],
            col_ptr,
            row_idx,
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
        self.row_idx.len()
    }

    /// Writes the pattern values of $M$, $C_q$ and $G$ into $K$.
    pub fn fill(&mut self, mass: &[f64], cq: &[f64], g: &[f64]) {
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
    }

    fn matrix(&self) -> SparseColMatRef<'_, usize, f64> {
        SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(
                self.dim,
                self.dim,
                &self.col_ptr,
                None,
                &self.row_idx,
            ),
            &self.values,
        )
    }

    /// Numeric factorization of the current values.
    pub fn factor(&mut self) -> Result<(), LuError> {
        let a = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(
                self.dim,
                self.dim,
                &self.col_ptr,
                None,
                &self.row_idx,
            ),
            &self.values,
        );
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
