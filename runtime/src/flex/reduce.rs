//! Reference conditions, modal reduction and Craig–Bampton (docs/theory.md §reduction, E21, E22).
//!
//! Input: a [`Mesh`]'s nodal invariants. Output: the invariants on fewer coordinates and
//! the basis $T$ with $q_f = T p$ in nodal coordinates. The generalized symmetric
//! eigenproblem $K\phi = \omega^2 M\phi$ is solved through the Cholesky factor of
//! $K = LL^\mathsf{T}$ and faer's symmetric eigendecomposition of
//! $L^{-1} M L^{-\mathsf{T}}$ (eigenvalues $1/\omega^2$, so that the lowest frequencies
//! are the accurate ones); $\phi = L^{-\mathsf{T}} v$ is then mass-normalized.
//! Each mode's largest component is made positive, so the basis is deterministic.

use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Mat, MatRef, Par, Side};

use super::{Dim, FlexError, Invariants, Mesh, Section};

/// Which nodal coordinates define the floating frame, i.e. are deleted by $B_r$
/// (docs/theory.md §reduction).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Reference {
    /// Clamped (tangent) frame at a node: all its coordinates are deleted.
    Clamped {
        /// The node.
        node: usize,
    },
    /// Simply supported between two nodes. Planar: `u, v` at `first` and `v` at `last`;
    /// spatial: `u_x, u_y, u_z, θ_x` at `first` and `u_y, u_z` at `last` (a beam along
    /// the body's x axis).
    SimplySupported {
        /// The pinned node.
        first: usize,
        /// The node on a roller.
        last: usize,
    },
    /// Any set of nodal coordinates (index `node × dofs_per_node + k`).
    Coordinates(Vec<usize>),
}

impl Reference {
    /// The deleted nodal coordinates, sorted.
    ///
    /// # Errors
    /// [`FlexError::ReferenceIndex`] for a node or coordinate outside the mesh.
    pub fn deleted(&self, mesh: &Mesh) -> Result<Vec<usize>, FlexError> {
        let dpn = mesh.dim().dofs_per_node();
        let nodes = mesh.nodes().len();
        let node_ok = |node: usize| {
            if node < nodes {
                Ok(node * dpn)
            } else {
                Err(FlexError::ReferenceIndex {
                    what: "node",
                    index: node,
                    len: nodes,
                })
            }
        };
        let mut out = match self {
            Reference::Clamped { node } => {
                let at = node_ok(*node)?;
                (at..at + dpn).collect()
            }
            Reference::SimplySupported { first, last } => {
                let (a, b) = (node_ok(*first)?, node_ok(*last)?);
                match mesh.dim() {
                    Dim::Planar => vec![a, a + 1, b + 1],
                    Dim::Spatial => vec![a, a + 1, a + 2, a + 3, b + 1, b + 2],
                }
            }
            Reference::Coordinates(list) => {
                for &c in list {
                    if c >= mesh.ndof() {
                        return Err(FlexError::ReferenceIndex {
                            what: "coordinate",
                            index: c,
                            len: mesh.ndof(),
                        });
                    }
                }
                list.clone()
            }
        };
        out.sort_unstable();
        out.dedup();
        Ok(out)
    }
}

/// A body after its reference condition: the invariants on the kept nodal coordinates
/// $q_f^*$ ($q_f = B_r q_f^*$), with $K^* = B_r^\mathsf{T} K_{ff} B_r$ positive definite.
#[derive(Clone, Debug, PartialEq)]
pub struct Constrained {
    /// The invariants on the kept coordinates.
    pub invariants: Invariants,
    /// For each kept coordinate, its nodal index ($B_r$'s non-zero rows).
    pub kept: Vec<usize>,
    /// The number of nodal coordinates.
    pub ndof: usize,
    /// Nodal coordinates per node.
    pub dofs_per_node: usize,
}

/// A reduced body: invariants on coordinates $p$ with $q_f = T p$ ($q_f$ the nodal
/// coordinates of the mesh).
#[derive(Clone, Debug, PartialEq)]
pub struct Reduced {
    /// The invariants on $p$.
    pub invariants: Invariants,
    /// $T$, row-major `ndof × n` (nodal coordinates × reduced coordinates).
    pub basis: Vec<f64>,
    /// Modal reduction: the circular frequencies $\omega_k$ (rad/s) of the kept modes, in
    /// the order kept (ascending for [`Constrained::modes`]). Craig–Bampton: those of the kept fixed-interface modes. No reduction:
    /// empty.
    pub frequencies: Vec<f64>,
}

impl Mesh {
    /// Applies a reference condition and checks that it removes every rigid-body motion.
    ///
    /// The check is geometric and exact: the stiffness of a valid, connected mesh with
    /// positive section stiffnesses annihilates exactly its rigid-body motions
    /// ([`Mesh::rigid_motions`]), so $B_r^\mathsf{T}K_{ff}B_r$ is non-singular if and only if
    /// those motions restricted to the deleted coordinates are independent. Their rank
    /// is read from the singular values of that restriction with unit columns (ratio
    /// 1e-8). A Cholesky factorization of $K^*$ backs it up.
    ///
    /// # Errors
    /// A defect of the mesh, [`FlexError::ReferenceIndex`], [`FlexError::RigidBodyMotion`]
    /// or [`FlexError::NotPositiveDefinite`].
    pub fn constrain(&self, reference: &Reference) -> Result<Constrained, FlexError> {
        let nodal = self.invariants()?;
        let deleted = reference.deleted(self)?;
        let r = self.dim().rigid_motions();
        let rigid = self.rigid_motions();
        let restricted = Mat::<f64>::from_fn(deleted.len(), r, |i, j| rigid[deleted[i] * r + j]);
        let rank = column_rank(restricted.as_ref());
        if rank < r {
            return Err(FlexError::RigidBodyMotion {
                remaining: r - rank,
                total: r,
            });
        }
        let kept: Vec<usize> = (0..self.ndof())
            .filter(|i| deleted.binary_search(i).is_err())
            .collect();
        let invariants = nodal.select(&kept);
        let n = kept.len();
        square(&invariants.k_ff, n)
            .llt(Side::Lower)
            .map_err(|e| not_pd("stiffness", &e))?;
        Ok(Constrained {
            invariants,
            kept,
            ndof: self.ndof(),
            dofs_per_node: self.dim().dofs_per_node(),
        })
    }
}

impl Constrained {
    /// All circular frequencies $\omega$ (rad/s) of $K^*\phi = \omega^2 M^*\phi$, ascending.
    ///
    /// # Errors
    /// [`FlexError::NotPositiveDefinite`] (mass) or [`FlexError::Eigen`].
    pub fn frequencies(&self) -> Result<Vec<f64>, FlexError> {
        let n = self.invariants.n;
        let (lambda, _) = eigh_generalized(
            square(&self.invariants.k_ff, n).as_ref(),
            square(&self.invariants.m_ff, n).as_ref(),
        )?;
        Ok(lambda.iter().map(|l| l.max(0.0).sqrt()).collect())
    }

    /// The body without reduction: $T = B_r$.
    #[must_use]
    pub fn unreduced(&self) -> Reduced {
        let n = self.kept.len();
        let mut basis = vec![0.0; self.ndof * n];
        for (j, &i) in self.kept.iter().enumerate() {
            basis[i * n + j] = 1.0;
        }
        Reduced {
            invariants: self.invariants.clone(),
            basis,
            frequencies: Vec::new(),
        }
    }

    /// Modal reduction (E21): the lowest `modes` mass-normalized modes $\Phi$ of
    /// $K^*\phi = \omega^2 M^*\phi$, $q_f = B_r\Phi p$. The reduced $M_{ff}$ is the identity
    /// and $K_{ff} = \operatorname{diag}(\omega_k^2)$ up to rounding.
    ///
    /// # Errors
    /// [`FlexError::Modes`] when `modes` exceeds the coordinates, or a failure of the
    /// eigenproblem.
    pub fn modes(&self, modes: usize) -> Result<Reduced, FlexError> {
        let n = self.invariants.n;
        if modes > n {
            return Err(FlexError::Modes {
                requested: modes,
                available: n,
            });
        }
        self.mode_set(&(0..modes).collect::<Vec<_>>())
    }

    /// Modal reduction to a chosen set of modes, by their index in ascending order of
    /// frequency (0 is the lowest): for example the lowest bending modes and the first
    /// axial one, which a spinning body's centrifugal load needs.
    ///
    /// # Errors
    /// [`FlexError::Modes`] for an index beyond the coordinates, or a failure of the
    /// eigenproblem.
    pub fn mode_set(&self, set: &[usize]) -> Result<Reduced, FlexError> {
        let n = self.invariants.n;
        if let Some(&bad) = set.iter().find(|&&k| k >= n) {
            return Err(FlexError::Modes {
                requested: bad + 1,
                available: n,
            });
        }
        let (lambda, phi) = eigh_generalized(
            square(&self.invariants.k_ff, n).as_ref(),
            square(&self.invariants.m_ff, n).as_ref(),
        )?;
        let modes = set.len();
        let t: Vec<f64> = (0..n * modes)
            .map(|ij| phi[(ij / modes, set[ij % modes])])
            .collect();
        Ok(Reduced {
            invariants: self.invariants.transform(&t, modes),
            basis: self.lift(&t, modes),
            frequencies: set.iter().map(|&k| lambda[k].max(0.0).sqrt()).collect(),
        })
    }

    /// Craig–Bampton (E22): the kept coordinates of the `boundary` nodes stay, the others
    /// are their static condensation $-K_{ii}^{-1}K_{ib}$ plus the lowest `modes`
    /// fixed-interface modes $\Phi_i$ of $K_{ii}\phi = \omega^2 M_{ii}\phi$. The reduced
    /// coordinates are `[q_b; p]`, `q_b` in nodal order.
    ///
    /// # Errors
    /// [`FlexError::Boundary`] for a node that does not exist or keeps no coordinate,
    /// [`FlexError::Modes`], or a failure of a factorization or the eigenproblem.
    pub fn craig_bampton(&self, boundary: &[usize], modes: usize) -> Result<Reduced, FlexError> {
        let n = self.invariants.n;
        let dpn = self.dofs_per_node;
        let mut is_b = vec![false; n];
        for &node in boundary {
            let mut any = false;
            for (c, &nodal) in self.kept.iter().enumerate() {
                if nodal / dpn == node {
                    is_b[c] = true;
                    any = true;
                }
            }
            if !any {
                return Err(FlexError::Boundary { node });
            }
        }
        let b: Vec<usize> = (0..n).filter(|&c| is_b[c]).collect();
        let i: Vec<usize> = (0..n).filter(|&c| !is_b[c]).collect();
        let (nb, ni) = (b.len(), i.len());
        if modes > ni {
            return Err(FlexError::Modes {
                requested: modes,
                available: ni,
            });
        }
        let k = &self.invariants.k_ff;
        let m = &self.invariants.m_ff;
        let kii = Mat::<f64>::from_fn(ni, ni, |r, c| k[i[r] * n + i[c]]);
        let mii = Mat::<f64>::from_fn(ni, ni, |r, c| m[i[r] * n + i[c]]);
        let kib = Mat::<f64>::from_fn(ni, nb, |r, c| k[i[r] * n + b[c]]);
        // ψ = −K_ii⁻¹ K_ib
        let llt = kii
            .llt(Side::Lower)
            .map_err(|e| not_pd("interior stiffness", &e))?;
        let mut psi = kib;
        {
            use faer::linalg::solvers::Solve;
            llt.solve_in_place(psi.as_mut());
        }
        let (lambda, phi) = eigh_generalized(kii.as_ref(), mii.as_ref())?;
        let cols = nb + modes;
        let mut t = vec![0.0; n * cols];
        for (c, &row) in b.iter().enumerate() {
            t[row * cols + c] = 1.0;
        }
        for (r, &row) in i.iter().enumerate() {
            for c in 0..nb {
                t[row * cols + c] = -psi[(r, c)];
            }
            for c in 0..modes {
                t[row * cols + nb + c] = phi[(r, c)];
            }
        }
        Ok(Reduced {
            invariants: self.invariants.transform(&t, cols),
            basis: self.lift(&t, cols),
            frequencies: lambda[..modes].iter().map(|l| l.max(0.0).sqrt()).collect(),
        })
    }

    /// $B_r t$: rows of `t` (kept coordinates) placed at their nodal indices.
    fn lift(&self, t: &[f64], cols: usize) -> Vec<f64> {
        let mut out = vec![0.0; self.ndof * cols];
        for (r, &nodal) in self.kept.iter().enumerate() {
            out[nodal * cols..][..cols].copy_from_slice(&t[r * cols..][..cols]);
        }
        out
    }
}

/// How a [`Beam`] is reduced after its reference condition.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Reduction {
    /// Keep every nodal coordinate.
    None,
    /// Keep the lowest `n` modes (E21).
    Modes(usize),
    /// Keep the modes of these indices in ascending order of frequency (0 the lowest;
    /// [`Constrained::mode_set`]): the lowest bending modes and the first axial one of a
    /// spinning beam, whose centrifugal load only axial modes carry.
    ModeSet(Vec<usize>),
    /// Craig–Bampton (E22): the coordinates of the boundary nodes and `modes`
    /// fixed-interface modes.
    CraigBampton {
        /// Boundary (joint, contact) nodes.
        boundary: Vec<usize>,
        /// Fixed-interface modes kept.
        modes: usize,
    },
}

/// A uniform straight beam along the body's x axis from the body origin: the whole chain
/// from description to reduced invariants.
#[derive(Clone, Debug, PartialEq)]
pub struct Beam {
    /// Planar or spatial.
    pub dim: Dim,
    /// The number of equal elements (nodes `0..=elements`, node 0 at the origin).
    pub elements: usize,
    /// Its length.
    pub length: f64,
    /// Its section.
    pub section: Section,
    /// Its reference condition.
    pub reference: Reference,
    /// Its reduction.
    pub reduction: Reduction,
}

impl Beam {
    /// The mesh ([`Mesh::line`]).
    #[must_use]
    pub fn mesh(&self) -> Mesh {
        Mesh::line(self.dim, self.length, self.elements, self.section)
    }

    /// The reduced body.
    ///
    /// # Errors
    /// Any [`FlexError`] of meshing, the reference condition or the reduction.
    pub fn reduce(&self) -> Result<Reduced, FlexError> {
        if self.elements == 0 {
            return Err(FlexError::NoElements);
        }
        let constrained = self.mesh().constrain(&self.reference)?;
        match &self.reduction {
            Reduction::None => Ok(constrained.unreduced()),
            Reduction::Modes(n) => constrained.modes(*n),
            Reduction::ModeSet(set) => constrained.mode_set(set),
            Reduction::CraigBampton { boundary, modes } => {
                constrained.craig_bampton(boundary, *modes)
            }
        }
    }

    /// The reduced body's invariants.
    ///
    /// # Errors
    /// As [`Beam::reduce`].
    pub fn invariants(&self) -> Result<Invariants, FlexError> {
        Ok(self.reduce()?.invariants)
    }

    /// The length of a beam's data slot: [`Invariants::flat_len`], then the length and
    /// axial stiffness, the basis $T$ (`ndof × n`) and the centrifugal geometric
    /// stiffness $K_\Omega$ (`n × n`).
    #[must_use]
    pub fn slot_len(&self) -> usize {
        let n = self.coordinates();
        let ndof = (self.elements + 1) * self.dim.dofs_per_node();
        Invariants::flat_len(self.dim.d(), n) + 2 + ndof * n + n * n
    }

    /// Writes the layout of a model's beam data slot into `out`:
    /// `[invariants (Invariants::write_flat), length, EA, T, K_Ω]`, `T` the reduced basis
    /// row-major `ndof × n` (nodal coordinates in the body frame × elastic coordinates;
    /// the rows of the coordinates the reference condition deletes are zero) and `K_Ω`
    /// the reduced geometric stiffness of a unit spin ([`Beam::spin_stiffness`]). The
    /// generated code reads the nodes' displacements (`body.node(k)`) from `T` and the
    /// geometric stiffening of a spinning beam from `K_Ω`.
    ///
    /// # Errors
    /// As [`Beam::reduce`], or [`FlexError::Layout`] when `out` does not have
    /// [`Beam::slot_len`] values.
    pub fn write_slot(&self, out: &mut [f64]) -> Result<(), FlexError> {
        let reduced = self.reduce()?;
        let inv = &reduced.invariants;
        let n = inv.n;
        let flat = Invariants::flat_len(inv.d, n);
        let want = flat + 2 + reduced.basis.len() + n * n;
        if out.len() != want {
            return Err(FlexError::Layout {
                d: inv.d,
                n,
                expected: want,
                got: out.len(),
            });
        }
        let (head, tail) = out.split_at_mut(flat);
        inv.write_flat(head)?;
        tail[0] = self.length;
        tail[1] = self.section.ea;
        let (basis, k_spin) = tail[2..].split_at_mut(reduced.basis.len());
        basis.copy_from_slice(&reduced.basis);
        k_spin.copy_from_slice(&self.spin_stiffness(&reduced.basis, n));
        Ok(())
    }

    /// The geometric stiffness of the beam spinning at unit rate about an axis through
    /// its root (node 0, the body origin) perpendicular to it, on the reduced
    /// coordinates of the basis `t` (`ndof × n`, row-major):
    /// $K_\Omega = \int_0^l P(x)\,(N_v'^\mathsf{T}N_v' + N_w'^\mathsf{T}N_w')\,dx$ with
    /// the centrifugal axial force $P(x) = \rho A\,(l^2 - x^2)/2$ and $N_v'$, $N_w'$ the
    /// slopes of the lateral deflections (the Hermite cubics of E18/E20, $\vartheta_z = v'$,
    /// $\vartheta_y = -w'$). A body spinning at $\bar\omega$ feels
    /// $-(\bar\omega_y^2 + \bar\omega_z^2)K_\Omega q_f$ (planar: $-\dot\theta^2 K_\Omega q_f$):
    /// the stress stiffening of the centrifugal tension, which the linear floating frame
    /// lacks (docs/theory.md §finite-elements). The integrand has degree 6 along an element: 5-point
    /// Gauss–Legendre is exact.
    #[must_use]
    pub fn spin_stiffness(&self, t: &[f64], n: usize) -> Vec<f64> {
        const X: [f64; 5] = [
            -0.906_179_845_938_664,
            -0.538_469_310_105_683_1,
            0.0,
            0.538_469_310_105_683_1,
            0.906_179_845_938_664,
        ];
        const W: [f64; 5] = [
            0.236_926_885_056_189_1,
            0.478_628_670_499_366_5,
            0.568_888_888_888_888_9,
            0.478_628_670_499_366_5,
            0.236_926_885_056_189_1,
        ];
        let dpn = self.dim.dofs_per_node();
        // (deflection, slope, sign of the slope coordinate) per lateral direction.
        let lateral: &[(usize, usize, f64)] = match self.dim {
            Dim::Planar => &[(1, 2, 1.0)],
            Dim::Spatial => &[(1, 5, 1.0), (2, 4, -1.0)],
        };
        let (l, ne) = (self.length, self.elements as f64);
        let h = l / ne;
        let mut k = vec![0.0; n * n];
        let mut slope = vec![0.0; n];
        for e in 0..self.elements {
            let (a, b) = (e * dpn, (e + 1) * dpn);
            for (x, w) in X.iter().zip(W) {
                let s = 0.5 * (1.0 + x);
                let xe = (e as f64 + s) * h;
                let p = 0.5 * self.section.rho_a * (l * l - xe * xe);
                let c = [
                    (-6.0 * s + 6.0 * s * s) / h,
                    1.0 - 4.0 * s + 3.0 * s * s,
                    (6.0 * s - 6.0 * s * s) / h,
                    3.0 * s * s - 2.0 * s,
                ];
                for &(v, th, sign) in lateral {
                    let rows = [a + v, a + th, b + v, b + th];
                    let signs = [1.0, sign, 1.0, sign];
                    for (j, sl) in slope.iter_mut().enumerate() {
                        *sl = (0..4).map(|i| c[i] * signs[i] * t[rows[i] * n + j]).sum();
                    }
                    let f = 0.5 * w * h * p;
                    for i in 0..n {
                        for j in 0..n {
                            k[i * n + j] += f * slope[i] * slope[j];
                        }
                    }
                }
            }
        }
        k
    }

    /// The number of elastic coordinates after reduction (without computing them).
    #[must_use]
    pub fn coordinates(&self) -> usize {
        let dpn = self.dim.dofs_per_node();
        match &self.reduction {
            Reduction::Modes(n) => *n,
            Reduction::ModeSet(set) => set.len(),
            Reduction::None => {
                let mesh = self.mesh();
                mesh.ndof() - self.reference.deleted(&mesh).map_or(0, |d| d.len())
            }
            Reduction::CraigBampton { boundary, modes } => {
                let mesh = self.mesh();
                let deleted = self.reference.deleted(&mesh).unwrap_or_default();
                let kept_b = boundary
                    .iter()
                    .flat_map(|&node| node * dpn..(node + 1) * dpn)
                    .filter(|c| deleted.binary_search(c).is_err())
                    .count();
                kept_b + modes
            }
        }
    }
}

/// Solves $K\phi = \lambda M\phi$ for symmetric positive definite $K$ and $M$: the
/// eigenvalues ascending and the $M$-orthonormal eigenvectors as columns.
///
/// The problem is solved in its inverse form $M\phi = \mu K\phi$, $\mu = 1/\lambda$,
/// through the Cholesky factor of $K = LL^\mathsf{T}$: the symmetric matrix
/// $L^{-1} M L^{-\mathsf{T}}$ has eigenvalues $\mu$ with absolute errors of order
/// $\varepsilon\mu_{\max}$, so the *lowest* frequencies, the ones a reduction keeps, come
/// out to relative accuracy $\varepsilon$ however wide the spectrum (a beam's torsional
/// and axial frequencies lie far above its bending ones). The Cholesky factor of $M$
/// would give the highest ones accurately instead and lose
/// $\varepsilon\,\omega_{\max}^2/\omega_1^2$ on the lowest (1.7e-3 on a spatial beam
/// with small rotary inertia).
///
/// # Errors
/// [`FlexError::NotPositiveDefinite`] when $K$ is not, or an eigenvalue $\mu$ is not
/// positive ($M$ not positive definite to working precision); [`FlexError::Eigen`] when
/// the decomposition does not converge.
pub(crate) fn eigh_generalized(
    k: MatRef<'_, f64>,
    m: MatRef<'_, f64>,
) -> Result<(Vec<f64>, Mat<f64>), FlexError> {
    let n = k.nrows();
    let llt = k.llt(Side::Lower).map_err(|e| not_pd("stiffness", &e))?;
    let l = llt.L();
    // A = L⁻¹ M L⁻ᵀ: X = L⁻¹ M, then A = L⁻¹ Xᵀ (M symmetric).
    let mut x = m.to_owned();
    solve_lower_triangular_in_place(l, x.as_mut(), Par::Seq);
    let mut a = x.transpose().to_owned();
    solve_lower_triangular_in_place(l, a.as_mut(), Par::Seq);
    let a = Mat::<f64>::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    let evd = a
        .self_adjoint_eigen(Side::Lower)
        .map_err(|_| FlexError::Eigen { dim: n })?;
    // μ ascending is λ descending: take them from the top.
    let mut lambda = Vec::with_capacity(n);
    let mut v = Mat::<f64>::zeros(n, n);
    for j in 0..n {
        let src = n - 1 - j;
        let mu = evd.S()[src];
        if mu.is_nan() || mu <= 0.0 {
            return Err(FlexError::NotPositiveDefinite {
                matrix: "mass",
                pivot: j,
            });
        }
        lambda.push(1.0 / mu);
        // φ = L⁻ᵀ v has φᵀKφ = 1 and φᵀMφ = μ: scale by 1/√μ for φᵀMφ = 1.
        let s = 1.0 / mu.sqrt();
        for i in 0..n {
            v[(i, j)] = evd.U()[(i, src)] * s;
        }
    }
    let mut phi = v;
    solve_upper_triangular_in_place(l.transpose(), phi.as_mut(), Par::Seq);
    for j in 0..n {
        let (mut big, mut at) = (0.0f64, 0);
        for i in 0..n {
            if phi[(i, j)].abs() > big {
                big = phi[(i, j)].abs();
                at = i;
            }
        }
        if phi[(at, j)] < 0.0 {
            for i in 0..n {
                phi[(i, j)] = -phi[(i, j)];
            }
        }
    }
    Ok((lambda, phi))
}

/// The numerical rank of `a`'s columns, each scaled to unit length (relative threshold
/// 1e-8 on the singular values); a zero column does not count.
fn column_rank(a: MatRef<'_, f64>) -> usize {
    let (rows, cols) = (a.nrows(), a.ncols());
    let norms: Vec<f64> = (0..cols)
        .map(|j| (0..rows).map(|i| a[(i, j)] * a[(i, j)]).sum::<f64>().sqrt())
        .collect();
    let nonzero: Vec<usize> = (0..cols).filter(|&j| norms[j] > 0.0).collect();
    if nonzero.is_empty() || rows == 0 {
        return 0;
    }
    let scaled = Mat::<f64>::from_fn(rows, nonzero.len(), |i, c| {
        a[(i, nonzero[c])] / norms[nonzero[c]]
    });
    // Singular values of a tall or wide matrix: those of the small Gram matrix.
    let gram = scaled.transpose() * &scaled;
    let Ok(ev) = gram.self_adjoint_eigenvalues(Side::Lower) else {
        return 0;
    };
    let top = ev.iter().copied().fold(0.0f64, f64::max);
    ev.iter().filter(|&&v| v > 1e-16 * top).count()
}

fn square(v: &[f64], n: usize) -> Mat<f64> {
    Mat::<f64>::from_fn(n, n, |i, j| v[i * n + j])
}

fn not_pd(matrix: &'static str, e: &faer::linalg::solvers::LltError) -> FlexError {
    let pivot = match e {
        faer::linalg::solvers::LltError::NonPositivePivot { index } => *index,
    };
    FlexError::NotPositiveDefinite { matrix, pivot }
}
