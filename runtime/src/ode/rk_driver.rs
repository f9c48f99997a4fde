//! The adaptive step driver shared by the embedded Runge–Kutta pairs ([`Dopri5`],
//! [`Dop853`]), after the main loop of Hairer's `dopri5.f` and `dop853.f`.
//!
//! Input: a method ([`EmbeddedRk`]: its stages, error estimate and dense output) and
//! the common state [`RkState`]. Output: [`Integrator`] behaviour — reset with Hairer's
//! `HINIT`, one accepted step per call (stop times, `max_steps`, underflow, retry after
//! a recoverable failure, PI control with `h_max`, FSAL), dense output and `set_state`.
//! Invariants: the stage `k[0]` holds $f(t, y)$ whenever `fsal` is set; stepping does
//! not allocate.
//!
//! [`Dopri5`]: super::Dopri5
//! [`Dop853`]: super::Dop853
//! [`Integrator`]: super::Integrator

use super::common::{
    check_len, check_state, check_stop, eval, hinit, interpolate_prelude, is_recoverable,
    limit_to_stop, replace_state, underflows, PiController, RECOVER_FACTOR,
};
use super::error::OdeError;
use super::options::{check_h0, OdeOptions, OdeStats};
use super::system::OdeSystem;

/// What every embedded pair keeps: options, controller, the accepted state, the
/// proposed step and scratch for the new state.
#[derive(Clone, Debug)]
pub(crate) struct RkState {
    pub(crate) opts: OdeOptions,
    ctrl: PiController,
    started: bool,
    /// Whether `k[0]` holds $f(t, y)$ for the current state.
    fsal: bool,
    dir: f64,
    pub(crate) t: f64,
    t_prev: f64,
    h: f64,
    h_last: f64,
    attempts: u64,
    pub(crate) y: Vec<f64>,
    /// $y_{n+1}$ of the current attempt.
    pub(crate) y_new: Vec<f64>,
    /// Scratch for stage arguments and error estimates.
    pub(crate) tmp: Vec<f64>,
    pub(crate) stats: OdeStats,
}

impl RkState {
    /// After a failed attempt of size `h`: a recoverable failure of the right-hand side
    /// counts as a rejection and cuts the step by [`RECOVER_FACTOR`] (the failure is
    /// handed back, to be reported if the step size underflows later); any other
    /// error, or a step that would underflow, is returned as the error.
    fn recover(&mut self, e: OdeError, h: f64) -> Result<OdeError, OdeError> {
        let h_new = h * RECOVER_FACTOR;
        if !is_recoverable(&e) || underflows(self.t, h_new) {
            return Err(e);
        }
        self.stats.rejected += 1;
        self.h = h_new;
        Ok(e)
    }
}

/// The method-specific part of an embedded Runge–Kutta pair.
pub(crate) trait EmbeddedRk {
    /// The order $p$ given to `HINIT`.
    const ORDER: i32;
    /// Index in [`k`](Self::k) of the stage $f(t+h, y_{n+1})$, the first stage of the
    /// next step.
    const FSAL: usize;

    /// The stage derivatives (at least 3; `k[0]` is $f(t, y)$).
    fn k(&mut self) -> &mut [Vec<f64>];

    /// One attempt of size `h` from `(st.t, st.y)`: the stages, $y_{n+1}$ into
    /// `st.y_new`; returns the error norm (infinite for a non-finite $y_{n+1}$).
    fn attempt<S: OdeSystem + ?Sized>(
        &mut self,
        st: &mut RkState,
        sys: &mut S,
        h: f64,
    ) -> Result<f64, OdeError>;

    /// Completes an accepted attempt ending at `t_new` before `y` is replaced: the FSAL
    /// stage (unless [`attempt`](Self::attempt) has it already) and the interpolant.
    /// An error rejects the attempt like a failed one.
    fn accept<S: OdeSystem + ?Sized>(
        &mut self,
        st: &mut RkState,
        sys: &mut S,
        h: f64,
        t_new: f64,
    ) -> Result<(), OdeError>;

    /// Forgets the interpolant (at reset).
    fn forget_dense(&mut self) {}

    /// The interpolant of the last step at $\theta = (t - t_{\text{prev}})/h$.
    fn dense(&self, theta: f64, out: &mut [f64]) -> Result<(), OdeError>;
}

/// An embedded pair: the common state and the method.
#[derive(Clone, Debug)]
pub(crate) struct RkDriver<M> {
    pub(crate) st: RkState,
    m: M,
}

impl<M: EmbeddedRk> RkDriver<M> {
    /// A driver for systems of dimension `dim` (options validated).
    pub(crate) fn new(
        dim: usize,
        opts: OdeOptions,
        ctrl: PiController,
        m: M,
    ) -> Result<Self, OdeError> {
        opts.validate(dim)?;
        let v = || vec![0.0; dim];
        Ok(Self {
            st: RkState {
                opts,
                ctrl,
                started: false,
                fsal: false,
                dir: 1.0,
                t: 0.0,
                t_prev: 0.0,
                h: 0.0,
                h_last: 0.0,
                attempts: 0,
                y: v(),
                y_new: v(),
                tmp: v(),
                stats: OdeStats::default(),
            },
            m,
        })
    }

    pub(crate) fn dim(&self) -> usize {
        self.st.y.len()
    }

    /// The method's own part.
    pub(crate) fn method_mut(&mut self) -> &mut M {
        &mut self.m
    }

    pub(crate) fn t(&self) -> f64 {
        self.st.t
    }

    pub(crate) fn t_prev(&self) -> f64 {
        self.st.t_prev
    }

    pub(crate) fn y(&self) -> &[f64] {
        &self.st.y
    }

    pub(crate) fn h_next(&self) -> f64 {
        self.st.h
    }

    pub(crate) fn stats(&self) -> &OdeStats {
        &self.st.stats
    }

    pub(crate) fn reset<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t0: f64,
        y0: &[f64],
        h0: Option<f64>,
    ) -> Result<(), OdeError> {
        check_len(self.dim(), sys.dim())?;
        check_len(self.dim(), y0.len())?;
        check_state(t0, y0)?;
        let st = &mut self.st;
        let h0 = h0.or(st.opts.h_init);
        if let Some(h) = h0 {
            check_h0(h)?;
        }
        st.started = false;
        self.m.forget_dense();
        st.stats.restarts += 1;
        st.y.copy_from_slice(y0);
        st.t = t0;
        st.t_prev = t0;
        st.h_last = 0.0;
        st.attempts = 0;
        st.ctrl.reset();
        st.dir = h0.map_or(1.0, f64::signum);
        let k = self.m.k();
        eval(sys, &mut st.stats, t0, &st.y, &mut k[0])?;
        st.fsal = true;
        st.h = match h0 {
            Some(h) => h,
            None => {
                let (k1, rest) = k.split_at_mut(1);
                let (k2, k3) = rest.split_at_mut(1);
                let (tol, h_max, dir) = (&st.opts.tol, st.opts.h_max, st.dir);
                hinit(
                    sys,
                    &mut st.stats,
                    tol,
                    M::ORDER,
                    h_max,
                    dir,
                    (t0, &st.y, &k1[0]),
                    &mut k2[0],
                    &mut k3[0],
                )?
            }
        };
        st.started = true;
        Ok(())
    }

    pub(crate) fn step<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t_stop: Option<f64>,
    ) -> Result<f64, OdeError> {
        let (st, m) = (&mut self.st, &mut self.m);
        if !st.started {
            return Err(OdeError::NotStarted);
        }
        if check_stop(st.t, st.dir, t_stop)? {
            return Ok(st.t);
        }
        if !st.fsal {
            eval(sys, &mut st.stats, st.t, &st.y, &mut m.k()[0])?;
            st.fsal = true;
        }
        let mut rejected = false;
        let mut failure = None;
        loop {
            if st.attempts >= st.opts.max_steps {
                return Err(OdeError::MaxStepsExceeded {
                    t: st.t,
                    steps: st.opts.max_steps,
                });
            }
            let h = st.dir * st.h.abs().min(st.opts.h_max);
            let (h, hits) = limit_to_stop(st.t, h, t_stop);
            if !hits && underflows(st.t, h) {
                // A recoverable failure on the way down is the better report.
                return Err(failure.unwrap_or(OdeError::StepSizeTooSmall { t: st.t, h }));
            }
            st.attempts += 1;
            let err = match m.attempt(st, sys, h) {
                Ok(err) => err,
                Err(e) => {
                    failure = Some(st.recover(e, h)?);
                    rejected = true;
                    continue;
                }
            };
            let (h_new, accepted) = st.ctrl.control(err, h);
            if !accepted {
                rejected = true;
                st.stats.rejected += 1;
                st.h = h_new;
                continue;
            }
            let mut h_new = st.dir * h_new.abs().min(st.opts.h_max);
            if rejected {
                h_new = st.dir * h_new.abs().min(h.abs());
            }
            let t_new = match (hits, t_stop) {
                (true, Some(ts)) => ts,
                _ => st.t + h,
            };
            if let Err(e) = m.accept(st, sys, h, t_new) {
                // The new state or a dense-output stage failed recoverably: the
                // attempt is rejected like one with a large error.
                failure = Some(st.recover(e, h)?);
                rejected = true;
                continue;
            }
            std::mem::swap(&mut st.y, &mut st.y_new);
            m.k().swap(0, M::FSAL);
            st.t_prev = st.t;
            st.t = t_new;
            st.h_last = h;
            st.h = h_new;
            st.stats.steps += 1;
            return Ok(st.t);
        }
    }

    /// After [`set_state`](Self::set_state) the interpolant still describes the step
    /// as integrated.
    pub(crate) fn interpolate(&self, t: f64, out: &mut [f64]) -> Result<(), OdeError> {
        let st = &self.st;
        if interpolate_prelude(t, (st.t_prev, st.t), &st.y, st.h_last == 0.0, out)? {
            return Ok(());
        }
        self.m.dense((t - st.t_prev) / st.h_last, out)
    }

    /// Replaces $y$. Unless `keep_derivative`, the FSAL derivative becomes stale, so the
    /// next step evaluates $f(t, y)$ once more.
    pub(crate) fn set_state(&mut self, y: &[f64], keep_derivative: bool) -> Result<(), OdeError> {
        let st = &mut self.st;
        replace_state(st.t, &mut st.y, y, &mut st.stats)?;
        st.fsal &= keep_derivative;
        Ok(())
    }
}

/// Implements [`Integrator`](super::Integrator) for a newtype `$ty(RkDriver<_>)`; the
/// literal documents `interpolate`.
macro_rules! embedded_rk_integrator {
    ($ty:ty, $interpolate_doc:literal) => {
        impl Integrator for $ty {
            fn dim(&self) -> usize {
                self.0.dim()
            }

            fn reset<S: OdeSystem + ?Sized>(
                &mut self,
                sys: &mut S,
                t0: f64,
                y0: &[f64],
                h0: Option<f64>,
            ) -> Result<(), OdeError> {
                self.0.reset(sys, t0, y0, h0)
            }

            fn step<S: OdeSystem + ?Sized>(
                &mut self,
                sys: &mut S,
                t_stop: Option<f64>,
            ) -> Result<f64, OdeError> {
                self.0.step(sys, t_stop)
            }

            fn t(&self) -> f64 {
                self.0.t()
            }

            fn t_prev(&self) -> f64 {
                self.0.t_prev()
            }

            fn y(&self) -> &[f64] {
                self.0.y()
            }

            fn h_next(&self) -> f64 {
                self.0.h_next()
            }

            #[doc = $interpolate_doc]
            ///
            /// After [`set_state`](Self::set_state) it still describes the step as
            /// integrated.
            fn interpolate(&self, t: f64, out: &mut [f64]) -> Result<(), OdeError> {
                self.0.interpolate(t, out)
            }

            /// Replaces $y$. The FSAL derivative becomes stale, so the next step
            /// evaluates $f(t, y)$ once more.
            fn set_state(&mut self, y: &[f64]) -> Result<(), OdeError> {
                self.0.set_state(y, false)
            }

            /// Replaces $y$ and keeps the FSAL derivative.
            fn set_state_keeping_derivative(&mut self, y: &[f64]) -> Result<(), OdeError> {
                self.0.set_state(y, true)
            }

            fn stats(&self) -> &OdeStats {
                self.0.stats()
            }
        }
    };
}
pub(crate) use embedded_rk_integrator;
