//! The error of a simulation: a typed [`SimErrorKind`] together with the partial
//! [`Run`] computed before the failure.
//!
//! Input: failures of assembly, of the analyses inside the right-hand side (boxed as
//! [`RhsError`](crate::ode::RhsError) by the integrators) and of the integrators.
//! Output: one kind per cause, each with the time and what is known about it (the
//! constraints involved, the iterations, the residual).

use std::fmt;

use super::trajectory::Run;
use crate::dynamics::DynamicsError;
use crate::kinematics::KinematicsError;
use crate::ode::{OdeError, Quantity as OdeQuantity};
use crate::workspace::{EvalError, Quantity};
use crate::{AssemblyError, Error};

/// Which matrix was singular.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SingularMatrix {
    /// $C_\beta$ in the position analysis K1 (partitioning).
    DependentPositions,
    /// $J_d$ in the velocity analysis K2 (partitioning).
    DependentVelocities,
    /// The augmented matrix of (E31) with $J$ of the given rank.
    Augmented {
        /// Numerical rank of $J$.
        rank: usize,
    },
    /// $J J^\mathsf{T}$ (or $C_q C_q^\mathsf{T}$) in a projection.
    Projection,
    /// The mass matrix (unconstrained formulation: not positive definite).
    Mass,
}

impl fmt::Display for SingularMatrix {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::DependentPositions => f.write_str("dependent Jacobian `C_beta`"),
            Self::DependentVelocities => f.write_str("dependent velocity Jacobian `J_d`"),
            Self::Augmented { rank } => write!(f, "augmented matrix (rank of `J` {rank})"),
            Self::Projection => f.write_str("projection matrix `J J^T`"),
            Self::Mass => f.write_str("mass matrix `M`"),
        }
    }
}

/// Where a NaN or an infinity appeared.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NonFiniteSource {
    /// A function of the model, at entry `(row, col)`.
    Model {
        /// The quantity.
        quantity: Quantity,
        /// Row (or vector index).
        row: usize,
        /// Column, for matrices.
        col: Option<usize>,
    },
    /// A state or derivative of the integrator, at component `component` of its state.
    Integrator {
        /// State or derivative.
        quantity: OdeQuantity,
        /// Component of the integrator's state.
        component: usize,
    },
}

impl fmt::Display for NonFiniteSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Model {
                quantity,
                row,
                col: Some(c),
            } => write!(f, "{quantity}, entry ({row}, {c})"),
            Self::Model { quantity, row, .. } => write!(f, "{quantity}, entry {row}"),
            Self::Integrator {
                quantity,
                component,
            } => write!(f, "integrator {quantity}, component {component}"),
        }
    }
}

/// What grew in a [`SimErrorKind::Diverged`] run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Monitored {
    /// The distance of the positions from a holonomic constraint's surface,
    /// $|C_i| / \lVert (C_q)_i\rVert_\infty$ in the units of $q$, against the size of
    /// the coordinates it involves.
    PositionViolation {
        /// The constraint farthest from being met.
        constraint: &'static str,
    },
    /// $|E - E_0|$ of a conservative model (the impacts' losses set apart), against its
    /// energy scale (the largest kinetic energy and the range of the potential energy
    /// seen so far).
    EnergyDrift,
    /// The size of the coordinates $\lVert q\rVert_\infty$ (the largest named),
    /// against the motion's scale at the start: $\lVert q_0\rVert_\infty +
    /// \lVert\dot q_0\rVert_\infty T + \lVert\ddot q_0\rVert_\infty T^2/2$ over the
    /// span $T$.
    Coordinates {
        /// The largest coordinate.
        coordinate: &'static str,
    },
}

impl Monitored {
    fn bound_reason(self) -> &'static str {
        match self {
            Self::PositionViolation { .. } => {
                "1e4 times the tolerance at the size of the coordinates the constraint \
                 involves, at most 5 % of that size (Baumgarte: 5 %; a fixed step: 50 %): \
                 the integration has left the motion; tighten the tolerance, shorten the \
                 step, or use partitioning or projection"
            }
            Self::Coordinates { .. } => {
                "1e6 times the motion's scale at the start (the size of q0 plus the \
                 distances its initial velocities and accelerations cover in the span): \
                 the integration diverged; tighten the tolerance or shorten the step"
            }
            Self::EnergyDrift => {
                "1e4 times the tolerance of the energy the motion exchanges (largest kinetic \
                 energy, range of the potential), at most 5 % of it (a fixed step: 50 %): \
                 the integration has left the motion; tighten the tolerance or shorten the \
                 step"
            }
        }
    }
}

impl fmt::Display for Monitored {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::PositionViolation { constraint } => write!(
                f,
                "the violation of constraint `{constraint}` (the distance of q from its \
                 surface, |C_i| / |(C_q)_i|, in the units of q)"
            ),
            Self::EnergyDrift => f.write_str("the energy drift |E - E0|"),
            Self::Coordinates { coordinate } => {
                write!(f, "the size of the coordinates (|{coordinate}|)")
            }
        }
    }
}

/// Why a simulation failed.
#[derive(Debug, thiserror::Error)]
pub enum SimErrorKind {
    /// The time span or the output times are invalid (including an `output_every`
    /// spacing so fine that the grid would have more than 2^26 rows).
    #[error(
        "invalid time span or output times: t0 = {t0}, t_end = {t_end}, offending value {value:e}"
    )]
    InvalidTimes {
        /// Start time.
        t0: f64,
        /// End time.
        t_end: f64,
        /// The value that is out of order, out of the span or not finite.
        value: f64,
    },
    /// A user-given initial state has the wrong length.
    #[error("initial {what} has length {found}, expected {expected}")]
    InitialLength {
        /// `"coordinates"` or `"velocities"`.
        what: &'static str,
        /// Length given.
        found: usize,
        /// The model's number of coordinates.
        expected: usize,
    },
    /// Consistent initial conditions could not be assembled.
    #[error("cannot assemble the initial conditions: {0}")]
    Assembly(#[from] AssemblyError),
    /// The initial positions put a contact's gap below zero by more than the
    /// consistency tolerance: the bodies start inside each other.
    #[error("the initial state penetrates contact `{contact}` at t = {t:?}: its gap is {gap:e} (below -{tolerance:.1e}); start the contact touching (gap 0) or open")]
    InitialPenetration {
        /// Time.
        t: f64,
        /// The deepest penetrating contact.
        contact: &'static str,
        /// Its gap, negative.
        gap: f64,
        /// The largest penetration accepted as touching.
        tolerance: f64,
    },
    /// The mass matrix at the initial state has a direction of negative kinetic
    /// energy ([`crate::inertia`]): the model has no physical motion.
    #[error("the kinetic energy is negative in a direction of `{coordinate}` at t = {t:?}: {}", crate::inertia::explain(*ratio))]
    NegativeMass {
        /// Time.
        t: f64,
        /// The coordinate whose pivot is negative (the direction involves it and
        /// coordinates before it).
        coordinate: &'static str,
        /// The pivot over its diagonal.
        ratio: f64,
    },
    /// A Newton iteration (K1 or the position projection) did not converge.
    #[error("Newton iteration failed at t = {t:?} after {iterations} iterations: residual {residual:e}, {}", involved("constraints", constraints, "every residual is within the tolerance, the iteration stalled or kept landing on another solution branch"))]
    NewtonFailed {
        /// Time.
        t: f64,
        /// Iterations performed.
        iterations: usize,
        /// Final $\lVert C\rVert_\infty$.
        residual: f64,
        /// Constraints whose residual exceeds the tolerance, or else (a stall on a
        /// singular Jacobian) those that take part in a near dependence of $C_q$ at the
        /// last recorded state (its left singular vectors, see `partition`).
        constraints: Vec<&'static str>,
    },
    /// A matrix became singular.
    #[error("singular {matrix} at t = {t:?} (pivot ratio {ratio:e}); {}", involved("constraints", constraints, "no residual exceeds the tolerance and no constraints are nearly dependent at the last recorded state"))]
    Singular {
        /// Time.
        t: f64,
        /// Which matrix.
        matrix: SingularMatrix,
        /// Smallest / largest pivot.
        ratio: f64,
        /// Holonomic constraints whose residual exceeded the tolerance at that point,
        /// or else those that take part in a near dependence of $C_q$ at the last
        /// recorded state (its left singular vectors: the whole dependent set).
        constraints: Vec<&'static str>,
    },
    /// The augmented matrix of (E31) is singular while $J$ has full rank: the mass
    /// matrix is singular on the tangent space of the constraints (a massless
    /// coordinate that no constraint determines, for instance).
    ///
    /// Or its constraint block is what fails: the kept rows of $J$ nearly dependent
    /// (`nearly_dependent` names them; see [`crate::DynamicsError::Singular`]), a
    /// near-singular configuration rather than a singular mass matrix.
    #[error("singular augmented matrix at t = {t:?} (pivot ratio {ratio:e}): {}", singular_mass_cause(*jacobian_ratio, nearly_dependent, coordinates))]
    SingularMass {
        /// Time.
        t: f64,
        /// Smallest / largest pivot of the equilibrated matrix.
        ratio: f64,
        /// The coordinates whose accelerations are undetermined.
        coordinates: Vec<&'static str>,
        /// Smallest / largest pivot of the kept rows of $J$.
        jacobian_ratio: f64,
        /// The constraints within [`crate::NEARLY_DEPENDENT`] of dependence on the
        /// others (empty: the mass matrix is what is singular).
        nearly_dependent: Vec<&'static str>,
    },
    /// The step size fell below what the precision of `t` resolves.
    #[error(
        "step size {h:e} too small at t = {t:?}{}",
        lock_clause(nearly_dependent)
    )]
    StepSizeTooSmall {
        /// Time of the last accepted state.
        t: f64,
        /// Step size.
        h: f64,
        /// The holonomic constraints that take part in a near dependence of $C_q$ at
        /// the last recorded state (a singular value below $10^{-3}$ of the largest,
        /// rows at unit length): a lock or singular configuration where the
        /// accelerations grow without bound. Empty when $C_q$ is well conditioned
        /// there (stiffness, a discontinuity).
        nearly_dependent: Vec<&'static str>,
    },
    /// More step attempts than allowed.
    #[error("more than {steps} step attempts, at t = {t:?}")]
    MaxSteps {
        /// Time of the last accepted state.
        t: f64,
        /// The limit.
        steps: u64,
    },
    /// A monitored quantity of an accepted state grew beyond what the run's tolerance
    /// and the model's scale allow (see [`Monitored`]): the integration has left the
    /// motion it was asked for, and its rows from there on would be a wrong answer.
    #[error("{quantity} grew to {value:e} at t = {t:?}, beyond its bound {bound:e} ({})", quantity.bound_reason())]
    Diverged {
        /// Time of the accepted state.
        t: f64,
        /// What grew.
        quantity: Monitored,
        /// Its value there.
        value: f64,
        /// The largest value the tolerance and the model's scale allow.
        bound: f64,
    },
    /// Baumgarte stabilization reached a configuration where the constraints are
    /// dependent (their Jacobian lost rank) although they were independent at the
    /// start: a singular configuration (a lock, a change point, a rolling disk lying
    /// flat). Its equations keep a solution there (the minimum-norm split of the
    /// dependent rows), so the run would go on through it onto any branch;
    /// partitioning and projection stop there.
    #[error("the constraints {constraints:?} became dependent at t = {t:?}: a singular configuration, which Baumgarte stabilization would integrate through onto an arbitrary branch")]
    SingularConfiguration {
        /// Time of the accepted state.
        t: f64,
        /// The constraints found dependent on the others.
        constraints: Vec<&'static str>,
    },
    /// Baumgarte stabilization with a fixed step the method cannot integrate stably:
    /// the constraint error obeys $\ddot e + 2\alpha\dot e + \beta^2 e = 0$ (and
    /// $\dot e + 2\alpha e = 0$ for non-holonomic rows), whose fastest rate
    /// `rate` times `h` lies outside the method's region of absolute stability.
    #[error("Baumgarte stabilization (alpha = {alpha}, beta = {beta}) is unstable with the fixed step h = {h:e}: its constraint error decays at rate {rate:e} 1/s, and h * rate must stay below {limit} for the method; take h <= {:e} or smaller gains", limit / rate)]
    BaumgarteUnstable {
        /// The fixed step.
        h: f64,
        /// Velocity-level gain.
        alpha: f64,
        /// Position-level gain.
        beta: f64,
        /// The largest magnitude of the eigenvalues of the constraint error's dynamics.
        rate: f64,
        /// The stability limit of $h \cdot$ rate of the method on the negative real axis.
        limit: f64,
    },
    /// The integration stopped making progress: at the rate of its last `window`
    /// step attempts, which advanced the time by `advance`, the rest of the span would
    /// need `needed` attempts, more than 100 times the `budget` of attempts left
    /// ([`Simulation::max_steps`](super::Simulation::max_steps)). A run creeping at
    /// step sizes far below its span (a singular configuration, a state the
    /// formulation keeps failing at) ends here instead of running for hours into its
    /// step limit.
    #[error("no progress at t = {t:?}: the last {window} step attempts advanced the time by {advance:e}, at which rate the remaining span needs {needed:e} attempts, more than 100 times the {budget} left{}", lock_clause(nearly_dependent))]
    NoProgress {
        /// Time of the last accepted state.
        t: f64,
        /// The attempts of the window.
        window: u64,
        /// The time they advanced.
        advance: f64,
        /// The attempts the rest of the span needs at that rate.
        needed: f64,
        /// The attempts left before the step limit.
        budget: u64,
        /// The holonomic constraints nearly dependent at the last accepted state (see
        /// [`Self::StepSizeTooSmall`]).
        nearly_dependent: Vec<&'static str>,
    },
    /// A NaN or an infinity.
    #[error("non-finite value at t = {t:?} in the {source_of}")]
    NonFinite {
        /// Time.
        t: f64,
        /// Where it appeared.
        source_of: NonFiniteSource,
    },
    /// Another failure of the analyses (redundant constraints that contradict each
    /// other, a failed partition, malformed patterns).
    #[error(transparent)]
    Analysis(Error),
    /// Another failure of the integrator (invalid tolerances or step sizes).
    #[error(transparent)]
    Integrator(OdeError),
    /// An impact could not be solved (a singular configuration names the constraints
    /// and contacts of the dependent set), or a resting contact's equations failed.
    #[error(transparent)]
    Impact(crate::ImpactError),
}

impl SimErrorKind {
    /// The time of the failure, when it is tied to one.
    #[must_use]
    pub fn t(&self) -> Option<f64> {
        match self {
            Self::NewtonFailed { t, .. }
            | Self::NegativeMass { t, .. }
            | Self::Singular { t, .. }
            | Self::SingularMass { t, .. }
            | Self::StepSizeTooSmall { t, .. }
            | Self::MaxSteps { t, .. }
            | Self::Diverged { t, .. }
            | Self::SingularConfiguration { t, .. }
            | Self::NoProgress { t, .. }
            | Self::NonFinite { t, .. } => Some(*t),
            Self::Impact(
                crate::ImpactError::Singular { t, .. } | crate::ImpactError::SingularMass { t, .. },
            ) => Some(*t),
            Self::Analysis(Error::Dynamics(
                DynamicsError::Singular { t, .. } | DynamicsError::InconsistentRedundant { t, .. },
            )) => Some(*t),
            Self::Analysis(Error::Kinematics(
                KinematicsError::NewtonFailed { t, .. }
                | KinematicsError::SingularDependent { t, .. }
                | KinematicsError::SingularVelocity { t, .. }
                | KinematicsError::BranchSwitch { t, .. },
            )) => Some(*t),
            _ => None,
        }
    }

    /// Classifies an error of the analyses; `constraints` names the holonomic
    /// constraints not met when a singular matrix stopped a Newton iteration.
    pub(crate) fn from_analysis(e: Error, constraints: Vec<&'static str>) -> Self {
        match e {
            Error::Kinematics(KinematicsError::NewtonFailed {
                t,
                iterations,
                residual,
                violated,
            }) => Self::NewtonFailed {
                t,
                iterations,
                residual,
                constraints: violated,
            },
            // A branch switch that a step at the underflow limit still produces is a
            // failure of K1 to follow the motion.
            Error::Kinematics(KinematicsError::BranchSwitch {
                t,
                iterations,
                residual,
            }) => Self::NewtonFailed {
                t,
                iterations,
                residual,
                constraints,
            },
            Error::Kinematics(KinematicsError::SingularDependent { t, ratio, .. }) => {
                Self::Singular {
                    t,
                    matrix: SingularMatrix::DependentPositions,
                    ratio,
                    constraints,
                }
            }
            Error::Kinematics(KinematicsError::SingularVelocity { t, ratio }) => Self::Singular {
                t,
                matrix: SingularMatrix::DependentVelocities,
                ratio,
                constraints,
            },
            Error::Dynamics(DynamicsError::Singular {
                t,
                ratio,
                coordinates,
                jacobian_ratio,
                nearly_dependent,
                ..
            }) => Self::SingularMass {
                t,
                ratio,
                coordinates,
                jacobian_ratio,
                nearly_dependent,
            },
            Error::Eval(e)
            | Error::Kinematics(KinematicsError::Eval(e))
            | Error::Dynamics(DynamicsError::Eval(e)) => Self::from_eval(e),
            other => Self::Analysis(other),
        }
    }

    pub(crate) fn from_eval(e: EvalError) -> Self {
        match e {
            EvalError::NonFinite {
                quantity,
                t,
                row,
                col,
                ..
            } => Self::NonFinite {
                t,
                source_of: NonFiniteSource::Model { quantity, row, col },
            },
            other => Self::Analysis(other.into()),
        }
    }

    /// Classifies an integrator error (a failed evaluation's own kind is held by the
    /// system that failed, see `System::take_failure`).
    pub(crate) fn from_ode(e: OdeError) -> Self {
        match e {
            OdeError::StepSizeTooSmall { t, h } => Self::StepSizeTooSmall {
                t,
                h,
                nearly_dependent: Vec::new(),
            },
            OdeError::MaxStepsExceeded { t, steps } => Self::MaxSteps { t, steps },
            OdeError::NonFinite {
                t,
                component,
                quantity,
            } => Self::NonFinite {
                t,
                source_of: NonFiniteSource::Integrator {
                    quantity,
                    component,
                },
            },
            other => Self::Integrator(other),
        }
    }
}

/// The cause clause of [`SimErrorKind::SingularMass`].
fn singular_mass_cause(jacobian_ratio: f64, nearly: &[&str], coordinates: &[&str]) -> String {
    if nearly.is_empty() {
        format!(
            "the mass matrix is singular on the constraint tangent space; {}",
            involved(
                "coordinates",
                coordinates,
                "the singular direction mixes accelerations and multipliers"
            )
        )
    } else {
        crate::dynamics::near_singular_clause(jacobian_ratio, nearly)
    }
}

/// `"{what} involved: [..]"`, or why none can be named.
/// The clause of a step-size failure at a near-singular configuration.
fn lock_clause(nearly_dependent: &[&str]) -> String {
    if nearly_dependent.is_empty() {
        String::new()
    } else {
        format!(
            ": the constraints {nearly_dependent:?} are nearly dependent there (a lock or \
             singular configuration of the mechanism, where the accelerations grow without \
             bound)"
        )
    }
}

fn involved(what: &str, names: &[&str], otherwise: &str) -> String {
    if names.is_empty() {
        format!("no {what} identified: {otherwise}")
    } else {
        format!("{what} involved: {names:?}")
    }
}

/// A failed simulation: why, and the run up to the failure.
#[derive(Debug)]
pub struct SimError {
    /// The cause.
    pub kind: SimErrorKind,
    /// Rows, statistics and monitors up to the last accepted step before the failure.
    pub partial: Box<Run>,
}

impl SimError {
    /// The time of the failure, when it is tied to one.
    #[must_use]
    pub fn t(&self) -> Option<f64> {
        self.kind.t()
    }
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "simulation failed: {}", self.kind)?;
        if let Some((t, _, _)) = self.partial.final_state() {
            write!(
                f,
                " ({} rows kept, the last at t = {t:?})",
                self.partial.trajectory.len()
            )?;
        }
        Ok(())
    }
}

impl std::error::Error for SimError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.kind)
    }
}
