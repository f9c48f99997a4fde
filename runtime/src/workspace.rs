//! Per-model buffers and checked evaluation of the generated functions.
//!
//! Input: a [`Mechanism`] and its [`Info`]. Output: the values of $M$, $Q$, $C$,
//! $C_q$, $C_t$, $G$, $g$ and $\gamma = [\gamma_h; \gamma_{nh}]$ in buffers owned by
//! [`Workspace`], with $J = [C_q; G]$ also scattered into a dense row-major
//! $m \times n$ array. Every evaluation checks that its output is finite and reports the
//! first offending entry as an [`EvalError`].
//!
//! Invariant: all buffers are allocated in [`Workspace::new`]; evaluations never
//! allocate. A workspace may be shared by [`Kinematics`](crate::Kinematics) and
//! [`Dynamics`](crate::Dynamics) of the same model.

use std::fmt;

use crate::{Info, Mechanism, Pattern};

/// A quantity computed by the model or by the runtime, named in error messages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// Input coordinates `q`.
    Coordinates,
    /// Input velocities `q̇`.
    Velocities,
    /// Input time `t`.
    Time,
    /// The mass matrix `M`.
    MassMatrix,
    /// The generalized forces `Q`.
    Forces,
    /// The holonomic constraints `C`.
    Constraints,
    /// The holonomic Jacobian `C_q`.
    HolonomicJacobian,
    /// The time partial `C_t`.
    HolonomicRate,
    /// `γ_h`.
    HolonomicGamma,
    /// The non-holonomic matrix `G`.
    NonholonomicMatrix,
    /// The non-holonomic bias `g`.
    NonholonomicBias,
    /// `γ_nh`.
    NonholonomicGamma,
    /// Computed accelerations `q̈`.
    Accelerations,
    /// Computed multipliers `λ`.
    Multipliers,
    /// The contact gaps.
    ContactGaps,
    /// The contact normal Jacobian `D` (or the gaps' time partials).
    ContactJacobian,
}

impl fmt::Display for Quantity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Coordinates => "coordinates `q`",
            Self::Velocities => "velocities `q'`",
            Self::Time => "time `t`",
            Self::MassMatrix => "mass matrix `M`",
            Self::Forces => "generalized forces `Q`",
            Self::Constraints => "holonomic constraints `C`",
            Self::HolonomicJacobian => "holonomic Jacobian `C_q`",
            Self::HolonomicRate => "time partial `C_t`",
            Self::HolonomicGamma => "holonomic acceleration term `gamma_h`",
            Self::NonholonomicMatrix => "non-holonomic matrix `G`",
            Self::NonholonomicBias => "non-holonomic bias `g`",
            Self::NonholonomicGamma => "non-holonomic acceleration term `gamma_nh`",
            Self::Accelerations => "accelerations `q''`",
            Self::Multipliers => "multipliers `lambda`",
            Self::ContactGaps => "contact gaps",
            Self::ContactJacobian => "contact normal Jacobian `D`",
        })
    }
}

/// Errors of evaluation and of model description.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EvalError {
    /// A value is NaN or infinite. `row`/`col` locate it (`col` only for matrices).
    #[error("non-finite {quantity} at t = {t:?}: entry ({row}{}) is {value}", col.map(|c| format!(", {c}")).unwrap_or_default())]
    NonFinite {
        /// The offending quantity.
        quantity: Quantity,
        /// Time of the evaluation.
        t: f64,
        /// Row (or vector index).
        row: usize,
        /// Column, for matrices.
        col: Option<usize>,
        /// The value found.
        value: f64,
    },
    /// A buffer passed by the caller has the wrong length.
    #[error("{quantity} has length {found}, expected {expected}")]
    Length {
        /// Which buffer.
        quantity: Quantity,
        /// Its length.
        found: usize,
        /// The length the model requires.
        expected: usize,
    },
    /// The model passed is not the one the workspace (or analysis) was made for.
    #[error("the model passed (`{found}`) is not the one the workspace or analysis was made for (`{expected}`): different name, sizes or sparsity patterns")]
    Model {
        /// The model of the workspace.
        expected: &'static str,
        /// The model passed.
        found: &'static str,
    },
    /// A sparsity pattern of the model is malformed.
    #[error("pattern of the {quantity} of model `{model}`: entry #{entry} {reason}")]
    Pattern {
        /// The model's name.
        model: &'static str,
        /// Which pattern.
        quantity: Quantity,
        /// Index of the bad entry.
        entry: usize,
        /// What is wrong with it.
        reason: PatternDefect,
    },
}

/// What is wrong with a pattern entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PatternDefect {
    /// Row or column out of range.
    OutOfRange,
    /// Not sorted by row then column, or duplicated.
    Unsorted,
}

impl fmt::Display for PatternDefect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::OutOfRange => "is out of range",
            Self::Unsorted => "is not sorted by row then column, or is duplicated",
        })
    }
}

/// Adds $0 \cdot x_i$ for every entry of `x` into the four lanes of `acc`: a lane stays
/// $\pm 0$ while the entries are finite and turns NaN at the first NaN or infinite
/// one, and stays NaN. One pass without branches, two vector operations per four
/// entries (a search for the first offender, [`check_finite`], is a loop with an exit
/// per entry); [`finite_lanes`] reads the verdict.
#[inline]
pub(crate) fn accumulate_finite(acc: &mut [f64; 4], x: &[f64]) {
    accumulate(acc, x, |v| v * 0.0);
}

/// Adds every entry of `x` into the four lanes of `acc`: once an entry is NaN or
/// infinite its lane stays NaN or infinite (finite entries may overflow a lane too).
/// One operation per two entries, where [`accumulate_finite`] takes two; for checks
/// whose failure only starts an exact search ([`Workspace::check_dynamics_terms`]).
#[inline]
pub(crate) fn accumulate_sum(acc: &mut [f64; 4], x: &[f64]) {
    accumulate(acc, x, |v| v);
}

/// Adds `term(x_i)` for every entry of `x` into the four lanes of `acc`, the remainder
/// first.
#[inline(always)]
fn accumulate(acc: &mut [f64; 4], x: &[f64], term: impl Fn(f64) -> f64) {
    let chunks = x.chunks_exact(4);
    for (a, &v) in acc.iter_mut().zip(chunks.remainder()) {
        *a += term(v);
    }
    for c in chunks {
        for (a, &v) in acc.iter_mut().zip(c) {
            *a += term(v);
        }
    }
}

/// Whether every entry [`accumulate_finite`] added into `acc` was finite.
#[inline]
pub(crate) fn finite_lanes(acc: &[f64; 4]) -> bool {
    (acc[0] + acc[1]) + (acc[2] + acc[3]) == 0.0
}

/// Whether every entry of `x` is finite ([`accumulate_finite`]).
#[inline]
pub(crate) fn all_finite(x: &[f64]) -> bool {
    let mut acc = [0.0; 4];
    accumulate_finite(&mut acc, x);
    finite_lanes(&acc)
}

/// Checks that every entry of `x` is finite.
pub(crate) fn check_finite(quantity: Quantity, t: f64, x: &[f64]) -> Result<(), EvalError> {
    check_finite_from(quantity, t, x, 0)
}

/// [`check_finite`] for the rows `first..` of a vector (the non-holonomic rows of
/// $\gamma$ after its `first` holonomic ones): an error names the row in the whole.
fn check_finite_from(quantity: Quantity, t: f64, x: &[f64], first: usize) -> Result<(), EvalError> {
    match x.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(k) => Err(EvalError::NonFinite {
            quantity,
            t,
            row: first + k,
            col: None,
            value: x[k],
        }),
    }
}

/// Checks that every pattern value is finite.
fn check_finite_pattern(
    quantity: Quantity,
    t: f64,
    pattern: Pattern,
    x: &[f64],
) -> Result<(), EvalError> {
    match x.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(k) => Err(EvalError::NonFinite {
            quantity,
            t,
            row: pattern[k].0 as usize,
            col: Some(pattern[k].1 as usize),
            value: x[k],
        }),
    }
}

/// Checks a caller buffer length.
pub(crate) fn check_len(quantity: Quantity, x: &[f64], expected: usize) -> Result<(), EvalError> {
    if x.len() == expected {
        Ok(())
    } else {
        Err(EvalError::Length {
            quantity,
            found: x.len(),
            expected,
        })
    }
}

/// Checks the input time, coordinates and (optionally) velocities of an evaluation.
/// `found` is the model described by `expected` (the same `Info`, or one with the same
/// name and shapes): the buffers sized by one fit the functions of the other.
pub(crate) fn check_same_model(expected: &Info, found: &Info) -> Result<(), EvalError> {
    let (a, b) = (expected, found);
    let same = std::ptr::eq(a, b)
        || (a.name == b.name
            && a.nq() == b.nq()
            && a.nh() == b.nh()
            && a.nnh() == b.nnh()
            && a.mass_pattern.len() == b.mass_pattern.len()
            && a.holonomic_pattern.len() == b.holonomic_pattern.len()
            && a.nonholonomic_pattern.len() == b.nonholonomic_pattern.len());
    if same {
        Ok(())
    } else {
        Err(EvalError::Model {
            expected: a.name,
            found: b.name,
        })
    }
}

pub(crate) fn check_state(
    info: &Info,
    t: f64,
    q: &[f64],
    qd: Option<&[f64]>,
) -> Result<(), EvalError> {
    if !t.is_finite() {
        return Err(EvalError::NonFinite {
            quantity: Quantity::Time,
            t,
            row: 0,
            col: None,
            value: t,
        });
    }
    check_len(Quantity::Coordinates, q, info.nq())?;
    check_finite(Quantity::Coordinates, t, q)?;
    if let Some(qd) = qd {
        check_len(Quantity::Velocities, qd, info.nq())?;
        check_finite(Quantity::Velocities, t, qd)?;
    }
    Ok(())
}

pub(crate) fn check_pattern(
    model: &'static str,
    quantity: Quantity,
    pattern: Pattern,
    rows: usize,
    cols: usize,
) -> Result<(), EvalError> {
    let bad = |entry, reason| EvalError::Pattern {
        model,
        quantity,
        entry,
        reason,
    };
    for (k, &(r, c)) in pattern.iter().enumerate() {
        if r as usize >= rows || c as usize >= cols {
            return Err(bad(k, PatternDefect::OutOfRange));
        }
        if k > 0 && pattern[k - 1] >= (r, c) {
            return Err(bad(k, PatternDefect::Unsorted));
        }
    }
    Ok(())
}

/// Writes the pattern `values` into the dense row-major `rows × ncols` array `out`
/// (zeroing it first).
pub fn scatter_row_major(pattern: Pattern, values: &[f64], ncols: usize, out: &mut [f64]) {
    out.fill(0.0);
    for (&(r, c), &v) in pattern.iter().zip(values) {
        out[r as usize * ncols + c as usize] = v;
    }
}

/// The correction of the velocities inside a fused evaluation of the dynamics terms
/// ([`Workspace::eval_dynamics_terms_corrected`]): `correct(cq, g, ct, bias, qd)` reads
/// the pattern values of $C_q$ and $G$ and the rates $C_t$, $g$ at the point and may
/// change the velocities `qd` before the terms that depend on them are evaluated.
pub type VelocityCorrection<'a> = dyn FnMut(&[f64], &[f64], &[f64], &[f64], &mut [f64]) + 'a;

/// Buffers for one model, allocated once.
#[derive(Debug, Clone)]
pub struct Workspace {
    info: &'static Info,
    pub(crate) mass_values: Vec<f64>,
    pub(crate) cq_values: Vec<f64>,
    pub(crate) g_values: Vec<f64>,
    /// Dense row-major `m × n` array of $J = [C_q; G]$. Only
    /// [`scatter_jacobian`](Self::scatter_jacobian) writes it, at the entries of the
    /// patterns: the others stay the zeros of the allocation.
    pub(crate) jacobian: Vec<f64>,
    pub(crate) c: Vec<f64>,
    pub(crate) ct: Vec<f64>,
    pub(crate) bias: Vec<f64>,
    /// $[\gamma_h; \gamma_{nh}]$ (length $m$).
    pub(crate) gamma: Vec<f64>,
    pub(crate) forces: Vec<f64>,
    /// The row norms of $C_q$ of [`constraints_and_row_norms`](Self::constraints_and_row_norms).
    row_norms: Vec<f64>,
}

impl Workspace {
    /// Allocates the buffers of the model described by `info`, after checking its
    /// patterns.
    pub fn new(info: &'static Info) -> Result<Self, EvalError> {
        let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
        check_pattern(info.name, Quantity::MassMatrix, info.mass_pattern, n, n)?;
        check_pattern(
            info.name,
            Quantity::HolonomicJacobian,
            info.holonomic_pattern,
            mh,
            n,
        )?;
        check_pattern(
            info.name,
            Quantity::NonholonomicMatrix,
            info.nonholonomic_pattern,
            mnh,
            n,
        )?;
        Ok(Self {
            info,
            mass_values: vec![0.0; info.mass_pattern.len()],
            cq_values: vec![0.0; info.holonomic_pattern.len()],
            g_values: vec![0.0; info.nonholonomic_pattern.len()],
            jacobian: vec![0.0; (mh + mnh) * n],
            c: vec![0.0; mh],
            ct: vec![0.0; mh],
            bias: vec![0.0; mnh],
            gamma: vec![0.0; mh + mnh],
            forces: vec![0.0; n],
            row_norms: vec![0.0; mh],
        })
    }

    /// The model description.
    #[must_use]
    pub fn info(&self) -> &'static Info {
        self.info
    }

    /// The output slices of the fused evaluation ($C$ only when `constraints`), and the
    /// rates $C_t$, $g$ beside them (read by the correction of
    /// [`eval_dynamics_terms_corrected`](Self::eval_dynamics_terms_corrected)).
    fn dynamics_outputs(
        &mut self,
        constraints: bool,
    ) -> (crate::DynamicsTerms<'_>, (&[f64], &[f64])) {
        let (gamma_h, gamma_nh) = self.gamma.split_at_mut(self.info.nh());
        let terms = crate::DynamicsTerms {
            holonomic: constraints.then_some(&mut self.c[..]),
            mass: &mut self.mass_values,
            forces: &mut self.forces,
            holonomic_jacobian: &mut self.cq_values,
            holonomic_gamma: gamma_h,
            nonholonomic_matrix: &mut self.g_values,
            nonholonomic_gamma: gamma_nh,
        };
        (terms, (&self.ct, &self.bias))
    }

    /// The model passed has the description this workspace was made for (same
    /// `Info`, or one with the same name and shapes), so that its functions write
    /// buffers of the sizes reserved here; `q` (and `qd`) have its length.
    fn check_model<M: Mechanism + ?Sized>(
        &self,
        mech: &M,
        q: &[f64],
        qd: Option<&[f64]>,
    ) -> Result<(), EvalError> {
        let a = self.info;
        check_same_model(a, mech.info())?;
        check_len(Quantity::Coordinates, q, a.nq())?;
        if let Some(qd) = qd {
            check_len(Quantity::Velocities, qd, a.nq())?;
        }
        Ok(())
    }

    /// Evaluates the pattern values of $C_q$ and $G$ and scatters them into the dense
    /// $J$ ([`Workspace::jacobian`]).
    pub fn eval_jacobian<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
    ) -> Result<(), EvalError> {
        self.check_model(mech, q, None)?;
        self.eval_jacobian_values(mech, t, q)?;
        self.scatter_jacobian();
        Ok(())
    }

    /// Evaluates the pattern values of $C_q$ and $G$ only.
    pub fn eval_jacobian_values<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
    ) -> Result<(), EvalError> {
        self.check_model(mech, q, None)?;
        let info = self.info;
        if info.nh() > 0 {
            mech.holonomic_jacobian(t, q, &mut self.cq_values);
            check_finite_pattern(
                Quantity::HolonomicJacobian,
                t,
                info.holonomic_pattern,
                &self.cq_values,
            )?;
        }
        self.eval_nonholonomic_matrix(mech, t, q)
    }

    /// Evaluates the pattern values of $G$ (nothing without non-holonomic rows).
    fn eval_nonholonomic_matrix<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
    ) -> Result<(), EvalError> {
        let info = self.info;
        if info.nnh() > 0 {
            mech.nonholonomic_matrix(t, q, &mut self.g_values);
            check_finite_pattern(
                Quantity::NonholonomicMatrix,
                t,
                info.nonholonomic_pattern,
                &self.g_values,
            )?;
        }
        Ok(())
    }

    /// Evaluates $C(q,t)$.
    pub fn eval_constraints<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
    ) -> Result<(), EvalError> {
        self.check_model(mech, q, None)?;
        if self.info.nh() > 0 {
            mech.holonomic(t, q, &mut self.c);
            check_finite(Quantity::Constraints, t, &self.c)?;
        }
        Ok(())
    }

    /// Evaluates $C(q,t)$ and the pattern values of $C_q$ and $G$, $C$ and $C_q$ in one
    /// call of the model's fused
    /// [`holonomic_with_jacobian`](Mechanism::holonomic_with_jacobian) (the dense $J$
    /// is not scattered).
    pub fn eval_constraints_with_jacobian<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
    ) -> Result<(), EvalError> {
        self.check_model(mech, q, None)?;
        let info = self.info;
        if info.nh() > 0 {
            mech.holonomic_with_jacobian(t, q, &mut self.c, &mut self.cq_values);
            check_finite(Quantity::Constraints, t, &self.c)?;
            check_finite_pattern(
                Quantity::HolonomicJacobian,
                t,
                info.holonomic_pattern,
                &self.cq_values,
            )?;
        }
        self.eval_nonholonomic_matrix(mech, t, q)
    }

    /// Evaluates $C_t$ and $g$ (nothing for a model with neither: both stay the zeros
    /// of the allocation).
    pub fn eval_rates<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
    ) -> Result<(), EvalError> {
        self.check_model(mech, q, None)?;
        let info = self.info;
        let holonomic = info.nh() > 0 && info.time.holonomic;
        let nonholonomic = info.nnh() > 0 && !info.nonholonomic_homogeneous;
        if !(holonomic || nonholonomic) {
            // Both zero, as allocated: only this writes them.
            return Ok(());
        }
        if holonomic {
            mech.holonomic_rate(t, q, &mut self.ct);
            check_finite(Quantity::HolonomicRate, t, &self.ct)?;
        } else {
            self.ct.fill(0.0);
        }
        if nonholonomic {
            mech.nonholonomic_bias(t, q, &mut self.bias);
            check_finite(Quantity::NonholonomicBias, t, &self.bias)?;
        } else {
            self.bias.fill(0.0);
        }
        Ok(())
    }

    /// Evaluates $\gamma = [\gamma_h; \gamma_{nh}]$.
    pub fn eval_gamma<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
        qd: &[f64],
    ) -> Result<(), EvalError> {
        self.check_model(mech, q, Some(qd))?;
        let mh = self.info.nh();
        let (h, nh) = self.gamma.split_at_mut(mh);
        if mh > 0 {
            mech.holonomic_gamma(t, q, qd, h);
            check_finite(Quantity::HolonomicGamma, t, h)?;
        }
        if !nh.is_empty() {
            mech.nonholonomic_gamma(t, q, qd, nh);
            check_finite_from(Quantity::NonholonomicGamma, t, nh, mh)?;
        }
        Ok(())
    }

    /// Evaluates the pattern values of $M$ and the forces $Q$.
    pub fn eval_mass_and_forces<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
        qd: &[f64],
    ) -> Result<(), EvalError> {
        self.check_model(mech, q, Some(qd))?;
        mech.mass_matrix(t, q, &mut self.mass_values);
        check_finite_pattern(
            Quantity::MassMatrix,
            t,
            self.info.mass_pattern,
            &self.mass_values,
        )?;
        mech.forces(t, q, qd, &mut self.forces);
        check_finite(Quantity::Forces, t, &self.forces)
    }

    /// Evaluates, in one call of the model's fused
    /// [`dynamics_terms`](Mechanism::dynamics_terms), the pattern values of $M$, $C_q$
    /// and $G$, the forces $Q$ and $\gamma = [\gamma_h; \gamma_{nh}]$ (the dense $J$ is
    /// not scattered; $C$ is not evaluated).
    pub fn eval_dynamics_terms<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
        qd: &[f64],
    ) -> Result<(), EvalError> {
        self.eval_dynamics_terms_with(mech, t, q, qd, false)
    }

    /// [`eval_dynamics_terms`](Self::eval_dynamics_terms), and $C$ from the same call
    /// when `constraints` ([`constraints`](Self::constraints); its finiteness is left
    /// to the caller). Without it, the $C$ held here is not written.
    pub fn eval_dynamics_terms_with<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
        qd: &[f64],
        constraints: bool,
    ) -> Result<(), EvalError> {
        self.check_model(mech, q, Some(qd))?;
        self.eval_dynamics_terms_unchecked(mech, t, q, qd, constraints);
        self.check_dynamics_terms(t)
    }

    /// [`eval_dynamics_terms_with`](Self::eval_dynamics_terms_with) for a caller that
    /// holds the model this workspace was made for and coordinates of its length (the
    /// simulation's point, which builds both from the model once: no check of the
    /// model, a call through `dyn Mechanism` and three comparisons per evaluation), and
    /// without the check of the terms, for a caller that checks them with
    /// [`check_dynamics_terms`](Self::check_dynamics_terms) before anything but the
    /// model's generated solve reads them (which declines, or leaves a non-finite
    /// entry in its solution, whenever an input is not finite: see
    /// `sim::point::Point::accelerations`).
    #[inline]
    pub(crate) fn eval_dynamics_terms_unchecked<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
        qd: &[f64],
        constraints: bool,
    ) {
        debug_assert!(self.check_model(mech, q, Some(qd)).is_ok());
        let (terms, _) = self.dynamics_outputs(constraints);
        mech.dynamics_terms(t, q, qd, terms);
    }

    /// [`eval_dynamics_terms`](Self::eval_dynamics_terms) through
    /// [`Mechanism::dynamics_terms_corrected`]: `correct(cq, g, ct, bias, qd)` may change
    /// `qd` between the position terms and the velocity terms; the rates $C_t$, $g$ it
    /// reads must have been evaluated at `(t, q)` ([`eval_rates`](Self::eval_rates)).
    /// $C$ at `(t, q)` too when `constraints`, as in
    /// [`eval_dynamics_terms_with`](Self::eval_dynamics_terms_with).
    pub fn eval_dynamics_terms_corrected<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
        qd: &mut [f64],
        constraints: bool,
        correct: &mut VelocityCorrection<'_>,
    ) -> Result<(), EvalError> {
        self.check_model(mech, q, Some(qd))?;
        self.eval_dynamics_terms_corrected_unchecked(mech, t, q, qd, constraints, correct);
        self.check_dynamics_terms(t)
    }

    /// [`eval_dynamics_terms_corrected`](Self::eval_dynamics_terms_corrected) for the
    /// simulation's point, without the checks: the model's (see
    /// [`eval_dynamics_terms_unchecked`](Self::eval_dynamics_terms_unchecked)) and the
    /// terms'. `correct` reads $C_q$ and $G$ unchecked (a generated projection declines
    /// on a non-finite entry; the runtime's iteration may leave non-finite velocities
    /// and report no convergence), and the caller checks the terms before anything
    /// else but the model's generated solve reads them.
    #[inline]
    pub(crate) fn eval_dynamics_terms_corrected_unchecked<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
        t: f64,
        q: &[f64],
        qd: &mut [f64],
        constraints: bool,
        correct: &mut VelocityCorrection<'_>,
    ) {
        debug_assert!(self.check_model(mech, q, Some(qd)).is_ok());
        let (terms, (ct, bias)) = self.dynamics_outputs(constraints);
        mech.dynamics_terms_corrected(t, q, qd, terms, &mut |cq, g, qd| {
            correct(cq, g, ct, bias, qd);
        });
    }

    /// The finiteness checks of the dynamics terms: one branch-free pass that sums every
    /// output into four lanes ([`accumulate_sum`]), and the scan that names the quantity
    /// and the entry only after the sum is not finite. A NaN or an infinite entry
    /// makes its lane, and so the sum, NaN or infinite for good; finite entries whose
    /// sum overflows only cost the scan, which then finds nothing.
    #[inline]
    pub(crate) fn check_dynamics_terms(&self, t: f64) -> Result<(), EvalError> {
        let mut acc = [0.0; 4];
        for x in [
            &self.mass_values,
            &self.forces,
            &self.cq_values,
            &self.g_values,
            &self.gamma,
        ] {
            accumulate_sum(&mut acc, x);
        }
        if ((acc[0] + acc[1]) + (acc[2] + acc[3])).is_finite() {
            Ok(())
        } else {
            self.locate_non_finite_terms(t)
        }
    }

    /// The first non-finite entry of the dynamics terms, as an error (`Ok` when there
    /// is none).
    #[cold]
    #[inline(never)]
    fn locate_non_finite_terms(&self, t: f64) -> Result<(), EvalError> {
        let info = self.info;
        let mh = info.nh();
        check_finite_pattern(
            Quantity::MassMatrix,
            t,
            info.mass_pattern,
            &self.mass_values,
        )?;
        check_finite(Quantity::Forces, t, &self.forces)?;
        check_finite_pattern(
            Quantity::HolonomicJacobian,
            t,
            info.holonomic_pattern,
            &self.cq_values,
        )?;
        check_finite_pattern(
            Quantity::NonholonomicMatrix,
            t,
            info.nonholonomic_pattern,
            &self.g_values,
        )?;
        check_finite(Quantity::HolonomicGamma, t, &self.gamma[..mh])?;
        check_finite_from(Quantity::NonholonomicGamma, t, &self.gamma[mh..], mh)
    }

    /// Scatters the pattern values of $C_q$ and $G$ into the dense $J$: only the
    /// entries of the patterns are written, the others are zero since the allocation
    /// and nothing writes them (see [`Workspace::jacobian`]'s field).
    pub(crate) fn scatter_jacobian(&mut self) {
        let n = self.info.nq();
        let (h, nh) = self.jacobian.split_at_mut(self.info.nh() * n);
        for (pattern, values, out) in [
            (self.info.holonomic_pattern, &self.cq_values, h),
            (self.info.nonholonomic_pattern, &self.g_values, nh),
        ] {
            for (&(r, c), &v) in pattern.iter().zip(values) {
                out[r as usize * n + c as usize] = v;
            }
        }
    }

    /// The dense row-major $J = [C_q; G]$ of the last [`Workspace::eval_jacobian`].
    #[must_use]
    pub fn jacobian(&self) -> &[f64] {
        &self.jacobian
    }

    /// $C$ of the last [`Workspace::eval_constraints`] and the row norms of the $C_q$
    /// held in the pattern values, by the model's generated
    /// [`Mechanism::holonomic_row_norms`] or else the runtime's walk of the pattern
    /// ([`scale::pattern_row_norms`](crate::scale)): what the projections' convergence
    /// tests read, without the dense $C_q$.
    pub(crate) fn constraints_and_row_norms<M: Mechanism + ?Sized>(
        &mut self,
        mech: &M,
    ) -> (&[f64], &[f64]) {
        if !mech.holonomic_row_norms(&self.cq_values, &mut self.row_norms) {
            crate::scale::pattern_row_norms(
                self.info.holonomic_pattern,
                &self.cq_values,
                &mut self.row_norms,
            );
        }
        (&self.c, &self.row_norms)
    }

    /// $C$ of the last [`Workspace::eval_constraints`].
    #[must_use]
    pub fn constraints(&self) -> &[f64] {
        &self.c
    }

    /// $[\gamma_h; \gamma_{nh}]$ of the last [`Workspace::eval_gamma`].
    #[must_use]
    pub fn gamma(&self) -> &[f64] {
        &self.gamma
    }

    /// $Q$ of the last [`Workspace::eval_mass_and_forces`].
    #[must_use]
    pub fn forces(&self) -> &[f64] {
        &self.forces
    }
}

#[cfg(test)]
mod tests {
    use std::cell::Cell;

    use super::*;
    use crate::{DynamicsTerms, Symbol};

    /// Three coordinates, one holonomic and one non-holonomic row, every output of the
    /// dynamics terms 1 except the entry `poison` names (output index, entry), set to
    /// the value `bad`.
    struct Poisoned {
        poison: Cell<(usize, usize)>,
        bad: Cell<f64>,
    }

    const SYMBOL: Symbol = Symbol { name: "s", doc: "" };

    static INFO: Info = Info {
        name: "poisoned",
        coordinates: &[SYMBOL, SYMBOL, SYMBOL],
        holonomic: &[SYMBOL],
        nonholonomic: &[SYMBOL],
        mass_pattern: &[(0, 0), (0, 2), (1, 1), (2, 0), (2, 2)],
        holonomic_pattern: &[(0, 0), (0, 1), (0, 2)],
        nonholonomic_pattern: &[(0, 1), (0, 2)],
        ..Info::EMPTY
    };

    impl Mechanism for Poisoned {
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
            out.fill(1.0);
        }
        fn kinetic_energy(&self, _: f64, _: &[f64], _: &[f64]) -> f64 {
            0.0
        }
        fn dynamics_terms(&self, _: f64, _: &[f64], _: &[f64], out: DynamicsTerms<'_>) {
            let outputs = [
                out.mass,
                out.forces,
                out.holonomic_jacobian,
                out.holonomic_gamma,
                out.nonholonomic_matrix,
                out.nonholonomic_gamma,
                out.holonomic.unwrap_or_default(),
            ];
            let (which, entry) = self.poison.get();
            for (k, x) in outputs.into_iter().enumerate() {
                x.fill(1.0);
                if k == which {
                    x[entry] = self.bad.get();
                }
            }
        }
    }

    /// The one-pass check of the dynamics terms finds a NaN or an infinity in any entry
    /// of any output the solve reads, and the error names the quantity, the entry
    /// (row and column of a matrix, from its pattern; γ_nh's row after γ_h's) and the
    /// time, as the entry-by-entry scan did.
    #[test]
    fn every_non_finite_dynamics_term_is_located() {
        let mech = Poisoned {
            poison: Cell::new((usize::MAX, 0)),
            bad: Cell::new(f64::NAN),
        };
        let mut ws = Workspace::new(&INFO).unwrap();
        let (q, qd) = ([0.0; 3], [0.0; 3]);
        assert_eq!(ws.eval_dynamics_terms(&mech, 0.5, &q, &qd), Ok(()));
        let outputs = [
            (Quantity::MassMatrix, INFO.mass_pattern.len()),
            (Quantity::Forces, 3),
            (Quantity::HolonomicJacobian, INFO.holonomic_pattern.len()),
            (Quantity::HolonomicGamma, 1),
            (
                Quantity::NonholonomicMatrix,
                INFO.nonholonomic_pattern.len(),
            ),
            (Quantity::NonholonomicGamma, 1),
        ];
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            mech.bad.set(bad);
            for (which, &(quantity, len)) in outputs.iter().enumerate() {
                for entry in 0..len {
                    mech.poison.set((which, entry));
                    let err = ws.eval_dynamics_terms(&mech, 0.5, &q, &qd).unwrap_err();
                    let (row, col) = match quantity {
                        Quantity::MassMatrix => {
                            let (r, c) = INFO.mass_pattern[entry];
                            (r as usize, Some(c as usize))
                        }
                        Quantity::HolonomicJacobian => {
                            let (r, c) = INFO.holonomic_pattern[entry];
                            (r as usize, Some(c as usize))
                        }
                        Quantity::NonholonomicMatrix => {
                            let (r, c) = INFO.nonholonomic_pattern[entry];
                            (r as usize, Some(c as usize))
                        }
                        Quantity::NonholonomicGamma => (INFO.nh() + entry, None),
                        _ => (entry, None),
                    };
                    let EvalError::NonFinite {
                        quantity: found,
                        t,
                        row: r,
                        col: c,
                        value,
                    } = err
                    else {
                        panic!("{err}");
                    };
                    assert_eq!((found, t, r, c), (quantity, 0.5, row, col), "{bad}");
                    assert_eq!(value.to_bits(), bad.to_bits());
                }
            }
        }
        // Finite entries near the overflow threshold are finite: 0·x stays 0.
        mech.poison.set((1, 2));
        mech.bad.set(f64::MAX);
        assert_eq!(ws.eval_dynamics_terms(&mech, 0.5, &q, &qd), Ok(()));
    }

    /// Finite terms whose sums overflow the lanes of the one-pass check pass it: the
    /// overflow only starts the search, which finds nothing; a NaN among them is still
    /// named.
    #[test]
    fn finite_terms_whose_sums_overflow_pass() {
        let mut ws = Workspace::new(&INFO).unwrap();
        for x in [
            &mut ws.mass_values,
            &mut ws.forces,
            &mut ws.cq_values,
            &mut ws.g_values,
            &mut ws.gamma,
        ] {
            x.fill(f64::MAX);
        }
        let mut acc = [0.0; 4];
        accumulate_sum(&mut acc, &ws.mass_values);
        assert!(acc.iter().any(|a| a.is_infinite()), "the lanes overflow");
        assert_eq!(ws.check_dynamics_terms(0.5), Ok(()));
        ws.forces[1] = f64::NAN;
        let err = ws.check_dynamics_terms(0.5).unwrap_err();
        assert!(matches!(
            err,
            EvalError::NonFinite {
                quantity: Quantity::Forces,
                row: 1,
                col: None,
                ..
            }
        ));
    }

    /// [`all_finite`] at every position of slices longer and shorter than its four
    /// lanes.
    #[test]
    fn all_finite_finds_every_offender() {
        for len in 0..11_u32 {
            let mut x: Vec<f64> = (0..len).map(|k| f64::from(k) * 1e300).collect();
            let len = x.len();
            assert!(all_finite(&x));
            for k in 0..len {
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                    let keep = x[k];
                    x[k] = bad;
                    assert!(!all_finite(&x), "{len} {k} {bad}");
                    x[k] = keep;
                }
            }
        }
    }
}
