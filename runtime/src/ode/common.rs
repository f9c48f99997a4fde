//! Small kernels shared by the integrators: checked evaluation of the right-hand side,
//! error norms, Hairer's initial step size and the stop-time rule.
//!
//! Input: slices of equal length $n$. Output: scalars or slices written in place.
//! Invariants: nothing here allocates; every derivative that leaves [`eval`] is finite.

use super::error::{OdeError, Quantity};
use super::options::{OdeStats, Tolerances};
use super::system::OdeSystem;

/// Machine epsilon $2^{-52}$, the `UROUND` of Hairer's codes and the `u` of Shampine–Gordon.
pub(crate) const UROUND: f64 = f64::EPSILON;

/// Index of the first NaN or infinite entry. The common case, all finite, is one
/// branch-free pass ([`all_finite`](crate::workspace::all_finite)); the position is
/// searched only after it fails.
#[inline]
pub(crate) fn first_non_finite(x: &[f64]) -> Option<usize> {
    if crate::workspace::all_finite(x) {
        return None;
    }
    x.iter().position(|v| !v.is_finite())
}

/// Checks that a state is finite.
pub(crate) fn check_state(t: f64, y: &[f64]) -> Result<(), OdeError> {
    match first_non_finite(y) {
        Some(component) => Err(OdeError::NonFinite {
            t,
            component,
            quantity: Quantity::State,
        }),
        None => Ok(()),
    }
}

/// Checks the length of a slice against the dimension.
#[inline]
pub(crate) fn check_len(expected: usize, found: usize) -> Result<(), OdeError> {
    if expected == found {
        Ok(())
    } else {
        Err(OdeError::DimensionMismatch { expected, found })
    }
}

/// Evaluates $f(t, y)$ into `dy`, counts it, and checks the output for NaN and infinity.
#[inline]
pub(crate) fn eval<S: OdeSystem + ?Sized>(
    sys: &mut S,
    stats: &mut OdeStats,
    t: f64,
    y: &[f64],
    dy: &mut [f64],
) -> Result<(), OdeError> {
    stats.rhs_evals += 1;
    sys.rhs(t, y, dy)
        .map_err(|source| OdeError::Rhs { t, source })?;
    match first_non_finite(dy) {
        Some(component) => Err(OdeError::NonFinite {
            t,
            component,
            quantity: Quantity::Derivative,
        }),
        None => Ok(()),
    }
}

/// Whether an error only rejects the step attempt: a recoverable failure of the
/// right-hand side (see [`RhsError::recoverable`](super::RhsError::recoverable)).
#[inline]
pub(crate) fn is_recoverable(e: &OdeError) -> bool {
    matches!(e, OdeError::Rhs { source, .. } if source.is_recoverable())
}

/// Step-size factor after a recoverable failure of the right-hand side: as after a
/// Newton failure in implicit codes (Hairer's `RADAU5` halves, DASSL quarters), a
/// drastic cut, since the failure carries no error estimate to scale by.
pub(crate) const RECOVER_FACTOR: f64 = 0.25;

/// Whether a step of size `h` from `t` is below what `t` can resolve (Hairer's rule
/// $0.1|h| \le |t|\,u$).
#[inline]
pub(crate) fn underflows(t: f64, h: f64) -> bool {
    0.1 * h.abs() <= t.abs() * UROUND
}

/// The mixed RMS norm of a local error estimate `err`,
/// $\sqrt{\frac1n\sum_i (e_i/s_i)^2}$ with $s_i = \text{atol}_i + \text{rtol}\max(|y_i|, |\hat y_i|)$.
#[inline]
pub(crate) fn rms_norm(tol: &Tolerances, err: &[f64], y: &[f64], y_new: &[f64]) -> f64 {
    let mut sum = 0.0;
    for (i, ((e, a), b)) in err.iter().zip(y).zip(y_new).enumerate() {
        let sk = tol.atol(i) + tol.rtol * a.abs().max(b.abs());
        sum += (e / sk) * (e / sk);
    }
    (sum / err.len().max(1) as f64).sqrt()
}

/// Hairer's `HINIT` (dopri5.f, dop853.f): a first step size $h$ such that
/// $h^{p}\max(\|f_0\|, \|f'\|) \approx 0.01$, where $f'$ is estimated from one explicit
/// Euler step. Costs one evaluation; uses `y1` and `f1` as scratch.
#[allow(clippy::too_many_arguments)]
pub(crate) fn hinit<S: OdeSystem + ?Sized>(
    sys: &mut S,
    stats: &mut OdeStats,
    tol: &Tolerances,
    order: i32,
    h_max: f64,
    dir: f64,
    (t, y, f0): (f64, &[f64], &[f64]),
    y1: &mut [f64],
    f1: &mut [f64],
) -> Result<f64, OdeError> {
    let sk = |i: usize| tol.atol(i) + tol.rtol * y[i].abs();
    let (mut dnf, mut dny) = (0.0, 0.0);
    for i in 0..y.len() {
        dnf += (f0[i] / sk(i)).powi(2);
        dny += (y[i] / sk(i)).powi(2);
    }
    let mut h = if dnf <= 1e-10 || dny <= 1e-10 {
        1e-6
    } else {
        (dny / dnf).sqrt() * 0.01
    };
    h = h.min(h_max) * dir;
    for i in 0..y.len() {
        y1[i] = y[i] + h * f0[i];
    }
    if let Err(e) = eval(sys, stats, t + h, y1, f1) {
        if !is_recoverable(&e) {
            return Err(e);
        }
        // The explicit Euler step went too far for the system: start below it.
        return Ok(h * RECOVER_FACTOR);
    }
    let mut der2 = 0.0;
    for i in 0..y.len() {
        der2 += ((f1[i] - f0[i]) / sk(i)).powi(2);
    }
    let der2 = der2.sqrt() / h.abs();
    let der12 = der2.max(dnf.sqrt());
    let h1 = if der12 <= 1e-15 {
        (h.abs() * 1e-3).max(1e-6)
    } else {
        (0.01 / der12).powf(1.0 / f64::from(order))
    };
    Ok((100.0 * h.abs()).min(h1).min(h_max) * dir)
}

/// Where a step of size `h` from `t` may go given a stop time: returns the step size to
/// use and whether it lands exactly on `t_stop`. As in Hairer's codes, a step that
/// would end within 1% short of `t_stop` is stretched to it.
#[inline]
pub(crate) fn limit_to_stop(t: f64, h: f64, t_stop: Option<f64>) -> (f64, bool) {
    match t_stop {
        Some(ts) if (t + 1.01 * h - ts) * h.signum() >= 0.0 => (ts - t, true),
        _ => (h, false),
    }
}

/// Validates a stop time against the direction `dir`; `Ok(true)` when already there.
#[inline]
pub(crate) fn check_stop(t: f64, dir: f64, t_stop: Option<f64>) -> Result<bool, OdeError> {
    match t_stop {
        Some(ts) if ts.is_nan() || (ts - t) * dir < 0.0 => {
            Err(OdeError::StopBehind { t, t_stop: ts })
        }
        Some(ts) => Ok(ts == t),
        None => Ok(false),
    }
}

/// Checks that `t` lies in the step `[t0, t1]` (either orientation), allowing for
/// round-off in the end points.
#[inline]
pub(crate) fn check_in_step(t: f64, t0: f64, t1: f64) -> Result<(), OdeError> {
    let (lo, hi) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
    let slack = 4.0 * UROUND * lo.abs().max(hi.abs()) + 1e-12 * (hi - lo);
    if t >= lo - slack && t <= hi + slack {
        Ok(())
    } else {
        Err(OdeError::OutsideStep {
            t,
            t_prev: t0,
            t_cur: t1,
        })
    }
}

/// The argument checks of `interpolate`: `out` as long as `y`, `t` in the step
/// `[t_prev, t_cur]`. Before the first step (`fresh`) the only value is `y`: it is
/// written to `out` and `Ok(true)` returned.
#[inline]
pub(crate) fn interpolate_prelude(
    t: f64,
    (t_prev, t_cur): (f64, f64),
    y: &[f64],
    fresh: bool,
    out: &mut [f64],
) -> Result<bool, OdeError> {
    check_len(y.len(), out.len())?;
    check_in_step(t, t_prev, t_cur)?;
    if fresh {
        out.copy_from_slice(y);
    }
    Ok(fresh)
}

/// The common part of `set_state`: checks `new` (length, finite at `t`), copies it
/// into `y` and counts the update. On error `y` is left unchanged.
#[inline]
pub(crate) fn replace_state(
    t: f64,
    y: &mut [f64],
    new: &[f64],
    stats: &mut OdeStats,
) -> Result<(), OdeError> {
    check_len(y.len(), new.len())?;
    check_state(t, new)?;
    y.copy_from_slice(new);
    stats.state_updates += 1;
    Ok(())
}

/// The step-size controller of the explicit pairs: a PI controller in the form of
/// Hairer's `dopri5.f` and `dop853.f`,
/// $$h_{\text{new}} = h\Big/\operatorname{clamp}\!\Big(\frac{\text{err}^{\alpha}}
/// {\text{err}_{\text{old}}^{\beta}\,\text{safe}},\ \tfrac1{\text{fac}_2},\ \tfrac1{\text{fac}_1}\Big),$$
/// with Gustafsson's predictive limit as in Hairer's `radau5.f`: after an accepted step
/// $h$ that followed an accepted step $h_{\text{acc}}$ with error $\text{err}_{\text{acc}}$,
/// the divisor is at least
/// $\frac{h_{\text{acc}}}{h}\big(\text{err}^2/\text{err}_{\text{acc}}\big)^{1/q}/\text{safe}$
/// (clamped alike): the trend of the error over the last two steps is extrapolated, so
/// that a step growing into faster motion is shortened before it fails. After a
/// rejection the step is cut by $\text{err}^{1/q}/\text{safe}$ (at most by $\text{fac}_1$).
///
/// [`PiController::gustafsson`] is the one in use;
/// `docs/decisions/0025-explicit-pairs-step-size-control.md` has the measurements that
/// chose it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PiController {
    expo1: f64,
    beta: f64,
    safe: f64,
    facc1: f64,
    facc2: f64,
    facold: f64,
    /// The exponent $1/q$ of the predictive limit and of the cut after a rejection.
    expo: f64,
    predictive: Predictive,
}

/// Gustafsson's predictive limit (Hairer's `radau5.f`): remembers the last accepted step
/// and its error, and after the next accepted step $h$ with error $\text{err}$ gives the
/// least divisor of $h$ it allows,
/// $\frac{h_{\text{acc}}}{h}\big(\text{err}^2/\text{err}_{\text{acc}}\big)^{e}/\text{safe}$
/// (unclamped): the error's trend over the two steps, extrapolated. Shared by
/// [`PiController`] and `Radau5`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Predictive {
    /// The last accepted step size (0 before the first) and its error (at least 0.01).
    h_acc: f64,
    err_acc: f64,
}

impl Predictive {
    /// Nothing accepted yet (and after a reset).
    pub(crate) const NEW: Self = Self {
        h_acc: 0.0,
        err_acc: ERRACC_MIN,
    };

    /// After an accepted step of size `h` with error `err`: the limit's divisor with
    /// exponent `expo` and safety factor `safe` (`None` when no step was accepted
    /// before); remembers this step.
    pub(crate) fn accept(&mut self, h: f64, err: f64, expo: f64, safe: f64) -> Option<f64> {
        let limit = (self.h_acc != 0.0)
            .then(|| (self.h_acc / h) * (err * err / self.err_acc).powf(expo) / safe);
        self.h_acc = h;
        self.err_acc = err.max(ERRACC_MIN);
        limit
    }
}

/// The least error the controllers remember: $\text{err}_{\text{old}}$ of the PI term
/// (Hairer's `FACOLD`) and $\text{err}_{\text{acc}}$ of the predictive limit (`radau5.f`).
const FACOLD_MIN: f64 = 1e-4;
const ERRACC_MIN: f64 = 1e-2;

/// The safety factor of [`PiController::gustafsson`]: 0.85 rather than Hairer's 0.9,
/// measured to keep the loose end of the work-precision curves monotone
/// (docs/decisions/0025-explicit-pairs-step-size-control.md).
const SAFE: f64 = 0.85;

impl PiController {
    /// Gustafsson's PI.3.4 (integral gain 0.3, proportional gain 0.4: $\alpha = 0.7/q$,
    /// $\beta = 0.4/q$; Gustafsson, ACM TOMS 17, 1991) with the predictive limit and
    /// $\text{safe} = 0.85$, for an error estimate that behaves like $h^q$; `fac1` bounds
    /// the decrease of the step size, `fac2` its increase.
    pub(crate) fn gustafsson(q: f64, fac1: f64, fac2: f64) -> Self {
        Self::new(0.7 / q, 0.4 / q, SAFE, (fac1, fac2), 1.0 / q)
    }

    /// `expo1` is $\alpha$ above, `expo` is $1/q$.
    fn new(expo1: f64, beta: f64, safe: f64, (fac1, fac2): (f64, f64), expo: f64) -> Self {
        Self {
            expo1,
            beta,
            safe,
            facc1: 1.0 / fac1,
            facc2: 1.0 / fac2,
            facold: FACOLD_MIN,
            expo,
            predictive: Predictive::NEW,
        }
    }

    /// Forgets the previous errors and steps (at reset).
    pub(crate) fn reset(&mut self) {
        self.facold = FACOLD_MIN;
        self.predictive = Predictive::NEW;
    }

    /// The next step size after an attempt of size `h` with error `err` (a NaN or an
    /// infinite error counts as a huge one). Returns `(h_new, accepted)`.
    pub(crate) fn control(&mut self, err: f64, h: f64) -> (f64, bool) {
        let err = if err.is_finite() { err } else { f64::MAX };
        if err <= 1.0 {
            let pi = err.powf(self.expo1) / self.facold.powf(self.beta) / self.safe;
            let mut fac = pi.min(self.facc1).max(self.facc2);
            self.facold = err.max(FACOLD_MIN);
            if let Some(gus) = self.predictive.accept(h, err, self.expo, self.safe) {
                fac = fac.max(gus.min(self.facc1).max(self.facc2));
            }
            (h / fac, true)
        } else {
            (h / self.facc1.min(err.powf(self.expo) / self.safe), false)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{PiController, SAFE};

    /// A rejection cuts by $\text{err}^{1/q}/\text{safe}$, at most by $\text{fac}_1$; a
    /// NaN or infinite error counts as a huge one.
    #[test]
    fn a_rejection_cuts_by_the_error_of_the_attempt() {
        let mut c = PiController::gustafsson(8.0, 0.333, 6.0);
        let (h, ok) = c.control(2f64.powi(8), 1.0);
        assert!(!ok);
        assert!((h - SAFE / 2.0).abs() < 1e-15, "{h}");
        for err in [1e30, f64::NAN, f64::INFINITY] {
            let (h, ok) = c.control(err, 1.0);
            assert!(!ok);
            assert!((h - 0.333).abs() < 1e-15, "{err}: {h}");
        }
    }

    /// On the model of the local error, $\text{err} = (h/h_0)^q$, the closed loop settles
    /// where the PI term is 1, $\text{err}^{(\alpha-\beta)} = \text{safe}$, i.e.
    /// $\text{err}^* = \text{safe}^{q/0.3}$, with every step accepted, from a step far too small
    /// and from one just acceptable.
    #[test]
    fn on_the_model_problem_the_step_settles_at_the_fixed_point() {
        for q in [5.0, 8.0] {
            let fixed = SAFE.powf(q / 0.3);
            for h_start in [1e-3_f64, 0.999] {
                let mut c = PiController::gustafsson(q, 0.2, 10.0);
                let mut h = h_start;
                let mut rejected = 0;
                for _ in 0..200 {
                    let (h_new, ok) = c.control(h.powf(q), h);
                    rejected += usize::from(!ok);
                    h = h_new;
                }
                let err = h.powf(q);
                assert!((err / fixed - 1.0).abs() < 1e-6, "q {q}: {err} vs {fixed}");
                assert_eq!(rejected, 0, "q {q} from {h_start}");
            }
        }
    }

    /// The predictive limit: after two accepted steps whose error grew, the next step is
    /// the smaller of the PI step and Gustafsson's extrapolation
    /// $h\,\text{safe}\,(h/h_{\text{acc}})^{-1}(\text{err}_{\text{acc}}/\text{err}^2)^{1/q}$;
    /// after [`reset`](PiController::reset) the first step has no such limit again.
    #[test]
    fn a_growing_error_is_extrapolated() {
        let q = 8.0;
        let mut c = PiController::gustafsson(q, 0.333, 6.0);
        let (h1, ok) = c.control(0.02, 1.0);
        assert!(ok);
        let pi1 = 0.02f64.powf(0.7 / q) / 1e-4f64.powf(0.4 / q) / SAFE;
        assert!((h1 - 1.0 / pi1.clamp(1.0 / 6.0, 1.0 / 0.333)).abs() < 1e-14);
        // The second step, of size h1, has a much larger error.
        let (h2, ok) = c.control(0.8, h1);
        assert!(ok);
        let pi =
            (0.8f64.powf(0.7 / q) / 0.02f64.powf(0.4 / q) / SAFE).clamp(1.0 / 6.0, 1.0 / 0.333);
        let gus =
            ((1.0 / h1) * (0.64f64 / 0.02).powf(1.0 / q) / SAFE).clamp(1.0 / 6.0, 1.0 / 0.333);
        assert!(gus > pi, "the case must exercise the limit");
        assert!((h2 - h1 / gus).abs() < 1e-14, "{h2} vs {}", h1 / gus);
        c.reset();
        let (h, _) = c.control(0.02, 1.0);
        assert_eq!(h, h1);
    }
}
