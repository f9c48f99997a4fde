//! Constraint reactions: multipliers and generalized constraint forces, per named
//! constraint, at a state or along a trajectory.
//!
//! Input: a [`Mechanism`], a [`Workspace`] and states $(t, q, \dot q)$. Output:
//! [`Reactions`], holding $\ddot q$, $\lambda = [\lambda_h; \lambda_{nh}]$ from the
//! augmented solve of [`Dynamics`] and, for every constraint $k$, its own generalized
//! force $-J_k^\mathsf{T}\lambda_k$ (length $n$). Summed, these give
//! $-C_q^\mathsf{T}\lambda_h$, $-G^\mathsf{T}\lambda_{nh}$ and the total
//! $F^c = -J^\mathsf{T}\lambda$.
//!
//! **Signs.** docs/theory.md §sign: $M\ddot q + C_q^\mathsf{T}\lambda_h + G^\mathsf{T}\lambda_{nh}
//! = Q$, so constraint $k$ pushes on the system with $-J_k^\mathsf{T}\lambda_k$. The
//! second seed paper (\[S2\], Chen, Wu & Mei 2016) writes the multiplier term on the
//! right-hand side, $\lambda^{[\text{S2}]} = -\lambda$, and its constraint force
//! $R = F^\mathsf{T}\lambda^{[\text{S2}]}$ is the same vector as ours
//! ([`Reactions::lambda_s2`]).
//!
//! **Redundant constraints.** When $J$ is rank deficient, [`Dynamics`] returns the
//! multipliers of least 2-norm among all that produce the same total force; the
//! constraints it found dependent are listed in [`Reactions::redundant`] (never hidden:
//! the individual reactions of a statically indeterminate system are not determined by
//! rigid-body dynamics, and the minimum-norm split is a choice).
//!
//! Invariant: [`ReactionAnalysis::evaluate`] does not allocate on the dense and sparse
//! paths once `Reactions` has been created (the redundant path allocates, as in
//! [`Dynamics`]).

use crate::dynamics::{AccelerationStats, Dynamics, DynamicsError, DynamicsParams, SolverPath};
use crate::workspace::{scatter_row_major, Workspace};
use crate::{Info, Mechanism};

/// Kind of a constraint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConstraintKind {
    /// A holonomic constraint $C_k(q, t) = 0$.
    Holonomic,
    /// A non-holonomic constraint $G_k\dot q + g_k = 0$.
    Nonholonomic,
}

/// The reaction of one named constraint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConstraintReaction<'a> {
    /// The constraint's name.
    pub name: &'static str,
    /// Holonomic or non-holonomic.
    pub kind: ConstraintKind,
    /// Row in $J = [C_q; G]$ (and in $\lambda$).
    pub row: usize,
    /// Its multiplier $\lambda_k$ (sign of docs/theory.md §sign).
    pub lambda: f64,
    /// Its generalized force $-J_k^\mathsf{T}\lambda_k$ (length $n$).
    pub force: &'a [f64],
    /// Whether the acceleration solve found it dependent on the others.
    pub redundant: bool,
}

/// Multipliers and constraint forces at one state.
#[derive(Clone, Debug)]
pub struct Reactions {
    info: &'static Info,
    /// Time of the state.
    pub t: f64,
    /// Accelerations $\ddot q$.
    pub qdd: Vec<f64>,
    /// $\lambda = [\lambda_h; \lambda_{nh}]$, sign of docs/theory.md §sign.
    pub lambda: Vec<f64>,
    /// Row-major $m \times n$: row $k$ is $-J_k^\mathsf{T}\lambda_k$.
    forces: Vec<f64>,
    /// Rows of the constraints found redundant.
    redundant_rows: Vec<usize>,
    /// Statistics of the acceleration solve.
    pub stats: AccelerationStats,
}

impl Reactions {
    /// Zeroed reactions for the model described by `info`.
    #[must_use]
    pub fn new(info: &'static Info) -> Self {
        let (n, m) = (info.nq(), info.nh() + info.nnh());
        Self {
            info,
            t: 0.0,
            qdd: vec![0.0; n],
            lambda: vec![0.0; m],
            forces: vec![0.0; m * n],
            redundant_rows: Vec::with_capacity(m),
            stats: AccelerationStats {
                path: SolverPath::Dense,
                rank: m,
                pivot_ratio: 1.0,
            },
        }
    }

    /// The model description.
    #[must_use]
    pub fn info(&self) -> &'static Info {
        self.info
    }

    /// $\lambda_h$.
    #[must_use]
    pub fn lambda_h(&self) -> &[f64] {
        &self.lambda[..self.info.nh()]
    }

    /// $\lambda_{nh}$.
    #[must_use]
    pub fn lambda_nh(&self) -> &[f64] {
        &self.lambda[self.info.nh()..]
    }

    /// The multipliers in the sign of \[S2\], $\lambda^{[\text{S2}]} = -\lambda$.
    #[must_use]
    pub fn lambda_s2(&self) -> Vec<f64> {
        self.lambda.iter().map(|l| -l).collect()
    }

    /// The generalized force of constraint row `k`, $-J_k^\mathsf{T}\lambda_k$.
    ///
    /// # Panics
    /// When `k` is not below $m_h + m_{nh}$.
    #[must_use]
    pub fn constraint_force(&self, k: usize) -> &[f64] {
        let n = self.info.nq();
        &self.forces[k * n..(k + 1) * n]
    }

    /// The reaction of the constraint called `name`.
    #[must_use]
    pub fn get(&self, name: &str) -> Option<ConstraintReaction<'_>> {
        self.iter().find(|r| r.name == name)
    }

    /// The reactions of all constraints, holonomic first, in row order.
    pub fn iter(&self) -> impl Iterator<Item = ConstraintReaction<'_>> + '_ {
        let info = self.info;
        let mh = info.nh();
        (0..self.lambda.len()).map(move |k| {
            let (name, kind) = if k < mh {
                (info.holonomic[k].name, ConstraintKind::Holonomic)
            } else {
                (info.nonholonomic[k - mh].name, ConstraintKind::Nonholonomic)
            };
            ConstraintReaction {
                name,
                kind,
                row: k,
                lambda: self.lambda[k],
                force: self.constraint_force(k),
                redundant: self.redundant_rows.contains(&k),
            }
        })
    }

    /// Names of the constraints the solve found redundant (empty when $J$ has full
    /// rank). Their multipliers, and those of the constraints they depend on, are the
    /// minimum-norm split.
    pub fn redundant(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.iter().filter(|r| r.redundant).map(|r| r.name)
    }

    /// Sum of the constraint forces of the rows `range` into `out` (length $n$).
    fn sum_rows(&self, range: std::ops::Range<usize>, out: &mut [f64]) {
        out.fill(0.0);
        for k in range {
            for (o, f) in out.iter_mut().zip(self.constraint_force(k)) {
                *o += f;
            }
        }
    }

    /// $-C_q^\mathsf{T}\lambda_h$ into `out` (length $n$).
    pub fn holonomic_force_inplace(&self, out: &mut [f64]) {
        self.sum_rows(0..self.info.nh(), out);
    }

    /// $-G^\mathsf{T}\lambda_{nh}$ into `out` (length $n$).
    pub fn nonholonomic_force_inplace(&self, out: &mut [f64]) {
        self.sum_rows(self.info.nh()..self.lambda.len(), out);
    }

    /// The total generalized constraint force $F^c = -J^\mathsf{T}\lambda$.
    #[must_use]
    pub fn total_force(&self) -> Vec<f64> {
        let mut out = vec![0.0; self.info.nq()];
        self.sum_rows(0..self.lambda.len(), &mut out);
        out
    }
}

/// Reactions along a trajectory.
#[derive(Clone, Debug)]
pub struct ReactionHistory {
    /// One entry per sample, in the order given.
    pub samples: Vec<Reactions>,
    /// Every constraint found redundant at some sample, with the first time it was.
    pub redundant: Vec<(&'static str, f64)>,
}

impl ReactionHistory {
    /// $\max_k |\lambda_k|$ over all samples.
    #[must_use]
    pub fn max_abs_lambda(&self) -> f64 {
        self.samples
            .iter()
            .flat_map(|r| r.lambda.iter())
            .fold(0.0_f64, |a, l| a.max(l.abs()))
    }

    /// The multiplier of constraint row `k` at every sample.
    #[must_use]
    pub fn lambda_of(&self, k: usize) -> Vec<f64> {
        self.samples.iter().map(|r| r.lambda[k]).collect()
    }
}

/// Scratch for reaction analyses of one model (the acceleration solve and $J$).
#[derive(Debug)]
pub struct ReactionAnalysis {
    dynamics: Dynamics,
    jacobian: Vec<f64>,
    cq: Vec<f64>,
    g: Vec<f64>,
}

impl ReactionAnalysis {
    /// Scratch for the model described by `info`.
    ///
    /// # Errors
    /// The sparse symbolic factorization of [`Dynamics::new`].
    pub fn new(info: &'static Info, params: DynamicsParams) -> Result<Self, DynamicsError> {
        let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
        Ok(Self {
            dynamics: Dynamics::new(info, params)?,
            jacobian: vec![0.0; (mh + mnh) * n],
            cq: vec![0.0; info.holonomic_pattern.len()],
            g: vec![0.0; info.nonholonomic_pattern.len()],
        })
    }

    /// The acceleration solver (for its parameters and last redundancy report).
    #[must_use]
    pub fn dynamics(&self) -> &Dynamics {
        &self.dynamics
    }

    /// Multipliers and per-constraint forces at $(q, \dot q, t)$.
    ///
    /// # Errors
    /// Those of [`Dynamics::accelerations`].
    #[allow(clippy::too_many_arguments)]
    pub fn evaluate<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &mut Workspace,
        t: f64,
        q: &[f64],
        qd: &[f64],
        out: &mut Reactions,
    ) -> Result<AccelerationStats, DynamicsError> {
        let info = mech.info();
        let (n, mh) = (info.nq(), info.nh());
        let stats =
            self.dynamics
                .accelerations(mech, ws, t, q, qd, &mut out.qdd, &mut out.lambda)?;
        // J from the same evaluation point (the workspace keeps only pattern values).
        mech.holonomic_jacobian(t, q, &mut self.cq);
        mech.nonholonomic_matrix(t, q, &mut self.g);
        {
            let (h, nh) = self.jacobian.split_at_mut(mh * n);
            scatter_row_major(info.holonomic_pattern, &self.cq, n, h);
            scatter_row_major(info.nonholonomic_pattern, &self.g, n, nh);
        }
        for (k, &l) in out.lambda.iter().enumerate() {
            let row = &self.jacobian[k * n..(k + 1) * n];
            for (f, j) in out.forces[k * n..(k + 1) * n].iter_mut().zip(row) {
                *f = -j * l;
            }
        }
        out.t = t;
        out.stats = stats;
        out.redundant_rows.clear();
        for name in self.dynamics.redundant_constraints() {
            let k = info
                .holonomic
                .iter()
                .position(|s| s.name == name)
                .or_else(|| {
                    info.nonholonomic
                        .iter()
                        .position(|s| s.name == name)
                        .map(|k| k + mh)
                });
            if let Some(k) = k {
                out.redundant_rows.push(k);
            }
        }
        Ok(stats)
    }

    /// Reactions at every sample $(t, q, \dot q)$ of a trajectory.
    ///
    /// # Errors
    /// The first failure of [`ReactionAnalysis::evaluate`].
    pub fn along<'s, M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &mut Workspace,
        samples: impl IntoIterator<Item = (f64, &'s [f64], &'s [f64])>,
    ) -> Result<ReactionHistory, DynamicsError> {
        let mut history = ReactionHistory {
            samples: Vec::new(),
            redundant: Vec::new(),
        };
        for (t, q, qd) in samples {
            let mut r = Reactions::new(mech.info());
            self.evaluate(mech, ws, t, q, qd, &mut r)?;
            for name in r.redundant() {
                if !history.redundant.iter().any(|(n, _)| *n == name) {
                    history.redundant.push((name, t));
                }
            }
            history.samples.push(r);
        }
        Ok(history)
    }
}
