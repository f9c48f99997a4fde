//! What a simulation returns: the sampled [`Trajectory`], work [`Stats`] and the
//! constraint and energy [`Monitors`], bundled in a [`Run`].
//!
//! Input: rows pushed by the driver. Output: flat row-major storage with accessors.
//! Invariant: every column has one entry per row (`q`, `qd` have `n` per row, `lambda`
//! has `m_h + m_nh`), except `energy`, which is empty unless the model is
//! [conservative](crate::Info::conservative).

use std::time::Duration;

use crate::Info;

/// Sampled motion, one row per output time, stored as flat row-major vectors.
#[derive(Clone, Debug)]
pub struct Trajectory {
    info: &'static Info,
    /// Times of the rows.
    pub t: Vec<f64>,
    /// Coordinates, `n` per row.
    pub q: Vec<f64>,
    /// Velocities, `n` per row.
    pub qd: Vec<f64>,
    /// Multipliers $[\lambda_h; \lambda_{nh}]$, `m` per row (sign convention of
    /// [`Mechanism`](crate::Mechanism): the constraint force is $-J^\mathsf{T}\lambda$).
    pub lambda: Vec<f64>,
    /// $\lVert C(q,t)\rVert_\infty$ per row.
    pub position_violation: Vec<f64>,
    /// $\lVert [C_q\dot q + C_t;\ G\dot q + g]\rVert_\infty$ per row.
    pub velocity_violation: Vec<f64>,
    /// $T + V$ per row; empty unless the model is conservative.
    pub energy: Vec<f64>,
}

impl Trajectory {
    pub(crate) fn new(info: &'static Info, rows: usize) -> Self {
        let (n, m) = (info.nq(), info.nh() + info.nnh());
        let e = if info.conservative { rows } else { 0 };
        Self {
            info,
            t: Vec::with_capacity(rows),
            q: Vec::with_capacity(rows * n),
            qd: Vec::with_capacity(rows * n),
            lambda: Vec::with_capacity(rows * m),
            position_violation: Vec::with_capacity(rows),
            velocity_violation: Vec::with_capacity(rows),
            energy: Vec::with_capacity(e),
        }
    }

    /// Drops the rows after time `t` (the rows of a step taken back).
    pub(crate) fn truncate_after(&mut self, t: f64) {
        let rows = self.t.partition_point(|&r| r <= t);
        let (n, m) = (self.info.nq(), self.info.nh() + self.info.nnh());
        self.t.truncate(rows);
        self.q.truncate(rows * n);
        self.qd.truncate(rows * n);
        self.lambda.truncate(rows * m);
        self.position_violation.truncate(rows);
        self.velocity_violation.truncate(rows);
        if self.info.conservative {
            self.energy.truncate(rows);
        }
    }

    #[allow(clippy::too_many_arguments)]
    pub(crate) fn push(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        lambda: &[f64],
        position_violation: f64,
        velocity_violation: f64,
        energy: Option<f64>,
    ) {
        self.t.push(t);
        self.q.extend_from_slice(q);
        self.qd.extend_from_slice(qd);
        self.lambda.extend_from_slice(lambda);
        self.position_violation.push(position_violation);
        self.velocity_violation.push(velocity_violation);
        if let Some(e) = energy {
            self.energy.push(e);
        }
    }

    /// The model description (coordinate and constraint names).
    #[must_use]
    pub fn info(&self) -> &'static Info {
        self.info
    }

    /// Number of rows.
    #[must_use]
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether there are no rows.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Coordinates of row `i`.
    #[must_use]
    pub fn q(&self, i: usize) -> &[f64] {
        let n = self.info.nq();
        &self.q[i * n..(i + 1) * n]
    }

    /// Velocities of row `i`.
    #[must_use]
    pub fn qd(&self, i: usize) -> &[f64] {
        let n = self.info.nq();
        &self.qd[i * n..(i + 1) * n]
    }

    /// Multipliers of row `i`.
    #[must_use]
    pub fn lambda(&self, i: usize) -> &[f64] {
        let m = self.info.nh() + self.info.nnh();
        &self.lambda[i * m..(i + 1) * m]
    }

    /// Energy of row `i`, when the model is conservative.
    #[must_use]
    pub fn energy(&self, i: usize) -> Option<f64> {
        self.energy.get(i).copied()
    }

    /// The row closest to time `t` (`None` when empty).
    #[must_use]
    pub fn row_at(&self, t: f64) -> Option<usize> {
        (0..self.len()).min_by(|&a, &b| (self.t[a] - t).abs().total_cmp(&(self.t[b] - t).abs()))
    }

    /// The values of coordinate `name` over all rows.
    #[must_use]
    pub fn coordinate(&self, name: &str) -> Option<Vec<f64>> {
        let j = self.info.coordinate_index(name)?;
        Some((0..self.len()).map(|i| self.q(i)[j]).collect())
    }

    /// The values of the velocity of coordinate `name` over all rows.
    #[must_use]
    pub fn velocity(&self, name: &str) -> Option<Vec<f64>> {
        let j = self.info.coordinate_index(name)?;
        Some((0..self.len()).map(|i| self.qd(i)[j]).collect())
    }
}

/// Work counters of a run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Accepted steps.
    pub steps: u64,
    /// Rejected step attempts.
    pub rejected: u64,
    /// Evaluations of the state-space right-hand side (each one is a full K1 + K2 +
    /// augmented solve for partitioning, one augmented solve otherwise).
    pub rhs_evals: u64,
    /// Newton updates of the integration: the position corrections of the right-hand
    /// side and of accepted steps, and the position projection (output rows apart, in
    /// [`output_newton_iterations`](Self::output_newton_iterations)).
    pub newton_iterations: u64,
    /// Matrix factorizations of the integration: one per Newton update, per velocity
    /// solve and per augmented solve of a right-hand side (output rows apart, in
    /// [`output_factorizations`](Self::output_factorizations)).
    pub factorizations: u64,
    /// Newton updates spent on output rows: the interpolated states of requested output
    /// times corrected onto the constraints. They serve the output, not the
    /// integration, which never continues from them.
    pub output_newton_iterations: u64,
    /// Factorizations spent on output rows: their corrections, and the augmented solves
    /// of their accelerations and multipliers.
    pub output_factorizations: u64,
    /// Re-partitions (monitor or recovery from a failed Newton iteration).
    pub repartitions: u64,
    /// Jacobians of the right-hand side formed by an implicit integrator
    /// ([`Method::Radau5`](super::Method::Radau5)); their evaluations are in `rhs_evals`.
    pub jacobians: u64,
    /// Factorizations of an implicit integrator's iteration matrices.
    pub stage_factorizations: u64,
    /// Simplified Newton iterations of an implicit integrator's stage equations.
    pub stage_newton_iterations: u64,
    /// Restarts of the integrator after the first start.
    pub restarts: u64,
    /// Wall-clock time of [`run`](super::Simulation::run), assembly included.
    pub wall_time: Duration,
}

/// Constraint and energy monitors, taken at every accepted step and every output row.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Monitors {
    /// Largest $\lVert C\rVert_\infty$.
    pub max_position_violation: f64,
    /// Largest $\lVert C_q\dot q + C_t\rVert_\infty$.
    pub max_velocity_violation: f64,
    /// Largest $\lVert G\dot q + g\rVert_\infty$.
    pub max_nonholonomic_violation: f64,
    /// $T + V$ at the start (conservative models only).
    pub energy_initial: Option<f64>,
    /// $T + V$ at the last accepted state (conservative models only).
    pub energy_final: Option<f64>,
    /// Kinetic energy taken by the impacts so far (their `energy_lost`, summed).
    pub energy_lost_in_impacts: f64,
    /// Largest $|E - (E_0 - E_\text{impacts})|$ (conservative models only): the drift
    /// of the integration, the impacts' losses (up to that state) set apart.
    pub max_energy_drift: Option<f64>,
}

impl Monitors {
    pub(crate) fn observe(&mut self, v: (f64, f64, f64), energy: Option<f64>) {
        self.max_position_violation = self.max_position_violation.max(v.0);
        self.max_velocity_violation = self.max_velocity_violation.max(v.1);
        self.max_nonholonomic_violation = self.max_nonholonomic_violation.max(v.2);
        if let Some(e) = energy {
            let e0 = *self.energy_initial.get_or_insert(e);
            let d = (e - (e0 - self.energy_lost_in_impacts)).abs();
            self.max_energy_drift = Some(self.max_energy_drift.map_or(d, |m| m.max(d)));
        }
    }
}

/// The result of a simulation (or the part computed before a failure).
#[derive(Clone, Debug)]
pub struct Run {
    /// Sampled motion.
    pub trajectory: Trajectory,
    /// Work counters.
    pub stats: Stats,
    /// Constraint and energy monitors.
    pub monitors: Monitors,
    /// Constraints found redundant, named once as first identified (by Algorithm P at
    /// assembly, or else by the acceleration solve; which rows of a dependent set get
    /// named depends on the pivoting). Their multipliers are the minimum-norm split,
    /// their small inconsistencies from drift are solved in the least-squares sense
    /// (see [`Dynamics`](crate::Dynamics)), and K1, K2 and the projection use the other rows.
    pub redundant_constraints: Vec<&'static str>,
    /// Declared initial velocities that assembly had to change (see
    /// [`Kinematics::assemble_declared`](crate::Kinematics::assemble_declared)).
    pub overridden_velocities: Vec<crate::OverriddenVelocity>,
    /// The impacts, in time order (one per contact that struck: simultaneous impacts
    /// are resolved one contact at a time, see [`crate::sim`]).
    pub impacts: Vec<crate::Impact>,
    /// Contacts that came to rest (accumulated impacts) and released, in time order.
    pub contact_events: Vec<super::ContactEvent>,
    /// The times of the accepted steps at which the partition was chosen anew (one per
    /// re-partition counted in [`Stats::repartitions`] after the start).
    pub repartition_times: Vec<f64>,
}

impl Run {
    /// The last row: `(t, q, q̇)` (`None` when nothing was computed).
    #[must_use]
    pub fn final_state(&self) -> Option<(f64, &[f64], &[f64])> {
        let tr = &self.trajectory;
        let i = tr.len().checked_sub(1)?;
        Some((tr.t[i], tr.q(i), tr.qd(i)))
    }
}
