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

use super::common::{check_state, eval, PiController};
use super::dop853_tableau::{A, BHH, C, D, ER};
use super::error::OdeError;
use super::integrator::Integrator;
use super::options::{OdeOptions, OdeStats};
use super::rk_driver::{embedded_rk_integrator, EmbeddedRk, RkDriver, RkState};
use super::stages::{combine, row, Stages};
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
    k: Stages,
    /// Coefficients of the interpolant on the last step (`rcont1..8` of dop853.f),
    /// row `r` at `r * n..(r + 1) * n`.
    cont: Vec<f64>,
    /// Scratch for the fifth-order error estimate (the third-order one is in `tmp`).
    err5: Vec<f64>,
}

impl Dop853 {
    /// An integrator for systems of dimension `dim`.
    ///
    /// # Errors
    /// Invalid options, see [`OdeOptions::validate`].
    pub fn new(dim: usize, opts: OdeOptions) -> Result<Self, OdeError> {
        let ctrl = PiController::new(1.0 / 8.0, 0.0, 0.9, 0.333, 6.0);
        let m = Dp853 {
            dense_ready: false,
            dense_from: None,
            k: Stages::new(dim, 16),
            cont: vec![0.0; 8 * dim],
            err5: vec![0.0; dim],
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
    /// The argument $y + h\sum_j a_{sj} k_j$ of stage `s` (0-based, 1–15) into
    /// `st.tmp`, each row of `A` as an array of its length (checked at compile time).
    #[inline]
    fn argument(&mut self, st: &mut RkState, s: usize, h: f64) {
        let (out, y, done) = (&mut st.tmp, Some(&st.y[..]), self.k.all());
        macro_rules! rows {
            ($($s:literal: $c:literal),* $(,)?) => {
                match s {
                    $( $s => combine(out, y, h, &const { row::<$c>(A[$s]) }, done), )*
                    _ => unreachable!("stage {s} has no argument"),
                }
            };
        }
        rows!(1: 1, 2: 2, 3: 2, 4: 3, 5: 3, 6: 4, 7: 5, 8: 6, 9: 7, 10: 8, 11: 9,
            13: 8, 14: 8, 15: 8);
    }

    /// Evaluates stage `s` (0-based) of a step of size `h` from the current state.
    fn stage<S: OdeSystem + ?Sized>(
        &mut self,
        st: &mut RkState,
        sys: &mut S,
        s: usize,
        h: f64,
    ) -> Result<(), OdeError> {
        self.argument(st, s, h);
        eval(
            sys,
            &mut st.stats,
            st.t + C[s] * h,
            &st.tmp,
            self.k.get_mut(s),
        )
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
        let n = st.y.len();
        let (y, y_new) = (&st.y[..n], &st.y_new[..n]);
        let (k1, kf) = (self.k.get(0), self.k.get(FSAL));
        let (c, rest) = self.cont.split_at_mut(4 * n);
        let (c12, c34) = c.split_at_mut(2 * n);
        let (c1, c2) = c12.split_at_mut(n);
        let (c3, c4) = c34.split_at_mut(n);
        for i in 0..n {
            let ydiff = y_new[i] - y[i];
            let bspl = h * k1[i] - ydiff;
            c1[i] = y[i];
            c2[i] = ydiff;
            c3[i] = bspl;
            c4[i] = ydiff - h * kf[i] - bspl;
        }
        let k = self.k.all();
        for (r, d) in [
            const { row::<12>(D[0]) },
            const { row::<12>(D[1]) },
            const { row::<12>(D[2]) },
            const { row::<12>(D[3]) },
        ]
        .iter()
        .enumerate()
        {
            combine(&mut rest[r * n..][..n], None, h, d, k);
        }
        Ok(())
    }
}

/// The weights $b_j$ of the eighth-order solution (row 12 of `A`).
const B: [(usize, f64); 8] = row::<8>(A[FSAL]);

/// The third-order error estimate's coefficients as one row: $\sum_j b_j k_j - \sum_j
/// \hat b_j k_j$ with $\hat b$ = `BHH` (negated: $e + (-\hat b)k = e - \hat b k$
/// exactly).
const ERR3: [(usize, f64); 11] = {
    let mut out = [(0, 0.0); 11];
    let mut i = 0;
    while i < 8 {
        out[i] = B[i];
        i += 1;
    }
    while i < 11 {
        out[i] = (BHH[i - 8].0, -BHH[i - 8].1);
        i += 1;
    }
    out
};

/// The fifth-order error estimate's coefficients `ER`.
const ERR5: [(usize, f64); 8] = row::<8>(ER);

impl EmbeddedRk for Dp853 {
    const ORDER: i32 = 8;
    const FSAL: usize = FSAL;

    fn stages(&mut self) -> &mut Stages {
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
        let k = self.k.all();
        combine(&mut st.y_new, Some(&st.y), h, &B, k);
        if check_state(st.t + h, &st.y_new).is_err() {
            return Ok(f64::INFINITY);
        }
        // The two estimates with the kernel of the stages (each entry sees the
        // operations of dop853.f in their order: `h = 1` scales nothing), then their
        // sums component by component, in order.
        combine(&mut st.tmp, None, 1.0, &ERR3, k);
        combine(&mut self.err5, None, 1.0, &ERR5, k);
        let n = st.y.len();
        let (err3, err5) = (&st.tmp[..n], &self.err5[..n]);
        let (y, y_new) = (&st.y[..n], &st.y_new[..n]);
        let tol = &st.opts.tol;
        let (mut e5, mut e3) = (0.0, 0.0);
        for i in 0..n {
            let sk = tol.atol(i) + tol.rtol * y[i].abs().max(y_new[i].abs());
            e3 += (err3[i] / sk) * (err3[i] / sk);
            e5 += (err5[i] / sk) * (err5[i] / sk);
        }
        let deno = if e5 + 0.01 * e3 > 0.0 {
            e5 + 0.01 * e3
        } else {
            1.0
        };
        Ok(h.abs() * e5 * (1.0 / (n as f64 * deno)).sqrt())
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
        let mut fsal = eval(sys, &mut st.stats, t_new, &st.y_new, self.k.get_mut(FSAL));
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
        let n = out.len();
        let [r1, r2, r3, r4, r5, r6, r7, r8] = std::array::from_fn(|r| &self.cont[r * n..][..n]);
        for i in 0..n {
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
