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

/// Index in `k` of the first of the three stages only the dense output evaluates.
const DENSE_STAGES: usize = 13;

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
    /// Stage derivatives 1–16 (index = stage − 1); stages 14–16 empty without
    /// `dense_output`.
    k: [Vec<f64>; 16],
    /// Coefficients of the interpolant on the last step (`rcont1..8` of dop853.f);
    /// empty without `dense_output`.
    cont: [Vec<f64>; 8],
}

/// `out = y + h * sum_j a_j k_j` over the listed coefficients.
///
/// Each entry sees the operations of a pass per coefficient ($o \leftarrow y$, then
/// $o \mathrel{+}= (h a_j) k_j$ in the order of the list), with the sum in a register.
/// Dispatched on the number of coefficients (1 to 12 in the tableau) so that the loop
/// over the components runs with the stage derivatives' slices and the products
/// $h a_j$ held outside it, no bounds check inside, and the compiler's vectorization
/// across components; measured by instruction counts in
/// `benchmarks/measurements.md` ("The explicit pairs' stage sums").
#[inline]
fn combine(out: &mut [f64], y: &[f64], h: f64, coeffs: &[(usize, f64)], k: &[Vec<f64>]) {
    macro_rules! by_len {
        ($($l:literal)*) => {
            match coeffs.len() {
                $($l => combine_n::<$l>(out, y, h, coeffs, k),)*
                _ => combine_any(out, y, h, coeffs, k),
            }
        };
    }
    by_len!(0 1 2 3 4 5 6 7 8 9 10 11 12);
}

/// [`combine`] for `L` coefficients.
#[inline(always)]
fn combine_n<const L: usize>(
    out: &mut [f64],
    y: &[f64],
    h: f64,
    coeffs: &[(usize, f64)],
    k: &[Vec<f64>],
) {
    let n = out.len();
    let y = &y[..n];
    let ks: [&[f64]; L] = std::array::from_fn(|c| &k[coeffs[c].0][..n]);
    let ha: [f64; L] = std::array::from_fn(|c| h * coeffs[c].1);
    for (i, (o, y)) in out.iter_mut().zip(y).enumerate() {
        let mut s = *y;
        for (a, kj) in ha.iter().zip(&ks) {
            s += a * kj[i];
        }
        *o = s;
    }
}

/// [`combine`] for any number of coefficients (none of the tableau's).
#[cold]
fn combine_any(out: &mut [f64], y: &[f64], h: f64, coeffs: &[(usize, f64)], k: &[Vec<f64>]) {
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
        // The three dense stages and the interpolant only serve `dense_output`, which
        // is fixed for the integrator's life: without it they stay empty (eleven
        // allocations fewer per run).
        let dense = if opts.dense_output { dim } else { 0 };
        let ctrl = PiController::gustafsson(8.0, 0.333, 6.0);
        let m = Dp853 {
            dense_ready: false,
            dense_from: None,
            k: std::array::from_fn(|s| vec![0.0; if s < DENSE_STAGES { dim } else { dense }]),
            cont: std::array::from_fn(|_| vec![0.0; dense]),
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
        sys.aside(true);
        let stages = (DENSE_STAGES..16).try_for_each(|s| self.stage(st, sys, s, h));
        sys.aside(false);
        stages?;
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
    /// The error sums $(E_3, E_5)$ of [`attempt`](EmbeddedRk::attempt): per component,
    /// the two error estimates summed in registers coefficient by coefficient (each
    /// entry sees the operations of `dop853.f` in their order), then added to the sums
    /// component by component, in order. The stages' slices are taken once, outside
    /// the loop (see [`combine_n`]).
    #[inline(always)]
    fn error_sums(&self, st: &RkState) -> (f64, f64) {
        const NB: usize = A[FSAL].len();
        const NH: usize = BHH.len();
        const NE: usize = ER.len();
        let n = st.y.len();
        let slices = |list: &'static [(usize, f64)], c: usize| &self.k[list[c].0][..n];
        let kb: [&[f64]; NB] = std::array::from_fn(|c| slices(A[FSAL], c));
        let kh: [&[f64]; NH] = std::array::from_fn(|c| slices(BHH, c));
        let ke: [&[f64]; NE] = std::array::from_fn(|c| slices(ER, c));
        let (y, y_new) = (&st.y[..n], &st.y_new[..n]);
        let tol = &st.opts.tol;
        let (mut e3, mut e5) = (0.0, 0.0);
        for i in 0..n {
            let mut err3 = 0.0;
            for (&(_, b), k) in A[FSAL].iter().zip(&kb) {
                err3 += b * k[i];
            }
            for (&(_, b), k) in BHH.iter().zip(&kh) {
                err3 -= b * k[i];
            }
            let mut err5 = 0.0;
            for (&(_, c), k) in ER.iter().zip(&ke) {
                err5 += c * k[i];
            }
            let sk = tol.atol(i) + tol.rtol * y[i].abs().max(y_new[i].abs());
            e3 += (err3 / sk) * (err3 / sk);
            e5 += (err5 / sk) * (err5 / sk);
        }
        (e3, e5)
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
        let (e3, e5) = self.error_sums(st);
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
        sys.step_end_next();
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
