//! RADAU5: the implicit Runge–Kutta method Radau IIA of order 5 (three stages), after
//! Hairer & Wanner's `radau5.f` (*Solving ODEs II*, §IV.8), for stiff systems.
//!
//! Input: an [`OdeSystem`], [`OdeOptions`], an initial state. Output: one accepted step
//! per call, its collocation polynomial as dense output (order 3 in the interior, the
//! step's order 5 at its end), and work counters including Jacobians, factorizations and
//! Newton iterations.
//! Invariants: L-stable and stiffly accurate, so stiff components are damped in one
//! step whatever the step size; no allocation after construction.
//!
//! **The step.** The stage equations $Z = h (A \otimes I) F(Z)$ are solved by the
//! simplified Newton iteration of `radau5.f`: with $T^{-1} A^{-1} T$ block diagonal, each
//! iteration solves one real system $(\gamma/h - J)$ and one complex system
//! $((\alpha + i\beta)/h - J)$ (here as a real system of twice the size). The Jacobian
//! $J = \partial f/\partial y$ is approximated by forward differences of the
//! right-hand side ($n$ evaluations, increment $\sqrt{u \max(10^{-5}, |y_i|)}$) and
//! reused while the Newton iteration contracts fast ($\theta \le 10^{-3}$); the
//! factorizations are kept while the step size changes by a factor in $[1, 1.2]$.
//! Since it only evaluates $f$, the method serves every formulation of
//! [`crate::sim`] unchanged (the state-space ODE of partitioning or projection).
//!
//! **Error control** as in `radau5.f`, except for the tolerance transformation: the
//! tolerances become $\text{rtol}' = 0.2\,\text{rtol}^{4/5}$,
//! $\text{atol}' = \text{atol}\,\text{rtol}'/\text{rtol}$ (the embedded estimate is of
//! order 3; radau5.f's $0.1\,\text{rtol}^{2/3}$ makes the global error grow like
//! $\text{rtol}^{5/6}$, so it drifts above rtol as the tolerance tightens); the estimate
//! $(\gamma/h - J)^{-1}(f(t, y) + \sum_i e_i Z_i / h)$, filtered by the stiff
//! factorization, is measured in the RMS norm with scale
//! $\text{atol}' + \text{rtol}'|y|$; Gustafsson's predictive controller with
//! $\text{safe} = 0.9$ and factors in $[1/5, 8]$. A Newton iteration that does not
//! converge in 7 iterations, diverges ($\theta \ge 0.99$) — unless its last two
//! updates are below a tenth of the tolerance, the round-off of $f$ —, produces a
//! non-finite stage derivative, or a [recoverable](super::RhsError::recoverable) failure of the system,
//! rejects the attempt with half (a quarter for the failure) of the step.

use super::common::{
    check_len, check_state, check_stop, eval, hinit, interpolate_prelude, is_recoverable,
    limit_to_stop, replace_state, underflows, Predictive, RECOVER_FACTOR, UROUND,
};
use super::error::{OdeError, Quantity};
use super::integrator::Integrator;
use super::options::{check_h0, OdeOptions, OdeStats};
use super::system::OdeSystem;
use crate::linalg::small::SmallLu;

/// The tolerance transformation $\text{rtol}' = c\,\text{rtol}^{e}$ (radau5.f: $c = 0.1$,
/// $e = 2/3$). The error estimate is of order 3 (it behaves like $h^4$), so the step
/// follows $h \propto \text{rtol}'^{1/4}$ and the global error of the order-5 solution
/// like $h^5 \propto \text{rtol}'^{5/4}$: $e = 4/5$ makes it proportional to rtol
/// (radau5.f's $2/3$ gives $\text{rtol}^{5/6}$, 78× rtol on the pendulum at 1e-12),
/// and $c = 0.2$ puts it at 0.3–3 × rtol on the pendulum and car axis for rtol
/// 1e-3…1e-12 (docs/decisions/0026-implicit-integrator-radau5.md).
const TOL_FACTOR: f64 = 0.2;
const TOL_EXPONENT: f64 = 0.8;
/// Growth per accepted step of the step-size cap set by a failed stage iteration.
const NEWTON_CAP_GROWTH: f64 = 1.05;
/// Most Newton iterations per attempt (`NIT` of radau5.f).
const NIT: u32 = 7;
/// Safety factor of the step-size control.
const SAFE: f64 = 0.9;
/// Bounds of $h_\text{old}/h_\text{new}$ (`FACR`, `FACL`).
const FACR: f64 = 0.125;
const FACL: f64 = 5.0;
/// Newton updates (scaled norm of the tolerance) below which an iteration that stops
/// contracting has reached the round-off of `f`. radau5.f stops at `fnewt` =
/// `min(0.03, rtol'^½)` of the tolerance, which at tight tolerances asks the stages for
/// more digits than `f` has where the absolute tolerance is the scale (components near
/// zero): such an iteration then "diverges" at every step size and the steps collapse
/// (`spinup_beam`: 1,447 steps at rtol 1e-8, 86,701 at 1e-9;
/// docs/decisions/0026-implicit-integrator-radau5.md). Stages known to a tenth of the
/// tolerance are kept instead.
const NEWTON_NOISE: f64 = 0.1;
/// Contraction below which the Jacobian is reused (`THET`).
const THET: f64 = 1e-3;
/// Step-size ratios for which the factorizations are kept (`QUOT1`, `QUOT2`).
const QUOT1: f64 = 1.0;
const QUOT2: f64 = 1.2;

/// The coefficients of radau5.f (`RADCOR`).
struct Coef {
    c1: f64,
    c2: f64,
    dd: [f64; 3],
    /// $\gamma$ (real eigenvalue of $A^{-1}$), $\alpha \pm i\beta$ (the complex pair).
    u1: f64,
    alph: f64,
    beta: f64,
}

fn coef() -> Coef {
    let sq6 = 6.0_f64.sqrt();
    let c81 = 81.0_f64.cbrt();
    let c9 = 9.0_f64.cbrt();
    let u1 = (6.0 + c81 - c9) / 30.0;
    let alph = (12.0 - c81 + c9) / 60.0;
    let beta = (c81 + c9) * 3.0_f64.sqrt() / 60.0;
    let cno = alph * alph + beta * beta;
    Coef {
        c1: (4.0 - sq6) / 10.0,
        c2: (4.0 + sq6) / 10.0,
        dd: [
            -(13.0 + 7.0 * sq6) / 3.0,
            (-13.0 + 7.0 * sq6) / 3.0,
            -1.0 / 3.0,
        ],
        u1: 1.0 / u1,
        alph: alph / cno,
        beta: beta / cno,
    }
}

// The digits of radau5.f, kept as published.
#[allow(clippy::excessive_precision)]
const T11: f64 = 9.123_239_487_089_294_279_2e-2;
#[allow(clippy::excessive_precision)]
const T12: f64 = -0.141_255_295_020_954_208_43;
#[allow(clippy::excessive_precision)]
const T13: f64 = -3.002_919_410_514_742_449_2e-2;
#[allow(clippy::excessive_precision)]
const T21: f64 = 0.241_717_932_707_107_018_96;
#[allow(clippy::excessive_precision)]
const T22: f64 = 0.204_129_352_293_799_931_99;
#[allow(clippy::excessive_precision)]
const T23: f64 = 0.382_942_112_757_261_937_79;
#[allow(clippy::excessive_precision)]
const T31: f64 = 0.966_048_182_615_092_936_19;
#[allow(clippy::excessive_precision)]
const TI11: f64 = 4.325_579_890_063_155_351;
#[allow(clippy::excessive_precision)]
const TI12: f64 = 0.339_199_251_815_809_869_54;
#[allow(clippy::excessive_precision)]
const TI13: f64 = 0.541_770_539_935_874_871_19;
#[allow(clippy::excessive_precision)]
const TI21: f64 = -4.178_718_591_551_904_727_3;
#[allow(clippy::excessive_precision)]
const TI22: f64 = -0.327_682_820_761_062_387_08;
#[allow(clippy::excessive_precision)]
const TI23: f64 = 0.476_623_554_500_550_451_96;
#[allow(clippy::excessive_precision)]
const TI31: f64 = -0.502_872_634_945_786_875_95;
#[allow(clippy::excessive_precision)]
const TI32: f64 = 2.571_926_949_855_605_429_2;
#[allow(clippy::excessive_precision)]
const TI33: f64 = -0.596_039_204_828_224_924_97;

/// Radau IIA of order 5 with simplified Newton, a finite-difference Jacobian, error
/// control and dense output, after Hairer & Wanner's `radau5.f`.
///
/// Each step solves the collocation equations by a simplified Newton iteration with a
/// finite-difference Jacobian of $f$ (reused while the iteration contracts fast) and
/// one real and one complex factorization; the local error is controlled against the
/// transformed tolerances $\text{rtol}' = 0.2\,\text{rtol}^{4/5}$,
/// $\text{atol}' = \text{atol}\,\text{rtol}'/\text{rtol}$. Dense output is the
/// collocation polynomial (order 3 inside the step). Non-convergence, a non-finite
/// stage derivative or a recoverable failure of the system rejects the attempt.
pub struct Radau5 {
    opts: OdeOptions,
    k: Coef,
    /// Transformed relative tolerance and the factor on the absolute ones.
    rtol: f64,
    atol_factor: f64,
    started: bool,
    dir: f64,
    t: f64,
    t_prev: f64,
    /// Proposed size of the next attempt (signed).
    h: f64,
    /// Size of the last accepted step (0 before the first one).
    h_last: f64,
    attempts: u64,
    /// No accepted step since reset: zero Newton guesses, extra error test.
    first: bool,
    reject: bool,
    /// Whether `f0` holds $f(t, y)$.
    f_current: bool,
    /// Whether `jac` was computed at the current state.
    jac_current: bool,
    jac_valid: bool,
    /// Step size of the current factorizations (0: none).
    h_fact: f64,
    theta: f64,
    faccon: f64,
    /// Gustafsson's predictive limit on the accepted steps.
    predictive: Predictive,
    /// Largest step size the stage iteration is trusted with: set to the reduced step
    /// after the iteration fails to converge, relaxed by [`NEWTON_CAP_GROWTH`] per
    /// accepted step.
    newton_cap: f64,
    y: Vec<f64>,
    f0: Vec<f64>,
    scal: Vec<f64>,
    /// $\partial f/\partial y$, row-major.
    jac: Vec<f64>,
    e1: SmallLu,
    e2: SmallLu,
    z: [Vec<f64>; 3],
    f: [Vec<f64>; 3],
    tmp: Vec<f64>,
    /// Real and imaginary parts of the complex solve, stacked.
    tmp2: Vec<f64>,
    /// Coefficients of the collocation polynomial of the last step (`CONT` of radau5.f).
    cont: [Vec<f64>; 4],
    stats: OdeStats,
}

impl std::fmt::Debug for Radau5 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Radau5")
            .field("dim", &self.y.len())
            .field("t", &self.t)
            .field("h", &self.h)
            .field("stats", &self.stats)
            .finish_non_exhaustive()
    }
}

/// Why a Newton iteration gave up.
enum Failure {
    /// Too slow or diverging: retry with the step scaled by the factor.
    Shrink(f64),
    /// A recoverable failure of the system or a singular matrix.
    Error(OdeError),
}

impl Radau5 {
    /// An integrator for systems of dimension `dim`.
    ///
    /// # Errors
    /// Invalid options, see [`OdeOptions::validate`].
    pub fn new(dim: usize, opts: OdeOptions) -> Result<Self, OdeError> {
        opts.validate(dim)?;
        let v = || vec![0.0; dim];
        let r = opts.tol.rtol.max(10.0 * UROUND);
        let rtol = TOL_FACTOR * r.powf(TOL_EXPONENT);
        Ok(Self {
            k: coef(),
            rtol,
            atol_factor: rtol / r,
            opts,
            started: false,
            dir: 1.0,
            t: 0.0,
            t_prev: 0.0,
            h: 0.0,
            h_last: 0.0,
            attempts: 0,
            first: true,
            reject: false,
            f_current: false,
            jac_current: false,
            jac_valid: false,
            h_fact: 0.0,
            theta: 0.0,
            faccon: 1.0,
            predictive: Predictive::NEW,
            newton_cap: f64::INFINITY,
            y: v(),
            f0: v(),
            scal: v(),
            jac: vec![0.0; dim * dim],
            e1: SmallLu::new(dim),
            e2: SmallLu::new(2 * dim),
            z: std::array::from_fn(|_| v()),
            f: std::array::from_fn(|_| v()),
            tmp: v(),
            tmp2: vec![0.0; 2 * dim],
            cont: std::array::from_fn(|_| v()),
            stats: OdeStats::default(),
        })
    }

    /// The options in use.
    pub fn options(&self) -> &OdeOptions {
        &self.opts
    }

    fn update_scal(&mut self) {
        for i in 0..self.y.len() {
            self.scal[i] = self.opts.tol.atol(i) * self.atol_factor + self.rtol * self.y[i].abs();
        }
    }

    fn norm(&self, x: &[f64]) -> f64 {
        let n = x.len().max(1);
        let s: f64 = x
            .iter()
            .zip(&self.scal)
            .map(|(e, s)| (e / s) * (e / s))
            .sum();
        (s / n as f64).sqrt()
    }

    /// $J$ by forward differences at the current state (needs `f0`).
    fn jacobian<S: OdeSystem + ?Sized>(&mut self, sys: &mut S) -> Result<(), OdeError> {
        let n = self.y.len();
        self.stats.jac_evals += 1;
        self.jac_valid = false;
        self.tmp.copy_from_slice(&self.y);
        for j in 0..n {
            let yj = self.tmp[j];
            let delt = (UROUND * yj.abs().max(1e-5)).sqrt();
            self.tmp[j] = yj + delt;
            let delt = self.tmp[j] - yj;
            let res = eval(sys, &mut self.stats, self.t, &self.tmp, &mut self.z[0]);
            self.tmp[j] = yj;
            res?;
            for i in 0..n {
                self.jac[i * n + j] = (self.z[0][i] - self.f0[i]) / delt;
            }
        }
        self.jac_current = true;
        self.jac_valid = true;
        Ok(())
    }

    /// Forms and factors $\gamma/h - J$ and $(\alpha + i\beta)/h - J$.
    fn factor(&mut self, h: f64) -> Result<(), OdeError> {
        let n = self.y.len();
        let fac1 = self.k.u1 / h;
        let (alphn, betan) = (self.k.alph / h, self.k.beta / h);
        self.stats.factorizations += 1;
        let a = self.e1.matrix_mut();
        for i in 0..n {
            for j in 0..n {
                a[i * n + j] = -self.jac[i * n + j];
            }
            a[i * n + i] += fac1;
        }
        let p1 = self.e1.factor();
        let m = 2 * n;
        let b = self.e2.matrix_mut();
        b.fill(0.0);
        for i in 0..n {
            for j in 0..n {
                let v = -self.jac[i * n + j];
                b[i * m + j] = v;
                b[(n + i) * m + n + j] = v;
            }
            b[i * m + i] += alphn;
            b[(n + i) * m + n + i] += alphn;
            b[i * m + n + i] = -betan;
            b[(n + i) * m + i] = betan;
        }
        let p2 = self.e2.factor();
        self.h_fact = h;
        if p1.ratio() <= UROUND || p2.ratio() <= UROUND {
            self.h_fact = 0.0;
            return Err(OdeError::StepSizeTooSmall { t: self.t, h });
        }
        Ok(())
    }

    /// The simplified Newton iteration for the stages of a step of size `h`; on success
    /// `z` holds $Z_1, Z_2, Z_3$ and the number of iterations is returned.
    fn newton<S: OdeSystem + ?Sized>(&mut self, sys: &mut S, h: f64) -> Result<u32, Failure> {
        let n = self.y.len();
        let (c1, c2) = (self.k.c1, self.k.c2);
        let (c1m1, c2m1) = (c1 - 1.0, c2 - 1.0);
        if self.first || self.h_last == 0.0 {
            for v in self.z.iter_mut().chain(self.f.iter_mut()) {
                v.fill(0.0);
            }
        } else {
            // Extrapolate the last collocation polynomial.
            let c3q = h / self.h_last;
            let (c1q, c2q) = (c1 * c3q, c2 * c3q);
            let [_, a1, a2, a3] = &self.cont;
            let [z1, z2, z3] = &mut self.z;
            let [f1, f2, f3] = &mut self.f;
            for i in 0..n {
                let (ak1, ak2, ak3) = (a1[i], a2[i], a3[i]);
                let p = |q: f64| q * (ak1 + (q - c2m1) * (ak2 + (q - c1m1) * ak3));
                let (x1, x2, x3) = (p(c1q), p(c2q), p(c3q));
                z1[i] = x1;
                z2[i] = x2;
                z3[i] = x3;
                f1[i] = TI11 * x1 + TI12 * x2 + TI13 * x3;
                f2[i] = TI21 * x1 + TI22 * x2 + TI23 * x3;
                f3[i] = TI31 * x1 + TI32 * x2 + TI33 * x3;
            }
        }
        let fnewt = (10.0 * UROUND / self.rtol).max(0.03_f64.min(self.rtol.sqrt()));
        self.faccon = self.faccon.max(UROUND).powf(0.8);
        self.theta = THET.abs();
        let fac1 = self.k.u1 / h;
        let (alphn, betan) = (self.k.alph / h, self.k.beta / h);
        let (mut dynold, mut thqold) = (0.0_f64, 0.0_f64);
        let mut newt = 0;
        let mut stalled = false;
        loop {
            if newt >= NIT {
                return Err(Failure::Shrink(0.5));
            }
            // Stage derivatives, written over z (after the argument is formed).
            for (s, c) in [(0, c1), (1, c2), (2, 1.0)] {
                for i in 0..n {
                    self.tmp[i] = self.y[i] + self.z[s][i];
                }
                match eval(
                    sys,
                    &mut self.stats,
                    self.t + c * h,
                    &self.tmp,
                    &mut self.z[s],
                ) {
                    Ok(()) => {}
                    Err(OdeError::NonFinite {
                        quantity: Quantity::Derivative,
                        ..
                    }) => return Err(Failure::Shrink(0.5)),
                    Err(e) => return Err(Failure::Error(e)),
                }
            }
            self.stats.newton_iterations += 1;
            let [z1, z2, z3] = &mut self.z;
            let [f1, f2, f3] = &self.f;
            for i in 0..n {
                let (a1, a2, a3) = (z1[i], z2[i], z3[i]);
                z1[i] = TI11 * a1 + TI12 * a2 + TI13 * a3 - f1[i] * fac1;
                let (s2, s3) = (-f2[i], -f3[i]);
                z2[i] = TI21 * a1 + TI22 * a2 + TI23 * a3 + s2 * alphn - s3 * betan;
                z3[i] = TI31 * a1 + TI32 * a2 + TI33 * a3 + s3 * alphn + s2 * betan;
            }
            self.e1.solve(z1);
            self.tmp2[..n].copy_from_slice(z2);
            self.tmp2[n..].copy_from_slice(z3);
            self.e2.solve(&mut self.tmp2);
            z2.copy_from_slice(&self.tmp2[..n]);
            z3.copy_from_slice(&self.tmp2[n..]);
            newt += 1;
            let dyno = {
                let s: f64 = (0..n)
                    .map(|i| {
                        let s = self.scal[i];
                        (self.z[0][i] / s).powi(2)
                            + (self.z[1][i] / s).powi(2)
                            + (self.z[2][i] / s).powi(2)
                    })
                    .sum();
                (s / (3 * n.max(1)) as f64).sqrt()
            };
            if !dyno.is_finite() {
                return Err(Failure::Shrink(0.5));
            }
            if newt > 1 && newt < NIT {
                let thq = dyno / dynold;
                self.theta = if newt == 2 {
                    thq
                } else {
                    (thq * thqold).sqrt()
                };
                thqold = thq;
                // Two updates a tenth of the tolerance or less that no longer contract
                // fast enough are the round-off of f: the stages are kept.
                let at_noise = dyno.max(dynold) <= NEWTON_NOISE;
                if self.theta < 0.99 {
                    self.faccon = self.theta / (1.0 - self.theta);
                    let dyth =
                        self.faccon * dyno * self.theta.powi((NIT - 1 - newt) as i32) / fnewt;
                    if dyth >= 1.0 && at_noise {
                        stalled = true;
                    } else if dyth >= 1.0 {
                        let qnewt = dyth.clamp(1e-4, 20.0);
                        let e = -1.0 / (4.0 + f64::from(NIT) - 1.0 - f64::from(newt));
                        return Err(Failure::Shrink(0.8 * qnewt.powf(e)));
                    }
                } else if at_noise {
                    stalled = true;
                } else {
                    return Err(Failure::Shrink(0.5));
                }
            }
            dynold = dyno.max(UROUND);
            let [z1, z2, z3] = &mut self.z;
            let [f1, f2, f3] = &mut self.f;
            for i in 0..n {
                f1[i] += z1[i];
                f2[i] += z2[i];
                f3[i] += z3[i];
                z1[i] = T11 * f1[i] + T12 * f2[i] + T13 * f3[i];
                z2[i] = T21 * f1[i] + T22 * f2[i] + T23 * f3[i];
                z3[i] = T31 * f1[i] + f2[i];
            }
            if stalled || self.faccon * dyno <= fnewt {
                return Ok(newt);
            }
        }
    }

    /// The error estimate of radau5.f (`ESTRAD`); uses `f[1]`, `f[0]` and `tmp`.
    fn estimate<S: OdeSystem + ?Sized>(&mut self, sys: &mut S, h: f64) -> Result<f64, OdeError> {
        let n = self.y.len();
        let [d1, d2, d3] = self.k.dd;
        let (hee1, hee2, hee3) = (d1 / h, d2 / h, d3 / h);
        for i in 0..n {
            let f2 = hee1 * self.z[0][i] + hee2 * self.z[1][i] + hee3 * self.z[2][i];
            self.f[1][i] = f2;
            self.tmp[i] = f2 + self.f0[i];
        }
        self.e1.solve(&mut self.tmp);
        let mut err = self.norm(&self.tmp).max(1e-10);
        if err >= 1.0 && (self.first || self.reject) {
            for i in 0..n {
                self.tmp[i] += self.y[i];
            }
            let (tmp, f1) = (&self.tmp, &mut self.f[0]);
            eval(sys, &mut self.stats, self.t, tmp, f1)?;
            for i in 0..n {
                self.tmp[i] = self.f[0][i] + self.f[1][i];
            }
            self.e1.solve(&mut self.tmp);
            err = self.norm(&self.tmp).max(1e-10);
        }
        Ok(if err.is_finite() { err } else { f64::MAX })
    }

    /// Makes the Jacobian and factorizations ready for an attempt of size `h`.
    fn prepare<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        h: f64,
        new_jac: bool,
    ) -> Result<(), OdeError> {
        let new_jac = new_jac || !self.jac_valid;
        if new_jac {
            self.jacobian(sys)?;
        }
        if new_jac || self.h_fact != h {
            self.factor(h)?;
        }
        Ok(())
    }

    /// A recoverable failure: reject, cut the step, keep the error for the report.
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

impl Integrator for Radau5 {
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
        self.first = true;
        self.reject = false;
        self.jac_current = false;
        self.jac_valid = false;
        self.h_fact = 0.0;
        self.faccon = 1.0;
        self.theta = 0.0;
        self.predictive = Predictive::NEW;
        self.newton_cap = f64::INFINITY;
        self.dir = h0.map_or(1.0, f64::signum);
        self.update_scal();
        eval(sys, &mut self.stats, t0, &self.y, &mut self.f0)?;
        self.f_current = true;
        self.h = match h0 {
            Some(h) => h,
            None => {
                let [a, b, _] = &mut self.z;
                hinit(
                    sys,
                    &mut self.stats,
                    &self.opts.tol,
                    5,
                    self.opts.h_max,
                    self.dir,
                    (t0, &self.y, &self.f0),
                    a,
                    b,
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
        if !self.f_current {
            eval(sys, &mut self.stats, self.t, &self.y, &mut self.f0)?;
            self.f_current = true;
        }
        let n = self.y.len();
        let mut failure = None;
        // A new Jacobian is needed when the last Newton iteration contracted slowly.
        let mut new_jac = !self.jac_valid || (!self.jac_current && self.theta > THET);
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
                return Err(failure.unwrap_or(OdeError::StepSizeTooSmall { t: self.t, h }));
            }
            self.attempts += 1;
            if let Err(e) = self.prepare(sys, h, new_jac) {
                new_jac = false;
                if matches!(e, OdeError::StepSizeTooSmall { .. }) {
                    // A singular iteration matrix: retry with half the step.
                    self.stats.rejected += 1;
                    self.h = 0.5 * h;
                    self.reject = true;
                    continue;
                }
                failure = Some(self.recover(e, h)?);
                self.reject = true;
                continue;
            }
            new_jac = false;
            let newt = match self.newton(sys, h) {
                Ok(k) => k,
                Err(Failure::Shrink(f)) => {
                    self.newton_cap = (h * f).abs();
                    self.stats.rejected += 1;
                    self.h = h * f;
                    self.reject = true;
                    new_jac = !self.jac_current;
                    continue;
                }
                Err(Failure::Error(e)) => {
                    failure = Some(self.recover(e, h)?);
                    self.reject = true;
                    new_jac = !self.jac_current;
                    continue;
                }
            };
            let err = match self.estimate(sys, h) {
                Ok(e) => e,
                Err(e) => {
                    failure = Some(self.recover(e, h)?);
                    self.reject = true;
                    continue;
                }
            };
            let fac = SAFE.min(SAFE * f64::from(1 + 2 * NIT) / f64::from(newt + 2 * NIT));
            let mut quot = FACR.max(FACL.min(err.powf(0.25) / fac));
            let mut h_new = h / quot;
            if err >= 1.0 {
                self.stats.rejected += 1;
                self.h = if self.first { 0.1 * h } else { h_new };
                self.reject = true;
                new_jac = !self.jac_current;
                continue;
            }
            // Accepted: Gustafsson's predictive controller.
            let limit = self.predictive.accept(h, err, 0.25, SAFE);
            if let (false, Some(facgus)) = (self.first, limit) {
                quot = quot.max(facgus.clamp(FACR, FACL));
                h_new = h / quot;
            }
            let t_new = match (hits, t_stop) {
                (true, Some(ts)) => ts,
                _ => self.t + h,
            };
            // The new state and the collocation polynomial, then f there.
            let (c1, c2) = (self.k.c1, self.k.c2);
            let (c1m1, c2m1, c1mc2) = (c1 - 1.0, c2 - 1.0, c1 - c2);
            for i in 0..n {
                self.tmp[i] = self.y[i] + self.z[2][i];
            }
            if check_state(t_new, &self.tmp).is_err() {
                self.stats.rejected += 1;
                self.h = 0.5 * h;
                self.reject = true;
                continue;
            }
            // f at the new state into f[2] (scratch) before committing anything.
            if let Err(e) = eval(sys, &mut self.stats, t_new, &self.tmp, &mut self.f[2]) {
                failure = Some(self.recover(e, h)?);
                self.reject = true;
                continue;
            }
            {
                let [z1, z2, z3] = &self.z;
                let [c0, cn1, cn2, cn3] = &mut self.cont;
                for i in 0..n {
                    let (z1i, z2i, z3i) = (z1[i], z2[i], z3[i]);
                    cn1[i] = (z2i - z3i) / c2m1;
                    let ak = (z1i - z2i) / c1mc2;
                    let acont3 = (ak - z1i / c1) / c2;
                    cn2[i] = (ak - cn1[i]) / c1m1;
                    cn3[i] = cn2[i] - acont3;
                    c0[i] = self.tmp[i];
                }
            }
            self.y.copy_from_slice(&self.tmp);
            self.f0.copy_from_slice(&self.f[2]);
            self.f_current = true;
            self.update_scal();
            self.t_prev = self.t;
            self.t = t_new;
            self.h_last = h;
            self.first = false;
            self.jac_current = false;
            self.stats.steps += 1;
            let mut h_new = self.dir * h_new.abs().min(self.opts.h_max).min(self.newton_cap);
            self.newton_cap *= NEWTON_CAP_GROWTH;
            if self.reject {
                h_new = self.dir * h_new.abs().min(h.abs());
            }
            self.reject = false;
            let qt = h_new / h;
            // Keep the factorizations (and the step) when the change is small.
            self.h = if self.theta <= THET && (QUOT1..=QUOT2).contains(&qt) {
                h
            } else {
                h_new
            };
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

    /// The collocation polynomial of the last step (`CONTR5`): with
    /// $s = (t - t_n)/h \in [-1, 0]$,
    /// $c_0 + s(c_1 + (s - c_2 + 1)(c_2' + (s - c_1 + 1)c_3))$. After
    /// [`set_state`](Self::set_state) it still describes the step as integrated.
    fn interpolate(&self, t: f64, out: &mut [f64]) -> Result<(), OdeError> {
        if interpolate_prelude(t, (self.t_prev, self.t), &self.y, self.h_last == 0.0, out)? {
            return Ok(());
        }
        let s = (t - self.t) / self.h_last;
        let (c1m1, c2m1) = (self.k.c1 - 1.0, self.k.c2 - 1.0);
        let [c0, c1, c2, c3] = &self.cont;
        for i in 0..out.len() {
            out[i] = c0[i] + s * (c1[i] + (s - c2m1) * (c2[i] + (s - c1m1) * c3[i]));
        }
        Ok(())
    }

    /// Replaces $y$; the next step evaluates $f(t, y)$ again. The Jacobian, an
    /// approximation anyway, is kept.
    fn set_state(&mut self, y: &[f64]) -> Result<(), OdeError> {
        replace_state(self.t, &mut self.y, y, &mut self.stats)?;
        self.f_current = false;
        self.update_scal();
        Ok(())
    }

    /// Replaces $y$ and keeps $f(t, y)$.
    fn set_state_keeping_derivative(&mut self, y: &[f64]) -> Result<(), OdeError> {
        replace_state(self.t, &mut self.y, y, &mut self.stats)?;
        self.update_scal();
        Ok(())
    }

    fn stats(&self) -> &OdeStats {
        &self.stats
    }
}
