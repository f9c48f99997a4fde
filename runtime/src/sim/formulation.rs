//! The formulations of [`Formulation`]: one implementation of [`Form`] each, on the
//! shared [`Point`].
//!
//! Input: the integrator's state $y = [q; \dot q]$ and the current [`Point`]. Output: the
//! full state the formulation assigns to $y$ ([`Form::reconstruct`]), $\ddot q$
//! ([`Form::accelerations`]), the corrections of kept states ([`Form::keep`]) and what
//! the integrator must do with them ([`Form::CORRECTION`]), and which failures of the
//! right-hand side only reject a step attempt ([`Form::recoverable`]).
//!
//! | formulation | reconstruct | kept states | failures that reject an attempt |
//! |---|---|---|---|
//! | [`Partitioned`] | the point of the chart of the last accepted state | polished to the Newton tolerance; the derivative stays valid | the chart's Newton, a singular projection, redundant rows inconsistent |
//! | [`Projected`] | $y$ as it is | projected on $C = 0$, $J\dot q + c = 0$ | redundant rows inconsistent |
//! | [`Stabilized`] | $y$ as it is | as they are | none |
//! | [`Free`] | $y$ as it is | as they are | none |

use super::chart::{Chart, ChartFailure, VelocityTerms, KAPPA};
use super::error::{SimErrorKind, SingularMatrix};
use super::point::{Point, REFIT_RATIO, SINGULAR_RATIO};
use super::Formulation;
use crate::linalg::inf_norm;
use crate::Mechanism;

/// Relative size of a Newton correction of the integrator's prediction that never
/// counts as a branch switch (see [`Partitioned`]), for the evaluations that hardly
/// move (a correction within the integrator's tolerance never counts either).
const BRANCH_FLOOR: f64 = 1e-8;

/// Fraction of its value when the rows were chosen below which the pivot ratio of the
/// chart's $N N^\mathsf{T}$ renews the kept rows of a model with redundant constraints:
/// the kept rows are turning dependent while the dropped ones could take over.
const REFIT_FRACTION: f64 = 1e-2;

/// What the driver does with a kept state after [`Form::keep`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Correction {
    /// Nothing changed.
    None,
    /// The state changed, its derivative did not: the integrator keeps its derivatives.
    SameDerivative,
    /// The state and its derivative changed.
    Changed,
}

/// One way of turning the constrained equations into an ODE on $y = [q; \dot q]$.
pub(crate) trait Form {
    /// What [`keep`](Self::keep) does to an accepted state, for the integrator.
    const CORRECTION: Correction;

    /// Takes the current full state of `p` (consistent, at `t`) as the last accepted
    /// one. By default there is nothing to take: the formulation keeps no state of
    /// its own.
    fn accept<M: Mechanism + ?Sized>(
        &mut self,
        _p: &mut Point<'_, M>,
        _t: f64,
    ) -> Result<(), SimErrorKind> {
        Ok(())
    }

    /// Fills `p.q`, `p.qd` from the state `y` at `t`. By default `y` is $[q; \dot q]$
    /// itself.
    fn reconstruct<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        _t: f64,
        y: &[f64],
    ) -> Result<(), SimErrorKind> {
        copy_state(p, y);
        Ok(())
    }

    /// $\ddot q$ and $\lambda$ at the full state of `p`.
    fn accelerations<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<(), SimErrorKind>;

    /// Fills `p` from `y` at `t` for a state the driver keeps (accepted or output),
    /// before [`keep`](Self::keep) corrects it.
    fn reconstruct_kept<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
        y: &[f64],
    ) -> Result<(), SimErrorKind> {
        self.reconstruct(p, t, y)
    }

    /// Corrects a state the driver keeps (accepted or output), already reconstructed.
    /// By default it is kept as integrated ([`Correction::None`]).
    fn keep<M: Mechanism + ?Sized>(
        &mut self,
        _p: &mut Point<'_, M>,
        _t: f64,
    ) -> Result<(), SimErrorKind> {
        Ok(())
    }

    /// Whether a failure of the right-hand side only rejects the step attempt. By
    /// default none does: every failure ends the run with its typed error.
    fn recoverable(&self, _e: &SimErrorKind) -> bool {
        false
    }
}

/// Whether `e` is the augmented solve's inconsistency of redundant rows: a failure of a
/// trial state near a rank drop of $C_q$, off the constraints by the step's error (the
/// first-order bound of the dropped rows' residual assumes consistent positions), is
/// rejected like a failed Newton iteration, and a shorter step brings the stage back;
/// a genuinely inconsistent set fails every retry and ends the run with the typed error
/// (docs/decisions/0036-through-a-rank-drop.md).
fn inconsistent_redundant(e: &SimErrorKind) -> bool {
    matches!(
        e,
        SimErrorKind::Analysis(crate::Error::Dynamics(
            crate::DynamicsError::InconsistentRedundant { .. }
        ))
    )
}

/// Copies $y = [q; \dot q]$ into the state of `p` ([`Point::set_state`]).
fn copy_state<M: Mechanism + ?Sized>(p: &mut Point<'_, M>, y: &[f64]) {
    p.set_state(y);
}

/// Coordinate partitioning in the local chart of the last accepted state
/// ([`Formulation::Partitioning`], see [`Chart`]).
///
/// The chart's Newton converges to the intersection of the normal space through the
/// prediction with the manifold nearest to it; a correction larger than the move from
/// the last accepted state means it went to another one (the mirror assembly of a
/// loop), so the evaluation fails, recoverably.
#[derive(Debug)]
pub(crate) struct Partitioned {
    chart: Chart,
    /// The last accepted positions, their time and the largest accepted speed
    /// $\|\dot q\|_\infty$: in a rheonomic model the manifold moves with time, so an
    /// evaluation at the accepted positions but a later time needs a correction of
    /// about $|t - t_a|\,\|\dot q_a\|_\infty$ (Radau5's first stage guesses are the
    /// accepted state itself), which is no branch switch.
    accepted: Vec<f64>,
    t_accepted: f64,
    speed_accepted: f64,
    /// Pivot ratio of the chart's $N N^\mathsf{T}$ when its rows were last chosen (0
    /// before the first anchor): the reference of [`REFIT_FRACTION`].
    fit_ratio: f64,
    /// The `(t, y)` whose state is in the point (the last reconstruction), so that the
    /// driver's reconstruction of an accepted state the integrator has just evaluated
    /// costs nothing.
    cached: Option<f64>,
    y_cached: Vec<f64>,
    /// Whether the velocities of the point are still to be projected (with the
    /// dynamics terms, in [`Form::accelerations`]).
    pending: bool,
    /// Whether the last kept state was left off the chart by
    /// [`reconstruct_kept`](Form::reconstruct_kept) (its chord did not converge).
    off_chart: bool,
}

impl Partitioned {
    pub fn new(n: usize, m: usize, mh: usize, (rtol, atol): (f64, f64)) -> Self {
        Self {
            chart: Chart::new(n, m, mh, rtol, atol),
            accepted: vec![0.0; n],
            t_accepted: 0.0,
            speed_accepted: 0.0,
            fit_ratio: 0.0,
            cached: None,
            y_cached: vec![0.0; 2 * n],
            pending: false,
            off_chart: false,
        }
    }

    /// Whether a pivot ratio of $N N^\mathsf{T}$ calls for renewing the kept rows (see
    /// [`REFIT_FRACTION`]).
    fn worse(&self, ratio: f64) -> bool {
        ratio.is_nan() || ratio <= REFIT_RATIO || ratio < REFIT_FRACTION * self.fit_ratio
    }
}

impl Form for Partitioned {
    const CORRECTION: Correction = Correction::SameDerivative;

    /// Anchors the chart of the next step at the accepted state: the maps
    /// [`keep`](Form::keep) staged for it when it was kept, made here otherwise.
    fn accept<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<(), SimErrorKind> {
        self.accepted.copy_from_slice(&p.q);
        self.t_accepted = t;
        self.speed_accepted = inf_norm(&p.qd);
        if p.rows.is_empty() {
            return Ok(());
        }
        let eval = SimErrorKind::from_eval;
        let mut ratio = match self.chart.anchor_staged(p, t) {
            Some(ratio) => ratio,
            None => {
                p.factorizations += 1;
                self.chart.anchor(p, t).map_err(eval)?
            }
        };
        if self.worse(ratio) && p.refit(t) {
            p.factorizations += 1;
            ratio = self.chart.anchor(p, t).map_err(eval)?;
            self.fit_ratio = ratio;
        }
        if self.fit_ratio == 0.0 {
            self.fit_ratio = ratio;
        }
        if ratio.is_nan() || ratio <= SINGULAR_RATIO {
            return Err(SimErrorKind::Singular {
                t,
                matrix: SingularMatrix::Projection,
                ratio,
                constraints: Vec::new(),
            });
        }
        Ok(())
    }

    /// The point of the chart: Newton on the normal coordinates from `y`; its
    /// velocities are projected with the dynamics terms in
    /// [`accelerations`](Form::accelerations) (by the factored projection here when
    /// the chart's iteration does not serve the point, see [`Chart::serves`]).
    fn reconstruct<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
        y: &[f64],
    ) -> Result<(), SimErrorKind> {
        if self.cached == Some(t) && self.y_cached == y {
            return Ok(());
        }
        self.cached = None;
        copy_state(p, y);
        if p.rows_h > 0 {
            match self.chart.correct(p, t) {
                Ok(iterations) => p.newton_iterations += iterations as u64,
                Err(ChartFailure::Eval(e)) => return Err(SimErrorKind::from_eval(e)),
                Err(ChartFailure::Newton {
                    iterations,
                    residual,
                }) => {
                    p.newton_iterations += iterations as u64;
                    let tol = p.newton.tolerance;
                    return Err(SimErrorKind::NewtonFailed {
                        t,
                        iterations,
                        residual,
                        constraints: p.violated(t, tol),
                    });
                }
            }
            let (mut moved, mut correction) = (0.0_f64, 0.0_f64);
            for ((&yj, &qj), &aj) in y.iter().zip(&p.q).zip(&self.accepted) {
                moved = moved.max((yj - aj).abs());
                correction = correction.max((qj - yj).abs());
            }
            let scale = inf_norm(&p.q);
            let floor = BRANCH_FLOOR * scale + self.chart.tolerance(scale);
            let drift = 2.0 * (t - self.t_accepted).abs() * self.speed_accepted;
            if correction > moved + drift + floor {
                return Err(SimErrorKind::NewtonFailed {
                    t,
                    iterations: 0,
                    residual: correction,
                    constraints: Vec::new(),
                });
            }
        }
        // The velocities: with the dynamics terms when the chart's iteration serves the
        // point (see `accelerations`), here otherwise.
        self.pending = self.chart.serves(p);
        if !self.pending {
            p.project_velocities(t)?;
        }
        self.cached = Some(t);
        self.y_cached.copy_from_slice(y);
        Ok(())
    }

    /// With the velocities of the chart's point, when [`reconstruct`](Form::reconstruct)
    /// left them: projected by the chart's iteration inside one call of the fused
    /// evaluation ([`Point::dynamics_terms_corrected`]), so that $C_q$ and $G$ at the
    /// point come with $M$, $Q$ and $\gamma$.
    fn accelerations<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<(), SimErrorKind> {
        if self.pending {
            self.pending = false;
            let (mech, info, distance) = (p.mech, p.info, self.chart.distance(&p.q));
            let chart = &mut self.chart;
            let mut outcome = None;
            let versions = p
                .dynamics_terms_corrected(t, &mut |cq, g, ct, bias, qd| {
                    let terms = VelocityTerms { cq, g, ct, bias };
                    outcome = chart.project_velocities(mech, info, terms, distance, qd, KAPPA);
                })
                .map_err(SimErrorKind::from_eval)?;
            if outcome.is_some() {
                // The state is the one the terms were evaluated at.
                return p.accelerations_with(t, versions, None);
            }
            // Not contracting (a non-finite C_q or G among the causes, named by the
            // check): the factored projection, and the terms again.
            p.check_terms(t)?;
            p.project_velocities(t)?;
        }
        p.accelerations(t, None)
    }

    /// The chart's point, for [`keep`](Form::keep) to polish.
    /// A kept state the chart's chord iteration cannot correct (an output point far
    /// inside a long step of Radau5's dense output, where the anchor's normals no
    /// longer contract) is left to [`keep`](Form::keep)'s full Newton projection from
    /// `y` itself: an evaluation would be retried with a shorter step, a kept point
    /// cannot.
    fn reconstruct_kept<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
        y: &[f64],
    ) -> Result<(), SimErrorKind> {
        match self.reconstruct(p, t, y) {
            Err(SimErrorKind::NewtonFailed { .. }) => {
                self.cached = None;
                self.off_chart = true;
                copy_state(p, y);
                Ok(())
            }
            r => {
                self.off_chart = false;
                r
            }
        }
    }

    /// Polishes the chart's point to the Newton tolerance, below the integrator's
    /// tolerance, so the derivatives the integrator keeps stay valid.
    ///
    /// The maps of the next anchor are made first, at the point as reconstructed (its
    /// $J$ came with the last evaluation), and staged ([`Chart::stage`]): the positions
    /// are polished by the chord iteration with them (its first update is Newton's,
    /// and one is the norm), the velocities by the chart's chord iteration with them
    /// to round-off (the same orthogonal projection at the polished positions), and
    /// [`accept`](Form::accept) takes them as the anchor. An accepted step thus factors
    /// one Gram matrix and evaluates one $J$ (at the polished positions). Kept states
    /// off the chart, ill-conditioned maps and models whose redundant constraints were
    /// dropped take minimum-norm Newton and the anchor's iteration instead.
    fn keep<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<(), SimErrorKind> {
        self.cached = None;
        self.pending = false;
        let eval = SimErrorKind::from_eval;
        if p.rows.is_empty() {
            return Ok(());
        }
        let staged = if self.off_chart || p.rows_h != p.info.nh() {
            false
        } else {
            p.factorizations += 1;
            let (ratio, serves) = self.chart.stage(p, t).map_err(eval)?;
            serves && !self.worse(ratio)
        };
        if !staged {
            p.project_positions(t)?;
            return match self.chart.correct_velocities(p, t, 0.0) {
                Ok(Some(_)) => Ok(()),
                Ok(None) => p.project_velocities(t),
                Err(e) => Err(eval(e)),
            };
        }
        if p.rows_h > 0 {
            let tol = p.newton.tolerance;
            if self.chart.polish(p, t, tol).map_err(eval)?.is_none() {
                p.project_positions(t)?;
            }
        }
        match self.chart.correct_velocities_staged(p, t).map_err(eval)? {
            Some(_) => {}
            None => p.project_velocities(t)?,
        }
        self.chart.stage_for(t, &p.q);
        Ok(())
    }

    fn recoverable(&self, e: &SimErrorKind) -> bool {
        matches!(
            e,
            SimErrorKind::NewtonFailed { .. } | SimErrorKind::Singular { .. }
        ) || inconsistent_redundant(e)
    }
}

/// Index 1 with projection of positions and velocities after each step
/// ([`Formulation::Projection`]).
#[derive(Debug)]
pub(crate) struct Projected;

impl Form for Projected {
    const CORRECTION: Correction = Correction::Changed;

    fn accelerations<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<(), SimErrorKind> {
        p.accelerations(t, None)
    }

    fn keep<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<(), SimErrorKind> {
        p.project(t)
    }

    fn recoverable(&self, e: &SimErrorKind) -> bool {
        inconsistent_redundant(e)
    }
}

/// Index 1 with Baumgarte stabilization ([`Formulation::Baumgarte`]).
#[derive(Debug)]
pub(crate) struct Stabilized {
    alpha: f64,
    beta: f64,
    shift: Vec<f64>,
}

impl Stabilized {
    pub fn new(alpha: f64, beta: f64, m: usize) -> Self {
        Self {
            alpha,
            beta,
            shift: vec![0.0; m],
        }
    }
}

impl Form for Stabilized {
    const CORRECTION: Correction = Correction::None;

    /// With $\gamma$ shifted by $-2\alpha[C_q\dot q + C_t; G\dot q + g] - \beta^2[C; 0]$.
    fn accelerations<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<(), SimErrorKind> {
        p.stabilized_accelerations(t, self.alpha, self.beta, &mut self.shift)
    }
}

/// $M\ddot q = Q$ without multipliers ([`Formulation::Unconstrained`]).
#[derive(Debug)]
pub(crate) struct Free;

impl Form for Free {
    const CORRECTION: Correction = Correction::None;

    fn accelerations<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<(), SimErrorKind> {
        p.free_accelerations(t)
    }
}

/// The formulation chosen at run time.
// One lives per run, so the size of the largest variant (the chart's scratch) costs
// nothing worth a box.
#[allow(clippy::large_enum_variant)]
#[derive(Debug)]
pub(crate) enum AnyForm {
    Partitioned(Partitioned),
    Projected(Projected),
    Stabilized(Stabilized),
    Free(Free),
}

impl AnyForm {
    /// The implementation of `formulation` for a model with `n` coordinates, `m`
    /// constraint rows of which `mh` holonomic, and the integrator's tolerances.
    pub fn new(formulation: Formulation, n: usize, m: usize, mh: usize, tol: (f64, f64)) -> Self {
        match formulation {
            Formulation::Partitioning => Self::Partitioned(Partitioned::new(n, m, mh, tol)),
            Formulation::Projection => Self::Projected(Projected),
            Formulation::Baumgarte { alpha, beta } => {
                Self::Stabilized(Stabilized::new(alpha, beta, m))
            }
            Formulation::Unconstrained => Self::Free(Free),
        }
    }

    /// What [`keep`](Form::keep) does to an accepted state.
    pub fn correction(&self) -> Correction {
        match self {
            Self::Partitioned(_) => Partitioned::CORRECTION,
            Self::Projected(_) => Projected::CORRECTION,
            Self::Stabilized(_) => Stabilized::CORRECTION,
            Self::Free(_) => Free::CORRECTION,
        }
    }
}

macro_rules! each {
    ($self:expr, $f:ident => $body:expr) => {
        match $self {
            AnyForm::Partitioned($f) => $body,
            AnyForm::Projected($f) => $body,
            AnyForm::Stabilized($f) => $body,
            AnyForm::Free($f) => $body,
        }
    };
}

impl AnyForm {
    pub fn accept<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<(), SimErrorKind> {
        each!(self, f => f.accept(p, t))
    }

    pub fn reconstruct<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
        y: &[f64],
    ) -> Result<(), SimErrorKind> {
        each!(self, f => f.reconstruct(p, t, y))
    }

    pub fn reconstruct_kept<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
        y: &[f64],
    ) -> Result<(), SimErrorKind> {
        each!(self, f => f.reconstruct_kept(p, t, y))
    }

    pub fn accelerations<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<(), SimErrorKind> {
        each!(self, f => f.accelerations(p, t))
    }

    pub fn keep<M: Mechanism + ?Sized>(
        &mut self,
        p: &mut Point<'_, M>,
        t: f64,
    ) -> Result<(), SimErrorKind> {
        each!(self, f => f.keep(p, t))
    }

    pub fn recoverable(&self, e: &SimErrorKind) -> bool {
        each!(self, f => f.recoverable(e))
    }
}
