//! DOPRI5: the explicit Runge–Kutta pair of Dormand & Prince of orders 5(4), after
//! Hairer's `dopri5.f`.
//!
//! Input: an [`OdeSystem`], [`OdeOptions`], an initial state. Output: one accepted step
//! per call, advanced with the fifth-order solution (local extrapolation), and (when
//! `dense_output`) Hairer's fourth-order continuous extension on it (no extra
//! evaluation, a pass over the stages).
//! Invariants: FSAL, i.e. the seventh stage $f(t+h, y_{n+1})$ is the first stage of the
//! next step, so an attempt costs 6 evaluations and reset costs 1 (plus 1 for the
//! automatic initial step size); no allocation after construction.
//!
//! Error control: the local error estimate $h\sum_i e_i k_i$ of the embedded
//! fourth-order solution is measured in the mixed RMS norm of [`Tolerances`]
//! (accepted when $\le 1$); the step size follows Gustafsson's PI.3.4 controller with
//! the predictive limit (`common::PiController::gustafsson` with $q = 5$), $\text{safe} =
//! 0.85$, $\text{fac}_1 = 0.2$, $\text{fac}_2 = 10$ (Hairer's bounds).
//!
//! [`Tolerances`]: super::Tolerances

use super::common::{check_state, eval, rms_norm, PiController};
use super::error::OdeError;
use super::integrator::Integrator;
use super::options::{OdeOptions, OdeStats};
use super::rk_driver::{embedded_rk_integrator, EmbeddedRk, RkDriver, RkState};
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
pub struct Dopri5(RkDriver<Dp5>);

/// The stages and the interpolant of DOPRI5.
#[derive(Clone, Debug)]
pub(crate) struct Dp5 {
    /// Whether `cont` describes the last step.
    dense_ready: bool,
    /// With `dense_output`, the interpolant is prepared only on the steps that reach
    /// this time (every step when `None`), see [`Dopri5::dense_output_from`].
    dense_from: Option<f64>,
    /// Stage derivatives 1–7 (index = stage − 1).
    k: [Vec<f64>; 7],
    /// Coefficients of the interpolant on the last step (`rcont1..5` of dopri5.f),
    /// row `r` at `r * n..(r + 1) * n`; empty without `dense_output` (fixed for the
    /// integrator's life).
    cont: Vec<f64>,
}

impl Dopri5 {
    /// An integrator for systems of dimension `dim`.
    ///
    /// # Errors
    /// Invalid options, see [`OdeOptions::validate`].
    pub fn new(dim: usize, opts: OdeOptions) -> Result<Self, OdeError> {
        let ctrl = PiController::gustafsson(5.0, 0.2, 10.0);
        let m = Dp5 {
            dense_ready: false,
            dense_from: None,
            k: std::array::from_fn(|_| vec![0.0; dim]),
            cont: vec![0.0; if opts.dense_output { 5 * dim } else { 0 }],
        };
        RkDriver::new(dim, opts, ctrl, m).map(Self)
    }

    /// The options in use.
    pub fn options(&self) -> &OdeOptions {
        &self.0.st.opts
    }

    /// With `dense_output` on, prepares the interpolant (a pass over the stages, no
    /// evaluation) only on the accepted steps that reach `t` in the direction of
    /// integration; `None` (the default): on every step. As
    /// [`Dop853::dense_output_from`](super::Dop853::dense_output_from).
    pub fn dense_output_from(&mut self, t: Option<f64>) {
        self.0.method_mut().dense_from = t;
    }
}

/// The stages of `k`, each cut to length `n` (so that the loops over `0..n`
/// index them without bounds checks).
#[inline]
fn cut<const S: usize>(k: &mut [Vec<f64>; S], n: usize) -> [&mut [f64]; S] {
    k.each_mut().map(|k| &mut k[..n])
}

impl EmbeddedRk for Dp5 {
    const ORDER: i32 = 5;
    const FSAL: usize = 6;

    fn k(&mut self) -> &mut [Vec<f64>] {
        &mut self.k
    }

    /// Stages 2–7 into `k`, $y_{n+1}$ into `y_new`; returns the error norm.
    fn attempt<S: OdeSystem + ?Sized>(
        &mut self,
        st: &mut RkState,
        sys: &mut S,
        h: f64,
    ) -> Result<f64, OdeError> {
        let n = st.y.len();
        let (t, y, tmp) = (st.t, &st.y[..n], &mut st.tmp[..n]);
        let [k1, k2, k3, k4, k5, k6, k7] = cut(&mut self.k, n);
        let stats = &mut st.stats;
        for i in 0..n {
            tmp[i] = y[i] + h * A21 * k1[i];
        }
        eval(sys, stats, t + C2 * h, tmp, k2)?;
        for i in 0..n {
            tmp[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i]);
        }
        eval(sys, stats, t + C3 * h, tmp, k3)?;
        for i in 0..n {
            tmp[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
        }
        eval(sys, stats, t + C4 * h, tmp, k4)?;
        for i in 0..n {
            tmp[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
        }
        eval(sys, stats, t + C5 * h, tmp, k5)?;
        for i in 0..n {
            tmp[i] =
                y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
        }
        eval(sys, stats, t + h, tmp, k6)?;
        let y_new = &mut st.y_new[..n];
        for i in 0..n {
            y_new[i] =
                y[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i]);
        }
        sys.step_end_next();
        eval(sys, stats, t + h, y_new, k7)?;
        for i in 0..n {
            tmp[i] =
                h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
        }
        if check_state(t + h, y_new).is_err() {
            return Ok(f64::INFINITY);
        }
        Ok(rms_norm(&st.opts.tol, tmp, y, y_new))
    }

    /// With `dense_output` (on a step that reaches [`dense_from`](Self::dense_from)),
    /// stores the interpolant of the accepted step; the FSAL stage `k[6]` is there
    /// already, so this cannot fail.
    fn accept<S: OdeSystem + ?Sized>(
        &mut self,
        st: &mut RkState,
        _sys: &mut S,
        h: f64,
        t_new: f64,
    ) -> Result<(), OdeError> {
        let wanted = self.dense_from.is_none_or(|td| (t_new - td) * h >= 0.0);
        self.dense_ready = st.opts.dense_output && wanted;
        if !self.dense_ready {
            return Ok(());
        }
        let n = st.y.len();
        let [k1, _, k3, k4, k5, k6, k7] = cut(&mut self.k, n);
        let (c1, c) = self.cont.split_at_mut(n);
        let (c2, c) = c.split_at_mut(n);
        let (c3, c) = c.split_at_mut(n);
        let (c4, c5) = c.split_at_mut(n);
        let c5 = &mut c5[..n];
        let (y, y_new) = (&st.y[..n], &st.y_new[..n]);
        for i in 0..n {
            let ydiff = y_new[i] - y[i];
            let bspl = h * k1[i] - ydiff;
            c1[i] = y[i];
            c2[i] = ydiff;
            c3[i] = bspl;
            c4[i] = ydiff - h * k7[i] - bspl;
            c5[i] =
                h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i]);
        }
        Ok(())
    }

    fn forget_dense(&mut self) {
        self.dense_ready = false;
    }

    fn dense(&self, th: f64, out: &mut [f64]) -> Result<(), OdeError> {
        if !self.dense_ready {
            return Err(OdeError::DenseOutputUnavailable);
        }
        let th1 = 1.0 - th;
        let n = out.len();
        let [c1, c2, c3, c4, c5] = std::array::from_fn(|r| &self.cont[r * n..][..n]);
        for i in 0..n {
            out[i] = c1[i] + th * (c2[i] + th1 * (c3[i] + th * (c4[i] + th1 * c5[i])));
        }
        Ok(())
    }
}

embedded_rk_integrator!(
    Dopri5,
    r"Hairer's `CONTD5`: with $\theta = (t - t_{\text{prev}})/h$,
$r_1 + \theta(r_2 + (1-\theta)(r_3 + \theta(r_4 + (1-\theta) r_5)))$, fourth order."
);
