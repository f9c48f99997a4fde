//! Dense $LU$ with complete pivoting, $P A Q = L U$, on a reusable buffer.
//!
//! Input: a square matrix written into [`DenseLu::matrix_mut`]. Output: the factors in
//! place, the permutations, and the pivot magnitudes (the diagonal of $U$, which with
//! complete pivoting is non-increasing in exact arithmetic and reveals the rank).
//!
//! **Equilibration.** Before factoring, the rows and then the columns are scaled by
//! powers of two to a largest magnitude in $[1/\sqrt2, \sqrt2)$ ($A \to D_r A D_c$; exact
//! in floating point), and solves undo the scaling. Units enter the matrices of the
//! runtime as row and column scalings (the unit of a constraint scales its row of
//! $C_q$, the unit of a coordinate its column, a mass unit the block $M$), so the pivot
//! ratio, which decides singularity, does not depend on them: a pendulum of 1 t is as
//! regular as one of 1 kg.
//!
//! Invariant: no allocation after [`DenseLu::new`].

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::full_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{Mat, MatMut, Par};

/// Pivot magnitudes of a factorization: $\max_k |u_{kk}|$ and $\min_k |u_{kk}|$.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Pivots {
    pub max: f64,
    pub min: f64,
}

impl Pivots {
    /// $\min|u_{kk}| / \max|u_{kk}|$; 1 for an empty matrix, 0 when singular or not finite.
    pub fn ratio(self) -> f64 {
        if self.max == 0.0 && self.min == 0.0 {
            return 0.0;
        }
        let r = self.min / self.max;
        if r.is_finite() {
            r
        } else {
            0.0
        }
    }
}

/// A reusable complete-pivoting $LU$ of an `n × n` matrix.
pub(crate) struct DenseLu {
    n: usize,
    a: Mat<f64>,
    row_fwd: Vec<usize>,
    row_inv: Vec<usize>,
    col_fwd: Vec<usize>,
    col_inv: Vec<usize>,
    mem: MemBuffer,
    rhs_cols: usize,
    /// Row and column scale factors of the last factorization (powers of two).
    row_scale: Vec<f64>,
    col_scale: Vec<f64>,
}

impl std::fmt::Debug for DenseLu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DenseLu")
            .field("n", &self.n)
            .finish_non_exhaustive()
    }
}

impl DenseLu {
    /// Buffers for an `n × n` matrix and right-hand sides of up to `rhs_cols` columns.
    pub fn new(n: usize, rhs_cols: usize) -> Self {
        let req = StackReq::any_of(&[
            factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Default::default()),
            solve::solve_in_place_scratch::<usize, f64>(n, rhs_cols.max(1), Par::Seq),
        ]);
        Self {
            n,
            a: Mat::zeros(n, n),
            row_fwd: vec![0; n],
            row_inv: vec![0; n],
            col_fwd: vec![0; n],
            col_inv: vec![0; n],
            mem: MemBuffer::new(req),
            rhs_cols: rhs_cols.max(1),
            row_scale: vec![1.0; n],
            col_scale: vec![1.0; n],
        }
    }

    pub fn dim(&self) -> usize {
        self.n
    }

    /// The matrix to factor (column-major); overwritten by the factors.
    pub fn matrix_mut(&mut self) -> MatMut<'_, f64> {
        self.a.as_mut()
    }

    /// Equilibrates and factors the matrix in place and returns the pivot magnitudes
    /// of the equilibrated matrix.
    pub fn factor(&mut self) -> Pivots {
        let n = self.n;
        if n == 0 {
            return Pivots { max: 1.0, min: 1.0 };
        }
        for i in 0..n {
            let mut big = 0.0_f64;
            for j in 0..n {
                big = big.max(self.a[(i, j)].abs());
            }
            let s = power_of_two_inverse(big);
            self.row_scale[i] = s;
            for j in 0..n {
                self.a[(i, j)] *= s;
            }
        }
        for j in 0..n {
            let mut big = 0.0_f64;
            for i in 0..n {
                big = big.max(self.a[(i, j)].abs());
            }
            let s = power_of_two_inverse(big);
            self.col_scale[j] = s;
            for i in 0..n {
                self.a[(i, j)] *= s;
            }
        }
        let _ = factor::lu_in_place(
            self.a.as_mut(),
            &mut self.row_fwd,
            &mut self.row_inv,
            &mut self.col_fwd,
            &mut self.col_inv,
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        );
        let mut max = 0.0_f64;
        let mut min = f64::INFINITY;
        for k in 0..n {
            let u = self.a[(k, k)].abs();
            if u.is_nan() {
                return Pivots { max, min: 0.0 };
            }
            max = max.max(u);
            min = min.min(u);
        }
        Pivots { max, min }
    }

    /// The sign of $\det A$ from the last factorization: the product of the signs of
    /// the pivots and of the two permutations ($0$ when a pivot is zero or NaN).
    pub fn det_sign(&self) -> f64 {
        let n = self.n;
        let mut sign = 1.0;
        for k in 0..n {
            let u = self.a[(k, k)];
            if u == 0.0 || u.is_nan() {
                return 0.0;
            }
            sign *= u.signum();
        }
        if odd(&self.row_fwd) != odd(&self.col_fwd) {
            sign = -sign;
        }
        sign
    }

    /// Solves $A X = B$ in place with the last factorization; `rhs` is `n × k`,
    /// `k ≤ rhs_cols`.
    pub fn solve_in_place(&mut self, mut rhs: MatMut<'_, f64>) {
        if self.n == 0 {
            return;
        }
        debug_assert!(rhs.ncols() <= self.rhs_cols);
        // D_r A D_c (D_c⁻¹ x) = D_r b.
        for k in 0..rhs.ncols() {
            for i in 0..self.n {
                rhs[(i, k)] *= self.row_scale[i];
            }
        }
        let row = PermRef::new_checked(&self.row_fwd, &self.row_inv, self.n);
        let col = PermRef::new_checked(&self.col_fwd, &self.col_inv, self.n);
        solve::solve_in_place(
            self.a.as_ref(),
            self.a.as_ref(),
            row,
            col,
            rhs.as_mut(),
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
        for k in 0..rhs.ncols() {
            for i in 0..self.n {
                rhs[(i, k)] *= self.col_scale[i];
            }
        }
    }

    /// Solves $A x = b$ for one vector in place.
    pub fn solve_vec(&mut self, b: &mut [f64]) {
        let n = self.n;
        self.solve_in_place(MatMut::from_column_major_slice_mut(b, n, 1));
    }
}

/// The power of two nearest to $1/x$ (in the log sense), 1 for zero or non-finite $x$
/// (a zero row stays zero and keeps the factorization singular), clamped so that the
/// factor stays a normal number.
///
/// Read from the bits of a normal $x = m\,2^e$, $m \in [1, 2)$: the nearest power is
/// $2^e$ below $m = \sqrt2$ and $2^{e+1}$ from it (it runs twice per row and column of
/// every small factorization, where a `log2` would cost as much as the elimination).
pub(crate) fn power_of_two_inverse(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return 1.0;
    }
    let bits = x.abs().to_bits();
    let biased = (bits >> 52) & 0x7ff;
    if biased == 0 {
        // Subnormal: beyond the clamp.
        return 2.0_f64.powi(1000);
    }
    #[allow(clippy::cast_possible_wrap)]
    let mut e = biased as i64 - 1023;
    if f64::from_bits((bits & ((1 << 52) - 1)) | (1023 << 52)) >= std::f64::consts::SQRT_2 {
        e += 1;
    }
    let e = (-e).clamp(-1000, 1000);
    #[allow(clippy::cast_sign_loss)]
    f64::from_bits(((e + 1023) as u64) << 52)
}

#[cfg(test)]
mod power_tests {
    use std::f64::consts::SQRT_2;

    use super::power_of_two_inverse;

    /// The nearest power of two to 1/x in the log sense, against `log2` (at powers of
    /// two, on either side of the √2 midpoints, and at the extremes).
    #[test]
    fn matches_the_rounded_logarithm() {
        let slow = |x: f64| 2.0_f64.powi((-x.log2().round()).clamp(-1000.0, 1000.0) as i32);
        for k in -1000..=1000 {
            let p = 2.0_f64.powi(k);
            for x in [
                p,
                p * (SQRT_2 - 1e-4),
                p * (SQRT_2 + 1e-4),
                p * 1.9,
                p * 0.75,
            ] {
                assert_eq!(power_of_two_inverse(x), slow(x), "{x:e}");
                assert_eq!(power_of_two_inverse(-x), slow(x), "{x:e}");
            }
        }
        assert_eq!(power_of_two_inverse(0.0), 1.0);
        assert_eq!(power_of_two_inverse(f64::NAN), 1.0);
        assert_eq!(power_of_two_inverse(1e-310), 2.0_f64.powi(1000));
    }
}

/// Whether a permutation is odd: $n$ minus its number of cycles, each cycle counted at
/// its smallest index (quadratic, but allocation-free; the matrices are small).
fn odd(perm: &[usize]) -> bool {
    let mut transpositions = 0;
    for (i, &first) in perm.iter().enumerate() {
        let mut j = first;
        let mut smallest = true;
        let mut len = 1;
        while j != i {
            if j < i {
                smallest = false;
                break;
            }
            j = perm[j];
            len += 1;
        }
        if smallest {
            transpositions += len - 1;
        }
    }
    transpositions % 2 == 1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn det_sign_follows_the_determinant() {
        // det = 0*… : a permuted matrix with det -6 and one with det +6.
        for (entries, expected) in [
            ([[0.0, 2.0, 0.0], [3.0, 0.0, 0.0], [0.0, 0.0, 1.0]], -1.0),
            ([[0.0, 2.0, 0.0], [0.0, 0.0, 3.0], [1.0, 0.0, 0.0]], 1.0),
            ([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 10.0]], -1.0),
        ] {
            let mut lu = DenseLu::new(3, 1);
            {
                let mut a = lu.matrix_mut();
                for (i, row) in entries.iter().enumerate() {
                    for (j, v) in row.iter().enumerate() {
                        a[(i, j)] = *v;
                    }
                }
            }
            lu.factor();
            assert_eq!(lu.det_sign(), expected, "{entries:?}");
        }
    }
}
