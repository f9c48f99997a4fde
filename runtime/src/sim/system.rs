//! The state-space right-hand side of each [`Formulation`], and the corrections and
//! evaluations the driver applies to accepted and output states.
//!
//! Input: a mechanism, a formulation and the analysis scratch. Output: an
//! [`OdeSystem`] on $y = [q; \dot q]$ with $\dot y = [\dot q; \ddot q]$ for every
//! formulation. They differ in what the right-hand side does with $y$:
//! - partitioning: $y$ is moved onto the manifold in the local chart of the last
//!   accepted state ([`Chart`]: Newton on the normal coordinates from the integrator's
//!   prediction, then the orthogonal projection of the velocities), so $\dot y$ depends
//!   on the chart's independent (tangential) coordinates only, and the integrator's
//!   error test sees every coordinate;
//! - projection and Baumgarte: $\ddot q$ of the index-1 system at $y$ as it is.
//!
//! Invariant: all buffers are sized in [`MechSystem::new`]; `rhs`, `reconstruct`,
//! `project`, `accelerations` and `violations` do not allocate (except when building an
//! error).

use super::chart::{Chart, ChartFailure};
use super::error::{SimErrorKind, SingularMatrix};
use super::Formulation;
use crate::dynamics::{Dynamics, DynamicsParams};
use crate::kinematics::{Kinematics, KinematicsParams};
use crate::linalg::dense::{gram_factor, DenseLu};
use crate::linalg::inf_norm;
use crate::ode::{OdeSystem, RhsError};
use crate::scale;
use crate::workspace::{EvalError, Workspace};
use crate::{Error, Info, Mechanism};

/// Pivot ratio below which a projection matrix counts as singular.
const SINGULAR_RATIO: f64 = super::chart::SINGULAR_RATIO;

/// Pivot ratio of the projection matrix (equilibrated $J_R J_R^\mathsf{T}$) below which
/// the kept rows of a model with redundant constraints are renewed (see
/// [`MechSystem::refit`]): a ratio of $10^{-8}$ is a condition of $10^4$ for $J_R$,
/// where Newton starts to stall long before the matrix is singular.
const REFIT_RATIO: f64 = 1e-8;

/// Fraction of its value when the rows were chosen below which the pivot ratio of the
/// chart's $N N^\mathsf{T}$ renews the kept rows of a model with redundant constraints:
/// the kept rows are turning dependent while the dropped ones could take over.
const REFIT_FRACTION: f64 = 1e-2;

/// Recoverable failures in a row (since the last accepted step) before a failure stops
/// the integrator: with the integrators' cut of 4 per failure the step has then shrunk
/// by $4^{10} \approx 10^6$.
const MAX_RETRIES: u32 = 10;

/// Relative size of a Newton correction of the integrator's prediction that never
/// counts as a branch switch (see [`MechSystem::rhs`]), for the evaluations that hardly
/// move (a correction within the integrator's tolerance never counts either).
const BRANCH_FLOOR: f64 = 1e-8;

pub(crate) struct MechSystem<'a, M: Mechanism + ?Sized> {
    pub mech: &'a M,
    pub info: &'static Info,
    pub form: Formulation,
    pub ws: Workspace,
    pub kin: Kinematics,
    pub dynamics: Dynamics,
    /// Current full coordinates.
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub lambda: Vec<f64>,
    shift: Vec<f64>,
    vel: Vec<f64>,
    mu: Vec<f64>,
    lu_h: DenseLu,
    lu_v: DenseLu,
    /// Partitioning: the chart of the last accepted state.
    chart: Chart,
    pub newton_iterations: u64,
    pub factorizations: u64,
    /// Holonomic constraints not met when the last analysis failed.
    pub failure_constraints: Vec<&'static str>,
    /// Constraints the augmented solve found redundant so far.
    pub redundant: Vec<&'static str>,
    /// The constraint rows projected on, the first `rows_h` holonomic (all rows unless
    /// Algorithm P dropped redundant ones, see [`Self::fit_rows`]).
    rows: Vec<usize>,
    rows_h: usize,
    /// Partitioning: the last accepted full state (the reference of the branch check).
    q_acc: Vec<f64>,
    /// Recoverable failures since the last accepted step.
    retries: u32,
    /// Partitioning: the `(t, y)` whose corrected state is in `q`, `qd` (the last
    /// [`reconstruct`](Self::reconstruct)), so that the driver's reconstruction of an
    /// accepted state the integrator has just evaluated costs nothing.
    cached: Option<f64>,
    y_cached: Vec<f64>,
    /// Pivot ratio of the chart's $N N^\mathsf{T}$ when its rows were last chosen (0
    /// before the first anchor): the reference of [`REFIT_FRACTION`].
    fit_ratio: f64,
}

impl<M: Mechanism + ?Sized> std::fmt::Debug for MechSystem<'_, M> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MechSystem")
            .field("model", &self.info.name)
            .field("form", &self.form)
            .finish_non_exhaustive()
    }
}

impl<'a, M: Mechanism + ?Sized> MechSystem<'a, M> {
    pub fn new(
        mech: &'a M,
        form: Formulation,
        kin: KinematicsParams,
        dynamics: DynamicsParams,
        (rtol, atol): (f64, f64),
    ) -> Result<Self, Error> {
        let info = mech.info();
        let (n, mh, m) = (info.nq(), info.nh(), info.nh() + info.nnh());
        let projection = !matches!(form, Formulation::Baumgarte { .. });
        Ok(Self {
            mech,
            info,
            form,
            ws: Workspace::new(info)?,
            kin: Kinematics::new(info, kin),
            dynamics: Dynamics::new(info, dynamics)?,
            q: vec![0.0; n],
            qd: vec![0.0; n],
            qdd: vec![0.0; n],
            lambda: vec![0.0; m],
            shift: vec![0.0; m],
            vel: vec![0.0; m],
            mu: vec![0.0; m],
            lu_h: DenseLu::new(if projection { mh } else { 0 }, 1),
            lu_v: DenseLu::new(if projection { m } else { 0 }, 1),
            chart: Chart::new(n, m, mh, rtol, atol),
            newton_iterations: 0,
            factorizations: 0,
            failure_constraints: Vec::new(),
            redundant: Vec::new(),
            rows: (0..m).collect(),
            rows_h: mh,
            q_acc: vec![0.0; n],
            retries: 0,
            cached: None,
            y_cached: vec![0.0; 2 * n],
            fit_ratio: 0.0,
        })
    }

    /// Fits the projected rows (partitioning and projection) to the partition of the
    /// assembly, which may have dropped redundant holonomic constraints; returns the
    /// names of the dropped ones.
    pub fn fit_rows(&mut self) -> Vec<&'static str> {
        let Some(p) = self.kin.partition() else {
            return Vec::new();
        };
        let info = self.info;
        let (mh, nnh) = (info.nh(), info.nnh());
        let names = p
            .redundant_rows()
            .iter()
            .map(|&i| info.holonomic[i].name)
            .collect();
        let r = p.holonomic_rows().len();
        if !matches!(self.form, Formulation::Baumgarte { .. }) {
            self.rows.clear();
            self.rows.extend_from_slice(p.holonomic_rows());
            self.rows.extend(mh..mh + nnh);
            self.rows_h = r;
            if r != mh {
                self.lu_h = DenseLu::new(r, 1);
                self.lu_v = DenseLu::new(r + nnh, 1);
                self.chart.resize(r);
            }
        }
        names
    }

    /// Partitioning: takes the current full state (consistent, at `t`) as the last
    /// accepted one: the anchor of the chart of the next step and the reference of the
    /// branch check.
    pub fn accept(&mut self, t: f64) -> Result<(), SimErrorKind> {
        if self.form != Formulation::Partitioning {
            return Ok(());
        }
        self.retries = 0;
        self.q_acc.copy_from_slice(&self.q);
        if self.rows_h == 0 {
            return Ok(());
        }
        self.ws
            .eval_jacobian(self.mech, t, &self.q)
            .map_err(SimErrorKind::from_eval)?;
        self.factorizations += 1;
        let mut ratio = self
            .chart
            .anchor(&self.ws, &self.q, &self.rows[..self.rows_h]);
        let worse =
            ratio.is_nan() || ratio <= REFIT_RATIO || ratio < REFIT_FRACTION * self.fit_ratio;
        if worse && self.refit(t) {
            self.ws
                .eval_jacobian(self.mech, t, &self.q)
                .map_err(SimErrorKind::from_eval)?;
            ratio = self
                .chart
                .anchor(&self.ws, &self.q, &self.rows[..self.rows_h]);
            self.fit_ratio = ratio;
        }
        if self.fit_ratio == 0.0 {
            self.fit_ratio = ratio;
        }
        if ratio.is_nan() || ratio <= SINGULAR_RATIO {
            return Err(SimErrorKind::Singular {
                t,
                matrix: SingularMatrix::Projection,
                ratio,
                constraints: Vec::new(),
            });
        }
        Ok(())
    }

    /// Writes the state vector of the current full state `q`, `qd` into `y`.
    pub fn gather(&self, y: &mut [f64]) {
        let n = self.q.len();
        y[..n].copy_from_slice(&self.q);
        y[n..].copy_from_slice(&self.qd);
    }

    /// Fills the full `q`, `qd` from the state `y` at `t`: for partitioning, the point
    /// of the manifold the current chart assigns to `y`, to the integrator's tolerance
    /// (see [`Chart`]).
    pub fn reconstruct(&mut self, t: f64, y: &[f64]) -> Result<(), SimErrorKind> {
        let n = self.q.len();
        if self.form != Formulation::Partitioning {
            self.q.copy_from_slice(&y[..n]);
            self.qd.copy_from_slice(&y[n..]);
            return Ok(());
        }
        if self.cached == Some(t) && self.y_cached == y {
            return Ok(());
        }
        self.cached = None;
        self.q.copy_from_slice(&y[..n]);
        self.qd.copy_from_slice(&y[n..]);
        if self.rows_h > 0 {
            let rows = &self.rows[..self.rows_h];
            match self
                .chart
                .correct(self.mech, &mut self.ws, t, &mut self.q, rows)
            {
                Ok(iterations) => self.newton_iterations += iterations as u64,
                Err(ChartFailure::Eval(e)) => return Err(SimErrorKind::from_eval(e)),
                Err(ChartFailure::Newton {
                    iterations,
                    residual,
                }) => {
                    self.newton_iterations += iterations as u64;
                    let tol = self.kin.params().newton.tolerance;
                    return Err(SimErrorKind::NewtonFailed {
                        t,
                        iterations,
                        residual,
                        constraints: self.violated(tol),
                    });
                }
            }
            // A correction larger than the move from the last accepted state: Newton
            // went to another intersection of the normal space with the manifold.
            let (mut moved, mut correction) = (0.0_f64, 0.0_f64);
            for ((&yj, &qj), &aj) in y.iter().zip(&self.q).zip(&self.q_acc) {
                moved = moved.max((yj - aj).abs());
                correction = correction.max((qj - yj).abs());
            }
            let scale = inf_norm(&self.q);
            let floor = BRANCH_FLOOR * scale + self.chart.tolerance(scale);
            if correction > moved + floor {
                return Err(SimErrorKind::NewtonFailed {
                    t,
                    iterations: 0,
                    residual: correction,
                    constraints: Vec::new(),
                });
            }
        }
        self.project_velocities(t)?;
        self.cached = Some(t);
        self.y_cached.copy_from_slice(y);
        Ok(())
    }

    /// [`reconstruct`](Self::reconstruct) for a state the driver keeps (accepted or
    /// output): for partitioning, the point of the chart (when the integrator has just
    /// evaluated there, otherwise `y`) polished by [`project`](Self::project), so that
    /// the constraints hold to the simulation's Newton tolerance (the polish is below
    /// the integrator's tolerance, the derivatives the integrator keeps stay valid).
    pub fn reconstruct_exact(&mut self, t: f64, y: &[f64]) -> Result<(), SimErrorKind> {
        if self.form != Formulation::Partitioning {
            return self.reconstruct(t, y);
        }
        if self.cached != Some(t) || self.y_cached != y {
            let n = self.q.len();
            self.q.copy_from_slice(&y[..n]);
            self.qd.copy_from_slice(&y[n..]);
        }
        self.cached = None;
        self.project(t)
    }

    /// $\ddot q$ and $\lambda$ at the full state (with the stabilization term for
    /// Baumgarte).
    pub fn accelerations(&mut self, t: f64) -> Result<(), SimErrorKind> {
        let shift = if let Formulation::Baumgarte { alpha, beta } = self.form {
            self.velocity_terms(t).map_err(SimErrorKind::from_eval)?;
            let mh = self.info.nh();
            let c = self.ws.constraints();
            for (i, s) in self.shift.iter_mut().enumerate() {
                let position = if i < mh { beta * beta * c[i] } else { 0.0 };
                *s = -2.0 * alpha * self.vel[i] - position;
            }
            Some(&self.shift[..])
        } else {
            None
        };
        self.factorizations += 1;
        self.dynamics
            .accelerations_shifted(
                self.mech,
                &mut self.ws,
                t,
                &self.q,
                &self.qd,
                shift,
                &mut self.qdd,
                &mut self.lambda,
            )
            .map_err(|e| SimErrorKind::from_analysis(e.into(), Vec::new()))?;
        // Reported once, as first identified: which rows of a dependent set the
        // pivoting names can change along the motion, the redundancy does not.
        if self.redundant.is_empty() {
            self.redundant.extend(self.dynamics.redundant_constraints());
        }
        Ok(())
    }

    /// Evaluates $C$ (in the workspace) and the velocity-level residuals
    /// $[C_q\dot q + C_t;\ G\dot q + g]$ (in `vel`) at the full state.
    fn velocity_terms(&mut self, t: f64) -> Result<(), EvalError> {
        let info = self.info;
        let mh = info.nh();
        self.ws.eval_constraints(self.mech, t, &self.q)?;
        self.ws.eval_jacobian_values(self.mech, t, &self.q)?;
        self.ws.eval_rates(self.mech, t, &self.q)?;
        self.vel[..mh].copy_from_slice(&self.ws.ct);
        self.vel[mh..].copy_from_slice(&self.ws.bias);
        for (&(r, c), v) in info.holonomic_pattern.iter().zip(&self.ws.cq_values) {
            self.vel[r as usize] += v * self.qd[c as usize];
        }
        for (&(r, c), v) in info.nonholonomic_pattern.iter().zip(&self.ws.g_values) {
            self.vel[mh + r as usize] += v * self.qd[c as usize];
        }
        Ok(())
    }

    /// $(\lVert C\rVert_\infty, \lVert C_q\dot q + C_t\rVert_\infty,
    /// \lVert G\dot q + g\rVert_\infty)$ at the full state.
    pub fn violations(&mut self, t: f64) -> Result<(f64, f64, f64), EvalError> {
        self.velocity_terms(t)?;
        let mh = self.info.nh();
        Ok((
            inf_norm(self.ws.constraints()),
            inf_norm(&self.vel[..mh]),
            inf_norm(&self.vel[mh..]),
        ))
    }

    /// Projection onto the constraint manifold: Newton with minimum-norm corrections
    /// $\Delta q = -C_q^\mathsf{T}(C_q C_q^\mathsf{T})^{-1}C$ on the positions, then
    /// $\dot q \leftarrow \dot q - J^\mathsf{T}(J J^\mathsf{T})^{-1}(J\dot q + [C_t; g])$.
    pub fn project(&mut self, t: f64) -> Result<(), SimErrorKind> {
        let info = self.info;
        let (n, mh) = (info.nq(), info.nh());
        let newton = self.kin.params().newton;
        let eval = |e: EvalError| SimErrorKind::from_eval(e);
        // One renewal of the dropped redundant rows per projection (see `refit`).
        let mut refitted = false;
        if mh > 0 {
            let mut iterations = 0;
            loop {
                self.ws
                    .eval_constraints(self.mech, t, &self.q)
                    .map_err(eval)?;
                let residual = inf_norm(self.ws.constraints());
                self.ws.eval_jacobian(self.mech, t, &self.q).map_err(eval)?;
                let tol = newton.tolerance;
                let size = scale::coordinate_size(&self.q);
                if scale::all_met(self.ws.constraints(), self.ws.jacobian(), n, tol, size) {
                    break;
                }
                let stalled = iterations == newton.max_iterations || !residual.is_finite();
                if stalled && !refitted && self.refit(t) {
                    (refitted, iterations) = (true, 0);
                    continue;
                }
                if stalled {
                    return Err(SimErrorKind::NewtonFailed {
                        t,
                        iterations,
                        residual,
                        constraints: self.violated(tol),
                    });
                }
                let ratio = gram_factor(
                    &mut self.lu_h,
                    &self.ws.jacobian,
                    &self.rows[..self.rows_h],
                    n,
                );
                if (ratio.is_nan() || ratio <= REFIT_RATIO) && !refitted && self.refit(t) {
                    refitted = true;
                    continue;
                }
                let rows = &self.rows[..self.rows_h];
                if ratio.is_nan() || ratio <= SINGULAR_RATIO {
                    return Err(SimErrorKind::Singular {
                        t,
                        matrix: SingularMatrix::Projection,
                        ratio,
                        constraints: self.violated(tol),
                    });
                }
                for (mu, &i) in self.mu.iter_mut().zip(rows) {
                    *mu = self.ws.constraints()[i];
                }
                self.lu_h.solve_vec(&mut self.mu[..rows.len()]);
                for (&i, mu) in rows.iter().zip(&self.mu) {
                    let row = &self.ws.jacobian[i * n..(i + 1) * n];
                    for (qj, a) in self.q.iter_mut().zip(row) {
                        *qj -= a * mu;
                    }
                }
                iterations += 1;
                self.newton_iterations += 1;
                self.factorizations += 1;
            }
        }
        self.project_velocities(t)
    }

    /// The orthogonal projection of the velocities onto the velocity constraints at
    /// the current positions,
    /// $\dot q \leftarrow \dot q - J^\mathsf{T}(J J^\mathsf{T})^{-1}(J\dot q + [C_t; g])$
    /// (the rows `rows`).
    fn project_velocities(&mut self, t: f64) -> Result<(), SimErrorKind> {
        let n = self.info.nq();
        if self.rows.is_empty() {
            return Ok(());
        }
        let eval = SimErrorKind::from_eval;
        self.velocity_terms(t).map_err(eval)?;
        self.ws.eval_jacobian(self.mech, t, &self.q).map_err(eval)?;
        let mut ratio = gram_factor(&mut self.lu_v, &self.ws.jacobian, &self.rows, n);
        if (ratio.is_nan() || ratio <= REFIT_RATIO) && self.refit(t) {
            self.ws.eval_jacobian(self.mech, t, &self.q).map_err(eval)?;
            ratio = gram_factor(&mut self.lu_v, &self.ws.jacobian, &self.rows, n);
        }
        let rows = &self.rows[..];
        self.factorizations += 1;
        if ratio.is_nan() || ratio <= SINGULAR_RATIO {
            return Err(SimErrorKind::Singular {
                t,
                matrix: SingularMatrix::Projection,
                ratio,
                constraints: Vec::new(),
            });
        }
        for (mu, &i) in self.mu.iter_mut().zip(rows) {
            *mu = self.vel[i];
        }
        self.lu_v.solve_vec(&mut self.mu[..rows.len()]);
        for (&i, mu) in rows.iter().zip(&self.mu) {
            let row = &self.ws.jacobian[i * n..(i + 1) * n];
            for (v, a) in self.qd.iter_mut().zip(row) {
                *v -= a * mu;
            }
        }
        Ok(())
    }

    /// Renews the redundant holonomic rows left out of the projections and the chart,
    /// when there are any: which rows of a dependent set are independent changes along
    /// the motion (the three pin_y rows of the parallelogram become dependent at the
    /// bottom of its swing, and a set that dropped a pin_x row turns singular there).
    /// Returns whether the rows were renewed (the rank of $C_q$ unchanged).
    fn refit(&mut self, t: f64) -> bool {
        let redundant = self
            .kin
            .partition()
            .is_some_and(|p| !p.redundant_rows().is_empty());
        if !redundant {
            return false;
        }
        let rank = self.rows_h;
        let ok = self
            .kin
            .repartition(self.mech, &mut self.ws, t, &self.q)
            .is_ok_and(|p| p.holonomic_rows().len() == rank);
        if ok {
            self.fit_rows();
        }
        ok
    }

    /// The holonomic constraints not met to the relative `tolerance` at the last
    /// evaluation of $C$ and $C_q$ (see [`crate::scale`]).
    fn violated(&self, tolerance: f64) -> Vec<&'static str> {
        let size = scale::coordinate_size(&self.q);
        let n = self.info.nq();
        scale::unmet(
            self.ws.constraints(),
            self.ws.jacobian(),
            n,
            tolerance,
            size,
        )
        .map(|i| self.info.holonomic[i].name)
        .collect()
    }
}

impl<M: Mechanism + ?Sized> OdeSystem for MechSystem<'_, M> {
    fn dim(&self) -> usize {
        2 * self.info.nq()
    }

    /// Partitioning: a failure of the chart's Newton iteration (it diverged, or jumped
    /// to another intersection of the normal space with the manifold: a correction
    /// larger than the move from the last accepted state, since along the motion the
    /// prediction errs by the local error only) or a singular projection comes from a
    /// step too long for the chart, so it is [recoverable](RhsError::recoverable): the
    /// integrator retries a shorter step. After [`MAX_RETRIES`] such failures in a row
    /// the failure ends the run.
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let n = self.q.len();
        let r = self.reconstruct(t, y).and_then(|()| self.accelerations(t));
        match r {
            Ok(()) => {
                dy[..n].copy_from_slice(&self.qd);
                dy[n..].copy_from_slice(&self.qdd);
                Ok(())
            }
            Err(e @ (SimErrorKind::NewtonFailed { .. } | SimErrorKind::Singular { .. }))
                if self.form == Formulation::Partitioning =>
            {
                self.cached = None;
                self.retries += 1;
                if self.retries <= MAX_RETRIES {
                    Err(RhsError::recoverable(e))
                } else {
                    Err(RhsError::new(e))
                }
            }
            Err(e) => {
                self.cached = None;
                Err(RhsError::new(e))
            }
        }
    }
}
