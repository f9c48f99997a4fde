//! The sign of the kinetic energy at a state: whether the mass matrix has a direction
//! of negative kinetic energy (a negative mass or moment of inertia, a kinetic energy
//! written with a wrong sign). An inertia tensor that violates the triangle inequality
//! but is positive definite gives a positive kinetic energy and is not found here.
//!
//! Such a model has no physical motion, but nothing else stops it: the augmented
//! system stays regular and the integrators run (the generated solve declines on a
//! negative pivot and the general path solves it). A simulation checks it once, at its
//! start ([`crate::sim`]).
//!
//! **Method.** $A = M + \rho J^\mathsf{T} J$, $J = [C_q; G]$ and
//! $\rho = \sum_k |M_{kk}| / \sum J_{rk}^2$ (the generated solve's augmented-Lagrangian
//! weight: the added block has the trace of $M$'s), is factorized as $LDL^\mathsf{T}$
//! without pivoting, until the first pivot that is not clearly positive
//! ($d_k \le \tau s_k$, $s_k = |A_{kk}| + 10^{-12} \max_j |A_{jj}|$, $\tau =$
//! [`PIVOT_TOLERANCE`]). A physical mass matrix is positive semi-definite, and so is
//! $\rho J^\mathsf{T} J$, so every pivot of $A$ is non-negative up to round-off (the
//! term makes a mass matrix singular only off the constraints, as with Euler
//! parameters, regular). A pivot below $-\tau s_k$ after pivots above $\tau s_j$ is not
//! round-off (those pivots bound the growth of the entries by $1/\tau$, so the error of
//! $d_k$ is about $n \epsilon / \tau \ll \tau$) but a negative eigenvalue of $A$, hence
//! of $M$. A pivot in $[-\tau s_k, \tau s_k]$ stops the test without a verdict: a
//! singular direction is the acceleration solve's to report, with the coordinates it
//! leaves undetermined.
//!
//! Dense: $n^3/6$ multiplications, done only up to [`LIMIT`] coordinates.

use crate::mechanism::{Mechanism, Pattern};
use crate::workspace::{EvalError, Workspace};

/// The relative size of a pivot that counts as clearly positive or negative.
pub const PIVOT_TOLERANCE: f64 = 1e-6;

/// The largest number of coordinates for which [`negative_direction`] factorizes
/// (above it the test is skipped: 300³/6 is 4.5 million multiplications, about a
/// millisecond).
pub const LIMIT: usize = 300;

/// A direction of negative kinetic energy found by [`negative_direction`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NegativeDirection {
    /// The coordinate whose pivot is negative (the direction involves it and
    /// coordinates before it).
    pub coordinate: usize,
    /// The pivot over its scale $s_k$ (below $-$[`PIVOT_TOLERANCE`]).
    pub ratio: f64,
}

/// What a negative pivot (`ratio` of its diagonal) means, for the errors that report
/// one.
pub(crate) fn explain(ratio: f64) -> String {
    format!(
        "the mass matrix is not positive semi-definite (pivot {ratio:.3e} of its diagonal); \
         a negative mass or moment of inertia, or a kinetic energy written with a wrong sign?"
    )
}

/// Whether the mass matrix at `(t, q)` has a direction of negative kinetic energy
/// (module docs); `None` when every pivot is clearly positive, when a pivot is too
/// small to tell, and above [`LIMIT`] coordinates.
///
/// # Errors
/// A length that is not the model's, or a non-finite entry of $M$ or $J$.
pub fn negative_direction<M: Mechanism + ?Sized>(
    mech: &M,
    t: f64,
    q: &[f64],
    qd: &[f64],
) -> Result<Option<NegativeDirection>, EvalError> {
    let n = mech.info().nq();
    if n == 0 || n > LIMIT {
        return Ok(None);
    }
    negative_direction_in(mech, &mut Workspace::new(mech.info())?, t, q, qd)
}

/// [`negative_direction`] with the caller's workspace `ws` (the model's), whose mass
/// matrix, forces and Jacobian it overwrites: a simulation checks its start with the
/// workspace it runs in instead of allocating one.
///
/// # Errors
/// As [`negative_direction`].
pub(crate) fn negative_direction_in<M: Mechanism + ?Sized>(
    mech: &M,
    ws: &mut Workspace,
    t: f64,
    q: &[f64],
    qd: &[f64],
) -> Result<Option<NegativeDirection>, EvalError> {
    let info = mech.info();
    let n = info.nq();
    if n == 0 || n > LIMIT {
        return Ok(None);
    }
    ws.eval_mass_and_forces(mech, t, q, qd)?;
    ws.eval_jacobian(mech, t, q)?;
    Ok(factor(n, info.mass_pattern, &ws.mass_values, ws.jacobian()))
}

/// The test on the values: `mass` on `pattern` (both triangles), `jacobian` dense
/// row-major with `n` columns.
fn factor(n: usize, pattern: Pattern, mass: &[f64], jacobian: &[f64]) -> Option<NegativeDirection> {
    let mut a = vec![0.0; n * n];
    for (&(r, c), &v) in pattern.iter().zip(mass) {
        let (r, c) = (r as usize, c as usize);
        a[r * n + c] = v;
        a[c * n + r] = v;
    }
    let trace: f64 = (0..n).map(|k| a[k * n + k].abs()).sum();
    let squares: f64 = jacobian.iter().map(|v| v * v).sum();
    if squares > 0.0 {
        let rho = trace / squares;
        for row in jacobian.chunks_exact(n) {
            for (i, &ri) in row.iter().enumerate().filter(|(_, v)| **v != 0.0) {
                for (j, &rj) in row.iter().enumerate() {
                    a[i * n + j] += rho * ri * rj;
                }
            }
        }
    }
    let largest = (0..n).map(|k| a[k * n + k].abs()).fold(0.0, f64::max);
    let scale: Vec<f64> = (0..n)
        .map(|k| a[k * n + k].abs() + 1e-12 * largest)
        .collect();
    let mut column = vec![0.0; n];
    for k in 0..n {
        let d = a[k * n + k];
        if d < -PIVOT_TOLERANCE * scale[k] {
            return Some(NegativeDirection {
                coordinate: k,
                ratio: d / scale[k],
            });
        }
        // Not clearly positive (or not a number): no verdict.
        if d.partial_cmp(&(PIVOT_TOLERANCE * scale[k])) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        // The lower triangle of the trailing block: a_ij −= a_ik a_jk / d.
        for i in k + 1..n {
            column[i] = a[i * n + k];
        }
        for i in k + 1..n {
            let f = column[i] / d;
            if f != 0.0 {
                for j in k + 1..=i {
                    a[i * n + j] -= f * column[j];
                }
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    const DIAGONAL: Pattern = &[(0, 0), (1, 1)];
    const FULL: Pattern = &[(0, 0), (0, 1), (1, 0), (1, 1)];

    #[test]
    fn positive_definite_and_semi_definite_masses_pass() {
        // diag(1, 2): positive definite.
        assert_eq!(factor(2, DIAGONAL, &[1.0, 2.0], &[]), None);
        // [1 1; 1 1] is singular (rank 1): no verdict, not a negative direction.
        assert_eq!(factor(2, FULL, &[1.0, 1.0, 1.0, 1.0], &[]), None);
        // The same with the row (1, −1) of a constraint: regular and positive.
        assert_eq!(factor(2, FULL, &[1.0, 1.0, 1.0, 1.0], &[1.0, -1.0]), None);
    }

    #[test]
    fn a_negative_mass_is_found() {
        // The pendulum with m = −1 at (1, 0): M = −I, the rod's row (2, 0). On the
        // tangent space (0, 1) the kinetic energy is −1/2.
        let found = factor(2, DIAGONAL, &[-1.0, -1.0], &[2.0, 0.0]).expect("a negative direction");
        assert_eq!(found.coordinate, 1);
        assert!(found.ratio < -0.5, "{found:?}");
        // [1 2; 2 1] has the eigenvalue −1 along (1, −1): the second pivot 1 − 4 = −3.
        let found = factor(2, FULL, &[1.0, 2.0, 2.0, 1.0], &[]).expect("a negative direction");
        assert_eq!(found.coordinate, 1);
        assert!((found.ratio - -3.0).abs() < 1e-9, "{found:?}");
    }
}
