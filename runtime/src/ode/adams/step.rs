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
use super::{Adams, Coeffs};

/// $\gamma^\ast_1..\gamma^\ast_{13}$ of `ode.f` (docs/theory.md §adams), 1-based.
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

/// $1/i$ (index 0 unused), the values `STEP` divides out.
const INV: [f64; 14] = {
    let mut t = [0.0; 14];
    let mut i = 1;
    while i < 14 {
        t[i] = 1.0 / i as f64;
        i += 1;
    }
    t
};

/// $v_{i} = 1/(i(i+1))$ (index 0 unused), the start of the $v$, $w$ recurrences of
/// block 1 after a change of step size, as `STEP` divides them out.
const V1: [f64; 14] = {
    let mut t = [0.0; 14];
    let mut i = 1;
    while i < 14 {
        t[i] = 1.0 / (i * (i + 1)) as f64;
        i += 1;
    }
    t
};

/// Components the predictor sweeps together (two SSE2 registers).
const LANES: usize = 4;

/// The predictor's sweep for the components `l0..l0 + W`, column by column from `k`
/// down to 1, with the sum and the carried difference in registers: $\phi_i \leftarrow
/// \beta_i\phi_i$ for $i > n_s$ ($\phi^\ast$), $p \mathrel{+}= g_i\phi_i$, then
/// $\phi_i \mathrel{+}= \phi_{i+1}$ ($\phi_{k+1} = 0$). Each entry sees the operations
/// of `STEP`'s loops in their order.
#[inline(always)]
fn predict_lanes<const W: usize>(
    phi: &mut [f64],
    n: usize,
    l0: usize,
    c: &Coeffs,
    k: usize,
    p: &mut [f64],
) {
    let mut s = [0.0; W];
    let mut next = [0.0; W];
    for i in (1..=k).rev() {
        let at = (i - 1) * n + l0;
        let col = <&mut [f64; W]>::try_from(&mut phi[at..at + W]).expect("W entries");
        if i > c.ns {
            let b = c.beta[i];
            for x in col.iter_mut() {
                *x *= b;
            }
        }
        let g = c.g[i];
        for ((s, x), next) in s.iter_mut().zip(col.iter_mut()).zip(next.iter_mut()) {
            *s += g * *x;
            *x += *next;
            *next = *x;
        }
    }
    p[l0..l0 + W].copy_from_slice(&s);
}

/// Block 4's update of the differences for the components `l0..l0 + W`, with
/// $d = f - \phi_1$ in registers: $\phi_{k+1} = d$, $\phi_{k+2} = d - \phi_{k+2}$,
/// then $\phi_i \mathrel{+}= d$ for $i = 1..k$ (the operations of `STEP`'s loops).
#[inline(always)]
fn update_lanes<const W: usize>(phi: &mut [f64], n: usize, l0: usize, k: usize, yp: &[f64]) {
    let mut d = [0.0; W];
    let (lo, hi) = phi.split_at_mut(k * n);
    let (ck1, ck2) = hi.split_at_mut(n);
    let yp = <&[f64; W]>::try_from(&yp[l0..l0 + W]).expect("W entries");
    let phi1 = <&[f64; W]>::try_from(&lo[l0..l0 + W]).expect("W entries");
    let a = <&mut [f64; W]>::try_from(&mut ck1[l0..l0 + W]).expect("W entries");
    let b = <&mut [f64; W]>::try_from(&mut ck2[l0..l0 + W]).expect("W entries");
    for w in 0..W {
        d[w] = yp[w] - phi1[w];
        a[w] = d[w];
        b[w] = d[w] - b[w];
    }
    for i in 0..k {
        let at = i * n + l0;
        let col = <&mut [f64; W]>::try_from(&mut lo[at..at + W]).expect("W entries");
        for (x, d) in col.iter_mut().zip(&d) {
            *x += d;
        }
    }
}

impl Adams {
    #[inline]
    fn col(&self, i: usize) -> usize {
        (i - 1) * self.y.len()
    }

    /// $\sqrt{\sum_l (\phi_{i,l}/wt_l)^2}$, the weighted norm of column `i`.
    fn col_norm(&self, i: usize) -> f64 {
        let n = self.y.len();
        let c = self.col(i);
        let mut s = 0.0;
        for (x, wt) in self.phi[c..c + n].iter().zip(&self.wt) {
            s += (x / wt).powi(2);
        }
        s.sqrt()
    }

    /// Block 1: coefficients of the formulas for this step; quantities that do not
    /// change while the step size is constant are not recomputed ($k < n_s$).
    fn block1(&mut self) {
        let (k, h) = (self.k, self.h);
        let (kp1, kp2) = (k + 1, k + 2);
        if h != self.hold {
            self.c.ns = 0;
        }
        if self.c.ns <= self.kold {
            self.c.ns += 1;
        }
        let ns = self.c.ns;
        let nsp1 = ns + 1;
        if k < ns {
            return;
        }
        self.snapshot();
        let c = &mut self.c;
        c.beta[ns] = 1.0;
        c.alpha[ns] = INV[ns];
        let mut temp1 = h * ns as f64;
        c.sig[nsp1] = 1.0;
        // The recurrences of beta and sigma carry their last value in a register
        // (the same operations as STEP's, without a store and reload per term).
        let (mut beta, mut sig) = (1.0, 1.0);
        for i in nsp1..=k {
            let im1 = i - 1;
            let temp2 = c.psi[im1];
            c.psi[im1] = temp1;
            beta = beta * temp1 / temp2;
            c.beta[i] = beta;
            temp1 = temp2 + h;
            let alpha = h / temp1;
            c.alpha[i] = alpha;
            sig *= i as f64 * alpha;
            c.sig[i + 1] = sig;
        }
        c.psi[k] = temp1;
        if ns <= 1 {
            c.v[1..=k].copy_from_slice(&V1[1..=k]);
            c.w[1..=k].copy_from_slice(&V1[1..=k]);
        } else {
            if k > self.kold {
                c.v[k] = V1[k];
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
    /// corrector, and $x \leftarrow x + h$. Only columns `1..=k+2` are touched.
    fn predict(&mut self) {
        let (n, k, h) = (self.y.len(), self.k, self.h);
        let c = &self.c;
        let phi = &mut self.phi[..(k + 2) * n];
        // phi_{k+2} = phi_{k+1}, phi_{k+1} = 0.
        let (lo, hi) = phi.split_at_mut((k + 1) * n);
        for (d, s) in hi.iter_mut().zip(&mut lo[k * n..]) {
            *d = *s;
            *s = 0.0;
        }
        let p = &mut self.p[..n];
        let mut l0 = 0;
        while l0 + LANES <= n {
            predict_lanes::<LANES>(phi, n, l0, c, k, p);
            l0 += LANES;
        }
        if l0 + 2 <= n {
            predict_lanes::<2>(phi, n, l0, c, k, p);
            l0 += 2;
        }
        for l0 in l0..n {
            predict_lanes::<1>(phi, n, l0, c, k, p);
        }
        if self.nornd {
            for (p, y) in p.iter_mut().zip(&self.y) {
                *p = y + h * *p;
            }
        } else {
            let (c15, c16) = self.phi[14 * n..16 * n].split_at_mut(n);
            for (((p, y), c15), c16) in p.iter_mut().zip(&self.y).zip(&*c15).zip(c16) {
                let tau = h * *p - c15;
                *p = y + tau;
                *c16 = (*p - y) - tau;
            }
        }
        self.xold = self.x;
        self.x += self.h;
    }

    /// Block 2 (second half): errors at orders $k$, $k-1$, $k-2$ and whether to lower
    /// the order; `yp` holds $f(x, p)$.
    fn estimate(&self) -> Estimates {
        let (n, k) = (self.y.len(), self.k);
        let km2 = k as isize - 2;
        let phi = &self.phi;
        let (yp, rwt, phi1) = (&self.yp[..n], &self.rwt[..n], &phi[..n]);
        let (mut erkm2, mut erkm1, mut erk) = (0.0, 0.0, 0.0);
        // One loop per case, each sum in the order of the components.
        if km2 > 0 {
            let (ckm1, ck) = (self.col(k - 1), self.col(k));
            let (phikm1, phik) = (&phi[ckm1..ckm1 + n], &phi[ck..ck + n]);
            for ((((yp, phi1), temp3), phikm1), phik) in
                yp.iter().zip(phi1).zip(rwt).zip(phikm1).zip(phik)
            {
                let temp4 = yp - phi1;
                erkm2 += ((phikm1 + temp4) * temp3).powi(2);
                erkm1 += ((phik + temp4) * temp3).powi(2);
                erk += (temp4 * temp3).powi(2);
            }
        } else if km2 == 0 {
            let ck = self.col(k);
            let phik = &phi[ck..ck + n];
            for (((yp, phi1), temp3), phik) in yp.iter().zip(phi1).zip(rwt).zip(phik) {
                let temp4 = yp - phi1;
                erkm1 += ((phik + temp4) * temp3).powi(2);
                erk += (temp4 * temp3).powi(2);
            }
        } else {
            for ((yp, phi1), temp3) in yp.iter().zip(phi1).zip(rwt) {
                erk += ((yp - phi1) * temp3).powi(2);
            }
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
        self.snapshot();
        let (n, k, h) = (self.y.len(), self.k, self.h);
        self.x = self.xold;
        for i in 1..=k {
            let r = 1.0 / self.c.beta[i];
            let (a, b) = self.phi[(i - 1) * n..(i + 1) * n].split_at_mut(n);
            for (x, next) in a.iter_mut().zip(&*b) {
                *x = r * (*x - next);
            }
        }
        for i in 2..=k {
            self.c.psi[i - 1] = self.c.psi[i] - h;
        }
    }

    /// Saves the coefficients before their first change in this call of
    /// [`sg_step`](Self::sg_step) (other than $n_s$, saved at its start), for
    /// [`abort`](Self::abort). Steps that keep $h$ and the order change nothing else
    /// and copy nothing.
    fn snapshot(&mut self) {
        if !self.snapped {
            self.saved = self.c;
            self.snapped = true;
        }
    }

    /// Restores the state of the last accepted step after an error in the middle of
    /// an attempt (`ns` is $n_s$ at the start of `sg_step`).
    fn abort(&mut self, ns: usize, error: OdeError) -> OdeError {
        self.restore();
        self.c = self.saved;
        self.c.ns = ns;
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
        let round = 2.0 * UROUND * self.ynorm;
        if p5eps < round {
            // Block 0: a tolerance below round-off is raised, as ode.f does.
            let eps = 2.0 * round * (1.0 + fouru);
            self.raise *= eps / self.eps;
            self.eps = eps;
            p5eps = 0.5 * eps;
        }
        // The coefficients at the start, for `abort`: n_s now, the rest before its
        // first change (`snapshot`).
        let saved = self.c.ns;
        self.snapped = false;
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
        let (p, yp, phi1) = (&mut self.p[..n], &self.yp[..n], &self.phi[..n]);
        if self.nornd {
            for (((y, p), yp), phi1) in self.y_new.iter_mut().zip(&*p).zip(yp).zip(phi1) {
                *y = p + temp1 * (yp - phi1);
            }
        } else {
            let c16 = &self.phi[15 * n..16 * n];
            for ((((y, p), yp), phi1), c16) in self
                .y_new
                .iter_mut()
                .zip(p.iter_mut())
                .zip(yp)
                .zip(phi1)
                .zip(c16)
            {
                let rho = temp1 * (yp - phi1) - c16;
                *y = *p + rho;
                *p = (*y - *p) - rho;
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
            self.phi[14 * n..15 * n].copy_from_slice(&self.p);
        }
        // phi_{k+1} = f - phi_1, phi_{k+2} = phi_{k+1} - phi_{k+2}, then
        // phi_i += phi_{k+1} for i = 1..=k.
        let (phi, yp) = (&mut self.phi[..kp2 * n], &self.yp[..n]);
        let mut l0 = 0;
        while l0 + LANES <= n {
            update_lanes::<LANES>(phi, n, l0, k, yp);
            l0 += LANES;
        }
        if l0 + 2 <= n {
            update_lanes::<2>(phi, n, l0, k, yp);
            l0 += 2;
        }
        for l0 in l0..n {
            update_lanes::<1>(phi, n, l0, k, yp);
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
