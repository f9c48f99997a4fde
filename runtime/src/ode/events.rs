//! Event location on dense output.
//!
//! Input: an event function $g(t, y)$ and an integrator that has just accepted a step.
//! Output: the first time $t^* \in (t_{\text{prev}}, t]$ where $g$ crosses zero in the
//! requested direction, located on the step's dense output to a time tolerance, with the
//! interpolated state there.
//!
//! This is step 1 of the impact algorithm (docs/theory.md §impacts-in-a-run): the caller applies the jump
//! at $t^*$ and restarts the integrator there with [`Integrator::reset`] (for the Adams
//! method a return to order 1). The root is bracketed by the signs of $g$ at the two
//! ends of the step and refined with the Illinois variant of regula falsi, which keeps a
//! bracket and converges superlinearly. Each step is scanned in four pieces of its
//! dense output, so a step that starts on the surface (right after an impact) and comes
//! back to it is still seen; two crossings closer than a quarter step are not (bound
//! the step with `h_max` if events can be that close).

use super::error::OdeError;
use super::integrator::Integrator;

/// Pieces each step is scanned in for sign changes.
const SUBSTEPS: usize = 4;

/// Which zero crossings of $g$ count as events.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Crossing {
    /// From positive to non-positive (a gap closing).
    Falling,
    /// From negative to non-negative.
    Rising,
    /// Either direction.
    Either,
}

/// Locates the zeros of one event function along an integration.
#[derive(Debug, Clone)]
pub struct EventLocator {
    crossing: Crossing,
    tol: f64,
    g_prev: f64,
    t_prev: f64,
    state: Vec<f64>,
    /// Interpolations spent on root finding so far.
    pub evaluations: u64,
}

impl EventLocator {
    /// A locator for states of dimension `dim`, locating times to within `tol`.
    #[must_use]
    pub fn new(dim: usize, crossing: Crossing, tol: f64) -> EventLocator {
        EventLocator {
            crossing,
            tol: tol.abs().max(f64::EPSILON),
            g_prev: f64::NAN,
            t_prev: f64::NAN,
            state: vec![0.0; dim],
            evaluations: 0,
        }
    }

    /// Records $g$ at the integrator's current state. Call after every
    /// [`reset`](Integrator::reset), so that the next step has a left end.
    pub fn start<I, G>(&mut self, integ: &I, g: &G)
    where
        I: Integrator + ?Sized,
        G: Fn(f64, &[f64]) -> f64,
    {
        self.t_prev = integ.t();
        self.g_prev = g(integ.t(), integ.y());
    }

    fn crosses(&self, a: f64, b: f64) -> bool {
        match self.crossing {
            Crossing::Falling => a > 0.0 && b <= 0.0,
            Crossing::Rising => a < 0.0 && b >= 0.0,
            Crossing::Either => (a > 0.0 && b <= 0.0) || (a < 0.0 && b >= 0.0),
        }
    }

    /// After an accepted step: the event time in the step, if $g$ crossed zero, with
    /// the state there available from [`state`](Self::state). Without an event the
    /// step's right end becomes the next left end.
    ///
    /// # Errors
    /// A failure of the integrator's dense output.
    pub fn check<I, G>(&mut self, integ: &I, g: &G) -> Result<Option<f64>, OdeError>
    where
        I: Integrator + ?Sized,
        G: Fn(f64, &[f64]) -> f64,
    {
        let (t0, g0) = (self.t_prev, self.g_prev);
        let t1 = integ.t();
        let g1 = g(t1, integ.y());
        self.t_prev = t1;
        self.g_prev = g1;
        // Scan the step in SUBSTEPS pieces of the dense output, so that a step that
        // leaves a surface and comes back to it (a restart on the ground followed by a
        // long step) still shows its crossing.
        let (mut a, mut ga) = (t0, g0);
        if ga == 0.0 {
            // The step starts on the surface (a restart right after an event): take the
            // side it leaves towards, just inside the step, as the starting sign.
            a = t0 + 1e-6 * (t1 - t0);
            integ.interpolate(a, &mut self.state)?;
            self.evaluations += 1;
            ga = g(a, &self.state);
        }
        let a0 = a;
        let mut bracket = None;
        for j in 1..=SUBSTEPS {
            #[allow(clippy::cast_precision_loss)]
            let frac = j as f64 / SUBSTEPS as f64;
            let (tj, gj) = if j == SUBSTEPS {
                (t1, g1)
            } else {
                let tj = a0 + (t1 - a0) * frac;
                integ.interpolate(tj, &mut self.state)?;
                self.evaluations += 1;
                (tj, g(tj, &self.state))
            };
            if self.crosses(ga, gj) {
                bracket = Some((a, ga, tj, gj));
                break;
            }
            (a, ga) = (tj, gj);
        }
        let Some((a, ga, b, gb)) = bracket else {
            return Ok(None);
        };
        if gb == 0.0 {
            integ.interpolate(b, &mut self.state)?;
            self.t_prev = b;
            self.g_prev = gb;
            return Ok(Some(b));
        }
        // Illinois regula falsi on [a, b] with g(a), g(b) of opposite signs.
        let (mut a, mut ga, mut b, mut gb) = (a, ga, b, gb);
        let mut side = 0i8;
        let mut t = b;
        for _ in 0..200 {
            if (b - a).abs() <= self.tol {
                break;
            }
            t = (a * gb - b * ga) / (gb - ga);
            if !(t > a.min(b) && t < a.max(b)) {
                t = 0.5 * (a + b);
            }
            integ.interpolate(t, &mut self.state)?;
            self.evaluations += 1;
            let gt = g(t, &self.state);
            if gt == 0.0 {
                a = t;
                b = t;
                break;
            }
            if (gt > 0.0) == (ga > 0.0) {
                a = t;
                ga = gt;
                if side == -1 {
                    gb *= 0.5;
                }
                side = -1;
            } else {
                b = t;
                gb = gt;
                if side == 1 {
                    ga *= 0.5;
                }
                side = 1;
            }
        }
        // Report the end of the bracket on the far side of the crossing, so that the
        // event has happened at the reported time.
        let t_event = if a == b { t } else { b };
        integ.interpolate(t_event, &mut self.state)?;
        self.g_prev = g(t_event, &self.state);
        self.t_prev = t_event;
        Ok(Some(t_event))
    }

    /// The interpolated state at the last located event.
    #[must_use]
    pub fn state(&self) -> &[f64] {
        &self.state
    }
}
