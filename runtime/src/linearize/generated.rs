//! The state matrix from the generated linearization Jacobian (exact up to rounding).
//!
//! With $L$ = [`Mechanism::linearization_jacobian`] at the operating point
//! $(q, \dot q, \ddot q, \lambda)$ and a column $\delta y = [\delta p; \delta\dot\gamma]$
//! of the reduced state, the tangent of the reduced map $f$ is found in three linear
//! solves, each the derivative of one stage of the map (K1, K2, the augmented system):
//!
//! 1. positions: $C_q^R[:, \beta]\,\delta\beta = -C_q^R[:, p]\,\delta p$, with $C_q^R$
//!    the holonomic rows that determine $\beta$ (the $\partial/\partial\dot q$ columns of
//!    the velocity rows of $L$ are $C_q$ and $G$);
//! 2. velocities: $J_R[:, \beta\eta]\,\delta\dot q_{\beta\eta} =
//!    -L_v^q\,\delta q - J_R[:, \gamma]\,\delta\dot\gamma$, $J_R = [C_q^R; G]$;
//! 3. accelerations: $\begin{bmatrix}M & J_R^\mathsf{T}\\ J_R & 0\end{bmatrix}
//!    \begin{bmatrix}\delta\ddot q\\ \delta\lambda_R\end{bmatrix} =
//!    -\begin{bmatrix}L_d^q\,\delta q + L_d^{\dot q}\,\delta\dot q\\
//!    L_a^q\,\delta q + L_a^{\dot q}\,\delta\dot q\end{bmatrix}_R$,
//!
//! and the column of $A$ is $[\delta\dot\eta; \delta\dot\gamma; \delta\ddot\gamma]$. Each
//! matrix is factored once (complete pivoting) for all columns. Redundant holonomic
//! rows are left out of the three solves as in the simulation; their multipliers (the
//! least-norm ones of [`Dynamics`](crate::Dynamics)) enter through $L_d$.

use faer::linalg::solvers::Solve;
use faer::Mat;

use super::LinearizeError;
use crate::partition::Partition;
use crate::workspace::scatter_row_major;
use crate::{Mechanism, Pattern};

/// $L$ (`rows × 2n`) and $M$ (`n × n`) at one operating point.
fn dense<M: Mechanism + ?Sized>(
    mech: &M,
    pattern: Pattern,
    t: f64,
    q: &[f64],
    qd: &[f64],
    inputs: &[f64],
) -> (Mat<f64>, Mat<f64>) {
    let info = mech.info();
    let n = info.nq();
    let rows = n + 2 * (info.nh() + info.nnh());
    let mut values = vec![0.0; pattern.len()];
    mech.linearization_jacobian(t, q, qd, inputs, &mut values);
    let mut l = vec![0.0; rows * 2 * n];
    scatter_row_major(pattern, &values, 2 * n, &mut l);
    let mut mv = vec![0.0; info.mass_pattern.len()];
    mech.mass_matrix(t, q, &mut mv);
    let mut m = vec![0.0; n * n];
    scatter_row_major(info.mass_pattern, &mv, n, &mut m);
    (
        Mat::from_fn(rows, 2 * n, |i, j| l[i * 2 * n + j]),
        Mat::from_fn(n, n, |i, j| m[i * n + j]),
    )
}

/// Solves `a x = b` by complete pivoting and checks the residual, so that a singular
/// stage is an error instead of a matrix of infinities.
fn solve(a: &Mat<f64>, b: &Mat<f64>, stage: &'static str) -> Result<Mat<f64>, LinearizeError> {
    if a.nrows() == 0 || a.ncols() == 0 {
        return Ok(Mat::zeros(a.ncols(), b.ncols()));
    }
    let x = a.full_piv_lu().solve(b);
    let r = a * &x - b;
    let scale = a.norm_max() * x.norm_max() + b.norm_max();
    let ok = x.norm_max().is_finite() && r.norm_max() <= 1e-9 * scale.max(f64::MIN_POSITIVE);
    if ok {
        Ok(x)
    } else {
        Err(LinearizeError::SingularTangent { stage })
    }
}

/// The state matrix $A$ (row-major, $d \times d$ with $d = |p| + |\gamma|$) at a
/// consistent operating point whose accelerations and multipliers are `qdd`, `lambda`.
#[allow(clippy::too_many_arguments)]
pub(super) fn state_matrix<M: Mechanism + ?Sized>(
    mech: &M,
    pattern: Pattern,
    partition: &Partition,
    t: f64,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    lambda: &[f64],
) -> Result<Vec<f64>, LinearizeError> {
    let info = mech.info();
    let n = info.nq();
    let (mh, mnh) = (info.nh(), info.nnh());
    let mut inputs = qdd.to_vec();
    inputs.extend_from_slice(lambda);
    let (l, m) = dense(mech, pattern, t, q, qd, &inputs);
    let beta = partition.dependent();
    let eta = partition.dependent_velocity();
    let gamma = partition.independent();
    let p: Vec<usize> = eta.iter().chain(gamma).copied().collect();
    let np = p.len();
    let d = np + gamma.len();
    // Rows of L: the velocity rows kept (holonomic R, then every non-holonomic row), and
    // the acceleration rows in the same order.
    let kept = partition.holonomic_rows();
    let vel_rows: Vec<usize> = kept
        .iter()
        .map(|&r| n + mh + mnh + r)
        .chain((0..mnh).map(|r| n + 2 * mh + mnh + r))
        .collect();
    let acc_rows: Vec<usize> = kept
        .iter()
        .map(|&r| n + r)
        .chain((0..mnh).map(|r| n + mh + r))
        .collect();
    let qdcol = |j: usize| n + j;

    // δq and δq̇ for every column of the reduced state (n × d each).
    let mut dq = Mat::<f64>::zeros(n, d);
    let mut dqd = Mat::<f64>::zeros(n, d);
    for (k, &i) in p.iter().enumerate() {
        dq[(i, k)] = 1.0;
    }
    for (k, &i) in gamma.iter().enumerate() {
        dqd[(i, np + k)] = 1.0;
    }

    // 1. Positions: C_q^R[:, β] δβ = −C_q^R[:, p] δp.
    let a1 = Mat::from_fn(kept.len(), beta.len(), |r, c| {
        l[(vel_rows[r], qdcol(beta[c]))]
    });
    let b1 = Mat::from_fn(kept.len(), d, |r, k| {
        -p.iter()
            .map(|&i| l[(vel_rows[r], qdcol(i))] * dq[(i, k)])
            .sum::<f64>()
    });
    let x1 = solve(&a1, &b1, "positions (C_q on the dependent coordinates)")?;
    for (c, &i) in beta.iter().enumerate() {
        for k in 0..d {
            dq[(i, k)] = x1[(c, k)];
        }
    }

    // 2. Velocities of β and η.
    let dep: Vec<usize> = beta.iter().chain(eta).copied().collect();
    let a2 = Mat::from_fn(vel_rows.len(), dep.len(), |r, c| {
        l[(vel_rows[r], qdcol(dep[c]))]
    });
    let b2 = Mat::from_fn(vel_rows.len(), d, |r, k| {
        let row = vel_rows[r];
        -(0..n)
            .map(|j| l[(row, j)] * dq[(j, k)] + l[(row, qdcol(j))] * dqd[(j, k)])
            .sum::<f64>()
    });
    let x2 = solve(
        &a2,
        &b2,
        "velocities ([C_q; G] on the dependent velocities)",
    )?;
    for (c, &i) in dep.iter().enumerate() {
        for k in 0..d {
            dqd[(i, k)] = x2[(c, k)];
        }
    }

    // 3. Accelerations from the augmented system with the kept rows.
    let na = n + vel_rows.len();
    let a3 = Mat::from_fn(na, na, |i, j| match (i < n, j < n) {
        (true, true) => m[(i, j)],
        (true, false) => l[(vel_rows[j - n], qdcol(i))],
        (false, true) => l[(vel_rows[i - n], qdcol(j))],
        (false, false) => 0.0,
    });
    let b3 = Mat::from_fn(na, d, |i, k| {
        let row = if i < n { i } else { acc_rows[i - n] };
        -(0..n)
            .map(|j| l[(row, j)] * dq[(j, k)] + l[(row, qdcol(j))] * dqd[(j, k)])
            .sum::<f64>()
    });
    let x3 = solve(&a3, &b3, "accelerations (the augmented matrix)")?;

    let mut a = vec![0.0; d * d];
    for k in 0..d {
        for (r, &i) in p.iter().enumerate() {
            a[r * d + k] = dqd[(i, k)];
        }
        for (r, &i) in gamma.iter().enumerate() {
            a[(np + r) * d + k] = x3[(i, k)];
        }
    }
    Ok(a)
}
