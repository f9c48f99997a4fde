//! The full state at one point $(t, q, \dot q)$ and what is evaluated there, shared by
//! the formulations ([`super::formulation`]).
//!
//! Input: a model and its analysis scratch. Output: $C$, $J$, $[C_t; g]$, the velocity
//! residuals, the projections onto the constraints, $\ddot q$ and $\lambda$ at the
//! current state.
//!
//! Invariant: a quantity is evaluated at most once per point. Each group of generated
//! functions is stamped with the version of the $(t, q)$ (and $\dot q$ for the dynamics
//! terms) it was evaluated at and reused while the state keeps that version, so the
//! velocity projection, the augmented solve, the monitors and the record of one state
//! share one $C_q$. A check compares the state with the last one seen ($t$ bitwise,
//! $q$ and $\dot q$ by value, copying them in the same pass) and numbers it anew when it
//! changed ([`Versions`]): $2n$ comparisons per check, one copy per new state, however
//! many groups are evaluated at it.
//! Nothing allocates after [`Point::new`] (except when building an error).

use std::cmp::Ordering;

use super::error::{SimErrorKind, SingularMatrix};
use crate::dynamics::{Dynamics, DynamicsParams, SolverPath, Velocities};
use crate::kinematics::{Kinematics, KinematicsParams};
use crate::linalg::inf_norm;
use crate::linalg::small::{gram_cholesky_planned, GramPlan, SmallCholesky};
use crate::scale;
use crate::workspace::{all_finite, EvalError, VelocityCorrection, Workspace};
use crate::{Error, Info, Mechanism, NewtonParams, RANK_PIVOT};

/// Pivot ratio below which a projection matrix $J J^\mathsf{T}$ counts as singular.
pub(crate) const SINGULAR_RATIO: f64 = 1e-14;

/// Pivot ratio of a projection matrix (equilibrated $J_R J_R^\mathsf{T}$) below which
/// the kept rows of a model with redundant constraints are renewed (see
/// [`Point::refit`]): a ratio of $10^{-8}$ is a condition of $10^4$ for $J_R$, where
/// Newton starts to stall long before the matrix is singular.
pub(crate) const REFIT_RATIO: f64 = 1e-8;

/// The last full state $(t, q, \dot q)$ a check of the groups saw, with a version of
/// its position $(t, q)$ and of the whole state: a group of evaluations is stamped
/// with the version it was made at, so that the stamps are numbers, and the state is
/// copied once when it changes instead of once per group evaluated at it. A check of a
/// position group compares $(t, q)$ only; the velocities are compared (or copied, after
/// a new position) when a group of the whole state is checked.
#[derive(Debug)]
struct Versions {
    t: f64,
    q: Vec<f64>,
    qd: Vec<f64>,
    /// Whether `qd` holds the velocities of the state of version `state` (cleared by a
    /// new position, whose velocities are copied at the next check of the state).
    qd_held: bool,
    position: u64,
    state: u64,
}

impl Versions {
    fn new(n: usize) -> Self {
        Self {
            // No time equals it bitwise but this NaN: the first check starts version 2.
            t: f64::NAN,
            q: vec![0.0; n],
            qd: vec![0.0; n],
            qd_held: false,
            position: 1,
            state: 1,
        }
    }

    /// The version of the position `(t, q)`: that of the last position seen when it is
    /// the same (`t` bitwise, `q` by value), a new one otherwise (which also starts a
    /// new version of the state).
    #[inline]
    fn position(&mut self, t: f64, q: &[f64]) -> u64 {
        if self.t.to_bits() != t.to_bits() || !same(&self.q, q) {
            self.t = t;
            self.q.copy_from_slice(q);
            self.qd_held = false;
            self.position += 1;
            self.state += 1;
        }
        self.position
    }

    /// The versions `(position, state)` of `(t, q, qd)` (see
    /// [`position`](Self::position)); the state's is new when the position is or the
    /// velocities differ from the last ones seen at it.
    #[inline]
    fn sync(&mut self, t: f64, q: &[f64], qd: &[f64]) -> (u64, u64) {
        let position = self.position(t, q);
        if !self.qd_held {
            // A new position has its new state version already.
            self.qd.copy_from_slice(qd);
            self.qd_held = true;
        } else if !same(&self.qd, qd) {
            self.qd.copy_from_slice(qd);
            self.state += 1;
        }
        (position, self.state)
    }
}

/// Whether `a` and `b` are equal entry by entry (by value, as `==`), in one pass without
/// branches (vectorized).
#[inline]
fn same(a: &[f64], b: &[f64]) -> bool {
    a.iter().zip(b).fold(true, |s, (x, y)| s & (x == y))
}

/// `out[r] += v * x[c]` for the entries `(r, c)` of `pattern` with the values `values`,
/// in the pattern's order, each run of consecutive entries of one row summed in a
/// register: the operations of the scatter in its order, bit for bit, without each
/// `+=` waiting for the store of the one before (the patterns are by rows).
#[inline]
fn add_products(out: &mut [f64], pattern: &[(u32, u32)], values: &[f64], x: &[f64]) {
    let mut entries = pattern.iter().zip(values);
    let Some((&(r, c), v)) = entries.next() else {
        return;
    };
    let mut row = r as usize;
    let mut sum = out[row] + v * x[c as usize];
    for (&(r, c), v) in entries {
        let r = r as usize;
        if r != row {
            out[row] = sum;
            row = r;
            sum = out[row];
        }
        sum += v * x[c as usize];
    }
    out[row] = sum;
}

/// The version of the state a group of evaluations holds values at (0: none).
type Stamp = u64;

/// How often a [`Point`] evaluated the holonomic constraints and their Jacobian, and
/// how: the fused evaluation computes both for little more than either.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct PositionEvaluations {
    /// $C$ alone (`Mechanism::holonomic`).
    pub constraints: u64,
    /// $C_q$ and $G$ without $C$ (`Mechanism::holonomic_jacobian`,
    /// `nonholonomic_matrix`; the dynamics terms are not counted).
    pub jacobian: u64,
    /// $C$ and $C_q$ in one call (`Mechanism::holonomic_with_jacobian`), $G$ beside.
    pub fused: u64,
}

/// The current full state and the evaluations made at it.
pub(crate) struct Point<'a, M: Mechanism + ?Sized> {
    pub mech: &'a M,
    pub info: &'static Info,
    pub ws: Workspace,
    pub dynamics: Dynamics,
    /// Assembly, Algorithm P and the choice of the independent constraint rows.
    pub kin: Kinematics,
    /// Newton tolerance of the position projection.
    pub newton: NewtonParams,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    /// $[\ddot q; \lambda]$, where the augmented solve writes them (see
    /// [`qdd`](Self::qdd), [`lambda`](Self::lambda)).
    pub solution: Vec<f64>,
    /// $[C_q\dot q + C_t;\ G\dot q + g]$ (see
    /// [`velocity_residuals`](Self::velocity_residuals)).
    pub vel: Vec<f64>,
    mu: Vec<f64>,
    lu_h: SmallCholesky,
    /// Whether `lu_h` holds the factor of the last position update of a projection
    /// whose projected rows are all holonomic (see [`Point::project`]).
    position_factor: bool,
    /// Whether the state being corrected is an output row (an interpolated state the
    /// integration does not continue from) or one of DOP853's dense stages
    /// ([`OdeSystem::aside`](crate::ode::OdeSystem)): its correction reads nothing the
    /// previous evaluations left and teaches the integration nothing, so that a row is
    /// a function of the interpolant alone and the steps do not depend on the rows.
    pub(crate) row: bool,
    /// $M$ of the evaluation at the state a step ends in, and its time
    /// ([`hold_metric`](Self::hold_metric)): the metric of that step's projection.
    metric: Vec<f64>,
    metric_t: Option<f64>,
    lu_v: SmallCholesky,
    /// The products of the Gram matrices of `lu_h` (the holonomic rows of `rows`) and
    /// `lu_v` (all of `rows`) the sparsity of $J$ leaves (see [`GramPlan`]).
    gram_h: GramPlan,
    gram_v: GramPlan,
    /// Scratch of a velocity update, and the previous iterate of the positions in
    /// [`project_in_mass_metric`](Self::project_in_mass_metric).
    dx: Vec<f64>,
    /// $M$ for [`free_accelerations`](Self::free_accelerations) (sized on first use).
    mass: SmallCholesky,
    /// The constraint rows projected on, the first `rows_h` holonomic (all rows unless
    /// assembly dropped redundant ones, see [`Point::fit_rows`]).
    pub rows: Vec<usize>,
    pub rows_h: usize,
    /// $C$; the pattern values of $C_q$, $G$ (written by their own functions or by the
    /// dynamics terms); the dense $J$; $C_t$, $g$; the dynamics terms ($M$, $Q$,
    /// $\gamma$); $\ddot q$, $\lambda$ (solved with the formulation's shift, a function
    /// of the state). Position groups hold a version of $(t, q)$, the others one of
    /// $(t, q, \dot q)$ ([`Versions`]).
    versions: Versions,
    constraints: Stamp,
    jacobian: Stamp,
    dense: Stamp,
    rates: Stamp,
    terms: Stamp,
    solved: Stamp,
    /// Whether the next evaluation of $C$ at a new point also evaluates $C_q$ and $G$
    /// (see [`constraints`](Self::constraints)): $J$ was asked for after $C$ at the
    /// last point $C$ was evaluated at.
    paired: bool,
    /// Whether every evaluation of the dynamics terms asks for $C$ at the point too
    /// (when not held): set for an integrator whose last evaluation of a step is at
    /// the state the step keeps (Adams' final evaluation), where the position group
    /// of the projections reads $C$ next, for a few operations on the sines the terms
    /// already have instead of a call of its own (see
    /// `docs/decisions/0018-c-and-cq-in-one-call.md`).
    pub constraints_with_terms: bool,
    /// $C$ with the next evaluation of the dynamics terms only (then cleared): set
    /// before the evaluation at the state a step ends in, where the projections and the
    /// monitors read $C$ next ([`OdeSystem::step_end_next`](crate::ode::OdeSystem)).
    pub constraints_next: bool,
    /// Whether the dynamics terms held (stamp `terms`) passed their finiteness check:
    /// [`dynamics_terms_at`](Self::dynamics_terms_at) and
    /// [`dynamics_terms_corrected`](Self::dynamics_terms_corrected) evaluate them
    /// unchecked, and [`accelerations`](Self::accelerations) lets the generated solve
    /// vouch for them.
    terms_checked: bool,
    /// $[\Delta q; \mu]$ of [`project_in_mass_metric`](Self::project_in_mass_metric).
    solution_scratch: Vec<f64>,
    /// Evaluations of the holonomic functions: $C$ alone, $C_q$ (with $G$) alone, both
    /// in one fused call (read by the tests).
    #[cfg_attr(not(test), allow(dead_code))]
    pub evaluations: PositionEvaluations,
    pub newton_iterations: u64,
    pub factorizations: u64,
    /// Constraints the augmented solve found redundant so far.
    pub redundant: Vec<&'static str>,
    /// The most holonomic rows the projections kept (the rank of $C_q$ at assembly);
    /// more than `rows_h` while the motion is near a rank drop (see
    /// [`project_positions`](Self::project_positions), which takes the rows back).
    rank: usize,
}

impl<'a, M: Mechanism + ?Sized> Point<'a, M> {
    pub fn new(
        mech: &'a M,
        dynamics: DynamicsParams,
        kin: KinematicsParams,
    ) -> Result<Self, Error> {
        let info = mech.info();
        let (n, mh, m) = (info.nq(), info.nh(), info.nh() + info.nnh());
        let mut point = Self {
            mech,
            info,
            ws: Workspace::new(info)?,
            dynamics: Dynamics::new(info, dynamics)?,
            kin: Kinematics::new(info, kin),
            newton: kin.newton,
            q: vec![0.0; n],
            qd: vec![0.0; n],
            solution: vec![0.0; n + m],
            vel: vec![0.0; m],
            mu: vec![0.0; m],
            lu_h: SmallCholesky::new(mh),
            position_factor: false,
            row: false,
            metric: vec![0.0; info.mass_pattern.len()],
            metric_t: None,
            lu_v: SmallCholesky::new(m),
            gram_h: GramPlan::default(),
            gram_v: GramPlan::default(),
            dx: vec![0.0; n],
            mass: SmallCholesky::new(0),
            rows: (0..m).collect(),
            rows_h: mh,
            versions: Versions::new(n),
            constraints: 0,
            jacobian: 0,
            dense: 0,
            rates: 0,
            terms: 0,
            solved: 0,
            paired: false,
            evaluations: PositionEvaluations::default(),
            newton_iterations: 0,
            factorizations: 0,
            redundant: Vec::new(),
            constraints_with_terms: false,
            constraints_next: false,
            terms_checked: true,
            solution_scratch: vec![0.0; n + m],
            rank: 0,
        };
        point.plan_grams();
        Ok(point)
    }

    /// Sets the state to $y = [q; \dot q]$ (a state from the integrator). Whether $C$
    /// comes with $J$ ([`constraints`](Self::constraints)) is learnt again from how the
    /// new state is used: what was asked for at the last state says nothing about
    /// the correction of a new one.
    pub fn set_state(&mut self, y: &[f64]) {
        let n = self.q.len();
        self.q.copy_from_slice(&y[..n]);
        self.qd.copy_from_slice(&y[n..]);
        self.paired = false;
    }

    /// Forgets every evaluation (after the workspace was used directly, as assembly
    /// does).
    pub fn invalidate(&mut self) {
        for s in [
            &mut self.constraints,
            &mut self.jacobian,
            &mut self.dense,
            &mut self.rates,
            &mut self.terms,
            &mut self.solved,
        ] {
            *s = 0;
        }
    }

    /// Forgets $\ddot q$ and $\lambda$ (after a resting contact corrected them in
    /// place, so that the next solve starts from the model's own equations).
    pub fn invalidate_solved(&mut self) {
        self.solved = 0;
    }

    /// $\ddot q$ of the last solve.
    pub fn qdd(&self) -> &[f64] {
        &self.solution[..self.info.nq()]
    }

    /// $\lambda$ of the last solve.
    pub fn lambda(&self) -> &[f64] {
        &self.solution[self.info.nq()..]
    }

    /// The versions `(position, state)` of the current $(t, q, \dot q)$
    /// ([`Versions::sync`]).
    #[inline]
    fn versions(&mut self, t: f64) -> (u64, u64) {
        self.versions.sync(t, &self.q, &self.qd)
    }

    /// The version of the current $(t, q)$.
    #[inline]
    fn position(&mut self, t: f64) -> u64 {
        self.versions.position(t, &self.q)
    }

    /// Keeps only the independent holonomic rows `holonomic` (and every non-holonomic
    /// one) in the projections, after assembly dropped redundant constraints
    /// (allocates).
    pub fn fit_rows(&mut self, holonomic: &[usize]) {
        let (mh, nnh) = (self.info.nh(), self.info.nnh());
        let same = self.rows_h == holonomic.len()
            && self.rows[..self.rows_h] == *holonomic
            && self.rows[self.rows_h..].iter().copied().eq(mh..mh + nnh);
        if same {
            // The rows of `Point::new` or of the last fit: the plans hold.
            self.rank = self.rank.max(self.rows_h);
            return;
        }
        self.rows.clear();
        self.rows.extend_from_slice(holonomic);
        self.rows.extend(mh..mh + nnh);
        self.rows_h = holonomic.len();
        self.rank = self.rank.max(self.rows_h);
        // Within the capacity of `Point::new` (every row): no allocation.
        self.lu_h.resize(self.rows_h);
        self.lu_v.resize(self.rows.len());
        self.plan_grams();
    }

    /// The plans of the projections' Gram matrices for the current `rows`, from the
    /// patterns of $C_q$ and $G$ (allocates).
    /// The plans of the Gram matrices of the rows `rows[..rows_h]` and of all `rows`
    /// (made with them, see [`fit_rows`](Self::fit_rows)).
    pub fn gram_plans(&self) -> (&GramPlan, &GramPlan) {
        (&self.gram_h, &self.gram_v)
    }

    fn plan_grams(&mut self) {
        let info = self.info;
        let (n, mh) = (info.nq(), info.nh());
        let mut nonzero = vec![false; (mh + info.nnh()) * n];
        for &(r, c) in info.holonomic_pattern {
            nonzero[r as usize * n + c as usize] = true;
        }
        for &(r, c) in info.nonholonomic_pattern {
            nonzero[(mh + r as usize) * n + c as usize] = true;
        }
        let nonzero = |i: usize, j: usize| nonzero[i * n + j];
        self.gram_h = GramPlan::new(&self.rows[..self.rows_h], n, nonzero);
        self.gram_v = GramPlan::new(&self.rows, n, nonzero);
    }

    /// Fits the projections to the current partition, which may have dropped redundant
    /// holonomic constraints; returns the names of the dropped ones.
    pub fn fit_partition(&mut self) -> Vec<&'static str> {
        let Some(p) = self.kin.partition() else {
            return Vec::new();
        };
        let info = self.info;
        let names = p
            .redundant_rows()
            .iter()
            .map(|&i| info.holonomic[i].name)
            .collect();
        let rows = p.holonomic_rows().to_vec();
        self.fit_rows(&rows);
        names
    }

    /// Renews the redundant holonomic rows left out of the projections and the chart,
    /// when there are any: which rows of a dependent set are independent changes along
    /// the motion (the three pin_y rows of the parallelogram become dependent at the
    /// bottom of its swing, and a set that dropped a pin_x row turns singular there).
    ///
    /// The rows are chosen by Algorithm P with the shared rank rule
    /// ([`crate::RANK_PIVOT`]), so the rank may change: near a configuration where
    /// $C_q$ loses rank (the parallelogram's flat position, where the three pin_x rows
    /// coincide) more rows are dropped; while fewer rows are kept than at assembly,
    /// [`project_positions`](Self::project_positions) chooses them anew at each kept
    /// state (one Algorithm P per kept state, on the few steps near the rank drop), so
    /// they are taken back when the motion leaves it. Returns whether the rows were
    /// renewed.
    pub fn refit(&mut self, t: f64) -> bool {
        let redundant = self
            .kin
            .partition()
            .is_some_and(|p| !p.redundant_rows().is_empty());
        if !redundant {
            return false;
        }
        self.position_factor = false;
        let params = self.kin.params.partition;
        self.kin.params.partition.pivot_tolerance = params.pivot_tolerance.max(RANK_PIVOT);
        let ok = self
            .kin
            .repartition(self.mech, &mut self.ws, t, &self.q)
            .is_ok_and(|p| !p.holonomic_rows().is_empty());
        self.kin.params.partition = params;
        // Algorithm P evaluated J into the workspace itself.
        self.invalidate();
        if ok {
            self.fit_partition();
        }
        ok
    }

    /// $C$ at the current $(t, q)$.
    ///
    /// Evaluated with $C_q$ and $G$ by the model's fused
    /// [`holonomic_with_jacobian`](Mechanism::holonomic_with_jacobian) when $J$ is not
    /// held at the point and was asked for after $C$ at the last point $C$ was
    /// evaluated at: an iteration that reads both at each iterate (the chart's polish)
    /// gets both from one call from its second iterate on, one that reads only $C$
    /// from a state just set (the chart's correction, after
    /// [`set_state`](Self::set_state)) evaluates $C$ alone. Callers that know they need
    /// both call
    /// [`constraints_with_jacobian`](Self::constraints_with_jacobian).
    pub fn constraints(&mut self, t: f64) -> Result<&[f64], EvalError> {
        let at = self.position(t);
        if self.constraints != at {
            if self.paired && self.jacobian != at {
                self.eval_fused(t, at)?;
            } else {
                self.ws.eval_constraints(self.mech, t, &self.q)?;
                self.evaluations.constraints += 1;
                self.constraints = at;
            }
            self.paired = false;
        }
        Ok(self.ws.constraints())
    }

    /// $C$ and the pattern values of $C_q$ and $G$ at the current $(t, q)$, by one
    /// fused evaluation when neither is held.
    pub fn constraints_with_jacobian_values(&mut self, t: f64) -> Result<(), EvalError> {
        let at = self.position(t);
        self.constraints_with_jacobian_values_at(t, at)
    }

    /// [`constraints_with_jacobian_values`](Self::constraints_with_jacobian_values) at
    /// the current $(t, q)$ of version `at`.
    fn constraints_with_jacobian_values_at(&mut self, t: f64, at: Stamp) -> Result<(), EvalError> {
        match (self.constraints == at, self.jacobian == at) {
            (true, true) => {}
            (false, false) => self.eval_fused(t, at)?,
            (false, true) => {
                self.ws.eval_constraints(self.mech, t, &self.q)?;
                self.evaluations.constraints += 1;
                self.constraints = at;
            }
            (true, false) => self.jacobian_values_at(t, at)?,
        }
        self.paired = true;
        Ok(())
    }

    /// $C$ and the dense $J$ at the current $(t, q)$ (see
    /// [`constraints_with_jacobian_values`](Self::constraints_with_jacobian_values)),
    /// read with [`Workspace::constraints`] and [`Workspace::jacobian`].
    pub fn constraints_with_jacobian(&mut self, t: f64) -> Result<(), EvalError> {
        let at = self.position(t);
        self.constraints_with_jacobian_values_at(t, at)?;
        self.dense_jacobian_at(t, at)
    }

    /// $C$, $C_q$ (one fused call) and $G$ at the current $(t, q)$, of version `at`,
    /// stamped.
    fn eval_fused(&mut self, t: f64, at: Stamp) -> Result<(), EvalError> {
        self.ws
            .eval_constraints_with_jacobian(self.mech, t, &self.q)?;
        self.evaluations.fused += 1;
        self.constraints = at;
        self.jacobian = at;
        Ok(())
    }

    /// Notes that $J$ is asked for: after $C$ at the same point, the next $C$ at a new
    /// point comes with $J$ (see [`constraints`](Self::constraints)).
    fn note_jacobian(&mut self, at: Stamp) {
        if !self.paired && self.constraints == at {
            self.paired = true;
        }
    }

    /// The pattern values of $C_q$ and $G$ at the current $(t, q)$, into the workspace
    /// (`ws.cq_values`, `ws.g_values`), without the dense $J$.
    pub fn jacobian_values(&mut self, t: f64) -> Result<(), EvalError> {
        let at = self.position(t);
        self.jacobian_values_at(t, at)
    }

    /// The pattern values of $C_q$ and $G$ at the current $(t, q)$, of version `at`.
    fn jacobian_values_at(&mut self, t: f64, at: Stamp) -> Result<(), EvalError> {
        self.note_jacobian(at);
        if self.jacobian != at {
            self.ws.eval_jacobian_values(self.mech, t, &self.q)?;
            self.evaluations.jacobian += 1;
            self.jacobian = at;
        }
        Ok(())
    }

    /// The dense $J$ at the current $(t, q)$.
    pub fn dense_jacobian(&mut self, t: f64) -> Result<&[f64], EvalError> {
        let at = self.position(t);
        self.dense_jacobian_at(t, at)?;
        Ok(self.ws.jacobian())
    }

    /// [`dense_jacobian`](Self::dense_jacobian) at the current $(t, q)$ of version `at`.
    fn dense_jacobian_at(&mut self, t: f64, at: Stamp) -> Result<(), EvalError> {
        self.note_jacobian(at);
        if self.dense != at {
            self.jacobian_values_at(t, at)?;
            self.ws.scatter_jacobian();
            self.dense = at;
        }
        Ok(())
    }

    /// The pattern values of $C_q$ and $G$ and the rates $[C_t; g]$ at the current
    /// $(t, q)$, in the workspace (each evaluated once per position): what a projection
    /// of the velocities reads besides $\dot q$, for one that forms its residuals itself
    /// (the chart's).
    pub fn velocity_terms(&mut self, t: f64) -> Result<(), EvalError> {
        let at = self.position(t);
        self.velocity_terms_at(t, at)
    }

    /// [`velocity_terms`](Self::velocity_terms) at the current $(t, q)$ of version `at`.
    fn velocity_terms_at(&mut self, t: f64, at: Stamp) -> Result<(), EvalError> {
        self.jacobian_values_at(t, at)?;
        self.rates_at(t, at)
    }

    /// The rates $C_t$, $g$ at the current $(t, q)$ of version `at`, evaluated once per
    /// position.
    fn rates_at(&mut self, t: f64, at: Stamp) -> Result<(), EvalError> {
        if self.rates != at {
            self.ws.eval_rates(self.mech, t, &self.q)?;
            self.rates = at;
        }
        Ok(())
    }

    /// $[C_q\dot q + C_t;\ G\dot q + g]$ at the current state, into `vel` (the
    /// functions evaluated once per $(t, q)$, the products with $\dot q$ every call: by
    /// the model's generated [`Mechanism::velocity_residuals`], else by walking the
    /// patterns).
    pub fn velocity_residuals(&mut self, t: f64) -> Result<(), EvalError> {
        let at = self.position(t);
        self.velocity_residuals_at(t, at)
    }

    /// [`velocity_residuals`](Self::velocity_residuals) at the current state, whose
    /// $(t, q)$ is of version `at`.
    fn velocity_residuals_at(&mut self, t: f64, at: Stamp) -> Result<(), EvalError> {
        let info = self.info;
        let mh = info.nh();
        self.velocity_terms_at(t, at)?;
        let ws = &self.ws;
        if self.mech.velocity_residuals(
            &ws.cq_values,
            &ws.g_values,
            &ws.ct,
            &ws.bias,
            &self.qd,
            &mut self.vel,
        ) {
            return Ok(());
        }
        let (holonomic, nonholonomic) = self.vel.split_at_mut(mh);
        holonomic.copy_from_slice(&self.ws.ct);
        nonholonomic.copy_from_slice(&self.ws.bias);
        add_products(
            holonomic,
            info.holonomic_pattern,
            &self.ws.cq_values,
            &self.qd,
        );
        add_products(
            nonholonomic,
            info.nonholonomic_pattern,
            &self.ws.g_values,
            &self.qd,
        );
        Ok(())
    }

    /// $(\lVert C\rVert_\infty, \lVert C_q\dot q + C_t\rVert_\infty,
    /// \lVert G\dot q + g\rVert_\infty)$ at the current state.
    pub fn violations(&mut self, t: f64) -> Result<(f64, f64, f64), EvalError> {
        self.constraints_with_jacobian_values(t)?;
        let c = inf_norm(self.ws.constraints());
        self.velocity_residuals(t)?;
        let mh = self.info.nh();
        Ok((c, inf_norm(&self.vel[..mh]), inf_norm(&self.vel[mh..])))
    }

    /// Whether assembly found the holonomic constraints dependent (a redundant set,
    /// whose rank can also drop along the motion).
    pub(crate) fn has_redundant_rows(&self) -> bool {
        self.rank > 0 && self.rank < self.info.nh()
    }

    /// $\ddot q$ and $\lambda$ at the current state from (E31), with $\gamma$ replaced
    /// by $\gamma + s$ when `shift` gives $s$ (Baumgarte); the terms come from one call
    /// of the model's fused evaluation.
    pub fn accelerations(&mut self, t: f64, shift: Option<&[f64]>) -> Result<(), SimErrorKind> {
        // A shift depends on the state only, so (t, q, q̇) identifies the solution.
        let versions = self.versions(t);
        self.accelerations_with(t, versions, shift)
    }

    /// [`accelerations`](Self::accelerations) at the current state, whose versions
    /// `(position, state)` the caller has just taken (no change of the state since).
    pub(crate) fn accelerations_with(
        &mut self,
        t: f64,
        versions: (Stamp, Stamp),
        shift: Option<&[f64]>,
    ) -> Result<(), SimErrorKind> {
        if self.solved == versions.1 {
            return Ok(());
        }
        self.accelerations_at(t, versions, shift)
    }

    /// [`accelerations`](Self::accelerations) at the current state, of versions
    /// `(position, state)`, not solved at yet.
    fn accelerations_at(
        &mut self,
        t: f64,
        (position, state): (Stamp, Stamp),
        shift: Option<&[f64]>,
    ) -> Result<(), SimErrorKind> {
        let with_c = self.constraints_asked();
        self.dynamics_terms_at(t, (position, state), with_c)?;
        self.factorizations += 1;
        // A model with redundant constraints gives the solve the velocity residuals,
        // for its check of the rows that are dependent only near a rank drop.
        let redundant = self.has_redundant_rows();
        // Terms just evaluated go to the solve unchecked: the generated solve declines,
        // or leaves a non-finite entry in its solution, whenever one of them is not
        // finite (`sim::solve::a_non_finite_input_never_gives_a_finite_generated_solution`),
        // so a finite solution proves them finite; before any other path the solve
        // checks them, naming a non-finite one.
        let checked = self.terms_checked;
        if redundant {
            self.redundant_velocity_residuals(t)?;
        }
        let velocities = redundant.then(|| Velocities {
            residuals: &self.vel,
            qd: &self.qd,
            speed: inf_norm(&self.qd),
        });
        let stats = self.dynamics.solve_evaluated(
            self.mech,
            &mut self.ws,
            t,
            shift,
            velocities,
            checked,
            &mut self.solution,
        );
        let stats = match stats {
            Ok(stats) => stats,
            Err(e) => {
                if !checked {
                    self.forget_terms();
                }
                return Err(SimErrorKind::from_analysis(e.into(), Vec::new()));
            }
        };
        self.terms_checked = true;
        self.solved = state;
        if stats.path == SolverPath::Redundant {
            // The redundant path scattered J at this point into the dense array.
            self.dense = position;
            // Reported once, as first identified: which rows of a dependent set the
            // pivoting names can change along the motion, the redundancy does not
            // (only this path finds rows redundant).
            if self.redundant.is_empty() {
                self.redundant.extend(self.dynamics.redundant_constraints());
            }
        }
        Ok(())
    }

    /// Whether the next evaluation of the dynamics terms writes $C$ too: always with
    /// [`constraints_with_terms`](Self::constraints_with_terms), once after
    /// [`constraints_next`](Self::constraints_next) (cleared here).
    fn constraints_asked(&mut self) -> bool {
        self.constraints_with_terms || std::mem::take(&mut self.constraints_next)
    }

    /// [`velocity_residuals`](Self::velocity_residuals) for the solve of a model with
    /// redundant constraints, out of line: the solve of every other model does not
    /// carry it.
    #[cold]
    #[inline(never)]
    fn redundant_velocity_residuals(&mut self, t: f64) -> Result<(), SimErrorKind> {
        self.velocity_residuals(t).map_err(SimErrorKind::from_eval)
    }

    /// $M$, $Q$, $C_q$, $G$ and $\gamma$ at the current state, from one call of the
    /// model's fused evaluation (which gives $C_q$ and $G$ to the position group too,
    /// and $C$ when [`constraints_with_terms`](Self::constraints_with_terms)).
    pub fn dynamics_terms(&mut self, t: f64) -> Result<(), SimErrorKind> {
        let versions = self.versions(t);
        self.dynamics_terms_at(t, versions, self.constraints_with_terms)?;
        self.check_terms(t)
    }

    /// [`dynamics_terms_and_constraints_at`](Self::dynamics_terms_and_constraints_at)
    /// at the current state's versions.
    #[cfg(test)]
    fn dynamics_terms_and_constraints(&mut self, t: f64) -> Result<(), SimErrorKind> {
        let versions = self.versions(t);
        self.dynamics_terms_and_constraints_at(t, versions)
    }

    /// [`dynamics_terms`](Self::dynamics_terms) and $C$ at the current state, of
    /// versions `(position, state)`: from the same call when neither is held (the
    /// generated code computes $C$ from the sines it already has),
    /// [`constraints`](Self::constraints) when the terms are. For callers that read $C$
    /// at every point (Baumgarte's shift), which go on to the solve: the terms are left
    /// unchecked for it to vouch for (a non-finite term reaches the solution through
    /// the solve's matrix or, by the shift, its right-hand side, and the check then
    /// names it); a non-finite $C$ is not stamped, so it is evaluated again and named
    /// here.
    fn dynamics_terms_and_constraints_at(
        &mut self,
        t: f64,
        versions: (Stamp, Stamp),
    ) -> Result<(), SimErrorKind> {
        self.dynamics_terms_at(t, versions, true)?;
        if self.constraints != versions.0 {
            self.constraints(t).map_err(SimErrorKind::from_eval)?;
        }
        Ok(())
    }

    /// [`dynamics_terms`](Self::dynamics_terms) at the current state, of versions
    /// `(position, state)`, asking for $C$ too when `constraints` and $C$ is not held
    /// at the position. Without it the workspace's $C$ is not written, so its stamp
    /// stays true.
    #[inline]
    fn dynamics_terms_at(
        &mut self,
        t: f64,
        (position, state): (Stamp, Stamp),
        constraints: bool,
    ) -> Result<(), SimErrorKind> {
        if self.terms != state {
            let with_c = constraints && self.constraints != position;
            self.jacobian = 0;
            if with_c {
                self.constraints = 0;
            }
            self.ws
                .eval_dynamics_terms_unchecked(self.mech, t, &self.q, &self.qd, with_c);
            self.terms_checked = false;
            self.terms = state;
            self.jacobian = position;
            if with_c {
                self.stamp_terms_constraints(position);
            }
        }
        Ok(())
    }

    /// The finiteness check of the held dynamics terms ([`Workspace::check_dynamics_terms`],
    /// naming the first non-finite entry), once per evaluation; terms that fail it are
    /// forgotten with what was stamped from them.
    pub(crate) fn check_terms(&mut self, t: f64) -> Result<(), SimErrorKind> {
        if !self.terms_checked {
            if let Err(e) = self.ws.check_dynamics_terms(t) {
                self.forget_terms();
                return Err(SimErrorKind::from_eval(e));
            }
            self.terms_checked = true;
        }
        Ok(())
    }

    /// Forgets the dynamics terms and what was stamped from them (after they failed
    /// their check).
    fn forget_terms(&mut self) {
        for s in [
            &mut self.terms,
            &mut self.jacobian,
            &mut self.dense,
            &mut self.solved,
        ] {
            *s = 0;
        }
    }

    /// Stamps the $C$ the dynamics terms wrote, when it is finite (a non-finite one is
    /// left for [`constraints`](Self::constraints) to evaluate and report, as before
    /// the terms carried it).
    fn stamp_terms_constraints(&mut self, position: Stamp) {
        if all_finite(self.ws.constraints()) {
            self.constraints = position;
        }
    }

    /// The velocities corrected by `correct(cq, g, ct, bias, qd)` with the pattern values
    /// of $C_q$, $G$ and the rates at the current $(t, q)$, then $M$, $Q$ and $\gamma$ at
    /// the corrected velocities, from one call of the model's fused evaluation
    /// ([`Mechanism::dynamics_terms_corrected`]). The terms are not checked here: as
    /// those of [`accelerations`](Self::accelerations), they go to the model's
    /// generated solve, which vouches for them, and [`check_terms`](Self::check_terms)
    /// checks them before anything else reads them (`correct` sees $C_q$ and $G$
    /// unchecked: a generated projection declines on a non-finite entry). Returns the
    /// versions of the corrected state, for
    /// [`accelerations_with`](Self::accelerations_with).
    pub fn dynamics_terms_corrected(
        &mut self,
        t: f64,
        correct: &mut VelocityCorrection<'_>,
    ) -> Result<(Stamp, Stamp), EvalError> {
        let at = self.position(t);
        self.rates_at(t, at)?;
        let with_c = self.constraints_asked() && self.constraints != at;
        self.jacobian = 0;
        self.terms = 0;
        if with_c {
            self.constraints = 0;
        }
        self.ws.eval_dynamics_terms_corrected_unchecked(
            self.mech,
            t,
            &self.q,
            &mut self.qd,
            with_c,
            correct,
        );
        // The velocities may have changed: a new state version, the same position.
        let (position, state) = self.versions(t);
        self.terms = state;
        self.terms_checked = false;
        self.jacobian = position;
        if with_c {
            self.stamp_terms_constraints(position);
        }
        Ok((position, state))
    }

    /// $\ddot q$ from $M\ddot q = Q$ at the current state (Cholesky of the dense $M$),
    /// $\lambda = 0$.
    pub fn free_accelerations(&mut self, t: f64) -> Result<(), SimErrorKind> {
        let state = self.versions(t).1;
        if self.solved == state {
            return Ok(());
        }
        self.dynamics_terms(t)?;
        let info = self.info;
        let n = info.nq();
        if self.mass.matrix_mut().len() != n * n {
            self.mass = SmallCholesky::new(n);
        }
        let a = self.mass.matrix_mut();
        a.fill(0.0);
        for (&(r, c), &v) in info.mass_pattern.iter().zip(&self.ws.mass_values) {
            a[r as usize * n + c as usize] = v;
        }
        self.factorizations += 1;
        let ratio = self.mass.factor().ratio();
        if ratio.is_nan() || ratio <= SINGULAR_RATIO {
            return Err(SimErrorKind::Singular {
                t,
                matrix: SingularMatrix::Mass,
                ratio,
                constraints: Vec::new(),
            });
        }
        let (qdd, lambda) = self.solution.split_at_mut(n);
        qdd.copy_from_slice(&self.ws.forces);
        self.mass.solve(qdd);
        lambda.fill(0.0);
        self.solved = state;
        Ok(())
    }

    /// $\ddot q$ and $\lambda$ at the current state with Baumgarte's shift of $\gamma$
    /// (see [`accelerations`](Self::accelerations)), formed in `shift` (left as it is
    /// when the state is the one last solved at, which needs no solve): the terms
    /// with $C$ from one fused call
    /// ([`dynamics_terms_and_constraints_at`](Self::dynamics_terms_and_constraints_at)),
    /// the shift from them, the solve. The state's versions are checked once for the
    /// three, which read the same $(t, q, \dot q)$.
    pub fn stabilized_accelerations(
        &mut self,
        t: f64,
        alpha: f64,
        beta: f64,
        shift: &mut [f64],
    ) -> Result<(), SimErrorKind> {
        let versions = self.versions(t);
        if self.solved == versions.1 {
            return Ok(());
        }
        self.dynamics_terms_and_constraints_at(t, versions)?;
        self.baumgarte_shift_at(t, versions.0, alpha, beta, shift)
            .map_err(SimErrorKind::from_eval)?;
        self.accelerations_at(t, versions, Some(shift))
    }

    /// The Baumgarte shift $s = -2\alpha [C_q\dot q + C_t; G\dot q + g] - \beta^2 [C; 0]$
    /// at the current state, whose $(t, q)$ is of version `at`, into `shift`.
    fn baumgarte_shift_at(
        &mut self,
        t: f64,
        at: Stamp,
        alpha: f64,
        beta: f64,
        shift: &mut [f64],
    ) -> Result<(), EvalError> {
        let mh = self.info.nh();
        self.constraints_with_jacobian_values_at(t, at)?;
        self.velocity_residuals_at(t, at)?;
        let c = self.ws.constraints();
        // -2α v - β²C on the holonomic rows, -2α v on the others (v - 0 is v, to the
        // bit, the sign of a zero included).
        let (damping, stiffness) = (-2.0 * alpha, beta * beta);
        let (holonomic, nonholonomic) = shift.split_at_mut(mh);
        let (vel_h, vel_nh) = self.vel.split_at(mh);
        for ((s, v), c) in holonomic.iter_mut().zip(vel_h).zip(c) {
            *s = damping * v - stiffness * c;
        }
        for (s, v) in nonholonomic.iter_mut().zip(vel_nh) {
            *s = damping * v;
        }
        Ok(())
    }

    /// Holds $M$ of the last evaluation, at the state a step ends in (DOP853's last
    /// stage, [`OdeSystem::step_end_next`](crate::ode::OdeSystem)), as the metric of the
    /// step's projection at `t` ([`project_in_mass_metric`](Self::project_in_mass_metric)):
    /// called before DOP853's dense stages, evaluated after it on the steps where the
    /// run interpolates, which would otherwise leave theirs, so that the step would
    /// depend on where the rows are. Other steps read the workspace's $M$, still that
    /// evaluation's.
    pub(crate) fn hold_metric(&mut self, t: f64) {
        self.metric.copy_from_slice(&self.ws.mass_values);
        self.metric_t = Some(t);
    }

    /// Projection onto the constraint manifold, in the metric of the mass matrix where
    /// the model's generated solve of the augmented system serves
    /// ([`project_in_mass_metric`](Self::project_in_mass_metric)), else (no generated
    /// solve, redundant rows, no convergence) orthogonally: Newton with minimum-norm
    /// corrections $\Delta q = -C_q^\mathsf{T}(C_q C_q^\mathsf{T})^{-1}C$ on the
    /// positions until $\lVert C\rVert_\infty \le \varepsilon(1 + \lVert q\rVert_\infty)$,
    /// then [`project_velocities`](Self::project_velocities).
    ///
    /// When the positions took a Newton update and every projected row is holonomic,
    /// the velocities are projected by the chord iteration with the factor of the last
    /// update's $J J^\mathsf{T}$ ([`chord_velocities`](Self::chord_velocities)), which
    /// converges to the same orthogonal projection at the corrected positions: one
    /// Gram matrix per projection.
    pub fn project(&mut self, t: f64) -> Result<(), SimErrorKind> {
        if self.project_in_mass_metric(t)? {
            return Ok(());
        }
        self.project_positions(t)?;
        if self.position_factor && self.chord_velocities(t)? {
            return Ok(());
        }
        self.project_velocities(t)
    }

    /// Most position updates of [`project_in_mass_metric`](Self::project_in_mass_metric).
    const MASS_UPDATES: usize = 3;

    /// The projection in the metric of $M$, by the model's generated solve of the
    /// augmented system (E31), or the sparse $LDL^\mathsf{T}$ of large models without
    /// one ([`Dynamics`]' general path, pivots checked alike), with the right-hand sides $[0; -C; 0]$ and
    /// $[0; -(J\dot q + [C_t; g])]$: positions by the Newton updates
    /// $\Delta q = -M^{-1}J^\mathsf{T}(J M^{-1} J^\mathsf{T})^{-1}[C; 0]$ with $M$ of the
    /// integrator's last evaluation (the state to project for DOP853, DOPRI5 and
    /// Adams, a stage of the step otherwise: no evaluation of its own) and $J$ at the
    /// latest positions (the non-holonomic rows ask $G\Delta q = 0$:
    /// the correction is one the velocity constraints admit), until the constraints
    /// are met to the Newton tolerance; then the velocities by one update with $J$ at
    /// the corrected positions, which meets $J\dot q + [C_t; g] = 0$ to round-off. The
    /// velocity update is the change of least kinetic energy that meets the velocity
    /// constraints. `false` when it does not apply (neither solve, rows dropped
    /// as redundant, a declined or non-finite solve) or the positions do not converge
    /// in [`MASS_UPDATES`](Self::MASS_UPDATES) updates, for the orthogonal projection
    /// to finish from where it stopped.
    fn project_in_mass_metric(&mut self, t: f64) -> Result<bool, SimErrorKind> {
        // A held metric serves this correction only.
        let held_t = self.metric_t.take();
        let info = self.info;
        let (n, mh, m) = (info.nq(), info.nh(), info.nh() + info.nnh());
        if m == 0
            || self.rows.len() != m
            || self.rows_h != mh
            || !self.dynamics.solves_without_pivoting()
        {
            return Ok(false);
        }
        let eval = SimErrorKind::from_eval;
        // M of the integrator's last evaluation: at the kept state for DOP853, DOPRI5
        // and Adams, at a stage of the step for the others (a metric as good, and no
        // evaluation of its own); the terms at the kept state when none is held, and
        // for an output row (the last evaluation there is the previous row's record,
        // and an interpolant off the manifold would land where that row was).
        // The metric held at the step's last stage (`hold_metric`, on steps with
        // dense stages) when the state is that stage's.
        let held = held_t == Some(t) && !self.row;
        if self.terms == 0 || self.row {
            self.dynamics_terms(t)?;
        } else if !held {
            self.check_terms(t)?;
        }
        let tol = self.newton.tolerance;
        let mut previous = f64::INFINITY;
        let mut met = false;
        for update in 0..=Self::MASS_UPDATES {
            // The solve reads the pattern values; so do the tests (no dense C_q).
            self.constraints_with_jacobian_values(t).map_err(eval)?;
            let size = scale::coordinate_size(&self.q);
            let (c, norms) = self.ws.constraints_and_row_norms(self.mech);
            let residual = inf_norm(c);
            if scale::all_met_by_norms(c, norms, tol, size)
                || (residual >= 0.5 * previous && scale::at_rounding_floor_by_norms(c, norms, size))
            {
                met = true;
                break;
            }
            // Not falling (or NaN): the orthogonal projection takes over, from the
            // better of the last two iterates.
            let falling = residual.partial_cmp(&previous) == Some(Ordering::Less);
            if !falling && update > 0 {
                self.q.copy_from_slice(&self.dx);
            }
            if update == Self::MASS_UPDATES || !falling {
                break;
            }
            previous = residual;
            self.dx.copy_from_slice(&self.q);
            let rows = &mut self.solution_scratch[n..];
            rows[..mh].copy_from_slice(c);
            rows[mh..].fill(0.0);
            if !self.mass_metric_update(true, held) {
                return Ok(false);
            }
            self.newton_iterations += 1;
        }
        if !met {
            return Ok(false);
        }
        // Velocities: one update with J at the corrected positions is exact but for the
        // rounding of the solve (pivots at least 1e-8 of their diagonals). It is not
        // checked here: a check cost 4–8 % of a run and never fired
        // (docs/decisions/0034-projection-in-the-mass-metric.md),
        // and the monitors evaluate the velocity residuals at every kept state anyway
        // (`Run::monitors`, the largest velocity violation).
        self.velocity_residuals(t).map_err(eval)?;
        self.solution_scratch[n..].copy_from_slice(&self.vel);
        Ok(self.mass_metric_update(false, held))
    }

    /// One update of [`project_in_mass_metric`](Self::project_in_mass_metric): with the
    /// constraint residuals $r$ in the rows of `solution_scratch`, the solve
    /// ([`Dynamics::solve_unchecked`]) of $[M\ J^\mathsf{T}; J\ 0][\Delta; \mu] = [0; -r]$ (the terms held in the
    /// workspace), and $\Delta$ added to the positions (`positions`) or to the
    /// velocities. `false`, with nothing changed, when the solve declines or its
    /// result is not finite.
    fn mass_metric_update(&mut self, positions: bool, held: bool) -> bool {
        let n = self.info.nq();
        let x = &mut self.solution_scratch;
        x[..n].fill(0.0);
        for r in &mut x[n..] {
            *r = -*r;
        }
        let ws = &self.ws;
        let mass = if held { &self.metric } else { &ws.mass_values };
        let terms = (&mass[..], &ws.cq_values[..], &ws.g_values[..]);
        if !self.dynamics.solve_unchecked(self.mech, terms, x) || !all_finite(x) {
            return false;
        }
        self.factorizations += 1;
        let target = if positions { &mut self.q } else { &mut self.qd };
        for (v, d) in target.iter_mut().zip(&x[..n]) {
            *v += d;
        }
        true
    }

    /// Most updates of [`chord_velocities`](Self::chord_velocities).
    const CHORD_UPDATES: usize = 4;

    /// The orthogonal projection of [`project_velocities`](Self::project_velocities)
    /// by the chord iteration
    /// $\dot q \leftarrow \dot q - J^\mathsf{T}G_0^{-1}(J\dot q + [C_t; g])$, with $J$
    /// at the current positions and $G_0$ the Gram matrix the last position update
    /// factored (at positions off by that update, so the iteration contracts at a rate
    /// proportional to its size, the positions' Newton tolerance times the
    /// conditioning): every update lies in the range of $J^\mathsf{T}$, so the limit is
    /// the orthogonal projection. Stops at round-off; returns `false` (velocities
    /// unchanged or partly updated, for the factored projection to finish) when it
    /// does not contract.
    fn chord_velocities(&mut self, t: f64) -> Result<bool, SimErrorKind> {
        let n = self.info.nq();
        let eval = SimErrorKind::from_eval;
        self.dense_jacobian(t).map_err(eval)?;
        self.velocity_residuals(t).map_err(eval)?;
        let m = self.rows.len();
        let mut previous = f64::INFINITY;
        for _ in 0..Self::CHORD_UPDATES {
            for (mu, &i) in self.mu.iter_mut().zip(&self.rows) {
                *mu = self.vel[i];
            }
            self.lu_h.solve(&mut self.mu[..m]);
            let jac = self.ws.jacobian();
            let dx = &mut self.dx;
            dx.fill(0.0);
            for (&i, mu) in self.rows.iter().zip(&self.mu) {
                for (d, a) in dx.iter_mut().zip(&jac[i * n..(i + 1) * n]) {
                    *d += a * mu;
                }
            }
            // The largest change without `f64::max` (whose NaN handling is a chain of
            // three instructions per entry), and a flag for a non-finite one.
            let (mut step, mut finite) = (0.0_f64, true);
            for (v, d) in self.qd.iter_mut().zip(&*dx) {
                *v -= d;
                let a = d.abs();
                step = if a > step { a } else { step };
                finite &= a <= f64::MAX;
            }
            if !finite || step >= 0.5 * previous {
                return Ok(false);
            }
            previous = step;
            // The residuals at the updated velocities, J q̇ + c − J Δq̇ (linear in q̇,
            // so no evaluation), met when each is at the round-off of its
            // evaluation, 32 ε (Σⱼ |Jᵢⱼ q̇ⱼ| + |cᵢ|).
            let mut met = true;
            for &i in &self.rows {
                let row = &jac[i * n..(i + 1) * n];
                let (mut change, mut products, mut jqd) = (0.0, 0.0, 0.0);
                for ((a, v), d) in row.iter().zip(&self.qd).zip(&*dx) {
                    change += a * d;
                    products += (a * v).abs();
                    jqd += a * v;
                }
                let c = self.vel[i] - jqd - change;
                self.vel[i] -= change;
                met &= self.vel[i].abs() <= 32.0 * f64::EPSILON * (products + c.abs());
            }
            if met {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// The positions' part of [`project`](Self::project).
    pub fn project_positions(&mut self, t: f64) -> Result<(), SimErrorKind> {
        let n = self.info.nq();
        let eval = SimErrorKind::from_eval;
        let tol = self.newton.tolerance;
        // One renewal of the dropped redundant rows per projection (see `refit`); the
        // rows dropped near a rank drop are taken back first when it is left.
        let mut refitted = self.rows_h < self.rank && self.refit(t);
        self.position_factor = false;
        if self.rows_h > 0 {
            let mut iterations = 0;
            let mut previous = f64::INFINITY;
            loop {
                self.constraints_with_jacobian(t).map_err(eval)?;
                let residual = inf_norm(self.ws.constraints());
                let size = scale::coordinate_size(&self.q);
                let (c, jac) = (self.ws.constraints(), self.ws.jacobian());
                // Met, or stagnant at the rounding floor (`scale::at_rounding_floor`).
                if scale::all_met(c, jac, n, tol, size)
                    || (residual >= 0.5 * previous && scale::at_rounding_floor(c, jac, n, size))
                {
                    break;
                }
                previous = residual;
                let stalled = iterations == self.newton.max_iterations || !residual.is_finite();
                if stalled && !refitted && self.refit(t) {
                    (refitted, iterations) = (true, 0);
                    continue;
                }
                if stalled {
                    return Err(SimErrorKind::NewtonFailed {
                        t,
                        iterations,
                        residual,
                        constraints: self.violated(t, tol),
                    });
                }
                let ratio = gram_cholesky_planned(&mut self.lu_h, self.ws.jacobian(), &self.gram_h);
                if (ratio.is_nan() || ratio <= REFIT_RATIO) && !refitted && self.refit(t) {
                    refitted = true;
                    continue;
                }
                if ratio.is_nan() || ratio <= SINGULAR_RATIO {
                    return Err(SimErrorKind::Singular {
                        t,
                        matrix: SingularMatrix::Projection,
                        ratio,
                        constraints: self.violated(t, tol),
                    });
                }
                let rows = &self.rows[..self.rows_h];
                for (mu, &i) in self.mu.iter_mut().zip(rows) {
                    *mu = self.ws.constraints()[i];
                }
                self.lu_h.solve(&mut self.mu[..rows.len()]);
                let jac = self.ws.jacobian();
                for (&i, mu) in rows.iter().zip(&self.mu) {
                    for (qj, a) in self.q.iter_mut().zip(&jac[i * n..(i + 1) * n]) {
                        *qj -= a * mu;
                    }
                }
                iterations += 1;
                self.newton_iterations += 1;
                self.factorizations += 1;
                self.position_factor = self.rows.len() == self.rows_h;
            }
        }
        Ok(())
    }

    /// The orthogonal projection of the velocities onto the velocity constraints at the
    /// current positions,
    /// $\dot q \leftarrow \dot q - J^\mathsf{T}(J J^\mathsf{T})^{-1}(J\dot q + [C_t; g])$
    /// (the rows `rows`).
    pub fn project_velocities(&mut self, t: f64) -> Result<(), SimErrorKind> {
        let n = self.info.nq();
        if self.rows.is_empty() {
            return Ok(());
        }
        let eval = SimErrorKind::from_eval;
        self.velocity_residuals(t).map_err(eval)?;
        self.dense_jacobian(t).map_err(eval)?;
        let mut ratio = gram_cholesky_planned(&mut self.lu_v, self.ws.jacobian(), &self.gram_v);
        if (ratio.is_nan() || ratio <= REFIT_RATIO) && self.refit(t) {
            self.velocity_residuals(t).map_err(eval)?;
            self.dense_jacobian(t).map_err(eval)?;
            ratio = gram_cholesky_planned(&mut self.lu_v, self.ws.jacobian(), &self.gram_v);
        }
        let rows = &self.rows[..];
        self.factorizations += 1;
        if ratio.is_nan() || ratio <= SINGULAR_RATIO {
            return Err(SimErrorKind::Singular {
                t,
                matrix: SingularMatrix::Projection,
                ratio,
                constraints: Vec::new(),
            });
        }
        for (mu, &i) in self.mu.iter_mut().zip(rows) {
            *mu = self.vel[i];
        }
        self.lu_v.solve(&mut self.mu[..rows.len()]);
        let jac = self.ws.jacobian();
        for (&i, mu) in rows.iter().zip(&self.mu) {
            for (v, a) in self.qd.iter_mut().zip(&jac[i * n..(i + 1) * n]) {
                *v -= a * mu;
            }
        }
        Ok(())
    }

    /// The holonomic constraints not met to the relative `tolerance` at the current
    /// $(t, q)$ (see [`crate::scale`]); empty when they cannot be evaluated.
    pub fn violated(&mut self, t: f64, tolerance: f64) -> Vec<&'static str> {
        if self.constraints_with_jacobian(t).is_err() {
            return Vec::new();
        }
        let size = scale::coordinate_size(&self.q);
        let n = self.info.nq();
        scale::unmet(
            self.ws.constraints(),
            self.ws.jacobian(),
            n,
            tolerance,
            size,
        )
        .map(|i| self.info.holonomic[i].name)
        .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{DynamicsParams, KinematicsParams, Symbol};

    /// A particle on the unit circle, $C = x^2 + y^2 - 1$, $C_q = [2x, 2y]$.
    struct Circle;

    static INFO: Info = Info {
        name: "circle",
        coordinates: &[Symbol { name: "x", doc: "" }, Symbol { name: "y", doc: "" }],
        holonomic: &[Symbol {
            name: "radius",
            doc: "",
        }],
        mass_pattern: &[(0, 0), (1, 1)],
        holonomic_pattern: &[(0, 0), (0, 1)],
        ..Info::EMPTY
    };

    impl Mechanism for Circle {
        fn info(&self) -> &'static Info {
            &INFO
        }
        fn parameter(&self, _: usize) -> f64 {
            unreachable!("no parameters")
        }
        fn set_parameter(&mut self, _: usize, _: f64) {
            unreachable!("no parameters")
        }
        fn mass_matrix(&self, _: f64, _: &[f64], out: &mut [f64]) {
            out.fill(1.0);
        }
        fn forces(&self, _: f64, _: &[f64], _: &[f64], out: &mut [f64]) {
            out.fill(0.0);
        }
        fn holonomic(&self, _: f64, q: &[f64], out: &mut [f64]) {
            out[0] = q[0] * q[0] + q[1] * q[1] - 1.0;
        }
        fn holonomic_jacobian(&self, _: f64, q: &[f64], out: &mut [f64]) {
            out[0] = 2.0 * q[0];
            out[1] = 2.0 * q[1];
        }
        fn kinetic_energy(&self, _: f64, _: &[f64], qd: &[f64]) -> f64 {
            0.5 * (qd[0] * qd[0] + qd[1] * qd[1])
        }
    }

    /// A point of [`Circle`] with the default parameters.
    fn circle_point(mech: &Circle) -> Point<'_, Circle> {
        Point::new(mech, DynamicsParams::default(), KinematicsParams::default()).expect("a point")
    }

    /// $C = x^2 + y^2 - 1$ in closed form.
    fn circle(q: &[f64]) -> f64 {
        q[0] * q[0] + q[1] * q[1] - 1.0
    }

    /// `add_products` is the scatter `out[r] += v * x[c]` bit for bit, for patterns by
    /// rows, with rows left and entered again, and empty.
    #[test]
    fn add_products_is_the_scatter() {
        let x = [0.1, -3.0, 7.0e5, 1.0 / 3.0];
        let patterns: [&[(u32, u32)]; 4] = [
            &[],
            &[(0, 0), (0, 1), (0, 3), (1, 1), (2, 0), (2, 2), (2, 3)],
            &[(1, 2), (0, 0), (0, 3), (1, 0), (1, 1), (2, 3), (0, 1)],
            &[(2, 3)],
        ];
        for pattern in patterns {
            let values: Vec<f64> = (0..pattern.len())
                .map(|i| (1.7 * i as f64 + 0.3).sin() * 10f64.powi(i as i32 - 3))
                .collect();
            let start = [0.25, -1e-9, 4.0];
            let mut expected = start;
            for (&(r, c), v) in pattern.iter().zip(&values) {
                expected[r as usize] += v * x[c as usize];
            }
            let mut out = start;
            add_products(&mut out, pattern, &values, &x);
            let bits = |a: &[f64; 3]| a.map(f64::to_bits);
            assert_eq!(bits(&out), bits(&expected), "{pattern:?}");
        }
    }

    fn counts(p: &Point<'_, Circle>) -> (u64, u64, u64) {
        let e = p.evaluations;
        (e.constraints, e.jacobian, e.fused)
    }

    /// $C$ comes with $J$ exactly when $J$ was asked for after $C$ at the last point
    /// since the state was set: an iteration reading both at each iterate (the chart's
    /// polish) evaluates them in one call from its second iterate on, one reading $C$
    /// only (the chart's correction) never evaluates $J$; the values are those of the
    /// separate functions.
    #[test]
    fn constraints_come_with_the_jacobian_when_both_were_read() {
        let mut p = circle_point(&Circle);
        // Reading C only, at three iterates.
        p.set_state(&[1.2, 0.1, 0.0, 0.0]);
        for k in 0..3 {
            p.q[1] = 0.1 * f64::from(k);
            p.constraints(0.0).expect("C");
        }
        assert_eq!(counts(&p), (3, 0, 0));
        // C, then J, at each iterate: separate at the first, fused from the second.
        for k in 0..3 {
            p.q[0] = 1.0 + 0.01 * f64::from(k);
            let c = p.constraints(0.0).expect("C")[0];
            let j = p.dense_jacobian(0.0).expect("J").to_vec();
            let (x, y) = (p.q[0], p.q[1]);
            assert_eq!(c, x * x + y * y - 1.0);
            assert_eq!(j, [2.0 * x, 2.0 * y]);
        }
        assert_eq!(counts(&p), (4, 1, 2));
        // A new state from the integrator: C alone again until J is asked for.
        p.set_state(&[0.9, 0.3, 0.0, 0.0]);
        p.constraints(0.0).expect("C");
        assert_eq!(counts(&p), (5, 1, 2));
        // Both asked for together: one fused call, then hits.
        p.q[0] = 0.95;
        p.constraints_with_jacobian(0.0).expect("C and J");
        p.violations(0.0).expect("violations");
        p.constraints(0.0).expect("C");
        p.dense_jacobian(0.0).expect("J");
        assert_eq!(counts(&p), (5, 1, 3));
        assert_eq!(p.ws.constraints()[0], 0.95 * 0.95 + 0.3 * 0.3 - 1.0);
    }

    /// $C$ comes with the dynamics terms only when asked for, and is never stale: terms
    /// evaluated without it leave the $C$ held at another point to be evaluated anew
    /// where it is read; with [`Point::constraints_with_terms`] (and for Baumgarte's
    /// [`Point::dynamics_terms_and_constraints_at`]) the terms' call writes it, and reading
    /// it at the same point evaluates nothing more. Values against the closed form
    /// $x^2 + y^2 - 1$.
    #[test]
    fn constraints_come_with_the_terms_only_when_asked_for() {
        let mut p = circle_point(&Circle);
        p.set_state(&[1.2, 0.1, 0.3, -0.2]);
        p.constraints(0.0).expect("C");
        assert_eq!(counts(&p), (1, 0, 0));
        // Terms at a new point without C: C there is evaluated when read.
        p.q[0] = 1.1;
        p.dynamics_terms(0.0).expect("terms");
        let expected = circle(&p.q);
        assert_eq!(p.constraints(0.0).expect("C")[0], expected);
        assert_eq!(counts(&p), (2, 0, 0));
        // Asked for with every evaluation of the terms: read at no further cost.
        p.constraints_with_terms = true;
        p.q[1] = 0.2;
        p.dynamics_terms(0.0).expect("terms");
        let expected = circle(&p.q);
        assert_eq!(p.constraints(0.0).expect("C")[0], expected);
        assert_eq!(counts(&p), (2, 0, 0));
        // Baumgarte's request, at a new point and then with the terms held.
        p.constraints_with_terms = false;
        p.q[0] = 1.05;
        p.dynamics_terms_and_constraints(0.0).expect("terms and C");
        let expected = circle(&p.q);
        assert_eq!(p.constraints(0.0).expect("C")[0], expected);
        assert_eq!(counts(&p), (2, 0, 0));
        p.q[1] = 0.25;
        p.dynamics_terms(0.0).expect("terms");
        p.dynamics_terms_and_constraints(0.0).expect("C alone");
        let expected = circle(&p.q);
        assert_eq!(p.constraints(0.0).expect("C")[0], expected);
        assert_eq!(counts(&p), (3, 0, 0));
    }

    /// [`Point::constraints_next`] gives $C$ with the next evaluation of the terms (the
    /// accelerations' call), read there at no further cost, and only with that one:
    /// the evaluation after it leaves $C$ to be evaluated where it is read.
    #[test]
    fn constraints_come_with_the_next_terms_once() {
        let mut p = circle_point(&Circle);
        p.set_state(&[1.2, 0.1, 0.3, -0.2]);
        p.constraints_next = true;
        p.accelerations(0.0, None).expect("accelerations");
        assert!(!p.constraints_next);
        let expected = circle(&p.q);
        assert_eq!(p.constraints(0.0).expect("C")[0], expected);
        assert_eq!(counts(&p), (0, 0, 0));
        p.set_state(&[1.1, 0.2, 0.3, -0.2]);
        p.accelerations(0.0, None).expect("accelerations");
        let expected = circle(&p.q);
        assert_eq!(p.constraints(0.0).expect("C")[0], expected);
        assert_eq!(counts(&p), (1, 0, 0));
    }
}
