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
pub(crate) fn inf_norm(x: &[f64]) -> f64 {
    x.iter().fold(0.0_f64, |acc, v| {
        if v.is_nan() || acc.is_nan() {
            f64::NAN
        } else {
            acc.max(v.abs())
        }
    })
}
