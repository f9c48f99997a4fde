//! Pseudo-inverse solves with small symmetric positive semi-definite matrices ($W$ and
//! $K_S K_S^\mathsf{T}$, of the size of the constraint count), by cyclic Jacobi rotations.
//!
//! Input: a symmetric $m \times m$ matrix (row-major). Output: its eigenvalues and
//! orthonormal eigenvectors, and $x = A^+ b$ with the eigenvalues below a relative
//! tolerance dropped. Jacobi is chosen for robustness on tiny matrices, where its
//! $O(m^3)$ sweeps cost nothing; it is accurate to a few ulps of the largest eigenvalue.
//!
//! Invariant: no allocation after [`Eigen::new`].

/// Eigen-decomposition scratch for an `m × m` symmetric matrix.
#[derive(Debug, Clone)]
pub(crate) struct Eigen {
    m: usize,
    a: Vec<f64>,
    v: Vec<f64>,
}

impl Eigen {
    pub fn new(m: usize) -> Self {
        Self {
            m,
            a: vec![0.0; m * m],
            v: vec![0.0; m * m],
        }
    }

    /// Loads `a` (row-major, symmetric) and diagonalises it.
    pub fn load(&mut self, a: &[f64]) {
        let m = self.m;
        self.a.copy_from_slice(&a[..m * m]);
        self.v.fill(0.0);
        for i in 0..m {
            self.v[i * m + i] = 1.0;
        }
        let (a, v) = (&mut self.a, &mut self.v);
        for _sweep in 0..64 {
            let off: f64 = (0..m)
                .flat_map(|p| (p + 1..m).map(move |q| (p, q)))
                .map(|(p, q)| a[p * m + q].powi(2))
                .sum();
            let diag: f64 = (0..m).map(|i| a[i * m + i].powi(2)).sum();
            if off <= (f64::EPSILON * f64::EPSILON) * diag || off == 0.0 {
                break;
            }
            for p in 0..m {
                for q in p + 1..m {
                    let apq = a[p * m + q];
                    if apq == 0.0 {
                        continue;
                    }
                    let theta = (a[q * m + q] - a[p * m + p]) / (2.0 * apq);
                    let t = theta.signum() / (theta.abs() + theta.hypot(1.0));
                    let c = 1.0 / t.hypot(1.0);
                    let s = t * c;
                    for k in 0..m {
                        let (akp, akq) = (a[k * m + p], a[k * m + q]);
                        a[k * m + p] = c * akp - s * akq;
                        a[k * m + q] = s * akp + c * akq;
                    }
                    for k in 0..m {
                        let (apk, aqk) = (a[p * m + k], a[q * m + k]);
                        a[p * m + k] = c * apk - s * aqk;
                        a[q * m + k] = s * apk + c * aqk;
                    }
                    for k in 0..m {
                        let (vkp, vkq) = (v[k * m + p], v[k * m + q]);
                        v[k * m + p] = c * vkp - s * vkq;
                        v[k * m + q] = s * vkp + c * vkq;
                    }
                }
            }
        }
    }

    /// $x = A^+ b$ for the loaded matrix, dropping eigenvalues $\mu$ with
    /// $|\mu| \le$ `tol` $\cdot \max|\mu|$; returns the rank kept.
    pub fn pinv_solve(&self, b: &[f64], tol: f64, x: &mut [f64]) -> usize {
        let m = self.m;
        let mu_max = (0..m).fold(0.0_f64, |a, i| a.max(self.a[i * m + i].abs()));
        x.fill(0.0);
        let mut rank = 0;
        for i in 0..m {
            let mu = self.a[i * m + i];
            if mu_max == 0.0 || mu.abs() <= tol * mu_max {
                continue;
            }
            rank += 1;
            let proj: f64 = (0..m).map(|k| self.v[k * m + i] * b[k]).sum::<f64>() / mu;
            for (k, xk) in x.iter_mut().enumerate().take(m) {
                *xk += proj * self.v[k * m + i];
            }
        }
        rank
    }
}

#[cfg(test)]
mod tests {
    use super::Eigen;

    #[test]
    fn inverse_and_pseudo_inverse() {
        // Regular: [[4, 1], [1, 3]] x = [1, 2] → x = [1/11, 7/11].
        let mut e = Eigen::new(2);
        e.load(&[4.0, 1.0, 1.0, 3.0]);
        let mut x = [0.0; 2];
        assert_eq!(e.pinv_solve(&[1.0, 2.0], 1e-12, &mut x), 2);
        assert!((x[0] - 1.0 / 11.0).abs() < 1e-15 && (x[1] - 7.0 / 11.0).abs() < 1e-15);
        // Rank one: [[1, 1], [1, 1]]⁺ [2, 2] = [1, 1].
        e.load(&[1.0, 1.0, 1.0, 1.0]);
        assert_eq!(e.pinv_solve(&[2.0, 2.0], 1e-12, &mut x), 1);
        assert!((x[0] - 1.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15);
    }
}
