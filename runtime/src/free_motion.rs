//! Free motion of constrained systems (docs/theory.md §redundant-coordinates, the second seed paper \[S2\]: Chen,
//! Wu & Mei 2016, "Free motion of holonomic system with redundant coordinates").
//!
//! Input: a [`Mechanism`] with a regular mass matrix $A = M$, a [`Workspace`], states
//! $(t, q, \dot q)$ and a choice of applied forces ([`AppliedForces`]). Output: the
//! explicit multiplier formula of \[S2\] and the free-motion residual, in the sign of
//! \[S2\] (docs/theory.md §redundant-multipliers):
//! $$A\ddot q = h + F^\mathsf{T}\lambda^{[\text{S2}]},\qquad W = F A^{-1} F^\mathsf{T},\qquad
//!   w = c + F A^{-1} h,\qquad \lambda^{[\text{S2}]} = -W^{-1} w,$$
//! with $F = J = [C_q; G]$, $c = -\gamma$ (for holonomic rows
//! $c = C_{tt} + 2C_{qt}\dot q + (C_q\dot q)_q\dot q = -\gamma_h$), and
//! $h = Q + \partial T/\partial q - T_{\dot q q}\dot q - T_{\dot q t}$, which is exactly
//! the generated [`Mechanism::forces`]. The applied part $Q$ is
//! [`Mechanism::applied_forces`]; $h^0 = h - Q$ is fixed by $T$ and $V$, so
//! $w = w^0 + K Q$ with $w^0 = c + F A^{-1} h^0$ and $K = F A^{-1}$ (affine in $Q$).
//! $\lambda^{[\text{S1}]} = -\lambda^{[\text{S2}]}$ is what [`Dynamics`](crate::Dynamics) returns.
//!
//! The motion is **free** (all constraint forces $R = F^\mathsf{T}\lambda^{[\text{S2}]}$ vanish)
//! exactly where $w = 0$ (S2-18): $g$ conditions, one per constraint. When $W$ is
//! singular (redundant constraints) $\lambda^{[\text{S2}]} = -W^+ w$ is the minimum-norm
//! multiplier, and still $\lambda = 0 \iff w = 0$.
//!
//! Principal items:
//! - [`FreeMotion::evaluate`]: everything of docs/theory.md §redundant-multipliers at one state ([`FreeMotionPoint`]);
//! - [`FreeMotion::check_along`]: is a motion free along a trajectory
//!   ([`FreeMotionReport`]);
//! - [`FreeMotion::free_forces`]: the applied forces that make the motion free
//!   ([`ForceDesign`]: minimum norm, the would-be constraint forces, or restricted to
//!   chosen components);
//! - [`FreeMotion::solve_parameter`]: the member of a one-parameter family of models
//!   (constraints, inertia or forces) for which the motion is free;
//! - [`Forced`]: a model whose declared applied forces are replaced by a function of the
//!   state, to simulate the designed motion.
//!
//! Invariant: [`FreeMotion::evaluate`] does not allocate except on a singular $W$.
//! A singular mass matrix (Euler parameters, docs/theory.md §singular-mass) is an error: use the
//! augmented solve ([`ReactionAnalysis`](crate::ReactionAnalysis)) and check
//! $\lambda \equiv 0$ there.

mod design;
mod forced;
mod sym;

pub use design::{ForceDesign, ForceSolution, ParameterSearch, ParameterSolution, Sample};
pub use forced::Forced;

use faer::Mat;

use crate::linalg::dense::DenseLu;
use crate::linalg::inf_norm;
use crate::workspace::{check_finite, check_len, check_state, EvalError, Quantity, Workspace};
use crate::{Info, Mechanism};

/// Which applied forces $Q$ enter $h = h^0 + Q$.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum AppliedForces<'a> {
    /// The model's own ([`Mechanism::applied_forces`]): $h$ = [`Mechanism::forces`].
    #[default]
    AsModeled,
    /// None: $Q = 0$, the forces of \[S2\]'s examples before the design (V1, V3).
    Without,
    /// These instead of the model's (length $n$).
    Replaced(&'a [f64]),
    /// These on top of the model's (length $n$).
    Added(&'a [f64]),
}

/// Tolerances of [`FreeMotion`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FreeMotionParams {
    /// Pivot ratio of the mass matrix below which it counts as singular.
    pub mass_tolerance: f64,
    /// Eigenvalues of $W$ (and of $K_S K_S^\mathsf{T}$) below this fraction of the largest
    /// count as zero: the rank of the constraints, and of a force design.
    pub rank_tolerance: f64,
    /// Relative size of $|w|$ (against the terms it is computed from) below which a force
    /// design counts as exact.
    pub residual_tolerance: f64,
}

impl Default for FreeMotionParams {
    fn default() -> Self {
        Self {
            mass_tolerance: 1e-12,
            rank_tolerance: 1e-12,
            residual_tolerance: 1e-10,
        }
    }
}

/// Errors of the free-motion analysis.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FreeMotionError {
    /// \[S2\] needs $\det A \ne 0$.
    #[error("mass matrix of `{model}` singular at t = {t:?} (pivot ratio {ratio:e}): the explicit multiplier formula needs a regular mass matrix; use the augmented solve and check that the multipliers vanish")]
    SingularMass {
        /// The model.
        model: &'static str,
        /// Time.
        t: f64,
        /// Smallest / largest pivot.
        ratio: f64,
    },
    /// A force component outside `0..n`.
    #[error("force component {index} out of range for `{model}` with {n} coordinates")]
    Component {
        /// The model.
        model: &'static str,
        /// The index given.
        index: usize,
        /// Number of coordinates.
        n: usize,
    },
    /// A parameter index outside the model's parameters.
    #[error("parameter {index} out of range for `{model}` with {count} parameters")]
    Parameter {
        /// The model.
        model: &'static str,
        /// The index given.
        index: usize,
        /// Number of parameters.
        count: usize,
    },
    /// An empty or non-finite search interval, or no grid.
    #[error("invalid parameter search on [{lo}, {hi}] with {grid} grid points: expected finite lo < hi and at least 2 points")]
    Search {
        /// Lower end.
        lo: f64,
        /// Upper end.
        hi: f64,
        /// Grid points.
        grid: usize,
    },
    /// A parameter search without sample states.
    #[error("parameter search needs at least one sample state")]
    NoSamples,
    /// Evaluation of the model.
    #[error(transparent)]
    Eval(#[from] EvalError),
}

/// Everything of docs/theory.md §redundant-multipliers at one state, in the sign of \[S2\].
#[derive(Clone, Debug, PartialEq)]
#[allow(non_snake_case)]
pub struct FreeMotionPoint {
    /// Time.
    pub t: f64,
    /// The applied forces $Q$ used.
    pub applied: Vec<f64>,
    /// $h = h^0 + Q$ (length $n$).
    pub h: Vec<f64>,
    /// $c = -\gamma$ (length $m$).
    pub c: Vec<f64>,
    /// $K = F A^{-1}$, row-major $m \times n$.
    pub K: Vec<f64>,
    /// $W = F A^{-1} F^\mathsf{T}$, row-major $m \times m$.
    pub W: Vec<f64>,
    /// $w^0 = c + F A^{-1} h^0$, the residual without applied forces.
    pub base_residual: Vec<f64>,
    /// $w = w^0 + K Q$: the free-motion residual, one per constraint.
    pub residual: Vec<f64>,
    /// $\lambda^{[\text{S2}]} = -W^+ w$.
    pub lambda_s2: Vec<f64>,
    /// $\ddot q = A^{-1}(h + F^\mathsf{T}\lambda^{[\text{S2}]})$.
    pub qdd: Vec<f64>,
    /// $R = F^\mathsf{T}\lambda^{[\text{S2}]}$, the generalized constraint force.
    pub reaction: Vec<f64>,
    /// Numerical rank of $W$ (the number of independent constraints).
    pub rank: usize,
    /// $\lVert W\lambda^{[\text{S2}]} + w\rVert_\infty$: zero unless the redundant constraints
    /// contradict each other.
    pub consistency: f64,
}

impl FreeMotionPoint {
    /// Zeroed for the model described by `info`.
    #[must_use]
    pub fn new(info: &Info) -> Self {
        let (n, m) = (info.nq(), info.nh() + info.nnh());
        Self {
            t: 0.0,
            applied: vec![0.0; n],
            h: vec![0.0; n],
            c: vec![0.0; m],
            K: vec![0.0; m * n],
            W: vec![0.0; m * m],
            base_residual: vec![0.0; m],
            residual: vec![0.0; m],
            lambda_s2: vec![0.0; m],
            qdd: vec![0.0; n],
            reaction: vec![0.0; n],
            rank: m,
            consistency: 0.0,
        }
    }

    /// The multipliers in the sign of docs/theory.md §sign, $\lambda = -\lambda^{[\text{S2}]}$.
    #[must_use]
    pub fn lambda(&self) -> Vec<f64> {
        self.lambda_s2.iter().map(|l| -l).collect()
    }

    /// $\lVert w\rVert_\infty$.
    #[must_use]
    pub fn max_residual(&self) -> f64 {
        inf_norm(&self.residual)
    }
}

/// Whether a motion is free along a set of states.
#[derive(Clone, Debug, PartialEq)]
pub struct FreeMotionReport {
    /// Number of states checked.
    pub samples: usize,
    /// $\max |w_\beta|$ per constraint (holonomic first).
    pub max_residual: Vec<f64>,
    /// $\max \lVert\lambda\rVert_\infty$.
    pub max_lambda: f64,
    /// $\max \lVert R\rVert_\infty$.
    pub max_reaction: f64,
    /// Time of the largest $\lVert R\rVert_\infty$.
    pub worst_t: f64,
    /// The tolerance on $\lVert R\rVert_\infty$ the verdict used.
    pub tolerance: f64,
    /// $\lVert R\rVert_\infty \le$ `tolerance` at every state (docs/theory.md §free-motion-analysis step 2).
    pub free: bool,
}

/// Scratch for the free-motion analysis of one model.
#[derive(Debug)]
pub struct FreeMotion {
    params: FreeMotionParams,
    info: &'static Info,
    lu: DenseLu,
    /// $A^{-1}[F^\mathsf{T} \mid h^0 \mid Q]$, $n \times (m + 2)$.
    rhs: Mat<f64>,
    model_applied: Vec<f64>,
    eigen: sym::Eigen,
}

impl FreeMotion {
    /// Scratch for the model described by `info`.
    #[must_use]
    pub fn new(info: &'static Info, params: FreeMotionParams) -> Self {
        let (n, m) = (info.nq(), info.nh() + info.nnh());
        Self {
            params,
            info,
            lu: DenseLu::new(n, m + 2),
            rhs: Mat::zeros(n, m + 2),
            model_applied: vec![0.0; n],
            eigen: sym::Eigen::new(m),
        }
    }

    /// The tolerances.
    #[must_use]
    pub fn params(&self) -> &FreeMotionParams {
        &self.params
    }

    /// The explicit multipliers and the free-motion residual at $(q, \dot q, t)$
    /// (docs/theory.md §redundant-multipliers). $q$ need not satisfy the constraints: the formulas hold
    /// pointwise.
    ///
    /// # Errors
    /// Non-finite model values or wrong lengths ([`FreeMotionError::Eval`]), a singular
    /// mass matrix.
    #[allow(clippy::too_many_arguments, clippy::many_single_char_names)]
    pub fn evaluate<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &mut Workspace,
        t: f64,
        q: &[f64],
        qd: &[f64],
        applied: AppliedForces<'_>,
        out: &mut FreeMotionPoint,
    ) -> Result<(), FreeMotionError> {
        let info = self.info;
        let (n, m) = (info.nq(), info.nh() + info.nnh());
        check_state(info, t, q, Some(qd))?;
        ws.eval_mass_and_forces(mech, t, q, qd)?;
        ws.eval_jacobian(mech, t, q)?;
        ws.eval_gamma(mech, t, q, qd)?;
        mech.applied_forces(t, q, qd, &mut self.model_applied);
        check_finite(Quantity::Forces, t, &self.model_applied)?;
        match applied {
            AppliedForces::AsModeled => out.applied.copy_from_slice(&self.model_applied),
            AppliedForces::Without => out.applied.fill(0.0),
            AppliedForces::Replaced(x) => {
                check_len(Quantity::Forces, x, n)?;
                out.applied.copy_from_slice(x);
            }
            AppliedForces::Added(x) => {
                check_len(Quantity::Forces, x, n)?;
                for ((o, a), b) in out.applied.iter_mut().zip(&self.model_applied).zip(x) {
                    *o = a + b;
                }
            }
        }
        check_finite(Quantity::Forces, t, &out.applied)?;
        let forces = ws.forces();
        let jac = ws.jacobian();
        let row = |k: usize| &jac[k * n..(k + 1) * n];

        // A X = [Fᵀ | h⁰ | Q].
        {
            let mut a = self.lu.matrix_mut();
            for j in 0..n {
                for i in 0..n {
                    a[(i, j)] = 0.0;
                }
            }
            for (&(r, c), &v) in info.mass_pattern.iter().zip(&ws.mass_values) {
                a[(r as usize, c as usize)] = v;
            }
        }
        let ratio = self.lu.factor().ratio();
        if ratio.is_nan() || ratio <= self.params.mass_tolerance {
            return Err(FreeMotionError::SingularMass {
                model: info.name,
                t,
                ratio,
            });
        }
        for i in 0..n {
            for k in 0..m {
                self.rhs[(i, k)] = jac[k * n + i];
            }
            self.rhs[(i, m)] = forces[i] - self.model_applied[i];
            self.rhs[(i, m + 1)] = out.applied[i];
        }
        self.lu.solve_in_place(self.rhs.as_mut());
        let x = &self.rhs;

        out.t = t;
        for (hi, ((f, a), qa)) in out
            .h
            .iter_mut()
            .zip(forces.iter().zip(&self.model_applied).zip(&out.applied))
        {
            *hi = f - a + qa;
        }
        for b in 0..m {
            out.c[b] = -ws.gamma()[b];
            for s in 0..n {
                out.K[b * n + s] = x[(s, b)];
            }
            for k in 0..m {
                out.W[b * m + k] = (0..n).map(|s| row(b)[s] * x[(s, k)]).sum();
            }
            let (jh0, jq) = (0..n).fold((0.0, 0.0), |(p, r), s| {
                (p + row(b)[s] * x[(s, m)], r + row(b)[s] * x[(s, m + 1)])
            });
            out.base_residual[b] = out.c[b] + jh0;
            out.residual[b] = out.base_residual[b] + jq;
        }
        // λ = −W⁺ w (W⁻¹ when the constraints are independent).
        self.eigen.load(&out.W);
        out.rank = self.eigen.pinv_solve(
            &out.residual,
            self.params.rank_tolerance,
            &mut out.lambda_s2,
        );
        for l in &mut out.lambda_s2 {
            *l = -*l;
        }
        out.consistency = (0..m)
            .map(|b| {
                let wl: f64 = (0..m).map(|k| out.W[b * m + k] * out.lambda_s2[k]).sum();
                (wl + out.residual[b]).abs()
            })
            .fold(0.0, f64::max);
        for s in 0..n {
            out.qdd[s] = x[(s, m)]
                + x[(s, m + 1)]
                + (0..m).map(|k| x[(s, k)] * out.lambda_s2[k]).sum::<f64>();
            out.reaction[s] = (0..m).map(|k| row(k)[s] * out.lambda_s2[k]).sum();
        }
        check_finite(Quantity::Multipliers, t, &out.lambda_s2)?;
        check_finite(Quantity::Accelerations, t, &out.qdd)?;
        Ok(())
    }

    /// Whether the motion through the given states is free: $w$, $\lambda$ and $R$ at
    /// each, with the verdict $\lVert R\rVert_\infty \le$ `tolerance` everywhere.
    ///
    /// # Errors
    /// The first failure of [`FreeMotion::evaluate`].
    pub fn check_along<'s, M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &mut Workspace,
        samples: impl IntoIterator<Item = (f64, &'s [f64], &'s [f64])>,
        applied: AppliedForces<'_>,
        tolerance: f64,
    ) -> Result<FreeMotionReport, FreeMotionError> {
        let m = self.info.nh() + self.info.nnh();
        let mut point = FreeMotionPoint::new(self.info);
        let mut report = FreeMotionReport {
            samples: 0,
            max_residual: vec![0.0; m],
            max_lambda: 0.0,
            max_reaction: 0.0,
            worst_t: f64::NAN,
            tolerance,
            free: true,
        };
        for (t, q, qd) in samples {
            self.evaluate(mech, ws, t, q, qd, applied, &mut point)?;
            report.samples += 1;
            for (r, w) in report.max_residual.iter_mut().zip(&point.residual) {
                *r = r.max(w.abs());
            }
            report.max_lambda = report.max_lambda.max(inf_norm(&point.lambda_s2));
            let r = inf_norm(&point.reaction);
            if r > report.max_reaction || report.worst_t.is_nan() {
                report.max_reaction = report.max_reaction.max(r);
                report.worst_t = t;
            }
        }
        report.free = report.max_reaction <= tolerance;
        Ok(report)
    }
}
