//! Gaussian elimination with complete (row and column) pivoting, in phases.
//!
//! Input: a dense row-major `m × n` matrix (copied in by [`Elimination::load`]) and a
//! [`Tier`] per column. Each [`Elimination::phase`] picks pivots at positions
//! `k0, k0+1, …` choosing the row among positions `k..row_end` and the column among
//! positions `k..n`: the largest entry among [`Tier::Preferred`] columns if it exceeds
//! `tol · scale`, else the largest among [`Tier::Allowed`] columns, never a
//! [`Tier::Forbidden`] one. `scale` is the largest entry of the phase's candidate rows
//! over *all* remaining columns, so a phase restricted to some columns measures how
//! their pivots compare with the best available ones.
//!
//! The update runs over every row below the pivot, including rows of later phases:
//! after a phase over the holonomic rows the non-holonomic rows hold the Schur
//! complement $\hat G = G_p - G_\beta C_\beta^{-1} C_p$ (Algorithm P, step 2).
//!
//! **Equilibration.** [`Elimination::load`] scales each row by a power of two to a
//! largest magnitude near 1 (see [`DenseLu`](super::dense::DenseLu)), so that pivot
//! choices and rank decisions do not depend on the units of the constraints. Columns
//! are not equilibrated by their own entries: which coordinate becomes dependent is decided by comparing the
//! derivatives of a constraint with respect to the coordinates, which scaling each
//! column by its own largest entry would equalize (the single row of a pendulum,
//! $[2x, 2y]$, would no longer say that $x$ is the better pivot near $y = 0$).
//!
//! Invariant: no allocation after [`Elimination::new`].

use super::dense::power_of_two_inverse;

/// How a column may be chosen as a pivot column.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Tier {
    /// Chosen whenever an acceptable pivot exists among these columns.
    Preferred,
    /// Chosen only when no preferred column offers an acceptable pivot.
    Allowed,
    /// Never chosen.
    Forbidden,
}

/// Outcome of one phase.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Phase {
    /// Number of pivots found (≤ the requested count).
    pub rank: usize,
    /// Largest magnitude in the candidate rows at the start of the phase.
    pub scale: f64,
    /// Smallest pivot magnitude of the phase (`+∞` when `rank == 0`).
    pub min_pivot: f64,
    /// Product of the pivot magnitudes of the phase (of the row-scaled matrix; divide
    /// by the pivot rows' [`Elimination::row_scale`] for the original one).
    pub abs_det: f64,
    /// Position of the first pivot taken from an [`Tier::Allowed`] column, if any.
    pub first_allowed: Option<usize>,
    /// Largest candidate left when the phase stopped early (0 otherwise).
    pub rejected: f64,
}

impl Phase {
    /// `min_pivot / scale`, 1 for an empty phase, 0 when rank deficient.
    pub fn ratio(&self, requested: usize) -> f64 {
        if requested == 0 {
            1.0
        } else if self.rank < requested || self.scale == 0.0 {
            0.0
        } else {
            self.min_pivot / self.scale
        }
    }
}

/// Elimination workspace for an `m × n` matrix.
#[derive(Debug)]
pub(crate) struct Elimination {
    m: usize,
    n: usize,
    a: Vec<f64>,
    /// `rows[k]`: the original row now at position `k`.
    pub rows: Vec<usize>,
    /// `cols[k]`: the original column now at position `k`.
    pub cols: Vec<usize>,
    /// Tier of each *original* column.
    pub tier: Vec<Tier>,
    /// The factor each *original* row was scaled by at [`Elimination::load`].
    pub row_scale: Vec<f64>,
}

impl Elimination {
    pub fn new(m: usize, n: usize) -> Self {
        Self {
            m,
            n,
            a: vec![0.0; m * n],
            rows: (0..m).collect(),
            cols: (0..n).collect(),
            tier: vec![Tier::Preferred; n],
            row_scale: vec![1.0; m],
        }
    }

    /// Copies the first `m` rows of the row-major `a` (row length `n`), scales each to a
    /// largest magnitude near 1, resets the permutations and marks every column
    /// preferred.
    pub fn load(&mut self, a: &[f64]) {
        let (m, n) = (self.m, self.n);
        self.a.copy_from_slice(&a[..m * n]);
        for (row, scale) in self.a.chunks_exact_mut(n.max(1)).zip(&mut self.row_scale) {
            let s = power_of_two_inverse(row.iter().fold(0.0_f64, |b, v| b.max(v.abs())));
            row.iter_mut().for_each(|v| *v *= s);
            *scale = s;
        }
        for (k, r) in self.rows.iter_mut().enumerate() {
            *r = k;
        }
        for (k, c) in self.cols.iter_mut().enumerate() {
            *c = k;
        }
        self.tier.fill(Tier::Preferred);
    }

    /// Zeroes the rows `rows` (original indices, before any phase) so that no pivot is
    /// taken from them.
    pub fn clear_rows(&mut self, rows: &[usize]) {
        let n = self.n;
        for &i in rows {
            self.a[i * n..(i + 1) * n].fill(0.0);
        }
    }

    /// Eliminates up to `count` pivots at positions `k0..k0+count`, with candidate rows
    /// at positions `k..row_end`; stops early when no acceptable pivot (`> tol · scale`)
    /// is left.
    pub fn phase(&mut self, k0: usize, row_end: usize, count: usize, tol: f64) -> Phase {
        let (m, n) = (self.m, self.n);
        let mut scale = 0.0_f64;
        for i in k0..row_end {
            for j in k0..n {
                scale = scale.max(self.a[i * n + j].abs());
            }
        }
        let mut out = Phase {
            rank: 0,
            scale,
            min_pivot: f64::INFINITY,
            abs_det: 1.0,
            first_allowed: None,
            rejected: 0.0,
        };
        let threshold = tol * scale;
        for k in k0..(k0 + count).min(row_end).min(n) {
            // (magnitude, row position, column position) per tier.
            let mut best = [(0.0_f64, k, k); 2];
            for i in k..row_end {
                for jp in k..n {
                    let slot = match self.tier[self.cols[jp]] {
                        Tier::Preferred => 0,
                        Tier::Allowed => 1,
                        Tier::Forbidden => continue,
                    };
                    let v = self.a[i * n + jp].abs();
                    if v > best[slot].0 {
                        best[slot] = (v, i, jp);
                    }
                }
            }
            let (v, ip, jp) = if best[0].0 > threshold && best[0].0 > 0.0 {
                best[0]
            } else if best[1].0 > threshold && best[1].0 > 0.0 {
                out.first_allowed.get_or_insert(k);
                best[1]
            } else {
                out.rejected = best[0].0.max(best[1].0);
                break;
            };
            self.swap_rows(k, ip);
            self.swap_cols(k, jp);
            out.rank += 1;
            out.min_pivot = out.min_pivot.min(v);
            out.abs_det *= v;
            let p = self.a[k * n + k];
            for i in (k + 1)..m {
                let l = self.a[i * n + k] / p;
                if l != 0.0 {
                    for j in (k + 1)..n {
                        self.a[i * n + j] -= l * self.a[k * n + j];
                    }
                }
                self.a[i * n + k] = 0.0;
            }
        }
        out
    }

    fn swap_rows(&mut self, r1: usize, r2: usize) {
        if r1 == r2 {
            return;
        }
        let n = self.n;
        for j in 0..n {
            self.a.swap(r1 * n + j, r2 * n + j);
        }
        self.rows.swap(r1, r2);
    }

    fn swap_cols(&mut self, c1: usize, c2: usize) {
        if c1 == c2 {
            return;
        }
        let n = self.n;
        for i in 0..self.m {
            self.a.swap(i * n + c1, i * n + c2);
        }
        self.cols.swap(c1, c2);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn duplicated_row_has_rank_one() {
        let mut e = Elimination::new(2, 2);
        e.load(&[1.0, 2.0, 1.0, 2.0]);
        let ph = e.phase(0, 2, 2, 1e-9);
        assert_eq!(ph.rank, 1);
        assert_eq!(e.cols[0], 1);
    }

    #[test]
    fn preferences_steer_the_column_choice() {
        let mut e = Elimination::new(1, 2);
        e.load(&[1.0, 5.0]);
        e.tier[1] = Tier::Allowed;
        let ph = e.phase(0, 1, 1, 1e-9);
        assert_eq!((ph.rank, e.cols[0], ph.first_allowed), (1, 0, None));
    }
}
