//! The classical fourth-order Runge–Kutta method with a fixed step size.
//!
//! Input: an [`OdeSystem`], a step size $h$, an initial state. Output: one step of size
//! $h$ per call (the last one shortened, or stretched by at most $10^{-10}h$ against
//! round-off, to end exactly on `t_stop`), with a third-order dense output built from
//! the four stage values.
//! Invariants: four evaluations of the right-hand side per step and none at reset; no
//! error control, but a recoverable failure of the right-hand side
//! ([`RhsError::recoverable`](super::RhsError::recoverable)) halves this one step
//! (counted as a rejection) until it succeeds or underflows; no allocation after
//! construction.
//!
//! $$k_1 = f(t, y),\; k_2 = f(t+\tfrac h2, y+\tfrac h2 k_1),\;
//! k_3 = f(t+\tfrac h2, y+\tfrac h2 k_2),\; k_4 = f(t+h, y+hk_3),$$
//! $$y_{n+1} = y_n + \tfrac h6(k_1 + 2k_2 + 2k_3 + k_4).$$
//! Dense output (Hairer–Nørsett–Wanner I, §II.6): $y(t+\theta h) \approx y +
//! h\sum_i b_i(\theta)k_i$ with $b_1 = \theta - \frac32\theta^2 + \frac23\theta^3$,
//! $b_2 = b_3 = \theta^2 - \frac23\theta^3$, $b_4 = -\frac12\theta^2 + \frac23\theta^3$.

use super::common::{
    check_len, check_state, check_stop, eval, interpolate_prelude, is_recoverable, replace_state,
    underflows,
};
use super::error::OdeError;
use super::integrator::Integrator;
use super::options::{check_h0, OdeStats};
use super::system::OdeSystem;

/// Classical Runge–Kutta of order 4 with a fixed step size.
#[derive(Clone, Debug)]
pub struct Rk4 {
    h: f64,
    max_steps: u64,
    started: bool,
    t: f64,
    t_prev: f64,
    h_last: f64,
    steps_since_reset: u64,
    y: Vec<f64>,
    y_prev: Vec<f64>,
    k: [Vec<f64>; 4],
    tmp: Vec<f64>,
    stats: OdeStats,
}

impl Rk4 {
    /// An integrator for systems of dimension `dim` with step size magnitude `h`.
    ///
    /// # Errors
    /// [`OdeError::InvalidStepSize`] unless `h` is finite and positive.
    pub fn new(dim: usize, h: f64) -> Result<Self, OdeError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(OdeError::InvalidStepSize { h });
        }
        let v = || vec![0.0; dim];
        Ok(Self {
            h,
            max_steps: u64::MAX,
            started: false,
            t: 0.0,
            t_prev: 0.0,
            h_last: 0.0,
            steps_since_reset: 0,
            y: v(),
            y_prev: v(),
            k: [v(), v(), v(), v()],
            tmp: v(),
            stats: OdeStats::default(),
        })
    }

    /// Limits the number of steps between two resets (default: no limit).
    #[must_use]
    pub fn with_max_steps(mut self, max_steps: u64) -> Self {
        self.max_steps = max_steps;
        self
    }

    /// The signed step size.
    pub fn h(&self) -> f64 {
        self.h
    }
    /// One step of size `h` from the current state into `tmp` (stages into `k`).
    fn attempt<S: OdeSystem + ?Sized>(&mut self, sys: &mut S, h: f64) -> Result<(), OdeError> {
        let t = self.t;
        let n = self.dim();
        let [k1, k2, k3, k4] = &mut self.k;
        let (y, tmp) = (&self.y, &mut self.tmp);
        eval(sys, &mut self.stats, t, y, k1)?;
        for i in 0..n {
            tmp[i] = y[i] + 0.5 * h * k1[i];
        }
        eval(sys, &mut self.stats, t + 0.5 * h, tmp, k2)?;
        for i in 0..n {
            tmp[i] = y[i] + 0.5 * h * k2[i];
        }
        eval(sys, &mut self.stats, t + 0.5 * h, tmp, k3)?;
        for i in 0..n {
            tmp[i] = y[i] + h * k3[i];
        }
        eval(sys, &mut self.stats, t + h, tmp, k4)?;
        for i in 0..n {
            tmp[i] = y[i] + h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        }
        Ok(())
    }
}

impl Integrator for Rk4 {
    fn dim(&self) -> usize {
        self.y.len()
    }

    /// `h0`, when given, replaces the step size (its sign sets the direction).
    fn reset<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t0: f64,
        y0: &[f64],
        h0: Option<f64>,
    ) -> Result<(), OdeError> {
        check_len(self.dim(), sys.dim())?;
        check_len(self.dim(), y0.len())?;
        check_state(t0, y0)?;
        if let Some(h) = h0 {
            check_h0(h)?;
            self.h = h;
        }
        self.y.copy_from_slice(y0);
        self.t = t0;
        self.t_prev = t0;
        self.h_last = 0.0;
        self.steps_since_reset = 0;
        self.started = true;
        self.stats.restarts += 1;
        Ok(())
    }

    fn step<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t_stop: Option<f64>,
    ) -> Result<f64, OdeError> {
        if !self.started {
            return Err(OdeError::NotStarted);
        }
        if check_stop(self.t, self.h.signum(), t_stop)? {
            return Ok(self.t);
        }
        if self.steps_since_reset >= self.max_steps {
            return Err(OdeError::MaxStepsExceeded {
                t: self.t,
                steps: self.max_steps,
            });
        }
        let t = self.t;
        let (mut h, mut hits) = match t_stop {
            Some(ts) if (ts - t).abs() <= self.h.abs() * (1.0 + 1e-10) => (ts - t, true),
            _ => (self.h, false),
        };
        loop {
            match self.attempt(sys, h) {
                Ok(()) => break,
                Err(e) if is_recoverable(&e) && !underflows(t, 0.5 * h) => {
                    // Shorten this step only; the next one has the nominal size again.
                    self.stats.rejected += 1;
                    h *= 0.5;
                    hits = false;
                }
                Err(e) => return Err(e),
            }
        }
        let tmp = &self.tmp;
        let t_new = if hits { t_stop.unwrap_or(t + h) } else { t + h };
        check_state(t_new, tmp)?;
        self.y_prev.copy_from_slice(&self.y);
        self.y.copy_from_slice(tmp);
        self.t_prev = t;
        self.t = t_new;
        self.h_last = h;
        self.steps_since_reset += 1;
        self.stats.steps += 1;
        Ok(self.t)
    }

    fn t(&self) -> f64 {
        self.t
    }

    fn t_prev(&self) -> f64 {
        self.t_prev
    }

    fn y(&self) -> &[f64] {
        &self.y
    }

    fn h_next(&self) -> f64 {
        self.h
    }

    /// Third-order interpolant from the stage values; after [`set_state`](Self::set_state)
    /// it still describes the step as integrated (before the correction).
    fn interpolate(&self, t: f64, out: &mut [f64]) -> Result<(), OdeError> {
        if interpolate_prelude(t, (self.t_prev, self.t), &self.y, self.h_last == 0.0, out)? {
            return Ok(());
        }
        let th = (t - self.t_prev) / self.h_last;
        let (th2, th3) = (th * th, th * th * th);
        let b1 = th - 1.5 * th2 + 2.0 / 3.0 * th3;
        let b23 = th2 - 2.0 / 3.0 * th3;
        let b4 = -0.5 * th2 + 2.0 / 3.0 * th3;
        let h = self.h_last;
        let [k1, k2, k3, k4] = &self.k;
        for i in 0..out.len() {
            out[i] = self.y_prev[i] + h * (b1 * k1[i] + b23 * (k2[i] + k3[i]) + b4 * k4[i]);
        }
        Ok(())
    }

    /// Replaces $y$; a one-step method keeps no other history.
    fn set_state(&mut self, y: &[f64]) -> Result<(), OdeError> {
        replace_state(self.t, &mut self.y, y, &mut self.stats)
    }

    fn stats(&self) -> &OdeStats {
        &self.stats
    }
}
