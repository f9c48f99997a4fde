//! The scales of the runtime's convergence and consistency decisions.
//!
//! A decision that compares a number with an absolute threshold changes its outcome
//! with the units of the model. The runtime's decisions are made against these scales
//! instead (`docs/decisions/0041-scale-model.md`):
//!
//! - **the size of $q$**: $s_q = \lVert q\rVert_\infty$, the precision to which the
//!   coordinates can be known;
//! - **a constraint's sensitivity**: $\lVert (C_q)_i\rVert_\infty$, the row norm of its
//!   Jacobian, so that $|C_i| / \lVert (C_q)_i\rVert_\infty$ is, to first order, the
//!   distance of $q$ from the constraint's surface in the units of $q$.
//!
//! A holonomic constraint is met when that distance is within the relative tolerance of
//! $s_q$: $|C_i| \le \varepsilon\,\lVert (C_q)_i\rVert_\infty\, s_q$. Changing the unit
//! of a constraint scales both sides by the same factor, changing the unit of length
//! scales $C_i$ (or $(C_q)_i$) and $s_q$ together, and a mass unit does not enter.
//! Solves and singularity tests of square matrices equilibrate rows and columns (see
//! [`crate::linalg::dense`]).

use crate::linalg::inf_norm;

/// The size of the coordinates, $\lVert q\rVert_\infty$.
pub(crate) fn coordinate_size(q: &[f64]) -> f64 {
    inf_norm(q)
}

/// Whether the residual `ci` of a constraint whose Jacobian row has the norm `norm` is
/// met to the relative `tolerance` (see the module docs); a NaN residual never is.
#[inline]
fn met(ci: f64, norm: f64, tolerance: f64, size: f64) -> bool {
    !(ci.is_nan() || ci.abs() > tolerance * norm * size)
}

/// The constraints of `c` not met to the relative `tolerance` (see the module docs),
/// with `jacobian` the dense row-major $C_q$ (at least `c.len()` rows of length `n`) and
/// `size` the size of $q$; a NaN residual is never met.
pub(crate) fn unmet<'a>(
    c: &'a [f64],
    jacobian: &'a [f64],
    n: usize,
    tolerance: f64,
    size: f64,
) -> impl Iterator<Item = usize> + 'a {
    c.iter().enumerate().filter_map(move |(i, &ci)| {
        let norm = inf_norm(&jacobian[i * n..(i + 1) * n]);
        (!met(ci, norm, tolerance, size)).then_some(i)
    })
}

/// Whether every constraint of `c` is met (see [`unmet`]).
pub(crate) fn all_met(c: &[f64], jacobian: &[f64], n: usize, tolerance: f64, size: f64) -> bool {
    unmet(c, jacobian, n, tolerance, size).next().is_none()
}

/// One step of a row norm's maximum: `a` when it is larger than the norm `m` so far or
/// NaN, `m` otherwise. Once NaN, a norm stays NaN (`a > NaN` is false, and a NaN `a`
/// replaces it). The rule of the runtime's walk of a pattern and of the generated
/// [`Mechanism::holonomic_row_norms`](crate::Mechanism::holonomic_row_norms), which
/// calls it, so that the two give the same norms.
#[inline(always)]
pub fn norm_step(m: f64, a: f64) -> f64 {
    if a > m || a.is_nan() {
        a
    } else {
        m
    }
}

/// The row norms $\lVert (C_q)_i\rVert_\infty$ of a Jacobian given by its `pattern`
/// (entries in any order) and `values`, into `norms` (one per row): the numbers
/// [`inf_norm`] gives on the dense rows, whose other entries are zeros (the maximum is
/// exact; a NaN entry makes its row's norm NaN). What the projections' convergence
/// tests read, without scattering the dense $C_q$.
pub(crate) fn pattern_row_norms(pattern: &[(u32, u32)], values: &[f64], norms: &mut [f64]) {
    norms.fill(0.0);
    // The maximum of a run of entries of one row in a register, stored when the row
    // changes (not stored and reloaded entry by entry, each waiting for the last).
    let mut entries = pattern.iter().zip(values);
    let Some((&(r, _), v)) = entries.next() else {
        return;
    };
    let (mut row, mut norm) = (r as usize, v.abs());
    for (&(r, _), v) in entries {
        let r = r as usize;
        if r != row {
            norms[row] = norm_step(norms[row], norm);
            (row, norm) = (r, 0.0);
        }
        norm = norm_step(norm, v.abs());
    }
    norms[row] = norm_step(norms[row], norm);
}

/// [`all_met`] with the row norms of $C_q$ given (see [`pattern_row_norms`]): the
/// same decision.
pub(crate) fn all_met_by_norms(c: &[f64], norms: &[f64], tolerance: f64, size: f64) -> bool {
    c.iter()
        .zip(norms)
        .all(|(&ci, &norm)| met(ci, norm, tolerance, size))
}

/// [`at_rounding_floor`] with the row norms of $C_q$ given: the same decision.
pub(crate) fn at_rounding_floor_by_norms(c: &[f64], norms: &[f64], size: f64) -> bool {
    all_met_by_norms(c, norms, ROUNDING_FLOOR, size.max(1.0))
}

/// Whether every constraint of `c` is within its rounding floor
/// $64\,\varepsilon\,\lVert (C_q)_i\rVert_\infty \max(s_q, 1)$.
///
/// The relative test of [`all_met`] asks for a distance within $\varepsilon s_q$ of the
/// surface; when the coordinates are all near zero (a linkage whose joint angles start
/// at 0) that is below what evaluating $C$ can resolve, since the rounding of $C$
/// follows the size of the geometry, not of $q$. Newton then stagnates at this floor.
/// A Newton iteration whose residual has stopped falling accepts the point when this
/// holds; the unit scale is a floor for angles (1 rad) that only applies after
/// stagnation, where further iterations cannot improve the point.
pub(crate) fn at_rounding_floor(c: &[f64], jacobian: &[f64], n: usize, size: f64) -> bool {
    all_met(c, jacobian, n, ROUNDING_FLOOR, size.max(1.0))
}

/// The distance from the constraints within which [`at_rounding_floor`] holds, for
/// coordinates of size `size`: $64\,\varepsilon \max(s_q, 1)$ (a Newton update of
/// about that size moves by the rounding of $C$).
pub(crate) fn rounding_floor_distance(size: f64) -> f64 {
    ROUNDING_FLOOR * size.max(1.0)
}

/// The relative tolerance of [`at_rounding_floor`].
const ROUNDING_FLOOR: f64 = 64.0 * f64::EPSILON;

#[cfg(test)]
mod tests {
    use super::*;

    /// The Cartesian pendulum's rod `x² + y² − l²` at a state off the circle by a
    /// relative 1e-13: met at a tolerance of 1e-12 and not at 1e-14 in every unit of
    /// length (the residual grows as l², the row norm and the size as l).
    #[test]
    fn the_rod_is_met_alike_in_every_unit_of_length() {
        for l in [1e-3, 1.0, 1e3] {
            let (x, y) = (l * (1.0 + 1e-13), 0.0);
            let c = [x * x + y * y - l * l];
            let jacobian = [2.0 * x, 2.0 * y];
            let size = coordinate_size(&[x, y]);
            assert!(all_met(&c, &jacobian, 2, 1e-12, size), "l = {l}");
            assert!(!all_met(&c, &jacobian, 2, 1e-14, size), "l = {l}");
        }
    }

    /// Near q = 0 the relative test cannot be met at round-off, the floor can; a
    /// residual far above round-off is not at the floor.
    #[test]
    fn the_rounding_floor_holds_where_the_size_of_q_gives_none() {
        let (q, jacobian) = ([1e-6, 0.0], [1.0, 0.5]);
        let size = coordinate_size(&q);
        let c = [2e-16];
        assert!(!all_met(&c, &jacobian, 2, 1e-14, size));
        assert!(at_rounding_floor(&c, &jacobian, 2, size));
        assert!(!at_rounding_floor(&[1e-10], &jacobian, 2, size));
    }

    /// The norms from a pattern in any order are the dense rows' norms, NaN included,
    /// and the decisions from them are the dense decisions.
    #[test]
    fn pattern_row_norms_are_the_dense_ones() {
        let n = 3;
        // Rows 0 and 2 in a scattered order; row 1 empty; row 3 with a NaN entry.
        let pattern = [(2, 1), (0, 2), (3, 0), (2, 0), (0, 0), (3, 2)];
        let values = [-4.0, 0.5, 1.0, 3.0, -2.0, f64::NAN];
        let mut dense = vec![0.0; 4 * n];
        for (&(r, c), &v) in pattern.iter().zip(&values) {
            dense[r as usize * n + c as usize] = v;
        }
        let mut norms = [7.0; 4];
        pattern_row_norms(&pattern, &values, &mut norms);
        for (i, &norm) in norms.iter().enumerate() {
            let d = inf_norm(&dense[i * n..(i + 1) * n]);
            assert!(norm == d || (norm.is_nan() && d.is_nan()), "row {i}");
        }
        assert_eq!(norms[..3], [2.0, 0.0, 4.0]);
        for c in [
            [1e-13, 0.0, 1e-13, 0.0],
            [1e-13, 1e-300, 0.0, 5.0],
            [3e-12, 0.0, 0.0, 0.0],
        ] {
            for tol in [1e-12, 1e-14] {
                assert_eq!(
                    all_met_by_norms(&c, &norms, tol, 1.0),
                    all_met(&c, &dense, n, tol, 1.0),
                    "{c:?} at {tol}"
                );
            }
            assert_eq!(
                at_rounding_floor_by_norms(&c, &norms, 0.5),
                at_rounding_floor(&c, &dense, n, 0.5)
            );
        }
        assert!(!all_met_by_norms(
            &[f64::NAN, 0.0, 0.0, 0.0],
            &norms,
            1.0,
            1.0
        ));
    }

    #[test]
    fn a_nan_residual_is_never_met() {
        assert_eq!(
            unmet(&[f64::NAN], &[1.0], 1, 1.0, 1.0).collect::<Vec<_>>(),
            [0]
        );
    }
}
