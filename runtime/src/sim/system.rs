//! The state-space right-hand side of each [`Formulation`], and the corrections and
//! evaluations the driver applies to accepted and output states.
//!
//! Input: a mechanism, a formulation and the analysis scratch. Output: an
//! [`OdeSystem`] on
//! - partitioning: $y = [p; \dot\gamma]$, $p = [\eta; \gamma]$, $\dot y = [\dot\eta;
//!   \dot\gamma; \ddot\gamma]$ (Algorithm D; a mechanism without degrees of freedom gets
//!   one inert component so that the integrators have a state);
//! - projection and Baumgarte: $y = [q; \dot q]$, $\dot y = [\dot q; \ddot q]$.
//!
//! Invariant: all buffers are sized in [`MechSystem::new`]; `rhs`, `reconstruct`,
//! `project`, `accelerations` and `violations` do not allocate (except when building an
//! error).

use super::error::{SimErrorKind, SingularMatrix};
use super::Formulation;
use crate::dynamics::{Dynamics, DynamicsParams};
use crate::kinematics::{Kinematics, KinematicsError, KinematicsParams};
use crate::linalg::dense::DenseLu;
use crate::linalg::inf_norm;
use crate::ode::{OdeSystem, RhsError};
use crate::scale;
use crate::workspace::{EvalError, Workspace};
use crate::{Error, Info, Mechanism};

/// Pivot ratio below which the projection matrix counts as singular.
const SINGULAR_RATIO: f64 = 1e-14;

/// Pivot ratio of the projection matrix (equilibrated $J_R J_R^\mathsf{T}$) below which
/// the kept rows of a model with redundant constraints are renewed: a ratio of
/// $10^{-8}$ is a condition of $10^4$ for $J_R$, where the Newton projection starts to
/// stall long before the matrix is singular.
const REFIT_RATIO: f64 = 1e-8;

/// Recoverable kinematic failures in a row (since the last accepted step) before a
/// failure stops the integrator: with the integrators' cut of 4 per failure the step
/// has then shrunk by $4^{10} \approx 10^6$, and the driver's re-partition is the
/// better cure.
const MAX_RETRIES: u32 = 10;

/// Relative size of a Newton correction of the K1 guess that never counts as a branch
/// switch (see [`MechSystem::rhs`]), for the evaluations that hardly move.
const BRANCH_FLOOR: f64 = 1e-8;

pub(crate) struct MechSystem<'a, M: Mechanism + ?Sized> {
    pub mech: &'a M,
    pub info: &'static Info,
    pub form: Formulation,
    pub ws: Workspace,
    pub kin: Kinematics,
    pub dynamics: Dynamics,
    /// Current full coordinates (also the Newton guess of the next K1).
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub lambda: Vec<f64>,
    shift: Vec<f64>,
    vel: Vec<f64>,
    mu: Vec<f64>,
    lu_h: DenseLu,
    lu_v: DenseLu,
    /// Partitioning: $[\eta; \gamma]$ and $\gamma$.
    coords: Vec<usize>,
    gamma: Vec<usize>,
    dim: usize,
    /// Time of the full state in `q`, `qd` (the base of the next K1 guess).
    pub t_state: f64,
    pub newton_iterations: u64,
    pub factorizations: u64,
    /// Holonomic constraints not met when the last analysis failed.
    pub failure_constraints: Vec<&'static str>,
    /// Constraints the augmented solve found redundant so far.
    pub redundant: Vec<&'static str>,
    /// Projection: the constraint rows projected on, the first `rows_h` holonomic
    /// (all rows unless Algorithm P dropped redundant ones, see [`Self::fit_rows`]).
    rows: Vec<usize>,
    rows_h: usize,
    /// Partitioning: the last accepted full state, its time and the sign of
    /// $\det J_d$ there (the reference of the branch check).
    q_acc: Vec<f64>,
    qd_acc: Vec<f64>,
    t_acc: f64,
    sign_acc: f64,
    /// Recoverable failures since the last accepted step.
    retries: u32,
    /// Whether `q_acc`, `qd_acc` hold an accepted state.
    anchored: bool,
    /// A re-partition found another rank of $C_q$ than the first partition.
    pub rank_changed: bool,
    /// Partitioning, the last K1: its guess, the largest move of a coordinate from the
    /// base state to the guess, and the largest Newton correction of the guess.
    guess: Vec<f64>,
    moved: f64,
    correction: f64,
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
    ) -> Result<Self, Error> {
        let info = mech.info();
        let (n, mh, m) = (info.nq(), info.nh(), info.nh() + info.nnh());
        let dim = match form {
            Formulation::Partitioning => (2 * (n - mh) - info.nnh()).max(1),
            _ => 2 * n,
        };
        let projection = matches!(form, Formulation::Projection);
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
            coords: Vec::with_capacity(n),
            gamma: Vec::with_capacity(n),
            dim,
            t_state: 0.0,
            newton_iterations: 0,
            factorizations: 0,
            failure_constraints: Vec::new(),
            redundant: Vec::new(),
            rows: (0..m).collect(),
            rows_h: mh,
            q_acc: vec![0.0; n],
            qd_acc: vec![0.0; n],
            t_acc: 0.0,
            sign_acc: 0.0,
            retries: 0,
            anchored: false,
            rank_changed: false,
            guess: vec![0.0; n],
            moved: 0.0,
            correction: 0.0,
        })
    }

    /// Fits the state dimension (partitioning) or the projected rows (projection) to
    /// the partition of the assembly, which may have dropped redundant holonomic
    /// constraints; returns the names of the dropped ones.
    pub fn fit_rows(&mut self) -> Vec<&'static str> {
        let Some(p) = self.kin.partition() else {
            return Vec::new();
        };
        let info = self.info;
        let (n, mh, nnh) = (info.nq(), info.nh(), info.nnh());
        let names = p
            .redundant_rows()
            .iter()
            .map(|&i| info.holonomic[i].name)
            .collect();
        let r = p.holonomic_rows().len();
        match self.form {
            Formulation::Partitioning => self.dim = (2 * (n - r) - nnh).max(1),
            Formulation::Projection => {
                self.rows.clear();
                self.rows.extend_from_slice(p.holonomic_rows());
                self.rows.extend(mh..mh + nnh);
                self.rows_h = r;
                if r != mh {
                    self.lu_h = DenseLu::new(r, 1);
                    self.lu_v = DenseLu::new(r + nnh, 1);
                }
            }
            Formulation::Baumgarte { .. } => {}
        }
        names
    }

    /// Copies the index sets of the current partition (no allocation: the capacity is
    /// `n`); returns whether they changed.
    pub fn update_indices(&mut self) -> bool {
        let p = self
            .kin
            .partition()
            .expect("partitioning keeps a partition");
        let (eta, ind) = (p.dependent_velocity(), p.independent());
        if !self.coords.is_empty() && self.coords.len() != eta.len() + ind.len() {
            // The rank of C_q changed (a redundant row became independent or the
            // reverse): the state would change dimension. The driver reports it.
            self.rank_changed = true;
            return false;
        }
        let same = self.coords.len() == eta.len() + ind.len()
            && self.coords[..eta.len()] == *eta
            && self.coords[eta.len()..] == *ind;
        if same {
            return false;
        }
        self.coords.clear();
        self.coords.extend_from_slice(p.dependent_velocity());
        self.coords.extend_from_slice(p.independent());
        self.gamma.clear();
        self.gamma.extend_from_slice(p.independent());
        true
    }

    /// Partitioning: takes the current full state (consistent, at `t`) as the last
    /// accepted one: the reference of the branch check and the state an evaluation
    /// that failed recoverably falls back to. Runs K2 for the sign of $\det J_d$ under
    /// the current partition (so call it again after a re-partition).
    pub fn accept(&mut self, t: f64) -> Result<(), Error> {
        if self.form != Formulation::Partitioning {
            return Ok(());
        }
        self.factorizations += 1;
        self.kin
            .velocity(self.mech, &mut self.ws, t, &self.q, &mut self.qd)?;
        self.q_acc.copy_from_slice(&self.q);
        self.qd_acc.copy_from_slice(&self.qd);
        self.t_acc = t;
        self.t_state = t;
        self.sign_acc = self.kin.dependent_sign();
        self.retries = 0;
        self.anchored = true;
        Ok(())
    }

    /// Writes the state vector of the current full state `q`, `qd` into `y`.
    pub fn gather(&self, y: &mut [f64]) {
        match self.form {
            Formulation::Partitioning => {
                y.fill(0.0);
                let np = self.coords.len();
                for (k, &j) in self.coords.iter().enumerate() {
                    y[k] = self.q[j];
                }
                for (k, &j) in self.gamma.iter().enumerate() {
                    y[np + k] = self.qd[j];
                }
            }
            _ => {
                let n = self.q.len();
                y[..n].copy_from_slice(&self.q);
                y[n..].copy_from_slice(&self.qd);
            }
        }
    }

    /// Fills the full `q`, `qd` from the state `y` at `t` (K1 and K2 for partitioning).
    pub fn reconstruct(&mut self, t: f64, y: &[f64]) -> Result<(), Error> {
        match self.form {
            Formulation::Partitioning => {
                let np = self.coords.len();
                // The base of the guess is the last accepted state (once there is one):
                // a state of the motion, so that the predictor errs by O(dt²) and the
                // branch check of `rhs` can compare the correction with the move.
                // Chaining from the last evaluation (a stage of a trial step, maybe a
                // rejected one) gives errors of the order of the move itself.
                if self.anchored {
                    self.q.copy_from_slice(&self.q_acc);
                    self.qd.copy_from_slice(&self.qd_acc);
                    self.t_state = self.t_acc;
                }
                let mut moved = 0.0_f64;
                for (k, &j) in self.coords.iter().enumerate() {
                    moved = moved.max((y[k] - self.q[j]).abs());
                    self.q[j] = y[k];
                }
                // First-order predictor for the guess of β: the base's β moved along
                // its velocity. Without it, fast mechanisms (Andrews) and long steps
                // let Newton converge to another assembly branch.
                let dt = t - self.t_state;
                if let Some(p) = self.kin.partition() {
                    for &j in p.dependent() {
                        self.q[j] += self.qd[j] * dt;
                        moved = moved.max((self.qd[j] * dt).abs());
                    }
                }
                self.guess.copy_from_slice(&self.q);
                let r = self.kin.position(self.mech, &mut self.ws, t, &mut self.q);
                self.correction = self.kin.partition().map_or(0.0, |p| {
                    p.dependent()
                        .iter()
                        .fold(0.0_f64, |a, &j| a.max((self.q[j] - self.guess[j]).abs()))
                });
                self.moved = moved;
                let iterations = self.kin.residual_history().len().saturating_sub(1) as u64;
                self.newton_iterations += iterations;
                self.factorizations += iterations;
                if let Err(e) = r {
                    self.note_failure(&e);
                    return Err(e.into());
                }
                for (k, &j) in self.gamma.iter().enumerate() {
                    self.qd[j] = y[np + k];
                }
                self.factorizations += 1;
                if let Err(e) = self
                    .kin
                    .velocity(self.mech, &mut self.ws, t, &self.q, &mut self.qd)
                {
                    self.note_failure(&e);
                    return Err(e.into());
                }
                self.t_state = t;
            }
            _ => {
                let n = self.q.len();
                self.q.copy_from_slice(&y[..n]);
                self.qd.copy_from_slice(&y[n..]);
            }
        }
        Ok(())
    }

    /// Records the holonomic constraints not met by the last iterate of a failed K1.
    fn note_failure(&mut self, e: &KinematicsError) {
        if let KinematicsError::SingularDependent { .. }
        | KinematicsError::SingularVelocity { .. } = e
        {
            let tol = self.kin.params().newton.tolerance;
            self.failure_constraints = self.violated(tol);
        }
    }

    /// $\ddot q$ and $\lambda$ at the full state (with the stabilization term for
    /// Baumgarte).
    pub fn accelerations(&mut self, t: f64) -> Result<(), Error> {
        let shift = if let Formulation::Baumgarte { alpha, beta } = self.form {
            self.velocity_terms(t)?;
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
        self.dynamics.accelerations_shifted(
            self.mech,
            &mut self.ws,
            t,
            &self.q,
            &self.qd,
            shift,
            &mut self.qdd,
            &mut self.lambda,
        )?;
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
        let (n, mh, m) = (info.nq(), info.nh(), info.nh() + info.nnh());
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
                if scale::all_met(self.ws.constraints(), &self.ws.jacobian, n, tol, size) {
                    break;
                }
                if (iterations == newton.max_iterations || !residual.is_finite())
                    && !refitted
                    && self.refit(t)
                {
                    refitted = true;
                    iterations = 0;
                    continue;
                }
                if iterations == newton.max_iterations || !residual.is_finite() {
                    return Err(SimErrorKind::NewtonFailed {
                        t,
                        iterations,
                        residual,
                        constraints: self.violated(tol),
                    });
                }
                let ratio = gram(
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
        if m > 0 {
            self.velocity_terms(t).map_err(eval)?;
            self.ws.eval_jacobian(self.mech, t, &self.q).map_err(eval)?;
            let mut ratio = gram(&mut self.lu_v, &self.ws.jacobian, &self.rows, n);
            if (ratio.is_nan() || ratio <= REFIT_RATIO) && !refitted && self.refit(t) {
                self.ws.eval_jacobian(self.mech, t, &self.q).map_err(eval)?;
                ratio = gram(&mut self.lu_v, &self.ws.jacobian, &self.rows, n);
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
        }
        Ok(())
    }

    /// Renews the redundant holonomic rows left out of the projection, when there are
    /// any: which rows of a dependent set are independent changes along the motion (the
    /// three pin_y rows of the parallelogram become dependent at the bottom of its
    /// swing). Returns whether the rows were renewed.
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

    fn rhs_inner(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Error> {
        self.reconstruct(t, y)?;
        self.rhs_inner_full(t, dy)
    }

    /// $\dot y$ from the full state already reconstructed at `t`.
    fn rhs_inner_full(&mut self, t: f64, dy: &mut [f64]) -> Result<(), Error> {
        self.accelerations(t)?;
        match self.form {
            Formulation::Partitioning => {
                dy.fill(0.0);
                let np = self.coords.len();
                for (k, &j) in self.coords.iter().enumerate() {
                    dy[k] = self.qd[j];
                }
                for (k, &j) in self.gamma.iter().enumerate() {
                    dy[np + k] = self.qdd[j];
                }
            }
            _ => {
                let n = self.q.len();
                dy[..n].copy_from_slice(&self.qd);
                dy[n..].copy_from_slice(&self.qdd);
            }
        }
        Ok(())
    }
}

/// Writes $A_R A_R^\mathsf{T}$ of the rows `rows` of the dense row-major `a` (`· × n`)
/// into `lu`, factors it and returns the pivot ratio.
fn gram(lu: &mut DenseLu, a: &[f64], rows: &[usize], n: usize) -> f64 {
    {
        let mut g = lu.matrix_mut();
        for (i, &ri) in rows.iter().enumerate() {
            let ri = &a[ri * n..(ri + 1) * n];
            for (k, &rk) in rows[..=i].iter().enumerate() {
                let rk = &a[rk * n..(rk + 1) * n];
                let v: f64 = ri.iter().zip(rk).map(|(x, y)| x * y).sum();
                g[(i, k)] = v;
                g[(k, i)] = v;
            }
        }
    }
    lu.factor().ratio()
}

impl<M: Mechanism + ?Sized> OdeSystem for MechSystem<'_, M> {
    fn dim(&self) -> usize {
        self.dim
    }

    /// Partitioning: a kinematic failure of K1 or K2 (Newton diverged, a singular
    /// dependent block, or a jump to another solution branch) comes from a guess
    /// extrapolated too far, so it is [recoverable](RhsError::recoverable).
    ///
    /// K1 has jumped branches when
    /// - the sign of $\det J_d$ differs from the last accepted state's (the mirror
    ///   assembly, see [`Kinematics::dependent_sign`]), or
    /// - Newton corrected the guess by more than the largest move of a coordinate
    ///   from the base state to the guess (plus [`BRANCH_FLOOR`]): along the motion
    ///   the first-order predictor moves by $O(h)$ and errs by $O(h^2)$, so a larger
    ///   correction means the step is outside the predictor's range, as when an angle
    ///   lands on another turn ($\beta + 2\pi k$: same sign, same configuration, a
    ///   discontinuous state).
    ///
    /// The integrator then retries a shorter step
    /// from the last accepted state, which also becomes the base of the next guess.
    /// After [`MAX_RETRIES`] such failures in a row the failure stops the integrator
    /// and the driver re-partitions.
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        if self.form != Formulation::Partitioning {
            return self.rhs_inner(t, y, dy).map_err(RhsError::new);
        }
        let r = self.reconstruct(t, y).and_then(|()| {
            let sign = self.kin.dependent_sign();
            let floor = BRANCH_FLOOR * scale::coordinate_size(&self.q);
            if (self.sign_acc != 0.0 && sign != self.sign_acc)
                || self.correction > self.moved + floor
            {
                let history = self.kin.residual_history();
                return Err(Error::Kinematics(KinematicsError::BranchSwitch {
                    t,
                    iterations: history.len().saturating_sub(1),
                    residual: history.last().copied().unwrap_or(0.0),
                }));
            }
            Ok(())
        });
        let r = r.and_then(|()| self.rhs_inner_full(t, dy));
        match r {
            Ok(()) => Ok(()),
            Err(
                e @ Error::Kinematics(
                    KinematicsError::NewtonFailed { .. }
                    | KinematicsError::BranchSwitch { .. }
                    | KinematicsError::SingularDependent { .. }
                    | KinematicsError::SingularVelocity { .. },
                ),
            ) => {
                self.q.copy_from_slice(&self.q_acc);
                self.qd.copy_from_slice(&self.qd_acc);
                self.t_state = self.t_acc;
                self.retries += 1;
                if self.retries <= MAX_RETRIES {
                    Err(RhsError::recoverable(e))
                } else {
                    Err(RhsError::new(e))
                }
            }
            Err(e) => Err(RhsError::new(e)),
        }
    }
}
