//! The state-space system the integrators see: a [`Point`] and a formulation
//! ([`AnyForm`]) as an [`OdeSystem`] on $y = [q; \dot q]$, $\dot y = [\dot q; \ddot q]$,
//! and its public face [`StateSpace`].
//!
//! Errors stay typed: a failing evaluation keeps its [`SimErrorKind`] in the system and
//! hands the integrator a [`Failed`] marker (recoverable or not, as the formulation
//! says), which the caller exchanges for the kind with [`System::take_failure`].
//!
//! Invariant: no allocation after [`System::new`] (except when building an error).

use super::error::SimErrorKind;
use super::formulation::{AnyForm, Correction};
use super::point::Point;
use super::Formulation;
use crate::dynamics::DynamicsParams;
use crate::kinematics::KinematicsParams;
use crate::ode::{OdeSystem, RhsError};
use crate::{Error, Mechanism, PartitionParams, Preferences};

/// Recoverable failures in a row (since the last accepted step) before a failure stops
/// the integrator: with the integrators' cut of 4 per failure the step has then shrunk
/// by $4^{10} \approx 10^6$.
const MAX_RETRIES: u32 = 10;

/// What the right-hand side hands the integrators when it fails: the typed failure
/// stays with the system.
#[derive(Clone, Copy, Debug, thiserror::Error)]
#[error("the evaluation failed (the state-space system holds the typed failure)")]
pub struct Failed;

/// A mechanism under a formulation, with the analysis scratch.
pub(crate) struct System<'a, M: Mechanism + ?Sized> {
    pub point: Point<'a, M>,
    pub form: AnyForm,
    /// Recoverable failures since the last accepted step.
    retries: u32,
    /// Whether the next evaluation is at the state the step ends in
    /// ([`OdeSystem::step_end_next`]), and the time of the last evaluation when it was
    /// that one: evaluations for the interpolant after it ([`OdeSystem::aside`]) would
    /// replace its $M$, which projection holds for the step's correction first
    /// (`Point::hold_metric`).
    step_end: bool,
    step_end_t: Option<f64>,
    /// The failure of the last evaluation that failed.
    failure: Option<SimErrorKind>,
    /// Contacts, impacts and resting contacts (models with contacts only).
    pub contacts: Option<super::contacts::Contacts>,
}

impl<M: Mechanism + ?Sized> std::fmt::Debug for System<'_, M> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("System")
            .field("model", &self.point.info.name)
            .field("form", &self.form)
            .finish_non_exhaustive()
    }
}

impl<'a, M: Mechanism + ?Sized> System<'a, M> {
    pub fn new(
        mech: &'a M,
        formulation: Formulation,
        kin: KinematicsParams,
        dynamics: DynamicsParams,
        tolerances: (f64, f64),
    ) -> Result<Self, Error> {
        let info = mech.info();
        let (n, mh, m) = (info.nq(), info.nh(), info.nh() + info.nnh());
        Ok(Self {
            point: Point::new(mech, dynamics, kin)?,
            form: AnyForm::new(formulation, n, m, mh, tolerances),
            retries: 0,
            step_end: false,
            step_end_t: None,
            failure: None,
            contacts: super::contacts::Contacts::new(info, tolerances.0)?,
        })
    }

    /// $\ddot q$ and $\lambda$ at the full state of the point: the formulation's, with
    /// the correction of resting contacts.
    pub fn accelerations(&mut self, t: f64) -> Result<(), SimErrorKind> {
        self.form.accelerations(&mut self.point, t)?;
        if let Some(c) = self.contacts.as_mut() {
            c.correct(&mut self.point, t)?;
        }
        Ok(())
    }

    /// Takes the current full state (consistent, at `t`) as the last accepted one.
    pub fn accept(&mut self, t: f64) -> Result<(), SimErrorKind> {
        self.retries = 0;
        self.form.accept(&mut self.point, t)
    }

    /// Writes the state vector of the current full state into `y`.
    pub fn gather(&self, y: &mut [f64]) {
        let n = self.point.q.len();
        y[..n].copy_from_slice(&self.point.q);
        y[n..].copy_from_slice(&self.point.qd);
    }

    /// Fills the full state from `y` at `t` and corrects it as a kept state (accepted
    /// or output); returns what the integrator must do with the correction.
    pub fn keep(&mut self, t: f64, y: &[f64]) -> Result<Correction, SimErrorKind> {
        self.form.reconstruct_kept(&mut self.point, t, y)?;
        self.form.keep(&mut self.point, t)?;
        Ok(self.form.correction())
    }

    /// [`keep`](Self::keep) for an output row: an interpolated state the integration
    /// does not continue from, corrected without reading or changing what the run's
    /// evaluations left (see `Point::row`).
    pub fn keep_row(&mut self, t: f64, y: &[f64]) -> Result<Correction, SimErrorKind> {
        self.point.row = true;
        let kept = self.keep(t, y);
        self.point.row = false;
        kept
    }

    /// The typed failure of the last evaluation that failed.
    pub fn take_failure(&mut self) -> Option<SimErrorKind> {
        self.failure.take()
    }
}

impl<M: Mechanism + ?Sized> OdeSystem for System<'_, M> {
    fn dim(&self) -> usize {
        2 * self.point.info.nq()
    }

    /// A failure the formulation calls [recoverable](RhsError::recoverable) rejects the
    /// attempt (the integrator retries a shorter step); after [`MAX_RETRIES`] of them
    /// in a row the failure ends the run.
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let n = self.point.q.len();
        let step_end = std::mem::take(&mut self.step_end);
        let r = self
            .form
            .reconstruct(&mut self.point, t, y)
            .and_then(|()| self.accelerations(t));
        match r {
            Ok(()) => {
                self.step_end_t = step_end.then_some(t);
                dy[..n].copy_from_slice(&self.point.qd);
                dy[n..].copy_from_slice(self.point.qdd());
                Ok(())
            }
            Err(e) => {
                self.step_end_t = None;
                let recoverable = self.form.recoverable(&e) && self.retries < MAX_RETRIES;
                self.retries += u32::from(recoverable);
                self.failure = Some(e);
                Err(if recoverable {
                    RhsError::recoverable(Failed)
                } else {
                    RhsError::new(Failed)
                })
            }
        }
    }

    /// $C$ with the next evaluation's terms: the correction of the kept state and the
    /// monitors read it there (for a few operations on the sines the terms have, where
    /// a call of its own would evaluate them again).
    fn step_end_next(&mut self) {
        self.point.constraints_next = true;
        self.step_end = true;
    }

    /// Evaluations for the interpolant only are corrected like an output row's
    /// (`Point::row`): they teach the formulation nothing, and projection holds the $M$
    /// of the step's last stage before they replace it (on the steps without them the
    /// workspace still has it).
    fn aside(&mut self, on: bool) {
        if let (true, Some(t), AnyForm::Projected(_)) = (on, self.step_end_t, &self.form) {
            self.point.hold_metric(t);
        }
        self.point.row = on;
    }
}

/// A mechanism under a [`Formulation`] as the simulation integrates it: an
/// [`OdeSystem`] on $y = [q; \dot q]$ with $\dot y = [\dot q; \ddot q]$, for driving an
/// integrator of [`crate::ode`] directly or measuring one evaluation.
///
/// ```
/// use pfaff::ode::OdeSystem;
/// use pfaff::sim::{Formulation, StateSpace};
/// use pfaff::Mechanism;
///
/// #[pfaff::mechanism]
/// pub mod pendulum {
///     static x: Coordinate = Coordinate { q0: 1.0 };
///     static y: Coordinate = Coordinate {};
///     fn kinetic_energy() -> f64 {
///         0.5 * (x.dot().powi(2) + y.dot().powi(2))
///     }
///     fn potential_energy() -> f64 {
///         9.81 * y
///     }
///     #[holonomic]
///     fn rod() -> f64 {
///         x.powi(2) + y.powi(2) - 1.0
///     }
/// }
///
/// let model = pendulum::Model::default();
/// let mut sys = StateSpace::new(&model, Formulation::Partitioning, 1e-8, 1e-8)?;
/// sys.start(0.0, &[1.0, 0.0], &[0.0, 0.0])?;
/// let mut dy = [0.0; 4];
/// sys.rhs(0.0, &[1.0, 0.0, 0.0, 0.0], &mut dy).unwrap();
/// // At rest on the horizontal: the bob falls with g, the rod pulls nothing.
/// assert!((dy[3] + 9.81).abs() < 1e-12 && dy[2].abs() < 1e-12);
/// # Ok::<(), pfaff::sim::SimErrorKind>(())
/// ```
pub struct StateSpace<'a, M: Mechanism + ?Sized>(System<'a, M>);

impl<M: Mechanism + ?Sized> std::fmt::Debug for StateSpace<'_, M> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl<'a, M: Mechanism + ?Sized> StateSpace<'a, M> {
    /// `mech` under `formulation`, with the simulation's defaults for the analyses
    /// and the integrator's tolerances `rtol`, `atol` (partitioning stops its Newton
    /// iterations at a fraction of them).
    ///
    /// # Errors
    /// Malformed patterns of the model ([`SimErrorKind::Analysis`]).
    pub fn new(
        mech: &'a M,
        formulation: Formulation,
        rtol: f64,
        atol: f64,
    ) -> Result<Self, SimErrorKind> {
        let kin = KinematicsParams {
            partition: PartitionParams {
                allow_redundant: true,
                ..PartitionParams::default()
            },
            newton: crate::NewtonParams {
                tolerance: super::NEWTON_TOLERANCE,
                ..crate::NewtonParams::default()
            },
        };
        let dynamics = DynamicsParams {
            redundant_tolerance: super::REDUNDANT_TOLERANCE,
            ..DynamicsParams::default()
        };
        System::new(mech, formulation, kin, dynamics, (rtol, atol))
            .map(Self)
            .map_err(SimErrorKind::Analysis)
    }

    /// The same system with the augmented system solved by `solver` (default
    /// [`LinearSolver::Auto`](crate::LinearSolver::Auto): the model's generated solve
    /// first); `LinearSolver::Dense` or `Sparse` force the general paths, for
    /// comparisons.
    ///
    /// # Errors
    /// A failed sparse symbolic factorization ([`SimErrorKind::Analysis`]).
    pub fn linear_solver(mut self, solver: crate::LinearSolver) -> Result<Self, SimErrorKind> {
        let point = &mut self.0.point;
        let params = DynamicsParams {
            solver,
            ..*point.dynamics.params()
        };
        point.dynamics = crate::Dynamics::new(point.info, params)
            .map_err(|e| SimErrorKind::Analysis(e.into()))?;
        point.invalidate();
        Ok(self)
    }

    /// Starts from the consistent state `(t, q, q̇)` (as assembled, for example the
    /// model's initial state): Algorithm P picks the independent constraint rows, and
    /// the state becomes the last accepted one (for partitioning, the anchor of the
    /// chart).
    ///
    /// # Errors
    /// Wrong lengths or non-finite values, a singular or redundant-and-inconsistent
    /// constraint set.
    pub fn start(&mut self, t: f64, q: &[f64], qd: &[f64]) -> Result<(), SimErrorKind> {
        let sys = &mut self.0;
        let p = &mut sys.point;
        p.kin
            .repartition_with(p.mech, &mut p.ws, t, q, Preferences::default())
            .map_err(|e| SimErrorKind::from_analysis(e.into(), Vec::new()))?;
        crate::workspace::check_state(p.info, t, q, Some(qd)).map_err(SimErrorKind::from_eval)?;
        p.invalidate();
        p.q.copy_from_slice(q);
        p.qd.copy_from_slice(qd);
        p.fit_partition();
        sys.accept(t)
    }

    /// Corrects the state `y` $= [q; \dot q]$ at `t` as the formulation corrects an
    /// accepted step (projection: onto $C = 0$ and $J\dot q + [C_t; g] = 0$;
    /// partitioning: the chart's polish; Baumgarte: nothing) and takes it as the last
    /// accepted state; read the result with [`q`](Self::q) and [`qd`](Self::qd).
    ///
    /// # Errors
    /// The correction's failures: a Newton iteration that does not converge, a
    /// singular Gram matrix, a model function that fails.
    pub fn keep(&mut self, t: f64, y: &[f64]) -> Result<(), SimErrorKind> {
        self.0.keep(t, y)?;
        self.0.accept(t)
    }

    /// The full coordinates of the last evaluation.
    #[must_use]
    pub fn q(&self) -> &[f64] {
        &self.0.point.q
    }

    /// The full velocities of the last evaluation.
    #[must_use]
    pub fn qd(&self) -> &[f64] {
        &self.0.point.qd
    }

    /// The multipliers of the last evaluation.
    #[must_use]
    pub fn multipliers(&self) -> &[f64] {
        self.0.point.lambda()
    }

    /// The typed failure of the last evaluation that failed (the integrators carry a
    /// [`Failed`] marker).
    pub fn take_failure(&mut self) -> Option<SimErrorKind> {
        self.0.take_failure()
    }
}

impl<M: Mechanism + ?Sized> OdeSystem for StateSpace<'_, M> {
    fn dim(&self) -> usize {
        self.0.dim()
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        self.0.rhs(t, y, dy)
    }

    fn step_end_next(&mut self) {
        self.0.step_end_next();
    }

    fn aside(&mut self, on: bool) {
        self.0.aside(on);
    }
}
