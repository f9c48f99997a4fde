//! The guard of a run's kept states: a run whose constraint violation or energy drift
//! grows beyond what its tolerance and the model's scale allow stops with
//! [`SimErrorKind::Diverged`] instead of returning a wrong answer.
//!
//! Input: the states the driver keeps (accepted steps and output rows), with $C$ and the
//! pattern values of $C_q$ already evaluated there. Output: `None`, or the failure.
//!
//! The scales (see `crate::scale` for the convergence tests' model):
//!
//! - **a constraint's size** $s_i = \sum_j |(C_q)_{ij}|\, S_j / \lVert (C_q)_i\rVert_\infty$,
//!   with $S_j$ the largest $|q_j|$ seen so far: the size of the coordinates the
//!   constraint involves, weighted as it involves them (a pin joint's rows weigh the
//!   coupler's position in metres, not the crank's angle in radians). Its violation is
//!   the distance $d_i = |C_i| / \lVert (C_q)_i\rVert_\infty$ of $q$ from its surface,
//!   in the same units. Allowed: $\min(F(\text{rtol}\,s_i + \text{atol}),\ c\,s_i)$.
//! - **the energy scale** of a conservative model $E_s = \max(T_\text{max},
//!   V_\text{max} - V_\text{min})$ over the states seen so far: the energy the motion
//!   exchanges. Allowed drift: $\min(F\,\text{tol}, c)\,E_s$, with
//!   $\text{tol} = \text{rtol} + \text{atol}/\lVert q_0\rVert_\infty$.
//!
//! Baumgarte's violation is set by its gains, not by the tolerance: its bound is
//! $c\,s_i$ alone.
//!
//! $F = 10^4$ and $c = 5\,\%$: a correct run keeps both within a few times its tolerance
//! (the built-in models' default runs in every formulation stay below $10^{-2}$ of the
//! bounds); a run that leaves the motion (Baumgarte past its stability limit, a step
//! across a singular configuration onto another branch, a divergence) exceeds them by
//! orders of magnitude. A fixed step (RK4) has no tolerance: its bound is 50 %. Both
//! bounds have a floor at $10^3$ times the rounding of the quantity.

use super::error::{Monitored, SimErrorKind};
use crate::Info;

/// How many times the tolerance a kept state may be off its constraints or energy.
pub(crate) const FACTOR: f64 = 1e4;

/// The largest relative violation or energy drift accepted at any tolerance.
pub(crate) const CAP: f64 = 0.05;

/// How many times the motion's scale at the start the coordinates may grow to.
pub(crate) const GROWTH: f64 = 1e6;

/// The relative bound of a fixed step (RK4), which has no tolerance to relate to: a
/// coarse step legitimately drifts by several percent (the pendulum's energy by 5 % at
/// the steps of the proportionality tests), so only gross failures stop it.
pub(crate) const FIXED_CAP: f64 = 0.5;

/// Rounding floor of the bounds, relative to the size of the quantity.
const ROUNDING: f64 = 1e3 * f64::EPSILON;

pub(crate) struct Guard {
    info: &'static Info,
    /// `(rtol, atol)`, `None` for a fixed step.
    tolerances: Option<(f64, f64)>,
    /// Whether the constraints' violation is held to the tolerance (partitioning and
    /// projection correct it to their Newton tolerance) or only to [`CAP`] (Baumgarte,
    /// whose violation its gains set, not the tolerance).
    corrected: bool,
    /// $S_j$, the largest $|q_j|$ seen.
    size: Vec<f64>,
    /// Per row: $\sum_j |(C_q)_{ij}| S_j$ and $\lVert (C_q)_i\rVert_\infty$.
    weighted: Vec<f64>,
    norm: Vec<f64>,
    /// $\lVert q_0\rVert_\infty$.
    size0: Option<f64>,
    kinetic_max: f64,
    potential_range: (f64, f64),
    /// The motion's scale at the start (see [`Monitored::Coordinates`]).
    motion: f64,
}

impl Guard {
    pub fn new(info: &'static Info, tolerances: Option<(f64, f64)>, corrected: bool) -> Self {
        Self {
            info,
            tolerances,
            corrected,
            size: vec![0.0; info.nq()],
            weighted: vec![0.0; info.nh()],
            norm: vec![0.0; info.nh()],
            size0: None,
            kinetic_max: 0.0,
            potential_range: (f64::INFINITY, f64::NEG_INFINITY),
            motion: f64::INFINITY,
        }
    }

    /// The relative bound: $\min(F\,\text{tol}, c)$.
    fn relative(&self, tol: f64) -> f64 {
        match self.tolerances {
            Some(_) => (FACTOR * tol).min(CAP),
            None => FIXED_CAP,
        }
    }

    /// Sets the motion's scale from the initial state and accelerations over the span,
    /// at least `floor` (atol / rtol: below it the tolerance treats a coordinate as
    /// absolute, so a model at rest at the origin that a drive sets moving is measured
    /// from there).
    pub fn set_motion(&mut self, q: &[f64], qd: &[f64], qdd: &[f64], span: f64, floor: f64) {
        let norm = crate::linalg::inf_norm;
        self.motion = (norm(q) + norm(qd) * span + 0.5 * norm(qdd) * span * span).max(floor);
        if !(self.motion.is_finite() && self.motion > 0.0) {
            self.motion = f64::INFINITY;
        }
    }

    /// Checks the positions `q` against the residuals `c` and the pattern values
    /// `cq` of $C_q$ at them.
    pub fn positions(&mut self, t: f64, q: &[f64], c: &[f64], cq: &[f64]) -> Option<SimErrorKind> {
        let mut global = 0.0_f64;
        for (s, &x) in self.size.iter_mut().zip(q) {
            // A NaN is the non-finite guards' to report.
            if x.is_finite() {
                *s = s.max(x.abs());
            }
            global = global.max(*s);
        }
        self.size0.get_or_insert(global);
        let (j, largest) = q.iter().enumerate().fold((0, 0.0_f64), |(k, m), (j, x)| {
            if x.abs() > m {
                (j, x.abs())
            } else {
                (k, m)
            }
        });
        if largest > GROWTH * self.motion {
            return Some(SimErrorKind::Diverged {
                t,
                quantity: Monitored::Coordinates {
                    coordinate: self.info.coordinates[j].name,
                },
                value: largest,
                bound: GROWTH * self.motion,
            });
        }
        if c.is_empty() {
            return None;
        }
        self.weighted.fill(0.0);
        self.norm.fill(0.0);
        for (&(r, j), &v) in self.info.holonomic_pattern.iter().zip(cq) {
            let (r, j) = (r as usize, j as usize);
            self.weighted[r] += v.abs() * self.size[j];
            self.norm[r] = self.norm[r].max(v.abs());
        }
        let floor = ROUNDING * global;
        let mut worst: Option<(usize, f64, f64)> = None;
        for (i, &ci) in c.iter().enumerate() {
            let norm = self.norm[i];
            if !(norm > 0.0 && ci.is_finite()) {
                continue;
            }
            let distance = ci.abs() / norm;
            let s = self.weighted[i] / norm;
            let allowed = match (self.tolerances, self.corrected) {
                (Some((rtol, atol)), true) => (FACTOR * (rtol * s + atol)).min(CAP * s),
                (Some(_), false) => CAP * s,
                (None, _) => FIXED_CAP * s,
            }
            .max(floor);
            if distance > allowed && worst.is_none_or(|(_, d, a)| distance / allowed > d / a) {
                worst = Some((i, distance, allowed));
            }
        }
        worst.map(|(i, value, bound)| SimErrorKind::Diverged {
            t,
            quantity: Monitored::PositionViolation {
                constraint: self.info.holonomic[i].name,
            },
            value,
            bound,
        })
    }

    /// Checks the energy of a conservative model (after [`positions`](Self::positions)
    /// at the same state): kinetic `kinetic`, potential `potential`, the run's initial
    /// energy `e0` and the impacts' losses so far `lost`.
    pub fn energy(
        &mut self,
        t: f64,
        (kinetic, potential): (f64, f64),
        e0: f64,
        lost: f64,
    ) -> Option<SimErrorKind> {
        if !(kinetic.is_finite() && potential.is_finite()) {
            return None;
        }
        let e = kinetic + potential;
        self.kinetic_max = self.kinetic_max.max(kinetic);
        let (lo, hi) = &mut self.potential_range;
        *lo = lo.min(potential);
        *hi = hi.max(potential);
        let scale = self.kinetic_max.max(*hi - *lo);
        let tol = match (self.tolerances, self.size0) {
            (Some((rtol, atol)), Some(s)) if s > 0.0 => rtol + atol / s,
            (Some((rtol, _)), _) => rtol,
            (None, _) => 0.0,
        };
        let bound = (self.relative(tol) * scale).max(ROUNDING * (kinetic.abs() + potential.abs()));
        let drift = (e - (e0 - lost)).abs();
        (drift > bound).then_some(SimErrorKind::Diverged {
            t,
            quantity: Monitored::EnergyDrift,
            value: drift,
            bound,
        })
    }
}
