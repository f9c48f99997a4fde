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
//! manifold by the local error) and is a chord iteration with the map
//! $P = N^\mathsf{T}(N N^\mathsf{T})^{-1}$ made at the anchor ($\Delta q = -P\,C_R$), so an
//! evaluation factors and solves nothing: one update is one product with an
//! `n × r` matrix. It converges
//! linearly with a rate proportional to the distance from the anchor; the rate per unit
//! distance is measured whenever two updates are taken and carried to the next
//! evaluations. The iteration stops when the estimated remaining error
//! $\frac{\rho}{1-\rho}\lVert\Delta q\rVert$ is below [`KAPPA`] in the integrator's
//! weights $\text{atol} + \text{rtol}\,|q_j|$ (as the Newton iterations of implicit
//! integrators do), or at round-off. One update per evaluation is the norm.
//!
//! **Velocities** are projected orthogonally onto $J(q)\dot q + [C_t; g] = 0$ at the
//! corrected positions (all rows, the non-holonomic ones too), as projection does, but
//! without a factorization per evaluation: the chord iteration
//! $\dot q \leftarrow \dot q - J^\mathsf{T} G_a^{-1}(J\dot q + [C_t; g])$ with the inverse
//! of the anchor's $G_a = J_a J_a^\mathsf{T}$ (made once per step) converges to the
//! orthogonal projection at $q$ (every update lies in the range of $J(q)^\mathsf{T}$) at
//! the rate $\lVert I - J J^\mathsf{T} G_a^{-1}\rVert$, proportional to the distance from
//! the anchor like the positions'; each update is a product with the pattern of $J$ and
//! one with an `m × m` matrix. It stops like the positions' iteration. An iteration
//! that does not contract, and models whose redundant constraints were dropped, hand
//! over to the factored projection at the point ([`Point::project_velocities`]). Moving the velocities along the anchor's normals
//! instead (the derivative of the chart's map, which keeps the tangential velocities
//! of the integrator) was measured to be 2–30 times less accurate on the pendulum
//! (DOP853 and Adams, rtol 1e-5 to 1e-9).
//!
//! Invariant: no allocation after [`Chart::new`] (except when building an error).

use super::point::{Point, REFIT_RATIO};
use crate::linalg::inf_norm;
use crate::linalg::small::{gram_cholesky, SmallCholesky};
use crate::workspace::EvalError;
use crate::{Info, Mechanism};

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
    /// $J(q_a)$, dense row-major `m × n`; $N$ is its rows `rows[..rows_h]`.
    normals: Vec<f64>,
    /// The factorization of a Gram matrix, scratch for the maps.
    gram: SmallCholesky,
    /// $(N N^\mathsf{T})^{-1}N$, row-major `r × n` (its transpose is the map $P$).
    position_map: Vec<f64>,
    /// $G_a^{-1} = (J_a J_a^\mathsf{T})^{-1}$ of every projected row (holonomic and
    /// non-holonomic), row-major `m × m`, and whether $G_a$ is regular.
    velocity_map: Vec<f64>,
    velocity_map_regular: bool,
    /// For each constraint row, its place in `rows` (`usize::MAX` when not projected).
    slot: Vec<usize>,
    /// $G_a^{-1}$ times the velocity residuals.
    nu: Vec<f64>,
    /// The velocity residuals of every constraint row.
    vel: Vec<f64>,
    /// The residuals of the current update.
    mu: Vec<f64>,
    /// The current update.
    dx: Vec<f64>,
    /// The rows of the point's projections when anchored (the first `rows_h`
    /// holonomic), which the maps belong to; empty before the first anchor.
    rows: Vec<usize>,
    rows_h: usize,
    /// Measured contraction rate per unit distance from the anchor.
    rate_per_distance: Option<f64>,
    /// The same, measured on the velocities' iteration.
    velocity_rate_per_distance: Option<f64>,
    rtol: f64,
    atol: f64,
}

/// Writes $(A_R A_R^\mathsf{T})^{-1}A_R$ of the rows `rows` of the dense row-major `a`
/// (`· × n`) into `map` (row-major `|R| × n`), with `gram` (of size `|R|`) as scratch;
/// returns the pivot ratio of the Gram matrix.
fn normal_map(
    gram: &mut SmallCholesky,
    map: &mut [f64],
    a: &[f64],
    rows: &[usize],
    n: usize,
) -> f64 {
    let ratio = gram_cholesky(gram, a, rows, n);
    for (out, &i) in map.chunks_exact_mut(n.max(1)).zip(rows) {
        out.copy_from_slice(&a[i * n..(i + 1) * n]);
    }
    gram.solve_rows(map, n);
    ratio
}

/// $x \leftarrow x - M^\mathsf{T}\mu$ for the map `map` (`|μ| × n`, row-major), with
/// `dx` (length `n`) as scratch; returns the largest change and the largest in the
/// weights $\text{atol} + \text{rtol}\,|x_j|$ (at the new values).
fn update(
    map: &[f64],
    mu: &[f64],
    x: &mut [f64],
    dx: &mut [f64],
    (rtol, atol): (f64, f64),
) -> (f64, f64) {
    let n = x.len();
    dx.fill(0.0);
    for (row, m) in map.chunks_exact(n.max(1)).zip(mu) {
        for (d, a) in dx.iter_mut().zip(row) {
            *d += a * m;
        }
    }
    let (mut step, mut weighted) = (0.0_f64, 0.0_f64);
    for (xj, d) in x.iter_mut().zip(&*dx) {
        *xj -= d;
        step = step.max(d.abs());
        weighted = weighted.max(d.abs() / (atol + rtol * xj.abs()));
    }
    (step, weighted)
}

impl Chart {
    /// Scratch for a model with `n` coordinates and `m` constraint rows, of which `r`
    /// independent holonomic ones, for the integrator's tolerances `rtol`, `atol`.
    pub fn new(n: usize, m: usize, r: usize, rtol: f64, atol: f64) -> Self {
        Self {
            anchor: vec![0.0; n],
            normals: vec![0.0; m * n],
            gram: SmallCholesky::new(m),
            position_map: vec![0.0; n * r],
            velocity_map: vec![0.0; m * m],
            velocity_map_regular: false,
            slot: vec![usize::MAX; m],
            nu: vec![0.0; m],
            vel: vec![0.0; m],
            mu: vec![0.0; m],
            dx: vec![0.0; n],
            rows: Vec::with_capacity(m),
            rows_h: 0,
            rate_per_distance: None,
            velocity_rate_per_distance: None,
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
        self.rows.clear();
        self.rows.extend_from_slice(&p.rows);
        self.rows_h = p.rows_h;
        let (n, r, m) = (p.q.len(), p.rows_h, p.rows.len());
        if self.position_map.len() != n * r || self.velocity_map.len() != m * m {
            // Assembly dropped redundant rows (allocates, once).
            self.position_map = vec![0.0; n * r];
            self.velocity_map = vec![0.0; m * m];
        }
        self.slot.fill(usize::MAX);
        for (k, &i) in self.rows.iter().enumerate() {
            self.slot[i] = k;
        }
        let identity = |map: &mut [f64]| {
            map.fill(0.0);
            for k in 0..m {
                map[k * m + k] = 1.0;
            }
        };
        if m > r {
            self.gram.resize(m);
            let ratio = gram_cholesky(&mut self.gram, &self.normals, &self.rows, n);
            identity(&mut self.velocity_map);
            self.gram.solve_rows(&mut self.velocity_map, m);
            self.velocity_map_regular = ratio.is_finite() && ratio > REFIT_RATIO;
        }
        self.gram.resize(r);
        let ratio = normal_map(
            &mut self.gram,
            &mut self.position_map,
            &self.normals,
            &self.rows[..r],
            n,
        );
        if m == r {
            identity(&mut self.velocity_map);
            self.gram.solve_rows(&mut self.velocity_map, m);
            self.velocity_map_regular = ratio.is_finite() && ratio > REFIT_RATIO;
        }
        Ok(ratio)
    }

    /// Moves the positions of `p` along the anchor's normals onto $C_R(q, t) = 0$
    /// ($R$: the holonomic rows of the projections), to the integrator's tolerance (see
    /// the module docs); returns the number of updates.
    pub fn correct<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<usize, ChartFailure> {
        let rows_h = self.rows_h;
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
            let (c, rows) = (p.ws.constraints(), &self.rows[..rows_h]);
            let mut residual = 0.0_f64;
            for (mu, &i) in self.mu.iter_mut().zip(rows) {
                *mu = c[i];
                residual = residual.max(c[i].abs());
            }
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
            let (step, weighted) = self.update(&mut p.q, rows_h);
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
            if rate / (1.0 - rate) * weighted <= KAPPA {
                return Ok(iteration + 1);
            }
            previous = Some(weighted);
        }
        unreachable!("the loop returns at MAX_ITERATIONS")
    }

    /// [`update`] with the position map and the first `r` residuals of `mu`.
    fn update(&mut self, x: &mut [f64], r: usize) -> (f64, f64) {
        update(
            &self.position_map,
            &self.mu[..r],
            x,
            &mut self.dx,
            (self.rtol, self.atol),
        )
    }

    /// Projects the velocities of `p` orthogonally onto the velocity constraints at its
    /// positions by the chord iteration of the module docs, until the estimated
    /// remaining error is below `kappa` in the integrator's weights or at round-off;
    /// returns the number of updates, or `None` when the iteration does not contract
    /// (or the maps do not serve the point's rows, see [`serves`](Self::serves)) and the
    /// velocities are to be projected at the point instead.
    pub fn correct_velocities<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
        kappa: f64,
    ) -> Result<Option<usize>, EvalError> {
        if !self.serves(p) {
            return Ok(None);
        }
        p.velocity_residuals(t)?;
        let ws = &p.ws;
        let terms = VelocityTerms {
            cq: &ws.cq_values,
            g: &ws.g_values,
            ct: &ws.ct,
            bias: &ws.bias,
        };
        let distance = self.distance(&p.q);
        Ok(self.project_velocities(p.info, terms, distance, &mut p.qd, kappa))
    }

    /// Whether the velocity iteration serves the rows of `p`: the maps are regular and
    /// made for its rows, and no redundant constraint was dropped (the kept rows imply
    /// the dropped ones only while they keep their rank, which the factored projection
    /// checks at the point, renewing them when it falls, and maps made at the anchor
    /// cannot).
    pub fn serves<M: Mechanism + ?Sized>(&self, p: &Point<'_, M>) -> bool {
        self.velocity_map_regular
            && self.rows == p.rows
            && self.rows_h == p.rows_h
            && p.rows_h == p.info.nh()
    }

    /// The distance $\lVert q - q_a\rVert_\infty$ of positions `q` from the anchor.
    pub fn distance(&self, q: &[f64]) -> f64 {
        q.iter()
            .zip(&self.anchor)
            .fold(0.0_f64, |a, (x, y)| a.max((x - y).abs()))
    }

    /// The iteration of [`correct_velocities`](Self::correct_velocities) on `qd` at
    /// positions `distance` from the anchor, with the pattern values of $C_q$, $G$ and
    /// $C_t$, $g$ there.
    pub fn project_velocities(
        &mut self,
        info: &Info,
        terms: VelocityTerms<'_>,
        distance: f64,
        qd: &mut [f64],
        kappa: f64,
    ) -> Option<usize> {
        let m = self.rows.len();
        if m == 0 {
            return Some(0);
        }
        let mut rate = self
            .velocity_rate_per_distance
            .or(self.rate_per_distance)
            .map_or(UNKNOWN_RATE, |r| (r * distance).min(UNKNOWN_RATE));
        let mh = info.nh();
        let mut previous: Option<f64> = None;
        for iteration in 0..MAX_ITERATIONS {
            // The residuals J q̇ + [C_t; g] of the rows.
            self.vel[..mh].copy_from_slice(terms.ct);
            self.vel[mh..].copy_from_slice(terms.bias);
            for (&(r, c), v) in info.holonomic_pattern.iter().zip(terms.cq) {
                self.vel[r as usize] += v * qd[c as usize];
            }
            for (&(r, c), v) in info.nonholonomic_pattern.iter().zip(terms.g) {
                self.vel[mh + r as usize] += v * qd[c as usize];
            }
            for (mu, &i) in self.mu.iter_mut().zip(&self.rows) {
                *mu = self.vel[i];
            }
            // ν = G_a⁻¹ μ, Δq̇ = Jᵀν.
            let mu = &self.mu[..m];
            for (nu, row) in self.nu.iter_mut().zip(self.velocity_map.chunks_exact(m)) {
                *nu = row.iter().zip(mu).map(|(a, b)| a * b).sum();
            }
            let dx = &mut self.dx;
            dx.fill(0.0);
            for (&(r, c), v) in info.holonomic_pattern.iter().zip(terms.cq) {
                if let Some(nu) = self.nu.get(self.slot[r as usize]) {
                    dx[c as usize] += v * nu;
                }
            }
            for (&(r, c), v) in info.nonholonomic_pattern.iter().zip(terms.g) {
                if let Some(nu) = self.nu.get(self.slot[mh + r as usize]) {
                    dx[c as usize] += v * nu;
                }
            }
            let floor = 8.0 * f64::EPSILON * inf_norm(qd);
            let (mut step, mut weighted) = (0.0_f64, 0.0_f64);
            for (xj, d) in qd.iter_mut().zip(&*dx) {
                *xj -= d;
                step = step.max(d.abs());
                weighted = weighted.max(d.abs() / (self.atol + self.rtol * xj.abs()));
            }
            if step <= floor {
                return Some(iteration + 1);
            }
            if !step.is_finite() {
                return None;
            }
            if let Some(p) = previous {
                let measured = weighted / p;
                if measured.is_nan() || measured >= DIVERGENCE {
                    return None;
                }
                rate = measured;
                if step > 100.0 * floor && distance > 0.0 {
                    self.velocity_rate_per_distance = Some(measured / distance);
                }
            }
            let left = rate / (1.0 - rate);
            if left * weighted <= kappa || left * step <= floor {
                return Some(iteration + 1);
            }
            previous = Some(weighted);
        }
        None
    }
}

/// The pattern values of $C_q$ and $G$ and the rates $C_t$, $g$ at a point, for the
/// velocity iteration.
#[derive(Clone, Copy, Debug)]
pub(crate) struct VelocityTerms<'a> {
    pub cq: &'a [f64],
    pub g: &'a [f64],
    pub ct: &'a [f64],
    pub bias: &'a [f64],
}
