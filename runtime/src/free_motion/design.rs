//! The inverse problems of docs/theory.md §free-motion and §free-motion-analysis step 3 ("design mode").
//!
//! - **Forces.** $w = w^0 + K Q$ is affine in the applied forces, so the forces that make
//!   the motion free at a state are $Q \in F^\mathsf{T}\lambda^0 + \ker K$ with
//!   $\lambda^0$ the \[S2\] multiplier of the system without applied forces (the design
//!   remark of docs/theory.md §free-motion). [`ForceDesign`] picks one member: the least 2-norm one, the
//!   would-be constraint forces $F^\mathsf{T}\lambda^0$ themselves (least
//!   $A^{-1}$-norm), or the least-squares solution restricted to chosen components,
//!   which is exact when the components can cancel $w^0$ and is reported as inexact
//!   otherwise.
//! - **A parameter.** Given the forces, the member of a one-parameter family of models
//!   (a constraint, the inertia or the forces depending on a model parameter $p$) for
//!   which $w(p) = 0$ at a set of sample states: a grid scan of
//!   $\lVert w(p)\rVert_2^2$ over the samples, then Gauss–Newton from every local minimum.
//!
//! Both use [`FreeMotion::evaluate`] and allocate their (small) results.

use super::{AppliedForces, FreeMotion, FreeMotionError, FreeMotionPoint};
use crate::linalg::inf_norm;
use crate::{Mechanism, Workspace};

/// Which applied forces [`FreeMotion::free_forces`] returns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ForceDesign<'a> {
    /// The $Q$ of least 2-norm: $Q = K^\mathsf{T}(K K^\mathsf{T})^+(-w^0)$.
    MinimumNorm,
    /// "Apply the would-be constraint forces": $Q = F^\mathsf{T}\lambda^{0[\text{S2}]}$, the
    /// solution of least $A^{-1}$-norm.
    ConstraintForces,
    /// Only these components of $Q$ (coordinate indices) may be non-zero: the
    /// least-squares solution of $K_S Q_S = -w^0$ of least norm.
    Components(&'a [usize]),
}

/// Applied forces that make the motion free at one state.
#[derive(Clone, Debug, PartialEq)]
pub struct ForceSolution {
    /// $Q$ (length $n$), to be used *instead of* the model's declared applied forces
    /// ([`AppliedForces::Replaced`], [`super::Forced`]).
    pub applied: Vec<f64>,
    /// $\lVert w^0 + K Q\rVert_\infty$: the free-motion residual left.
    pub residual: f64,
    /// The size of the terms of $w$ the residual is compared with.
    pub scale: f64,
    /// Whether the residual is below `residual_tolerance · scale`: `false` when the
    /// chosen components cannot make the motion free at this state.
    pub exact: bool,
    /// Rank of $K_S$ (how many conditions the chosen components can satisfy).
    pub rank: usize,
}

/// A state at which a free-motion condition is imposed.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    /// Time.
    pub t: f64,
    /// Coordinates.
    pub q: Vec<f64>,
    /// Velocities.
    pub qd: Vec<f64>,
}

impl Sample {
    /// A sample from slices.
    #[must_use]
    pub fn new(t: f64, q: &[f64], qd: &[f64]) -> Self {
        Self {
            t,
            q: q.to_vec(),
            qd: qd.to_vec(),
        }
    }
}

/// A search for the parameter value that makes a motion free.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParameterSearch {
    /// The parameter (index in [`Info::parameters`](crate::Info::parameters)).
    pub index: usize,
    /// Lower end of the interval searched.
    pub lo: f64,
    /// Upper end of the interval searched.
    pub hi: f64,
    /// Points of the initial scan (at least 2).
    pub grid: usize,
    /// $\max|w|$ over the samples below which a value counts as a solution.
    pub tolerance: f64,
    /// Gauss–Newton iterations from each local minimum of the scan.
    pub max_iter: usize,
}

impl ParameterSearch {
    /// Parameter `index` on `[lo, hi]` with a 33-point scan, tolerance `1e-10` and 50
    /// iterations.
    #[must_use]
    pub fn new(index: usize, lo: f64, hi: f64) -> Self {
        Self {
            index,
            lo,
            hi,
            grid: 33,
            tolerance: 1e-10,
            max_iter: 50,
        }
    }
}

/// Result of [`FreeMotion::solve_parameter`].
#[derive(Clone, Debug, PartialEq)]
pub struct ParameterSolution {
    /// The values in `[lo, hi]` for which $\max|w| \le$ `tolerance` at every sample,
    /// ascending (empty when no member of the family makes the motion free).
    pub roots: Vec<f64>,
    /// The value with the smallest residual found.
    pub best: f64,
    /// $\max|w|$ over the samples at `best`.
    pub residual: f64,
    /// Evaluations of $w$ over all samples.
    pub evaluations: usize,
}

impl FreeMotion {
    /// Applied forces that make the motion free at $(q, \dot q, t)$, replacing the
    /// model's declared ones (docs/theory.md §free-motion, design).
    ///
    /// # Errors
    /// Those of [`FreeMotion::evaluate`]; [`FreeMotionError::Component`] for an index
    /// out of range.
    #[allow(non_snake_case)]
    pub fn free_forces<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        ws: &mut Workspace,
        t: f64,
        q: &[f64],
        qd: &[f64],
        design: ForceDesign<'_>,
    ) -> Result<ForceSolution, FreeMotionError> {
        let info = self.info;
        let (n, m) = (info.nq(), info.nh() + info.nnh());
        let mut p = FreeMotionPoint::new(info);
        self.evaluate(mech, ws, t, q, qd, AppliedForces::Without, &mut p)?;
        let K = &p.K;
        let w0 = &p.base_residual;
        let mut applied = vec![0.0; n];
        let rank = match design {
            ForceDesign::ConstraintForces => {
                applied.copy_from_slice(&p.reaction);
                p.rank
            }
            ForceDesign::MinimumNorm | ForceDesign::Components(_) => {
                let all: Vec<usize> = (0..n).collect();
                let cols = match design {
                    ForceDesign::Components(c) => c,
                    _ => &all[..],
                };
                if let Some(&index) = cols.iter().find(|&&c| c >= n) {
                    return Err(FreeMotionError::Component {
                        model: info.name,
                        index,
                        n,
                    });
                }
                // Q_S = K_Sᵀ (K_S K_Sᵀ)⁺ (−w⁰): the least-norm least-squares solution.
                let mut kk = vec![0.0; m * m];
                for a in 0..m {
                    for b in 0..m {
                        kk[a * m + b] = cols.iter().map(|&s| K[a * n + s] * K[b * n + s]).sum();
                    }
                }
                let rhs: Vec<f64> = w0.iter().map(|w| -w).collect();
                let mut y = vec![0.0; m];
                self.eigen.load(&kk);
                let rank = self
                    .eigen
                    .pinv_solve(&rhs, self.params.rank_tolerance, &mut y);
                for &s in cols {
                    applied[s] = (0..m).map(|a| K[a * n + s] * y[a]).sum();
                }
                rank
            }
        };
        let mut residual = 0.0_f64;
        let mut scale = inf_norm(w0);
        for b in 0..m {
            let kq: Vec<f64> = (0..n).map(|s| K[b * n + s] * applied[s]).collect();
            residual = residual.max((w0[b] + kq.iter().sum::<f64>()).abs());
            scale = scale.max(kq.iter().map(|v| v.abs()).sum());
        }
        Ok(ForceSolution {
            applied,
            residual,
            scale,
            exact: residual <= self.params.residual_tolerance * scale.max(f64::MIN_POSITIVE),
            rank,
        })
    }

    /// The values of a model parameter for which the motion is free at every sample
    /// state, with the given applied forces (docs/theory.md §free-motion-analysis step 3 for a family of
    /// constraints, inertias or forces).
    ///
    /// The samples may be arbitrary states (then a root makes $w \equiv 0$ identically
    /// there) or states of the intended motion, which the caller makes consistent with
    /// the constraints. The parameter is restored to its value on entry.
    ///
    /// # Errors
    /// An invalid search, no samples, a parameter out of range, and the failures of
    /// [`FreeMotion::evaluate`].
    pub fn solve_parameter<M: Mechanism + ?Sized>(
        &mut self,
        mech: &mut M,
        ws: &mut Workspace,
        search: &ParameterSearch,
        samples: &[Sample],
        applied: AppliedForces<'_>,
    ) -> Result<ParameterSolution, FreeMotionError> {
        let info = self.info;
        let &ParameterSearch {
            index,
            lo,
            hi,
            grid,
            tolerance,
            max_iter,
        } = search;
        if !(lo.is_finite() && hi.is_finite() && lo < hi && grid >= 2) {
            return Err(FreeMotionError::Search { lo, hi, grid });
        }
        if samples.is_empty() {
            return Err(FreeMotionError::NoSamples);
        }
        if index >= info.parameters.len() {
            return Err(FreeMotionError::Parameter {
                model: info.name,
                index,
                count: info.parameters.len(),
            });
        }
        let saved = mech.parameter(index);
        let mut evaluations = 0;
        let mut point = FreeMotionPoint::new(info);
        let mut residual = |mech: &mut M, p: f64| -> Result<Vec<f64>, FreeMotionError> {
            mech.set_parameter(index, p);
            evaluations += 1;
            let mut r = Vec::with_capacity(samples.len() * point.residual.len());
            for s in samples {
                self.evaluate(&*mech, ws, s.t, &s.q, &s.qd, applied, &mut point)?;
                r.extend_from_slice(&point.residual);
            }
            Ok(r)
        };
        let result: Result<_, FreeMotionError> = (|| {
            let sq = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
            #[allow(clippy::cast_precision_loss)]
            let at = |i: usize| lo + (hi - lo) * i as f64 / (grid - 1) as f64;
            let mut phi = Vec::with_capacity(grid);
            for i in 0..grid {
                phi.push(sq(&residual(mech, at(i))?));
            }
            let mut minima: Vec<usize> = (0..grid)
                .filter(|&i| {
                    (i == 0 || phi[i] <= phi[i - 1]) && (i + 1 == grid || phi[i] <= phi[i + 1])
                })
                .collect();
            minima.sort_by(|&a, &b| phi[a].total_cmp(&phi[b]));
            minima.truncate(8);
            let mut best = (at(minima[0]), f64::INFINITY);
            let mut roots: Vec<f64> = Vec::new();
            for &i in &minima {
                let (a, b) = (at(i.saturating_sub(1)), at((i + 1).min(grid - 1)));
                let mut p = at(i);
                let mut r = residual(mech, p)?;
                for _ in 0..max_iter {
                    if inf_norm(&r) == 0.0 {
                        break;
                    }
                    let d = 1e-6 * (1.0 + p.abs());
                    let (rp, rm) = (residual(mech, p + d)?, residual(mech, p - d)?);
                    let jr: f64 = rp
                        .iter()
                        .zip(&rm)
                        .zip(&r)
                        .map(|((x, y), z)| (x - y) / (2.0 * d) * z)
                        .sum();
                    let jj: f64 = rp
                        .iter()
                        .zip(&rm)
                        .map(|(x, y)| ((x - y) / (2.0 * d)).powi(2))
                        .sum();
                    if jj == 0.0 {
                        break;
                    }
                    let mut step = -jr / jj;
                    let mut improved = false;
                    for _ in 0..30 {
                        let trial = (p + step).clamp(a, b);
                        let rt = residual(mech, trial)?;
                        if sq(&rt) < sq(&r) {
                            let moved = (trial - p).abs();
                            p = trial;
                            r = rt;
                            improved = moved > 4.0 * f64::EPSILON * (1.0 + p.abs());
                            break;
                        }
                        step *= 0.5;
                    }
                    if !improved {
                        break;
                    }
                }
                let size = inf_norm(&r);
                if size < best.1 {
                    best = (p, size);
                }
                if size <= tolerance && !roots.iter().any(|x| (x - p).abs() <= 1e-9 * (hi - lo)) {
                    roots.push(p);
                }
            }
            roots.sort_by(f64::total_cmp);
            Ok((roots, best))
        })();
        mech.set_parameter(index, saved);
        let (roots, best) = result?;
        Ok(ParameterSolution {
            roots,
            best: best.0,
            residual: best.1,
            evaluations,
        })
    }
}
