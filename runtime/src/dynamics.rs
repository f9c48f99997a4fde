//! Accelerations and multipliers from the augmented system (docs/theory.md §augmented, E31).
//!
//! Input: $(q, \dot q, t)$ and a [`Workspace`]. Output: $\ddot q$ and
//! $\lambda = [\lambda_h; \lambda_{nh}]$ solving
//! $$\begin{bmatrix}M & J^\mathsf{T}\\ J & 0\end{bmatrix}
//!   \begin{bmatrix}\ddot q\\ \lambda\end{bmatrix} =
//!   \begin{bmatrix}Q\\ \gamma\end{bmatrix},\qquad J = \begin{bmatrix}C_q\\ G\end{bmatrix},
//!   \quad \gamma = \begin{bmatrix}\gamma_h\\ \gamma_{nh}\end{bmatrix},$$
//! i.e. $M\ddot q + J^\mathsf{T}\lambda = Q$ (sign convention of docs/theory.md §sign).
//!
//! **Paths.** The model's own solve ([`Mechanism::augmented_solve`]: a sparse
//! $LDL^\mathsf{T}$ the generator specialized to the patterns of $M$ and $J$, every
//! pivot checked) when it has one and its pivots are safe; otherwise a dense $LU$ for
//! small systems, and for large ones a sparse $LDL^\mathsf{T}$ in the generated solve's
//! order (coordinates first, no pivoting, every pivot checked; the symbolic
//! factorization once from the patterns) with a sparse $LU$ (partial pivoting) behind
//! it when a pivot fails; [`LinearSolver::Auto`] takes the model's solve first and
//! switches from dense to sparse at [`DynamicsParams::crossover`] unknowns.
//!
//! **Redundant constraints.** When the dense pivots (ratio below
//! [`DynamicsParams::rank_tolerance`]) or the sparse residual reveal a singular
//! system, complete pivoting on $J$ finds a maximal independent row set $R$ and the
//! redundant rows $D$ (reported by name, [`Dynamics::redundant_constraints`]). The
//! reduced system with $J_R$ gives $\ddot q$ (unique when $M$ is positive definite on
//! $\ker J$) and $\lambda_R$. Writing $J = T J_R$ with $T_R = I$ and
//! $T_D = J_D J_R^\mathsf{T}(J_R J_R^\mathsf{T})^{-1}$, every $\lambda$ with
//! $J^\mathsf{T}\lambda = J_R^\mathsf{T}\lambda_R$ satisfies $T^\mathsf{T}\lambda =
//! \lambda_R$, and the one of least 2-norm is
//! $\lambda = T (T^\mathsf{T}T)^{-1}\lambda_R$ (for a duplicated row: an equal
//! split). The redundant rows' $\gamma$ must agree with $\ddot q$ up to
//! [`DynamicsParams::redundant_tolerance`], otherwise
//! [`DynamicsError::InconsistentRedundant`]. Within it, $\ddot q$ meets the
//! independent rows exactly and the redundant ones in the least-squares sense of the
//! drift that made them disagree: a state off the constraint manifold by $\delta$
//! leaves $J_D\ddot q - \gamma_D = O(\delta)$, which no choice of $\ddot q$ can remove
//! without violating an independent row.
//!
//! **The split is kept.** Redundancy is usually structural (Bricard's linkage, a
//! parallelogram): the same rows stay dependent along the motion. The split $R$, $D$ of
//! a redundant solve is kept with its buffers, and the next solve starts from it: one
//! factorization of the reduced system, the consistency check of $D$ and the
//! multipliers, without trying the full system first and without a complete pivoting
//! of $J$. When the reduced matrix is no longer regular or the rows $D$ no longer agree
//! with $\ddot q$ (the motion left the configurations where they are redundant), the
//! split is dropped and the solve starts over from the full system.
//!
//! Invariant: no allocation after the first call, except when a new split of redundant
//! rows is found (its buffers) and when building an error.

use crate::linalg::dense::DenseLu;
use crate::linalg::elimination::Elimination;
use crate::linalg::inf_norm;
use crate::linalg::small::SmallLu;
use crate::linalg::sparse::{SparseKkt, SparseLdlt};
use crate::workspace::{
    all_finite, check_finite, check_len, check_same_model, check_state, EvalError, Quantity,
    Workspace,
};
use crate::{AugmentedSolve, Info, Mechanism};

/// Choice of the linear solver for the augmented system.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LinearSolver {
    /// The model's generated solve ([`Mechanism::augmented_solve`]) when it has one
    /// and accepts the system; otherwise dense below [`DynamicsParams::crossover`]
    /// unknowns, sparse from there on.
    #[default]
    Auto,
    /// Always dense.
    Dense,
    /// Always sparse: the $LDL^\mathsf{T}$ in the generated solve's order when its pivots
    /// pass, the $LU$ otherwise.
    Sparse,
    /// Always the sparse $LU$ (the general path of large models before the
    /// $LDL^\mathsf{T}$; kept for comparisons).
    SparseLu,
}

/// Tuning of [`Dynamics`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicsParams {
    /// Which linear solver.
    pub solver: LinearSolver,
    /// Size $n + m$ from which [`LinearSolver::Auto`] uses the sparse $LU$.
    pub crossover: usize,
    /// Relative pivot size below which the augmented matrix (dense path) or $J$ (the
    /// redundancy search) counts as rank deficient.
    pub rank_tolerance: f64,
    /// Relative residual above which a sparse solution is rejected (then the redundant
    /// path runs).
    pub residual_tolerance: f64,
    /// Relative residual of the redundant rows, $\max_D|J_D\ddot q - \gamma_D|$ over
    /// $\max_D(\lVert J_D\rVert(\lVert\ddot q\rVert + a_Q) + |\gamma_D|)$ with
    /// $a_Q = \max_j |Q_j|/M_{jj}$ (the accelerations the forces alone would give, the
    /// scale at a static equilibrium where $\ddot q = 0$), above which
    /// they count as inconsistent ([`DynamicsError::InconsistentRedundant`]). Below it
    /// the solution is the least-squares one described in the module docs. A kinematic
    /// analysis at an exact configuration keeps the default $10^{-8}$; a simulation,
    /// whose state drifts off the constraints by the integration error, raises it to
    /// match (see [`crate::sim`]).
    pub redundant_tolerance: f64,
}

impl Default for DynamicsParams {
    fn default() -> Self {
        Self {
            solver: LinearSolver::Auto,
            crossover: DEFAULT_CROSSOVER,
            rank_tolerance: 1e-10,
            residual_tolerance: 1e-10,
            redundant_tolerance: 1e-8,
        }
    }
}

/// Default crossover between the dense and the sparse path (unknowns $n + m$).
///
/// Measured on the planar pendulum chain (`runtime/tests/kin_chain.rs`, release, one
/// core): at $n + m = 12$ dense 1.7 µs vs sparse 1.4 µs, at 24: 5.9 vs 3.5 µs, at 96:
/// 171 vs 9 µs, at 384: 7–11 ms vs 36–47 µs. The chain is as sparse as models get, so
/// the switch sits a little above the measured break-even (≈ 10) to leave the tiny
/// systems, where both take a few µs, to the rank-revealing dense factorization.
pub const DEFAULT_CROSSOVER: usize = 16;

/// Which path solved the system.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SolverPath {
    /// The model's generated solve ([`Mechanism::augmented_solve`]).
    Generated,
    /// Dense complete-pivoting $LU$.
    Dense,
    /// Sparse $LU$.
    Sparse,
    /// Sparse $LDL^\mathsf{T}$, coordinates eliminated first.
    SparseLdlt,
    /// Rank-deficient $J$: reduced system and minimum-norm multipliers.
    Redundant,
}

/// Statistics of one acceleration solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccelerationStats {
    /// The path that produced the result.
    pub path: SolverPath,
    /// Numerical rank of $J$ ($= m$ unless [`SolverPath::Redundant`]).
    pub rank: usize,
    /// Smallest / largest pivot of the dense factorization used (1 on the sparse and
    /// the generated paths).
    pub pivot_ratio: f64,
}

/// Errors of the acceleration solve.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DynamicsError {
    /// The augmented matrix is singular although $J$ has full rank (or the reduced one
    /// is singular): $M$ is not positive definite on $\ker J$, or the kept rows of $J$
    /// are nearly dependent (`nearly_dependent` names them: a near-singular
    /// configuration).
    #[error("augmented system singular at t = {t:?} with `J` of rank {rank} (pivot ratio {ratio:e}): {}", singular_cause(*jacobian_ratio, nearly_dependent, coordinates))]
    Singular {
        /// Time.
        t: f64,
        /// Rank of $J$.
        rank: usize,
        /// Smallest / largest pivot (of the equilibrated matrix).
        ratio: f64,
        /// Coordinates whose accelerations the equations leave undetermined (the
        /// unknowns complete pivoting finds no pivot for, a massless coordinate for
        /// instance).
        coordinates: Vec<&'static str>,
        /// Smallest / largest pivot of the rows of $J$ kept (complete pivoting of the
        /// row-equilibrated $J$): the pivots of the augmented matrix's constraint block
        /// are of the order of their squares, so rows within [`NEARLY_DEPENDENT`] of
        /// dependence make it singular however regular $M$ is.
        jacobian_ratio: f64,
        /// The kept constraints whose rows are within [`NEARLY_DEPENDENT`] of
        /// dependence on the others (the rows complete pivoting reaches last): empty when
        /// $J$ is well conditioned and the mass matrix is what is singular.
        nearly_dependent: Vec<&'static str>,
    },
    /// Redundant constraints whose acceleration terms contradict the others.
    #[error("constraints {constraints:?} depend on the others at t = {t:?} and their acceleration equations contradict them (residual {residual:e}): redundant constraints that are inconsistent, or a singular configuration of independent ones (a lock of the mechanism, or a state carried there by the integration's drift){}", vanishing_note(vanishing))]
    InconsistentRedundant {
        /// Time.
        t: f64,
        /// The redundant constraints.
        constraints: Vec<&'static str>,
        /// $\max_D |J_D\ddot q - \gamma_D|$.
        residual: f64,
        /// Those of `constraints` whose rows of $J$ are zero there: a constraint whose
        /// gradient vanishes where it holds (`x² + y² − l²` with `l = 0`) exerts no
        /// force, and is redundant because it is degenerate, not because others imply it.
        vanishing: Vec<&'static str>,
    },
    /// The sparse symbolic factorization failed.
    #[error("sparse symbolic factorization of the augmented matrix of `{model}` failed: {reason}")]
    Symbolic {
        /// The model.
        model: &'static str,
        /// faer's report.
        reason: String,
    },
    /// Evaluation failed, or the result is not finite.
    #[error(transparent)]
    Eval(#[from] EvalError),
}

/// Acceleration analysis for one model.
#[derive(Debug)]
pub struct Dynamics {
    params: DynamicsParams,
    info: &'static Info,
    /// Whether the dense path is taken (below the sparse crossover).
    dense_path: bool,
    /// The dense path: partial pivoting first, complete pivoting when its pivots
    /// suggest a singular matrix. Allocated by [`Dynamics::new`] when there is no
    /// generated solve to try first, else at the first solve that needs them (most
    /// runs of a model with a generated solve never do: ten allocations fewer per run).
    /// These four are boxed: a model takes one path, and a structure holding the
    /// others inline is moved whole while a run is set up.
    small: Option<Box<SmallLu>>,
    dense: Option<Box<DenseLu>>,
    sparse: Option<Box<SparseKkt>>,
    /// The sparse $LDL^\mathsf{T}$ tried before the sparse $LU$ (`None` for
    /// [`LinearSolver::SparseLu`], and when its symbolic factorization is not possible).
    ldlt: Option<Box<SparseLdlt>>,
    /// Whether to try the model's generated solve (cleared when it has none).
    generated: bool,
    x: Vec<f64>,
    b: Vec<f64>,
    r: Vec<f64>,
    /// $[\ddot q; \lambda]$ of [`accelerations`](Self::accelerations), before they
    /// are handed out in the caller's two slices.
    out: Vec<f64>,
    redundant: Vec<usize>,
    /// The split of the last redundant solve, tried first while it serves.
    split: Option<Split>,
}

/// Rows of $J$ split into an independent set $R$ and redundant rows $D$, with the
/// buffers of a solve on it (see the module docs).
#[derive(Debug)]
struct Split {
    rows_r: Vec<usize>,
    rows_d: Vec<usize>,
    /// For each row of $J$, its place in $R$ (`usize::MAX` for the rows of $D$).
    slot: Vec<usize>,
    /// The reduced augmented system ($n + r$ unknowns) and its solution.
    reduced: Lu,
    x: Vec<f64>,
    /// $S = J_R J_R^\mathsf{T}$, then $A = I + X X^\mathsf{T}$ ($r \times r$).
    gram: Lu,
    /// $X = S^{-1} J_R J_D^\mathsf{T}$ by columns: column $k$ is `xt[k*r..(k+1)*r]`.
    xt: Vec<f64>,
    /// $\lambda_R$ mapped to the least-norm multipliers, length $r$.
    y: Vec<f64>,
    /// $w_d = J_d - T_d J_R$ of one row of $D$, length $n$.
    w: Vec<f64>,
}

/// A dense factorization sized for its use: partial pivoting below the crossover,
/// complete pivoting (faer) from it.
#[derive(Debug)]
enum Lu {
    Small(SmallLu),
    Dense(DenseLu),
}

impl Lu {
    fn new(n: usize, crossover: usize) -> Self {
        if n < crossover {
            Self::Small(SmallLu::new(n))
        } else {
            Self::Dense(DenseLu::new(n, 1))
        }
    }

    /// Zeroes the matrix.
    fn zero(&mut self) {
        match self {
            Self::Small(lu) => lu.matrix_mut().fill(0.0),
            Self::Dense(lu) => zero_dense(lu),
        }
    }

    /// Sets entry `(i, j)`.
    fn set(&mut self, i: usize, j: usize, v: f64) {
        match self {
            Self::Small(lu) => {
                let n = lu.dim();
                lu.matrix_mut()[i * n + j] = v;
            }
            Self::Dense(lu) => lu.matrix_mut()[(i, j)] = v,
        }
    }

    fn factor(&mut self) -> f64 {
        match self {
            Self::Small(lu) => lu.factor().ratio(),
            Self::Dense(lu) => lu.factor().ratio(),
        }
    }

    fn solve(&mut self, b: &mut [f64]) {
        match self {
            Self::Small(lu) => lu.solve(b),
            Self::Dense(lu) => lu.solve_vec(b),
        }
    }
}

/// Why a split did not give a solution.
enum SplitFailure {
    /// The reduced augmented matrix is singular (pivot ratio).
    Singular(f64),
    /// The rows $D$ disagree with $\ddot q$ (residual).
    Inconsistent(f64),
    /// A row of $D$ is no longer dependent on $R$ by the rank rule (the motion left
    /// the rank drop the split was made at); the rows' residual.
    Independent(f64),
}

/// The velocities of the state a solve is made at, for the check of the redundant
/// rows near a rank drop of $J$ (see [`Split::solve`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Velocities<'a> {
    /// $v = J\dot q + [C_t; g]$, every row.
    pub residuals: &'a [f64],
    /// $\dot q$.
    pub qd: &'a [f64],
    /// $\lVert\dot q\rVert_\infty$.
    pub speed: f64,
}

/// What [`Split::solve`] checks.
#[derive(Clone, Copy, Debug)]
struct Check<'a> {
    redundant_tolerance: f64,
    rank_tolerance: f64,
    velocities: Option<Velocities<'a>>,
    /// A split kept from an earlier solve, whose rows $D$ must still be dependent on
    /// $R$ by the rank rule ([`crate::RANK_PIVOT`]).
    kept: bool,
}

/// Multiple of [`crate::RANK_PIVOT`] by which a row of a kept split must exceed the
/// rank rule's distance to count as independent again: the split found by complete
/// pivoting measures pivots, the check distances, which agree within a small factor.
const INDEPENDENT: f64 = 10.0;

/// Safety factor on the first-order bound of the acceleration residual of a row that
/// is dependent only near a rank drop (docs/decisions/0036-through-a-rank-drop.md): the
/// bound's rate of the rows is estimated from $\gamma$.
const RANK_DROP_SAFETY: f64 = 4.0;

impl Dynamics {
    /// Scratch for the model described by `info`; the sparse symbolic factorization is
    /// computed here when the sparse path can be taken.
    pub fn new(info: &'static Info, params: DynamicsParams) -> Result<Self, DynamicsError> {
        let dim = info.nq() + info.nh() + info.nnh();
        let (dense, sparse) = match params.solver {
            LinearSolver::Dense => (true, false),
            LinearSolver::Sparse | LinearSolver::SparseLu => (false, true),
            LinearSolver::Auto => (dim < params.crossover, dim >= params.crossover),
        };
        let sparse = if sparse {
            Some(Box::new(SparseKkt::new(info).map_err(|e| {
                DynamicsError::Symbolic {
                    model: info.name,
                    reason: format!("{e:?}"),
                }
            })?))
        } else {
            None
        };
        let ldlt = if sparse.is_some() && params.solver != LinearSolver::SparseLu {
            SparseLdlt::new(info).map(Box::new)
        } else {
            None
        };
        let eager = dense && params.solver != LinearSolver::Auto;
        Ok(Self {
            params,
            info,
            dense_path: dense,
            small: eager.then(|| Box::new(SmallLu::new(dim))),
            dense: eager.then(|| Box::new(DenseLu::new(dim, 1))),
            sparse,
            ldlt,
            generated: params.solver == LinearSolver::Auto,
            x: vec![0.0; dim],
            b: vec![0.0; dim],
            r: vec![0.0; dim],
            out: vec![0.0; dim],
            redundant: Vec::with_capacity(info.nh() + info.nnh()),
            split: None,
        })
    }

    /// The tuning parameters.
    #[must_use]
    pub fn params(&self) -> &DynamicsParams {
        &self.params
    }

    /// Stored entries of the sparse augmented matrix (0 when the sparse path is off).
    #[must_use]
    pub fn sparse_nnz(&self) -> usize {
        self.sparse.as_ref().map_or(0, |k| k.nnz())
    }

    /// Constraints found redundant by the last solve (empty unless its path was
    /// [`SolverPath::Redundant`]).
    pub fn redundant_constraints(&self) -> impl Iterator<Item = &'static str> + '_ {
        let info = self.info;
        let mh = info.nh();
        self.redundant.iter().map(move |&r| {
            if r < mh {
                info.holonomic[r].name
            } else {
                info.nonholonomic[r - mh].name
            }
        })
    }

    /// Solves (E31) at $(q, \dot q, t)$: writes $\ddot q$ (length $n$) and
    /// $\lambda = [\lambda_h; \lambda_{nh}]$ (length $m$).
    #[allow(clippy::too_many_arguments)]
    pub fn accelerations<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &mut Workspace,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<AccelerationStats, DynamicsError> {
        self.accelerations_shifted(mech, ws, t, q, qd, None, qdd, lambda)
    }

    /// [`Dynamics::accelerations`] with $\gamma$ replaced by $\gamma + s$ (`shift`,
    /// length $m$): the stabilized right-hand side of Baumgarte's method.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn accelerations_shifted<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &mut Workspace,
        t: f64,
        q: &[f64],
        qd: &[f64],
        shift: Option<&[f64]>,
        qdd: &mut [f64],
        lambda: &mut [f64],
    ) -> Result<AccelerationStats, DynamicsError> {
        let info = self.info;
        let (n, m) = (info.nq(), info.nh() + info.nnh());
        check_same_model(info, ws.info())?;
        check_state(info, t, q, Some(qd))?;
        check_len(Quantity::Accelerations, qdd, n)?;
        check_len(Quantity::Multipliers, lambda, m)?;
        ws.eval_dynamics_terms(mech, t, q, qd)?;
        // The solution buffer leaves `self` for the call (a move of the vector, no
        // allocation) and comes back whatever the outcome.
        let mut out = std::mem::take(&mut self.out);
        let stats = self.solve_evaluated(mech, ws, t, shift, None, true, &mut out);
        if stats.is_ok() {
            qdd.copy_from_slice(&out[..n]);
            lambda.copy_from_slice(&out[n..]);
        }
        self.out = out;
        stats
    }

    /// The model's generated solve of (E31) with the evaluated terms of `ws` (and the
    /// shift of $\gamma$) into `out`: `None` when it declines, has no generated solve
    /// (then not tried again) or leaves a non-finite entry, for the general path.
    #[inline]
    fn try_generated<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &Workspace,
        shift: Option<&[f64]>,
        out: &mut [f64],
    ) -> Option<AccelerationStats> {
        right_hand_side(ws, shift, out);
        match mech.augmented_solve(&ws.mass_values, &ws.cq_values, &ws.g_values, out) {
            // A non-finite result goes to the general path, which reports it.
            AugmentedSolve::Solved if all_finite(out) => Some(AccelerationStats {
                path: SolverPath::Generated,
                rank: self.info.nh() + self.info.nnh(),
                pivot_ratio: 1.0,
            }),
            AugmentedSolve::Unavailable => {
                self.generated = false;
                None
            }
            AugmentedSolve::Solved | AugmentedSolve::Declined => None,
        }
    }

    /// Whether the model's generated solve of the augmented system is tried first and
    /// no split of redundant rows is in use: the state in which
    /// [`Mechanism::augmented_solve`] answers for this model.
    pub(crate) fn generated_solve(&self) -> bool {
        self.generated && self.split.is_none()
    }

    /// Whether [`solve_unchecked`](Self::solve_unchecked) can serve: the model's
    /// generated solve, or the sparse $LDL^\mathsf{T}$ when the model has none, and no
    /// split of redundant rows in use.
    pub(crate) fn solves_without_pivoting(&self) -> bool {
        self.split.is_none() && (self.generated || self.ldlt.is_some())
    }

    /// Solves $[M\ J^\mathsf{T}; J\ 0]\,x = b$ in place (`x` holds $b$ on entry) from
    /// the pattern values, by the model's generated solve or else the sparse
    /// $LDL^\mathsf{T}$, both with their pivots checked; `false` when neither serves or
    /// a pivot fails (`x` is then unspecified). For corrections (the projection in the
    /// metric of $M$), not for the accelerations of a run: no rank decision, no
    /// residual.
    pub(crate) fn solve_unchecked<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        (mass, cq, g): (&[f64], &[f64], &[f64]),
        x: &mut [f64],
    ) -> bool {
        if self.split.is_some() {
            return false;
        }
        if self.generated {
            match mech.augmented_solve(mass, cq, g, x) {
                AugmentedSolve::Solved => return true,
                AugmentedSolve::Declined => return false,
                // The model has none: not tried again, as in the accelerations.
                AugmentedSolve::Unavailable => self.generated = false,
            }
        }
        let Some(ldlt) = self.ldlt.as_mut() else {
            return false;
        };
        if !ldlt.factor(mass, cq, g) {
            return false;
        }
        self.b.copy_from_slice(x);
        ldlt.solve(&self.b, cq, x);
        true
    }

    /// The solve of [`Dynamics::accelerations_shifted`] with $M$, $Q$, $C_q$, $G$ and
    /// $\gamma$ already evaluated in `ws` (lengths checked by the caller), into
    /// `out` $= [\ddot q; \lambda]$ (length $n + m$; its contents are unspecified
    /// after an error). The model's generated solve works in `out` itself: the
    /// right-hand side is written there and solved in place, with no copy in between.
    /// `velocities`, when given, are those of the state (see [`Velocities`]): the
    /// redundant rows' check then allows for the rows that are dependent only near a
    /// rank drop of $J$. Unless `terms_checked`, the terms have not been checked for
    /// finiteness: the generated solve vouches for them by a finite solution, and
    /// every other path checks them first ([`Workspace::check_dynamics_terms`]).
    // The evaluated point's facts (shift, velocities, whether its terms are checked)
    // beside the buffers: one caller each in the point and in `accelerations_shifted`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn solve_evaluated<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &mut Workspace,
        t: f64,
        shift: Option<&[f64]>,
        velocities: Option<Velocities<'_>>,
        terms_checked: bool,
        out: &mut [f64],
    ) -> Result<AccelerationStats, DynamicsError> {
        let info = self.info;
        let m = info.nh() + info.nnh();
        self.redundant.clear();
        // Unchecked terms go to the generated solve first, which vouches for them by a
        // finite solution (see `sim::point::Point::accelerations`); every other path
        // reads checked terms.
        let vouch = !terms_checked && self.generated_solve();
        if !terms_checked && !vouch {
            ws.check_dynamics_terms(t)?;
        }

        if let Some(split) = self.split.as_mut() {
            right_hand_side(ws, shift, &mut self.b);
            ws.scatter_jacobian();
            let tol = self.params.redundant_tolerance;
            let check = Check {
                redundant_tolerance: tol,
                rank_tolerance: self.params.rank_tolerance,
                velocities,
                kept: true,
            };
            match split.solve(info, ws, &self.b, check, &mut self.x) {
                Ok(ratio) => {
                    self.redundant.extend_from_slice(&split.rows_d);
                    let stats = AccelerationStats {
                        path: SolverPath::Redundant,
                        rank: split.rows_r.len(),
                        pivot_ratio: ratio,
                    };
                    return self.finish(t, out, stats);
                }
                // Not redundant there any more: from the full system.
                Err(_) => self.split = None,
            }
        }

        if self.generated {
            if let Some(stats) = self.try_generated(mech, ws, shift, out) {
                return Ok(stats);
            }
        }
        if vouch {
            ws.check_dynamics_terms(t)?;
        }
        right_hand_side(ws, shift, &mut self.b);
        if self.dense_path && self.small.is_none() {
            self.allocate_dense();
        }
        let small = self.small.as_mut().and_then(|lu| {
            fill_small(lu, info, ws);
            let ratio = lu.factor().ratio();
            (ratio > self.params.rank_tolerance).then(|| {
                self.x.copy_from_slice(&self.b);
                lu.solve(&mut self.x);
                AccelerationStats {
                    path: SolverPath::Dense,
                    rank: m,
                    pivot_ratio: ratio,
                }
            })
        });
        let stats = if small.is_some() {
            small
        } else if let Some(lu) = self.dense.as_mut() {
            fill_dense(lu, info, ws, None);
            let ratio = lu.factor().ratio();
            if ratio > self.params.rank_tolerance {
                self.x.copy_from_slice(&self.b);
                lu.solve_vec(&mut self.x);
                Some(AccelerationStats {
                    path: SolverPath::Dense,
                    rank: m,
                    pivot_ratio: ratio,
                })
            } else {
                None
            }
        } else if let Some(kkt) = self.sparse.as_mut() {
            // The LDLᵀ's pivot tests vouch for its solution as the generated solve's do;
            // the LU's solution is checked by its residual.
            let ldlt = self.ldlt.as_mut().is_some_and(|f| {
                f.factor(&ws.mass_values, &ws.cq_values, &ws.g_values) && {
                    f.solve(&self.b, &ws.cq_values, &mut self.x);
                    true
                }
            });
            if ldlt {
                Some(AccelerationStats {
                    path: SolverPath::SparseLdlt,
                    rank: m,
                    pivot_ratio: 1.0,
                })
            } else if kkt
                .fill(&ws.mass_values, &ws.cq_values, &ws.g_values)
                .factor()
                .is_ok()
            {
                self.x.copy_from_slice(&self.b);
                kkt.solve_in_place(&mut self.x);
                let (res, scale) = kkt.residual(&self.x, &self.b, &mut self.r);
                (res <= self.params.residual_tolerance * scale).then_some(AccelerationStats {
                    path: SolverPath::Sparse,
                    rank: m,
                    pivot_ratio: 1.0,
                })
            } else {
                None
            }
        } else {
            unreachable!("Dynamics::new enables at least one path")
        };
        let stats = match stats {
            Some(s) => s,
            None => self.solve_redundant(ws, t, velocities)?,
        };
        self.finish(t, out, stats)
    }

    /// The buffers of the dense path, at its first use.
    #[cold]
    #[inline(never)]
    fn allocate_dense(&mut self) {
        let dim = self.x.len();
        self.small = Some(Box::new(SmallLu::new(dim)));
        self.dense = Some(Box::new(DenseLu::new(dim, 1)));
    }

    /// Checks the solution in `x` and hands it out as `out` $= [\ddot q; \lambda]$.
    fn finish(
        &self,
        t: f64,
        out: &mut [f64],
        stats: AccelerationStats,
    ) -> Result<AccelerationStats, DynamicsError> {
        let n = self.info.nq();
        check_finite(Quantity::Accelerations, t, &self.x[..n])?;
        check_finite(Quantity::Multipliers, t, &self.x[n..])?;
        out.copy_from_slice(&self.x);
        Ok(stats)
    }

    /// The rank-deficient path: finds the split of $J$ by complete pivoting (allocates
    /// its buffers) and solves on it; the split is kept for the next solves.
    fn solve_redundant(
        &mut self,
        ws: &mut Workspace,
        t: f64,
        velocities: Option<Velocities<'_>>,
    ) -> Result<AccelerationStats, DynamicsError> {
        let info = self.info;
        let (n, m) = (info.nq(), info.nh() + info.nnh());
        ws.scatter_jacobian();
        let mut elim = Elimination::new(m, n);
        elim.load(&ws.jacobian);
        // The constraint block of the augmented matrix has pivots of the order of those
        // of J M⁻¹ Jᵀ, the squares of J's: rows of J whose pivot ratio is below the
        // square root of the tolerance are what made the augmented matrix fail it (near
        // a change point, where loop closures become dependent).
        let phase = elim.phase(0, m, m, self.params.rank_tolerance.sqrt());
        let rank = phase.rank;
        let jacobian_ratio = if rank == 0 {
            0.0
        } else {
            phase.min_pivot / phase.scale
        };
        if rank == m {
            let mut lu = DenseLu::new(n + m, 1);
            fill_dense(&mut lu, info, ws, None);
            let coordinates = free_coordinates(&mut lu, info, self.params.rank_tolerance);
            return Err(DynamicsError::Singular {
                t,
                rank,
                ratio: lu.factor().ratio(),
                coordinates,
                jacobian_ratio,
                nearly_dependent: nearly_dependent(ws, info, &elim.rows[..rank]),
            });
        }
        let mut split = Split::new(
            n,
            m,
            elim.rows[..rank].to_vec(),
            elim.rows[rank..].to_vec(),
            self.params.crossover,
        );
        self.redundant.extend_from_slice(&split.rows_d);
        let rank_tol = self.params.rank_tolerance;
        let check = Check {
            redundant_tolerance: self.params.redundant_tolerance,
            rank_tolerance: rank_tol,
            velocities,
            kept: false,
        };
        match split.solve(info, ws, &self.b, check, &mut self.x) {
            Ok(ratio) => {
                self.split = Some(split);
                Ok(AccelerationStats {
                    path: SolverPath::Redundant,
                    rank,
                    pivot_ratio: ratio,
                })
            }
            Err(SplitFailure::Singular(ratio)) => {
                let mut lu = DenseLu::new(n + rank, 1);
                fill_dense(&mut lu, info, ws, Some(&split.slot));
                Err(DynamicsError::Singular {
                    t,
                    rank,
                    ratio,
                    coordinates: free_coordinates(&mut lu, info, rank_tol),
                    jacobian_ratio,
                    nearly_dependent: nearly_dependent(ws, info, &split.rows_r),
                })
            }
            // (A fresh split is not checked for independent rows.)
            Err(SplitFailure::Inconsistent(residual) | SplitFailure::Independent(residual)) => {
                let vanishing = self
                    .redundant
                    .iter()
                    .zip(self.redundant_constraints())
                    .filter(|&(&r, _)| ws.jacobian[r * n..(r + 1) * n].iter().all(|&a| a == 0.0))
                    .map(|(_, name)| name)
                    .collect();
                Err(DynamicsError::InconsistentRedundant {
                    t,
                    constraints: self.redundant_constraints().collect(),
                    residual,
                    vanishing,
                })
            }
        }
    }
}

/// The clause of [`DynamicsError::InconsistentRedundant`]'s message on constraints
/// whose gradient vanishes (none: empty).
fn vanishing_note(vanishing: &[&'static str]) -> String {
    if vanishing.is_empty() {
        return String::new();
    }
    format!(
        "; the gradients of {vanishing:?} are zero there: a constraint whose gradient \
         vanishes where it holds exerts no force (a parameter at a degenerate value, \
         such as a zero length?)"
    )
}

impl Split {
    /// Buffers for the split `rows_r`, `rows_d` of the `m` rows of $J$ ($n$ columns).
    fn new(n: usize, m: usize, rows_r: Vec<usize>, rows_d: Vec<usize>, crossover: usize) -> Self {
        let r = rows_r.len();
        let mut slot = vec![usize::MAX; m];
        for (k, &i) in rows_r.iter().enumerate() {
            slot[i] = k;
        }
        Self {
            reduced: Lu::new(n + r, crossover),
            x: vec![0.0; n + r],
            gram: Lu::new(r, crossover),
            xt: vec![0.0; r * rows_d.len()],
            y: vec![0.0; r],
            w: vec![0.0; n],
            rows_r,
            rows_d,
            slot,
        }
    }

    /// Solves the augmented system on the rows $R$, checks the rows $D$ and writes
    /// $[\ddot q; \lambda]$ (least-norm multipliers, module docs) into `out`; `b` is
    /// the full right-hand side $[Q; \gamma]$, $J$ is in `ws.jacobian` (dense). Returns
    /// the pivot ratio of the reduced matrix.
    ///
    /// The rows $D$ must meet $\ddot q$ to the relative `redundant_tolerance`, or, with
    /// the state's velocities, within the first-order bound of a row that is dependent
    /// only near a rank drop (docs/decisions/0036-through-a-rank-drop.md): with
    /// $T_d = X_d^\mathsf{T}$ the least-squares combination of the rows $R$ and
    /// $w_d = J_d - T_d J_R$ what the row adds to them,
    /// $|J_d\ddot q - \gamma_d| \le 2\lVert\dot w_d\rVert\,|v_d - T_d v_R| / \lVert w_d\rVert$,
    /// with $\lVert\dot w_d\rVert$ estimated by
    /// $(1 + \lVert T_d\rVert_1)\max_i|\gamma_i| / \lVert\dot q\rVert_\infty$.
    #[allow(non_snake_case)]
    fn solve(
        &mut self,
        info: &Info,
        ws: &Workspace,
        b: &[f64],
        check: Check<'_>,
        out: &mut [f64],
    ) -> Result<f64, SplitFailure> {
        let n = info.nq();
        let r = self.rows_r.len();
        self.reduced.zero();
        let reduced = &mut self.reduced;
        augmented_entries(info, ws, Some(&self.slot), |i, j, v| reduced.set(i, j, v));
        let ratio = self.reduced.factor();
        if ratio.is_nan() || ratio <= check.rank_tolerance {
            return Err(SplitFailure::Singular(ratio));
        }
        let x = &mut self.x;
        x[..n].copy_from_slice(&b[..n]);
        for (xk, &i) in x[n..].iter_mut().zip(&self.rows_r) {
            *xk = b[n + i];
        }
        self.reduced.solve(x);
        let qdd = &x[..n];

        // X = S⁻¹ J_R J_Dᵀ (S = J_R J_Rᵀ symmetric), T_D = Xᵀ: for the least-norm
        // multipliers below, and for the rows D near a rank drop.
        let J = &ws.jacobian;
        let row = |i: usize| &J[i * n..(i + 1) * n];
        let rows_r = &self.rows_r;
        for (a, &ra) in rows_r.iter().enumerate() {
            for (c, &rc) in rows_r.iter().enumerate() {
                self.gram.set(a, c, dot(row(ra), row(rc)));
            }
        }
        self.gram.factor();
        for (column, &d) in self.xt.chunks_exact_mut(r.max(1)).zip(&self.rows_d) {
            for (v, &ra) in column.iter_mut().zip(rows_r) {
                *v = dot(row(ra), row(d));
            }
            self.gram.solve(column);
        }
        let xt = &self.xt;

        // The redundant rows must be satisfied by q̈ too, relative to the accelerations
        // at play: those of the solution and those the forces alone would give,
        // max_j |Q_j| / M_jj (at a static equilibrium q̈ = 0 while the forces are not).
        let forced = info
            .mass_pattern
            .iter()
            .zip(&ws.mass_values)
            .filter(|(&(r, c), &m)| r == c && m != 0.0)
            .fold(0.0_f64, |a, (&(r, _), &m)| a.max((b[r as usize] / m).abs()));
        let (mut residual, mut scale) = (0.0_f64, 0.0_f64);
        for &d in &self.rows_d {
            let jd = row(d);
            residual = residual.max((dot(jd, qdd) - b[n + d]).abs());
            scale = scale.max(inf_norm(jd) * (inf_norm(qdd) + forced) + b[n + d].abs());
        }
        let bound = check.redundant_tolerance * scale.max(f64::MIN_POSITIVE);
        let strict = !residual.is_nan() && residual <= bound;
        if check.kept || !strict {
            // What each row of D adds to the rows R, w_d = J_d − T_d J_R, against the
            // rank rule, and the first-order bound of its residual.
            let rate = check.velocities.map_or(0.0, |v| {
                let gamma = b[n..].iter().fold(0.0_f64, |a, g| a.max(g.abs()));
                if v.speed > 0.0 {
                    gamma / v.speed
                } else {
                    0.0
                }
            });
            let mut consistent = !residual.is_nan();
            for (k, &d) in self.rows_d.iter().enumerate() {
                let jd = row(d);
                let t_d = &xt[k * r..(k + 1) * r];
                self.w.copy_from_slice(jd);
                for (&c, &ra) in t_d.iter().zip(rows_r) {
                    for (w, a) in self.w.iter_mut().zip(row(ra)) {
                        *w -= c * a;
                    }
                }
                let distance = dot(&self.w, &self.w).sqrt();
                let size = dot(jd, jd).sqrt();
                if check.kept && distance > INDEPENDENT * crate::RANK_PIVOT * size {
                    return Err(SplitFailure::Independent(residual));
                }
                if strict {
                    continue;
                }
                let allowance = check.velocities.map_or(0.0, |v| {
                    // v_d − T_d v_R and w_d less their round-off (32 ε times the sums of
                    // the magnitudes they are made of): a row dependent at every
                    // configuration has both at round-off and no allowance.
                    let (mut vr, mut v_size, mut w_size) = (v.residuals[d], 0.0, size);
                    for (c, &ra) in t_d.iter().zip(rows_r) {
                        vr -= c * v.residuals[ra];
                        v_size += c.abs() * v.residuals[ra].abs();
                        w_size += c.abs() * dot(row(ra), row(ra)).sqrt();
                    }
                    let rounding = 32.0 * f64::EPSILON;
                    let products = |i: usize| -> f64 {
                        row(i).iter().zip(v.qd).map(|(a, q)| (a * q).abs()).sum()
                    };
                    v_size += products(d)
                        + t_d
                            .iter()
                            .zip(rows_r)
                            .map(|(c, &ra)| c.abs() * products(ra))
                            .sum::<f64>();
                    let t1: f64 = t_d.iter().map(|c| c.abs()).sum();
                    let numerator = (vr.abs() - rounding * v_size).max(0.0);
                    2.0 * RANK_DROP_SAFETY * rate * (1.0 + t1) * numerator
                        / distance.max(rounding * w_size)
                });
                consistent &= (dot(jd, qdd) - b[n + d]).abs() <= bound + allowance;
            }
            if !consistent {
                return Err(SplitFailure::Inconsistent(residual));
            }
        }

        // Least-norm multipliers: λ = T (TᵀT)⁻¹ λ_R with T_D = Xᵀ and TᵀT = I + X Xᵀ.
        for a in 0..r {
            for c in 0..r {
                let xx: f64 = xt.chunks_exact(r).map(|col| col[a] * col[c]).sum();
                self.gram.set(a, c, f64::from(u8::from(a == c)) + xx);
            }
        }
        self.gram.factor();
        self.y.copy_from_slice(&x[n..]);
        self.gram.solve(&mut self.y);
        out[..n].copy_from_slice(qdd);
        for (k, &i) in rows_r.iter().enumerate() {
            out[n + i] = self.y[k];
        }
        for (k, &d) in self.rows_d.iter().enumerate() {
            out[n + d] = dot(&xt[k * r..(k + 1) * r], &self.y);
        }
        Ok(ratio)
    }
}

/// Writes $[Q; \gamma + s]$ (`s` the shift, when given) from `ws` into `b`.
#[inline]
fn right_hand_side(ws: &Workspace, shift: Option<&[f64]>, b: &mut [f64]) {
    let (q, gamma) = b.split_at_mut(ws.forces.len());
    q.copy_from_slice(&ws.forces);
    gamma.copy_from_slice(&ws.gamma);
    if let Some(shift) = shift {
        for (b, s) in gamma.iter_mut().zip(shift) {
            *b += s;
        }
    }
}

/// $\sum_i a_i b_i$.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The coordinates whose accelerations the augmented matrix in `lu` (filled, not yet
/// factored) leaves without a pivot under complete pivoting with the relative
/// tolerance `tol`: those a singular system does not determine.
fn free_coordinates(lu: &mut DenseLu, info: &Info, tol: f64) -> Vec<&'static str> {
    let dim = lu.dim();
    let a = lu.matrix_mut();
    let mut dense = vec![0.0; dim * dim];
    for i in 0..dim {
        for j in 0..dim {
            dense[i * dim + j] = a[(i, j)];
        }
    }
    let mut elim = Elimination::new(dim, dim);
    elim.load(&dense);
    let rank = elim.phase(0, dim, dim, tol).rank;
    let mut free: Vec<usize> = elim.cols[rank..]
        .iter()
        .copied()
        .filter(|&j| j < info.nq())
        .collect();
    free.sort_unstable();
    free.iter().map(|&j| info.coordinates[j].name).collect()
}

/// The pivot ratio of $J$'s kept rows below which [`DynamicsError::Singular`] names
/// them as nearly dependent. The augmented matrix's constraint pivots are of the order
/// of the squares of $J$'s: with $J$'s above $10^{-3}$ they are above $10^{-6}$, so a
/// failure of the rank tolerance ($10^{-10}$) needs a mass matrix conditioned worse
/// than $10^{-4}$ on the tangent space, and is named as the mass matrix's.
pub const NEARLY_DEPENDENT: f64 = 1e-3;

/// The constraints among `rows` (the rows of $J$ kept) that complete pivoting of the
/// row-equilibrated rows finds within [`NEARLY_DEPENDENT`] of dependence (the rows it
/// reaches after the last pivot above that ratio). Allocates (an error path).
fn nearly_dependent(ws: &Workspace, info: &Info, rows: &[usize]) -> Vec<&'static str> {
    let n = info.nq();
    let mh = info.nh();
    let mut kept = Vec::with_capacity(rows.len() * n);
    for &r in rows {
        kept.extend_from_slice(&ws.jacobian[r * n..(r + 1) * n]);
    }
    let mut elim = Elimination::new(rows.len(), n);
    elim.load(&kept);
    let well = elim.phase(0, rows.len(), rows.len(), NEARLY_DEPENDENT).rank;
    elim.rows[well..]
        .iter()
        .map(|&k| {
            let r = rows[k];
            if r < mh {
                info.holonomic[r].name
            } else {
                info.nonholonomic[r - mh].name
            }
        })
        .collect()
}

/// The cause clause of [`DynamicsError::Singular`]: the nearly dependent constraints
/// when there are any, the mass matrix otherwise.
fn singular_cause(jacobian_ratio: f64, nearly: &[&str], coordinates: &[&str]) -> String {
    if nearly.is_empty() {
        format!(
            "the mass matrix is singular on the constraint tangent space; {}",
            free_list(coordinates)
        )
    } else {
        near_singular_clause(jacobian_ratio, nearly)
    }
}

/// What a singular augmented matrix with the nearly dependent constraints `nearly`
/// (non-empty) means.
pub(crate) fn near_singular_clause(jacobian_ratio: f64, nearly: &[&str]) -> String {
    format!(
        "the constraints {nearly:?} are nearly dependent on the others there (pivot ratio \
         of `J` {jacobian_ratio:e}): a near-singular configuration, where the constraint \
         forces needed grow without bound (a change point or a lock of the mechanism, or a \
         state carried there by the integration's drift)"
    )
}

/// "coordinates involved: [..]", or why none are named.
fn free_list(coordinates: &[&str]) -> String {
    if coordinates.is_empty() {
        "no single coordinate is undetermined (the singular direction mixes accelerations and multipliers)".to_owned()
    } else {
        format!("coordinates involved: {coordinates:?}")
    }
}

/// Calls `set(i, j, v)` for the non-zero entries of
/// $\begin{bmatrix}M & J_R^\mathsf{T}\\ J_R & 0\end{bmatrix}$, with $J_R$ the rows
/// of $J$ that `slot` places (row `i` at `slot[i]`, dropped when `usize::MAX`; all rows
/// in order when `None`).
fn augmented_entries(
    info: &Info,
    ws: &Workspace,
    slot: Option<&[usize]>,
    mut set: impl FnMut(usize, usize, f64),
) {
    let n = info.nq();
    let mh = info.nh();
    for (&(r, c), &v) in info.mass_pattern.iter().zip(&ws.mass_values) {
        set(r as usize, c as usize, v);
    }
    // Position of constraint row `i` in the reduced system, if kept.
    let slot = |i: usize| -> Option<usize> {
        match slot {
            None => Some(i),
            Some(slot) => Some(slot[i]).filter(|&k| k != usize::MAX),
        }
    };
    let blocks = [
        (info.holonomic_pattern, &ws.cq_values, 0),
        (info.nonholonomic_pattern, &ws.g_values, mh),
    ];
    for (pattern, values, offset) in blocks {
        for (&(r, c), &v) in pattern.iter().zip(values.iter()) {
            if let Some(k) = slot(r as usize + offset) {
                set(n + k, c as usize, v);
                set(c as usize, n + k, v);
            }
        }
    }
}

/// Writes the augmented matrix with the rows of $J$ that `slot` places into `lu` (see
/// [`augmented_entries`]).
fn fill_dense(lu: &mut DenseLu, info: &Info, ws: &Workspace, slot: Option<&[usize]>) {
    zero_dense(lu);
    let mut a = lu.matrix_mut();
    augmented_entries(info, ws, slot, |i, j, v| a[(i, j)] = v);
}

/// Zeroes the matrix of `lu`.
fn zero_dense(lu: &mut DenseLu) {
    let dim = lu.dim();
    let mut a = lu.matrix_mut();
    for j in 0..dim {
        for i in 0..dim {
            a[(i, j)] = 0.0;
        }
    }
}

/// Writes the augmented matrix into the row-major `lu`.
fn fill_small(lu: &mut SmallLu, info: &Info, ws: &Workspace) {
    let dim = lu.dim();
    let a = lu.matrix_mut();
    a.fill(0.0);
    augmented_entries(info, ws, None, |i, j, v| a[i * dim + j] = v);
}
