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
//! follows Gustafsson's PI.3.4 controller with the predictive limit
//! (`common::PiController::gustafsson` with $q = 8$), $\text{safe} = 0.85$,
//! $\text{fac}_1 = 0.333$, $\text{fac}_2 = 6$ (Hairer's bounds).

use super::common::{check_state, eval, PiController};
use super::dop853_tableau::{A, BHH, C, D, ER};
use super::error::OdeError;
use super::integrator::Integrator;
use super::options::{OdeOptions, OdeStats};
use super::rk_driver::{embedded_rk_integrator, EmbeddedRk, RkDriver, RkState};
use super::system::OdeSystem;

/// Index of the FSAL stage $f(t+h, y_{n+1})$ in `k`.
const FSAL: usize = 12;

/// Dormand–Prince 8(5,3) with dense output of order 7.
#[derive(Clone, Debug)]
pub struct Dop853(RkDriver<Dp853>);

/// The stages and the interpolant of DOP853.
#[derive(Clone, Debug)]
pub(crate) struct Dp853 {
    /// Whether `cont` describes the last step.
    dense_ready: bool,
    /// With `dense_output`, the interpolant is prepared only on the steps that reach
    /// this time (every step when `None`), see [`Dop853::dense_output_from`].
    dense_from: Option<f64>,
    /// Stage derivatives 1–16 (index = stage − 1).
    k: [Vec<f64>; 16],
    /// Coefficients of the interpolant on the last step (`rcont1..8` of dop853.f).
    cont: [Vec<f64>; 8],
}

/// Components [`combine`] sums together (two SSE2 registers).
const LANES: usize = 4;

/// `out = y + h * sum_j a_j k_j` over the listed coefficients.
///
/// Four components at a time with the sums in registers: each entry sees the
/// operations of a pass per coefficient ($o \leftarrow y$, then $o \mathrel{+}=
/// (h a_j) k_j$ in the order of the list), without storing and reloading `out` once
/// per coefficient (stage 12 has eleven).
#[inline]
fn combine(out: &mut [f64], y: &[f64], h: f64, coeffs: &[(usize, f64)], k: &[Vec<f64>]) {
    let n = out.len();
    let mut l0 = 0;
    while l0 + LANES <= n {
        combine_lanes::<LANES>(out, y, h, coeffs, k, l0);
        l0 += LANES;
    }
    for l0 in l0..n {
        combine_lanes::<1>(out, y, h, coeffs, k, l0);
    }
}

/// [`combine`] for the components `l0..l0 + W`.
#[inline(always)]
fn combine_lanes<const W: usize>(
    out: &mut [f64],
    y: &[f64],
    h: f64,
    coeffs: &[(usize, f64)],
    k: &[Vec<f64>],
    l0: usize,
) {
    let mut s = <[f64; W]>::try_from(&y[l0..l0 + W]).expect("W entries");
    for &(j, a) in coeffs {
        let ha = h * a;
        let kj = <&[f64; W]>::try_from(&k[j][l0..l0 + W]).expect("W entries");
        for (s, kj) in s.iter_mut().zip(kj) {
            *s += ha * kj;
        }
    }
    out[l0..l0 + W].copy_from_slice(&s);
}

impl Dop853 {
    /// An integrator for systems of dimension `dim`.
    ///
    /// # Errors
    /// Invalid options, see [`OdeOptions::validate`].
    pub fn new(dim: usize, opts: OdeOptions) -> Result<Self, OdeError> {
        let v = || vec![0.0; dim];
        let ctrl = PiController::gustafsson(8.0, 0.333, 6.0);
        let m = Dp853 {
            dense_ready: false,
            dense_from: None,
            k: std::array::from_fn(|_| v()),
            cont: std::array::from_fn(|_| v()),
        };
        RkDriver::new(dim, opts, ctrl, m).map(Self)
    }

    /// The options in use.
    pub fn options(&self) -> &OdeOptions {
        &self.0.st.opts
    }

    /// With `dense_output` on, prepares the interpolant (three evaluations) only on the
    /// accepted steps that reach `t` in the direction of integration; `None` (the
    /// default): on every step. A caller that interpolates at known times sets the
    /// next of them before each step; [`interpolate`](Integrator::interpolate) on a
    /// step without the interpolant fails with [`OdeError::DenseOutputUnavailable`].
    pub fn dense_output_from(&mut self, t: Option<f64>) {
        self.0.method_mut().dense_from = t;
    }
}

impl Dp853 {
    /// Evaluates stage `s` (0-based) of a step of size `h` from the current state.
    fn stage<S: OdeSystem + ?Sized>(
        &mut self,
        st: &mut RkState,
        sys: &mut S,
        s: usize,
        h: f64,
    ) -> Result<(), OdeError> {
        let (done, rest) = self.k.split_at_mut(s);
        combine(&mut st.tmp, &st.y, h, A[s], done);
        eval(sys, &mut st.stats, st.t + C[s] * h, &st.tmp, &mut rest[0])
    }

    /// Evaluates the three extra stages and stores the interpolant of the accepted step
    /// (before `y` is replaced; `k[FSAL]` must hold $f(t+h, y_{n+1})$).
    fn store_dense<S: OdeSystem + ?Sized>(
        &mut self,
        st: &mut RkState,
        sys: &mut S,
        h: f64,
    ) -> Result<(), OdeError> {
        for s in 13..16 {
            self.stage(st, sys, s, h)?;
        }
        let [c1, c2, c3, c4, rest @ ..] = &mut self.cont;
        for i in 0..st.y.len() {
            let ydiff = st.y_new[i] - st.y[i];
            let bspl = h * self.k[0][i] - ydiff;
            c1[i] = st.y[i];
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

impl Dp853 {
    /// The error sums of [`attempt`](EmbeddedRk::attempt) for the components
    /// `l0..l0 + W`: the two error estimates summed in registers coefficient by
    /// coefficient (each entry sees the operations of `dop853.f` in their order), then
    /// added to `e3` and `e5` component by component, in order.
    #[inline(always)]
    fn error_lanes<const W: usize>(&self, st: &RkState, l0: usize, e3: &mut f64, e5: &mut f64) {
        let (mut err3, mut err5) = ([0.0; W], [0.0; W]);
        let lanes = |j: usize| <&[f64; W]>::try_from(&self.k[j][l0..l0 + W]).expect("W entries");
        for &(j, b) in A[FSAL] {
            for (e, k) in err3.iter_mut().zip(lanes(j)) {
                *e += b * k;
            }
        }
        for &(j, b) in BHH {
            for (e, k) in err3.iter_mut().zip(lanes(j)) {
                *e -= b * k;
            }
        }
        for &(j, c) in ER {
            for (e, k) in err5.iter_mut().zip(lanes(j)) {
                *e += c * k;
            }
        }
        let tol = &st.opts.tol;
        for (w, (err3, err5)) in err3.iter().zip(&err5).enumerate() {
            let i = l0 + w;
            let sk = tol.atol(i) + tol.rtol * st.y[i].abs().max(st.y_new[i].abs());
            *e3 += (err3 / sk) * (err3 / sk);
            *e5 += (err5 / sk) * (err5 / sk);
        }
    }
}

impl EmbeddedRk for Dp853 {
    const ORDER: i32 = 8;
    const FSAL: usize = FSAL;

    fn k(&mut self) -> &mut [Vec<f64>] {
        &mut self.k
    }

    /// Stages 2–12 and $y_{n+1}$ into `y_new`; returns the error norm.
    fn attempt<S: OdeSystem + ?Sized>(
        &mut self,
        st: &mut RkState,
        sys: &mut S,
        h: f64,
    ) -> Result<f64, OdeError> {
        for s in 1..12 {
            self.stage(st, sys, s, h)?;
        }
        combine(&mut st.y_new, &st.y, h, A[FSAL], &self.k);
        if check_state(st.t + h, &st.y_new).is_err() {
            return Ok(f64::INFINITY);
        }
        let (mut e5, mut e3) = (0.0, 0.0);
        let n = st.y.len();
        let mut l0 = 0;
        while l0 + LANES <= n {
            self.error_lanes::<LANES>(st, l0, &mut e3, &mut e5);
            l0 += LANES;
        }
        for l0 in l0..n {
            self.error_lanes::<1>(st, l0, &mut e3, &mut e5);
        }
        let deno = if e5 + 0.01 * e3 > 0.0 {
            e5 + 0.01 * e3
        } else {
            1.0
        };
        Ok(h.abs() * e5 * (1.0 / (st.y.len() as f64 * deno)).sqrt())
    }

    /// The FSAL stage $f(t_{\text{new}}, y_{n+1})$ and, with `dense_output` (on a step
    /// that reaches [`dense_from`](Self::dense_from)), the dense stages and the
    /// interpolant.
    fn accept<S: OdeSystem + ?Sized>(
        &mut self,
        st: &mut RkState,
        sys: &mut S,
        h: f64,
        t_new: f64,
    ) -> Result<(), OdeError> {
        let mut fsal = eval(sys, &mut st.stats, t_new, &st.y_new, &mut self.k[FSAL]);
        self.dense_ready = false;
        let wanted = self.dense_from.is_none_or(|td| (t_new - td) * h >= 0.0);
        if fsal.is_ok() && st.opts.dense_output && wanted {
            fsal = self.store_dense(st, sys, h);
            self.dense_ready = fsal.is_ok();
        }
        fsal
    }

    fn forget_dense(&mut self) {
        self.dense_ready = false;
    }

    fn dense(&self, s: f64, out: &mut [f64]) -> Result<(), OdeError> {
        if !self.dense_ready {
            return Err(OdeError::DenseOutputUnavailable);
        }
        let s1 = 1.0 - s;
        let [r1, r2, r3, r4, r5, r6, r7, r8] = &self.cont;
        for i in 0..out.len() {
            let p = r5[i] + s * (r6[i] + s1 * (r7[i] + s * r8[i]));
            out[i] = r1[i] + s * (r2[i] + s1 * (r3[i] + s * (r4[i] + s1 * p)));
        }
        Ok(())
    }
}

embedded_rk_integrator!(
    Dop853,
    r"Hairer's `CONTD8`: with $s = (t - t_{\text{prev}})/h$, $s_1 = 1 - s$ and
$p = r_5 + s(r_6 + s_1(r_7 + s r_8))$, the value
$r_1 + s(r_2 + s_1(r_3 + s(r_4 + s_1 p)))$, seventh order."
);
