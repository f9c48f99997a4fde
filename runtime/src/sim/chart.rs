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
//! $P = N^\mathsf{T}(N N^\mathsf{T})^{-1}$ of the anchor ($\Delta q = -P\,C_R$), so an
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
//! corrected positions (all rows, the non-holonomic ones too). Where the model has a
//! generated [`Mechanism::orthogonal_solve`] (every built-in model with constraints),
//! one call of it does this exactly: the system $[I\ J^\mathsf{T}; J\ 0]$ factored
//! at the point by straight-line code specialized to the patterns, at the same cost
//! whatever the distance from the anchor
//! (docs/decisions/0038-partitioning-velocities-by-generated-orthogonal-solve.md). Otherwise
//! (no generated solve, or it declines: dependent or nearly dependent rows), the chord
//! iteration
//! $\dot q \leftarrow \dot q - J^\mathsf{T} G_a^{-1}(J\dot q + [C_t; g])$ with the inverse
//! of the anchor's $G_a = J_a J_a^\mathsf{T}$ (made once per anchor, when first read)
//! converges to the orthogonal projection at $q$ (every update lies in the range of $J(q)^\mathsf{T}$) at
//! the rate $\lVert I - J J^\mathsf{T} G_a^{-1}\rVert$, proportional to the distance from
//! the anchor like the positions'; each update is a product with the pattern of $J$
//! (by rows), one with an `m × m` matrix and one with the pattern of $J^\mathsf{T}$ (by
//! columns: the pattern is laid out both ways once, so no sum goes through memory). It stops like the positions' iteration. An iteration
//! that does not contract, and models whose redundant constraints were dropped, hand
//! over to the factored projection at the point ([`Point::project_velocities`]). Moving the velocities along the anchor's normals
//! instead (the derivative of the chart's map, which keeps the tangential velocities
//! of the integrator) was measured to be 2–30 times less accurate on the pendulum
//! (DOP853 and Adams, rtol 1e-5 to 1e-9).
//!
//! Invariant: no allocation after [`Chart::new`] (except when building an error).

use super::point::{Point, REFIT_RATIO};
use crate::linalg::inf_norm;
use crate::linalg::small::{gram_cholesky, gram_cholesky_planned, SmallCholesky};
use crate::linalg::sparse::SparseLdlt;
use crate::scale;
use crate::workspace::EvalError;
use crate::{AugmentedSolve, Info, Mechanism};

/// Fraction of the integrator's tolerance the Newton iteration leaves as error.
///
/// Implicit integrators stop their Newton iterations a few hundredths of the tolerance
/// away from the solution (Hairer's `RADAU5`: 0.03). Here the left error moves the
/// evaluated state off the manifold by that much, and the right-hand side with it.
pub(crate) const KAPPA: f64 = 0.03;

/// [`KAPPA`] for a model whose redundant constraint rows were dropped: the right-hand
/// side off the manifold is then far more sensitive to the distance than a state's
/// own error. The dropped rows are dependent on the manifold only, so at a state
/// $10^{-4}$ off it (0.03 of rtol 1e-3) `bricard`'s accelerations were off by order
/// one, and its DOPRI5 runs gained 28 J of 32 at rtol 1e-3 where projection kept the
/// energy to 2e-4 J; with this fraction, 6e-4 J
/// (docs/decisions/0036-through-a-rank-drop.md).
const KAPPA_REDUNDANT: f64 = 1e-6;

/// Rows from which the maps are applied by a sparse factor instead of formed densely
/// (see [`Maps`]).
const SPARSE_ROWS: usize = 64;

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

/// The maps of one anchor: where they were made, its Jacobian and the explicit
/// inverses of its Gram matrices (formed from the Cholesky factor as
/// $D L^{-\mathsf{T}} L^{-1} D$, see [`SmallCholesky::inverse_into`]).
#[derive(Debug)]
struct Maps {
    /// The anchor $q_a$.
    anchor: Vec<f64>,
    /// $J(q_a)$, dense row-major `m × n`; $N$ is its rows `rows[..rows_h]` (not made
    /// when the sparse factor serves the anchor).
    normals: Vec<f64>,
    /// $(N N^\mathsf{T})^{-1}N$, row-major `r × n` (its transpose is the map $P$).
    position_map: Vec<f64>,
    /// $G_a^{-1} = (J_a J_a^\mathsf{T})^{-1}$ of every projected row (holonomic and
    /// non-holonomic), row-major `m × m`, and whether $G_a$ is regular.
    velocity_map: Vec<f64>,
    velocity_map_regular: bool,
    /// Whether `velocity_map` holds this anchor's $G_a^{-1}$. When every row is
    /// holonomic it is the inverse of `factor` and is made at the first chord update
    /// that needs it: the model's generated orthogonal solve projects the velocities
    /// of most evaluations, and an anchor whose map no update reads costs no inverse.
    velocity_map_made: bool,
    /// The Cholesky factor of $N N^\mathsf{T}$ (of $G_a$ too when every row is
    /// holonomic), when `factor_made`: the model's generated
    /// [`Mechanism::holonomic_normal_map`] forms `position_map` without it, and the
    /// factor is then made only if a velocity chord update reads $G_a^{-1}$.
    factor: SmallCholesky,
    factor_made: bool,
    /// For each constraint row, its place in `rows` (`usize::MAX` when not projected).
    slot: Vec<usize>,
    /// The rows of the point's projections when anchored (the first `rows_h`
    /// holonomic), which the maps belong to; empty before the first anchor.
    rows: Vec<usize>,
    rows_h: usize,
    /// The pivot ratio of $N N^\mathsf{T}$.
    ratio: f64,
    /// Whether `rows` are all the constraint rows in order (`slot` the identity).
    all_rows: bool,
    /// For models with [`SPARSE_ROWS`] holonomic rows or more (and no other rows, none
    /// dropped): the sparse $LDL^\mathsf{T}$ of $[I\ N^\mathsf{T}; N\ 0]$, whose
    /// solve with the right-hand side $[0; \mu]$ is $[P\mu; -(N N^\mathsf{T})^{-1}\mu]$:
    /// both maps applied in $O(\text{nnz})$, where forming them densely costs
    /// $O(r^2 n)$ per anchor (`chain100`: 39 ms a step). `None` until first needed;
    /// boxed, because the staged maps and the anchor's are swapped at every accepted
    /// step ([`Chart::anchor_staged`]) and the factor inline made that a copy of its
    /// whole structure.
    sparse: Option<Box<Sparse>>,
    /// Whether the maps of the current anchor are the sparse factor's.
    sparse_active: bool,
}

/// The sparse factor of [`Maps::sparse`] with its scratch.
#[derive(Debug)]
struct Sparse {
    ldlt: SparseLdlt,
    /// The unit mass entries of $I$, in the pattern's order.
    ones: Vec<f64>,
    b: Vec<f64>,
    x: Vec<f64>,
}

impl Sparse {
    fn new(info: &Info) -> Option<Self> {
        let n = info.nq();
        let diagonal: Vec<(u32, u32)> = (0..n as u32).map(|i| (i, i)).collect();
        let ldlt =
            SparseLdlt::with_patterns(n, &diagonal, (info.holonomic_pattern, info.nh()), (&[], 0))?;
        let dim = n + info.nh();
        Some(Self {
            ldlt,
            ones: vec![1.0; n],
            b: vec![0.0; dim],
            x: vec![0.0; dim],
        })
    }

    /// `x` = $[P\mu; -(N N^\mathsf{T})^{-1}\mu]$ of the last factor.
    fn solve(&mut self, mu: &[f64]) -> &[f64] {
        let n = self.ones.len();
        self.b[..n].fill(0.0);
        self.b[n..].copy_from_slice(mu);
        self.ldlt.solve(&self.b, &[], &mut self.x);
        &self.x
    }
}

impl Maps {
    fn new(n: usize, m: usize, r: usize) -> Self {
        Self {
            anchor: vec![0.0; n],
            normals: vec![0.0; m * n],
            position_map: vec![0.0; n * r],
            velocity_map: vec![0.0; m * m],
            velocity_map_regular: false,
            velocity_map_made: false,
            factor: SmallCholesky::new(r),
            factor_made: false,
            slot: vec![usize::MAX; m],
            rows: Vec::with_capacity(m),
            rows_h: 0,
            ratio: f64::NAN,
            all_rows: false,
            sparse: None,
            sparse_active: false,
        }
    }

    /// Makes the maps at the current positions of `p` (its dense $J$ there, or only the
    /// pattern values for the sparse factor), with `gram` as scratch; returns the pivot
    /// ratio of $N N^\mathsf{T}$.
    fn make<M: Mechanism + ?Sized>(
        &mut self,
        gram: &mut SmallCholesky,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<f64, EvalError> {
        self.anchor.copy_from_slice(&p.q);
        self.rows.clear();
        self.rows.extend_from_slice(&p.rows);
        self.rows_h = p.rows_h;
        let (n, r, m) = (p.q.len(), p.rows_h, p.rows.len());
        if self.position_map.len() != n * r || self.velocity_map.len() != m * m {
            // Assembly dropped redundant rows, or the rows kept changed in number near a
            // rank drop of C_q (allocates).
            self.position_map = vec![0.0; n * r];
            self.velocity_map = vec![0.0; m * m];
        }
        self.slot.fill(usize::MAX);
        for (k, &i) in self.rows.iter().enumerate() {
            self.slot[i] = k;
        }
        self.all_rows = self.rows.len() == self.slot.len()
            && self.rows.iter().enumerate().all(|(k, &i)| k == i);
        self.sparse_active = false;
        let info = p.info;
        if self.all_rows && m == r && r == info.nh() && r >= SPARSE_ROWS {
            if self.sparse.is_none() {
                // Once per simulation (allocates).
                self.sparse = Sparse::new(info).map(Box::new);
            }
            if let Some(sp) = self.sparse.as_mut() {
                p.jacobian_values(t)?;
                if sp.ldlt.factor(&sp.ones, &p.ws.cq_values, &[]) {
                    let ratio = sp.ldlt.schur_ratio();
                    self.sparse_active = true;
                    self.velocity_map_regular = ratio.is_finite() && ratio > REFIT_RATIO;
                    self.ratio = ratio;
                    return Ok(ratio);
                }
            }
        }
        self.normals.copy_from_slice(p.dense_jacobian(t)?);
        // The Gram matrices from the products the patterns leave (the point's plans are
        // made for its rows, which the maps copied): the dense sums' bits.
        let (plan_h, plan_v) = p.gram_plans();
        if m > r {
            gram.resize(m);
            let ratio = gram_cholesky_planned(gram, &self.normals, plan_v);
            gram.inverse_into(&mut self.velocity_map);
            self.velocity_map_made = true;
            self.velocity_map_regular = ratio.is_finite() && ratio > REFIT_RATIO;
        }
        // Every holonomic row, in order: the model's generated map, where it has one.
        let holonomic_in_order =
            r == info.nh() && self.rows[..r].iter().enumerate().all(|(k, &i)| k == i);
        let generated = holonomic_in_order
            .then(|| {
                p.mech
                    .holonomic_normal_map(&p.ws.cq_values, &mut self.position_map)
            })
            .flatten();
        self.factor_made = generated.is_none();
        let ratio = match generated {
            Some(ratio) => ratio,
            None => {
                let factor = &mut self.factor;
                factor.resize(r);
                let ratio = gram_cholesky_planned(factor, &self.normals, plan_h);
                for (out, &i) in self.position_map.chunks_exact_mut(n.max(1)).zip(&self.rows) {
                    out.copy_from_slice(&self.normals[i * n..(i + 1) * n]);
                }
                factor.solve_rows(&mut self.position_map, n);
                ratio
            }
        };
        if m == r {
            // Made when first read (`inverse_gram`).
            self.velocity_map_made = false;
            self.velocity_map_regular = ratio.is_finite() && ratio > REFIT_RATIO;
        }
        self.ratio = ratio;
        Ok(ratio)
    }

    /// A position update with these maps (see [`update`]).
    fn update(&mut self, mu: &[f64], dx: &mut [f64], x: &mut [f64], tol: (f64, f64)) -> (f64, f64) {
        match self.sparse.as_mut().filter(|_| self.sparse_active) {
            Some(sp) => {
                let n = x.len();
                dx.copy_from_slice(&sp.solve(&mu[..self.rows_h])[..n]);
                apply(x, dx, tol)
            }
            None => update(&self.position_map, &mu[..self.rows_h], x, dx, tol),
        }
    }

    /// $\nu = G_a^{-1}\mu$ for the velocity iteration.
    fn inverse_gram(&mut self, mu: &[f64], nu: &mut [f64]) {
        match self.sparse.as_mut().filter(|_| self.sparse_active) {
            Some(sp) => {
                let n = sp.ones.len();
                for (v, x) in nu.iter_mut().zip(&sp.solve(mu)[n..]) {
                    *v = -x;
                }
            }
            None => {
                if !self.velocity_map_made {
                    if !self.factor_made {
                        // The model's generated map served the anchor: the factor now,
                        // from the anchor's normals (the planned product's bits).
                        let (r, n) = (self.rows_h, self.anchor.len());
                        self.factor.resize(r);
                        gram_cholesky(&mut self.factor, &self.normals, &self.rows[..r], n);
                        self.factor_made = true;
                    }
                    self.factor.inverse_into(&mut self.velocity_map);
                    self.velocity_map_made = true;
                }
                symmetric_product(&self.velocity_map, mu, nu);
            }
        }
    }

    /// Whether the velocity iteration with these maps serves the rows of `p` (see
    /// [`Chart::serves`]).
    fn serves<M: Mechanism + ?Sized>(&self, p: &Point<'_, M>) -> bool {
        self.velocity_map_regular
            && self.rows == p.rows
            && self.rows_h == p.rows_h
            && p.rows_h == p.info.nh()
    }

    /// Whether a residual `residual` of the projected rows is within the rounding floor
    /// of `scale::at_rounding_floor` ($64\,\varepsilon\,\lVert (C_q)_i\rVert_\infty
    /// \max(s_q, 1)$, the row norms of the anchor's $J$ standing for the point's); `false`
    /// with the sparse factor, which forms no dense $J$.
    fn at_rounding_floor(&self, residual: f64, size: f64) -> bool {
        if self.sparse_active {
            return false;
        }
        let n = self.anchor.len();
        let norm = self
            .rows
            .iter()
            .take(self.rows_h)
            .flat_map(|&i| &self.normals[i * n..(i + 1) * n])
            .fold(0.0_f64, |a, &x| larger(a, x.abs()));
        residual <= scale::rounding_floor_distance(size) * norm
    }

    /// The distance $\lVert q - q_a\rVert_\infty$ of positions `q` from the anchor.
    fn distance(&self, q: &[f64]) -> f64 {
        q.iter()
            .zip(&self.anchor)
            .fold(0.0_f64, |a, (x, y)| larger(a, (x - y).abs()))
    }
}

/// A chart anchored at an accepted state, with the Newton scratch.
///
/// Besides the anchor's maps it holds the maps *staged* by [`Chart::stage`] at a kept
/// state before its polish: [`Chart::anchor_staged`] takes them as the next anchor
/// when the state is accepted, so that an accepted step factors one Gram matrix.
#[derive(Debug)]
pub(crate) struct Chart {
    maps: Maps,
    staged: Maps,
    /// The time and the polished positions of the kept state the staged maps were
    /// made for (`None`: no staged maps).
    staged_for: Option<f64>,
    staged_q: Vec<f64>,
    /// $G_a^{-1}$ times the velocity residuals.
    nu: Vec<f64>,
    /// The factorization of a Gram matrix, scratch for the maps.
    gram: SmallCholesky,
    /// The velocity residuals of every constraint row.
    vel: Vec<f64>,
    /// The residuals of the current update.
    mu: Vec<f64>,
    /// The current position update.
    dx: Vec<f64>,
    /// $[\Delta; \mu]$ of the model's generated orthogonal solve (`n + m`).
    exact: Vec<f64>,
    /// Whether the model's generated orthogonal solve is unavailable (learned at its
    /// first call): the chord iteration projects every evaluation's velocities.
    exact_unavailable: bool,
    /// The pattern of $J$ grouped by rows and by columns (made at the first velocity
    /// iteration).
    layout: Layout,
    /// Measured contraction rate per unit distance from the anchor.
    rate_per_distance: Option<f64>,
    /// The same, measured on the velocities' iteration.
    velocity_rate_per_distance: Option<f64>,
    rtol: f64,
    atol: f64,
}

/// `b` when it is larger than `a` (or `a` is NaN), `a` otherwise: one instruction
/// (`maxsd`), where [`f64::max`] also tests for NaN. The maxima of the chart start
/// from 0 and test their inputs for NaN where it matters.
#[inline(always)]
fn larger(a: f64, b: f64) -> f64 {
    if b > a {
        b
    } else {
        a
    }
}

/// $y = A x$ for a symmetric row-major `A` (`k × k`, `k` the length of `x`), as
/// $\sum_i x_i A_{i\cdot}$: contiguous rows added to `y` side by side. The dot products
/// of the rows give the same bits (`A` is exactly symmetric); the two were not told apart
/// in speed on andrews, the pendulum and car_axis (within 3 %, the noise).
fn symmetric_product(a: &[f64], x: &[f64], y: &mut [f64]) {
    let k = x.len();
    y.fill(0.0);
    for (row, &xi) in a.chunks_exact(k.max(1)).zip(x) {
        for (yj, aij) in y.iter_mut().zip(row) {
            *yj += aij * xi;
        }
    }
}

/// $x \leftarrow x - M^\mathsf{T}\mu$ for the map `map` (`|μ| × n`, row-major), with
/// `dx` (length `n`) as scratch; returns the largest change and the largest in the
/// weights $\text{atol} + \text{rtol}\,|x_j|$ (at the new values), NaN when a change is
/// NaN.
fn update(
    map: &[f64],
    mu: &[f64],
    x: &mut [f64],
    dx: &mut [f64],
    (rtol, atol): (f64, f64),
) -> (f64, f64) {
    let n = x.len();
    let tol = (rtol, atol);
    // The chart's own sizes unrolled (the built-in models have 2 to 10 coordinates):
    // the same sums in the same order, in registers.
    match n {
        1 => update_fixed::<1>(map, mu, x, tol),
        2 => update_fixed::<2>(map, mu, x, tol),
        3 => update_fixed::<3>(map, mu, x, tol),
        4 => update_fixed::<4>(map, mu, x, tol),
        5 => update_fixed::<5>(map, mu, x, tol),
        6 => update_fixed::<6>(map, mu, x, tol),
        7 => update_fixed::<7>(map, mu, x, tol),
        8 => update_fixed::<8>(map, mu, x, tol),
        9 => update_fixed::<9>(map, mu, x, tol),
        10 => update_fixed::<10>(map, mu, x, tol),
        _ => {
            dx.fill(0.0);
            for (row, m) in map.chunks_exact(n.max(1)).zip(mu) {
                for (d, a) in dx.iter_mut().zip(row) {
                    *d += a * m;
                }
            }
            apply(x, dx, tol)
        }
    }
}

/// [`update`] for `N` coordinates: $\Delta x$ summed in a local array over the rows
/// in their order (the general loop's operations, bit for bit), then applied.
// Index loops over constant bounds are what the compiler unrolls.
#[allow(clippy::needless_range_loop)]
fn update_fixed<const N: usize>(
    map: &[f64],
    mu: &[f64],
    x: &mut [f64],
    tol: (f64, f64),
) -> (f64, f64) {
    let mut dx = [0.0_f64; N];
    for (row, m) in map.chunks_exact(N).zip(mu) {
        let row: &[f64; N] = row.try_into().expect("rows of N entries");
        for j in 0..N {
            dx[j] += row[j] * m;
        }
    }
    apply(&mut x[..N], &dx, tol)
}

/// $x \leftarrow x - \Delta x$; returns the largest change and the largest in the
/// weights (see [`update`]), NaN when a change is NaN.
#[inline]
fn apply(x: &mut [f64], dx: &[f64], (rtol, atol): (f64, f64)) -> (f64, f64) {
    let (mut step, mut weighted, mut nan) = (0.0_f64, 0.0_f64, false);
    for (xj, &d) in x.iter_mut().zip(dx) {
        *xj -= d;
        nan |= d.is_nan();
        step = larger(step, d.abs());
        weighted = larger(weighted, d.abs() / (atol + rtol * xj.abs()));
    }
    if nan {
        return (f64::NAN, f64::NAN);
    }
    (step, weighted)
}

/// Most chord updates of [`Chart::polish`] before it hands over to Newton.
const POLISH_ITERATIONS: usize = 4;

impl Chart {
    /// Scratch for a model with `n` coordinates and `m` constraint rows, of which `r`
    /// independent holonomic ones, for the integrator's tolerances `rtol`, `atol`.
    pub fn new(n: usize, m: usize, r: usize, rtol: f64, atol: f64) -> Self {
        Self {
            maps: Maps::new(n, m, r),
            staged: Maps::new(n, m, r),
            staged_for: None,
            staged_q: vec![0.0; n],
            gram: SmallCholesky::new(m),
            nu: vec![0.0; m],
            vel: vec![0.0; m],
            mu: vec![0.0; m],
            dx: vec![0.0; n],
            exact: vec![0.0; n + m],
            exact_unavailable: false,
            layout: Layout::default(),
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
        self.staged_for = None;
        self.maps.make(&mut self.gram, p, t)
    }

    /// Makes the maps of the current positions of `p` (a kept state as reconstructed,
    /// on the manifold to the integrator's tolerance) as the staged ones, for
    /// [`polish`](Self::polish) and [`correct_velocities_staged`](Self::correct_velocities_staged)
    /// to use and [`anchor_staged`](Self::anchor_staged) to take; returns the pivot
    /// ratio of $N N^\mathsf{T}$ and whether the staged maps serve the point.
    pub fn stage<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<(f64, bool), EvalError> {
        self.staged_for = None;
        let ratio = self.staged.make(&mut self.gram, p, t)?;
        Ok((ratio, self.staged.serves(p)))
    }

    /// Records that the staged maps belong to the kept state `(t, q)`.
    pub fn stage_for(&mut self, t: f64, q: &[f64]) {
        self.staged_for = Some(t);
        self.staged_q.copy_from_slice(q);
    }

    /// Takes the staged maps as the anchor when they were staged for the state of `p`
    /// at `t` (and its rows); returns their pivot ratio then, `None` otherwise.
    ///
    /// The anchor is then the kept state before its polish, off the manifold by the
    /// chart's tolerance and as far from the polished state: the chart is the graph
    /// over the tangent space of a point that need not lie on the manifold, its
    /// conditioning and its contraction rates change by that relative amount.
    pub fn anchor_staged<M: Mechanism + ?Sized>(
        &mut self,
        p: &Point<'_, M>,
        t: f64,
    ) -> Option<f64> {
        if self.staged_for != Some(t)
            || self.staged_q != p.q
            || self.staged.rows != p.rows
            || self.staged.rows_h != p.rows_h
        {
            return None;
        }
        self.staged_for = None;
        std::mem::swap(&mut self.maps, &mut self.staged);
        Some(self.maps.ratio)
    }

    /// Polishes the positions of `p` onto the holonomic constraints to the relative
    /// `tolerance` (as [`Point::project_positions`] decides it) by the chord iteration
    /// with the staged position map: made at the first iterate, its first update is
    /// Newton's, and from a residual at the chart's tolerance one update is the norm.
    /// Returns the number of updates, or `None` when the iteration does not contract
    /// within a few updates (for Newton to take over from where it stopped).
    pub fn polish<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
        tolerance: f64,
    ) -> Result<Option<usize>, EvalError> {
        let r = self.staged.rows_h;
        let mut previous = f64::INFINITY;
        for iteration in 0..=POLISH_ITERATIONS {
            p.constraints(t)?;
            p.jacobian_values(t)?;
            let size = scale::coordinate_size(&p.q);
            let (c, norms) = p.ws.constraints_and_row_norms(p.mech);
            let residual = inf_norm(c);
            if scale::all_met_by_norms(c, norms, tolerance, size)
                || (residual >= 0.5 * previous && scale::at_rounding_floor_by_norms(c, norms, size))
            {
                return Ok(Some(iteration));
            }
            if iteration == POLISH_ITERATIONS || !residual.is_finite() || residual >= 0.5 * previous
            {
                return Ok(None);
            }
            previous = residual;
            for (mu, &i) in self.mu.iter_mut().zip(&self.staged.rows[..r]) {
                *mu = c[i];
            }
            let tol = (self.rtol, self.atol);
            self.staged.update(&self.mu, &mut self.dx, &mut p.q, tol);
            p.newton_iterations += 1;
        }
        Ok(None)
    }

    /// Moves the positions of `p` along the anchor's normals onto $C_R(q, t) = 0$
    /// ($R$: the holonomic rows of the projections), to the integrator's tolerance (see
    /// the module docs); returns the number of updates.
    pub fn correct<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<usize, ChartFailure> {
        let rows_h = self.maps.rows_h;
        let distance = self.maps.distance(&p.q);
        let mut rate = self
            .rate_per_distance
            .map_or(UNKNOWN_RATE, |r| (r * distance).min(UNKNOWN_RATE));
        let size = inf_norm(&p.q);
        let floor = 8.0 * f64::EPSILON * size;
        let kappa = if rows_h < p.info.nh() {
            KAPPA_REDUNDANT
        } else {
            KAPPA
        };
        let row = p.row;
        let mut previous: Option<f64> = None;
        for iteration in 0..=MAX_ITERATIONS {
            p.constraints(t)?;
            let (c, rows) = (p.ws.constraints(), &self.maps.rows[..rows_h]);
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
            let tol = (self.rtol, self.atol);
            let (step, weighted) = self.maps.update(&self.mu, &mut self.dx, &mut p.q, tol);
            // An update at round-off has converged, whatever rate its noise suggests.
            if step <= floor {
                return Ok(iteration + 1);
            }
            if let Some(p) = previous {
                let measured = weighted / p;
                if measured.is_nan() || measured >= DIVERGENCE {
                    // Stagnant with C at its rounding floor (which follows the size of
                    // the geometry, not of q: a linkage whose angles start at 0) as
                    // `scale::at_rounding_floor` accepts it: the ratio of updates at
                    // round-off is noise, not a divergence. KAPPA_REDUNDANT asks for
                    // updates that small; near a rank drop of the kept rows they are
                    // large (1e-13), C is not.
                    if self.maps.at_rounding_floor(residual, size) {
                        return Ok(iteration + 1);
                    }
                    return Err(ChartFailure::Newton {
                        iterations: iteration + 1,
                        residual,
                    });
                }
                rate = measured;
                // A rate measured on updates at round-off is noise; one measured on
                // an output row or a dense stage is not learned (`Point::row`).
                if step > 100.0 * floor && distance > 0.0 && !row {
                    self.rate_per_distance = Some(measured / distance);
                }
            }
            if rate / (1.0 - rate) * weighted <= kappa {
                return Ok(iteration + 1);
            }
            previous = Some(weighted);
        }
        unreachable!("the loop returns at MAX_ITERATIONS")
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
        self.correct_velocities_with(p, t, kappa, false)
    }

    /// [`correct_velocities`](Self::correct_velocities) to round-off with the staged
    /// maps (see [`stage`](Self::stage)).
    pub fn correct_velocities_staged<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<Option<usize>, EvalError> {
        self.correct_velocities_with(p, t, 0.0, true)
    }

    fn correct_velocities_with<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
        kappa: f64,
        staged: bool,
    ) -> Result<Option<usize>, EvalError> {
        let maps = if staged { &self.staged } else { &self.maps };
        if !maps.serves(p) {
            return Ok(None);
        }
        // The projection forms its residuals from these (its own, at each update).
        p.velocity_terms(t)?;
        let ws = &p.ws;
        let terms = VelocityTerms {
            cq: &ws.cq_values,
            g: &ws.g_values,
            ct: &ws.ct,
            bias: &ws.bias,
        };
        let distance = maps.distance(&p.q);
        if self.exact_projection(p.mech, p.info, terms, &mut p.qd, staged) {
            return Ok(Some(1));
        }
        Ok(self.iterate_velocities(p.info, terms, distance, &mut p.qd, kappa, staged))
    }

    /// Whether the velocity iteration serves the rows of `p`: the maps are regular and
    /// made for its rows, and no redundant constraint was dropped (the kept rows imply
    /// the dropped ones only while they keep their rank, which the factored projection
    /// checks at the point, renewing them when it falls, and maps made at the anchor
    /// cannot).
    pub fn serves<M: Mechanism + ?Sized>(&self, p: &Point<'_, M>) -> bool {
        self.maps.serves(p)
    }

    /// The distance $\lVert q - q_a\rVert_\infty$ of positions `q` from the anchor.
    pub fn distance(&self, q: &[f64]) -> f64 {
        self.maps.distance(q)
    }

    /// The orthogonal projection of `qd` onto the velocity constraints at a point with
    /// the pattern values `terms`, in one pass by the model's generated
    /// [`Mechanism::orthogonal_solve`] ($[I\ J^\mathsf{T}; J\ 0]$ factored at the
    /// point, the right-hand side $[0; -(J\dot q + [C_t; g])]$), else by the
    /// iteration of [`correct_velocities`](Self::correct_velocities) on `qd` at
    /// positions `distance` from the anchor. The iteration's limit is the same
    /// projection; the solve reaches it in one pass, where the iteration takes more
    /// updates the further the point is from the anchor (1 to 5 at DOP853's stages).
    /// The solve serves when every row is
    /// projected (no redundant row dropped) and its pivots pass (it declines for
    /// dependent or nearly dependent rows, which the iteration or the factored
    /// projection then handle).
    pub fn project_velocities<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        info: &Info,
        terms: VelocityTerms<'_>,
        distance: f64,
        qd: &mut [f64],
        kappa: f64,
    ) -> Option<usize> {
        if self.exact_projection(mech, info, terms, qd, false) {
            return Some(1);
        }
        self.iterate_velocities(info, terms, distance, qd, kappa, false)
    }

    /// The pattern layout of $J$ for `n` coordinates, made at the first velocity
    /// projection (once per simulation: the patterns are the model's).
    fn build_layout(&mut self, info: &Info, n: usize) {
        if !self.layout.built {
            self.layout = Layout::new(info, n, self.vel.len());
        }
    }

    /// Whether [`exact_projection`](Self::exact_projection) may serve the current (or
    /// the staged) maps: the model's solve is not known to be unavailable and every
    /// row is projected.
    fn exact_ready(&self, staged: bool) -> bool {
        let maps = if staged { &self.staged } else { &self.maps };
        !self.exact_unavailable && maps.all_rows && !maps.rows.is_empty()
    }

    /// The one-pass projection of [`project_velocities`](Self::project_velocities)
    /// for the maps of the current (or the staged) anchor; `false` when it does not
    /// apply, `qd` unchanged.
    fn exact_projection<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        info: &Info,
        terms: VelocityTerms<'_>,
        qd: &mut [f64],
        staged: bool,
    ) -> bool {
        if !self.exact_ready(staged) {
            return false;
        }
        // The model's projection, residuals included, where it has one; else the
        // residuals here and its solve.
        match mech.orthogonal_projection(terms.cq, terms.g, terms.ct, terms.bias, qd) {
            AugmentedSolve::Solved => return true,
            AugmentedSolve::Declined => return false,
            AugmentedSolve::Unavailable => {}
        }
        self.build_layout(info, qd.len());
        let n = qd.len();
        self.layout.residuals(terms, qd, &mut self.vel);
        for (r, v) in self.exact[n..].iter_mut().zip(&self.vel) {
            *r = -v;
        }
        match mech.orthogonal_solve(terms.cq, terms.g, &mut self.exact) {
            AugmentedSolve::Solved => {}
            AugmentedSolve::Unavailable => {
                self.exact_unavailable = true;
                return false;
            }
            AugmentedSolve::Declined => return false,
        }
        let delta = &self.exact[..n];
        // A non-finite input leaves a non-finite entry (as in the augmented solve):
        // the iteration then reports it.
        if !delta.iter().all(|d| d.is_finite()) {
            return false;
        }
        for (x, d) in qd.iter_mut().zip(delta) {
            *x += d;
        }
        true
    }

    fn iterate_velocities(
        &mut self,
        info: &Info,
        terms: VelocityTerms<'_>,
        distance: f64,
        qd: &mut [f64],
        kappa: f64,
        staged: bool,
    ) -> Option<usize> {
        self.build_layout(info, qd.len());
        let maps = if staged {
            &mut self.staged
        } else {
            &mut self.maps
        };
        let rate = self
            .velocity_rate_per_distance
            .or(self.rate_per_distance)
            .map_or(UNKNOWN_RATE, |r| (r * distance).min(UNKNOWN_RATE));
        let scratch = Scratch {
            nu: &mut self.nu,
            vel: &mut self.vel,
            mu: &mut self.mu,
        };
        let (updates, measured) = velocity_iteration(
            maps,
            scratch,
            &self.layout,
            terms,
            qd,
            (rate, kappa),
            (self.rtol, self.atol),
        );
        if let Some(measured) = measured.filter(|_| distance > 0.0) {
            self.velocity_rate_per_distance = Some(measured / distance);
        }
        updates
    }
}

/// The chart's scratch vectors for [`velocity_iteration`].
struct Scratch<'a> {
    nu: &'a mut [f64],
    vel: &'a mut [f64],
    mu: &'a mut [f64],
}

/// The combined pattern of $J$ (the holonomic rows, then the non-holonomic ones as
/// rows `mh..m`) grouped by rows and by columns, so that each sum of the velocity
/// iteration ($J\dot q$ by rows, $J^\mathsf{T}\nu$ by columns) is carried in a register
/// instead of scattered into memory entry by entry (consecutive entries of a pattern
/// share a row, and each `+=` waited for the store of the one before). Within a row
/// or a column the entries keep their order in the patterns, so the sums are the
/// scatter's, bit for bit.
#[derive(Debug, Default)]
struct Layout {
    built: bool,
    /// The number of holonomic rows.
    mh: usize,
    /// Row `i`'s entries are `by_row[row_start[i]..row_start[i + 1]]`: its column and
    /// the index of its value among the pattern values of $C_q$ (row `i < mh`) or of
    /// $G$.
    row_start: Vec<usize>,
    by_row: Vec<(u32, u32)>,
    /// Column `j`'s holonomic entries are `by_col[col_start[j]..col_split[j]]`, its
    /// non-holonomic ones `by_col[col_split[j]..col_start[j + 1]]`: each its row (of
    /// all `m`) and the index of its value.
    col_start: Vec<usize>,
    col_split: Vec<usize>,
    by_col: Vec<(u32, u32)>,
}

impl Layout {
    /// The layout of the patterns of `info`, for `n` coordinates and `m` rows.
    fn new(info: &Info, n: usize, m: usize) -> Self {
        let mh = info.nh();
        let (hol, non) = (info.holonomic_pattern, info.nonholonomic_pattern);
        let entries = || {
            let h = hol
                .iter()
                .enumerate()
                .map(|(k, &(r, c))| (r as usize, c, k, true));
            let g = non
                .iter()
                .enumerate()
                .map(move |(k, &(r, c))| (mh + r as usize, c, k, false));
            h.chain(g)
        };
        let index = |k: usize| u32::try_from(k).expect("pattern index fits u32");
        let mut row_start = vec![0; m + 1];
        for (r, ..) in entries() {
            row_start[r + 1] += 1;
        }
        for i in 0..m {
            row_start[i + 1] += row_start[i];
        }
        let mut by_row = vec![(0, 0); hol.len() + non.len()];
        let mut fill = row_start.clone();
        for (r, c, k, _) in entries() {
            by_row[fill[r]] = (c, index(k));
            fill[r] += 1;
        }
        let (mut count_h, mut count_g) = (vec![0; n], vec![0; n]);
        for (_, c, _, h) in entries() {
            if h {
                count_h[c as usize] += 1;
            } else {
                count_g[c as usize] += 1;
            }
        }
        let mut col_start = vec![0; n + 1];
        let mut col_split = vec![0; n];
        for j in 0..n {
            col_split[j] = col_start[j] + count_h[j];
            col_start[j + 1] = col_split[j] + count_g[j];
        }
        let mut by_col = vec![(0, 0); hol.len() + non.len()];
        let (mut fill_h, mut fill_g) = (col_start.clone(), col_split.clone());
        for (r, c, k, h) in entries() {
            let fill = if h { &mut fill_h } else { &mut fill_g };
            by_col[fill[c as usize]] = (index(r), index(k));
            fill[c as usize] += 1;
        }
        Self {
            built: true,
            mh,
            row_start,
            by_row,
            col_start,
            col_split,
            by_col,
        }
    }

    /// $J\dot q + [C_t; g]$ of every row into `vel`, with the pattern values of `terms`.
    #[inline(always)]
    fn residuals(&self, terms: VelocityTerms<'_>, qd: &[f64], vel: &mut [f64]) {
        let rates = terms.ct.iter().chain(terms.bias);
        for (i, (v, &start)) in vel.iter_mut().zip(rates).enumerate() {
            let entries = &self.by_row[self.row_start[i]..self.row_start[i + 1]];
            let values = if i < self.mh { terms.cq } else { terms.g };
            *v = entries
                .iter()
                .fold(start, |s, &(c, k)| s + values[k as usize] * qd[c as usize]);
        }
    }

    /// $(J^\mathsf{T}\nu)_j$ with the pattern values `(cq, g)` and `nu` of every row.
    #[inline(always)]
    fn column(&self, j: usize, (cq, g): (&[f64], &[f64]), nu: &[f64]) -> f64 {
        let (a, b, e) = (self.col_start[j], self.col_split[j], self.col_start[j + 1]);
        let d = self.by_col[a..b]
            .iter()
            .fold(0.0, |s, &(r, k)| s + cq[k as usize] * nu[r as usize]);
        self.by_col[b..e]
            .iter()
            .fold(d, |s, &(r, k)| s + g[k as usize] * nu[r as usize])
    }
}

/// The velocity iteration of [`Chart::correct_velocities`] with the maps `maps`, from
/// the contraction rate `rate`, to `kappa`; returns the number of updates (`None`:
/// not contracting) and the rate measured on updates above round-off.
fn velocity_iteration(
    maps: &mut Maps,
    s: Scratch<'_>,
    layout: &Layout,
    terms: VelocityTerms<'_>,
    qd: &mut [f64],
    (mut rate, kappa): (f64, f64),
    (rtol, atol): (f64, f64),
) -> (Option<usize>, Option<f64>) {
    let m = maps.rows.len();
    if m == 0 {
        return (Some(0), None);
    }
    let (vel, gathered, nu) = (&mut s.vel[..], &mut s.mu[..m], &mut s.nu[..m]);
    let dense = maps.all_rows;
    let (cq, g) = (terms.cq, terms.g);
    let mut previous: Option<f64> = None;
    let mut rate_measured = None;
    for iteration in 0..MAX_ITERATIONS {
        // The residuals J q̇ + [C_t; g] of the rows, row by row.
        layout.residuals(terms, qd, vel);
        // ν = G_a⁻¹ μ (of the rows the maps were made for).
        let mu: &[f64] = if dense {
            &vel[..m]
        } else {
            for (mu, &i) in gathered.iter_mut().zip(&maps.rows) {
                *mu = vel[i];
            }
            &*gathered
        };
        maps.inverse_gram(mu, nu);
        // ν of every row (0 for those not projected).
        let full: &[f64] = if dense {
            nu
        } else {
            vel.fill(0.0);
            for (&nu, &i) in nu.iter().zip(&maps.rows) {
                vel[i] = nu;
            }
            vel
        };
        // Δq̇ = Jᵀν column by column, and the update with its norms.
        let (mut step, mut weighted, mut size, mut nan) = (0.0_f64, 0.0_f64, 0.0_f64, false);
        for (j, xj) in qd.iter_mut().enumerate() {
            let d = layout.column(j, (cq, g), full);
            size = larger(size, xj.abs());
            *xj -= d;
            nan |= d.is_nan();
            step = larger(step, d.abs());
            weighted = larger(weighted, d.abs() / (atol + rtol * xj.abs()));
        }
        if nan || !step.is_finite() {
            return (None, rate_measured);
        }
        // The round-off of q̇ (its size before the update, as measured before).
        let floor = 8.0 * f64::EPSILON * size;
        if step <= floor {
            return (Some(iteration + 1), rate_measured);
        }
        if let Some(p) = previous {
            let measured = weighted / p;
            if measured.is_nan() || measured >= DIVERGENCE {
                return (None, rate_measured);
            }
            rate = measured;
            if step > 100.0 * floor {
                rate_measured = Some(measured);
            }
        }
        let left = rate / (1.0 - rate);
        if left * weighted <= kappa || left * step <= floor {
            return (Some(iteration + 1), rate_measured);
        }
        previous = Some(weighted);
    }
    (None, rate_measured)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanism::Symbol;

    const ROW: Symbol = Symbol { name: "c", doc: "" };

    /// The unrolled position update is the general loop's, bit for bit: the same
    /// changes, largest change and weighted change, for every size it serves and the
    /// sizes around them, with values whose order of addition shows in the last bits,
    /// and a NaN in the residuals reported as NaN.
    #[test]
    fn the_unrolled_update_is_the_loop() {
        #[allow(clippy::cast_precision_loss)]
        let value = |k: usize| (0.37 * (k * k + 1) as f64).sin() * 10f64.powi((k % 7) as i32 - 3);
        for n in 1..=12 {
            for r in [1, 3, n] {
                let map: Vec<f64> = (0..r * n).map(value).collect();
                let mut mu: Vec<f64> = (0..r).map(|k| value(k + 50) * 1e-6).collect();
                let x0: Vec<f64> = (0..n).map(|k| value(k + 90)).collect();
                let tol = (1e-8, 1e-10);
                for nan in [false, true] {
                    if nan {
                        mu[r - 1] = f64::NAN;
                    }
                    let (mut x, mut dx) = (x0.clone(), vec![0.0; n]);
                    let got = update(&map, &mu, &mut x, &mut dx, tol);
                    // The general loop.
                    let mut reference = vec![0.0; n];
                    for (row, m) in map.chunks_exact(n).zip(&mu) {
                        for (d, a) in reference.iter_mut().zip(row) {
                            *d += a * m;
                        }
                    }
                    let mut y = x0.clone();
                    let want = apply(&mut y, &reference, tol);
                    assert_eq!(got.0.to_bits(), want.0.to_bits(), "n = {n}, r = {r}");
                    assert_eq!(got.1.to_bits(), want.1.to_bits(), "n = {n}, r = {r}");
                    assert_eq!(got.0.is_nan(), nan, "n = {n}, r = {r}");
                    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(&x), bits(&y), "n = {n}, r = {r}");
                }
            }
        }
    }

    /// The layout's row and column sums are the scatter's over the patterns, bit for
    /// bit, on patterns whose entries are not sorted (rows revisited, an empty row and
    /// column, non-holonomic rows sharing columns with holonomic ones); the values are
    /// chosen so that the order of the additions shows in the last bits.
    #[test]
    fn layout_sums_are_the_scatters() {
        static HOLONOMIC: [(u32, u32); 7] =
            [(1, 2), (0, 0), (1, 0), (0, 3), (2, 4), (1, 3), (0, 2)];
        static NONHOLONOMIC: [(u32, u32); 4] = [(1, 0), (0, 4), (1, 2), (0, 0)];
        static ROWS: [Symbol; 3] = [ROW; 3];
        static NH_ROWS: [Symbol; 3] = [ROW; 3];
        let info = Info {
            holonomic: &ROWS,
            nonholonomic: &NH_ROWS[..2],
            holonomic_pattern: &HOLONOMIC,
            nonholonomic_pattern: &NONHOLONOMIC,
            ..Info::EMPTY
        };
        // n = 6 (column 5 empty), m = 5 (row 2 has one entry, rows 3-4 non-holonomic).
        let (n, m, mh) = (6, 5, 3);
        let layout = Layout::new(&info, n, m);
        #[allow(clippy::cast_precision_loss)]
        let value = |k: usize| 1.0 + (0.37 * (k * k + 1) as f64).sin() * 1e-3;
        let cq: Vec<f64> = (0..HOLONOMIC.len()).map(|k| 3.0 * value(k)).collect();
        let g: Vec<f64> = (0..NONHOLONOMIC.len())
            .map(|k| -7.0 * value(k + 9))
            .collect();
        let ct: Vec<f64> = (0..mh).map(|i| value(i + 20)).collect();
        let bias: Vec<f64> = (0..m - mh).map(|i| value(i + 30)).collect();
        let qd: Vec<f64> = (0..n).map(|j| 1e3 * value(j + 40) - 999.0).collect();
        let nu: Vec<f64> = (0..m).map(|i| value(i + 50) / 3.0).collect();
        let terms = VelocityTerms {
            cq: &cq,
            g: &g,
            ct: &ct,
            bias: &bias,
        };
        let mut vel = vec![0.0; m];
        layout.residuals(terms, &qd, &mut vel);
        let mut scatter = [ct.clone(), bias.clone()].concat();
        for (&(r, c), v) in HOLONOMIC.iter().zip(&cq) {
            scatter[r as usize] += v * qd[c as usize];
        }
        for (&(r, c), v) in NONHOLONOMIC.iter().zip(&g) {
            scatter[mh + r as usize] += v * qd[c as usize];
        }
        for (a, b) in vel.iter().zip(&scatter) {
            assert_eq!(
                a.to_bits(),
                b.to_bits(),
                "J q̇ + b: {vel:?} against {scatter:?}"
            );
        }
        let mut dx = vec![0.0; n];
        for (&(r, c), v) in HOLONOMIC.iter().zip(&cq) {
            dx[c as usize] += v * nu[r as usize];
        }
        for (&(r, c), v) in NONHOLONOMIC.iter().zip(&g) {
            dx[c as usize] += v * nu[mh + r as usize];
        }
        for (j, d) in dx.iter().enumerate() {
            let column = layout.column(j, (&cq, &g), &nu);
            assert_eq!(
                column.to_bits(),
                d.to_bits(),
                "(Jᵀν)_{j}: {column} against {d}"
            );
        }
        assert_eq!(layout.column(5, (&cq, &g), &nu), 0.0);
    }
}
