//! The stepping interface every integrator implements.
//!
//! Input: an [`OdeSystem`], an initial state given to [`Integrator::reset`], and stop
//! times. Output: one accepted step per [`Integrator::step`], the state at its end and
//! dense output on it.
//! Invariants: between calls the integrator holds an accepted state $(t, y)$ and the
//! previous step $[t_{\text{prev}}, t]$; it never steps past a `t_stop`; all scratch is
//! allocated by the constructor, so stepping does not allocate.

use super::error::OdeError;
use super::options::OdeStats;
use super::system::OdeSystem;

/// A one-step-at-a-time ODE integrator.
///
/// The direction of integration is fixed at [`reset`](Self::reset): backward when the
/// given initial step is negative, forward otherwise.
///
/// ```
/// use pfaff::ode::{Dopri5, Integrator, OdeOptions, OdeSystem, RhsError};
///
/// struct Decay;
/// impl OdeSystem for Decay {
///     fn dim(&self) -> usize { 1 }
///     fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
///         dy[0] = -y[0];
///         Ok(())
///     }
/// }
///
/// let mut sys = Decay;
/// let mut ode = Dopri5::new(1, OdeOptions::with_tol(1e-10))?;
/// ode.reset(&mut sys, 0.0, &[1.0], None)?;
/// ode.integrate_to(&mut sys, 1.0)?;
/// assert!((ode.y()[0] - (-1.0f64).exp()).abs() < 1e-9);
/// # Ok::<(), pfaff::ode::OdeError>(())
/// ```
pub trait Integrator {
    /// The dimension $n$ of the state.
    fn dim(&self) -> usize;

    /// Starts (again) from $y(t_0) = y_0$, discarding all history: the multistep method
    /// returns to order 1. Used at the start, after discontinuities, impacts and
    /// re-partitions. `h0` overrides the option `h_init`; its sign sets the direction.
    ///
    /// # Errors
    /// Wrong lengths, a non-finite `y0`, an invalid `h0`, or a failure of the first
    /// evaluations of the right-hand side.
    fn reset<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t0: f64,
        y0: &[f64],
        h0: Option<f64>,
    ) -> Result<(), OdeError>;

    /// Takes one accepted step, retrying rejected attempts internally, and returns the
    /// new time. With `Some(t_stop)` the step ends at `t_stop` at the latest (exactly
    /// on it when it gets there); when already at `t_stop` nothing is done.
    ///
    /// # Errors
    /// See [`OdeError`]. The state of the last accepted step stays readable.
    fn step<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t_stop: Option<f64>,
    ) -> Result<f64, OdeError>;

    /// Time of the current state.
    fn t(&self) -> f64;

    /// Start time of the last accepted step (equal to [`t`](Self::t) right after reset).
    fn t_prev(&self) -> f64;

    /// The current state.
    fn y(&self) -> &[f64];

    /// The step size the method proposes for its next attempt.
    fn h_next(&self) -> f64;

    /// Writes the dense-output approximation of $y(t)$ for $t$ in the last step
    /// $[t_{\text{prev}}, t]$ into `out`.
    ///
    /// # Errors
    /// [`OdeError::OutsideStep`], [`OdeError::DimensionMismatch`], or
    /// [`OdeError::DenseOutputUnavailable`].
    fn interpolate(&self, t: f64, out: &mut [f64]) -> Result<(), OdeError>;

    /// Overwrites the current state after a small external correction (a projection
    /// onto a constraint manifold) without restarting. See each method for what happens
    /// to its history and dense output.
    ///
    /// # Errors
    /// A wrong length or a non-finite value; the state is then left unchanged.
    fn set_state(&mut self, y: &[f64]) -> Result<(), OdeError>;

    /// Like [`set_state`](Self::set_state), for a correction to which the right-hand
    /// side is invariant, $f(t, y_\text{new}) = f(t, y)$ (moving coordinates that $f$
    /// recomputes from the others, as the partitioning formulation of [`crate::sim`]
    /// does): the derivative the method keeps for the current state stays valid, so an
    /// embedded pair reuses it (FSAL) instead of evaluating $f$ again. The default is
    /// [`set_state`](Self::set_state), right for methods whose `set_state` keeps it.
    ///
    /// # Errors
    /// As [`set_state`](Self::set_state).
    fn set_state_keeping_derivative(&mut self, y: &[f64]) -> Result<(), OdeError> {
        self.set_state(y)
    }

    /// Work counters.
    fn stats(&self) -> &OdeStats;

    /// Steps until `t_end` is reached exactly (never past it).
    ///
    /// # Errors
    /// The first error of [`step`](Self::step).
    fn integrate_to<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t_end: f64,
    ) -> Result<(), OdeError> {
        while self.t() != t_end {
            self.step(sys, Some(t_end))?;
        }
        Ok(())
    }
}
