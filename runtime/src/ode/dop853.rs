//! DOP853: the explicit Runge–Kutta method of order 8 of Dormand & Prince with Hairer's
//! combined 5th/3rd-order error estimator and 7th-order dense output (`dop853.f`).
//!
//! Input: an [`OdeSystem`], [`OdeOptions`], an initial state. Output: one accepted step
//! per call with the eighth-order solution, and (when `dense_output`) the seventh-order
//! interpolant on it.
//! Invariants: an attempt costs 11 evaluations, acceptance 1 more (the FSAL stage
//! $f(t+h, y_{n+1})$, first stage of the next step) and dense output 3 more; reset
//! costs 1 (plus 1 for the automatic initial step size); no allocation after
//! construction.
//!
//! Error estimate (Hairer, Nørsett & Wanner I, §II.10): with $s_i = \text{atol}_i +
//! \text{rtol}\max(|y_i|, |y_i^{\text{new}}|)$, $E_5 = \sum_i (\text{err}^{(5)}_i/s_i)^2$
//! and $E_3 = \sum_i (\text{err}^{(3)}_i/s_i)^2$,
//! $$\text{err} = |h|\,\frac{E_5}{\sqrt{n\,(E_5 + 0.01\,E_3)}},$$
//! which behaves like $h^8$ for small $h$ and is accepted when $\le 1$. The step size
//! follows Hairer's controller with $\text{safe} = 0.9$, $\beta = 0$,
//! $\text{fac}_1 = 0.333$, $\text{fac}_2 = 6$, exponent $1/8$.

use super::common::{
    check_in_step, check_len, check_state, check_stop, eval, hinit, is_recoverable, limit_to_stop,
    underflows, PiController, RECOVER_FACTOR,
};
use super::dop853_tableau::{A, BHH, C, D, ER};
use super::error::OdeError;
use super::integrator::Integrator;
use super::options::{check_h0, OdeOptions, OdeStats};
use super::system::OdeSystem;

/// Index of the FSAL stage $f(t+h, y_{n+1})$ in `k`.
const FSAL: usize = 12;

/// Dormand–Prince 8(5,3) with dense output of order 7.
#[derive(Clone, Debug)]
pub struct Dop853 {
    opts: OdeOptions,
    ctrl: PiController,
    started: bool,
    /// Whether `k[0]` holds $f(t, y)$ for the current state.
    fsal: bool,
    /// Whether `cont` describes the last step.
    dense_ready: bool,
    dir: f64,
    t: f64,
    t_prev: f64,
    h: f64,
    h_last: f64,
    attempts: u64,
    y: Vec<f64>,
    y_new: Vec<f64>,
    tmp: Vec<f64>,
    /// Stage derivatives 1–16 (index = stage − 1).
    k: [Vec<f64>; 16],
    /// Coefficients of the interpolant on the last step (`rcont1..8` of dop853.f).
    cont: [Vec<f64>; 8],
    stats: OdeStats,
}

/// `out = y + h * sum_j a_j k_j` over the listed coefficients.
#[inline]
fn combine(out: &mut [f64], y: &[f64], h: f64, coeffs: &[(usize, f64)], k: &[Vec<f64>]) {
    out.copy_from_slice(y);
    for &(j, a) in coeffs {
        let ha = h * a;
        for (o, kj) in out.iter_mut().zip(&k[j]) {
            *o += ha * kj;
        }
    }
}

impl Dop853 {
    /// An integrator for systems of dimension `dim`.
    ///
    /// # Errors
    /// Invalid options, see [`OdeOptions::validate`].
    pub fn new(dim: usize, opts: OdeOptions) -> Result<Self, OdeError> {
        opts.validate(dim)?;
        let v = || vec![0.0; dim];
        Ok(Self {
            opts,
            ctrl: PiController::new(1.0 / 8.0, 0.0, 0.9, 0.333, 6.0),
            started: false,
            fsal: false,
            dense_ready: false,
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

    /// Evaluates stage `s` (0-based) of a step of size `h` from the current state.
    fn stage<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        s: usize,
        h: f64,
    ) -> Result<(), OdeError> {
        let (done, rest) = self.k.split_at_mut(s);
        combine(&mut self.tmp, &self.y, h, A[s], done);
        eval(
            sys,
            &mut self.stats,
            self.t + C[s] * h,
            &self.tmp,
            &mut rest[0],
        )
    }

    /// One attempt of size `h`: stages 2–12 and $y_{n+1}$ into `y_new`; returns the
    /// error norm.
    fn attempt<S: OdeSystem + ?Sized>(&mut self, sys: &mut S, h: f64) -> Result<f64, OdeError> {
        for s in 1..12 {
            self.stage(sys, s, h)?;
        }
        combine(&mut self.y_new, &self.y, h, A[FSAL], &self.k);
        if check_state(self.t + h, &self.y_new).is_err() {
            return Ok(f64::INFINITY);
        }
        let tol = &self.opts.tol;
        let (mut e5, mut e3) = (0.0, 0.0);
        for i in 0..self.y.len() {
            let sk = tol.atol(i) + tol.rtol * self.y[i].abs().max(self.y_new[i].abs());
            let mut err3 = 0.0;
            for &(j, b) in A[FSAL] {
                err3 += b * self.k[j][i];
            }
            for &(j, b) in BHH {
                err3 -= b * self.k[j][i];
            }
            let mut err5 = 0.0;
            for &(j, e) in ER {
                err5 += e * self.k[j][i];
            }
            e3 += (err3 / sk) * (err3 / sk);
            e5 += (err5 / sk) * (err5 / sk);
        }
        let deno = if e5 + 0.01 * e3 > 0.0 {
            e5 + 0.01 * e3
        } else {
            1.0
        };
        Ok(h.abs() * e5 * (1.0 / (self.y.len() as f64 * deno)).sqrt())
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

    /// Evaluates the three extra stages and stores the interpolant of the accepted step
    /// (before `y` is replaced; `k[FSAL]` must hold $f(t+h, y_{n+1})$).
    fn store_dense<S: OdeSystem + ?Sized>(&mut self, sys: &mut S, h: f64) -> Result<(), OdeError> {
        for s in 13..16 {
            self.stage(sys, s, h)?;
        }
        let [c1, c2, c3, c4, rest @ ..] = &mut self.cont;
        for i in 0..self.y.len() {
            let ydiff = self.y_new[i] - self.y[i];
            let bspl = h * self.k[0][i] - ydiff;
            c1[i] = self.y[i];
            c2[i] = ydiff;
            c3[i] = bspl;
            c4[i] = ydiff - h * self.k[FSAL][i] - bspl;
        }
        for (c, d) in rest.iter_mut().zip(D) {
            c.fill(0.0);
            for &(j, dj) in d {
                for (ci, kj) in c.iter_mut().zip(&self.k[j]) {
                    *ci += h * dj * kj;
                }
            }
        }
        Ok(())
    }
}

impl Integrator for Dop853 {
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
        self.dense_ready = false;
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
                    8,
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
            let t_new = match (hits, t_stop) {
                (true, Some(ts)) => ts,
                _ => self.t + h,
            };
            let mut fsal = eval(sys, &mut self.stats, t_new, &self.y_new, &mut self.k[FSAL]);
            self.dense_ready = false;
            if fsal.is_ok() && self.opts.dense_output {
                fsal = self.store_dense(sys, h);
                self.dense_ready = fsal.is_ok();
            }
            if let Err(e) = fsal {
                // The new state or a dense-output stage failed recoverably: the
                // attempt is rejected like one with a large error.
                failure = Some(self.recover(e, h)?);
                rejected = true;
                continue;
            }
            std::mem::swap(&mut self.y, &mut self.y_new);
            self.k.swap(0, FSAL);
            self.t_prev = self.t;
            self.t = t_new;
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

    /// Hairer's `CONTD8`: with $s = (t - t_{\text{prev}})/h$, $s_1 = 1 - s$ and
    /// $p = r_5 + s(r_6 + s_1(r_7 + s r_8))$, the value
    /// $r_1 + s(r_2 + s_1(r_3 + s(r_4 + s_1 p)))$, seventh order. After
    /// [`set_state`](Self::set_state) it still describes the step as integrated.
    fn interpolate(&self, t: f64, out: &mut [f64]) -> Result<(), OdeError> {
        check_len(self.dim(), out.len())?;
        check_in_step(t, self.t_prev, self.t)?;
        if self.h_last == 0.0 {
            out.copy_from_slice(&self.y);
            return Ok(());
        }
        if !self.dense_ready {
            return Err(OdeError::DenseOutputUnavailable);
        }
        let s = (t - self.t_prev) / self.h_last;
        let s1 = 1.0 - s;
        let [r1, r2, r3, r4, r5, r6, r7, r8] = &self.cont;
        for i in 0..out.len() {
            let p = r5[i] + s * (r6[i] + s1 * (r7[i] + s * r8[i]));
            out[i] = r1[i] + s * (r2[i] + s1 * (r3[i] + s * (r4[i] + s1 * p)));
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
