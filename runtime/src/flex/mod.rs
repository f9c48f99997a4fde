//! Deformable bodies from beam elements: inertia shape integrals, stiffness, reference
//! conditions, modal reduction and Craig–Bampton (docs/theory.md §shape-integrals, §finite-elements).
//!
//! A body is a [`Mesh`]: nodes in the body frame and two-node Euler–Bernoulli beam
//! elements between them, planar (E18, E19; 3 nodal coordinates `u, v, θ` per node) or
//! spatial (E20 and the tables of docs/theory.md §beam-elements; 6 per node `u_x, u_y, u_z, θ_x, θ_y, θ_z`). Each
//! element has its frame $C_j$ (x along the element) and a [`Section`].
//! [`Mesh::invariants`] assembles the body's [`Invariants`] (E10, E11, E16, E17) on the
//! nodal coordinates, integrating every element exactly (Gauss–Legendre along the axis,
//! a section rule across it: the integrands are polynomials).
//!
//! Before a run the nodal model is cut down:
//! 1. [`Mesh::constrain`] applies a [`Reference`] condition $q_f = B_r q_f^*$ (the nodal
//!    coordinates that define the floating frame are deleted) and checks that
//!    $B_r^\mathsf{T} K_{ff} B_r$ is non-singular, i.e. that no rigid-body motion of the
//!    mesh survives ([`FlexError::RigidBodyMotion`] otherwise);
//! 2. [`Constrained::modes`] solves $K^*\phi = \omega^2 M^*\phi$, mass-normalizes and keeps
//!    the lowest `n` modes (E21), or [`Constrained::craig_bampton`] keeps the coordinates
//!    of boundary nodes and `n` fixed-interface modes (E22).
//!
//! Both return a [`Reduced`] body whose invariants are those of the nodal model
//! transformed by the basis $T$ ($q_f = T p$): $\bar S \to \bar S T$,
//! $\bar I_{kl} \to \bar I_{kl} T$, $\bar S_{kl} \to T^\mathsf{T}\bar S_{kl}T$,
//! $M_{ff} \to T^\mathsf{T} M_{ff} T$, $K_{ff} \to T^\mathsf{T} K_{ff} T$. With modes,
//! $M_{ff} = I$ and $K_{ff} = \operatorname{diag}(\omega_k^2)$. The number of modes kept
//! is the parameter that cuts a body down to what a scene excites.
//!
//! [`Beam`] is the whole chain for a uniform straight beam, the form a model
//! description uses (`Beam { elements: 8, length: l, ea, ei, rho_a, modes: 4, … }`).
//! [`Invariants::write_flat`] writes the invariants in the flat layout of a model's
//! data slot.
//!
//! ```
//! use pfaff::flex::{Beam, Dim, Reduction, Reference, Section};
//! // The spin-up beam of Kane, Ryan and Banerjee: 8 elements, clamped, 4 modes.
//! let beam = Beam {
//!     dim: Dim::Planar,
//!     elements: 8,
//!     length: 10.0,
//!     section: Section::planar(1.2, 2.8e7, 1.4e4),
//!     reference: Reference::Clamped { node: 0 },
//!     reduction: Reduction::Modes(4),
//! };
//! let body = beam.reduce()?;
//! // The first bending frequency, 1.8751² √(EI/ρA) / l² = 3.7977 rad/s.
//! assert!((body.frequencies[0] - 3.7977).abs() < 1e-4);
//! # Ok::<(), pfaff::flex::FlexError>(())
//! ```
//!
//! Everything here runs once per body and parameter set and allocates; nothing is meant
//! for a per-step path.

mod element;
mod invariants;
mod mesh;
mod reduce;

pub use invariants::Invariants;
pub use mesh::{Element, Mesh};
pub use reduce::{Beam, Constrained, Reduced, Reduction, Reference};

/// Planar (`d = 2`) or spatial (`d = 3`) body.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Dim {
    /// In the body's x–y plane: nodal coordinates `u, v, θ`.
    Planar,
    /// In space: nodal coordinates `u_x, u_y, u_z, θ_x, θ_y, θ_z`.
    Spatial,
}

impl Dim {
    /// The number of body-frame axes `d`: 2 or 3.
    #[must_use]
    pub const fn d(self) -> usize {
        match self {
            Dim::Planar => 2,
            Dim::Spatial => 3,
        }
    }

    /// Nodal coordinates per node: 3 or 6.
    #[must_use]
    pub const fn dofs_per_node(self) -> usize {
        match self {
            Dim::Planar => 3,
            Dim::Spatial => 6,
        }
    }

    /// Rigid-body motions of a body: 3 or 6.
    #[must_use]
    pub const fn rigid_motions(self) -> usize {
        self.dofs_per_node()
    }
}

/// Properties of a beam's cross-section, per unit length, in the element frame (x along
/// the element, y and z the section's centroidal principal axes).
///
/// A planar element uses `rho_a`, `ea` and `ei_z` (bending in the x–y plane); its model
/// is the centre line (E18), so rotary inertia is not part of it. A spatial element uses
/// all fields and needs $\rho I_y + \rho I_z > 0$: it is the only inertia of torsion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Section {
    /// Mass per unit length $\rho A$.
    pub rho_a: f64,
    /// Axial stiffness $EA$.
    pub ea: f64,
    /// Bending stiffness $EI_y$ (deflection `w` along z).
    pub ei_y: f64,
    /// Bending stiffness $EI_z$ (deflection `v` along y; the planar `EI`).
    pub ei_z: f64,
    /// Torsional stiffness $GJ$.
    pub gj: f64,
    /// $\rho I_y = \int\rho z^2\,dA$ (spatial only).
    pub rho_iy: f64,
    /// $\rho I_z = \int\rho y^2\,dA$ (spatial only).
    pub rho_iz: f64,
}

impl Section {
    /// A planar section: mass per length, axial and bending stiffness.
    #[must_use]
    pub const fn planar(rho_a: f64, ea: f64, ei: f64) -> Section {
        Section {
            rho_a,
            ea,
            ei_y: 0.0,
            ei_z: ei,
            gj: 0.0,
            rho_iy: 0.0,
            rho_iz: 0.0,
        }
    }

    /// A spatial section.
    #[must_use]
    pub const fn spatial(
        rho_a: f64,
        ea: f64,
        ei_y: f64,
        ei_z: f64,
        gj: f64,
        rho_iy: f64,
        rho_iz: f64,
    ) -> Section {
        Section {
            rho_a,
            ea,
            ei_y,
            ei_z,
            gj,
            rho_iy,
            rho_iz,
        }
    }

    /// A solid section of a homogeneous material: density `rho`, Young's modulus `e`,
    /// shear modulus `g`, area `a`, second moments `iy`, `iz` and torsion constant `j`.
    #[must_use]
    #[allow(clippy::many_single_char_names)]
    pub const fn material(rho: f64, e: f64, g: f64, a: f64, iy: f64, iz: f64, j: f64) -> Section {
        Section::spatial(rho * a, e * a, e * iy, e * iz, g * j, rho * iy, rho * iz)
    }

    /// The first field that is not valid for an element of `dim`, with its value.
    pub(crate) fn invalid_field(&self, dim: Dim) -> Option<(&'static str, f64)> {
        let positive: &[(&'static str, f64)] = match dim {
            Dim::Planar => &[("rho_a", self.rho_a), ("ea", self.ea), ("ei_z", self.ei_z)],
            Dim::Spatial => &[
                ("rho_a", self.rho_a),
                ("ea", self.ea),
                ("ei_y", self.ei_y),
                ("ei_z", self.ei_z),
                ("gj", self.gj),
            ],
        };
        for &(name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Some((name, v));
            }
        }
        if dim == Dim::Spatial {
            for (name, v) in [("rho_iy", self.rho_iy), ("rho_iz", self.rho_iz)] {
                if !(v.is_finite() && v >= 0.0) {
                    return Some((name, v));
                }
            }
            if self.rho_iy + self.rho_iz <= 0.0 {
                return Some(("rho_iy + rho_iz", self.rho_iy + self.rho_iz));
            }
        }
        None
    }
}

/// What went wrong building or reducing a deformable body.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FlexError {
    /// The mesh has no element.
    #[error("the mesh has no element")]
    NoElements,
    /// A node's position is not finite (or a planar node has a z coordinate).
    #[error(
        "node {node}: position {position:?} is not a finite point of the body's {dim:?} frame"
    )]
    NodePosition {
        /// The node.
        node: usize,
        /// Its position.
        position: [f64; 3],
        /// The mesh's dimension.
        dim: Dim,
    },
    /// An element names a node that does not exist.
    #[error("element {element} names node {node}, the mesh has {nodes} nodes")]
    NodeIndex {
        /// The element.
        element: usize,
        /// The node named.
        node: usize,
        /// The number of nodes.
        nodes: usize,
    },
    /// An element joins a node to itself or to a node at the same place.
    #[error("element {element} has length {length}")]
    Degenerate {
        /// The element.
        element: usize,
        /// Its length.
        length: f64,
    },
    /// A spatial element's y-axis hint is parallel to the element.
    #[error("element {element}: the y-axis hint {hint:?} is parallel to the element")]
    AxisHint {
        /// The element.
        element: usize,
        /// The hint.
        hint: [f64; 3],
    },
    /// A section property is not finite or not positive.
    #[error("element {element}: section property `{field}` is {value}")]
    Section {
        /// The element.
        element: usize,
        /// The property.
        field: &'static str,
        /// Its value.
        value: f64,
    },
    /// A node is not connected to node 0 through elements.
    #[error("node {node} is not connected to node 0 by elements")]
    Disconnected {
        /// The first node not reached.
        node: usize,
    },
    /// A reference condition names a node or coordinate that does not exist.
    #[error("reference condition: {what} {index} does not exist (the mesh has {len})")]
    ReferenceIndex {
        /// `node` or `coordinate`.
        what: &'static str,
        /// The index given.
        index: usize,
        /// The number there are.
        len: usize,
    },
    /// The reference condition leaves rigid-body motions of the mesh: $B_r^\mathsf{T} K_{ff} B_r$
    /// is singular.
    #[error(
        "the reference condition leaves {remaining} of the body's {total} rigid-body motions: \
         B_rᵀ K B_r is singular"
    )]
    RigidBodyMotion {
        /// The number of rigid-body motions not removed.
        remaining: usize,
        /// The number of rigid-body motions of the body (3 or 6).
        total: usize,
    },
    /// A matrix that must be positive definite is not (a Cholesky pivot is not positive).
    #[error("the {matrix} matrix is not positive definite (pivot {pivot})")]
    NotPositiveDefinite {
        /// `stiffness`, `mass`, `interior stiffness`, …
        matrix: &'static str,
        /// The failing pivot.
        pivot: usize,
    },
    /// More modes were asked for than there are coordinates.
    #[error("{requested} modes asked for, {available} available")]
    Modes {
        /// Modes asked for.
        requested: usize,
        /// Coordinates there are.
        available: usize,
    },
    /// A Craig–Bampton boundary node does not exist or carries no coordinate left by the
    /// reference condition.
    #[error("boundary node {node} does not exist or keeps no coordinate")]
    Boundary {
        /// The node.
        node: usize,
    },
    /// The symmetric eigenvalue decomposition did not converge.
    #[error("the {dim}x{dim} symmetric eigenvalue decomposition did not converge")]
    Eigen {
        /// Its size.
        dim: usize,
    },
    /// A flat array does not have the length of the layout.
    #[error("flat invariants of d = {d}, n = {n} hold {expected} values, got {got}")]
    Layout {
        /// Body-frame axes.
        d: usize,
        /// Elastic coordinates.
        n: usize,
        /// The layout's length.
        expected: usize,
        /// The length given.
        got: usize,
    },
}
