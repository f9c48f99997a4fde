//! The inertia shape integrals and stiffness of one deformable body (docs/theory.md E10,
//! E11, E17) on `n` elastic coordinates, and their transformation to other coordinates
//! $q_f = T p$.
//!
//! Invariant: every field has the length its doc states for the struct's `d` and `n`;
//! `m_ff` is the sum of the diagonal blocks of `sbar`; `sbar`'s block `(l, k)` is the
//! transpose of block `(k, l)`.

use faer::{Mat, MatRef};

use super::FlexError;

/// A deformable body's invariants on `n` elastic coordinates $q_f$, in the body frame
/// of `d` axes (2 planar, 3 spatial). Matrices are row-major `Vec<f64>`; indices
/// `k, l < d` are body axes, `i, j < n` elastic coordinates.
///
/// | field | symbol (E10, E11, E17) | size | entry |
/// |---|---|---|---|
/// | `mass` | $m = \int\rho\,dV$ | 1 | |
/// | `i1` | $\bar I_1 = \int\rho\,\bar u_o\,dV$ | `d` | `i1[k]` |
/// | `s` | $\bar S = \int\rho N\,dV$ | `d × n` | `s[k*n + j]` |
/// | `i_kl` | $I_{kl} = \int\rho\,x_kx_l\,dV$ | `d × d` | `i_kl[k*d + l]` |
/// | `ibar` | $\bar I_{kl} = \int\rho\,x_kN_l\,dV$ | `d × d × n` | `ibar[(k*d + l)*n + j]` |
/// | `sbar` | $\bar S_{kl} = \int\rho\,N_k^\mathsf{T}N_l\,dV$ | `d × d × n × n` | `sbar[((k*d + l)*n + i)*n + j]` |
/// | `m_ff` | $M_{ff} = \sum_k \bar S_{kk}$ | `n × n` | `m_ff[i*n + j]` |
/// | `k_ff` | $K_{ff}$ | `n × n` | `k_ff[i*n + j]` |
///
/// $x_k$ are the components of the undeformed position $\bar u_o$ in the body frame and
/// $N_k$ the rows of the shape matrix. [`Invariants::write_flat`] concatenates the fields
/// in this order.
#[derive(Clone, Debug, PartialEq)]
pub struct Invariants {
    /// Body-frame axes: 2 or 3.
    pub d: usize,
    /// Elastic coordinates.
    pub n: usize,
    /// $m$.
    pub mass: f64,
    /// $\bar I_1$, length `d`.
    pub i1: Vec<f64>,
    /// $\bar S$, `d × n`.
    pub s: Vec<f64>,
    /// $I_{kl}$, `d × d`.
    pub i_kl: Vec<f64>,
    /// $\bar I_{kl}$, `d × d` rows of length `n`.
    pub ibar: Vec<f64>,
    /// $\bar S_{kl}$, `d × d` blocks of `n × n`.
    pub sbar: Vec<f64>,
    /// $M_{ff}$, `n × n`.
    pub m_ff: Vec<f64>,
    /// $K_{ff}$, `n × n`.
    pub k_ff: Vec<f64>,
}

impl Invariants {
    /// All zero, of the given sizes.
    #[must_use]
    pub fn zeros(d: usize, n: usize) -> Invariants {
        Invariants {
            d,
            n,
            mass: 0.0,
            i1: vec![0.0; d],
            s: vec![0.0; d * n],
            i_kl: vec![0.0; d * d],
            ibar: vec![0.0; d * d * n],
            sbar: vec![0.0; d * d * n * n],
            m_ff: vec![0.0; n * n],
            k_ff: vec![0.0; n * n],
        }
    }

    /// $\bar I_{kl}$ as a slice of length `n`.
    #[must_use]
    pub fn ibar(&self, k: usize, l: usize) -> &[f64] {
        let n = self.n;
        &self.ibar[(k * self.d + l) * n..][..n]
    }

    /// $\bar S_{kl}$ as a row-major `n × n` slice.
    #[must_use]
    pub fn sbar(&self, k: usize, l: usize) -> &[f64] {
        let nn = self.n * self.n;
        &self.sbar[(k * self.d + l) * nn..][..nn]
    }

    /// The length of the flat layout for `d` axes and `n` coordinates:
    /// $1 + d + dn + d^2 + d^2n + d^2n^2 + 2n^2$.
    #[must_use]
    pub const fn flat_len(d: usize, n: usize) -> usize {
        1 + d + d * n + d * d + d * d * n + d * d * n * n + 2 * n * n
    }

    /// Writes `[mass, i1, s, i_kl, ibar, sbar, m_ff, k_ff]` (each as in the table of
    /// [`Invariants`]) into `out`, of length [`Invariants::flat_len`].
    ///
    /// # Errors
    /// [`FlexError::Layout`] when `out` has another length.
    pub fn write_flat(&self, out: &mut [f64]) -> Result<(), FlexError> {
        let expected = Self::flat_len(self.d, self.n);
        if out.len() != expected {
            return Err(FlexError::Layout {
                d: self.d,
                n: self.n,
                expected,
                got: out.len(),
            });
        }
        out[0] = self.mass;
        let mut at = 1;
        for part in self.parts() {
            out[at..at + part.len()].copy_from_slice(part);
            at += part.len();
        }
        Ok(())
    }

    /// Reads the flat layout of [`Invariants::write_flat`].
    ///
    /// # Errors
    /// [`FlexError::Layout`] when `flat` has another length.
    pub fn from_flat(d: usize, n: usize, flat: &[f64]) -> Result<Invariants, FlexError> {
        let expected = Self::flat_len(d, n);
        if flat.len() != expected {
            return Err(FlexError::Layout {
                d,
                n,
                expected,
                got: flat.len(),
            });
        }
        let mut inv = Invariants::zeros(d, n);
        inv.mass = flat[0];
        let mut at = 1;
        for part in inv.parts_mut() {
            let len = part.len();
            part.copy_from_slice(&flat[at..at + len]);
            at += len;
        }
        Ok(inv)
    }

    fn parts(&self) -> [&[f64]; 7] {
        [
            &self.i1, &self.s, &self.i_kl, &self.ibar, &self.sbar, &self.m_ff, &self.k_ff,
        ]
    }

    fn parts_mut(&mut self) -> [&mut [f64]; 7] {
        [
            &mut self.i1,
            &mut self.s,
            &mut self.i_kl,
            &mut self.ibar,
            &mut self.sbar,
            &mut self.m_ff,
            &mut self.k_ff,
        ]
    }

    /// The invariants on the coordinates `keep` (indices into the current ones, in the
    /// order given): the transformation by a Boolean $B_r$ that deletes the others.
    #[must_use]
    pub fn select(&self, keep: &[usize]) -> Invariants {
        let (d, n, m) = (self.d, self.n, keep.len());
        let mut out = Invariants::zeros(d, m);
        out.mass = self.mass;
        out.i1.clone_from(&self.i1);
        out.i_kl.clone_from(&self.i_kl);
        for k in 0..d {
            for (j, &c) in keep.iter().enumerate() {
                out.s[k * m + j] = self.s[k * n + c];
            }
        }
        for kl in 0..d * d {
            for (j, &c) in keep.iter().enumerate() {
                out.ibar[kl * m + j] = self.ibar[kl * n + c];
            }
            let (src, dst) = (
                &self.sbar[kl * n * n..][..n * n],
                &mut out.sbar[kl * m * m..][..m * m],
            );
            pick(src, n, keep, dst);
        }
        pick(&self.m_ff, n, keep, &mut out.m_ff);
        pick(&self.k_ff, n, keep, &mut out.k_ff);
        out
    }

    /// The invariants on new coordinates $p$ with $q_f = T p$, `t` row-major `n × t_cols`
    /// (docs/theory.md E21): $\bar S T$, $\bar I_{kl} T$, $T^\mathsf{T}\bar S_{kl} T$,
    /// $T^\mathsf{T} M_{ff} T$, $T^\mathsf{T} K_{ff} T$; $m$, $\bar I_1$, $I_{kl}$ unchanged.
    ///
    /// # Panics
    /// When `t.len() != n * t_cols`.
    #[must_use]
    pub fn transform(&self, t: &[f64], t_cols: usize) -> Invariants {
        let (d, n, m) = (self.d, self.n, t_cols);
        assert_eq!(t.len(), n * m, "transform: T must be n × t_cols");
        let tm = Mat::<f64>::from_fn(n, m, |i, j| t[i * m + j]);
        let mut out = Invariants::zeros(d, m);
        out.mass = self.mass;
        out.i1.clone_from(&self.i1);
        out.i_kl.clone_from(&self.i_kl);
        let rows = |v: &[f64], r: usize| Mat::<f64>::from_fn(r, n, |i, j| v[i * n + j]);
        let write = |a: MatRef<'_, f64>, dst: &mut [f64]| {
            let c = a.ncols();
            for i in 0..a.nrows() {
                for j in 0..c {
                    dst[i * c + j] = a[(i, j)];
                }
            }
        };
        write((rows(&self.s, d) * &tm).as_ref(), &mut out.s);
        write((rows(&self.ibar, d * d) * &tm).as_ref(), &mut out.ibar);
        let congruence = |a: &[f64]| {
            let a = Mat::<f64>::from_fn(n, n, |i, j| a[i * n + j]);
            tm.transpose() * (&a * &tm)
        };
        for kl in 0..d * d {
            let b = congruence(&self.sbar[kl * n * n..][..n * n]);
            write(b.as_ref(), &mut out.sbar[kl * m * m..][..m * m]);
        }
        write(congruence(&self.m_ff).as_ref(), &mut out.m_ff);
        write(congruence(&self.k_ff).as_ref(), &mut out.k_ff);
        out
    }

    /// $\max |M_{ff} - \sum_k \bar S_{kk}|$ and $\max |\bar S_{lk} - \bar S_{kl}^\mathsf{T}|$ and
    /// the asymmetry of $K_{ff}$, relative to the largest entry of each: a consistency
    /// check of the fields (zero up to rounding for invariants built here).
    #[must_use]
    pub fn consistency(&self) -> f64 {
        let (d, n) = (self.d, self.n);
        let scale = |v: &[f64]| {
            v.iter()
                .fold(0.0f64, |a, x| a.max(x.abs()))
                .max(f64::MIN_POSITIVE)
        };
        let mut worst = 0.0f64;
        let ms = scale(&self.m_ff);
        for i in 0..n * n {
            let sum: f64 = (0..d).map(|k| self.sbar(k, k)[i]).sum();
            worst = worst.max((self.m_ff[i] - sum).abs() / ms);
        }
        let ss = scale(&self.sbar);
        for k in 0..d {
            for l in 0..d {
                let (a, b) = (self.sbar(k, l), self.sbar(l, k));
                for i in 0..n {
                    for j in 0..n {
                        worst = worst.max((a[i * n + j] - b[j * n + i]).abs() / ss);
                    }
                }
            }
        }
        let ks = scale(&self.k_ff);
        for i in 0..n {
            for j in 0..n {
                worst = worst.max((self.k_ff[i * n + j] - self.k_ff[j * n + i]).abs() / ks);
            }
        }
        worst
    }
}

/// `dst = src[keep, keep]`, both row-major.
fn pick(src: &[f64], n: usize, keep: &[usize], dst: &mut [f64]) {
    let m = keep.len();
    for (i, &r) in keep.iter().enumerate() {
        for (j, &c) in keep.iter().enumerate() {
            dst[i * m + j] = src[r * n + c];
        }
    }
}
