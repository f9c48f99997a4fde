//! A line-by-line port of Shampine & Gordon's `STEP` (blocks 1–4 of `ode.f`).
//!
//! Input: the [`Adams`] state after an accepted step or a reset: $(x, y)$, the modified
//! divided differences $\phi_1..\phi_{k}$ (columns of `phi`), the step history `psi`,
//! order `k`, weights `wt`, tolerance `eps` and a proposed `h`.
//! Output: one accepted step with the new $(x, y)$, updated differences, and the order
//! and step size for the next step; or an error with the state of the last accepted
//! step restored (differences, coefficients and $x$).
//! Invariants: 1-based indices as in the Fortran (index 0 of the small arrays is
//! unused; column `i` of `phi` is `phi[(i-1)n..in]`); columns 15 and 16 hold the
//! round-off compensation terms when `nornd` is false.

// Index loops mirror the 1-based loops of ode.f so the port can be checked line by line.
#![allow(clippy::needless_range_loop)]

use super::super::common::{eval, is_recoverable, RECOVER_FACTOR, UROUND};
use super::super::error::OdeError;
use super::super::system::OdeSystem;
use super::Adams;

/// $\gamma^\ast_1..\gamma^\ast_{13}$ of `ode.f` (math-spec §9.1), 1-based.
const GSTR: [f64; 14] = [
    0.0, 0.5, 0.0833, 0.0417, 0.0264, 0.0188, 0.0143, 0.0114, 0.00936, 0.00789, 0.00679, 0.00592,
    0.00524, 0.00468,
];

/// Safety factor on the step size: at order $k$ the step size aims at
/// $\text{erk} = \text{SAFETY}^{k+1}\,\tfrac12\varepsilon$ (`STEP`: $\tfrac12\varepsilon$),
/// see the module docs of [`super`].
const SAFETY: f64 = 0.8;

/// The step size is kept while $\text{erk}$ lies within a factor `BAND` below the aim
/// (`STEP`: $2^{k+1}$, so that only doubling is possible).
const BAND: f64 = 32.0;

/// Error estimates of block 2.
#[derive(Clone, Copy, Debug)]
struct Estimates {
    err: f64,
    erk: f64,
    erkm1: f64,
    knew: usize,
}

impl Adams {
    #[inline]
    fn col(&self, i: usize) -> usize {
        (i - 1) * self.y.len()
    }

    /// `out = phi_i`-weighted norm helper: $\sqrt{\sum_l (x_l/wt_l)^2}$ of column `i`.
    fn col_norm(&self, i: usize) -> f64 {
        let c = self.col(i);
        let mut s = 0.0;
        for (l, wt) in self.wt.iter().enumerate() {
            s += (self.phi[c + l] / wt).powi(2);
        }
        s.sqrt()
    }

    /// Block 1: coefficients of the formulas for this step; quantities that do not
    /// change while the step size is constant are not recomputed ($k < n_s$).
    fn block1(&mut self) {
        let (k, h) = (self.k, self.h);
        let (kp1, kp2) = (k + 1, k + 2);
        let c = &mut self.c;
        if h != self.hold {
            c.ns = 0;
        }
        if c.ns <= self.kold {
            c.ns += 1;
        }
        let ns = c.ns;
        let nsp1 = ns + 1;
        if k < ns {
            return;
        }
        c.beta[ns] = 1.0;
        c.alpha[ns] = 1.0 / ns as f64;
        let mut temp1 = h * ns as f64;
        c.sig[nsp1] = 1.0;
        for i in nsp1..=k {
            let im1 = i - 1;
            let temp2 = c.psi[im1];
            c.psi[im1] = temp1;
            c.beta[i] = c.beta[im1] * c.psi[im1] / temp2;
            temp1 = temp2 + h;
            c.alpha[i] = h / temp1;
            c.sig[i + 1] = i as f64 * c.alpha[i] * c.sig[i];
        }
        c.psi[k] = temp1;
        if ns <= 1 {
            for iq in 1..=k {
                c.v[iq] = 1.0 / (iq * (iq + 1)) as f64;
                c.w[iq] = c.v[iq];
            }
        } else {
            if k > self.kold {
                c.v[k] = 1.0 / (k * kp1) as f64;
                for j in 1..=ns.saturating_sub(2) {
                    let i = k - j;
                    c.v[i] -= c.alpha[j + 1] * c.v[i + 1];
                }
            }
            let temp5 = c.alpha[ns];
            for iq in 1..=(kp1 - ns) {
                c.v[iq] -= temp5 * c.v[iq + 1];
                c.w[iq] = c.v[iq];
            }
            c.g[nsp1] = c.w[1];
        }
        for i in (ns + 2)..=kp1 {
            let temp6 = c.alpha[i - 1];
            for iq in 1..=(kp2 - i) {
                c.w[iq] -= temp6 * c.w[iq + 1];
            }
            c.g[i] = c.w[1];
        }
    }

    /// Block 2 (first half): $\phi \to \phi^\ast$, predictor $p$, differences for the
    /// corrector, and $x \leftarrow x + h$.
    fn predict(&mut self) {
        let (n, k, h) = (self.y.len(), self.k, self.h);
        let (kp1, kp2) = (k + 1, k + 2);
        for i in (self.c.ns + 1)..=k {
            let (ci, b) = (self.col(i), self.c.beta[i]);
            self.phi[ci..ci + n].iter_mut().for_each(|x| *x *= b);
        }
        let (c1, c2) = (self.col(kp1), self.col(kp2));
        for l in 0..n {
            self.phi[c2 + l] = self.phi[c1 + l];
            self.phi[c1 + l] = 0.0;
            self.p[l] = 0.0;
        }
        for j in 1..=k {
            let i = kp1 - j;
            let (ci, cn, gi) = (self.col(i), self.col(i + 1), self.c.g[i]);
            for l in 0..n {
                self.p[l] += gi * self.phi[ci + l];
                self.phi[ci + l] += self.phi[cn + l];
            }
        }
        if self.nornd {
            for l in 0..n {
                self.p[l] = self.y[l] + h * self.p[l];
            }
        } else {
            let (c15, c16) = (self.col(15), self.col(16));
            for l in 0..n {
                let tau = h * self.p[l] - self.phi[c15 + l];
                self.p[l] = self.y[l] + tau;
                self.phi[c16 + l] = (self.p[l] - self.y[l]) - tau;
            }
        }
        self.xold = self.x;
        self.x += self.h;
    }

    /// Block 2 (second half): errors at orders $k$, $k-1$, $k-2$ and whether to lower
    /// the order; `yp` holds $f(x, p)$.
    fn estimate(&self) -> Estimates {
        let k = self.k;
        let km2 = k as isize - 2;
        let (c1, ck) = (self.col(1), self.col(k));
        let ckm1 = if k >= 2 { self.col(k - 1) } else { 0 };
        let (mut erkm2, mut erkm1, mut erk) = (0.0, 0.0, 0.0);
        for l in 0..self.y.len() {
            let temp3 = 1.0 / self.wt[l];
            let temp4 = self.yp[l] - self.phi[c1 + l];
            if km2 > 0 {
                erkm2 += ((self.phi[ckm1 + l] + temp4) * temp3).powi(2);
            }
            if km2 >= 0 {
                erkm1 += ((self.phi[ck + l] + temp4) * temp3).powi(2);
            }
            erk += (temp4 * temp3).powi(2);
        }
        let absh = self.h.abs();
        let c = &self.c;
        if km2 > 0 {
            erkm2 = absh * c.sig[k - 1] * GSTR[k - 2] * erkm2.sqrt();
        }
        if km2 >= 0 {
            erkm1 = absh * c.sig[k] * GSTR[k - 1] * erkm1.sqrt();
        }
        let temp5 = absh * erk.sqrt();
        let err = temp5 * (c.g[k] - c.g[k + 1]);
        let erk = temp5 * c.sig[k + 1] * GSTR[k];
        let mut knew = k;
        if (km2 > 0 && erkm1.max(erkm2) <= erk) || (km2 == 0 && erkm1 <= 0.5 * erk) {
            knew = k - 1;
        }
        Estimates {
            err,
            erk,
            erkm1,
            knew,
        }
    }

    /// Block 3 (first half): undo $\phi^\ast$ and the predictor's updates of `phi`,
    /// `psi` and $x$.
    fn restore(&mut self) {
        let (n, k, h) = (self.y.len(), self.k, self.h);
        self.x = self.xold;
        for i in 1..=k {
            let (ci, cn, r) = (self.col(i), self.col(i + 1), 1.0 / self.c.beta[i]);
            for l in 0..n {
                self.phi[ci + l] = r * (self.phi[ci + l] - self.phi[cn + l]);
            }
        }
        for i in 2..=k {
            self.c.psi[i - 1] = self.c.psi[i] - h;
        }
    }

    /// Restores the state of the last accepted step after an error in the middle of
    /// an attempt (`saved` are the coefficients at the start of `step`).
    fn abort(&mut self, saved: super::Coeffs, error: OdeError) -> OdeError {
        self.restore();
        self.c = saved;
        error
    }

    /// Block 3 after a recoverable failure of the right-hand side in the `ifail`-th
    /// attempt: undo the attempt, cut the step by [`RECOVER_FACTOR`] (no error
    /// estimate to scale by) and, from the third failure, drop to order 1 as ode.f
    /// does. Returns the failure when the step would underflow.
    fn recover(&mut self, ifail: u32, e: OdeError) -> Result<OdeError, OdeError> {
        self.stats.rejected += 1;
        self.phase1 = false;
        self.restore();
        self.h *= RECOVER_FACTOR;
        if ifail >= 3 {
            self.k = 1;
        }
        if self.h.abs() < 4.0 * UROUND * self.x.abs() {
            return Err(e);
        }
        Ok(e)
    }

    /// `STEP`: attempts until one step is accepted. `wt`, `eps` and `h` are set by the
    /// caller.
    pub(super) fn sg_step<S: OdeSystem + ?Sized>(&mut self, sys: &mut S) -> Result<(), OdeError> {
        let fouru = 4.0 * UROUND;
        let n = self.y.len();
        if self.h.abs() < fouru * self.x.abs() {
            return Err(OdeError::StepSizeTooSmall {
                t: self.x,
                h: self.h,
            });
        }
        let mut p5eps = 0.5 * self.eps;
        let round = 2.0 * UROUND * self.y_norm();
        if p5eps < round {
            // Block 0: a tolerance below round-off is raised, as ode.f does.
            let eps = 2.0 * round * (1.0 + fouru);
            self.raise *= eps / self.eps;
            self.eps = eps;
            p5eps = 0.5 * eps;
        }
        self.c.g[1] = 1.0;
        self.c.g[2] = 0.5;
        self.c.sig[1] = 1.0;
        let saved = self.c;
        let mut ifail = 0;
        let mut failure = None;
        let est = loop {
            if self.attempts >= self.opts.max_steps {
                return Err(OdeError::MaxStepsExceeded {
                    t: self.x,
                    steps: self.opts.max_steps,
                });
            }
            self.attempts += 1;
            self.block1();
            self.predict();
            let (x, p, yp) = (self.x, &self.p, &mut self.yp);
            if let Err(e) = eval(sys, &mut self.stats, x, p, yp) {
                if !is_recoverable(&e) {
                    return Err(self.abort(saved, e));
                }
                ifail += 1;
                failure = Some(self.recover(ifail, e)?);
                continue;
            }
            let est = self.estimate();
            if est.err <= self.eps {
                break est;
            }
            // Block 3: the step failed.
            self.stats.rejected += 1;
            self.phase1 = false;
            self.restore();
            ifail += 1;
            let mut temp2 = 0.5;
            if ifail > 3 && p5eps < 0.25 * est.erk {
                temp2 = (p5eps / est.erk).sqrt();
            }
            let knew = if ifail >= 3 { 1 } else { est.knew };
            self.h *= temp2;
            self.k = knew;
            if self.h.abs() < fouru * self.x.abs() {
                // A recoverable failure on the way down is the better report.
                return Err(failure.unwrap_or(OdeError::StepSizeTooSmall {
                    t: self.x,
                    h: self.h,
                }));
            }
        };
        // Block 4: correct into `y_new` (compensation term into `p`), evaluate, and
        // commit only when the evaluation succeeded.
        let (k, h) = (self.k, self.h);
        let (kp1, kp2) = (k + 1, k + 2);
        let temp1 = h * self.c.g[kp1];
        let c1 = self.col(1);
        if self.nornd {
            for l in 0..n {
                self.y_new[l] = self.p[l] + temp1 * (self.yp[l] - self.phi[c1 + l]);
            }
        } else {
            let c16 = self.col(16);
            for l in 0..n {
                let rho = temp1 * (self.yp[l] - self.phi[c1 + l]) - self.phi[c16 + l];
                self.y_new[l] = self.p[l] + rho;
                self.p[l] = (self.y_new[l] - self.p[l]) - rho;
            }
        }
        let (x, y_new, yp) = (self.x, &self.y_new, &mut self.yp);
        if let Err(e) = eval(sys, &mut self.stats, x, y_new, yp) {
            if !is_recoverable(&e) {
                return Err(self.abort(saved, e));
            }
            // The corrected state failed recoverably: reject the step and take the
            // attempts again, shorter.
            self.recover(ifail + 1, e)?;
            return self.sg_step(sys);
        }
        self.kold = k;
        self.hold = h;
        std::mem::swap(&mut self.y, &mut self.y_new);
        if !self.nornd {
            let c15 = self.col(15);
            self.phi[c15..c15 + n].copy_from_slice(&self.p);
        }
        let (ck1, ck2) = (self.col(kp1), self.col(kp2));
        for l in 0..n {
            self.phi[ck1 + l] = self.yp[l] - self.phi[c1 + l];
            self.phi[ck2 + l] = self.phi[ck1 + l] - self.phi[ck2 + l];
        }
        for i in 1..=k {
            let ci = self.col(i);
            for l in 0..n {
                self.phi[ci + l] += self.phi[ck1 + l];
            }
        }
        self.select_order_and_step(est, p5eps);
        Ok(())
    }

    /// Block 4 (end): order and step size for the next step.
    fn select_order_and_step(&mut self, est: Estimates, p5eps: f64) {
        let k = self.k;
        let kp1 = k + 1;
        let absh = self.h.abs();
        let lower = est.knew + 1 == k;
        if lower || k == 12 {
            self.phase1 = false;
        }
        let mut erk = est.erk;
        if self.phase1 {
            self.k = kp1;
            erk = 0.0;
        } else if lower {
            self.k = k - 1;
            erk = est.erkm1;
        } else if kp1 <= self.c.ns {
            let erkp1 = absh * GSTR[kp1] * self.col_norm(k + 2);
            let raise = if k > 1 {
                if est.erkm1 <= erk.min(erkp1) {
                    self.k = k - 1;
                    erk = est.erkm1;
                    false
                } else {
                    erkp1 < erk && k != 12
                }
            } else {
                erkp1 < 0.5 * erk
            };
            if raise {
                self.k = kp1;
                erk = erkp1;
            }
        }
        let h = self.h;
        let mut hnew = h + h;
        if !self.phase1 {
            // The step size aims at erk = SAFETY^(k+1)·ε/2: it grows to that aim as soon
            // as erk has fallen a factor BAND below it, and shrinks as soon as erk
            // exceeds it.
            let expo = 1.0 / (self.k + 1) as f64;
            let aim = SAFETY.powi(self.k as i32 + 1) * p5eps;
            hnew = h;
            if erk * BAND <= aim {
                // erk = 0 (a polynomial solution) doubles.
                hnew = h * (aim / erk).powf(expo).min(2.0);
            } else if erk > aim {
                let r = (aim / erk).powf(expo);
                let a = absh * r.clamp(0.5, 0.9);
                hnew = a.max(4.0 * UROUND * self.x.abs()).copysign(h);
            }
        }
        self.h = hnew;
    }
}
