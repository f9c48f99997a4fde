//! The right-hand side of an ODE, $y' = f(t, y)$, and the error it may report.
//!
//! Input: an implementation of [`OdeSystem`] of fixed dimension $n$.
//! Output: $f(t, y)$ written into a caller-owned buffer of length $n$.
//! Invariants: `dim()` does not change while an integrator uses the system; `rhs`
//! writes every component of `dy` (integrators check the values for NaN and infinity).

use std::error::Error;
use std::fmt;

/// The right-hand side of $y' = f(t, y)$.
///
/// `rhs` takes `&mut self` so that implementations can keep scratch buffers, caches
/// and warm starts (a Newton iterate, a factorization) between calls.
///
/// ```
/// use pfaff::ode::{OdeSystem, RhsError};
///
/// /// The harmonic oscillator $y_0' = y_1$, $y_1' = -y_0$.
/// struct Oscillator;
///
/// impl OdeSystem for Oscillator {
///     fn dim(&self) -> usize {
///         2
///     }
///     fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
///         dy[0] = y[1];
///         dy[1] = -y[0];
///         Ok(())
///     }
/// }
/// ```
pub trait OdeSystem {
    /// The dimension $n$ of the state.
    fn dim(&self) -> usize;

    /// Writes $f(t, y)$ into `dy`; both slices have length [`dim`](Self::dim).
    ///
    /// # Errors
    /// Any failure of the model (a Newton iteration that did not converge, a singular
    /// matrix), wrapped with [`RhsError::new`]: the integrator stops and returns it
    /// unchanged inside [`OdeError::Rhs`](crate::ode::OdeError::Rhs). A failure wrapped
    /// with [`RhsError::recoverable`] instead rejects the step attempt: the adaptive
    /// integrators retry with a quarter of the step (counted in
    /// [`OdeStats::rejected`](crate::ode::OdeStats::rejected)), [`Rk4`](crate::ode::Rk4)
    /// shortens the step by halves, and the error is returned only when the step size
    /// underflows.
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError>;

    /// Told just before an evaluation at the state a step ends in, $f(t_{n+1},
    /// y_{n+1})$ (DOP853's and DOPRI5's first-same-as-last stage), which the caller
    /// keeps if the step is accepted: a system that corrects or monitors the states it
    /// keeps may compute with that evaluation what it reads there next. The default
    /// does nothing.
    fn step_end_next(&mut self) {}

    /// Told before (`true`) and after (`false`) evaluations that are not part of the
    /// solution, made only for the interpolant (DOP853's dense stages, computed on
    /// the steps where the caller interpolates): a system that learns from its
    /// evaluations (a contraction rate) should not learn from these, so that the
    /// steps do not depend on where the caller interpolates. The default does nothing.
    fn aside(&mut self, _on: bool) {}
}

/// A failure reported by [`OdeSystem::rhs`], carrying the system's own typed error.
///
/// The error is boxed so that the integrators need not be generic over it; the caller
/// gets its type back with [`downcast`](Self::downcast) or
/// [`downcast_ref`](Self::downcast_ref). `Display` and `source()` are those of the
/// wrapped error (the wrapper is transparent).
///
/// ```
/// use pfaff::ode::RhsError;
///
/// #[derive(Debug, PartialEq)]
/// struct Singular(usize);
/// impl std::fmt::Display for Singular {
///     fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
///         write!(f, "singular pivot {}", self.0)
///     }
/// }
/// impl std::error::Error for Singular {}
///
/// let e = RhsError::new(Singular(3));
/// assert_eq!(e.to_string(), "singular pivot 3");
/// assert_eq!(e.downcast::<Singular>().unwrap(), Singular(3));
/// ```
pub struct RhsError(Box<dyn Error + Send + Sync + 'static>, bool);

impl RhsError {
    /// Wraps a typed error of the system: the integration stops.
    pub fn new<E: Error + Send + Sync + 'static>(error: E) -> Self {
        Self(Box::new(error), false)
    }

    /// Wraps a typed error of the system that a shorter step may avoid (a Newton
    /// iteration that diverged or converged to another solution branch from a guess
    /// extrapolated too far): the integrator rejects the attempt and retries smaller.
    ///
    /// ```
    /// use pfaff::ode::RhsError;
    ///
    /// assert!(RhsError::recoverable(std::fmt::Error).is_recoverable());
    /// assert!(!RhsError::new(std::fmt::Error).is_recoverable());
    /// ```
    pub fn recoverable<E: Error + Send + Sync + 'static>(error: E) -> Self {
        Self(Box::new(error), true)
    }

    /// Whether the failure only rejects the step attempt (see [`recoverable`](Self::recoverable)).
    pub fn is_recoverable(&self) -> bool {
        self.1
    }

    /// Whether the wrapped error has type `E`.
    pub fn is<E: Error + 'static>(&self) -> bool {
        self.0.is::<E>()
    }

    /// A reference to the wrapped error if it has type `E`.
    pub fn downcast_ref<E: Error + 'static>(&self) -> Option<&E> {
        self.0.downcast_ref::<E>()
    }

    /// The wrapped error by value if it has type `E`, otherwise `self` unchanged.
    ///
    /// # Errors
    /// Returns `self` when the wrapped error is not an `E`.
    pub fn downcast<E: Error + 'static>(self) -> Result<E, Self> {
        let retry = self.1;
        self.0
            .downcast::<E>()
            .map(|b| *b)
            .map_err(|e| Self(e, retry))
    }

    /// The wrapped error as a trait object.
    pub fn into_inner(self) -> Box<dyn Error + Send + Sync + 'static> {
        self.0
    }
}

impl From<Box<dyn Error + Send + Sync + 'static>> for RhsError {
    fn from(error: Box<dyn Error + Send + Sync + 'static>) -> Self {
        Self(error, false)
    }
}

impl From<String> for RhsError {
    fn from(message: String) -> Self {
        Self(message.into(), false)
    }
}

impl From<&str> for RhsError {
    fn from(message: &str) -> Self {
        Self(message.into(), false)
    }
}

impl fmt::Debug for RhsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(&self.0, f)
    }
}

impl fmt::Display for RhsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(&self.0, f)
    }
}

impl Error for RhsError {
    fn source(&self) -> Option<&(dyn Error + 'static)> {
        self.0.source()
    }
}
