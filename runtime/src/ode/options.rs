//! Tolerances, options and work statistics shared by the integrators.
//!
//! Input: user settings. Output: validated settings (`validate`) and counters.
//! Invariants: a validated [`Tolerances`] has a finite, non-negative `rtol` (at most 1) and
//! a finite, positive `atol` for every component.

use super::error::OdeError;

/// Error tolerances: a scalar relative tolerance and a scalar or per-component
/// absolute tolerance.
///
/// The Runge–Kutta methods accept a step when the weighted RMS norm of the local error
/// estimate is at most one,
/// $$\sqrt{\tfrac1n\textstyle\sum_i (e_i/s_i)^2}\le 1,\qquad
/// s_i=\text{atol}_i+\text{rtol}\,\max(|y_i|,|y_i^{\text{new}}|).$$
/// [`Adams`](super::Adams) uses the Shampine–Gordon test described there.
#[derive(Clone, Debug, PartialEq)]
pub struct Tolerances {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance, used for every component unless `atol_components` is set.
    pub atol: f64,
    /// Per-component absolute tolerances (length `dim`), overriding `atol`.
    pub atol_components: Option<Vec<f64>>,
}

impl Tolerances {
    /// Scalar tolerances.
    pub fn new(rtol: f64, atol: f64) -> Self {
        Self {
            rtol,
            atol,
            atol_components: None,
        }
    }

    /// Sets per-component absolute tolerances.
    #[must_use]
    pub fn with_atol_components(mut self, atol: Vec<f64>) -> Self {
        self.atol_components = Some(atol);
        self
    }

    /// The absolute tolerance of component `i`.
    #[inline]
    pub fn atol(&self, i: usize) -> f64 {
        match &self.atol_components {
            Some(a) => a[i],
            None => self.atol,
        }
    }

    /// The largest absolute tolerance.
    pub fn atol_max(&self) -> f64 {
        match &self.atol_components {
            Some(a) => a.iter().copied().fold(0.0, f64::max),
            None => self.atol,
        }
    }

    /// Checks the tolerances for a system of dimension `dim`.
    ///
    /// # Errors
    /// [`OdeError::DimensionMismatch`] for a per-component vector of the wrong length,
    /// [`OdeError::InvalidTolerance`] for an `rtol` that is negative, not finite or above
    /// 1, or an `atol` that is not positive and finite.
    pub fn validate(&self, dim: usize) -> Result<(), OdeError> {
        let bad = |atol: f64| OdeError::InvalidTolerance {
            rtol: self.rtol,
            atol,
        };
        // A relative tolerance above 1 asks for no correct digit: the error estimate
        // could never be compared with the solution meaningfully.
        if !(self.rtol.is_finite() && self.rtol >= 0.0) || self.rtol > 1.0 {
            return Err(bad(self.atol));
        }
        // A zero absolute tolerance leaves a component that passes through zero a
        // weight of zero (a pure relative test there divides by it).
        let ok = |x: f64| x.is_finite() && x > 0.0;
        if let Some(a) = &self.atol_components {
            if a.len() != dim {
                return Err(OdeError::DimensionMismatch {
                    expected: dim,
                    found: a.len(),
                });
            }
            if let Some(&x) = a.iter().find(|&&x| !ok(x)) {
                return Err(bad(x));
            }
        } else if !ok(self.atol) {
            return Err(bad(self.atol));
        }
        Ok(())
    }
}

impl Default for Tolerances {
    /// `rtol = 1e-6`, `atol = 1e-6`.
    fn default() -> Self {
        Self::new(1e-6, 1e-6)
    }
}

/// Options of the adaptive integrators.
#[derive(Clone, Debug, PartialEq)]
pub struct OdeOptions {
    /// Error tolerances.
    pub tol: Tolerances,
    /// Size of the first step after `reset` when `reset` gives none; `None` lets the
    /// method choose (Hairer's `hinit` for the Runge–Kutta methods, the Shampine–Gordon
    /// rule for Adams).
    pub h_init: Option<f64>,
    /// Largest step size magnitude (default `f64::INFINITY`).
    pub h_max: f64,
    /// Largest number of step attempts, accepted and rejected, between two resets.
    pub max_steps: u64,
    /// Whether to prepare dense output on every step. [`Dop853`](super::Dop853) pays
    /// three extra evaluations per step for it, [`Dopri5`](super::Dopri5) a pass over
    /// its stages; without it their [`interpolate`](super::Integrator::interpolate)
    /// fails with [`OdeError::DenseOutputUnavailable`](super::OdeError). The others
    /// always have it.
    pub dense_output: bool,
}

impl Default for OdeOptions {
    fn default() -> Self {
        Self {
            tol: Tolerances::default(),
            h_init: None,
            h_max: f64::INFINITY,
            max_steps: 100_000,
            dense_output: true,
        }
    }
}

impl OdeOptions {
    /// Default options with `rtol = atol = tol`.
    pub fn with_tol(tol: f64) -> Self {
        Self {
            tol: Tolerances::new(tol, tol),
            ..Self::default()
        }
    }

    /// Checks the options for a system of dimension `dim`.
    ///
    /// # Errors
    /// See [`Tolerances::validate`]; [`OdeError::InvalidStepSize`] for a non-positive
    /// `h_max` or a zero or non-finite `h_init`.
    pub fn validate(&self, dim: usize) -> Result<(), OdeError> {
        self.tol.validate(dim)?;
        if self.h_max.is_nan() || self.h_max <= 0.0 {
            return Err(OdeError::InvalidStepSize { h: self.h_max });
        }
        if let Some(h) = self.h_init {
            check_h0(h)?;
        }
        Ok(())
    }
}

/// Checks a step size given by the user (non-zero, finite).
pub(crate) fn check_h0(h: f64) -> Result<(), OdeError> {
    if h.is_finite() && h != 0.0 {
        Ok(())
    } else {
        Err(OdeError::InvalidStepSize { h })
    }
}

/// Work counters, cumulative over the life of an integrator (resets do not clear them).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OdeStats {
    /// Accepted steps.
    pub steps: u64,
    /// Rejected step attempts.
    pub rejected: u64,
    /// Evaluations of the right-hand side.
    pub rhs_evals: u64,
    /// Calls to `reset`, the first one included.
    pub restarts: u64,
    /// Calls to `set_state`.
    pub state_updates: u64,
    /// Jacobians $\partial f/\partial y$ formed (implicit methods; their evaluations
    /// of the right-hand side are counted in `rhs_evals` too).
    pub jac_evals: u64,
    /// Factorizations of the iteration matrices (implicit methods; one per step size
    /// and Jacobian, covering the real and the complex system of [`Radau5`](super::Radau5)).
    pub factorizations: u64,
    /// Iterations of the stage equations' simplified Newton method (implicit methods).
    pub newton_iterations: u64,
}
