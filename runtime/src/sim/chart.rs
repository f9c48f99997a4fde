//! Local tangent-space coordinates for [`Formulation::Partitioning`](super::Formulation).
//!
//! Input: an *anchor* $q_a$ on the constraint manifold (the last accepted state) with
//! the independent rows $N = C_{q,R}(q_a)$ of its holonomic Jacobian, and a position
//! $\tilde q$ predicted by the integrator near it. Output: the point of the manifold
//! with the same tangential part,
//! $$q = \tilde q + N^\mathsf{T}\mu,\qquad C_R(q, t) = 0,$$
//! found by Newton on the $r$ normal coordinates $\mu$ (the dependent coordinates of the
//! chart). The chart is the graph of the manifold over its tangent space at $q_a$, an
//! orthonormal-quality partition: its conditioning is that of $N N^\mathsf{T}$, the best
//! any choice of dependent coordinates can have, and it is renewed at every step.
//!
//! **Newton.** The iteration starts from the integrator's own prediction (off the
//! manifold by the local error) and is a chord iteration with the factorization of
//! $N N^\mathsf{T}$ made at the anchor, so an evaluation factors nothing. It converges
//! linearly with a rate proportional to the distance from the anchor; the rate per unit
//! distance is measured whenever two updates are taken and carried to the next
//! evaluations. The iteration stops when the estimated remaining error
//! $\frac{\rho}{1-\rho}\lVert\Delta q\rVert$ is below [`KAPPA`] in the integrator's
//! weights $\text{atol} + \text{rtol}\,|q_j|$ (as the Newton iterations of implicit
//! integrators do), or at round-off. One update per evaluation is the norm.
//!
//! Invariant: no allocation after [`Chart::new`] (except when building an error).

use super::point::Point;
use crate::linalg::inf_norm;
use crate::linalg::small::{gram_cholesky, SmallCholesky};
use crate::workspace::EvalError;
use crate::Mechanism;

/// Fraction of the integrator's tolerance the Newton iteration leaves as error.
///
/// Implicit integrators stop their Newton iterations a few hundredths of the tolerance
/// away from the solution (Hairer's `RADAU5`: 0.03). Here the left error moves the
/// evaluated state off the manifold by that much, and the right-hand side with it.
pub(crate) const KAPPA: f64 = 0.03;

/// Most chord updates per evaluation before it is called a failure.
const MAX_ITERATIONS: usize = 12;

/// A contraction rate at or above which the chord iteration has failed.
const DIVERGENCE: f64 = 0.9;

/// Contraction rate assumed when none has been measured: forces a second update,
/// which measures it.
const UNKNOWN_RATE: f64 = 0.5;

/// The outcome of a failed correction.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum ChartFailure {
    /// The model's functions failed.
    Eval(EvalError),
    /// The chord iteration diverged or did not reach the tolerance.
    Newton {
        /// Updates taken.
        iterations: usize,
        /// $\lVert C\rVert_\infty$ at the last iterate.
        residual: f64,
    },
}

impl From<EvalError> for ChartFailure {
    fn from(e: EvalError) -> Self {
        Self::Eval(e)
    }
}

/// A chart anchored at an accepted state, with the Newton scratch.
#[derive(Debug)]
pub(crate) struct Chart {
    /// The anchor $q_a$.
    anchor: Vec<f64>,
    /// $J(q_a)$, dense row-major `m × n`; $N$ is its rows `rows`.
    normals: Vec<f64>,
    /// $N N^\mathsf{T}$, factored.
    gram: SmallCholesky,
    /// Normal coordinates of the current update.
    mu: Vec<f64>,
    /// Measured contraction rate per unit distance from the anchor.
    rate_per_distance: Option<f64>,
    rtol: f64,
    atol: f64,
}

impl Chart {
    /// Scratch for a model with `n` coordinates and `m` constraint rows, of which `r`
    /// independent holonomic ones, for the integrator's tolerances `rtol`, `atol`.
    pub fn new(n: usize, m: usize, r: usize, rtol: f64, atol: f64) -> Self {
        Self {
            anchor: vec![0.0; n],
            normals: vec![0.0; m * n],
            gram: SmallCholesky::new(r),
            mu: vec![0.0; r],
            rate_per_distance: None,
            rtol,
            atol,
        }
    }

    /// The integrator's tolerance $\text{atol} + \text{rtol}\,x$ for a value of size `x`.
    pub fn tolerance(&self, x: f64) -> f64 {
        self.atol + self.rtol * x.abs()
    }

    /// Anchors the chart at the current positions of `p` (on the manifold); returns
    /// the pivot ratio of $N N^\mathsf{T}$.
    pub fn anchor<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<f64, EvalError> {
        self.normals.copy_from_slice(p.dense_jacobian(t)?);
        self.anchor.copy_from_slice(&p.q);
        if self.mu.len() != p.rows_h {
            // Assembly dropped redundant rows (allocates, once).
            self.gram = SmallCholesky::new(p.rows_h);
            self.mu = vec![0.0; p.rows_h];
        }
        let n = p.q.len();
        Ok(gram_cholesky(
            &mut self.gram,
            &self.normals,
            &p.rows[..p.rows_h],
            n,
        ))
    }

    /// Moves the positions of `p` along the anchor's normals onto $C_R(q, t) = 0$
    /// ($R$: the holonomic rows of the projections), to the integrator's tolerance (see
    /// the module docs); returns the number of updates.
    pub fn correct<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<usize, ChartFailure> {
        let n = p.q.len();
        let rows_h = p.rows_h;
        let distance =
            p.q.iter()
                .zip(&self.anchor)
                .fold(0.0_f64, |a, (x, y)| a.max((x - y).abs()));
        let mut rate = self
            .rate_per_distance
            .map_or(UNKNOWN_RATE, |r| (r * distance).min(UNKNOWN_RATE));
        let floor = 8.0 * f64::EPSILON * inf_norm(&p.q);
        let mut previous: Option<f64> = None;
        for iteration in 0..=MAX_ITERATIONS {
            p.constraints(t)?;
            let (c, rows) = (p.ws.constraints(), &p.rows[..rows_h]);
            let residual = rows.iter().fold(0.0_f64, |a, &i| a.max(c[i].abs()));
            if !residual.is_finite() {
                return Err(ChartFailure::Newton {
                    iterations: iteration,
                    residual,
                });
            }
            if iteration == 0 && residual <= floor {
                return Ok(0);
            }
            if iteration == MAX_ITERATIONS {
                return Err(ChartFailure::Newton {
                    iterations: iteration,
                    residual,
                });
            }
            for (mu, &i) in self.mu.iter_mut().zip(rows) {
                *mu = c[i];
            }
            self.gram.solve(&mut self.mu);
            let mut step = 0.0_f64;
            let mut weighted = 0.0_f64;
            for (j, qj) in p.q.iter_mut().enumerate() {
                let dq: f64 = -self
                    .mu
                    .iter()
                    .zip(rows)
                    .map(|(mu, &i)| self.normals[i * n + j] * mu)
                    .sum::<f64>();
                *qj += dq;
                step = step.max(dq.abs());
                weighted = weighted.max(dq.abs() / (self.atol + self.rtol * qj.abs()));
            }
            // An update at round-off has converged, whatever rate its noise suggests.
            if step <= floor {
                return Ok(iteration + 1);
            }
            if let Some(p) = previous {
                let measured = weighted / p;
                if measured.is_nan() || measured >= DIVERGENCE {
                    return Err(ChartFailure::Newton {
                        iterations: iteration + 1,
                        residual,
                    });
                }
                rate = measured;
                // A rate measured on updates at round-off is noise.
                if step > 100.0 * floor && distance > 0.0 {
                    self.rate_per_distance = Some(measured / distance);
                }
            }
            if step <= floor || rate / (1.0 - rate) * weighted <= KAPPA {
                return Ok(iteration + 1);
            }
            previous = Some(weighted);
        }
        unreachable!("the loop returns at MAX_ITERATIONS")
    }
}
