//! The integration loop behind [`Simulation::run`].
//!
//! Input: a configured [`Simulation`] and the end time. Output: a [`Run`], or a
//! [`SimError`] with the rows recorded so far.
//!
//! Per accepted step: project (projection formulation), record the rows whose output
//! times the step passed (dense output, then reconstruction of the full state), update
//! the monitors at the accepted state, run the condition monitor (partitioning) and
//! restart on a re-partition, report progress. A failed K1 inside a step
//! (partitioning) is first retried by the integrator with shorter steps (a recoverable
//! failure, see `MechSystem::rhs`); if it persists, the driver re-partitions at the last
//! accepted state and restarts with an eighth of the proposed step; three failures
//! without progress end the run with the kinematic failure.
//!
//! Invariant: after the rows are reserved, the loop does not allocate unless it
//! re-partitions or fails (the trajectory grows only in [`Output::Steps`] mode).

use std::time::Instant;

use super::contacts::{Found, Refined};
use super::error::{SimError, SimErrorKind};
use super::formulation::Correction;
use super::guard::Guard;
use super::stepper::Stepper;
use super::system::System;
use super::trajectory::{Monitors, Run, Stats, Trajectory};
use super::{Formulation, Method, Output, Simulation};
use crate::assembly::write_prescription;
use crate::kinematics::KinematicsError;
use crate::ode::{OdeError, OdeOptions, OdeSystem, Tolerances};
use crate::workspace::EvalError;
use crate::{AssemblyError, Mechanism, MechanismExt, PartitionError, Prescription};

/// Ratios of a singular value of $C_q$ (rows at unit length) to the largest below
/// which constraints are reported as nearly dependent in a failure, tried in turn.
const NEAR_SINGULAR: [f64; 3] = [1e-3, 1e-2, 1e-1];

/// Most rows an [`Output::Every`] grid may ask for: a finer grid is a mistake (a unit
/// error) whose rows would not fit in memory; [`Output::Steps`] records every step.
const MAX_GRID_ROWS: f64 = (1_u64 << 26) as f64;

/// The output times in $(t_0, t_\text{end}]$.
fn output_times(output: &Output, t0: f64, t_end: f64) -> Result<Vec<f64>, SimErrorKind> {
    let bad = |value| SimErrorKind::InvalidTimes { t0, t_end, value };
    if !(t0.is_finite() && t_end.is_finite() && t_end >= t0) {
        return Err(bad(t_end));
    }
    if t_end == t0 {
        // A run of zero span: assembly and the initial row only.
        return Ok(Vec::new());
    }
    let span = t_end - t0;
    match output {
        Output::Steps => Ok(Vec::new()),
        Output::Every(dt) => {
            let k_max = ((span / dt) * (1.0 + 1e-12)).floor();
            if !(dt.is_finite() && *dt > 0.0 && k_max <= MAX_GRID_ROWS) {
                return Err(bad(*dt));
            }
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            let k_max = k_max as usize;
            Ok((1..=k_max)
                .map(|k| (t0 + k as f64 * dt).min(t_end))
                .collect())
        }
        Output::Times(times) => {
            let mut prev = t0;
            let mut out = Vec::with_capacity(times.len());
            for &t in times {
                if !t.is_finite() || t < prev || t > t_end {
                    return Err(bad(t));
                }
                if t > t0 && out.last() != Some(&t) {
                    out.push(t);
                }
                prev = t;
            }
            Ok(out)
        }
    }
}

struct Recorder<'a, 'm, M: Mechanism + ?Sized> {
    sys: System<'m, M>,
    traj: Trajectory,
    monitors: Monitors,
    started: Instant,
    y: &'a mut [f64],
    overridden: Vec<crate::OverriddenVelocity>,
    repartition_times: Vec<f64>,
    /// Newton iterations and factorizations spent on output rows (see
    /// [`output_row`](Self::output_row)).
    output_work: (u64, u64),
    /// The divergence guard of the kept states (not for the unconstrained formulation,
    /// which enforces nothing).
    guard: Option<Guard>,
}

impl<M: Mechanism + ?Sized> Recorder<'_, '_, M> {
    /// Monitors at the current full state; returns the violations.
    fn observe(&mut self, t: f64) -> Result<(f64, f64, f64), SimErrorKind> {
        let p = &mut self.sys.point;
        let v = p.violations(t).map_err(SimErrorKind::from_eval)?;
        let energy = p.info.conservative.then(|| p.mech.energy(t, &p.q, &p.qd));
        self.monitors.observe(v, energy);
        if energy.is_some() {
            self.monitors.energy_final = energy;
        }
        if let Some(g) = self.guard.as_mut() {
            let p = &mut self.sys.point;
            let mut tripped = g.positions(t, &p.q, p.ws.constraints(), &p.ws.cq_values);
            if let (None, Some(e0), true) =
                (&tripped, self.monitors.energy_initial, p.info.conservative)
            {
                let parts = (
                    p.mech.kinetic_energy(t, &p.q, &p.qd),
                    p.mech.potential_energy(t, &p.q),
                );
                let lost = self.monitors.energy_lost_in_impacts;
                tripped = g.energy(t, parts, e0, lost);
            }
            if let Some(kind) = tripped {
                // The failure keeps this state as the partial run's last row: recorded
                // without the guard.
                self.guard = None;
                return Err(kind);
            }
        }
        Ok(v)
    }

    /// Records a row at the current full state.
    fn record(&mut self, t: f64) -> Result<(), SimErrorKind> {
        self.sys.accelerations(t)?;
        let v = self.observe(t)?;
        let p = &self.sys.point;
        let energy = self.monitors.energy_final.filter(|_| p.info.conservative);
        self.traj
            .push(t, &p.q, &p.qd, p.lambda(), v.0, v.1.max(v.2), energy);
        Ok(())
    }

    /// Records the output row at `t` from the step's dense output (`y` scratch): the
    /// interpolated state corrected onto the constraints as the formulation keeps
    /// states, and its accelerations and multipliers. Its Newton iterations and
    /// factorizations are counted apart from the integration's, which they do not serve
    /// ([`Stats::output_newton_iterations`]): a run with many rows would otherwise
    /// report the corrections of its rows as work per evaluation.
    fn output_row(&mut self, stepper: &Stepper, t: f64, y: &mut [f64]) -> Result<(), SimErrorKind> {
        stepper.interpolate(t, y).map_err(SimErrorKind::from_ode)?;
        let before = (
            self.sys.point.newton_iterations,
            self.sys.point.factorizations,
        );
        let kept = self.sys.keep_row(t, y).and_then(|_| self.record(t));
        let p = &self.sys.point;
        self.output_work.0 += p.newton_iterations - before.0;
        self.output_work.1 += p.factorizations - before.1;
        kept
    }

    /// The holonomic constraints that take part in a near dependence of $C_q$ at the
    /// last full state ([`crate::partition::dependent_constraints`], singular values
    /// below the first of `ratios` that finds any): those that lock the
    /// mechanism when an iteration stalls on a singular Jacobian with a small residual.
    fn nearly_dependent(&mut self, ratios: &[f64]) -> Vec<&'static str> {
        let p = &mut self.sys.point;
        let Some(&t) = self.traj.t.last() else {
            return Vec::new();
        };
        p.invalidate();
        // The weakest dependence first: a stall near a fold (a slider at its reach)
        // leaves a ratio of a few 1e-3 at the last accepted state. Among the rows kept:
        // those found redundant are reported as such.
        let rows = &p.rows[..p.rows_h];
        crate::partition::dependent_constraints(p.mech, &mut p.ws, t, &p.q, rows, ratios)
    }

    /// Adds a row at the integrator's last accepted state when the rows end before it
    /// (output on a grid, or only at the end), so that a partial run ends where the
    /// integration stopped. Skipped when the state cannot be reconstructed. When its
    /// accelerations fail (often the failure being reported: the solve at the kept
    /// state), the row has the positions and velocities, their violations and energy,
    /// and NaN multipliers.
    fn record_last_accepted(&mut self, stepper: &Stepper) {
        let t = stepper.t();
        if self.traj.t.last().is_some_and(|&last| last >= t) || self.y.len() != stepper.y().len() {
            return;
        }
        self.y.copy_from_slice(stepper.y());
        match self.sys.keep(t, self.y) {
            Ok(_) => {
                if self.record(t).is_err() {
                    self.record_state(t);
                }
            }
            // The state cannot be corrected (projection at a singular configuration):
            // recorded as the integrator holds it, without accelerations, so that the
            // run still ends where it stopped.
            Err(_) => {
                self.sys.point.set_state(self.y);
                self.record_state(t);
            }
        }
    }

    /// Records a row at the current positions and velocities without their
    /// accelerations: NaN multipliers (violations NaN too if they cannot be evaluated).
    fn record_state(&mut self, t: f64) {
        let v = self.observe(t).unwrap_or((f64::NAN, f64::NAN, f64::NAN));
        let p = &self.sys.point;
        let energy = self.monitors.energy_final.filter(|_| p.info.conservative);
        let lambda = vec![f64::NAN; p.lambda().len()];
        self.traj
            .push(t, &p.q, &p.qd, &lambda, v.0, v.1.max(v.2), energy);
    }

    /// The run so far; moves the recorded rows and lists out (the recorder is not
    /// used after it: a copy of the trajectory was a copy and seven allocations per
    /// run).
    fn run(&mut self, stepper: Option<&Stepper>) -> Run {
        let (output_newton, output_factorizations) = self.output_work;
        let mut stats = Stats {
            newton_iterations: self.sys.point.newton_iterations - output_newton,
            factorizations: self.sys.point.factorizations - output_factorizations,
            output_newton_iterations: output_newton,
            output_factorizations,
            repartitions: self.sys.point.kin.repartitions() as u64,
            wall_time: self.started.elapsed(),
            ..Stats::default()
        };
        if let Some(s) = stepper {
            let o = s.stats();
            stats.steps = o.steps;
            stats.rejected = o.rejected;
            stats.rhs_evals = o.rhs_evals;
            stats.jacobians = o.jac_evals;
            stats.stage_factorizations = o.factorizations;
            stats.stage_newton_iterations = o.newton_iterations;
            stats.restarts = o.restarts.saturating_sub(1);
        }
        let (impacts, contact_events) = super::contacts::take(&self.sys);
        let info = self.sys.point.info;
        Run {
            trajectory: std::mem::replace(&mut self.traj, Trajectory::new(info, 0)),
            stats,
            monitors: self.monitors,
            redundant_constraints: std::mem::take(&mut self.sys.point.redundant),
            overridden_velocities: std::mem::take(&mut self.overridden),
            impacts,
            contact_events,
            repartition_times: std::mem::take(&mut self.repartition_times),
        }
    }

    fn fail(&mut self, stepper: Option<&Stepper>, kind: SimErrorKind) -> SimError {
        if let Some(s) = stepper {
            self.record_last_accepted(s);
        }
        self.failed(stepper, kind)
    }

    /// [`fail`](Self::fail) with the rows as recorded (the last one already the state
    /// the run stops at), the work of `stepper`'s steps counted.
    fn failed(&mut self, stepper: Option<&Stepper>, mut kind: SimErrorKind) -> SimError {
        match &mut kind {
            SimErrorKind::NewtonFailed { constraints, .. }
            | SimErrorKind::Singular { constraints, .. }
                if constraints.is_empty() =>
            {
                *constraints = self.nearly_dependent(&NEAR_SINGULAR);
            }
            // A step size driven to round-off where C_q is clearly near-singular (the
            // first of NEAR_SINGULAR only: the failure itself says nothing of rank) is
            // the accelerations growing without bound at a lock.
            SimErrorKind::StepSizeTooSmall {
                nearly_dependent, ..
            }
            | SimErrorKind::NoProgress {
                nearly_dependent, ..
            } => *nearly_dependent = self.nearly_dependent(&NEAR_SINGULAR[..1]),
            _ => {}
        }
        SimError {
            kind,
            partial: Box::new(self.run(stepper)),
        }
    }
}

#[allow(clippy::too_many_lines)]
pub(super) fn run<M: Mechanism + ?Sized>(
    sim: &mut Simulation<'_, M>,
    t_end: f64,
) -> Result<Run, SimError> {
    let started = Instant::now();
    let mech = sim.mech;
    let info = mech.info();
    let n = info.nq();
    let t0 = sim.t0;
    let empty = |kind| SimError {
        kind,
        partial: Box::new(Run {
            trajectory: Trajectory::new(info, 0),
            stats: Stats {
                wall_time: started.elapsed(),
                ..Stats::default()
            },
            monitors: Monitors::default(),
            redundant_constraints: Vec::new(),
            overridden_velocities: Vec::new(),
            impacts: Vec::new(),
            contact_events: Vec::new(),
            repartition_times: Vec::new(),
        }),
    };
    let times = output_times(&sim.output, t0, t_end).map_err(empty)?;

    // Initial guess and assembly.
    let (mut q, mut qd) = match &sim.initial {
        Some((q, qd)) => {
            for (what, v) in [("coordinates", q), ("velocities", qd)] {
                if v.len() != n {
                    return Err(empty(SimErrorKind::InitialLength {
                        what,
                        found: v.len(),
                        expected: n,
                    }));
                }
            }
            (q.clone(), qd.clone())
        }
        None => {
            let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
            mech.initial_state(&mut q, &mut qd);
            (q, qd)
        }
    };
    let mut sys = System::new(
        mech,
        sim.formulation,
        sim.kinematics,
        sim.dynamics,
        chart_tolerances(sim.method, sim.rtol, sim.atol),
    )
    .map_err(|e| empty(SimErrorKind::Analysis(e)))?;
    // Adams evaluates about twice per step, last at the state it keeps, where the
    // projections read C next: C with the terms there costs less than a call of its
    // own per step. The explicit pairs evaluate 6 to 16 times per step, Radau5 at its
    // stages: C at each costs more than the one call it saves
    // (docs/decisions/0018-c-and-cq-in-one-call.md).
    sys.point.constraints_with_terms = matches!(sim.method, Method::Adams);
    let pq: Vec<(&str, f64)> = sim
        .prescribed_q
        .iter()
        .map(|(s, v)| (s.as_str(), *v))
        .collect();
    let pqd: Vec<(&str, f64)> = sim
        .prescribed_qd
        .iter()
        .map(|(s, v)| (s.as_str(), *v))
        .collect();
    let prescription = Prescription {
        coordinates: &pq,
        velocities: &pqd,
    };
    let overridden = if sim.formulation == Formulation::Unconstrained {
        // Nothing to enforce, nothing to assemble: the state as given.
        write_prescription(info, t0, &mut q, &mut qd, &prescription)
            .map_err(|e| empty(assembly_error(e)))?;
        Vec::new()
    } else {
        let (_, overridden) = sys
            .point
            .kin
            .assemble_declared(mech, &mut sys.point.ws, t0, &mut q, &mut qd, &prescription)
            .map_err(|e| empty(assembly_error(e)))?;
        sys.point.invalidate();
        overridden
    };
    // A mass matrix with a negative direction has no physical motion, and nothing
    // later stops it (the general solve is regular): checked once, here.
    let negative = crate::inertia::negative_direction_in(mech, &mut sys.point.ws, t0, &q, &qd);
    // The terms it evaluated are not the point's (its state is set below).
    sys.point.invalidate();
    match negative {
        Ok(None) => {}
        Ok(Some(found)) => {
            return Err(empty(SimErrorKind::NegativeMass {
                t: t0,
                coordinate: info.coordinates[found.coordinate].name,
                ratio: found.ratio,
            }))
        }
        Err(e) => return Err(empty(SimErrorKind::from_eval(e))),
    }
    sys.point.q.copy_from_slice(&q);
    sys.point.qd.copy_from_slice(&qd);
    sys.point.redundant = sys.point.fit_partition();
    if let Err(e) = sys.accept(t0) {
        return Err(empty(e));
    }
    // Contacts closed at the start: impacts, then rest (none may start penetrated).
    let mut h_first = None;
    // T + V before those impacts and the kinetic energy they take (positions do not
    // jump): the run's initial energy is the state's as given.
    let mut start_energy = None;
    if let Some(c) = sys.contacts.as_mut() {
        if let Err(e) = c.check_initial(&sys.point, t0) {
            return Err(empty(e));
        }
        let p = &sys.point;
        let before = info.conservative.then(|| {
            let kinetic = mech.kinetic_energy(t0, &p.q, &p.qd);
            (kinetic + mech.potential_energy(t0, &p.q), kinetic)
        });
        let r = super::contacts::handle(&mut sys, None, t0).and_then(|h| {
            sys.accept(t0)?;
            if let Some(c) = sys.contacts.as_mut() {
                c.anchor(&sys.point, t0)?;
            }
            Ok(h)
        });
        match r {
            Ok(h) => h_first = h,
            Err(e) => return Err(empty(e)),
        }
        start_energy = before.map(|(e, t)| {
            let p = &sys.point;
            (e, t - mech.kinetic_energy(t0, &p.q, &p.qd))
        });
    }
    let mut monitors = Monitors::default();
    if let Some((e, lost)) = start_energy {
        monitors.energy_initial = Some(e);
        monitors.energy_lost_in_impacts = lost;
    }

    let rows = match sim.output {
        Output::Steps => 1024,
        _ => times.len() + 2,
    };
    let dim = sys.dim();
    let mut y = vec![0.0; dim];
    let mut rec = Recorder {
        sys,
        traj: Trajectory::new(info, rows),
        monitors,
        started,
        y: &mut y,
        overridden,
        repartition_times: Vec::new(),
        output_work: (0, 0),
        guard: (sim.monitors && sim.formulation != Formulation::Unconstrained).then(|| {
            Guard::new(
                info,
                (!matches!(sim.method, Method::Rk4 { .. })).then_some((sim.rtol, sim.atol)),
                !matches!(sim.formulation, Formulation::Baumgarte { .. }),
            )
        }),
    };
    if let Err(kind) = rec.record(t0) {
        return Err(rec.fail(None, kind));
    }
    if let Some(g) = rec.guard.as_mut() {
        let p = &rec.sys.point;
        g.set_motion(&p.q, &p.qd, p.qdd(), t_end - t0, sim.atol / sim.rtol);
    }
    if t_end == t0 {
        return Ok(rec.run(None));
    }

    // Integrator.
    let h_max = sim.h_max.unwrap_or(f64::INFINITY);
    if let Some(h) = sim.h_init.filter(|h| h.is_nan() || *h <= 0.0) {
        // The run goes forward: a negative first step is a bad step size, not a
        // backward integration.
        return Err(rec.fail(
            None,
            SimErrorKind::Integrator(OdeError::InvalidStepSize { h }),
        ));
    }
    // Dense output only where the run interpolates: rows on a grid or at given times,
    // and the location of contact events. DOP853 pays three evaluations per step for
    // it (the other methods have it free); a run with rows at the steps or at the end
    // only lands on them.
    let interpolates = !times.is_empty() || rec.sys.contacts.is_some();
    // Without contacts only the rows interpolate: DOP853 then prepares its interpolant
    // on the steps that reach the next row, not on the steps between rows of a grid
    // coarser than the steps.
    let rows_only = rec.sys.contacts.is_none();
    let opts = OdeOptions {
        tol: Tolerances::new(sim.rtol, sim.atol),
        h_init: sim.h_init.map(|h| h.max(super::min_step(t0, t_end))),
        h_max,
        max_steps: sim.max_steps,
        dense_output: interpolates,
    };
    if let Some(kind) = baumgarte_unstable(sim.formulation, sim.method, info.nnh() > 0) {
        return Err(rec.fail(None, kind));
    }
    // Baumgarte on a model whose constraints are independent at the start: a rank drop
    // of the Jacobian along the run (the solve's redundant path naming rows) is a
    // singular configuration it would integrate through.
    let watch_rank = matches!(sim.formulation, Formulation::Baumgarte { .. })
        && rec.sys.point.redundant.is_empty();
    let mut stepper = match Stepper::new(sim.method, dim, opts) {
        Ok(s) => s,
        Err(e) => return Err(rec.fail(None, SimErrorKind::Integrator(e))),
    };
    rec.sys.gather(rec.y);
    let min_h = super::min_step(t0, t_end);
    let restart_step = |h: Option<f64>| match sim.method {
        super::Method::Rk4 { .. } => None,
        _ => h.map(|h| h.max(min_h).min(h_max)),
    };
    if let Err(e) = stepper.reset(&mut rec.sys, t0, rec.y, restart_step(h_first)) {
        let kind = failure(e, &mut rec.sys);
        return Err(rec.fail(Some(&stepper), kind));
    }

    // Projection with an explicit pair: the next step starts from the projected state
    // with the FSAL derivative of the unprojected one, as Adams keeps its differences
    // (docs/decisions/0024-fsal-derivative-survives-the-projection.md): the
    // projection moves the state by about the local error, so the derivative's error
    // enters the next step multiplied by h, below the local error of the method.
    let keeps_fsal = sim.formulation == Formulation::Projection
        && matches!(sim.method, Method::Dopri5 | Method::Dop853);
    let mut yout = vec![0.0; dim];
    // A closing located on a dense output coarser than the steps is moved to where the
    // steps put it (`contacts::refine`), which needs the state at the start of the step.
    let refine_events = sim.method.coarse_dense_output() && rec.sys.contacts.is_some();
    let mut y_start = vec![0.0; if refine_events { dim } else { 0 }];
    let mut next_out = 0;
    let steps_mode = matches!(sim.output, Output::Steps);
    // The state each step starts from, and the one the last accepted step started
    // from: a step that ends at a state no evaluation succeeds from is taken back
    // (models with redundant constraints and no contacts, see below).
    let steps_back = rec.sys.point.has_redundant_rows() && rec.sys.contacts.is_none();
    let mut from = vec![0.0; if steps_back { dim } else { 0 }];
    let mut back = from.clone();
    let mut t_back = f64::NAN;
    let mut step_backs = 0_u32;

    macro_rules! bail {
        ($kind:expr) => {
            return Err(rec.fail(Some(&stepper), $kind))
        };
    }
    macro_rules! check {
        ($e:expr) => {
            match $e {
                Ok(v) => v,
                Err(kind) => bail!(kind),
            }
        };
    }
    let ode = SimErrorKind::from_ode;

    // The window of the progress check: attempts and time at its start.
    let mut window = (0_u64, t0);
    while stepper.t() < t_end {
        let attempts = stepper.stats().steps + stepper.stats().rejected;
        if attempts >= sim.max_steps {
            bail!(SimErrorKind::MaxSteps {
                t: stepper.t(),
                steps: sim.max_steps
            });
        }
        if attempts < window.0 {
            window = (attempts, stepper.t());
        }
        if attempts >= window.0 + PROGRESS_WINDOW {
            let t = stepper.t();
            let advance = t - window.1;
            let needed = (t_end - t) / advance * (attempts - window.0) as f64;
            let budget = sim.max_steps - attempts;
            // Negated so that a NaN rate (no advance at all) stops the run too.
            #[allow(clippy::cast_precision_loss, clippy::neg_cmp_op_on_partial_ord)]
            if !(needed <= PROGRESS_MARGIN * budget as f64) {
                bail!(SimErrorKind::NoProgress {
                    t,
                    window: attempts - window.0,
                    advance,
                    needed,
                    budget,
                    nearly_dependent: Vec::new(),
                });
            }
            window = (attempts, t);
        }
        let t_prev = stepper.t();
        if refine_events {
            y_start.copy_from_slice(stepper.y());
        }
        let partitions = rec.sys.point.kin.repartitions();
        if rows_only {
            // The interpolant on the steps that reach the next row only.
            let next = times.get(next_out).copied().unwrap_or(f64::INFINITY);
            stepper.dense_output_from(Some(next));
        }
        if steps_back {
            from.copy_from_slice(stepper.y());
        }
        let t = match stepper.step(&mut rec.sys, Some(t_end)) {
            Ok(t) => t,
            Err(e) => {
                let kind = failure(e, &mut rec.sys);
                // An accepted state next to a rank drop of C_q from which every
                // attempt fails the dropped rows' check
                // (docs/decisions/0036-through-a-rank-drop.md): the step that reached it is
                // taken back and redone
                // from where it started with half its size, a few times at most. Not
                // with contacts, whose resting set and anchors follow the steps.
                if steps_back
                    && step_backs < MAX_STEP_BACKS
                    && t_back < t_prev
                    && rank_drop_failure(&kind)
                {
                    step_backs += 1;
                    rec.traj.truncate_after(t_back);
                    next_out = times.partition_point(|&to| to <= t_back);
                    check!(rec.sys.keep(t_back, &back));
                    check!(rec.sys.accept(t_back));
                    rec.sys.gather(rec.y);
                    let h0 = 0.5 * (t_prev - t_back);
                    if let Err(e) = stepper.reset(&mut rec.sys, t_back, rec.y, Some(h0)) {
                        let kind = failure(e, &mut rec.sys);
                        bail!(kind)
                    }
                    t_back = f64::NAN;
                    continue;
                }
                bail!(kind)
            }
        };
        // Contacts: the first event in the step truncates it there (rows before it from
        // this step's dense output), the jump is applied and the integrator restarts.
        if let Some(mut found) = check!(super::contacts::locate(&mut rec.sys, &stepper, t_prev)) {
            let te = found.t();
            while next_out < times.len() && times[next_out] < te {
                let to = times[next_out];
                check!(rec.output_row(&stepper, to, &mut yout));
                next_out += 1;
            }
            if let (true, Found::Closing { c: k, t: te }) = (refine_events, found) {
                let refined = super::contacts::refine(
                    &mut stepper,
                    &mut rec.sys,
                    (t_prev, t),
                    &y_start,
                    k,
                    te,
                    &mut yout,
                );
                match refined {
                    Ok(te) => found = Found::Closing { c: k, t: te },
                    Err(Refined::Ode(e)) => {
                        let kind = failure(e, &mut rec.sys);
                        bail!(kind)
                    }
                    Err(Refined::Sim(kind)) => bail!(kind),
                }
                // Rows the correction moved before the event.
                while next_out < times.len() && times[next_out] < found.t() {
                    let to = times[next_out];
                    check!(rec.output_row(&stepper, to, &mut yout));
                    next_out += 1;
                }
            }
            let te = found.t();
            check!(stepper.interpolate(te, &mut yout).map_err(ode));
            check!(rec.sys.keep(te, &yout));
            let before = rec
                .sys
                .point
                .mech
                .kinetic_energy(te, &rec.sys.point.q, &rec.sys.point.qd);
            let h0 = match super::contacts::handle(&mut rec.sys, Some(found), te) {
                Ok(h0) => h0,
                Err(kind) => {
                    // The run ends at the event, with the state before the jump.
                    check!(stepper.interpolate(te, &mut yout).map_err(ode));
                    check!(rec.sys.keep(te, &yout));
                    if let Some(c) = rec.sys.contacts.as_mut() {
                        c.clear_resting();
                    }
                    let _ = rec.record(te);
                    // The row at the event is the last; the work of the steps to it
                    // is counted.
                    return Err(rec.failed(Some(&stepper), kind));
                }
            };
            check!(rec.sys.accept(te));
            let after = rec
                .sys
                .point
                .mech
                .kinetic_energy(te, &rec.sys.point.q, &rec.sys.point.qd);
            // The energy monitor measures the integration: the impacts' losses are set
            // apart from its drift.
            rec.monitors.energy_lost_in_impacts += before - after;
            if steps_mode {
                check!(rec.record(te));
            } else {
                check!(rec.observe(te));
            }
            if let Some(c) = rec.sys.contacts.as_mut() {
                check!(c.anchor(&rec.sys.point, te));
            }
            rec.sys.gather(rec.y);
            t_back = f64::NAN;
            if let Err(e) = stepper.reset(&mut rec.sys, te, rec.y, restart_step(h0)) {
                let kind = failure(e, &mut rec.sys);
                bail!(kind)
            }
            if let Some(f) = sim.progress.as_mut() {
                f(te);
            }
            continue;
        }
        // The accepted state, corrected as the formulation keeps it (partitioning: the
        // point of the chart the integrator has just evaluated, polished; the
        // right-hand side is invariant to the move, so the integrator keeps its
        // derivatives), then the anchor of the next step.
        // The state is read from the integrator and, when corrected, written back.
        let mut correction = check!(rec.sys.keep(t, stepper.y()));
        if keeps_fsal && correction == Correction::Changed {
            correction = Correction::SameDerivative;
        }
        if let Some(c) = rec.sys.contacts.as_mut() {
            if check!(c.project(&mut rec.sys.point, t)) {
                correction = Correction::Changed;
            }
        }
        if correction != Correction::None {
            rec.sys.gather(rec.y);
        }
        match correction {
            Correction::None => {}
            Correction::SameDerivative => {
                check!(stepper.set_state_keeping_derivative(rec.y).map_err(ode));
            }
            Correction::Changed => check!(stepper.set_state(rec.y).map_err(ode)),
        }
        check!(rec.sys.accept(t));
        if watch_rank && !rec.sys.point.redundant.is_empty() {
            let constraints = rec.sys.point.redundant.clone();
            bail!(SimErrorKind::SingularConfiguration { t, constraints });
        }
        if rec.sys.point.kin.repartitions() > partitions {
            rec.repartition_times.push(t);
        }
        // Its row (or its monitors), then the rows of the output times the step
        // passed, which overwrite the full state.
        if steps_mode {
            check!(rec.record(t));
        } else {
            check!(rec.observe(t));
        }
        if rec.sys.contacts.is_some() {
            check!(rec.sys.accelerations(t));
            if let Some(c) = rec.sys.contacts.as_mut() {
                check!(c.anchor(&rec.sys.point, t));
            }
        }
        while next_out < times.len() && times[next_out] <= t {
            let to = times[next_out];
            check!(rec.output_row(&stepper, to, &mut yout));
            next_out += 1;
        }
        if steps_back {
            std::mem::swap(&mut back, &mut from);
            t_back = t_prev;
        }
        if let Some(f) = sim.progress.as_mut() {
            f(t);
        }
    }
    if rec.traj.t.last() != Some(&t_end) {
        rec.y.copy_from_slice(stepper.y());
        check!(rec.sys.keep(t_end, rec.y));
        check!(rec.record(t_end));
    }
    Ok(rec.run(Some(&stepper)))
}

/// The largest $|h\lambda|$ on the negative real axis for which the classical RK4 is
/// stable (the real root of $|1 + z + z^2/2 + z^3/6 + z^4/24| = 1$, $z \approx
/// -2.785$).
const RK4_STABILITY: f64 = 2.785;

/// [`SimErrorKind::BaumgarteUnstable`] when Baumgarte stabilization runs with a fixed
/// step that puts the constraint error's dynamics outside RK4's stability interval:
/// $\ddot e + 2\alpha\dot e + \beta^2 e = 0$ has eigenvalues $-\alpha \pm
/// \sqrt{\alpha^2 - \beta^2}$ (modulus $\beta$ when complex), non-holonomic rows
/// $\dot e = -2\alpha e$. The adaptive methods control their steps and are not
/// checked.
fn baumgarte_unstable(
    formulation: Formulation,
    method: Method,
    nonholonomic: bool,
) -> Option<SimErrorKind> {
    let (Formulation::Baumgarte { alpha, beta }, Method::Rk4 { h }) = (formulation, method) else {
        return None;
    };
    let disc = alpha * alpha - beta * beta;
    let holonomic = if disc >= 0.0 {
        alpha.abs() + disc.sqrt()
    } else {
        beta.abs()
    };
    let rate = if nonholonomic {
        holonomic.max(2.0 * alpha.abs())
    } else {
        holonomic
    };
    (h * rate > RK4_STABILITY).then_some(SimErrorKind::BaumgarteUnstable {
        h,
        alpha,
        beta,
        rate,
        limit: RK4_STABILITY,
    })
}

/// Step attempts between two checks of the run's progress
/// ([`SimErrorKind::NoProgress`]).
const PROGRESS_WINDOW: u64 = 10_000;

/// How many times the attempts left the rest of the span may need, at the rate of the
/// last window, before the run is stopped for making no progress: the rate would have
/// to rise a thousandfold for the run to finish within its step limit, and a run
/// creeping at step sizes of round-off is stopped after one window instead of
/// spending the whole budget. (A hundredfold stopped the work-precision reference of
/// `flexible_pendulum`, whose rate across a stiff stretch is 103 times below what the
/// rest of its span needs, and which then finishes.)
const PROGRESS_MARGIN: f64 = 1000.0;

/// Most steps a run takes back ([`rank_drop_failure`]).
const MAX_STEP_BACKS: u32 = 8;

/// Whether a step's failure can be the one of a state next to a rank drop of $C_q$:
/// the dropped rows' check failing at every attempt (reported as such, or as the step
/// size's underflow that the retries end in), the position iteration stalling there
/// on the singular Jacobian, or the augmented matrix singular there (Bricard's loop
/// near $(q_1, q_2) = (\pi, -\pi)$ at rtol 1e-3).
fn rank_drop_failure(kind: &SimErrorKind) -> bool {
    matches!(
        kind,
        SimErrorKind::StepSizeTooSmall { .. }
            | SimErrorKind::NewtonFailed { .. }
            | SimErrorKind::SingularMass { .. }
            | SimErrorKind::Analysis(crate::Error::Dynamics(
                crate::DynamicsError::InconsistentRedundant { .. }
            ))
    )
}

/// A NaN met during assembly is a [`SimErrorKind::NonFinite`]; other failures are
/// [`SimErrorKind::Assembly`].
fn assembly_error(e: AssemblyError) -> SimErrorKind {
    let eval = match &e {
        AssemblyError::Eval(v)
        | AssemblyError::Kinematics(
            KinematicsError::Eval(v) | KinematicsError::Partition(PartitionError::Eval(v)),
        )
        | AssemblyError::Partition(PartitionError::Eval(v)) => Some(v),
        _ => None,
    };
    match eval {
        Some(v @ EvalError::NonFinite { .. }) => SimErrorKind::from_eval(v.clone()),
        _ => SimErrorKind::Assembly(e),
    }
}

/// The kind of an integrator's failure: a failed evaluation's is held by the system.
fn failure<M: Mechanism + ?Sized>(e: OdeError, sys: &mut System<'_, M>) -> SimErrorKind {
    match e {
        OdeError::Rhs { .. } => sys
            .take_failure()
            .unwrap_or_else(|| SimErrorKind::from_ode(e)),
        other => SimErrorKind::from_ode(other),
    }
}

/// The tolerances the partitioning chart's Newton iteration stops at (a fraction
/// [`KAPPA`](super::chart::KAPPA) of them). An implicit method differentiates the
/// right-hand side by finite differences, with increments near $\sqrt{u}$ of the
/// state: an iteration stopped at the integrator's tolerance would leave a noise of
/// that size in $f$, and $10^8$ times it in the Jacobian. For it the chart iterates to
/// round-off ([`NEWTON_TOLERANCE`](super::NEWTON_TOLERANCE), relative).
fn chart_tolerances(method: Method, rtol: f64, atol: f64) -> (f64, f64) {
    if method.differences_rhs() {
        let tight = super::NEWTON_TOLERANCE;
        (tight, atol * tight / rtol.max(tight))
    } else {
        (rtol, atol)
    }
}
