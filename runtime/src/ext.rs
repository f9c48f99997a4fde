//! Conveniences over any [`Mechanism`]: dense matrices, energy, constraint residuals
//! and a finite-difference check of the derivative functions.
//!
//! These helpers allocate small temporaries and are meant for setup, tests and
//! reporting; the hot paths use [`Workspace`](crate::Workspace).

use crate::workspace::scatter_row_major;
use crate::Mechanism;

/// Constraint residuals at a state (all $\infty$-norms).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Residuals {
    /// $\lVert C(q,t)\rVert_\infty$.
    pub position: f64,
    /// $\lVert C_q\dot q + C_t\rVert_\infty$.
    pub velocity: f64,
    /// $\lVert G\dot q + g\rVert_\infty$.
    pub nonholonomic: f64,
}

/// Largest absolute differences between the model's derivative functions and
/// finite differences of the functions they derive from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DerivativeCheck {
    /// $C_q$ against central differences of $C$ in $q$.
    pub holonomic_jacobian: f64,
    /// $C_t$ against central differences of $C$ in $t$.
    pub holonomic_rate: f64,
    /// $\gamma_h$ against $-\frac{d^2}{ds^2} C(q + s\dot q, t + s)$.
    pub holonomic_gamma: f64,
    /// $\gamma_{nh}$ against $-\frac{d}{ds}[G\dot q + g](q + s\dot q, t + s)$.
    pub nonholonomic_gamma: f64,
    /// $M$ against the Hessian of $T$ in $\dot q$.
    pub mass_matrix: f64,
}

/// Extension methods for every [`Mechanism`].
pub trait MechanismExt: Mechanism {
    /// $M$ as a dense row-major $n \times n$ array.
    fn mass_matrix_dense_inplace(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let info = self.info();
        let mut v = vec![0.0; info.mass_pattern.len()];
        self.mass_matrix(t, q, &mut v);
        scatter_row_major(info.mass_pattern, &v, info.nq(), out);
    }

    /// $C_q$ as a dense row-major $m_h \times n$ array.
    fn holonomic_jacobian_dense_inplace(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let info = self.info();
        let mut v = vec![0.0; info.holonomic_pattern.len()];
        self.holonomic_jacobian(t, q, &mut v);
        scatter_row_major(info.holonomic_pattern, &v, info.nq(), out);
    }

    /// $G$ as a dense row-major $m_{nh} \times n$ array.
    fn nonholonomic_matrix_dense_inplace(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let info = self.info();
        let mut v = vec![0.0; info.nonholonomic_pattern.len()];
        self.nonholonomic_matrix(t, q, &mut v);
        scatter_row_major(info.nonholonomic_pattern, &v, info.nq(), out);
    }

    /// Total energy $T + V$.
    fn energy(&self, t: f64, q: &[f64], qd: &[f64]) -> f64 {
        self.kinetic_energy(t, q, qd) + self.potential_energy(t, q)
    }

    /// Constraint residuals at $(q, \dot q, t)$.
    fn residuals(&self, t: f64, q: &[f64], qd: &[f64]) -> Residuals {
        let info = self.info();
        let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
        let norm = |x: &[f64]| x.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        let mut c = vec![0.0; mh];
        self.holonomic(t, q, &mut c);
        let mut jac = vec![0.0; mh * n];
        self.holonomic_jacobian_dense_inplace(t, q, &mut jac);
        let mut ct = vec![0.0; mh];
        self.holonomic_rate(t, q, &mut ct);
        let mut g = vec![0.0; mnh * n];
        self.nonholonomic_matrix_dense_inplace(t, q, &mut g);
        let mut bias = vec![0.0; mnh];
        self.nonholonomic_bias(t, q, &mut bias);
        let apply = |a: &[f64], b: &mut [f64]| {
            for (i, bi) in b.iter_mut().enumerate() {
                *bi += a[i * n..(i + 1) * n]
                    .iter()
                    .zip(qd)
                    .map(|(x, y)| x * y)
                    .sum::<f64>();
            }
        };
        apply(&jac, &mut ct);
        apply(&g, &mut bias);
        Residuals {
            position: norm(&c),
            velocity: norm(&ct),
            nonholonomic: norm(&bias),
        }
    }

    /// Compares the derivative functions with finite differences at $(q, \dot q, t)$.
    fn check_derivatives(&self, t: f64, q: &[f64], qd: &[f64]) -> DerivativeCheck {
        let info = self.info();
        let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
        let maxdiff = |a: &[f64], b: &[f64]| {
            a.iter()
                .zip(b)
                .fold(0.0_f64, |acc, (x, y)| acc.max((x - y).abs()))
        };
        let c_at = |t: f64, q: &[f64]| {
            let mut c = vec![0.0; mh];
            self.holonomic(t, q, &mut c);
            c
        };
        let h1 = 1e-6;
        // C_q.
        let mut jac = vec![0.0; mh * n];
        self.holonomic_jacobian_dense_inplace(t, q, &mut jac);
        let mut fd = vec![0.0; mh * n];
        let mut qp = q.to_vec();
        for j in 0..n {
            let h = h1 * (1.0 + q[j].abs());
            qp[j] = q[j] + h;
            let cp = c_at(t, &qp);
            qp[j] = q[j] - h;
            let cm = c_at(t, &qp);
            qp[j] = q[j];
            for i in 0..mh {
                fd[i * n + j] = (cp[i] - cm[i]) / (2.0 * h);
            }
        }
        let holonomic_jacobian = maxdiff(&jac, &fd);
        // C_t.
        let mut ct = vec![0.0; mh];
        self.holonomic_rate(t, q, &mut ct);
        let (cp, cm) = (c_at(t + h1, q), c_at(t - h1, q));
        let fd_t: Vec<f64> = cp
            .iter()
            .zip(&cm)
            .map(|(a, b)| (a - b) / (2.0 * h1))
            .collect();
        let holonomic_rate = maxdiff(&ct, &fd_t);
        // γ_h = -d²/ds² C(q + s q̇, t + s).
        let h2 = 1e-4;
        let path = |s: f64| -> Vec<f64> { q.iter().zip(qd).map(|(a, b)| a + s * b).collect() };
        let (c_p, c_0, c_m) = (
            c_at(t + h2, &path(h2)),
            c_at(t, q),
            c_at(t - h2, &path(-h2)),
        );
        let fd_gamma: Vec<f64> = (0..mh)
            .map(|i| -(c_p[i] - 2.0 * c_0[i] + c_m[i]) / (h2 * h2))
            .collect();
        let mut gamma = vec![0.0; mh];
        self.holonomic_gamma(t, q, qd, &mut gamma);
        let holonomic_gamma = maxdiff(&gamma, &fd_gamma);
        // γ_nh = -d/ds [G q̇ + g](q + s q̇, t + s).
        let nh_at = |s: f64| -> Vec<f64> {
            let qs = path(s);
            let mut g = vec![0.0; mnh * n];
            self.nonholonomic_matrix_dense_inplace(t + s, &qs, &mut g);
            let mut b = vec![0.0; mnh];
            self.nonholonomic_bias(t + s, &qs, &mut b);
            for (i, bi) in b.iter_mut().enumerate() {
                *bi += g[i * n..(i + 1) * n]
                    .iter()
                    .zip(qd)
                    .map(|(x, y)| x * y)
                    .sum::<f64>();
            }
            b
        };
        let (np, nm) = (nh_at(h1), nh_at(-h1));
        let fd_nh: Vec<f64> = np
            .iter()
            .zip(&nm)
            .map(|(a, b)| -(a - b) / (2.0 * h1))
            .collect();
        let mut gamma_nh = vec![0.0; mnh];
        self.nonholonomic_gamma(t, q, qd, &mut gamma_nh);
        let nonholonomic_gamma = maxdiff(&gamma_nh, &fd_nh);
        // M = ∂²T/∂q̇².
        let mut mass = vec![0.0; n * n];
        self.mass_matrix_dense_inplace(t, q, &mut mass);
        let h3 = 1e-3;
        let mut v = qd.to_vec();
        let mut t_at = |i: usize, si: f64, j: usize, sj: f64| {
            v[i] += si;
            v[j] += sj;
            let e = self.kinetic_energy(t, q, &v);
            v[i] -= si;
            v[j] -= sj;
            e
        };
        let mut fd_mass = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                fd_mass[i * n + j] =
                    (t_at(i, h3, j, h3) - t_at(i, h3, j, -h3) - t_at(i, -h3, j, h3)
                        + t_at(i, -h3, j, -h3))
                        / (4.0 * h3 * h3);
            }
        }
        let mass_matrix = maxdiff(&mass, &fd_mass);
        DerivativeCheck {
            holonomic_jacobian,
            holonomic_rate,
            holonomic_gamma,
            nonholonomic_gamma,
            mass_matrix,
        }
    }
}

impl<M: Mechanism + ?Sized> MechanismExt for M {}
