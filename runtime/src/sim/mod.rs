//! Simulation of a mechanism over time: assembly, a run-time choice of formulation and
//! integrator, output at requested times, monitors, statistics and typed failures.
//!
//! Input: a [`Mechanism`] (also `&dyn Mechanism`), a [`Formulation`], a [`Method`],
//! tolerances and output times. Output: a [`Run`] (trajectory, [`Stats`], [`Monitors`])
//! or a [`SimError`] that keeps the partial run.
//!
//! # Formulations
//! With $J = [C_q; G]$ and $\gamma = [\gamma_h; \gamma_{nh}]$ (docs/theory.md §constraints), the
//! accelerations come from the augmented system (E31)
//! $$\begin{bmatrix}M & J^\mathsf{T}\\ J & 0\end{bmatrix}
//!   \begin{bmatrix}\ddot q\\ \lambda\end{bmatrix} =
//!   \begin{bmatrix}Q\\ \gamma\end{bmatrix}.$$
//! - [`Formulation::Partitioning`] (docs/theory.md Algorithm D in local coordinates): the
//!   integrator carries $y = [q; \dot q]$, but the right-hand side is a function of
//!   independent coordinates only. At each evaluation $y$ is moved onto the manifold
//!   in the *chart* of the last accepted state $q_a$: the dependent coordinates are the
//!   $r$ components along the rows of $C_q(q_a)$ (an orthonormal-quality partition,
//!   renewed at every step, so never near a singular one), found by Newton from the
//!   integrator's own prediction with the factorization of $C_q C_q^\mathsf{T}$ made
//!   at $q_a$ and stopped at a fraction of the integrator's tolerance (one update per
//!   evaluation is the norm); the dependent velocities come from the orthogonal
//!   projection onto $J\dot q + [C_t; g] = 0$; then (E31). Since the dependent
//!   coordinates are integrated too, the error test sees their error, the Newton
//!   guess is the integrator's prediction, and a change of chart changes nothing the
//!   integrator holds: no restart. Accepted and output states are polished to the
//!   Newton tolerance [`NEWTON_TOLERANCE`] (constraints hold there, no drift) and
//!   handed back to the integrator, which keeps its derivatives (the right-hand side
//!   is invariant to the correction). An evaluation whose Newton iteration diverges,
//!   or corrects the prediction by more than it moved from the last accepted state
//!   (another intersection of the normal space with the manifold), is a recoverable
//!   failure: the integrator rejects the attempt and retries a quarter of the step.
//!   The choice of this chart over a partition of the coordinates themselves, with the
//!   measurements behind it, is in `docs/decisions/0021-partitioning-in-a-local-chart.md`.
//! - [`Formulation::Projection`]: index 1 on $y = [q; \dot q]$; after every accepted
//!   step $q$ is projected onto $C(q,t) = 0$ and $\dot q$ onto $J\dot q + [C_t; g] = 0$,
//!   handed back with [`Integrator::set_state`](crate::ode::Integrator::set_state).
//!   Where the model's generated solve of (E31) serves, in the metric of $M$ (the
//!   solve with right-hand sides $[0; -C; 0]$ and $[0; -(J\dot q + [C_t; g])]$: Newton
//!   updates $\Delta q = -M^{-1}J^\mathsf{T}(JM^{-1}J^\mathsf{T})^{-1}[C; 0]$, then the
//!   velocity change of least kinetic energy); otherwise (no generated solve,
//!   redundant rows) orthogonally, by Newton with minimum-norm corrections
//!   $\Delta q = -C_q^\mathsf{T}(C_qC_q^\mathsf{T})^{-1}C$ and
//!   $\dot q \leftarrow \dot q - J^\mathsf{T}(JJ^\mathsf{T})^{-1}(J\dot q + [C_t; g])$,
//!   dense in $m$. Either meets $C$ to the Newton tolerance and the velocity
//!   constraints to round-off (`docs/decisions/0034-projection-in-the-mass-metric.md`).
//! - [`Formulation::Baumgarte`]: index 1 on $y = [q; \dot q]$ with
//!   $\gamma_h \leftarrow \gamma_h - 2\alpha(C_q\dot q + C_t) - \beta^2 C$ and
//!   $\gamma_{nh} \leftarrow \gamma_{nh} - 2\alpha(G\dot q + g)$, so that the
//!   violations obey $\ddot C + 2\alpha\dot C + \beta^2 C = 0$ and
//!   $\dot h + 2\alpha h = 0$ ($h = G\dot q + g$): they are damped, not removed.
//!   [`Formulation::baumgarte`] gives the defaults $\alpha = \beta = 10\ \text{s}^{-1}$
//!   (critical damping, time constant 0.1 s; choose them a few times faster than the
//!   motion of interest and slower than what the step size can resolve).
//! - [`Formulation::Unconstrained`]: Lagrange's equations of the second kind in all
//!   coordinates, $M\ddot q = Q$, without multipliers (docs/theory.md (S2-22)): the
//!   constraints are not enforced. When the applied forces make the motion free
//!   (docs/theory.md §redundant-coordinates) they hold by themselves, and the monitors measure how well. The
//!   initial state is taken as given (prescriptions are written into it, nothing is
//!   assembled); $M$ is factored densely.
//!
//! # Example
//! ```
//! use pfaff::sim::{Formulation, Method, Simulation};
//!
//! /// A point mass on a rigid link, in Cartesian coordinates.
//! #[pfaff::mechanism]
//! pub mod pendulum {
//!     const m: f64 = 1.0;
//!     const l: f64 = 1.0;
//!     const g: f64 = 9.81;
//!     static x: Coordinate = Coordinate { q0: l, qd0: 0.0 };
//!     static y: Coordinate = Coordinate {};
//!     fn kinetic_energy() -> f64 {
//!         0.5 * m * (x.dot().powi(2) + y.dot().powi(2))
//!     }
//!     fn potential_energy() -> f64 {
//!         m * g * y
//!     }
//!     #[holonomic]
//!     fn rod() -> f64 {
//!         x.powi(2) + y.powi(2) - l.powi(2)
//!     }
//! }
//!
//! let model = pendulum::Model::default();
//! let run = Simulation::new(&model)
//!     .formulation(Formulation::Partitioning)
//!     .integrator(Method::Dop853)
//!     .tolerances(1e-10, 1e-12)
//!     .output_every(0.1)
//!     .run(2.0)?;
//! assert_eq!(run.trajectory.len(), 21);
//! assert!(run.monitors.max_position_violation < 1e-10);
//! assert!(run.monitors.max_energy_drift.unwrap() < 1e-7);
//! # Ok::<(), pfaff::sim::SimError>(())
//! ```

mod chart;
mod contacts;
mod driver;
mod error;
mod formulation;
mod guard;
mod point;
mod precision;
mod stepper;
mod system;
mod trajectory;

pub use contacts::{ContactEvent, ContactEventKind};
pub use error::{Monitored, NonFiniteSource, SimError, SimErrorKind, SingularMatrix};
pub use precision::{format_table, work_precision, Reference, Row, Sweep};
pub use system::{Failed, StateSpace};
pub use trajectory::{Monitors, Run, Stats, Trajectory};

use crate::{DynamicsParams, KinematicsParams, Mechanism, NewtonParams, PartitionParams};

/// The simulation's Newton tolerance (assembly and the states a run keeps: accepted,
/// output and projected ones), relative as in [`NewtonParams`].
///
/// A residual of $10^{-12}$ in the units of $C$ (metres for a loop closure of
/// centimetre-sized links) leaves angles wrong by $10^{-10}$, which a DOP853 run at
/// rtol $10^{-12}$ sees as noise. $10^{-14}$ keeps the coordinates at round-off.
pub const NEWTON_TOLERANCE: f64 = 1e-14;

/// The simulation's tolerance for the inconsistency of redundant constraints (see
/// [`DynamicsParams::redundant_tolerance`]).
///
/// A redundant row of $J$ is consistent on the constraint manifold, but the integrated
/// state sits off it by the Newton tolerance in positions and by the integration error
/// in velocities, and $J_D$ is then only nearly dependent on $J_R$. Measured on the
/// parallelogram (a redundant crank) swinging clear of its change points: at most
/// $10^{-13}$ relative at rtol $10^{-4}$ to $10^{-8}$; it grows without bound as the
/// motion approaches a singular configuration (about $10^{-6}$ near the parallelogram's
/// flat position), where the mechanism itself is singular. A redundant constraint that
/// contradicts the others gives a mismatch of order 1. $10^{-4}$ separates the two
/// with a wide margin on both sides (kinematic analysis at exact configurations keeps
/// $10^{-8}$).
pub const REDUNDANT_TOLERANCE: f64 = 1e-4;

/// The smallest step size a run over `[t0, t_end]` can start with anywhere in its span:
/// $32\,\varepsilon \max(|t_0|, |t_\text{end}|)$, above the integrators' underflow limits
/// ($10\,\varepsilon|t|$ for the Runge–Kutta methods, $4\varepsilon|t|$ for Adams). A
/// smaller first step given to [`Simulation::initial_step`] is raised to it (the
/// restarts after a re-partition start with it too, and would stop the run at the first
/// one after the time has grown).
#[must_use]
pub fn min_step(t0: f64, t_end: f64) -> f64 {
    32.0 * f64::EPSILON * t0.abs().max(t_end.abs())
}

/// How the constrained equations become an ODE (see the [module docs](self)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Formulation {
    /// Coordinate partitioning, docs/theory.md Algorithm D.
    Partitioning,
    /// Index 1 with projection of positions and velocities after each step.
    Projection,
    /// $M\ddot q = Q$ in all coordinates, without multipliers (docs/theory.md (S2-22)).
    Unconstrained,
    /// Index 1 with Baumgarte stabilization.
    Baumgarte {
        /// Velocity-level gain $\alpha$ [1/s].
        alpha: f64,
        /// Position-level gain $\beta$ [1/s].
        beta: f64,
    },
}

impl Formulation {
    /// Baumgarte with the defaults $\alpha = \beta = 10\ \text{s}^{-1}$.
    #[must_use]
    pub const fn baumgarte() -> Self {
        Self::Baumgarte {
            alpha: 10.0,
            beta: 10.0,
        }
    }

    /// The three formulations that enforce the constraints (Baumgarte with its
    /// defaults).
    pub const ALL: [Self; 3] = [Self::Partitioning, Self::Projection, Self::baumgarte()];

    /// A short name.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Self::Partitioning => "partitioning",
            Self::Projection => "projection",
            Self::Baumgarte { .. } => "baumgarte",
            Self::Unconstrained => "unconstrained",
        }
    }
}

/// The integrator (see [`crate::ode`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// Classical Runge–Kutta 4 with the fixed step `h` (tolerances are ignored).
    Rk4 {
        /// Step size.
        h: f64,
    },
    /// Dormand–Prince 5(4).
    Dopri5,
    /// Dormand–Prince 8(5,3).
    Dop853,
    /// Shampine–Gordon variable-order Adams.
    Adams,
    /// Radau IIA of order 5, implicit, for stiff systems (see [`crate::ode::Radau5`]).
    Radau5,
}

impl Method {
    /// The methods with error control (the explicit pairs, Adams and Radau IIA).
    pub const ADAPTIVE: [Self; 4] = [Self::Dopri5, Self::Dop853, Self::Adams, Self::Radau5];

    /// Whether the method forms $\partial f/\partial y$ by differences of the
    /// right-hand side (Radau5): the partitioning chart must then iterate to round-off,
    /// not to the integrator's tolerance (`driver::chart_tolerances`).
    pub(crate) const fn differences_rhs(self) -> bool {
        matches!(self, Self::Radau5)
    }

    /// Whether the method's dense output is less accurate than its steps (Radau5's
    /// collocation polynomial has the stage order 3, its steps order 5): a gap closing
    /// located on it is moved to where the steps put it (`contacts::refine`). The
    /// explicit pairs and Adams interpolate at their steps' accuracy.
    pub(crate) const fn coarse_dense_output(self) -> bool {
        matches!(self, Self::Radau5)
    }

    /// A short name.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Self::Rk4 { .. } => "rk4",
            Self::Dopri5 => "dopri5",
            Self::Dop853 => "dop853",
            Self::Adams => "adams",
            Self::Radau5 => "radau5",
        }
    }
}

/// Where rows of the trajectory are taken.
#[derive(Clone, Debug, PartialEq)]
enum Output {
    Steps,
    Every(f64),
    Times(Vec<f64>),
}

/// A simulation, configured by a builder and started by [`run`](Self::run).
///
/// Defaults: partitioning, DOP853, `rtol = 1e-6`, `atol = 1e-8`, a row at every
/// accepted step, start at $t = 0$ from the model's
/// [`initial_state`](Mechanism::initial_state), at most $10^6$ step attempts.
pub struct Simulation<'a, M: Mechanism + ?Sized> {
    mech: &'a M,
    formulation: Formulation,
    method: Method,
    rtol: f64,
    atol: f64,
    h_init: Option<f64>,
    h_max: Option<f64>,
    max_steps: u64,
    output: Output,
    t0: f64,
    initial: Option<(Vec<f64>, Vec<f64>)>,
    prescribed_q: Vec<(String, f64)>,
    prescribed_qd: Vec<(String, f64)>,
    kinematics: KinematicsParams,
    dynamics: DynamicsParams,
    progress: Option<Box<dyn FnMut(f64) + 'a>>,
    monitors: bool,
}

impl<M: Mechanism + ?Sized> std::fmt::Debug for Simulation<'_, M> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Simulation")
            .field("model", &self.mech.info().name)
            .field("formulation", &self.formulation)
            .field("method", &self.method)
            .field("rtol", &self.rtol)
            .field("atol", &self.atol)
            .field("output", &self.output)
            .finish_non_exhaustive()
    }
}

impl<'a, M: Mechanism + ?Sized> Simulation<'a, M> {
    /// A simulation of `mech` with the defaults.
    pub fn new(mech: &'a M) -> Self {
        Self {
            mech,
            formulation: Formulation::Partitioning,
            method: Method::Dop853,
            rtol: 1e-6,
            atol: 1e-8,
            h_init: None,
            h_max: None,
            max_steps: 1_000_000,
            output: Output::Steps,
            t0: 0.0,
            initial: None,
            prescribed_q: Vec::new(),
            prescribed_qd: Vec::new(),
            kinematics: KinematicsParams {
                partition: PartitionParams {
                    allow_redundant: true,
                    ..PartitionParams::default()
                },
                newton: NewtonParams {
                    tolerance: NEWTON_TOLERANCE,
                    ..NewtonParams::default()
                },
            },
            dynamics: DynamicsParams {
                redundant_tolerance: REDUNDANT_TOLERANCE,
                ..DynamicsParams::default()
            },
            progress: None,
            monitors: true,
        }
    }

    /// The formulation.
    #[must_use]
    pub fn formulation(mut self, formulation: Formulation) -> Self {
        self.formulation = formulation;
        self
    }

    /// The integrator.
    #[must_use]
    pub fn integrator(mut self, method: Method) -> Self {
        self.method = method;
        self
    }

    /// Relative and absolute tolerances of the adaptive integrators.
    #[must_use]
    pub fn tolerances(mut self, rtol: f64, atol: f64) -> Self {
        self.rtol = rtol;
        self.atol = atol;
        self
    }

    /// The first step size (also the first step after every restart). A step below
    /// [`min_step`] of the span, which the time could not resolve, is raised to it.
    #[must_use]
    pub fn initial_step(mut self, h: f64) -> Self {
        self.h_init = Some(h);
        self
    }

    /// The largest step size.
    #[must_use]
    pub fn max_step(mut self, h: f64) -> Self {
        self.h_max = Some(h);
        self
    }

    /// The largest number of step attempts (accepted and rejected, over all restarts).
    #[must_use]
    pub fn max_steps(mut self, n: u64) -> Self {
        self.max_steps = n;
        self
    }

    /// Rows at these times (increasing, within the span), by dense output; the start
    /// and the end are always recorded.
    #[must_use]
    pub fn output_times(mut self, times: &[f64]) -> Self {
        self.output = Output::Times(times.to_vec());
        self
    }

    /// Rows every `dt` from the start, by dense output; the end is always recorded. A
    /// grid of more than 2^26 rows is rejected ([`SimErrorKind::InvalidTimes`]).
    #[must_use]
    pub fn output_every(mut self, dt: f64) -> Self {
        self.output = Output::Every(dt);
        self
    }

    /// A row at every accepted step (the default).
    #[must_use]
    pub fn output_steps(mut self) -> Self {
        self.output = Output::Steps;
        self
    }

    /// The start time (default 0).
    #[must_use]
    pub fn start_time(mut self, t0: f64) -> Self {
        self.t0 = t0;
        self
    }

    /// The initial guess of $(q, \dot q)$ instead of the model's `initial_state`; it is
    /// made consistent by assembly.
    #[must_use]
    pub fn initial_state(mut self, q: &[f64], qd: &[f64]) -> Self {
        self.initial = Some((q.to_vec(), qd.to_vec()));
        self
    }

    /// Holds coordinate `name` at `value` during assembly.
    #[must_use]
    pub fn prescribe_coordinate(mut self, name: &str, value: f64) -> Self {
        self.prescribed_q.push((name.to_owned(), value));
        self
    }

    /// Holds the velocity of coordinate `name` at `value` during assembly.
    #[must_use]
    pub fn prescribe_velocity(mut self, name: &str, value: f64) -> Self {
        self.prescribed_qd.push((name.to_owned(), value));
        self
    }

    /// Tuning of assembly (K1, K2, Algorithm P) and of the Newton tolerance of kept
    /// states (default [`NEWTON_TOLERANCE`]).
    #[must_use]
    pub fn kinematics(mut self, params: KinematicsParams) -> Self {
        self.kinematics = params;
        self
    }

    /// Tuning of the augmented solve (dense or sparse path).
    #[must_use]
    pub fn dynamics(mut self, params: DynamicsParams) -> Self {
        self.dynamics = params;
        self
    }

    /// Whether the run is stopped with [`SimErrorKind::Diverged`] when its constraint
    /// violation, energy drift (conservative models) or coordinates grow beyond what
    /// the tolerance and the motion's scale allow (on by default). Off, a diverging
    /// run goes on until it fails otherwise or ends: for studying the divergence
    /// itself, or the failure it leads to.
    #[must_use]
    pub fn monitors(mut self, on: bool) -> Self {
        self.monitors = on;
        self
    }

    /// Calls `f(t)` after every accepted step (for a progress bar).
    #[must_use]
    pub fn on_progress(mut self, f: impl FnMut(f64) + 'a) -> Self {
        self.progress = Some(Box::new(f));
        self
    }

    /// Simulates from the start time to `t_end`. With `t_end` equal to the start time
    /// the run is the assembled initial state: one row, no step.
    ///
    /// # Errors
    /// A [`SimError`] with the cause and the rows computed before it.
    pub fn run(&mut self, t_end: f64) -> Result<Run, SimError> {
        driver::run(self, t_end)
    }
}
