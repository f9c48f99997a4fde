//! Generalized coordinate partitioning (docs/theory.md §partitioning, Algorithm P) and its condition
//! monitor.
//!
//! Input: a configuration $(q, t)$ (consistent or not) and the Jacobian
//! $J = [C_q; G]$ evaluated there. Output: a [`Partition`] of the coordinates into
//! - $\beta$ ($m_h$ dependent coordinates): the pivot columns of Gaussian elimination
//!   with complete pivoting on $C_q$;
//! - $\eta$ ($m_{nh}$ independent coordinates with dependent velocities): the pivot
//!   columns of complete pivoting on the Schur complement
//!   $\hat G = G_p - G_\beta C_\beta^{-1} C_p$;
//! - $\gamma$ (the rest): independent coordinates and velocities.
//!
//! Then $J_d = \begin{bmatrix}C_\beta & C_\eta\\ G_\beta & G_\eta\end{bmatrix}$ is
//! non-singular with $|\det J_d| = |\det C_\beta|\,|\det \hat G_\eta|$.
//!
//! Pivots are chosen on $J$ with its rows scaled to a largest entry near 1 (see
//! [`crate::scale`]), so that the partition does not depend on the units of the
//! constraints. A pivot below `pivot_tolerance` × (largest entry) means redundant or
//! singular constraints: the rows left without a pivot are reported by name.
//!
//! **Condition monitor.** The partition stores, per block, the ratio
//! $\rho = \min_k |u_{kk}| / \max_{ij} |a_{ij}|$ of the smallest pivot of $C_\beta$
//! (resp. $\hat G_\eta$) to the largest entry of $C_q$ (resp. $\hat G$). The same ratio
//! recomputed later ([`Partition::condition`]) falls towards 0 as the chosen dependent
//! block approaches singularity while a better choice exists; the caller re-partitions
//! when it drops below `deterioration` × its value at partition time.

use crate::linalg::elimination::{Elimination, Tier};
use crate::workspace::{check_state, EvalError, Workspace};
use crate::{Info, Mechanism};

/// The rank rule shared by the analyses of a model with redundant constraints: a row
/// of $J$ (rows scaled to a largest entry near 1) counts as dependent on the others
/// when what it adds to them, the pivot complete pivoting finds for it or its distance
/// to their span, is below `RANK_PIVOT` times its size.
///
/// It decides which rows the projections and the chart keep ([`crate::sim`]: the
/// re-partition of the kept rows, whose Gram matrices therefore keep pivot ratios
/// above about `RANK_PIVOT`², far above the singular test of `SINGULAR_RATIO`), and
/// which rows the augmented solve drops ([`crate::DynamicsParams::rank_tolerance`]'s
/// default is `RANK_PIVOT`²: the constraint block of the augmented matrix has the
/// squares of $J$'s pivots). Near a configuration where $C_q$ loses rank while the
/// solution set stays smooth (the parallelogram's flat position), the rows that turn
/// dependent are dropped by every analysis at the same distance, and taken back by
/// every analysis when the motion leaves it. Between $10^{-8}$ (the chart's maps lose
/// half the digits) and $10^{-3}$ (the dropped rows' own reactions start to matter,
/// docs/decisions/0036-through-a-rank-drop.md): $10^{-5}$.
pub const RANK_PIVOT: f64 = 1e-5;

/// Tuning of Algorithm P.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PartitionParams {
    /// Relative pivot threshold $\varepsilon_{piv}$ below which constraints are
    /// declared redundant or singular.
    pub pivot_tolerance: f64,
    /// Re-partition when a pivot ratio falls below this fraction of its value at
    /// partition time.
    pub deterioration: f64,
    /// Accept redundant holonomic constraints: the rows left without a pivot are
    /// dropped from $\beta$'s equations ([`Partition::redundant_rows`]) instead of
    /// failing with [`PartitionError::RedundantHolonomic`]. Near the constraint
    /// manifold the independent rows have the same solution set, so K1 and K2 on them
    /// satisfy the dropped rows too. Not with non-holonomic constraints.
    pub allow_redundant: bool,
}

impl Default for PartitionParams {
    fn default() -> Self {
        Self {
            pivot_tolerance: 1e-9,
            deterioration: 1e-3,
            allow_redundant: false,
        }
    }
}

/// Pivot ratios of the dependent blocks (see the module docs); 1 for an empty block.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Condition {
    /// Ratio for $C_\beta$ against $C_q$.
    pub holonomic: f64,
    /// Ratio for $\hat G_\eta$ against $\hat G$.
    pub nonholonomic: f64,
}

/// Role of a coordinate in a partition.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// In $\beta$: dependent coordinate and velocity.
    Dependent,
    /// In $\eta$: independent coordinate, dependent velocity.
    DependentVelocity,
    /// In $\gamma$: independent coordinate and velocity.
    Independent,
}

/// Errors of Algorithm P.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PartitionError {
    /// $C_q$ is rank deficient.
    #[error("redundant or singular holonomic constraints at t = {t:?}: {constraints:?} (pivot ratio {ratio:e}, rank {rank} of {rows})")]
    RedundantHolonomic {
        /// Time.
        t: f64,
        /// The constraints left without a pivot.
        constraints: Vec<&'static str>,
        /// Best pivot left at the stop / largest entry (below the tolerance).
        ratio: f64,
        /// Numerical rank of $C_q$.
        rank: usize,
        /// $m_h$.
        rows: usize,
    },
    /// $\hat G$ is rank deficient: non-holonomic constraints depend on the others.
    #[error("redundant or singular non-holonomic constraints at t = {t:?}: {constraints:?} (pivot ratio {ratio:e})")]
    RedundantNonholonomic {
        /// Time.
        t: f64,
        /// The constraints left without a pivot.
        constraints: Vec<&'static str>,
        /// Best pivot left at the stop / largest entry (below the tolerance).
        ratio: f64,
    },
    /// A coordinate asked to stay independent must be dependent.
    #[error("coordinate `{coordinate}` cannot be kept independent at t = {t:?}: constraints {constraints:?} can only be met by moving it (or other prescribed coordinates)")]
    PrescribedCoordinate {
        /// Time.
        t: f64,
        /// The coordinate that had to become dependent.
        coordinate: &'static str,
        /// The constraints that force it.
        constraints: Vec<&'static str>,
    },
    /// A coordinate whose velocity is prescribed must have a dependent velocity.
    #[error("the velocity of `{coordinate}` cannot be prescribed at t = {t:?}: constraints {constraints:?} determine it (too many or inconsistent prescribed velocities)")]
    PrescribedVelocity {
        /// Time.
        t: f64,
        /// The coordinate whose velocity had to become dependent.
        coordinate: &'static str,
        /// The constraints that determine it.
        constraints: Vec<&'static str>,
    },
    /// Evaluation failed.
    #[error(transparent)]
    Eval(#[from] EvalError),
}

/// Coordinates to keep independent if possible (indices into `q`).
#[derive(Clone, Copy, Debug, Default)]
pub struct Preferences<'a> {
    /// Coordinates that must not be in $\beta$.
    pub coordinates: &'a [usize],
    /// Coordinates whose velocity must be independent (in $\gamma$).
    pub velocities: &'a [usize],
}

/// A partition $q \equiv [\beta; \eta; \gamma]$ (Algorithm P).
#[derive(Clone, Debug)]
pub struct Partition {
    info: &'static Info,
    pub(crate) dependent: Vec<usize>,
    pub(crate) eta: Vec<usize>,
    pub(crate) independent: Vec<usize>,
    /// The holonomic rows that determine $\beta$ (all of them, in order, unless
    /// redundant rows were dropped) and the dropped ones.
    pub(crate) rows: Vec<usize>,
    pub(crate) redundant: Vec<usize>,
    pub(crate) reference: Condition,
    pub(crate) abs_det: f64,
    pub(crate) time: f64,
}

impl Partition {
    /// Runs Algorithm P at $(q, t)$ with a fresh scratch (allocates; see
    /// [`Kinematics`](crate::Kinematics) for the reusable form).
    pub fn compute<M: Mechanism + ?Sized>(
        mech: &M,
        ws: &mut Workspace,
        t: f64,
        q: &[f64],
        prefs: Preferences<'_>,
        params: &PartitionParams,
    ) -> Result<Self, PartitionError> {
        let info = ws.info();
        let mut elim = Elimination::new(info.nh() + info.nnh(), info.nq());
        compute_with(&mut elim, mech, ws, t, q, prefs, params)
    }

    /// $\beta$: dependent coordinates, in pivot order.
    #[must_use]
    pub fn dependent(&self) -> &[usize] {
        &self.dependent
    }

    /// The holonomic constraints (row indices) whose equations determine $\beta$.
    #[must_use]
    pub fn holonomic_rows(&self) -> &[usize] {
        &self.rows
    }

    /// The redundant holonomic constraints (row indices) left out of K1 and K2 (empty
    /// unless [`PartitionParams::allow_redundant`]).
    #[must_use]
    pub fn redundant_rows(&self) -> &[usize] {
        &self.redundant
    }

    /// $\eta$: independent coordinates with dependent velocities.
    #[must_use]
    pub fn dependent_velocity(&self) -> &[usize] {
        &self.eta
    }

    /// $\gamma$: fully independent coordinates.
    #[must_use]
    pub fn independent(&self) -> &[usize] {
        &self.independent
    }

    /// Names of $\beta$, $\eta$, $\gamma$.
    #[must_use]
    pub fn names(&self) -> [Vec<&'static str>; 3] {
        let name = |v: &[usize]| v.iter().map(|&i| self.info.coordinates[i].name).collect();
        [
            name(&self.dependent),
            name(&self.eta),
            name(&self.independent),
        ]
    }

    /// Role of coordinate `i`.
    #[must_use]
    pub fn role(&self, i: usize) -> Role {
        if self.dependent.contains(&i) {
            Role::Dependent
        } else if self.eta.contains(&i) {
            Role::DependentVelocity
        } else {
            Role::Independent
        }
    }

    /// Pivot ratios at partition time.
    #[must_use]
    pub fn reference_condition(&self) -> Condition {
        self.reference
    }

    /// $|\det C_\beta|$ at partition time.
    #[must_use]
    pub fn abs_det_dependent(&self) -> f64 {
        self.abs_det
    }

    /// Time at which the partition was computed.
    #[must_use]
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Recomputes the pivot ratios of this partition at $(q,t)$ with a fresh scratch
    /// (allocates; see [`Kinematics::condition`](crate::Kinematics::condition)).
    pub fn condition<M: Mechanism + ?Sized>(
        &self,
        mech: &M,
        ws: &mut Workspace,
        t: f64,
        q: &[f64],
    ) -> Result<Condition, EvalError> {
        let info = ws.info();
        let mut elim = Elimination::new(info.nh() + info.nnh(), info.nq());
        condition_with(&mut elim, self, mech, ws, t, q)
    }

    /// Whether `now` has deteriorated below `params.deterioration` × the reference.
    #[must_use]
    pub fn is_deteriorated(&self, now: Condition, params: &PartitionParams) -> bool {
        now.holonomic < params.deterioration * self.reference.holonomic
            || now.nonholonomic < params.deterioration * self.reference.nonholonomic
    }
}

/// Algorithm P on a reusable elimination scratch.
pub(crate) fn compute_with<M: Mechanism + ?Sized>(
    elim: &mut Elimination,
    mech: &M,
    ws: &mut Workspace,
    t: f64,
    q: &[f64],
    prefs: Preferences<'_>,
    params: &PartitionParams,
) -> Result<Partition, PartitionError> {
    let info = ws.info();
    let (n, mh, m) = (info.nq(), info.nh(), info.nh() + info.nnh());
    check_state(info, t, q, None)?;
    ws.eval_jacobian(mech, t, q)?;
    elim.load(&ws.jacobian);
    let names = |rows: &[usize]| -> Vec<&'static str> {
        rows.iter()
            .map(|&r| {
                if r < mh {
                    info.holonomic[r].name
                } else {
                    info.nonholonomic[r - mh].name
                }
            })
            .collect()
    };
    // Step 1: β from C_q, keeping prescribed coordinates (and coordinates with
    // prescribed velocities) out of it when possible.
    for &i in prefs.coordinates.iter().chain(prefs.velocities) {
        elim.tier[i] = Tier::Allowed;
    }
    let ph1 = elim.phase(0, mh, mh, params.pivot_tolerance);
    // Redundant rows are allowed: a prescription that could not be kept out of β is
    // the error to report (below), else the rows left without a pivot are dropped.
    let redundant_allowed = params.allow_redundant && m == mh;
    if ph1.rank < mh && redundant_allowed && ph1.first_allowed.is_none() {
        let r = ph1.rank;
        let mut rows = elim.rows[..r].to_vec();
        let mut redundant = elim.rows[r..mh].to_vec();
        rows.sort_unstable();
        redundant.sort_unstable();
        return Ok(Partition {
            info,
            dependent: elim.cols[..r].to_vec(),
            eta: Vec::new(),
            independent: elim.cols[r..n].to_vec(),
            rows,
            redundant,
            reference: Condition {
                holonomic: ph1.ratio(r),
                nonholonomic: 1.0,
            },
            abs_det: unscaled_det(elim, ph1.abs_det, ph1.rank),
            time: t,
        });
    }
    if ph1.rank < mh && !redundant_allowed {
        return Err(PartitionError::RedundantHolonomic {
            t,
            constraints: names(&elim.rows[ph1.rank..mh]),
            ratio: if ph1.scale > 0.0 {
                ph1.rejected / ph1.scale
            } else {
                0.0
            },
            rank: ph1.rank,
            rows: mh,
        });
    }
    if let Some(k) = ph1.first_allowed {
        let col = elim.cols[k];
        let coordinate = info.coordinates[col].name;
        let constraints = names(&elim.rows[k..mh]);
        return Err(if prefs.coordinates.contains(&col) {
            PartitionError::PrescribedCoordinate {
                t,
                coordinate,
                constraints,
            }
        } else {
            PartitionError::PrescribedVelocity {
                t,
                coordinate,
                constraints,
            }
        });
    }
    // Step 2: η among the remaining columns, from the Schur complement Ĝ that the
    // first phase left in the non-holonomic rows.
    elim.tier.fill(Tier::Preferred);
    for &i in prefs.velocities {
        elim.tier[i] = Tier::Allowed;
    }
    let ph2 = elim.phase(mh, m, m - mh, params.pivot_tolerance);
    if ph2.rank < m - mh {
        return Err(PartitionError::RedundantNonholonomic {
            t,
            constraints: names(&elim.rows[mh + ph2.rank..m]),
            ratio: if ph2.scale > 0.0 {
                ph2.rejected / ph2.scale
            } else {
                0.0
            },
        });
    }
    if let Some(k) = ph2.first_allowed {
        return Err(PartitionError::PrescribedVelocity {
            t,
            coordinate: info.coordinates[elim.cols[k]].name,
            constraints: names(&elim.rows[k..m]),
        });
    }
    Ok(Partition {
        info,
        dependent: elim.cols[..mh].to_vec(),
        eta: elim.cols[mh..m].to_vec(),
        independent: elim.cols[m..n].to_vec(),
        rows: (0..mh).collect(),
        redundant: Vec::new(),
        reference: Condition {
            holonomic: ph1.ratio(mh),
            nonholonomic: ph2.ratio(m - mh),
        },
        abs_det: unscaled_det(elim, ph1.abs_det, ph1.rank),
        time: t,
    })
}

/// $|\det C_\beta|$ of the original rows from the product of the first `rank` pivots of
/// the row-scaled matrix.
fn unscaled_det(elim: &Elimination, scaled: f64, rank: usize) -> f64 {
    elim.rows[..rank]
        .iter()
        .fold(scaled, |d, &r| d / elim.row_scale[r])
}

/// The condition monitor on a reusable elimination scratch.
pub(crate) fn condition_with<M: Mechanism + ?Sized>(
    elim: &mut Elimination,
    partition: &Partition,
    mech: &M,
    ws: &mut Workspace,
    t: f64,
    q: &[f64],
) -> Result<Condition, EvalError> {
    let info = ws.info();
    let (mh, m) = (info.nh(), info.nh() + info.nnh());
    check_state(info, t, q, None)?;
    ws.eval_jacobian(mech, t, q)?;
    elim.load(&ws.jacobian);
    // The dropped redundant rows do not enter K1 and K2: the kept ones must stay
    // regular on β (at the bottom of the parallelogram's swing its three pin_y rows
    // become dependent, and a partition that dropped a pin_x row must be renewed).
    elim.clear_rows(&partition.redundant);
    elim.tier.fill(Tier::Forbidden);
    for &i in &partition.dependent {
        elim.tier[i] = Tier::Preferred;
    }
    let r = partition.dependent.len();
    let ph1 = elim.phase(0, mh, r, 0.0);
    let holonomic = ph1.ratio(r);
    if ph1.rank < r {
        return Ok(Condition {
            holonomic,
            nonholonomic: 0.0,
        });
    }
    elim.tier.fill(Tier::Forbidden);
    for &i in &partition.eta {
        elim.tier[i] = Tier::Preferred;
    }
    let ph2 = elim.phase(mh, m, m - mh, 0.0);
    Ok(Condition {
        holonomic,
        nonholonomic: ph2.ratio(m - mh),
    })
}

/// The holonomic constraints among `rows` (the rows the analyses keep: constraints
/// found redundant are reported as such, not here) that take part in the near
/// dependence of those rows of $C_q(q, t)$, for naming them in an error: the first of
/// `ratios` below which some singular value $\sigma_k$ of them (scaled to unit length,
/// so that the units of the constraints do not count) lies relative to the largest, the left
/// singular vectors $u_k$ of all such values, and the rows whose entries in them reach
/// a tenth of their largest ($\sum_i u_{ik}\,\text{row}_i \approx 0$ is the dependent
/// combination), most involved first. Empty when no ratio finds a dependence (or
/// $C_q$ cannot be evaluated).
///
/// Complete pivoting names one row of the set only (the one left without a pivot,
/// which depends on the pivots' order): a driven slider-crank whose crank is longer
/// than its coupler locks with the coupler vertical, where the vertical rows of the
/// loop and the slider's guide are dependent together. Allocates (an error path).
pub(crate) fn dependent_constraints<M: Mechanism + ?Sized>(
    mech: &M,
    ws: &mut Workspace,
    t: f64,
    q: &[f64],
    rows: &[usize],
    ratios: &[f64],
) -> Vec<&'static str> {
    let info = ws.info();
    let (n, mh) = (info.nq(), rows.len());
    if mh == 0 || ws.eval_jacobian(mech, t, q).is_err() {
        return Vec::new();
    }
    let jacobian = &ws.jacobian;
    let norms: Vec<f64> = rows
        .iter()
        .map(|&r| {
            let row = &jacobian[r * n..(r + 1) * n];
            row.iter().map(|x| x * x).sum::<f64>().sqrt()
        })
        .collect();
    if norms.iter().any(|s| !s.is_finite()) {
        return Vec::new();
    }
    // A zero row is dependent by itself; the others are scaled to unit length.
    let a = faer::Mat::from_fn(mh, n, |i, j| {
        if norms[i] > 0.0 {
            jacobian[rows[i] * n + j] / norms[i]
        } else {
            0.0
        }
    });
    let Ok(svd) = a.svd() else {
        return Vec::new();
    };
    let (u, s) = (svd.U(), svd.S().column_vector());
    let largest = if s.nrows() > 0 { s[0] } else { 0.0 };
    // The full U has mh columns; the singular values beyond min(mh, n) are 0.
    let sigma = |k: usize| if k < s.nrows() { s[k] } else { 0.0 };
    for &ratio in ratios {
        let weak: Vec<usize> = (0..mh).filter(|&k| sigma(k) <= ratio * largest).collect();
        if weak.is_empty() {
            continue;
        }
        let weight: Vec<f64> = (0..mh)
            .map(|i| weak.iter().fold(0.0_f64, |w, &k| w.max(u[(i, k)].abs())))
            .collect();
        let top = weight.iter().fold(0.0_f64, |w, &x| w.max(x));
        let mut named: Vec<usize> = (0..mh)
            .filter(|&i| norms[i] == 0.0 || weight[i] >= 0.1 * top)
            .collect();
        named.sort_by(|&i, &k| weight[k].total_cmp(&weight[i]));
        return named
            .into_iter()
            .map(|i| info.holonomic[rows[i]].name)
            .collect();
    }
    Vec::new()
}
