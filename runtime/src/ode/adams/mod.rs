//! The variable-order, variable-step Adams method of Shampine & Gordon (`DE`/`STEP`/
//! `INTRP` of `ode.f`), docs/theory.md §adams.
//!
//! Input: an [`OdeSystem`], [`OdeOptions`], an initial state. Output: one accepted step
//! per call, the current order, and `INTRP` dense output on the last step.
//! Invariants: after [`reset`](Integrator::reset) the method is at order 1 with no
//! history (start phase: the order rises and $h$ doubles on every step until the first
//! failure or order 12); the order stays in 1..=12; an accepted step costs 2
//! evaluations (PECE), a rejected attempt 1, reset 1; no allocation after construction.
//!
//! # Method
//! Adams–Bashforth predictor of order $k$ and Adams–Moulton corrector in PECE form with
//! local extrapolation (the corrected value has order $k+1$ while the error is
//! controlled at order $k$), written with the modified divided differences $\phi_i$
//! and the step history $\psi_i = x_{n+1} - x_{n+1-i}$, $\alpha_i$, $\beta_i$,
//! $\sigma_i$ and $g_i$ (the private module `step` holds the port, block by block).
//!
//! # Tolerance semantics
//! With $\varepsilon = \max(\text{rtol}, \max_i\text{atol}_i)$ and weights
//! $wt_l = (\text{rtol}\,|y_l| + \text{atol}_l)/\varepsilon$, taken at the start of the
//! step, a step is accepted when
//! $$\text{err} = |h|\,(g_k - g_{k+1})\,\big\|f(x_{n+1}, p) - \phi_1\big\|
//! \le \varepsilon,\qquad \|x\| = \sqrt{\textstyle\sum_l (x_l/wt_l)^2}.$$
//! The norm is a 2-norm, *not* divided by $n$, so for $n > 1$ it is stricter than the
//! RMS norm of the Runge–Kutta methods. The estimate is that of the order-$k$ formula,
//! while the order-$(k+1)$ corrected value is kept (local extrapolation), so the error
//! actually committed is usually much smaller; docs/theory.md §adams calls this test "error per
//! unit step". There is no safety factor on acceptance. At order $k$ the step size
//! aims at $\text{erk} = a = 0.8^{k+1}\,\tfrac12\varepsilon$ (`STEP` aims at
//! $\tfrac12\varepsilon$), i.e. the new step is $0.8\,h\,(\tfrac12\varepsilon/\text{erk})^{1/(k+1)}$:
//! it grows by $\min\big(2, (a/\text{erk})^{1/(k+1)}\big)$ once $\text{erk} \le a/32$, is
//! kept while $a/32 < \text{erk} \le a$, and shrinks by $(a/\text{erk})^{1/(k+1)}$ within
//! $[\tfrac12, 0.9]$ above $a$ (a departure from `STEP`, below). A tolerance below what
//! round-off allows ($\tfrac12\varepsilon <
//! 2u\|y\|$) is raised as `ode.f` does, see [`Adams::tolerance_scale`]. When the
//! tolerances are within a factor 100 of that limit, the predictor and corrector sums
//! use round-off-compensated summation.
//!
//! # Departures from `DE`
//! `DE` is replaced by [`Integrator::step`]: one accepted step per call, always in the
//! "do not step past `tout`" mode when a `t_stop` is given (the step is shortened to end
//! on it; when closer than $4u|x|$, `DE`'s Euler extrapolation is used), the tolerance
//! raise is silent (recorded in [`Adams::tolerance_scale`]), `h_max` caps the step
//! size, and the work limit is `max_steps` attempts since the last reset. The initial
//! step is `h0` when given; otherwise, as `DE`/`STEP` do, the distance to the first
//! `t_stop` (or `h_max`, or $\max(1, |t_0|)$ without either), reduced to
//! $\tfrac14\sqrt{\varepsilon/\|f\|}$ when $\varepsilon < 16\|f\|h^2$.
//!
//! The step-size rule departs from `STEP`, whose only increase is a doubling when
//! $\text{erk}\,2^{k+1} \le \tfrac12\varepsilon$: at order 12 that keeps $h$ while erk
//! ranges over a factor 8192, so $h$ froze at whatever value the start phase or the last
//! failure left and the tolerance no longer set the error
//! (docs/decisions/0022-adams-step-size-follows-the-tolerance.md). Here $h$ follows the
//! tolerance within a
//! factor 32 of erk, and the safety factor 0.8 on $h$ (Hairer–Nørsett–Wanner I §II.4)
//! keeps the global error of the test problems within about 3 × rtol at no cost at
//! equal error.

mod intrp;
mod step;

use super::common::{
    check_len, check_state, check_stop, eval, interpolate_prelude, replace_state, UROUND,
};
use super::error::OdeError;
use super::integrator::Integrator;
use super::options::{check_h0, OdeOptions, OdeStats};
use super::system::OdeSystem;

/// Step-history quantities of `STEP`, 1-based (index 0 unused).
#[derive(Clone, Copy, Debug, Default)]
struct Coeffs {
    psi: [f64; 14],
    alpha: [f64; 14],
    beta: [f64; 14],
    sig: [f64; 14],
    v: [f64; 14],
    w: [f64; 14],
    g: [f64; 14],
    /// Number of steps taken with the current step size, including the current one.
    ns: usize,
}

impl Coeffs {
    /// The coefficients after a reset: $g_1 = 1$, $g_2 = \tfrac12$, $\sigma_1 = 1$
    /// (constants `STEP` sets on every call), everything else zero.
    fn start() -> Self {
        let mut c = Self::default();
        c.g[1] = 1.0;
        c.g[2] = 0.5;
        c.sig[1] = 1.0;
        c
    }
}

/// Shampine–Gordon variable-order variable-step Adams PECE integrator.
#[derive(Clone, Debug)]
pub struct Adams {
    opts: OdeOptions,
    started: bool,
    /// Whether the first step size is still to be chosen (no `h0` given).
    h_pending: bool,
    /// Whether `phi` and `psi` describe the last accepted step (for `INTRP`).
    dense_ok: bool,
    x: f64,
    xold: f64,
    h: f64,
    hold: f64,
    /// $\varepsilon$, possibly raised by the round-off test.
    eps: f64,
    /// The user's $\max(\text{rtol}, \text{atol})$.
    eps_user: f64,
    /// Factor by which the tolerances have been raised since the last reset.
    raise: f64,
    k: usize,
    kold: usize,
    phase1: bool,
    nornd: bool,
    /// Consecutive steps at order at most 4 (`kle4` of `DE`).
    kle4: u32,
    attempts: u64,
    c: Coeffs,
    /// The coefficients at the start of the current step (see `step::snapshot`).
    saved: Coeffs,
    /// Whether `saved` has been taken in the current call of `sg_step`.
    snapped: bool,
    y: Vec<f64>,
    y_new: Vec<f64>,
    p: Vec<f64>,
    yp: Vec<f64>,
    wt: Vec<f64>,
    /// $1/wt_l$.
    rwt: Vec<f64>,
    /// $\sqrt{\sum_l (y_l/wt_l)^2}$ with the weights of the current step.
    ynorm: f64,
    /// Columns 1..=16 of $\phi$, column-major.
    phi: Vec<f64>,
    stats: OdeStats,
}

impl Adams {
    /// An integrator for systems of dimension `dim`.
    ///
    /// # Errors
    /// Invalid options, see [`OdeOptions::validate`].
    pub fn new(dim: usize, opts: OdeOptions) -> Result<Self, OdeError> {
        opts.validate(dim)?;
        let v = || vec![0.0; dim];
        Ok(Self {
            eps_user: opts.tol.rtol.max(opts.tol.atol_max()),
            opts,
            started: false,
            h_pending: false,
            dense_ok: false,
            x: 0.0,
            xold: 0.0,
            h: 0.0,
            hold: 0.0,
            eps: 0.0,
            raise: 1.0,
            k: 1,
            kold: 0,
            phase1: true,
            nornd: true,
            kle4: 0,
            attempts: 0,
            c: Coeffs::start(),
            saved: Coeffs::start(),
            snapped: false,
            y: v(),
            y_new: v(),
            p: v(),
            yp: v(),
            wt: v(),
            rwt: v(),
            ynorm: 0.0,
            phi: vec![0.0; 16 * dim],
            stats: OdeStats::default(),
        })
    }

    /// The options in use.
    pub fn options(&self) -> &OdeOptions {
        &self.opts
    }

    /// The order $k$ the next step will be attempted with (1 after a reset).
    pub fn order(&self) -> usize {
        self.k
    }

    /// The order of the last accepted step (0 right after a reset).
    pub fn last_order(&self) -> usize {
        self.kold
    }

    /// Factor by which the round-off test has raised the tolerances since the last
    /// reset (1 when it never did).
    pub fn tolerance_scale(&self) -> f64 {
        self.raise
    }

    /// Whether the last 50 or more consecutive steps were taken at order 4 or less,
    /// `DE`'s hint that the problem may be stiff.
    pub fn stiffness_suspected(&self) -> bool {
        self.kle4 >= 50
    }

    /// Sets $wt_l = (\text{rtol}|y_l| + \text{atol}_l)/\varepsilon_{\text{user}}$, their
    /// inverses, and the weighted norm of $y$, $\sqrt{\sum_l (y_l/wt_l)^2}$ (the
    /// element-wise loops vectorize; the sum runs in the order of the components).
    fn set_weights(&mut self) -> Result<(), OdeError> {
        let tol = &self.opts.tol;
        let (rtol, eps) = (tol.rtol, self.eps_user);
        let n = self.y.len();
        let (wt, rwt, y) = (&mut self.wt[..n], &mut self.rwt[..n], &self.y[..n]);
        match &tol.atol_components {
            None => {
                let atol = tol.atol;
                for (wt, y) in wt.iter_mut().zip(y) {
                    *wt = (rtol * y.abs() + atol) / eps;
                }
            }
            Some(a) => {
                for ((wt, y), atol) in wt.iter_mut().zip(y).zip(&a[..n]) {
                    *wt = (rtol * y.abs() + atol) / eps;
                }
            }
        }
        if let Some(l) = wt.iter().position(|wt| *wt <= 0.0) {
            // A pure relative test on a zero component (DE's iflag = 6).
            return Err(OdeError::InvalidTolerance {
                rtol,
                atol: tol.atol(l),
            });
        }
        // `rwt` holds y/wt for the sum first, then 1/wt.
        for ((r, wt), y) in rwt.iter_mut().zip(&*wt).zip(y) {
            *r = y / wt;
        }
        let mut s = 0.0;
        for r in rwt.iter() {
            s += r.powi(2);
        }
        self.ynorm = s.sqrt();
        for (r, wt) in rwt.iter_mut().zip(&*wt) {
            *r = 1.0 / wt;
        }
        Ok(())
    }

    /// `DE`/`STEP` block 0: the first step size from a guess of its magnitude.
    fn initial_step(&mut self, guess: f64) {
        let sum = self.col_norm_yp();
        let mut absh = guess;
        if self.eps < 16.0 * sum * absh * absh {
            absh = 0.25 * (self.eps / sum).sqrt();
        }
        self.h = absh.max(4.0 * UROUND * self.x.abs()).copysign(self.h);
        self.h_pending = false;
    }

    /// $\|\phi_1\|$ right after reset, where $\phi_1 = f(x, y)$.
    fn col_norm_yp(&self) -> f64 {
        let mut s = 0.0;
        for (f, wt) in self.phi.iter().zip(&self.wt) {
            s += (f / wt).powi(2);
        }
        s.sqrt()
    }
}

impl Integrator for Adams {
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
        let n = self.dim();
        check_len(n, sys.dim())?;
        check_len(n, y0.len())?;
        check_state(t0, y0)?;
        let h0 = h0.or(self.opts.h_init);
        if let Some(h) = h0 {
            check_h0(h)?;
        }
        self.started = false;
        self.dense_ok = false;
        self.stats.restarts += 1;
        self.y.copy_from_slice(y0);
        self.x = t0;
        self.xold = t0;
        self.eps = self.eps_user;
        self.raise = 1.0;
        self.set_weights()?;
        // Block 0 of STEP with `start` set: phi_1 = f, phi_2 = 0, order 1.
        eval(sys, &mut self.stats, t0, y0, &mut self.phi[..n])?;
        self.phi[n..2 * n].fill(0.0);
        self.h = h0.unwrap_or(1.0);
        self.h_pending = h0.is_none();
        self.hold = 0.0;
        self.k = 1;
        self.kold = 0;
        self.c = Coeffs::start();
        self.phase1 = true;
        self.kle4 = 0;
        self.attempts = 0;
        let round = 2.0 * UROUND * self.ynorm;
        self.nornd = 0.5 * self.eps > 100.0 * round;
        if !self.nornd {
            self.phi[14 * n..15 * n].fill(0.0);
        }
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
        let dir = self.h.signum();
        if check_stop(self.x, dir, t_stop)? {
            return Ok(self.x);
        }
        let fouru = 4.0 * UROUND;
        if let Some(ts) = t_stop {
            if (ts - self.x).abs() < fouru * self.x.abs() {
                // DE: too close to step; extrapolate with Euler and stop there.
                let (x, y, yp) = (self.x, &self.y, &mut self.yp);
                eval(sys, &mut self.stats, x, y, yp)?;
                let dt = ts - self.x;
                for (y, f) in self.y.iter_mut().zip(&self.yp) {
                    *y += dt * f;
                }
                self.xold = self.x;
                self.x = ts;
                self.stats.steps += 1;
                return Ok(self.x);
            }
        }
        if self.h_pending {
            let guess = match t_stop {
                Some(ts) => (ts - self.x).abs(),
                None if self.opts.h_max.is_finite() => self.opts.h_max,
                None => self.x.abs().max(1.0),
            };
            self.initial_step(guess);
        }
        self.set_weights()?;
        let mut h = self.h.abs().min(self.opts.h_max);
        let mut hits = false;
        if let Some(ts) = t_stop {
            if (ts - self.x).abs() <= h {
                h = (ts - self.x).abs();
                hits = true;
            }
        }
        self.h = h.copysign(dir);
        let h_try = self.h;
        if let Err(e) = self.sg_step(sys) {
            self.dense_ok = false;
            return Err(e);
        }
        // Land exactly on `t_stop` unless failed attempts shortened the step.
        if let (true, true, Some(ts)) = (hits, self.hold == h_try, t_stop) {
            self.x = ts;
        }
        self.dense_ok = true;
        self.kle4 = if self.kold > 4 { 0 } else { self.kle4 + 1 };
        self.stats.steps += 1;
        if let Err(e) = check_state(self.x, &self.y) {
            self.dense_ok = false;
            return Err(e);
        }
        Ok(self.x)
    }

    fn t(&self) -> f64 {
        self.x
    }

    fn t_prev(&self) -> f64 {
        self.xold
    }

    fn y(&self) -> &[f64] {
        &self.y
    }

    fn h_next(&self) -> f64 {
        self.h
    }

    /// `INTRP`: the Adams polynomial of the last step through the current $(x, y)$,
    /// evaluated from the modified divided differences.
    fn interpolate(&self, t: f64, out: &mut [f64]) -> Result<(), OdeError> {
        if interpolate_prelude(t, (self.xold, self.x), &self.y, self.kold == 0, out)? {
            return Ok(());
        }
        if !self.dense_ok {
            return Err(OdeError::DenseOutputUnavailable);
        }
        self.intrp(t, out);
        Ok(())
    }

    /// Replaces $y$ and keeps the differences $\phi$ (so $\phi_1$ stays $f$ at the
    /// uncorrected state; the error this makes is of the size of the correction times
    /// $h$). The round-off compensation term is cleared. `INTRP` then passes through the
    /// corrected state at $t$: the whole interpolant on the last step is shifted by the
    /// correction.
    fn set_state(&mut self, y: &[f64]) -> Result<(), OdeError> {
        let n = self.dim();
        replace_state(self.x, &mut self.y, y, &mut self.stats)?;
        if !self.nornd {
            self.phi[14 * n..15 * n].fill(0.0);
        }
        Ok(())
    }

    fn stats(&self) -> &OdeStats {
        &self.stats
    }
}
