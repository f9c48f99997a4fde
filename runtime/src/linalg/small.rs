//! Factorizations for the small dense systems of one evaluation, without the set-up of a
//! general (blocked, workspace-driven) solver: an $LU$ with partial pivoting and a
//! Cholesky factorization, row-major, in place, with loops the compiler unrolls and
//! vectorizes for the sizes of a mechanism (a few to a few dozen unknowns).
//!
//! Input: a square matrix written into [`SmallLu::matrix_mut`] or
//! [`SmallCholesky::matrix_mut`] (row-major, `n × n`). Output: the factors in place
//! and the pivot magnitudes. Partial pivoting is not rank revealing: callers that must
//! tell a singular matrix from a regular one (the augmented system with redundant
//! constraints) check the returned ratio and fall back to complete pivoting
//! ([`super::dense::DenseLu`]) below their threshold.
//!
//! **Equilibration**, as in [`super::dense`]: the $LU$ scales rows, then columns, the
//! Cholesky factorization rows and columns alike ($D A D$, keeping the symmetry), by
//! powers of two to a largest magnitude near 1 (a unit diagonal for Cholesky), and the
//! solves undo it; the pivot ratios are those of the equilibrated matrix, so they do
//! not depend on the units of the model.
//!
//! Invariant: no allocation after construction.

use super::dense::{power_of_two_inverse, Pivots};

/// Largest size with kernels unrolled for it (`N` a constant: no loop control, no
/// bounds checks in the inner loops); the loops of [`SmallCholesky`] serve the larger
/// ones.
const FIXED: usize = 10;

/// `Some(f::<n>(args))` when `n` is at most [`FIXED`], `None` otherwise.
macro_rules! fixed {
    ($n:expr, $f:ident ( $($arg:expr),* )) => {
        match $n {
            1 => Some($f::<1>($($arg),*)),
            2 => Some($f::<2>($($arg),*)),
            3 => Some($f::<3>($($arg),*)),
            4 => Some($f::<4>($($arg),*)),
            5 => Some($f::<5>($($arg),*)),
            6 => Some($f::<6>($($arg),*)),
            7 => Some($f::<7>($($arg),*)),
            8 => Some($f::<8>($($arg),*)),
            9 => Some($f::<9>($($arg),*)),
            FIXED => Some($f::<FIXED>($($arg),*)),
            _ => None,
        }
    };
}

/// $PA = LU$ with partial (row) pivoting of an `n × n` matrix.
#[derive(Clone, Debug)]
pub(crate) struct SmallLu {
    n: usize,
    a: Vec<f64>,
    perm: Vec<usize>,
    row_scale: Vec<f64>,
    col_scale: Vec<f64>,
}

impl SmallLu {
    pub fn new(n: usize) -> Self {
        Self {
            n,
            a: vec![0.0; n * n],
            perm: vec![0; n],
            row_scale: vec![1.0; n],
            col_scale: vec![1.0; n],
        }
    }

    pub fn dim(&self) -> usize {
        self.n
    }

    /// The matrix to factor, row-major; overwritten by the factors.
    pub fn matrix_mut(&mut self) -> &mut [f64] {
        &mut self.a
    }

    /// Equilibrates and factors in place; returns the pivot magnitudes ($|u_{kk}|$) of
    /// the equilibrated matrix.
    pub fn factor(&mut self) -> Pivots {
        let n = self.n;
        let a = &mut self.a;
        for (row, s) in a.chunks_exact_mut(n.max(1)).zip(&mut self.row_scale) {
            *s = power_of_two_inverse(row.iter().fold(0.0_f64, |m, x| m.max(x.abs())));
            row.iter_mut().for_each(|x| *x *= *s);
        }
        for (j, s) in self.col_scale.iter_mut().enumerate() {
            let big = (0..n).fold(0.0_f64, |m, i| m.max(a[i * n + j].abs()));
            *s = power_of_two_inverse(big);
            for i in 0..n {
                a[i * n + j] *= *s;
            }
        }
        let (mut max, mut min) = (0.0_f64, f64::INFINITY);
        for k in 0..n {
            let mut p = k;
            let mut best = a[k * n + k].abs();
            for i in k + 1..n {
                let v = a[i * n + k].abs();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            self.perm[k] = p;
            if p != k {
                for j in 0..n {
                    a.swap(k * n + j, p * n + j);
                }
            }
            if best.is_nan() {
                return Pivots { max, min: 0.0 };
            }
            max = max.max(best);
            min = min.min(best);
            if best == 0.0 {
                continue;
            }
            let inv = 1.0 / a[k * n + k];
            let (upper, lower) = a.split_at_mut((k + 1) * n);
            let row_k = &upper[k * n + k + 1..k * n + n];
            for row in lower.chunks_exact_mut(n) {
                let l = row[k] * inv;
                row[k] = l;
                if l != 0.0 {
                    for (x, u) in row[k + 1..].iter_mut().zip(row_k) {
                        *x -= l * u;
                    }
                }
            }
        }
        if n == 0 {
            return Pivots { max: 1.0, min: 1.0 };
        }
        Pivots { max, min }
    }

    /// Solves $A x = b$ in place with the last factorization.
    pub fn solve(&self, b: &mut [f64]) {
        let n = self.n;
        let a = &self.a;
        // D_r A D_c (D_c⁻¹ x) = D_r b.
        for (x, s) in b.iter_mut().zip(&self.row_scale) {
            *x *= s;
        }
        for k in 0..n {
            b.swap(k, self.perm[k]);
        }
        for i in 1..n {
            let s: f64 = a[i * n..i * n + i]
                .iter()
                .zip(&b[..i])
                .map(|(l, x)| l * x)
                .sum();
            b[i] -= s;
        }
        for i in (0..n).rev() {
            let s: f64 = a[i * n + i + 1..(i + 1) * n]
                .iter()
                .zip(&b[i + 1..])
                .map(|(u, x)| u * x)
                .sum();
            b[i] = (b[i] - s) / a[i * n + i];
        }
        for (x, s) in b.iter_mut().zip(&self.col_scale) {
            *x *= s;
        }
    }
}

/// $A = L L^\mathsf{T}$ of a symmetric positive definite `n × n` matrix (the lower
/// triangle is read).
///
/// The factor is kept twice, $L$ in the lower triangle and $L^\mathsf{T}$ in the upper
/// one, with the reciprocals of its diagonal: both substitutions of a solve then run
/// along contiguous rows and multiply instead of dividing.
#[derive(Clone, Debug)]
pub(crate) struct SmallCholesky {
    n: usize,
    a: Vec<f64>,
    scale: Vec<f64>,
    /// $1 / l_{kk}$.
    inverse: Vec<f64>,
    /// Scratch of [`inverse_into`](Self::inverse_into) beyond [`FIXED`].
    work: Vec<f64>,
}

impl SmallCholesky {
    pub fn new(n: usize) -> Self {
        Self {
            n,
            a: vec![0.0; n * n],
            scale: vec![1.0; n],
            inverse: vec![1.0; n],
            work: if n > FIXED {
                vec![0.0; n * n]
            } else {
                Vec::new()
            },
        }
    }

    /// The matrix to factor, row-major (its lower triangle is used); overwritten by $L$.
    pub fn matrix_mut(&mut self) -> &mut [f64] {
        &mut self.a[..self.n * self.n]
    }

    /// Makes it the factorization of an `n × n` matrix, `n` at most the size it was
    /// created with (no allocation).
    pub fn resize(&mut self, n: usize) {
        assert!(
            n <= self.scale.len(),
            "SmallCholesky::resize beyond its capacity"
        );
        self.n = n;
    }

    /// Factors in place; returns the magnitudes of the pivots of the equivalent $LU$,
    /// $l_{kk}^2$ (a non-positive pivot, the matrix not positive definite, gives a
    /// minimum of 0).
    pub fn factor(&mut self) -> Pivots {
        let n = self.n;
        if n == 0 {
            return Pivots { max: 1.0, min: 1.0 };
        }
        let (a, scale, inverse) = (&mut self.a, &mut self.scale, &mut self.inverse);
        if let Some(p) = fixed!(n, factor_fixed(a, scale, inverse)) {
            return p;
        }
        let a = &mut self.a[..n * n];
        let scale = &mut self.scale[..n];
        for (i, s) in scale.iter_mut().enumerate() {
            *s = power_of_two_inverse(a[i * n + i].abs().sqrt());
        }
        for (i, row) in a.chunks_exact_mut(n).enumerate() {
            let si = scale[i];
            for (x, sj) in row[..=i].iter_mut().zip(&scale[..=i]) {
                *x *= si * sj;
            }
        }
        let (mut max, mut min) = (0.0_f64, f64::INFINITY);
        // Row by row (the left-looking form): row i of L from the rows above it.
        for i in 0..n {
            let (done, rest) = a.split_at_mut(i * n);
            let row = &mut rest[..n];
            for j in 0..i {
                let lj = &done[j * n..j * n + j];
                let s: f64 = row[..j].iter().zip(lj).map(|(x, y)| x * y).sum();
                row[j] = (row[j] - s) * self.inverse[j];
            }
            let d = row[i] - row[..i].iter().map(|x| x * x).sum::<f64>();
            if d.is_nan() || d <= 0.0 {
                return Pivots {
                    max: max.max(d.abs()),
                    min: 0.0,
                };
            }
            max = max.max(d);
            min = min.min(d);
            let l = d.sqrt();
            row[i] = l;
            self.inverse[i] = 1.0 / l;
        }
        // Lᵀ into the upper triangle, for the backward substitution.
        for i in 0..n {
            for j in i + 1..n {
                a[i * n + j] = a[j * n + i];
            }
        }
        Pivots { max, min }
    }

    /// Solves $A x = b$ in place with the last factorization.
    pub fn solve(&self, b: &mut [f64]) {
        let n = self.n;
        let (a, scale, inverse) = (&self.a, &self.scale, &self.inverse);
        if fixed!(n, solve_fixed(a, scale, inverse, b)).is_some() {
            return;
        }
        let a = &self.a[..n * n];
        let b = &mut b[..n];
        let (scale, inverse) = (&self.scale[..n], &self.inverse[..n]);
        // D A D (D⁻¹ x) = D b.
        for (x, s) in b.iter_mut().zip(scale) {
            *x *= s;
        }
        // Column by column (L y = b with the columns of L, the rows of Lᵀ, then
        // Lᵀ x = y with the columns of Lᵀ, the rows of L): the updates of one column
        // are independent, so the chain of dependent operations is n long, not n².
        for j in 0..n {
            let (head, tail) = b.split_at_mut(j + 1);
            let bj = head[j] * inverse[j];
            head[j] = bj;
            for (x, u) in tail.iter_mut().zip(&a[j * n + j + 1..(j + 1) * n]) {
                *x -= u * bj;
            }
        }
        for i in (0..n).rev() {
            let (head, tail) = b.split_at_mut(i);
            let bi = tail[0] * inverse[i];
            tail[0] = bi;
            for (x, l) in head.iter_mut().zip(&a[i * n..i * n + i]) {
                *x -= l * bi;
            }
        }
        for (x, s) in b.iter_mut().zip(scale) {
            *x *= s;
        }
    }

    /// Solves $A X = B$ in place for the `k` columns of `x` (`n × k`, row-major) with
    /// the last factorization: the substitutions run along the rows of `x`, so the
    /// columns are solved side by side.
    pub fn solve_rows(&self, x: &mut [f64], k: usize) {
        let n = self.n;
        let (a, scale, inverse) = (&self.a, &self.scale, &self.inverse);
        if fixed!(n, solve_rows_fixed(a, scale, inverse, x, k)).is_some() {
            return;
        }
        let a = &self.a[..n * n];
        let x = &mut x[..n * k];
        let (scale, inverse) = (&self.scale[..n], &self.inverse[..n]);
        if k == 0 {
            return;
        }
        for (row, s) in x.chunks_exact_mut(k).zip(scale) {
            row.iter_mut().for_each(|v| *v *= s);
        }
        for j in 0..n {
            let (head, tail) = x.split_at_mut((j + 1) * k);
            let xj = &mut head[j * k..];
            xj.iter_mut().for_each(|v| *v *= inverse[j]);
            for (row, u) in tail.chunks_exact_mut(k).zip(&a[j * n + j + 1..(j + 1) * n]) {
                for (v, w) in row.iter_mut().zip(&*xj) {
                    *v -= u * w;
                }
            }
        }
        for i in (0..n).rev() {
            let (head, tail) = x.split_at_mut(i * k);
            let xi = &mut tail[..k];
            xi.iter_mut().for_each(|v| *v *= inverse[i]);
            for (row, l) in head.chunks_exact_mut(k).zip(&a[i * n..i * n + i]) {
                for (v, w) in row.iter_mut().zip(&*xi) {
                    *v -= l * w;
                }
            }
        }
        for (row, s) in x.chunks_exact_mut(k).zip(scale) {
            row.iter_mut().for_each(|v| *v *= s);
        }
    }

    /// Writes $A^{-1}$ (row-major `n × n`, both triangles) into `out` from the last
    /// factorization, as LAPACK's `potri` forms it: $W = L^{-1}$ by rows, then
    /// $A^{-1} = D W^\mathsf{T} W D$ ($D$ the equilibration). Every entry of both
    /// products is an independent dot product, so the work is $n^3/3$ multiply-adds
    /// without the dependent chains of `n` solves with the columns of the identity.
    pub fn inverse_into(&mut self, out: &mut [f64]) {
        let n = self.n;
        let (a, scale, inverse) = (&self.a, &self.scale, &self.inverse);
        if fixed!(n, inverse_fixed(a, scale, inverse, out)).is_some() {
            return;
        }
        let a = &self.a[..n * n];
        let (scale, inverse) = (&self.scale[..n], &self.inverse[..n]);
        let w = &mut self.work[..n * n];
        let out = &mut out[..n * n];
        // Row i of W from the rows above it: (L W)_{ik} = 0 for k < i.
        for i in 0..n {
            let (done, rest) = w.split_at_mut(i * n);
            let li = &a[i * n..i * n + i];
            for k in 0..i {
                let s: f64 = (k..i).map(|j| li[j] * done[j * n + k]).sum();
                rest[k] = -s * inverse[i];
            }
            rest[i] = inverse[i];
        }
        for i in 0..n {
            for k in 0..=i {
                let s: f64 = (i..n).map(|j| w[j * n + i] * w[j * n + k]).sum();
                let v = s * (scale[i] * scale[k]);
                out[i * n + k] = v;
                out[k * n + i] = v;
            }
        }
    }
}

/// [`SmallCholesky::inverse_into`] for `N × N`.
// Index loops over constant bounds are what the compiler unrolls.
#[allow(clippy::needless_range_loop)]
fn inverse_fixed<const N: usize>(a: &[f64], scale: &[f64], inverse: &[f64], out: &mut [f64]) {
    let (a, scale, inverse, out) = (&a[..N * N], &scale[..N], &inverse[..N], &mut out[..N * N]);
    let mut w = [[0.0_f64; N]; N];
    for i in 0..N {
        for k in 0..i {
            let mut s = 0.0;
            for j in k..i {
                s += a[i * N + j] * w[j][k];
            }
            w[i][k] = -s * inverse[i];
        }
        w[i][i] = inverse[i];
    }
    for i in 0..N {
        for k in 0..=i {
            let mut s = 0.0;
            for j in i..N {
                s += w[j][i] * w[j][k];
            }
            let v = s * (scale[i] * scale[k]);
            out[i * N + k] = v;
            out[k * N + i] = v;
        }
    }
}

/// [`SmallCholesky::factor`] for `N × N` (same operations, in a local array).
// Index loops over constant bounds are what the compiler unrolls.
#[allow(clippy::needless_range_loop)]
fn factor_fixed<const N: usize>(a: &mut [f64], scale: &mut [f64], inverse: &mut [f64]) -> Pivots {
    let (a, scale, inverse) = (&mut a[..N * N], &mut scale[..N], &mut inverse[..N]);
    let mut l = [[0.0_f64; N]; N];
    for i in 0..N {
        scale[i] = power_of_two_inverse(a[i * N + i].abs().sqrt());
    }
    for i in 0..N {
        for j in 0..=i {
            l[i][j] = a[i * N + j] * (scale[i] * scale[j]);
        }
    }
    let (mut max, mut min) = (0.0_f64, f64::INFINITY);
    for i in 0..N {
        for j in 0..i {
            let mut s = 0.0;
            for k in 0..j {
                s += l[i][k] * l[j][k];
            }
            l[i][j] = (l[i][j] - s) * inverse[j];
        }
        let mut s = 0.0;
        for k in 0..i {
            s += l[i][k] * l[i][k];
        }
        let d = l[i][i] - s;
        if d.is_nan() || d <= 0.0 {
            return Pivots {
                max: max.max(d.abs()),
                min: 0.0,
            };
        }
        max = max.max(d);
        min = min.min(d);
        let v = d.sqrt();
        l[i][i] = v;
        inverse[i] = 1.0 / v;
    }
    for i in 0..N {
        for j in 0..N {
            a[i * N + j] = if j <= i { l[i][j] } else { l[j][i] };
        }
    }
    Pivots { max, min }
}

/// The substitutions of [`SmallCholesky::solve`] for `N × N` on the scaled `x`.
// Index loops over constant bounds are what the compiler unrolls.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn substitute_fixed<const N: usize>(a: &[f64], inverse: &[f64], x: &mut [f64; N]) {
    let (a, inverse) = (&a[..N * N], &inverse[..N]);
    for j in 0..N {
        let xj = x[j] * inverse[j];
        x[j] = xj;
        for i in j + 1..N {
            x[i] -= a[j * N + i] * xj;
        }
    }
    for i in (0..N).rev() {
        let xi = x[i] * inverse[i];
        x[i] = xi;
        for j in 0..i {
            x[j] -= a[i * N + j] * xi;
        }
    }
}

/// [`SmallCholesky::solve`] for `N × N`.
// Index loops over constant bounds are what the compiler unrolls.
#[allow(clippy::needless_range_loop)]
fn solve_fixed<const N: usize>(a: &[f64], scale: &[f64], inverse: &[f64], b: &mut [f64]) {
    let (b, scale) = (&mut b[..N], &scale[..N]);
    let mut x = [0.0_f64; N];
    for i in 0..N {
        x[i] = b[i] * scale[i];
    }
    substitute_fixed(a, inverse, &mut x);
    for i in 0..N {
        b[i] = x[i] * scale[i];
    }
}

/// [`SmallCholesky::solve_rows`] for `N × N`: column by column, each one unrolled
/// (the columns' chains are independent, so consecutive ones overlap).
// Index loops over constant bounds are what the compiler unrolls.
#[allow(clippy::needless_range_loop)]
fn solve_rows_fixed<const N: usize>(
    a: &[f64],
    scale: &[f64],
    inverse: &[f64],
    x: &mut [f64],
    k: usize,
) {
    let (x, scale) = (&mut x[..N * k], &scale[..N]);
    for c in 0..k {
        let mut col = [0.0_f64; N];
        for i in 0..N {
            col[i] = x[i * k + c] * scale[i];
        }
        substitute_fixed(a, inverse, &mut col);
        for i in 0..N {
            x[i * k + c] = col[i] * scale[i];
        }
    }
}

/// Writes $A_R A_R^\mathsf{T}$ of the rows `rows` of the dense row-major `a` (`· × n`)
/// into `ch`, factors it and returns the pivot ratio (0 when not positive definite).
///
/// Up to [`FIXED`] rows the lower triangle is accumulated in registers, one column of
/// $A_R$ at a time (a sum of outer products): its `r(r+1)/2` sums are independent, where
/// dot products of rows are each a chain of `n` dependent additions. The sums run over
/// the columns in the same order either way, so the two give the same bits.
///
/// The dense reference of [`gram_cholesky_planned`], which the runtime's Gram matrices
/// use (its tests compare the two bit for bit); the chart uses this one where no plan
/// is at hand (the anchor's $G_a^{-1}$ made late, after the model's generated map).
pub(crate) fn gram_cholesky(ch: &mut SmallCholesky, a: &[f64], rows: &[usize], n: usize) -> f64 {
    let r = rows.len();
    let g = ch.matrix_mut();
    if fixed!(r, gram_fixed(g, a, rows, n)).is_none() {
        for (i, &ri) in rows.iter().enumerate() {
            let ri = &a[ri * n..(ri + 1) * n];
            for (k, &rk) in rows[..=i].iter().enumerate() {
                let rk = &a[rk * n..(rk + 1) * n];
                g[i * r + k] = ri.iter().zip(rk).map(|(x, y)| x * y).sum();
            }
        }
    }
    ch.factor().ratio()
}

/// The products of the Gram matrix $A_R A_R^\mathsf{T}$ of `gram_cholesky` that the
/// sparsity of the rows leaves, for [`gram_cholesky_planned`]: the constraint
/// Jacobians of mechanisms have a few entries per row (andrews' $6 \times 7$ $C_q$ has
/// 20 of 42), so the rows share few columns and most of the $r(r+1)n/2$ products of
/// the dense sums are products with a structural zero.
#[derive(Clone, Debug, Default)]
pub(crate) struct GramPlan {
    r: usize,
    /// `(k, x, y)`: entry `k` of the `r × r` Gram matrix (lower triangle, row-major)
    /// gains `a[x] * a[y]`, with `a` the dense row-major matrix; ordered by column, so
    /// each entry sums its products in the order of the dense loop.
    products: Vec<(u32, u32, u32)>,
}

impl GramPlan {
    /// The plan for the rows `rows` of an `m × n` row-major matrix whose entry `(i, j)`
    /// may be non-zero only where `nonzero(i, j)` (allocates).
    pub fn new(rows: &[usize], n: usize, nonzero: impl Fn(usize, usize) -> bool) -> Self {
        let r = rows.len();
        let index = |v: usize| u32::try_from(v).expect("a matrix of fewer than 2^32 entries");
        // Each column's rows (places in `rows`, ascending) with an entry there: every
        // pair of them is a product, in the dense loop's order. Counted first, so that
        // the plan is one allocation of its size.
        let nonzero = &nonzero;
        let in_column = |j: usize| (0..r).filter(move |&i| nonzero(rows[i], j));
        let count = (0..n)
            .map(|j| {
                let c = in_column(j).count();
                c * (c + 1) / 2
            })
            .sum();
        let mut products = Vec::with_capacity(count);
        let mut column = Vec::with_capacity(r);
        for j in 0..n {
            column.clear();
            column.extend(in_column(j));
            for (a, &i) in column.iter().enumerate() {
                for &k in &column[..=a] {
                    products.push((
                        index(i * r + k),
                        index(rows[i] * n + j),
                        index(rows[k] * n + j),
                    ));
                }
            }
        }
        Self { r, products }
    }
}

/// `gram_cholesky` with the products of `plan` only: the same matrix to the last
/// bit (a skipped product is $\pm 0$, which adds nothing to a sum), so the same
/// factor and ratio.
pub(crate) fn gram_cholesky_planned(ch: &mut SmallCholesky, a: &[f64], plan: &GramPlan) -> f64 {
    let g = ch.matrix_mut();
    debug_assert_eq!(
        g.len(),
        plan.r * plan.r,
        "a factorization of the plan's size"
    );
    g.fill(0.0);
    for &(k, x, y) in &plan.products {
        g[k as usize] += a[x as usize] * a[y as usize];
    }
    ch.factor().ratio()
}

/// The lower triangle of [`gram_cholesky`]'s matrix for `R` rows.
// Index loops over constant bounds are what the compiler unrolls.
#[allow(clippy::needless_range_loop)]
fn gram_fixed<const R: usize>(g: &mut [f64], a: &[f64], rows: &[usize], n: usize) {
    let (g, rows) = (&mut g[..R * R], &rows[..R]);
    let mut acc = [[0.0_f64; R]; R];
    let mut start = [0_usize; R];
    for i in 0..R {
        start[i] = rows[i] * n;
    }
    for j in 0..n {
        let mut col = [0.0_f64; R];
        for i in 0..R {
            col[i] = a[start[i] + j];
        }
        for i in 0..R {
            for k in 0..=i {
                acc[i][k] += col[i] * col[k];
            }
        }
    }
    for i in 0..R {
        for k in 0..=i {
            g[i * R + k] = acc[i][k];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The planned Gram matrix and its factor equal the dense ones bitwise, for a sparse
    /// matrix with values of every magnitude and sign (entries from a sine) and row
    /// sets in and out of order, of every size with and without the fixed kernels.
    #[test]
    fn planned_gram_equals_the_dense_one() {
        for (m, n) in [(3, 4), (6, 7), (12, 13)] {
            // Row i has entries in the columns i, i + 1 and (3i) mod n.
            let nonzero = |i: usize, j: usize| j == i % n || j == (i + 1) % n || j == (3 * i) % n;
            let a: Vec<f64> = (0..m * n)
                .map(|k| {
                    let (i, j) = (k / n, k % n);
                    #[allow(clippy::cast_precision_loss)]
                    let x = (k as f64 * 1.7).sin() * 10f64.powi(i32::try_from(k % 7).unwrap() - 3);
                    if nonzero(i, j) {
                        x
                    } else {
                        0.0
                    }
                })
                .collect();
            let all: Vec<usize> = (0..m).collect();
            let shuffled: Vec<usize> = (0..m).rev().step_by(2).chain(0..1).collect();
            for rows in [&all[..], &all[1..], &shuffled[..]] {
                let r = rows.len();
                let (mut dense, mut planned) = (SmallCholesky::new(r), SmallCholesky::new(r));
                let ratio = gram_cholesky(&mut dense, &a, rows, n);
                let plan = GramPlan::new(rows, n, nonzero);
                assert_eq!(
                    gram_cholesky_planned(&mut planned, &a, &plan).to_bits(),
                    ratio.to_bits()
                );
                for (x, y) in dense.matrix_mut().iter().zip(planned.matrix_mut().iter()) {
                    assert_eq!(x.to_bits(), y.to_bits(), "{m}x{n} rows {rows:?}");
                }
            }
        }
    }

    /// A fixed well-conditioned matrix and right-hand side (entries from a sine, to
    /// avoid structure), solved and checked by the residual.
    #[test]
    fn lu_and_cholesky_solve_to_round_off() {
        for n in [1, 2, 3, 7, 13, 30] {
            let a: Vec<f64> = (0..n * n)
                .map(|k| {
                    let (i, j) = (k / n, k % n);
                    #[allow(clippy::cast_precision_loss)]
                    let x = ((i * 7 + j * 3) as f64).sin();
                    x + if i == j { n as f64 } else { 0.0 }
                })
                .collect();
            #[allow(clippy::cast_precision_loss)]
            let b: Vec<f64> = (0..n).map(|i| (i as f64).cos()).collect();
            let residual = |x: &[f64], m: &[f64]| {
                (0..n)
                    .map(|i| {
                        let r: f64 = (0..n).map(|j| m[i * n + j] * x[j]).sum::<f64>() - b[i];
                        r.abs()
                    })
                    .fold(0.0, f64::max)
            };
            let mut lu = SmallLu::new(n);
            lu.matrix_mut().copy_from_slice(&a);
            assert!(lu.factor().ratio() > 0.0);
            let mut x = b.clone();
            lu.solve(&mut x);
            #[allow(clippy::cast_precision_loss)]
            let tol = 64.0 * f64::EPSILON * (n * n) as f64;
            assert!(residual(&x, &a) < tol, "LU n = {n}");
            // AᵀA + I is symmetric positive definite.
            let s: Vec<f64> = (0..n * n)
                .map(|k| {
                    let (i, j) = (k / n, k % n);
                    (0..n).map(|r| a[r * n + i] * a[r * n + j]).sum::<f64>()
                        + if i == j { 1.0 } else { 0.0 }
                })
                .collect();
            let mut ch = SmallCholesky::new(n);
            ch.matrix_mut().copy_from_slice(&s);
            assert!(ch.factor().ratio() > 0.0);
            let mut x = b.clone();
            ch.solve(&mut x);
            assert!(
                residual(&x, &s) < tol * n as f64 * n as f64,
                "Cholesky n = {n}"
            );
            // The explicit inverse: its product with b has the same residual.
            let mut inv = vec![0.0; n * n];
            ch.inverse_into(&mut inv);
            let z: Vec<f64> = (0..n)
                .map(|i| (0..n).map(|j| inv[i * n + j] * b[j]).sum())
                .collect();
            assert!(
                residual(&z, &s) < tol * n as f64 * n as f64,
                "Cholesky inverse n = {n}"
            );
        }
    }

    /// The Cholesky solves and the explicit inverse agree with the
    /// independent partial-pivoting LU on symmetric positive definite matrices of the
    /// sizes of a mechanism's Gram matrices, `n` = 1 to 12, some with scales spread
    /// over twelve orders of magnitude (which equilibration removes): the two solutions
    /// to a few units of round-off times the condition of the equilibrated matrix.
    #[test]
    fn cholesky_solves_agree_with_lu() {
        for n in 1..=12_usize {
            for spread in [0.0, 12.0] {
                // A = D (BᵀB + I) D with B from a sine, D = 10^(spread·i/n).
                #[allow(clippy::cast_precision_loss)]
                let d: Vec<f64> = (0..n)
                    .map(|i| 10f64.powf(spread * i as f64 / n as f64))
                    .collect();
                #[allow(clippy::cast_precision_loss)]
                let bm: Vec<f64> = (0..n * n).map(|k| (1.3 * k as f64 + 0.4).sin()).collect();
                let a: Vec<f64> = (0..n * n)
                    .map(|k| {
                        let (i, j) = (k / n, k % n);
                        let s: f64 = (0..n).map(|r| bm[r * n + i] * bm[r * n + j]).sum();
                        d[i] * d[j] * (s + if i == j { 1.0 } else { 0.0 })
                    })
                    .collect();
                let mut ch = SmallCholesky::new(n);
                ch.matrix_mut().copy_from_slice(&a);
                assert!(ch.factor().ratio() > 0.0);
                let mut lu = SmallLu::new(n);
                lu.matrix_mut().copy_from_slice(&a);
                assert!(lu.factor().ratio() > 0.0);
                // Three right-hand sides: a cosine, a unit vector, all ones.
                #[allow(clippy::cast_precision_loss)]
                let cols: Vec<Vec<f64>> = vec![
                    (0..n).map(|i| (i as f64).cos()).collect(),
                    (0..n).map(|i| if i == n / 2 { 1.0 } else { 0.0 }).collect(),
                    vec![1.0; n],
                ];
                let mut inv = vec![0.0; n * n];
                ch.inverse_into(&mut inv);
                // The columns side by side: the identity's give the inverse.
                let mut e: Vec<f64> = (0..n * n)
                    .map(|k| if k / n == k % n { 1.0 } else { 0.0 })
                    .collect();
                ch.solve_rows(&mut e, n);
                for i in 0..n {
                    for k in 0..n {
                        let size = (inv[i * n + i] * inv[k * n + k]).sqrt();
                        #[allow(clippy::cast_precision_loss)]
                        let tol = 1e3 * f64::EPSILON * size * (n * n) as f64;
                        let err = (e[i * n + k] - inv[i * n + k]).abs();
                        assert!(err <= tol, "solve_rows n = {n} spread {spread}: {err:e}");
                    }
                }
                for b in &cols {
                    // The explicit inverse times b against the solve.
                    let z: Vec<f64> = (0..n)
                        .map(|i| (0..n).map(|j| inv[i * n + j] * b[j]).sum())
                        .collect();
                    let (mut x, mut y) = (b.clone(), b.clone());
                    ch.solve(&mut x);
                    lu.solve(&mut y);
                    for i in 0..n {
                        // Relative to the solution's size in the equilibrated units.
                        let size = (0..n).map(|j| (y[j] * d[j]).abs()).fold(0.0, f64::max);
                        let err = ((x[i] - y[i]) * d[i]).abs();
                        #[allow(clippy::cast_precision_loss)]
                        let tol = 1e3 * f64::EPSILON * size * (n * n) as f64;
                        assert!(
                            err <= tol,
                            "solve n = {n} spread {spread}: {err:e} > {tol:e}"
                        );
                        let err = ((z[i] - y[i]) * d[i]).abs();
                        assert!(err <= tol, "inverse n = {n} spread {spread}: {err:e}");
                    }
                }
            }
        }
    }

    /// `gram_cholesky` forms $A_R A_R^\mathsf{T}$ of chosen rows (in a chosen order)
    /// exactly as the dot products of the rows do, for 1 to 12 rows (the unrolled
    /// kernels and the loops), and its explicit inverse is symmetric with
    /// $G G^{-1} = I$ to round-off times the condition (the rows from a sine of a
    /// square, well conditioned).
    #[test]
    fn gram_of_rows_and_its_inverse() {
        let n = 15_usize;
        #[allow(clippy::cast_precision_loss)]
        let a: Vec<f64> = (0..2 * 12 * n)
            .map(|k| (0.37 * (k * k) as f64 + 0.2).sin())
            .collect();
        for r in 1..=12_usize {
            // Every other row, backwards.
            let rows: Vec<usize> = (0..r).map(|i| 2 * (r - 1 - i) + 1).collect();
            let mut ch = SmallCholesky::new(r);
            assert!(gram_cholesky(&mut ch, &a, &rows, n) > 0.0);
            let g: Vec<f64> = (0..r * r)
                .map(|k| {
                    let (ri, rk) = (rows[k / r], rows[k % r]);
                    (0..n).map(|j| a[ri * n + j] * a[rk * n + j]).sum()
                })
                .collect();
            // The factor holds L and Lᵀ now; compare through its inverse.
            let mut inv = vec![0.0; r * r];
            ch.inverse_into(&mut inv);
            for i in 0..r {
                for k in 0..r {
                    assert_eq!(inv[i * r + k].to_bits(), inv[k * r + i].to_bits());
                    let e: f64 = (0..r).map(|j| g[i * r + j] * inv[j * r + k]).sum();
                    let want = if i == k { 1.0 } else { 0.0 };
                    #[allow(clippy::cast_precision_loss)]
                    let tol = 1e3 * f64::EPSILON * (r * r) as f64;
                    assert!((e - want).abs() <= tol, "r = {r}: G G⁻¹ {e} at ({i}, {k})");
                }
            }
            // The lower triangle as formed, before factoring.
            let mut check = SmallCholesky::new(r);
            let formed = {
                let m = check.matrix_mut();
                if fixed!(r, gram_fixed(m, &a, &rows, n)).is_none() {
                    for i in 0..r {
                        for k in 0..=i {
                            m[i * r + k] = g[i * r + k];
                        }
                    }
                }
                m.to_vec()
            };
            for i in 0..r {
                for k in 0..=i {
                    assert_eq!(formed[i * r + k], g[i * r + k], "r = {r} ({i}, {k})");
                }
            }
        }
    }

    #[test]
    fn singular_and_indefinite_matrices_are_reported() {
        let mut lu = SmallLu::new(2);
        lu.matrix_mut().copy_from_slice(&[1.0, 2.0, 2.0, 4.0]);
        assert_eq!(lu.factor().ratio(), 0.0);
        let mut ch = SmallCholesky::new(2);
        ch.matrix_mut().copy_from_slice(&[1.0, 2.0, 2.0, 1.0]);
        assert_eq!(ch.factor().ratio(), 0.0);
    }
}
