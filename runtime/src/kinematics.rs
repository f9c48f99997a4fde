//! Kinematic analysis with a coordinate partition (docs/theory.md §partitioning, Algorithm K).
//!
//! - **K1, position** ([`Kinematics::position`]): Newton–Raphson on the dependent
//!   coordinates $\beta$ with $p = [\eta; \gamma]$ fixed,
//!   $C_\beta\,\Delta\beta = -C(\beta, p, t)$, until
//!   $\lVert\Delta\beta\rVert_\infty \le \varepsilon\lVert q\rVert_\infty$ and every
//!   constraint is within $\varepsilon\lVert q\rVert_\infty$ of its surface,
//!   $|C_i| \le \varepsilon\,\lVert (C_q)_i\rVert_\infty \lVert q\rVert_\infty$ (the scale
//!   model of [`crate::scale`]: the outcome does not depend on units).
//! - **K2, velocity** ([`Kinematics::velocity`]): the dependent velocities from (E34),
//!   $J_d [\dot\beta; \dot\eta] = -J_\gamma \dot\gamma - [C_t; g]$.
//! - **Monitor** ([`Kinematics::monitor`]): recompute the pivot ratios of the current
//!   partition and re-partition (Algorithm P) when they deteriorate; re-partitions are
//!   counted.
//!
//! Input: a [`Workspace`] of the same model, $(q, t)$ and $\dot q$. Output: $q$ and
//! $\dot q$ corrected in place. The [`Kinematics`] struct holds the partition (a cache)
//! and scratch, never the state. Invariant: after [`Kinematics::new`], K1, K2 and the
//! monitor do not allocate unless they re-partition.

use crate::linalg::dense::DenseLu;
use crate::linalg::elimination::Elimination;
use crate::linalg::inf_norm;
use crate::partition::{
    compute_with, condition_with, Condition, Partition, PartitionError, PartitionParams,
    Preferences,
};
use crate::scale;
use crate::workspace::{check_same_model, check_state, EvalError, Workspace};
use crate::{Info, Mechanism};

/// Tuning of the Newton iteration K1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonParams {
    /// Relative tolerance $\varepsilon$ on the step and on the residual.
    pub tolerance: f64,
    /// Iteration cap.
    pub max_iterations: usize,
}

impl Default for NewtonParams {
    fn default() -> Self {
        Self {
            tolerance: 1e-12,
            max_iterations: 25,
        }
    }
}

/// Tuning of [`Kinematics`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct KinematicsParams {
    /// Newton iteration K1.
    pub newton: NewtonParams,
    /// Algorithm P and its monitor.
    pub partition: PartitionParams,
}

/// Statistics of one K1 solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonStats {
    /// Newton updates performed (0 when the guess already satisfies the constraints).
    pub iterations: usize,
    /// Final $\lVert C\rVert_\infty$.
    pub residual: f64,
    /// Last $\lVert\Delta\beta\rVert_\infty$.
    pub step: f64,
}

/// Errors of kinematic analysis.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum KinematicsError {
    /// Newton did not converge.
    #[error("position analysis failed at t = {t:?} after {iterations} iterations: residual {residual:e}, {}", if violated.is_empty() { "every constraint within the tolerance but the Newton step did not settle".to_owned() } else { format!("violated constraints {violated:?}") })]
    NewtonFailed {
        /// Time.
        t: f64,
        /// Iterations performed.
        iterations: usize,
        /// Final $\lVert C\rVert_\infty$.
        residual: f64,
        /// Constraints whose residual exceeds the tolerance.
        violated: Vec<&'static str>,
    },
    /// $C_\beta$ became singular during Newton.
    #[error("dependent Jacobian `C_beta` is singular at t = {t:?}, iteration {iteration} (pivot ratio {ratio:e}); re-partition")]
    SingularDependent {
        /// Time.
        t: f64,
        /// Iteration at which it happened.
        iteration: usize,
        /// Smallest / largest pivot.
        ratio: f64,
    },
    /// $J_d$ is singular in the velocity solve.
    #[error("dependent velocity Jacobian `J_d` is singular at t = {t:?} (pivot ratio {ratio:e}); re-partition")]
    SingularVelocity {
        /// Time.
        t: f64,
        /// Smallest / largest pivot.
        ratio: f64,
    },
    /// Algorithm P failed.
    /// K1 converged, but to another solution branch than the reference state's: the
    /// sign of $\det J_d$ differs from the reference (see
    /// [`Kinematics::dependent_sign`]), or the correction of the guess exceeds the
    /// predicted motion. Detected by the simulation: the guess was extrapolated too far.
    #[error("position analysis at t = {t:?} converged on another solution branch; a shorter step is needed")]
    BranchSwitch {
        /// Time.
        t: f64,
        /// Newton iterations performed.
        iterations: usize,
        /// Final $\lVert C\rVert_\infty$.
        residual: f64,
    },
    #[error(transparent)]
    Partition(#[from] PartitionError),
    /// Evaluation failed.
    #[error(transparent)]
    Eval(#[from] EvalError),
}

/// Pivot ratio below which a dense dependent block counts as singular.
const SINGULAR_RATIO: f64 = 1e-14;

/// Kinematic analysis (Algorithms P and K) for one model.
#[derive(Debug)]
pub struct Kinematics {
    pub(crate) params: KinematicsParams,
    pub(crate) elim: Elimination,
    lu_h: DenseLu,
    lu_d: DenseLu,
    pub(crate) partition: Option<Partition>,
    repartitions: usize,
    history: Vec<f64>,
    rhs: Vec<f64>,
    sign: f64,
    info: &'static Info,
}

impl Kinematics {
    /// Scratch for the model described by `info`.
    #[must_use]
    pub fn new(info: &'static Info, params: KinematicsParams) -> Self {
        let (n, mh, m) = (info.nq(), info.nh(), info.nh() + info.nnh());
        Self {
            params,
            elim: Elimination::new(m, n),
            lu_h: DenseLu::new(mh, 1),
            lu_d: DenseLu::new(m, 1),
            partition: None,
            repartitions: 0,
            history: Vec::with_capacity(params.newton.max_iterations + 1),
            rhs: vec![0.0; m],
            sign: 0.0,
            info,
        }
    }

    /// The tuning parameters.
    #[must_use]
    pub fn params(&self) -> &KinematicsParams {
        &self.params
    }

    /// The current partition, if any.
    #[must_use]
    pub fn partition(&self) -> Option<&Partition> {
        self.partition.as_ref()
    }

    /// Replaces the partition (not counted as a re-partition).
    pub fn set_partition(&mut self, partition: Partition) {
        self.partition = Some(partition);
    }

    /// Number of re-partitions (partitions computed while one already existed).
    #[must_use]
    pub fn repartitions(&self) -> usize {
        self.repartitions
    }

    /// $\lVert C\rVert_\infty$ after each iteration of the last K1 solve (the first
    /// entry is the initial residual).
    /// The sign of $\det J_d$ (E34) at the last K2, in the column order of the current
    /// partition ($0$ before any K2 or when singular).
    ///
    /// Along a motion with a fixed partition $J_d$ stays non-singular, so its
    /// determinant keeps its sign; the mirror-image assembly of a loop (the other root
    /// of K1 for the same $p$) lies across the singular set $\det C_\beta = 0$ and has
    /// the opposite sign for the usual fold between two branches. A change of sign
    /// between two nearby states therefore means that K1 jumped branches or the
    /// motion crossed a singular configuration: either way the step was too long.
    #[must_use]
    pub fn dependent_sign(&self) -> f64 {
        self.sign
    }

    /// $\lVert C\rVert_\infty$ before each iteration of the last K1
    /// ([`position`](Self::position)) and after the last one; empty when that call failed
    /// before evaluating $C$.
    #[must_use]
    pub fn residual_history(&self) -> &[f64] {
        &self.history
    }

    /// Runs Algorithm P at $(q, t)$ and makes the result current.
    pub fn repartition<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &mut Workspace,
        t: f64,
        q: &[f64],
    ) -> Result<&Partition, PartitionError> {
        self.repartition_with(mech, ws, t, q, Preferences::default())
    }

    pub(crate) fn repartition_with<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &mut Workspace,
        t: f64,
        q: &[f64],
        prefs: Preferences<'_>,
    ) -> Result<&Partition, PartitionError> {
        check_same_model(self.info, ws.info())?;
        let p = compute_with(
            &mut self.elim,
            mech,
            ws,
            t,
            q,
            prefs,
            &self.params.partition,
        )?;
        if self.partition.is_some() {
            self.repartitions += 1;
        }
        Ok(self.partition.insert(p))
    }

    fn ensure_partition<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &mut Workspace,
        t: f64,
        q: &[f64],
    ) -> Result<(), PartitionError> {
        if self.partition.is_none() {
            self.repartition(mech, ws, t, q)?;
        }
        Ok(())
    }

    /// Pivot ratios of the current partition at $(q, t)$ (partitions first if there is
    /// no partition yet).
    pub fn condition<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &mut Workspace,
        t: f64,
        q: &[f64],
    ) -> Result<Condition, KinematicsError> {
        check_same_model(self.info, ws.info())?;
        self.ensure_partition(mech, ws, t, q)?;
        let Self {
            elim, partition, ..
        } = self;
        let p = partition.as_ref().expect("partition ensured above");
        Ok(condition_with(elim, p, mech, ws, t, q)?)
    }

    /// The condition monitor: re-partitions when the pivot ratios fell below
    /// `deterioration` × their reference values. Returns whether it re-partitioned.
    pub fn monitor<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &mut Workspace,
        t: f64,
        q: &[f64],
    ) -> Result<bool, KinematicsError> {
        let now = self.condition(mech, ws, t, q)?;
        let p = self
            .partition
            .as_ref()
            .expect("partition ensured by condition");
        if p.is_deteriorated(now, &self.params.partition) {
            self.repartition(mech, ws, t, q)?;
            Ok(true)
        } else {
            Ok(false)
        }
    }

    /// K1: Newton–Raphson on $\beta$ with $p$ fixed; corrects `q` in place.
    pub fn position<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &mut Workspace,
        t: f64,
        q: &mut [f64],
    ) -> Result<NewtonStats, KinematicsError> {
        let info = ws.info();
        // The history describes this call even when it fails before the first residual.
        self.history.clear();
        check_same_model(self.info, info)?;
        check_state(info, t, q, None)?;
        self.ensure_partition(mech, ws, t, q)?;
        let n = info.nq();
        let Self {
            params,
            lu_h,
            partition,
            history,
            rhs,
            ..
        } = self;
        let p = partition.as_ref().expect("partition ensured above");
        let (beta, rows) = (&p.dependent, &p.rows);
        if lu_h.dim() != rows.len() {
            // Redundant rows dropped: a smaller block (allocates at a re-partition only).
            *lu_h = DenseLu::new(rows.len(), 1);
        }
        let tol = params.newton.tolerance;
        history.clear();
        // C and C_q at the iterate (one fused evaluation): the residual, the scale of
        // its test, and the first Newton matrix.
        ws.eval_constraints_with_jacobian(mech, t, q)?;
        ws.scatter_jacobian();
        let mut residual = inf_norm(&ws.c);
        history.push(residual);
        let met = |ws: &Workspace, q: &[f64]| {
            scale::all_met(&ws.c, &ws.jacobian, n, tol, scale::coordinate_size(q))
        };
        if met(ws, q) {
            return Ok(NewtonStats {
                iterations: 0,
                residual,
                step: 0.0,
            });
        }
        let mut step = f64::INFINITY;
        let mut previous = residual;
        for iteration in 1..=params.newton.max_iterations {
            if iteration > 1 {
                ws.eval_jacobian(mech, t, q)?;
            }
            {
                let mut a = lu_h.matrix_mut();
                for (r, &i) in rows.iter().enumerate() {
                    for (k, &j) in beta.iter().enumerate() {
                        a[(r, k)] = ws.jacobian[i * n + j];
                    }
                }
            }
            let ratio = lu_h.factor().ratio();
            if ratio.is_nan() || ratio <= SINGULAR_RATIO {
                return Err(KinematicsError::SingularDependent {
                    t,
                    iteration,
                    ratio,
                });
            }
            let dx = &mut rhs[..rows.len()];
            for (v, &i) in dx.iter_mut().zip(rows) {
                *v = -ws.c[i];
            }
            lu_h.solve_vec(dx);
            step = 0.0;
            for (k, &j) in beta.iter().enumerate() {
                q[j] += dx[k];
                step = step.max(dx[k].abs());
            }
            ws.eval_constraints(mech, t, q)?;
            residual = inf_norm(&ws.c);
            if history.len() < history.capacity() {
                history.push(residual);
            }
            // The row norms of the last C_q (one update old) scale the residual test.
            // Stagnation at the rounding floor also ends the iteration (see
            // `scale::at_rounding_floor`).
            let stagnant = residual >= 0.5 * previous
                && scale::at_rounding_floor(&ws.c, &ws.jacobian, n, scale::coordinate_size(q));
            previous = residual;
            if (step <= tol * scale::coordinate_size(q) && met(ws, q)) || stagnant {
                return Ok(NewtonStats {
                    iterations: iteration,
                    residual,
                    step,
                });
            }
            if !residual.is_finite() {
                break;
            }
        }
        let violated: Vec<&'static str> =
            scale::unmet(&ws.c, &ws.jacobian, n, tol, scale::coordinate_size(q))
                .map(|i| info.holonomic[i].name)
                .collect();
        // Every constraint met, only the updates still moving: a root where the block
        // of the dependent coordinates is singular (a pendulum in Cartesian
        // coordinates hanging straight down with `y` held: `x² = 0`, which Newton
        // halves at each update). The positions meet the constraints to the tolerance,
        // which is what is asked of them; they are determined there only to about the
        // square root of it, which no further update changes.
        if violated.is_empty() && residual.is_finite() {
            return Ok(NewtonStats {
                iterations: history.len() - 1,
                residual,
                step,
            });
        }
        Err(KinematicsError::NewtonFailed {
            t,
            iterations: history.len() - 1,
            residual,
            violated,
        })
    }

    /// K2: dependent velocities $[\dot\beta; \dot\eta]$ from (E34), keeping
    /// $\dot\gamma$; corrects `qd` in place.
    pub fn velocity<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &mut Workspace,
        t: f64,
        q: &[f64],
        qd: &mut [f64],
    ) -> Result<(), KinematicsError> {
        let info = ws.info();
        check_same_model(self.info, info)?;
        check_state(info, t, q, Some(qd))?;
        self.ensure_partition(mech, ws, t, q)?;
        let (n, mh) = (info.nq(), info.nh());
        let m = mh + info.nnh();
        ws.eval_jacobian(mech, t, q)?;
        ws.eval_rates(mech, t, q)?;
        let Self {
            lu_d,
            partition,
            rhs,
            sign,
            ..
        } = self;
        let p = partition.as_ref().expect("partition ensured above");
        let dep = || p.dependent.iter().chain(&p.eta);
        // The rows of J_d: the holonomic rows of β (all unless redundant ones were
        // dropped), then the non-holonomic ones.
        let rows = || p.rows.iter().copied().chain(mh..m);
        let md = p.rows.len() + (m - mh);
        if lu_d.dim() != md {
            *lu_d = DenseLu::new(md, 1);
        }
        {
            let mut a = lu_d.matrix_mut();
            for (r, i) in rows().enumerate() {
                for (k, &j) in dep().enumerate() {
                    a[(r, k)] = ws.jacobian[i * n + j];
                }
            }
        }
        for (r, i) in rhs[..md].iter_mut().zip(rows()) {
            let c = if i < mh { ws.ct[i] } else { ws.bias[i - mh] };
            let row = &ws.jacobian[i * n..(i + 1) * n];
            *r = -c - p.independent.iter().map(|&j| row[j] * qd[j]).sum::<f64>();
        }
        let ratio = lu_d.factor().ratio();
        *sign = lu_d.det_sign();
        if ratio.is_nan() || ratio <= SINGULAR_RATIO {
            return Err(KinematicsError::SingularVelocity { t, ratio });
        }
        lu_d.solve_vec(&mut rhs[..md]);
        for (k, j) in dep().enumerate() {
            qd[*j] = rhs[k];
        }
        Ok(())
    }
}
