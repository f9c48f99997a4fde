//! The stage derivatives of the explicit Runge–Kutta pairs in one buffer, and the
//! kernel that forms their linear combinations.
//!
//! Input: the dimension $n$ and the number of stages $s$. Output: stage $j$ (0-based)
//! at `j * n..(j + 1) * n` of one vector; [`combine`]
//! $o = y + \sum_j (h a_j) k_j$ over a coefficient row.
//! Invariants: no allocation after [`Stages::new`]; every slice a kernel reads is cut
//! to length $n$ once, before its loop, so the loops carry no bounds checks; the
//! entries see the operations of a pass per coefficient, in the order of the row.

/// Components [`combine`] sums together in registers (two SSE2 registers).
const LANES: usize = 4;

/// The stage derivatives $k_1, \dots, k_s$ of a pair, stage-major in one vector.
#[derive(Clone, Debug)]
pub(crate) struct Stages {
    n: usize,
    k: Vec<f64>,
}

impl Stages {
    /// `count` stages of dimension `n`, zero.
    pub(crate) fn new(n: usize, count: usize) -> Self {
        Self {
            n,
            k: vec![0.0; n * count],
        }
    }

    /// Every stage, stage `j` at `j * n..(j + 1) * n`.
    #[inline]
    pub(crate) fn all(&self) -> &[f64] {
        &self.k
    }

    /// Every stage, mutable.
    #[inline]
    pub(crate) fn all_mut(&mut self) -> &mut [f64] {
        &mut self.k
    }

    /// Stage `j`.
    #[inline]
    pub(crate) fn get(&self, j: usize) -> &[f64] {
        &self.k[j * self.n..][..self.n]
    }

    /// Stage `j`, mutable.
    #[inline]
    pub(crate) fn get_mut(&mut self, j: usize) -> &mut [f64] {
        &mut self.k[j * self.n..][..self.n]
    }

    /// Copies stage `from` into stage `to` (the FSAL stage into the first).
    #[inline]
    pub(crate) fn copy(&mut self, from: usize, to: usize) {
        let n = self.n;
        self.k.copy_within(from * n..(from + 1) * n, to * n);
    }
}

/// A coefficient row as an array of its length, checked at compile time (`const {
/// row::<C>(A[s]) }`): the length becomes a constant of the kernels, whose loop over the
/// coefficients then unrolls with each stage's slice cut once.
pub(crate) const fn row<const C: usize>(r: &[(usize, f64)]) -> [(usize, f64); C] {
    assert!(r.len() == C, "the row has another length");
    let mut out = [(0, 0.0); C];
    let mut i = 0;
    while i < C {
        out[i] = r[i];
        i += 1;
    }
    out
}

/// Stage `j` of the stage-major `k` (dimension `n`) for each `(j, _)` of `coeffs`.
#[inline(always)]
pub(crate) fn rows<'a, const C: usize>(
    k: &'a [f64],
    n: usize,
    coeffs: &[(usize, f64); C],
) -> [&'a [f64]; C] {
    std::array::from_fn(|c| &k[coeffs[c].0 * n..][..n])
}

/// `out = init + sum_j (h a_j) k_j` over the `(j, a_j)` of `coeffs` (`init` zero when
/// `None`), with `k` the stages stage-major and `n = out.len()`.
///
/// Four components at a time with the sums in registers: each entry sees the
/// operations of a pass per coefficient ($o \leftarrow y$, then $o \mathrel{+}=
/// (h a_j) k_j$ in the order of the row), without storing and reloading `out` once
/// per coefficient (stage 12 of DOP853 has eleven).
#[inline(always)]
pub(crate) fn combine<const C: usize>(
    out: &mut [f64],
    init: Option<&[f64]>,
    h: f64,
    coeffs: &[(usize, f64); C],
    k: &[f64],
) {
    let n = out.len();
    let init = init.map(|y| &y[..n]);
    let rows = rows(k, n, coeffs);
    let ha: [f64; C] = std::array::from_fn(|c| h * coeffs[c].1);
    let mut l0 = 0;
    while l0 + LANES <= n {
        combine_lanes::<LANES, C>(out, init, &ha, &rows, l0);
        l0 += LANES;
    }
    while l0 < n {
        combine_lanes::<1, C>(out, init, &ha, &rows, l0);
        l0 += 1;
    }
}

/// [`combine`] for the components `l0..l0 + W` (all slices of length `out.len()`).
#[inline(always)]
fn combine_lanes<const W: usize, const C: usize>(
    out: &mut [f64],
    init: Option<&[f64]>,
    ha: &[f64; C],
    rows: &[&[f64]; C],
    l0: usize,
) {
    let mut s = match init {
        Some(y) => <[f64; W]>::try_from(&y[l0..l0 + W]).expect("W entries"),
        None => [0.0; W],
    };
    for (row, ha) in rows.iter().zip(ha) {
        let kj = <&[f64; W]>::try_from(&row[l0..l0 + W]).expect("W entries");
        for (s, kj) in s.iter_mut().zip(kj) {
            *s += ha * kj;
        }
    }
    out[l0..l0 + W].copy_from_slice(&s);
}
