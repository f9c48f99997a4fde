//! DOPRI5: the explicit Runge–Kutta pair of Dormand & Prince of orders 5(4), after
//! Hairer's `dopri5.f`.
//!
//! Input: an [`OdeSystem`], [`OdeOptions`], an initial state. Output: one accepted step
//! per call, advanced with the fifth-order solution (local extrapolation), and Hairer's
//! fourth-order continuous extension on it (no extra evaluation).
//! Invariants: FSAL, i.e. the seventh stage $f(t+h, y_{n+1})$ is the first stage of the
//! next step, so an attempt costs 6 evaluations and reset costs 1 (plus 1 for the
//! automatic initial step size); no allocation after construction.
//!
//! Error control: the local error estimate $h\sum_i e_i k_i$ of the embedded
//! fourth-order solution is measured in the mixed RMS norm of [`Tolerances`]
//! (accepted when $\le 1$); the step size follows Hairer's PI controller with
//! $\text{safe} = 0.9$, $\beta = 0.04$, $\text{fac}_1 = 0.2$, $\text{fac}_2 = 10$,
//! exponent $1/5 - 0.75\beta$.
//!
//! [`Tolerances`]: super::Tolerances

use super::common::{
    check_in_step, check_len, check_state, check_stop, eval, hinit, is_recoverable, limit_to_stop,
    rms_norm, underflows, PiController, RECOVER_FACTOR,
};
use super::error::OdeError;
use super::integrator::Integrator;
use super::options::{check_h0, OdeOptions, OdeStats};
use super::system::OdeSystem;

const C2: f64 = 0.2;
const C3: f64 = 0.3;
const C4: f64 = 0.8;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 0.2;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// Dormand–Prince 5(4) with PI step-size control and dense output.
#[derive(Clone, Debug)]
pub struct Dopri5 {
    opts: OdeOptions,
    ctrl: PiController,
    started: bool,
    /// Whether `k[0]` holds $f(t, y)$ for the current state.
    fsal: bool,
    dir: f64,
    t: f64,
    t_prev: f64,
    h: f64,
    h_last: f64,
    attempts: u64,
    y: Vec<f64>,
    y_new: Vec<f64>,
    tmp: Vec<f64>,
    k: [Vec<f64>; 7],
    /// Coefficients of the interpolant on the last step (`rcont1..5` of dopri5.f).
    cont: [Vec<f64>; 5],
    stats: OdeStats,
}

impl Dopri5 {
    /// An integrator for systems of dimension `dim`.
    ///
    /// # Errors
    /// Invalid options, see [`OdeOptions::validate`].
    pub fn new(dim: usize, opts: OdeOptions) -> Result<Self, OdeError> {
        opts.validate(dim)?;
        let v = || vec![0.0; dim];
        Ok(Self {
            opts,
            ctrl: PiController::new(0.2 - 0.04 * 0.75, 0.04, 0.9, 0.2, 10.0),
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
            k: std::array::from_fn(|_| v()),
            cont: std::array::from_fn(|_| v()),
            stats: OdeStats::default(),
        })
    }

    /// The options in use.
    pub fn options(&self) -> &OdeOptions {
        &self.opts
    }

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

    /// One attempt of size `h`: stages 2–7 into `k`, $y_{n+1}$ into `y_new`; returns
    /// the error norm.
    fn attempt<S: OdeSystem + ?Sized>(&mut self, sys: &mut S, h: f64) -> Result<f64, OdeError> {
        let (t, y, tmp) = (self.t, &self.y, &mut self.tmp);
        let [k1, k2, k3, k4, k5, k6, k7] = &mut self.k;
        let st = &mut self.stats;
        for i in 0..y.len() {
            tmp[i] = y[i] + h * A21 * k1[i];
        }
        eval(sys, st, t + C2 * h, tmp, k2)?;
        for i in 0..y.len() {
            tmp[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i]);
        }
        eval(sys, st, t + C3 * h, tmp, k3)?;
        for i in 0..y.len() {
            tmp[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
        }
        eval(sys, st, t + C4 * h, tmp, k4)?;
        for i in 0..y.len() {
            tmp[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
        }
        eval(sys, st, t + C5 * h, tmp, k5)?;
        for i in 0..y.len() {
            tmp[i] =
                y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
        }
        eval(sys, st, t + h, tmp, k6)?;
        let y_new = &mut self.y_new;
        for i in 0..y.len() {
            y_new[i] =
                y[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i]);
        }
        eval(sys, st, t + h, y_new, k7)?;
        for i in 0..y.len() {
            tmp[i] =
                h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
        }
        if check_state(t + h, y_new).is_err() {
            return Ok(f64::INFINITY);
        }
        Ok(rms_norm(&self.opts.tol, tmp, y, y_new))
    }

    /// Stores the interpolant of the accepted step (before `y` is replaced).
    fn store_dense(&mut self, h: f64) {
        let [k1, _, k3, k4, k5, k6, k7] = &self.k;
        let [c1, c2, c3, c4, c5] = &mut self.cont;
        for i in 0..self.y.len() {
            let ydiff = self.y_new[i] - self.y[i];
            let bspl = h * k1[i] - ydiff;
            c1[i] = self.y[i];
            c2[i] = ydiff;
            c3[i] = bspl;
            c4[i] = ydiff - h * k7[i] - bspl;
            c5[i] =
                h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i]);
        }
    }
}

impl Integrator for Dopri5 {
    fn dim(&self) -> usize {
        self.y.len()
    }

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
        let h0 = h0.or(self.opts.h_init);
        if let Some(h) = h0 {
            check_h0(h)?;
        }
        self.started = false;
        self.stats.restarts += 1;
        self.y.copy_from_slice(y0);
        self.t = t0;
        self.t_prev = t0;
        self.h_last = 0.0;
        self.attempts = 0;
        self.ctrl.reset();
        self.dir = h0.map_or(1.0, f64::signum);
        eval(sys, &mut self.stats, t0, &self.y, &mut self.k[0])?;
        self.fsal = true;
        self.h = match h0 {
            Some(h) => h,
            None => {
                let [k1, k2, k3, ..] = &mut self.k;
                let (tol, h_max, dir) = (&self.opts.tol, self.opts.h_max, self.dir);
                hinit(
                    sys,
                    &mut self.stats,
                    tol,
                    5,
                    h_max,
                    dir,
                    (t0, &self.y, k1),
                    k2,
                    k3,
                )?
            }
        };
        self.started = true;
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
        if check_stop(self.t, self.dir, t_stop)? {
            return Ok(self.t);
        }
        if !self.fsal {
            eval(sys, &mut self.stats, self.t, &self.y, &mut self.k[0])?;
            self.fsal = true;
        }
        let mut rejected = false;
        let mut failure = None;
        loop {
            if self.attempts >= self.opts.max_steps {
                return Err(OdeError::MaxStepsExceeded {
                    t: self.t,
                    steps: self.opts.max_steps,
                });
            }
            let h = self.dir * self.h.abs().min(self.opts.h_max);
            let (h, hits) = limit_to_stop(self.t, h, t_stop);
            if !hits && underflows(self.t, h) {
                // A recoverable failure on the way down is the better report.
                return Err(failure.unwrap_or(OdeError::StepSizeTooSmall { t: self.t, h }));
            }
            self.attempts += 1;
            let err = match self.attempt(sys, h) {
                Ok(err) => err,
                Err(e) => {
                    failure = Some(self.recover(e, h)?);
                    rejected = true;
                    continue;
                }
            };
            let (h_new, accepted) = self.ctrl.control(err, h);
            if !accepted {
                rejected = true;
                self.stats.rejected += 1;
                self.h = h_new;
                continue;
            }
            let mut h_new = self.dir * h_new.abs().min(self.opts.h_max);
            if rejected {
                h_new = self.dir * h_new.abs().min(h.abs());
            }
            self.store_dense(h);
            std::mem::swap(&mut self.y, &mut self.y_new);
            self.k.swap(0, 6);
            self.t_prev = self.t;
            self.t = match (hits, t_stop) {
                (true, Some(ts)) => ts,
                _ => self.t + h,
            };
            self.h_last = h;
            self.h = h_new;
            self.stats.steps += 1;
            return Ok(self.t);
        }
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

    /// Hairer's `CONTD5`: with $\theta = (t - t_{\text{prev}})/h$,
    /// $r_1 + \theta(r_2 + (1-\theta)(r_3 + \theta(r_4 + (1-\theta) r_5)))$, fourth order.
    /// After [`set_state`](Self::set_state) it still describes the step as integrated.
    fn interpolate(&self, t: f64, out: &mut [f64]) -> Result<(), OdeError> {
        check_len(self.dim(), out.len())?;
        check_in_step(t, self.t_prev, self.t)?;
        if self.h_last == 0.0 {
            out.copy_from_slice(&self.y);
            return Ok(());
        }
        let th = (t - self.t_prev) / self.h_last;
        let th1 = 1.0 - th;
        let [c1, c2, c3, c4, c5] = &self.cont;
        for i in 0..out.len() {
            out[i] = c1[i] + th * (c2[i] + th1 * (c3[i] + th * (c4[i] + th1 * c5[i])));
        }
        Ok(())
    }

    /// Replaces $y$. The FSAL derivative becomes stale, so the next step evaluates
    /// $f(t, y)$ once more.
    fn set_state(&mut self, y: &[f64]) -> Result<(), OdeError> {
        check_len(self.dim(), y.len())?;
        check_state(self.t, y)?;
        self.y.copy_from_slice(y);
        self.fsal = false;
        self.stats.state_updates += 1;
        Ok(())
    }

    fn stats(&self) -> &OdeStats {
        &self.stats
    }
}
