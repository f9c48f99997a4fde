//! A body as a mesh of beam elements, and the assembly of its nodal invariants
//! (docs/theory.md E16, E17).
//!
//! Input: nodes in the body frame, elements with their sections. Output: [`Invariants`]
//! on the body's nodal coordinates $q_n$ (node after node, each node's translations then
//! rotations, in the body frame), and the rigid-body motions of the mesh as nodal
//! vectors. Element $j$ contributes through $N = C_j S_j \bar C_j^\mathsf{T} B_j$, its
//! undeformed points are $\bar u_o = p_a + C_j (x, y, z)$ (section offset included), and
//! its stiffness $B_j^\mathsf{T}\bar C_j K_j \bar C_j^\mathsf{T} B_j$.

use super::element::{
    planar_shape, planar_stiffness, section_points, spatial_shape, spatial_stiffness, GAUSS_4,
    PLANAR_DOFS, SPATIAL_DOFS,
};
use super::{Dim, FlexError, Invariants, Section};

/// One two-node beam element of a [`Mesh`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Element {
    /// Its first and second node; the element's x axis points from the first to the second.
    pub nodes: [usize; 2],
    /// Its cross-section.
    pub section: Section,
    /// Spatial elements: a body-frame vector in the element's x–y plane that fixes the
    /// section's y axis ($C_j$'s second column is its part normal to the element). `None`
    /// takes the body's y axis, or its −x axis for an element within 25° of y.
    pub y_axis: Option<[f64; 3]>,
}

/// A deformable body made of beam elements: nodes in the body frame and the elements
/// between them.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    dim: Dim,
    nodes: Vec<[f64; 3]>,
    elements: Vec<Element>,
}

impl Mesh {
    /// An empty mesh.
    #[must_use]
    pub fn new(dim: Dim) -> Mesh {
        Mesh {
            dim,
            nodes: Vec::new(),
            elements: Vec::new(),
        }
    }

    /// A straight beam along the body's x axis from the origin, of `length`, cut into
    /// `elements` equal elements (nodes `0..=elements`, node 0 at the origin).
    #[must_use]
    pub fn line(dim: Dim, length: f64, elements: usize, section: Section) -> Mesh {
        let mut mesh = Mesh::new(dim);
        for i in 0..=elements {
            mesh.add_node([length * i as f64 / elements as f64, 0.0, 0.0]);
        }
        for i in 0..elements {
            mesh.add_element(Element {
                nodes: [i, i + 1],
                section,
                y_axis: None,
            });
        }
        mesh
    }

    /// Adds a node at `position` (body frame; planar meshes use x and y) and returns its
    /// index.
    pub fn add_node(&mut self, position: [f64; 3]) -> usize {
        self.nodes.push(position);
        self.nodes.len() - 1
    }

    /// Adds an element and returns its index. It is checked by [`Mesh::invariants`].
    pub fn add_element(&mut self, element: Element) -> usize {
        self.elements.push(element);
        self.elements.len() - 1
    }

    /// Planar or spatial.
    #[must_use]
    pub fn dim(&self) -> Dim {
        self.dim
    }

    /// The nodes' positions.
    #[must_use]
    pub fn nodes(&self) -> &[[f64; 3]] {
        &self.nodes
    }

    /// The elements.
    #[must_use]
    pub fn elements(&self) -> &[Element] {
        &self.elements
    }

    /// The number of nodal coordinates: nodes × 3 (planar) or × 6 (spatial).
    #[must_use]
    pub fn ndof(&self) -> usize {
        self.nodes.len() * self.dim.dofs_per_node()
    }

    /// Checks nodes, elements, sections and connectivity.
    ///
    /// # Errors
    /// The first defect found, as a [`FlexError`].
    pub fn check(&self) -> Result<(), FlexError> {
        if self.elements.is_empty() {
            return Err(FlexError::NoElements);
        }
        for (node, p) in self.nodes.iter().enumerate() {
            if !p.iter().all(|x| x.is_finite()) || (self.dim == Dim::Planar && p[2] != 0.0) {
                return Err(FlexError::NodePosition {
                    node,
                    position: *p,
                    dim: self.dim,
                });
            }
        }
        let size = self.size();
        for (j, e) in self.elements.iter().enumerate() {
            for &node in &e.nodes {
                if node >= self.nodes.len() {
                    return Err(FlexError::NodeIndex {
                        element: j,
                        node,
                        nodes: self.nodes.len(),
                    });
                }
            }
            let length = dist(self.nodes[e.nodes[0]], self.nodes[e.nodes[1]]);
            if length.is_nan() || length <= 1e-12 * size {
                return Err(FlexError::Degenerate { element: j, length });
            }
            if let Some((field, value)) = e.section.invalid_field(self.dim) {
                return Err(FlexError::Section {
                    element: j,
                    field,
                    value,
                });
            }
            self.frame(j)?;
        }
        // Connectivity: every node reached from node 0.
        let mut reached = vec![false; self.nodes.len()];
        reached[0] = true;
        let mut changed = true;
        while changed {
            changed = false;
            for e in &self.elements {
                let [a, b] = e.nodes;
                if reached[a] != reached[b] {
                    reached[a] = true;
                    reached[b] = true;
                    changed = true;
                }
            }
        }
        if let Some(node) = reached.iter().position(|r| !r) {
            return Err(FlexError::Disconnected { node });
        }
        Ok(())
    }

    /// The largest distance between two nodes' coordinates (a length scale of the mesh).
    fn size(&self) -> f64 {
        let c = self.centroid();
        2.0 * self.nodes.iter().map(|&p| dist(p, c)).fold(0.0, f64::max)
    }

    fn centroid(&self) -> [f64; 3] {
        let mut c = [0.0; 3];
        for p in &self.nodes {
            for k in 0..3 {
                c[k] += p[k] / self.nodes.len() as f64;
            }
        }
        c
    }

    /// The frame $C_j$ of element `j` (columns: its x, y, z axes in the body frame; the
    /// planar one in the top-left 2 × 2 block) and its length.
    ///
    /// # Errors
    /// [`FlexError::AxisHint`] when a spatial element's y-axis hint is parallel to it.
    pub fn frame(&self, j: usize) -> Result<([[f64; 3]; 3], f64), FlexError> {
        let e = &self.elements[j];
        let (a, b) = (self.nodes[e.nodes[0]], self.nodes[e.nodes[1]]);
        let l = dist(a, b);
        let ex = [(b[0] - a[0]) / l, (b[1] - a[1]) / l, (b[2] - a[2]) / l];
        let c = match self.dim {
            Dim::Planar => [[ex[0], -ex[1], 0.0], [ex[1], ex[0], 0.0], [0.0, 0.0, 1.0]],
            Dim::Spatial => {
                let hint = e.y_axis.unwrap_or(if ex[1].abs() > 0.9 {
                    [-1.0, 0.0, 0.0]
                } else {
                    [0.0, 1.0, 0.0]
                });
                let z = cross(ex, hint);
                let nz = norm(z);
                if nz.is_nan() || nz <= 1e-8 * norm(hint) {
                    return Err(FlexError::AxisHint { element: j, hint });
                }
                let ez = [z[0] / nz, z[1] / nz, z[2] / nz];
                let ey = cross(ez, ex);
                [
                    [ex[0], ey[0], ez[0]],
                    [ex[1], ey[1], ez[1]],
                    [ex[2], ey[2], ez[2]],
                ]
            }
        };
        Ok((c, l))
    }

    /// The body's invariants on all its nodal coordinates (docs/theory.md E10, E16, E17),
    /// integrated exactly.
    ///
    /// # Errors
    /// A defect of the mesh ([`Mesh::check`]).
    pub fn invariants(&self) -> Result<Invariants, FlexError> {
        self.check()?;
        let (dim, d, nf) = (self.dim, self.dim.d(), self.ndof());
        let dpn = dim.dofs_per_node();
        let ne = 2 * dpn;
        let mut inv = Invariants::zeros(d, nf);
        let mut nl = vec![0.0; d * ne]; // C S C̄ᵀ at one point, d × ne
        for (j, e) in self.elements.iter().enumerate() {
            let (c, l) = self.frame(j)?;
            let p = self.nodes[e.nodes[0]];
            // Global column of each element column.
            let cols: Vec<usize> = (0..ne).map(|i| e.nodes[i / dpn] * dpn + i % dpn).collect();
            for &(xi, wx) in &GAUSS_4 {
                for &(y, z, wc) in &section_points(&e.section) {
                    let w = e.section.rho_a * l * wx * wc;
                    // ū_o = p + C (x, y, z)
                    let local = [xi * l, y, z];
                    let mut u = [0.0; 3];
                    for k in 0..d {
                        u[k] = p[k] + (0..d).map(|m| c[k][m] * local[m]).sum::<f64>();
                    }
                    local_shape(dim, &c, l, xi, y, z, &mut nl);
                    accumulate(&mut inv, &u[..d], &nl, &cols, w);
                }
            }
            let ke = match dim {
                Dim::Planar => planar_stiffness(l, &e.section),
                Dim::Spatial => spatial_stiffness(l, &e.section),
            };
            // C̄ K_e C̄ᵀ, scattered.
            let cb = frame_blocks(dim, &c);
            let kr = congruence_t(&cb, &ke, ne);
            for (a, &ga) in cols.iter().enumerate() {
                for (b, &gb) in cols.iter().enumerate() {
                    inv.k_ff[ga * nf + gb] += kr[a * ne + b];
                }
            }
        }
        for i in 0..nf * nf {
            inv.m_ff[i] = (0..d).map(|k| inv.sbar(k, k)[i]).sum();
        }
        Ok(inv)
    }

    /// The rigid-body motions of the mesh as nodal vectors, row-major `ndof × r`
    /// (`r` = 3 planar, 6 spatial): translations along each body axis, then small
    /// rotations about each axis through the nodes' centroid (planar: about z). The
    /// stiffness matrix of a valid mesh annihilates exactly these.
    #[must_use]
    pub fn rigid_motions(&self) -> Vec<f64> {
        let (dpn, r) = (self.dim.dofs_per_node(), self.dim.rigid_motions());
        let c = self.centroid();
        let mut out = vec![0.0; self.ndof() * r];
        for (i, p) in self.nodes.iter().enumerate() {
            let x = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
            let row = |k: usize| (i * dpn + k) * r;
            match self.dim {
                Dim::Planar => {
                    out[row(0)] = 1.0;
                    out[row(1) + 1] = 1.0;
                    out[row(0) + 2] = -x[1];
                    out[row(1) + 2] = x[0];
                    out[row(2) + 2] = 1.0;
                }
                Dim::Spatial => {
                    for k in 0..3 {
                        out[row(k) + k] = 1.0;
                        let mut axis = [0.0; 3];
                        axis[k] = 1.0;
                        let v = cross(axis, x);
                        for m in 0..3 {
                            out[row(m) + 3 + k] = v[m];
                        }
                        out[row(3 + k) + 3 + k] = 1.0;
                    }
                }
            }
        }
        out
    }
}

/// $C S \bar C^\mathsf{T}$ at one point, row-major `d × ne`.
#[allow(clippy::many_single_char_names)]
fn local_shape(dim: Dim, c: &[[f64; 3]; 3], l: f64, xi: f64, y: f64, z: f64, out: &mut [f64]) {
    let d = dim.d();
    let (s, ne): (Vec<f64>, usize) = match dim {
        Dim::Planar => (planar_shape(l, xi).to_vec(), PLANAR_DOFS),
        Dim::Spatial => (spatial_shape(l, xi, y, z).to_vec(), SPATIAL_DOFS),
    };
    let cb = frame_blocks(dim, c);
    // (C S)[k][a] then (C S) C̄ᵀ.
    let mut cs = vec![0.0; d * ne];
    for k in 0..d {
        for a in 0..ne {
            cs[k * ne + a] = (0..d).map(|m| c[k][m] * s[m * ne + a]).sum();
        }
    }
    for k in 0..d {
        for b in 0..ne {
            out[k * ne + b] = (0..ne).map(|a| cs[k * ne + a] * cb[b * ne + a]).sum();
        }
    }
}

/// $\bar C = \operatorname{blockdiag}(C, \dots)$ on the element's columns, row-major
/// `ne × ne`: planar `(C₂, 1, C₂, 1)`, spatial `(C, C, C, C)`.
fn frame_blocks(dim: Dim, c: &[[f64; 3]; 3]) -> Vec<f64> {
    let (blocks, size): (&[(usize, usize)], usize) = match dim {
        Dim::Planar => (&[(0, 2), (2, 1), (3, 2), (5, 1)], PLANAR_DOFS),
        Dim::Spatial => (&[(0, 3), (3, 3), (6, 3), (9, 3)], SPATIAL_DOFS),
    };
    let mut out = vec![0.0; size * size];
    for &(at, len) in blocks {
        for i in 0..len {
            for j in 0..len {
                out[(at + i) * size + at + j] = if len == 1 { 1.0 } else { c[i][j] };
            }
        }
    }
    out
}

/// $\bar C K \bar C^\mathsf{T}$ for row-major `n × n` matrices.
fn congruence_t(cb: &[f64], k: &[f64], n: usize) -> Vec<f64> {
    let mut t = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            t[i * n + j] = (0..n).map(|a| cb[i * n + a] * k[a * n + j]).sum();
        }
    }
    let mut out = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            out[i * n + j] = (0..n).map(|a| t[i * n + a] * cb[j * n + a]).sum();
        }
    }
    out
}

/// Adds one quadrature point of weight `w` (mass) at undeformed position `u` with
/// element shape matrix `nl` (`d × ne`, columns at global `cols`) to the integrals.
fn accumulate(inv: &mut Invariants, u: &[f64], nl: &[f64], cols: &[usize], w: f64) {
    let (d, n, ne) = (inv.d, inv.n, cols.len());
    inv.mass += w;
    for k in 0..d {
        inv.i1[k] += w * u[k];
        for (a, &g) in cols.iter().enumerate() {
            inv.s[k * n + g] += w * nl[k * ne + a];
        }
        for l in 0..d {
            inv.i_kl[k * d + l] += w * u[k] * u[l];
            let kl = k * d + l;
            for (a, &g) in cols.iter().enumerate() {
                inv.ibar[kl * n + g] += w * u[k] * nl[l * ne + a];
            }
            let block = &mut inv.sbar[kl * n * n..][..n * n];
            for (a, &ga) in cols.iter().enumerate() {
                let na = w * nl[k * ne + a];
                if na == 0.0 {
                    continue;
                }
                for (b, &gb) in cols.iter().enumerate() {
                    block[ga * n + gb] += na * nl[l * ne + b];
                }
            }
        }
    }
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm([a[0] - b[0], a[1] - b[1], a[2] - b[2]])
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
