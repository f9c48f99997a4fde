//! Impacts: the generalized impulse–momentum solve with holonomic and non-holonomic
//! constraints (docs/theory.md §impacts, Algorithm I-solve).
//!
//! Input: a model with contacts ([`Info::contacts`]: gaps $\delta_c(q, t)$, their normal
//! Jacobians $D_c = \partial\delta_c/\partial q$ and restitution parameters $e_c$), the
//! impact configuration $(t, q)$, the pre-impact velocities $\dot q^-$ and the contacts
//! that strike. Output: an [`Impact`]: $\dot q^+$, the normal impulse $\hat P_c$ of each
//! contact, the impulsive reaction $\Lambda$ of every named constraint, the finite
//! multipliers before and after (their jump, docs/theory.md §multiplier-jump) and the kinetic energy
//! before and after.
//!
//! **The augmented form (E41).** With $J = [C_q; G]$ and the normal velocities
//! $v_n = D\dot q + \delta_t$, one linear system
//! $$\begin{bmatrix}M & J^\mathsf{T} & -D^\mathsf{T}\\ J & 0 & 0\\ D & 0 & 0\end{bmatrix}
//! \begin{bmatrix}\Delta\dot q\\ \Lambda\\ \hat P\end{bmatrix} =
//! \begin{bmatrix}0\\ 0\\ -(1+e)\,v_n^-\end{bmatrix}$$
//! gives everything at once: the velocity jump leaves both kinds of constraint
//! satisfied ($J\Delta\dot q = 0$, so $J\dot q^+ = J\dot q^-$), and Newton's law
//! $v_n^+ = -e\,v_n^-$ holds for every striking contact. Several contacts in one solve
//! is *simultaneous* Newton restitution; the simulation applies the sequential law
//! instead (see [`crate::sim`]), one contact per solve.
//!
//! **The partitioned form (E42)**, [`ImpactSolver::solve_partitioned`], eliminates the
//! constraints with the velocity transformation $\dot q = B_v\dot\gamma + b_v$ of
//! Algorithm P: $\hat M = B_v^\mathsf{T} M B_v$, $W = D B_v \hat M^{-1} B_v^\mathsf{T}
//! D^\mathsf{T}$, $W\hat P = -(1+e)v_n^-$, $\Delta\dot q = B_v\hat M^{-1}B_v^\mathsf{T}
//! D^\mathsf{T}\hat P$, and $J_d^\mathsf{T}\Lambda = [D^\mathsf{T}\hat P -
//! M\Delta\dot q]_{\beta,\eta}$. The two forms agree to round-off (tests V13–V16).
//!
//! **Energy.** For one contact, $T^- - T^+ = \tfrac12(1-e^2)\,m_\text{eff}\,(v_n^-)^2
//! \ge 0$ with $m_\text{eff} = W^{-1}$, for a kinetic energy quadratic in $\dot q$.
//!
//! **Singular configurations.** When the rows of $[J; D]$ are dependent (a contact
//! normal the constraints already fix, or a singular position of the mechanism), the
//! impulses are not determined: [`ImpactError::Singular`] names the rows of the
//! dependent set.
//!
//! [`ImpactSolver`] holds its scratch: after [`ImpactSolver::new`], a solve allocates
//! only the [`Impact`] it returns.

// Index loops mirror the block structure of the augmented matrix.
#![allow(clippy::needless_range_loop)]

use crate::linalg::dense::DenseLu;
use crate::workspace::{check_finite, scatter_row_major, EvalError, Quantity, Workspace};
use crate::{
    Dynamics, DynamicsError, DynamicsParams, Info, Mechanism, Partition, PartitionError,
    PartitionParams, Preferences,
};

/// Rows of $[J; D]$ (each scaled to unit length) whose component orthogonal to the
/// rows before it is shorter than this are dependent.
pub const RANK_TOLERANCE: f64 = 1e-10;

/// Pivot ratio of the equilibrated augmented matrix below which $M$ counts as singular
/// on the null space of $[J; D]$.
const MASS_TOLERANCE: f64 = 1e-13;

/// The result of one impulse solve.
#[derive(Clone, Debug, PartialEq)]
pub struct Impact {
    /// Time of the impact.
    pub t: f64,
    /// The contacts that struck (indices into [`Info::contacts`]).
    pub contacts: Vec<usize>,
    /// Their names.
    pub names: Vec<&'static str>,
    /// The normal impulse $\hat P$ of each contact of [`contacts`](Self::contacts)
    /// (positive: the contact pushes the gap open).
    pub impulses: Vec<f64>,
    /// Their normal velocities $v_n^-$ before the impact.
    pub normal_velocity_before: Vec<f64>,
    /// Their normal velocities $v_n^+$ after the impact.
    pub normal_velocity_after: Vec<f64>,
    /// The impulsive constraint reactions $\Lambda = [\Lambda_h; \Lambda_{nh}]$, one
    /// per named constraint of the model (holonomic first), in the sign convention of
    /// the multipliers (the generalized impulse of the constraints is
    /// $-J^\mathsf{T}\Lambda$).
    pub constraint_impulses: Vec<f64>,
    /// The coordinates at the impact.
    pub q: Vec<f64>,
    /// Velocities before.
    pub qd_before: Vec<f64>,
    /// Velocities after.
    pub qd_after: Vec<f64>,
    /// The finite multipliers (E31) at $(q, \dot q^-)$.
    pub lambda_before: Vec<f64>,
    /// The finite multipliers (E31) at $(q, \dot q^+)$.
    pub lambda_after: Vec<f64>,
    /// The accelerations (E31) at $(q, \dot q^-)$.
    pub qdd_before: Vec<f64>,
    /// The accelerations (E31) at $(q, \dot q^+)$.
    pub qdd_after: Vec<f64>,
    /// Kinetic energy before.
    pub kinetic_before: f64,
    /// Kinetic energy after.
    pub kinetic_after: f64,
}

impl Impact {
    /// $T^- - T^+$, the kinetic energy the impact dissipates.
    #[must_use]
    pub fn energy_lost(&self) -> f64 {
        self.kinetic_before - self.kinetic_after
    }

    /// The jump $\Delta\lambda = \lambda^+ - \lambda^-$ of the finite multipliers
    /// (docs/theory.md §multiplier-jump).
    #[must_use]
    pub fn multiplier_jump(&self) -> Vec<f64> {
        self.lambda_after
            .iter()
            .zip(&self.lambda_before)
            .map(|(a, b)| a - b)
            .collect()
    }

    /// The impulsive reaction $\Lambda$ of the constraint called `name`.
    #[must_use]
    pub fn constraint_impulse(&self, info: &Info, name: &str) -> Option<f64> {
        let i = info
            .holonomic
            .iter()
            .chain(info.nonholonomic)
            .position(|s| s.name == name)?;
        self.constraint_impulses.get(i).copied()
    }

    /// The normal impulse of the contact called `name`, if it struck.
    #[must_use]
    pub fn impulse(&self, name: &str) -> Option<f64> {
        let k = self.names.iter().position(|n| *n == name)?;
        Some(self.impulses[k])
    }
}

/// Errors of the impulse solve.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ImpactError {
    /// The rows of $[J; D]$ are dependent: the impulses are not determined.
    #[error(
        "impact at t = {t:?}: the constraints and contacts {} are dependent here (a singular \
         configuration), so the impulses are not determined",
        names(constraints)
    )]
    Singular {
        /// Time.
        t: f64,
        /// The constraints and contacts of the dependent set.
        constraints: Vec<&'static str>,
    },
    /// The mass matrix is singular on the null space of the constraints and contacts.
    #[error("impact at t = {t:?}: the mass matrix is singular on the constraints' null space (pivot ratio {ratio:e})")]
    SingularMass {
        /// Time.
        t: f64,
        /// Pivot ratio of the equilibrated augmented matrix.
        ratio: f64,
    },
    /// A coefficient of restitution outside $[0, 1]$.
    #[error("contact `{contact}`: coefficient of restitution {value} outside [0, 1]")]
    Restitution {
        /// The contact.
        contact: &'static str,
        /// The value.
        value: f64,
    },
    /// A contact index out of range, or none given.
    #[error("impact: no contact {index} in a model with {count} contacts")]
    NoContact {
        /// The index asked for.
        index: usize,
        /// The model's number of contacts.
        count: usize,
    },
    /// Evaluation of the model.
    #[error(transparent)]
    Eval(#[from] EvalError),
    /// The finite multipliers around the impact.
    #[error(transparent)]
    Dynamics(#[from] DynamicsError),
    /// Algorithm P for the partitioned form.
    #[error(transparent)]
    Partition(PartitionError),
}

fn names(v: &[&str]) -> String {
    let q: Vec<String> = v.iter().map(|s| format!("`{s}`")).collect();
    q.join(", ")
}

/// Scratch for the impulse solves of one model.
#[derive(Debug)]
pub struct ImpactSolver {
    info: &'static Info,
    ws: Workspace,
    dynamics: Dynamics,
    /// Dense $M$ ($n \times n$, row-major).
    mass: Vec<f64>,
    mass_values: Vec<f64>,
    d_values: Vec<f64>,
    /// Dense $D$ (contacts × $n$, row-major).
    d: Vec<f64>,
    rate: Vec<f64>,
    gaps: Vec<f64>,
    gamma: Vec<f64>,
    lu: DenseLu,
    x: Vec<f64>,
    /// Rows of $[J; D]$ for the rank test, and the orthonormal basis.
    rows: Vec<f64>,
}

impl ImpactSolver {
    /// Scratch for the model described by `info`.
    ///
    /// # Errors
    /// Malformed patterns of the model, or a failure to set up the augmented solve.
    pub fn new(info: &'static Info) -> Result<Self, crate::Error> {
        let (n, m, nc) = (info.nq(), info.nh() + info.nnh(), info.ncontacts());
        crate::workspace::check_pattern(
            info.name,
            Quantity::ContactJacobian,
            info.contact_pattern,
            nc,
            n,
        )?;
        let dim = n + m + nc;
        Ok(Self {
            info,
            ws: Workspace::new(info)?,
            dynamics: Dynamics::new(
                info,
                DynamicsParams {
                    redundant_tolerance: crate::sim::REDUNDANT_TOLERANCE,
                    ..DynamicsParams::default()
                },
            )?,
            mass: vec![0.0; n * n],
            mass_values: vec![0.0; info.mass_pattern.len()],
            d_values: vec![0.0; info.contact_pattern.len()],
            d: vec![0.0; nc * n],
            rate: vec![0.0; nc],
            gaps: vec![0.0; nc],
            gamma: vec![0.0; nc],
            lu: DenseLu::new(dim, 1),
            x: vec![0.0; dim],
            rows: vec![0.0; (m + nc) * n],
        })
    }

    /// The gaps $\delta(q, t)$ of every contact.
    ///
    /// # Errors
    /// A non-finite gap.
    pub fn gaps<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
    ) -> Result<&[f64], EvalError> {
        mech.contact_gaps(t, q, &mut self.gaps);
        check_finite(Quantity::ContactGaps, t, &self.gaps)?;
        Ok(&self.gaps)
    }

    /// The normal velocities $v_n = D\dot q + \delta_t$ of every contact, into `out`.
    ///
    /// # Errors
    /// A non-finite $D$ or $\delta_t$.
    pub fn normal_velocities<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
        qd: &[f64],
        out: &mut [f64],
    ) -> Result<(), EvalError> {
        self.eval_contacts(mech, t, q)?;
        let n = self.info.nq();
        for (c, o) in out.iter_mut().enumerate() {
            *o = self.rate[c] + dot(&self.d[c * n..(c + 1) * n], qd);
        }
        Ok(())
    }

    fn eval_contacts<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
    ) -> Result<(), EvalError> {
        let info = self.info;
        mech.contact_jacobian(t, q, &mut self.d_values);
        check_finite(Quantity::ContactJacobian, t, &self.d_values)?;
        scatter_row_major(info.contact_pattern, &self.d_values, info.nq(), &mut self.d);
        mech.contact_rate(t, q, &mut self.rate);
        check_finite(Quantity::ContactJacobian, t, &self.rate)?;
        Ok(())
    }

    fn check_contacts<M: Mechanism + ?Sized>(
        &self,
        mech: &M,
        contacts: &[usize],
    ) -> Result<(), ImpactError> {
        let info = self.info;
        for &c in contacts {
            let Some(contact) = info.contacts.get(c) else {
                return Err(ImpactError::NoContact {
                    index: c,
                    count: info.ncontacts(),
                });
            };
            let e = mech.parameter(contact.restitution as usize);
            if !(0.0..=1.0).contains(&e) {
                return Err(ImpactError::Restitution {
                    contact: contact.name,
                    value: e,
                });
            }
        }
        if contacts.is_empty() {
            return Err(ImpactError::NoContact {
                index: 0,
                count: info.ncontacts(),
            });
        }
        Ok(())
    }

    /// Evaluates $M$, $J$, $D$ and $\delta_t$ at $(t, q)$ and checks that the rows of
    /// $[J; D_\text{contacts}]$ are independent.
    fn evaluate<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
        contacts: &[usize],
    ) -> Result<(), ImpactError> {
        let info = self.info;
        let n = info.nq();
        mech.mass_matrix(t, q, &mut self.mass_values);
        check_finite(Quantity::MassMatrix, t, &self.mass_values)?;
        scatter_row_major(info.mass_pattern, &self.mass_values, n, &mut self.mass);
        self.ws.eval_jacobian(mech, t, q)?;
        self.eval_contacts(mech, t, q)?;
        self.rank_check(t, contacts)
    }

    /// Modified Gram–Schmidt over the rows of $[J; D_\text{contacts}]$, each scaled to
    /// unit length; a dependent row fails with the names of the rows of its
    /// combination.
    fn rank_check(&mut self, t: f64, contacts: &[usize]) -> Result<(), ImpactError> {
        let info = self.info;
        let (n, m) = (info.nq(), info.nh() + info.nnh());
        let k = m + contacts.len();
        let jac = self.ws.jacobian();
        for r in 0..k {
            let src = if r < m {
                &jac[r * n..(r + 1) * n]
            } else {
                let c = contacts[r - m];
                &self.d[c * n..(c + 1) * n]
            };
            self.rows[r * n..(r + 1) * n].copy_from_slice(src);
        }
        let mut dependent = None;
        for r in 0..k {
            let (done, rest) = self.rows.split_at_mut(r * n);
            let row = &mut rest[..n];
            let len = dot(row, row).sqrt();
            if len == 0.0 {
                dependent = Some(r);
                break;
            }
            row.iter_mut().for_each(|v| *v /= len);
            for p in 0..r {
                let b = &done[p * n..(p + 1) * n];
                let c = dot(row, b);
                row.iter_mut().zip(b).for_each(|(v, b)| *v -= c * b);
            }
            let res = dot(row, row).sqrt();
            if res < RANK_TOLERANCE {
                dependent = Some(r);
                break;
            }
            row.iter_mut().for_each(|v| *v /= res);
        }
        let Some(r) = dependent else {
            return Ok(());
        };
        // The combination: least squares of row r on the rows before it (allocates, on
        // the failure path only).
        let row_of = |i: usize| -> Vec<f64> {
            if i < m {
                jac[i * n..(i + 1) * n].to_vec()
            } else {
                let c = contacts[i - m];
                self.d[c * n..(c + 1) * n].to_vec()
            }
        };
        let target = row_of(r);
        let prev: Vec<Vec<f64>> = (0..r).map(row_of).collect();
        let mut gram = vec![0.0; r * r];
        let mut rhs = vec![0.0; r];
        for i in 0..r {
            rhs[i] = dot(&prev[i], &target);
            for j in 0..r {
                gram[i * r + j] = dot(&prev[i], &prev[j]);
            }
        }
        solve_dense(&mut gram, r, &mut rhs);
        let big = rhs.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        let name = |i: usize| -> &'static str {
            if i < info.nh() {
                info.holonomic[i].name
            } else if i < m {
                info.nonholonomic[i - info.nh()].name
            } else {
                info.contacts[contacts[i - m]].name
            }
        };
        let mut constraints: Vec<&'static str> = (0..r)
            .filter(|&i| rhs[i].is_finite() && rhs[i].abs() > 1e-8 * big)
            .map(name)
            .collect();
        constraints.push(name(r));
        Err(ImpactError::Singular { t, constraints })
    }

    /// The impulse solve in the augmented form (E41) for the striking `contacts`
    /// (simultaneous Newton restitution when there are several).
    ///
    /// # Errors
    /// See [`ImpactError`].
    pub fn solve<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
        qd: &[f64],
        contacts: &[usize],
    ) -> Result<Impact, ImpactError> {
        self.check_contacts(mech, contacts)?;
        crate::workspace::check_state(self.info, t, q, Some(qd))?;
        self.evaluate(mech, t, q, contacts)?;
        let info = self.info;
        let (n, m) = (info.nq(), info.nh() + info.nnh());
        let vn: Vec<f64> = contacts
            .iter()
            .map(|&c| self.rate[c] + dot(&self.d[c * n..(c + 1) * n], qd))
            .collect();
        self.fill_augmented(|c| contacts.contains(&c));
        let ratio = self.lu.factor().ratio();
        if ratio < MASS_TOLERANCE {
            return Err(ImpactError::SingularMass { t, ratio });
        }
        self.x.fill(0.0);
        for (k, &c) in contacts.iter().enumerate() {
            let e = mech.parameter(info.contacts[c].restitution as usize);
            self.x[n + m + c] = -(1.0 + e) * vn[k];
        }
        self.lu.solve_vec(&mut self.x);
        let qd_after: Vec<f64> = qd.iter().zip(&self.x[..n]).map(|(a, b)| a + b).collect();
        let constraint_impulses = self.x[n..n + m].to_vec();
        let impulses = contacts.iter().map(|&c| self.x[n + m + c]).collect();
        self.finish(
            mech,
            t,
            q,
            qd,
            qd_after,
            contacts,
            impulses,
            constraint_impulses,
            vn,
        )
    }

    /// The impulse solve in the partitioned form (E42), in the independent velocities
    /// of Algorithm P (allocates: a check of [`solve`](Self::solve) and an alternative
    /// to it).
    ///
    /// # Errors
    /// See [`ImpactError`].
    #[allow(clippy::too_many_lines)]
    pub fn solve_partitioned<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
        qd: &[f64],
        contacts: &[usize],
    ) -> Result<Impact, ImpactError> {
        self.check_contacts(mech, contacts)?;
        crate::workspace::check_state(self.info, t, q, Some(qd))?;
        self.evaluate(mech, t, q, contacts)?;
        let info = self.info;
        let (n, m) = (info.nq(), info.nh() + info.nnh());
        let p = Partition::compute(
            mech,
            &mut self.ws,
            t,
            q,
            Preferences::default(),
            &PartitionParams::default(),
        )
        .map_err(|e| match e {
            PartitionError::RedundantHolonomic { constraints, .. }
            | PartitionError::RedundantNonholonomic { constraints, .. } => {
                ImpactError::Singular { t, constraints }
            }
            other => ImpactError::Partition(other),
        })?;
        self.ws.eval_jacobian(mech, t, q)?;
        let jac = self.ws.jacobian().to_vec();
        let dep: Vec<usize> = p
            .dependent()
            .iter()
            .chain(p.dependent_velocity())
            .copied()
            .collect();
        let ind = p.independent().to_vec();
        let f = ind.len();
        debug_assert_eq!(dep.len(), m);
        // B_v (n × f): dependent velocities from J_d x_d = -J_γ.
        let mut bv = vec![0.0; n * f];
        for (k, &g) in ind.iter().enumerate() {
            let mut jd = vec![0.0; m * m];
            let mut rhs = vec![0.0; m];
            for r in 0..m {
                for (c, &dc) in dep.iter().enumerate() {
                    jd[r * m + c] = jac[r * n + dc];
                }
                rhs[r] = -jac[r * n + g];
            }
            solve_dense(&mut jd, m, &mut rhs);
            for (c, &dc) in dep.iter().enumerate() {
                bv[dc * f + k] = rhs[c];
            }
            bv[g * f + k] = 1.0;
        }
        // M̂ = Bᵀ M B and the contact rows D B.
        let mb = matmul(&self.mass, &bv, n, n, f);
        let mut mhat = vec![0.0; f * f];
        for i in 0..f {
            for j in 0..f {
                mhat[i * f + j] = (0..n).map(|r| bv[r * f + i] * mb[r * f + j]).sum();
            }
        }
        let k = contacts.len();
        let mut db = vec![0.0; k * f];
        for (a, &c) in contacts.iter().enumerate() {
            for j in 0..f {
                db[a * f + j] = (0..n).map(|r| self.d[c * n + r] * bv[r * f + j]).sum();
            }
        }
        // Y = M̂⁻¹ (D B)ᵀ (f × k), W = (D B) Y.
        let mut y = vec![0.0; f * k];
        for a in 0..k {
            let mut col: Vec<f64> = (0..f).map(|j| db[a * f + j]).collect();
            let mut mm = mhat.clone();
            solve_dense(&mut mm, f, &mut col);
            for j in 0..f {
                y[j * k + a] = col[j];
            }
        }
        let mut w = vec![0.0; k * k];
        for a in 0..k {
            for b in 0..k {
                w[a * k + b] = (0..f).map(|j| db[a * f + j] * y[j * k + b]).sum();
            }
        }
        let vn: Vec<f64> = contacts
            .iter()
            .map(|&c| self.rate[c] + dot(&self.d[c * n..(c + 1) * n], qd))
            .collect();
        let mut impulses: Vec<f64> = contacts
            .iter()
            .zip(&vn)
            .map(|(&c, v)| -(1.0 + mech.parameter(info.contacts[c].restitution as usize)) * v)
            .collect();
        solve_dense(&mut w, k, &mut impulses);
        let dgamma: Vec<f64> = (0..f)
            .map(|j| (0..k).map(|a| y[j * k + a] * impulses[a]).sum())
            .collect();
        let dqd: Vec<f64> = (0..n)
            .map(|r| (0..f).map(|j| bv[r * f + j] * dgamma[j]).sum())
            .collect();
        let qd_after: Vec<f64> = qd.iter().zip(&dqd).map(|(a, b)| a + b).collect();
        // J_dᵀ Λ = [Dᵀ P̂ − M Δq̇]_{β,η}.
        let mut jdt = vec![0.0; m * m];
        let mut rhs = vec![0.0; m];
        for (c, &dc) in dep.iter().enumerate() {
            for r in 0..m {
                jdt[c * m + r] = jac[r * n + dc];
            }
            let dp: f64 = contacts
                .iter()
                .zip(&impulses)
                .map(|(&ct, pi)| self.d[ct * n + dc] * pi)
                .sum();
            let mdq: f64 = (0..n).map(|j| self.mass[dc * n + j] * dqd[j]).sum();
            rhs[c] = dp - mdq;
        }
        solve_dense(&mut jdt, m, &mut rhs);
        self.finish(mech, t, q, qd, qd_after, contacts, impulses, rhs, vn)
    }

    /// Factors the augmented matrix of (E41) at $(t, q)$ with the rows of the contacts
    /// in `active` (identity rows for the others); allocation-free except on failure.
    fn factor_active<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
        active: &[bool],
    ) -> Result<(), ImpactError> {
        let info = self.info;
        let (n, nc) = (info.nq(), info.ncontacts());
        mech.mass_matrix(t, q, &mut self.mass_values);
        check_finite(Quantity::MassMatrix, t, &self.mass_values)?;
        scatter_row_major(info.mass_pattern, &self.mass_values, n, &mut self.mass);
        self.ws.eval_jacobian(mech, t, q)?;
        self.eval_contacts(mech, t, q)?;
        self.fill_augmented(|c| active[c]);
        let ratio = self.lu.factor().ratio();
        if ratio < MASS_TOLERANCE {
            let contacts: Vec<usize> = (0..nc).filter(|&c| active[c]).collect();
            self.rank_check(t, &contacts)?;
            return Err(ImpactError::SingularMass { t, ratio });
        }
        Ok(())
    }

    /// Writes the augmented matrix $[M\ {-D^\mathsf{T}}\ J^\mathsf{T}; J; D]$ of the
    /// impulse and resting-contact solves into `lu`, from the mass matrix, $J$ in the
    /// workspace and $D$ already evaluated; a contact for which `takes_part` is false
    /// keeps an identity row, so its unknown is 0.
    fn fill_augmented(&mut self, takes_part: impl Fn(usize) -> bool) {
        let info = self.info;
        let (n, m, nc) = (info.nq(), info.nh() + info.nnh(), info.ncontacts());
        let dim = n + m + nc;
        let jac = self.ws.jacobian();
        let mut a = self.lu.matrix_mut();
        for i in 0..dim {
            for j in 0..dim {
                a[(i, j)] = 0.0;
            }
        }
        for i in 0..n {
            for j in 0..n {
                a[(i, j)] = self.mass[i * n + j];
            }
        }
        for r in 0..m {
            for j in 0..n {
                let v = jac[r * n + j];
                a[(n + r, j)] = v;
                a[(j, n + r)] = v;
            }
        }
        for c in 0..nc {
            if takes_part(c) {
                for j in 0..n {
                    let v = self.d[c * n + j];
                    a[(n + m + c, j)] = v;
                    a[(j, n + m + c)] = -v;
                }
            } else {
                a[(n + m + c, n + m + c)] = 1.0;
            }
        }
    }

    /// Resting contact: corrects the accelerations `qdd` and multipliers `lambda` of
    /// the model's equations at $(t, q, \dot q)$ so that the contacts in `active` stay
    /// closed ($D\ddot q = \gamma_c$), and writes their normal forces $\nu$ into `nu`
    /// (positive: compressive; the generalized contact force is $D^\mathsf{T}\nu$).
    /// The correction is the least-action change of the accelerations:
    /// $[M\ J^\mathsf{T}\ {-D^\mathsf{T}};\ J\ 0\ 0;\ D\ 0\ 0]
    /// [\Delta\ddot q; \Delta\lambda; \nu] = [0; 0; \gamma_c - D\ddot q]$.
    /// Allocation-free.
    ///
    /// # Errors
    /// A failed evaluation, or a singular matrix.
    #[allow(clippy::too_many_arguments)]
    pub fn rest_correction<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &mut [f64],
        lambda: &mut [f64],
        active: &[bool],
        nu: &mut [f64],
    ) -> Result<(), ImpactError> {
        self.factor_active(mech, t, q, active)?;
        let info = self.info;
        let (n, m, nc) = (info.nq(), info.nh() + info.nnh(), info.ncontacts());
        mech.contact_gamma(t, q, qd, &mut self.gamma);
        check_finite(Quantity::ContactJacobian, t, &self.gamma)?;
        self.x.fill(0.0);
        for c in 0..nc {
            if active[c] {
                self.x[n + m + c] = self.gamma[c] - dot(&self.d[c * n..(c + 1) * n], qdd);
            }
        }
        self.lu.solve_vec(&mut self.x);
        for (a, d) in qdd.iter_mut().zip(&self.x[..n]) {
            *a += d;
        }
        for (l, d) in lambda.iter_mut().zip(&self.x[n..n + m]) {
            *l += d;
        }
        for c in 0..nc {
            nu[c] = if active[c] { self.x[n + m + c] } else { 0.0 };
        }
        Ok(())
    }

    /// Moves $(q, \dot q)$ back onto the contacts in `active` ($\delta = 0$,
    /// $v_n = 0$) by the least-action corrections that keep $J\Delta q = 0$ and
    /// $J\Delta\dot q = 0$ (one step for the positions: the drift between two steps
    /// is small). Allocation-free.
    ///
    /// # Errors
    /// A failed evaluation, or a singular matrix.
    pub fn project_rest<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &mut [f64],
        qd: &mut [f64],
        active: &[bool],
    ) -> Result<(), ImpactError> {
        let info = self.info;
        let (n, m, nc) = (info.nq(), info.nh() + info.nnh(), info.ncontacts());
        mech.contact_gaps(t, q, &mut self.gaps);
        check_finite(Quantity::ContactGaps, t, &self.gaps)?;
        self.factor_active(mech, t, q, active)?;
        self.x.fill(0.0);
        for c in 0..nc {
            if active[c] {
                self.x[n + m + c] = -self.gaps[c];
            }
        }
        self.lu.solve_vec(&mut self.x);
        for (a, d) in q.iter_mut().zip(&self.x[..n]) {
            *a += d;
        }
        self.factor_active(mech, t, q, active)?;
        self.x.fill(0.0);
        for c in 0..nc {
            if active[c] {
                let vn = self.rate[c] + dot(&self.d[c * n..(c + 1) * n], qd);
                self.x[n + m + c] = -vn;
            }
        }
        self.lu.solve_vec(&mut self.x);
        for (a, d) in qd.iter_mut().zip(&self.x[..n]) {
            *a += d;
        }
        Ok(())
    }

    /// The normal accelerations $\dot v_n = D\ddot q - \gamma_c$ of every contact at
    /// $(t, q, \dot q)$ with the accelerations `qdd`, into `out`.
    ///
    /// # Errors
    /// A non-finite $D$ or $\gamma_c$.
    pub fn normal_accelerations<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        out: &mut [f64],
    ) -> Result<(), EvalError> {
        self.eval_contacts(mech, t, q)?;
        mech.contact_gamma(t, q, qd, &mut self.gamma);
        check_finite(Quantity::ContactJacobian, t, &self.gamma)?;
        let n = self.info.nq();
        for (c, o) in out.iter_mut().enumerate() {
            *o = dot(&self.d[c * n..(c + 1) * n], qdd) - self.gamma[c];
        }
        Ok(())
    }

    #[allow(clippy::too_many_arguments)]
    fn finish<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qd_after: Vec<f64>,
        contacts: &[usize],
        impulses: Vec<f64>,
        constraint_impulses: Vec<f64>,
        vn: Vec<f64>,
    ) -> Result<Impact, ImpactError> {
        let info = self.info;
        let n = info.nq();
        check_finite(Quantity::Velocities, t, &qd_after)?;
        let m = info.nh() + info.nnh();
        let mut lambda_before = vec![0.0; m];
        let mut lambda_after = vec![0.0; m];
        let mut qdd_before = vec![0.0; n];
        let mut qdd_after = vec![0.0; n];
        self.dynamics.accelerations(
            mech,
            &mut self.ws,
            t,
            q,
            qd,
            &mut qdd_before,
            &mut lambda_before,
        )?;
        self.dynamics.accelerations(
            mech,
            &mut self.ws,
            t,
            q,
            &qd_after,
            &mut qdd_after,
            &mut lambda_after,
        )?;
        let normal_velocity_after = contacts
            .iter()
            .map(|&c| self.rate[c] + dot(&self.d[c * n..(c + 1) * n], &qd_after))
            .collect();
        Ok(Impact {
            t,
            contacts: contacts.to_vec(),
            names: contacts.iter().map(|&c| info.contacts[c].name).collect(),
            impulses,
            normal_velocity_before: vn,
            normal_velocity_after,
            constraint_impulses,
            q: q.to_vec(),
            kinetic_before: mech.kinetic_energy(t, q, qd),
            kinetic_after: mech.kinetic_energy(t, q, &qd_after),
            qd_before: qd.to_vec(),
            qd_after,
            lambda_before,
            lambda_after,
            qdd_before,
            qdd_after,
        })
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `a (r × k) · b (k × c)`, row-major.
fn matmul(a: &[f64], b: &[f64], r: usize, k: usize, c: usize) -> Vec<f64> {
    let mut out = vec![0.0; r * c];
    for i in 0..r {
        for l in 0..k {
            let v = a[i * k + l];
            if v != 0.0 {
                for j in 0..c {
                    out[i * c + j] += v * b[l * c + j];
                }
            }
        }
    }
    out
}

/// Solves `a x = b` in place (Gaussian elimination with partial pivoting; `a` is
/// destroyed). A zero pivot leaves non-finite values, which the callers check.
fn solve_dense(a: &mut [f64], n: usize, b: &mut [f64]) {
    for k in 0..n {
        let p = (k..n)
            .max_by(|&i, &j| a[i * n + k].abs().total_cmp(&a[j * n + k].abs()))
            .unwrap_or(k);
        if p != k {
            for j in 0..n {
                a.swap(k * n + j, p * n + j);
            }
            b.swap(k, p);
        }
        let piv = a[k * n + k];
        for i in k + 1..n {
            let f = a[i * n + k] / piv;
            if f != 0.0 {
                for j in k..n {
                    a[i * n + j] -= f * a[k * n + j];
                }
                b[i] -= f * b[k];
            }
        }
    }
    for k in (0..n).rev() {
        let s: f64 = (k + 1..n).map(|j| a[k * n + j] * b[j]).sum();
        b[k] = (b[k] - s) / a[k * n + k];
    }
}
