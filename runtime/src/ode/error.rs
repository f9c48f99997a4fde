//! Errors of the integrators, each carrying where it happened.
//!
//! Input: failures detected while stepping (step size underflow, work limit, NaN or
//! infinity, a failing right-hand side) or bad arguments.
//! Output: one [`OdeError`] enum. Invariant: after any error the integrator still
//! holds the last accepted state, readable with `t()` and `y()`.

use super::system::RhsError;

/// Which quantity held a NaN or an infinity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// The output of [`OdeSystem::rhs`](super::OdeSystem::rhs).
    Derivative,
    /// A state: the initial one, one given to `set_state`, or a newly computed one.
    State,
}

impl std::fmt::Display for Quantity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Quantity::Derivative => "derivative",
            Quantity::State => "state",
        })
    }
}

/// An error of an ODE integrator.
#[derive(Debug, thiserror::Error)]
pub enum OdeError {
    /// The step size fell below what the precision of `t` can resolve.
    #[error("step size {h:e} too small at t = {t:?}")]
    StepSizeTooSmall {
        /// Time of the last accepted state.
        t: f64,
        /// The step size that was too small.
        h: f64,
    },
    /// More step attempts (accepted and rejected) since the last `reset` than allowed.
    #[error("more than {steps} step attempts since the last reset, at t = {t:?}")]
    MaxStepsExceeded {
        /// Time of the last accepted state.
        t: f64,
        /// The limit `max_steps` that was reached.
        steps: u64,
    },
    /// A NaN or an infinity in a derivative or a state.
    #[error("non-finite {quantity} in component {component} at t = {t:?}")]
    NonFinite {
        /// Time at which the value was produced (a stage time for a derivative).
        t: f64,
        /// Index of the first non-finite component.
        component: usize,
        /// Whether a derivative or a state was non-finite.
        quantity: Quantity,
    },
    /// The right-hand side failed; `source` is the system's own error.
    #[error("right-hand side failed at t = {t:?}")]
    Rhs {
        /// Time at which the right-hand side was evaluated.
        t: f64,
        /// The system's error, recoverable with [`RhsError::downcast`].
        #[source]
        source: RhsError,
    },
    /// A slice had the wrong length.
    #[error("dimension mismatch: expected {expected}, found {found}")]
    DimensionMismatch {
        /// The integrator's dimension.
        expected: usize,
        /// The length that was given.
        found: usize,
    },
    /// `rtol` must be finite, non-negative and at most 1, `atol` finite and positive
    /// (for every component).
    #[error("invalid tolerances rtol = {rtol:e}, atol = {atol:e}: expected 0 <= rtol <= 1 and a finite atol > 0")]
    InvalidTolerance {
        /// The relative tolerance.
        rtol: f64,
        /// The (smallest) absolute tolerance.
        atol: f64,
    },
    /// A step size given as an argument or option is zero, negative where a magnitude
    /// is expected, or not finite.
    #[error("invalid step size {h:e}")]
    InvalidStepSize {
        /// The step size that was given.
        h: f64,
    },
    /// `t_stop` lies behind the current time in the direction of integration.
    #[error("t_stop = {t_stop:?} lies behind t = {t:?} in the direction of integration")]
    StopBehind {
        /// Current time.
        t: f64,
        /// The stop time that was given.
        t_stop: f64,
    },
    /// Dense output was asked outside the last step.
    #[error("t = {t:?} lies outside the last step [{t_prev:?}, {t_cur:?}]")]
    OutsideStep {
        /// Requested time.
        t: f64,
        /// Start of the last step.
        t_prev: f64,
        /// End of the last step.
        t_cur: f64,
    },
    /// No dense output for the last step: it was switched off in the options, or a
    /// failed step overwrote the history it is built from.
    #[error("dense output is unavailable: disabled in the options or lost by a failed step")]
    DenseOutputUnavailable,
    /// `step` was called before `reset`.
    #[error("the integrator has no state, call `reset` first")]
    NotStarted,
}

impl OdeError {
    /// The time at which the error happened, when it is tied to one.
    pub fn t(&self) -> Option<f64> {
        match *self {
            OdeError::StepSizeTooSmall { t, .. }
            | OdeError::MaxStepsExceeded { t, .. }
            | OdeError::NonFinite { t, .. }
            | OdeError::Rhs { t, .. }
            | OdeError::StopBehind { t, .. }
            | OdeError::OutsideStep { t, .. } => Some(t),
            _ => None,
        }
    }

    /// Recovers the system's typed error from an [`OdeError::Rhs`], with its time.
    ///
    /// # Errors
    /// Returns `self` unchanged if it is another variant or holds another error type.
    pub fn into_rhs_error<E: std::error::Error + 'static>(self) -> Result<(f64, E), Self> {
        match self {
            OdeError::Rhs { t, source } => source
                .downcast::<E>()
                .map(|e| (t, e))
                .map_err(|source| OdeError::Rhs { t, source }),
            other => Err(other),
        }
    }
}
