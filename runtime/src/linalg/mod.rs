//! Small numerical kernels shared by the analysis modules.
//!
//! - [`elimination`]: Gaussian elimination with complete pivoting on a dense row-major
//!   matrix, with column preferences (the engine of Algorithm P, the condition monitor
//!   and the rank-revealing search for redundant constraints).
//! - [`dense`]: a reusable dense $LU$ with complete pivoting (faer), allocation-free
//!   after construction.
//! - [`small`]: $LU$ with partial pivoting and Cholesky for the small systems of one
//!   evaluation, without a general solver's set-up.
//! - [`sparse`]: the sparse augmented matrix assembled from the patterns of
//!   [`Info`](crate::Info), with a symbolic $LU$ computed once.
//!
//! Invariant: every buffer is sized at construction; the hot paths never allocate.

pub(crate) mod dense;
pub(crate) mod elimination;
pub(crate) mod small;
pub(crate) mod sparse;

/// $\lVert x\rVert_\infty$; `NaN` entries propagate (so callers detect them).
///
/// Branch-free, with four running maxima and a flag for NaN, so that it vectorizes:
/// the maximum is exact, so the result does not depend on the order (it is called per
/// step on states and per Newton iteration on every row of the Jacobian).
#[inline]
pub(crate) fn inf_norm(x: &[f64]) -> f64 {
    let mut m = [0.0_f64; 4];
    let mut nan = false;
    let chunks = x.chunks_exact(4);
    let rest = chunks.remainder();
    for c in chunks {
        for (m, v) in m.iter_mut().zip(c) {
            let a = v.abs();
            *m = if a > *m { a } else { *m };
            nan |= v.is_nan();
        }
    }
    for (m, v) in m.iter_mut().zip(rest) {
        let a = v.abs();
        *m = if a > *m { a } else { *m };
        nan |= v.is_nan();
    }
    let m = m[0].max(m[1]).max(m[2].max(m[3]));
    if nan {
        f64::NAN
    } else {
        m
    }
}

#[cfg(test)]
mod tests {
    use super::inf_norm;

    /// The largest magnitude at every position and length (the four running maxima and
    /// the remainder), a NaN anywhere propagates, the empty norm is zero.
    #[test]
    fn inf_norm_is_the_largest_magnitude_and_propagates_nan() {
        assert_eq!(inf_norm(&[]), 0.0);
        for n in 1..=11 {
            for at in 0..n {
                let mut x: Vec<f64> = (0..n).map(|i| 0.5 * i as f64 - 1.0).collect();
                x[at] = -7.5;
                assert_eq!(inf_norm(&x), 7.5, "n = {n}, at {at}");
                x[at] = f64::NAN;
                assert!(inf_norm(&x).is_nan(), "n = {n}, NaN at {at}");
                x[at] = f64::NEG_INFINITY;
                assert_eq!(inf_norm(&x), f64::INFINITY, "n = {n}, -inf at {at}");
            }
        }
    }
}
