//! The trait boundary between generated code and the runtime.
//!
//! `#[pfaff::mechanism]` emits one `impl Mechanism` per model. Everything crosses the
//! boundary as plain `f64` slices with caller-owned output buffers, so generated code
//! never allocates and never names a linear-algebra type. Matrices are written as the
//! values of their structurally non-zero entries, in the order of the pattern that
//! [`Info`] exports (row-major, sorted by row then column).
//!
//! Sign convention (docs/theory.md §sign): the equations of motion are
//! $M\ddot q + C_q^\mathsf{T}\lambda^h + G^\mathsf{T}\lambda^{nh} = Q$, so the generalized
//! constraint force is $-J^\mathsf{T}\lambda$.

/// A named symbol of a model (coordinate or constraint), with its doc comment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Symbol {
    /// The name as written in the model.
    pub name: &'static str,
    /// The doc comment of the declaration, trimmed (empty when there is none).
    pub doc: &'static str,
}

/// A parameter of a model with its default value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Parameter {
    /// The name as written in the model.
    pub name: &'static str,
    /// The doc comment of the declaration (empty when there is none).
    pub doc: &'static str,
    /// The default value.
    pub default: f64,
}

/// A sparsity pattern: the structurally non-zero entries `(row, column)` of a matrix,
/// sorted by row, then column. Generated functions write the values in this order.
pub type Pattern = &'static [(u32, u32)];

/// Which parts of a model depend explicitly on time.
///
/// The runtime uses these flags to skip work; the generator emits no code for
/// the time derivatives that are identically zero.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[allow(clippy::struct_excessive_bools)]
pub struct TimeDependence {
    /// `M` depends on `t`.
    pub mass: bool,
    /// The generalized forces depend on `t`.
    pub forces: bool,
    /// `C` depends on `t` (rheonomic holonomic constraints, `C_t ≠ 0`).
    pub holonomic: bool,
    /// `G` or `g` depends on `t`.
    pub nonholonomic: bool,
}

/// A reference frame of a body-level model: an origin and an orientation, functions of
/// `q` and `t`. Its pose is written by [`Mechanism::frame_poses`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frame {
    /// The name as written in the model.
    pub name: &'static str,
    /// The doc comment of the declaration (empty when there is none).
    pub doc: &'static str,
    /// The frame it is given relative to (`None`: the ground frame).
    pub parent: Option<u32>,
    /// A planar frame: it moves in the global x–y plane and turns about z.
    pub planar: bool,
    /// Its orientation is given by Euler parameters, whose normalization is the
    /// holonomic constraint of this index.
    pub normalization: Option<u32>,
}

/// A named point fixed in a frame. Its global position is written by
/// [`Mechanism::point_positions`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Point {
    /// The name as written in the model.
    pub name: &'static str,
    /// The doc comment of the declaration (empty when there is none).
    pub doc: &'static str,
    /// Index of the frame it is fixed in ([`Info::frames`]).
    pub frame: u32,
}

/// A rigid body: mass properties attached to a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Body {
    /// The name as written in the model.
    pub name: &'static str,
    /// The doc comment of the declaration (empty when there is none).
    pub doc: &'static str,
    /// Index of its frame ([`Info::frames`]).
    pub frame: u32,
}

/// What a joint is, as declared.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum JointKind {
    /// Planar revolute joint (2 rows).
    PlanarRevolute,
    /// Planar prismatic joint (2 rows).
    PlanarPrismatic,
    /// Planar fixed joint (3 rows).
    PlanarFixed,
    /// Spherical joint (3 rows).
    Spherical,
    /// Spatial revolute joint (5 rows).
    Revolute,
    /// Universal (Hooke) joint (4 rows).
    Universal,
    /// Cylindrical joint (4 rows).
    Cylindrical,
    /// Spatial prismatic joint (5 rows).
    Prismatic,
    /// Spatial fixed joint (6 rows).
    Fixed,
    /// Distance between two points (1 row).
    Distance,
    /// A driver: a coordinate or angle prescribed as a function of time (1 row).
    Driver,
    /// No velocity of a point along a direction (1 non-holonomic row); a knife edge.
    ZeroVelocity,
    /// A thin wheel rolling without slip on the plane z = 0 (1 holonomic contact row and
    /// 2 non-holonomic no-slip rows).
    RollingWheel,
}

/// A joint: named constraint rows between two frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Joint {
    /// The name as written in the model; its rows are named `name.suffix`.
    pub name: &'static str,
    /// The doc comment of the declaration (empty when there is none).
    pub doc: &'static str,
    /// What it is.
    pub kind: JointKind,
    /// The two frames it joins (`None`: the ground). The reactions reported for the
    /// joint act on the first.
    pub frames: [Option<u32>; 2],
    /// Its rows among the holonomic constraints: `start..start + len`.
    pub holonomic: (u32, u32),
    /// Its rows among the non-holonomic constraints: `start..start + len`.
    pub nonholonomic: (u32, u32),
}

/// A contact: a gap function `g(q, t)` that must stay non-negative, with a coefficient
/// of restitution.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Contact {
    /// The name as written in the model.
    pub name: &'static str,
    /// The doc comment of the declaration (empty when there is none).
    pub doc: &'static str,
    /// Index of the parameter holding its coefficient of restitution.
    pub restitution: u32,
}

/// A named array of model data whose length is fixed by the model but whose values are
/// known only at run time (for example finite-element invariants read from a file).
/// Values are read and written with [`Mechanism::data`] and [`Mechanism::set_data`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DataSlot {
    /// The name as written in the model.
    pub name: &'static str,
    /// The doc comment of the declaration (empty when there is none).
    pub doc: &'static str,
    /// The number of values.
    pub len: u32,
}

/// The values given to [`Mechanism::set_data`] do not fit the slot.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DataError {
    /// The model has no slot of this index.
    #[error("model `{model}` has no data slot {index}")]
    NoSlot {
        /// The model's name.
        model: &'static str,
        /// The index asked for.
        index: usize,
    },
    /// The number of values differs from the slot's length.
    #[error("data slot `{slot}` holds {expected} values, got {got}")]
    Length {
        /// The slot's name.
        slot: &'static str,
        /// Its length.
        expected: usize,
        /// The number of values given.
        got: usize,
    },
    /// A value is not finite.
    #[error("data slot `{slot}`: value {index} is {value}")]
    NotFinite {
        /// The slot's name.
        slot: &'static str,
        /// Position of the value.
        index: usize,
        /// The value.
        value: f64,
    },
}

/// Static description of a model: sizes, names, patterns and structural flags.
///
/// Everything a model's generated code is specialised on (sizes, patterns, which
/// functions exist) is here and is `'static`. Values known only at run time live in the
/// model itself: parameters, and the arrays of [`Info::data`].
#[derive(Clone, Copy, Debug)]
pub struct Info {
    /// The model's name (its module name).
    pub name: &'static str,
    /// The model's doc comment.
    pub doc: &'static str,
    /// Generalized coordinates `q`, in order.
    pub coordinates: &'static [Symbol],
    /// Parameters, in order.
    pub parameters: &'static [Parameter],
    /// Holonomic constraints `C(q, t) = 0`, in row order.
    pub holonomic: &'static [Symbol],
    /// Non-holonomic constraints `G(q, t) q̇ + g(q, t) = 0`, in row order.
    pub nonholonomic: &'static [Symbol],
    /// Non-zero entries of the mass matrix (both triangles).
    pub mass_pattern: Pattern,
    /// Non-zero entries of `C_q`.
    pub holonomic_pattern: Pattern,
    /// Non-zero entries of `G`.
    pub nonholonomic_pattern: Pattern,
    /// Explicit time dependence of each part.
    pub time: TimeDependence,
    /// `g ≡ 0`: the non-holonomic constraints are homogeneous in the velocities.
    pub nonholonomic_homogeneous: bool,
    /// `T + V` is a first integral: no applied forces, no explicit time, and a kinetic
    /// energy that is a quadratic form of the velocities (`T1 = T0 = 0`).
    pub conservative: bool,
    /// Reference frames of a body-level model, in declaration order.
    pub frames: &'static [Frame],
    /// Named points, in declaration order.
    pub points: &'static [Point],
    /// Rigid bodies, in declaration order.
    pub bodies: &'static [Body],
    /// Joints, in declaration order, with their constraint rows.
    pub joints: &'static [Joint],
    /// Named scalar outputs, written by [`Mechanism::outputs`].
    pub outputs: &'static [Symbol],
    /// Contacts (gap functions), in row order.
    pub contacts: &'static [Contact],
    /// Non-zero entries of the contact normal Jacobian `D = ∂gap/∂q`.
    pub contact_pattern: Pattern,
    /// Arrays of run-time model data.
    pub data: &'static [DataSlot],
    /// The pattern of [`Mechanism::linearization_jacobian`] (rows of the stacked
    /// residuals, columns `[q; q̇]`), when the model emits it (`#[mechanism(linearize)]`);
    /// `None` otherwise, and [`linearize`](crate::linearize) then uses differences.
    pub linearization: Option<Pattern>,
}

impl Info {
    /// A model with no coordinates and nothing else: the base of hand-written
    /// descriptions (`Info { name: .., coordinates: .., ..Info::EMPTY }`).
    pub const EMPTY: Info = Info {
        name: "",
        doc: "",
        coordinates: &[],
        parameters: &[],
        holonomic: &[],
        nonholonomic: &[],
        mass_pattern: &[],
        holonomic_pattern: &[],
        nonholonomic_pattern: &[],
        time: TimeDependence {
            mass: false,
            forces: false,
            holonomic: false,
            nonholonomic: false,
        },
        nonholonomic_homogeneous: true,
        conservative: false,
        frames: &[],
        points: &[],
        bodies: &[],
        joints: &[],
        outputs: &[],
        contacts: &[],
        contact_pattern: &[],
        data: &[],
        linearization: None,
    };
}

impl Info {
    /// Number of generalized coordinates `n`.
    #[must_use]
    pub const fn nq(&self) -> usize {
        self.coordinates.len()
    }
    /// Number of holonomic constraints `m_h`.
    #[must_use]
    pub const fn nh(&self) -> usize {
        self.holonomic.len()
    }
    /// Number of non-holonomic constraints `m_nh`.
    #[must_use]
    pub const fn nnh(&self) -> usize {
        self.nonholonomic.len()
    }
    /// Index of the coordinate called `name`.
    #[must_use]
    pub fn coordinate_index(&self, name: &str) -> Option<usize> {
        self.coordinates.iter().position(|s| s.name == name)
    }
    /// Index of the parameter called `name`.
    #[must_use]
    pub fn parameter_index(&self, name: &str) -> Option<usize> {
        self.parameters.iter().position(|p| p.name == name)
    }
    /// Index of the output called `name`.
    #[must_use]
    pub fn output_index(&self, name: &str) -> Option<usize> {
        self.outputs.iter().position(|p| p.name == name)
    }
    /// Index of the frame called `name`.
    #[must_use]
    pub fn frame_index(&self, name: &str) -> Option<usize> {
        self.frames.iter().position(|p| p.name == name)
    }
    /// Index of the joint called `name`.
    #[must_use]
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|p| p.name == name)
    }
    /// Number of contacts.
    #[must_use]
    pub const fn ncontacts(&self) -> usize {
        self.contacts.len()
    }
}

/// Where [`Mechanism::dynamics_terms`] writes: every quantity the index-1 equations
/// $[M\ J^\mathsf{T}; J\ 0][\ddot q; \lambda] = [Q; \gamma]$ need at one point, and,
/// when asked for, the constraints $C$ there, each in the layout of its own function.
#[derive(Debug)]
pub struct DynamicsTerms<'a> {
    /// Where to write `C` (length `m_h`), as [`Mechanism::holonomic`], or `None` not to
    /// compute it. A caller that reads $C$ at every point (Baumgarte's shift) gets it
    /// for a few operations on the sines already there; one that does not asks for
    /// nothing, and the generated code skips every operation only `C` needs.
    pub holonomic: Option<&'a mut [f64]>,
    /// Values of [`Info::mass_pattern`].
    pub mass: &'a mut [f64],
    /// `Q` (length `n`), as [`Mechanism::forces`].
    pub forces: &'a mut [f64],
    /// Values of [`Info::holonomic_pattern`].
    pub holonomic_jacobian: &'a mut [f64],
    /// `γ_h` (length `m_h`).
    pub holonomic_gamma: &'a mut [f64],
    /// Values of [`Info::nonholonomic_pattern`].
    pub nonholonomic_matrix: &'a mut [f64],
    /// `γ_nh` (length `m_nh`).
    pub nonholonomic_gamma: &'a mut [f64],
}

/// The outcome of [`Mechanism::augmented_solve`] and [`Mechanism::orthogonal_solve`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AugmentedSolve {
    /// The model has no specialized solve (the default).
    Unavailable,
    /// Solved: the buffer holds the solution ($[\ddot q; \lambda]$ for
    /// [`Mechanism::augmented_solve`]).
    Solved,
    /// A pivot was not safely positive (a mass matrix singular off the constraints,
    /// redundant or nearly dependent constraints, a singular configuration): the buffer
    /// holds nothing useful, and the general path must solve.
    Declined,
}

/// A mechanism: the functions that `#[pfaff::mechanism]` generates.
///
/// All matrices are written as the values of their pattern entries (see [`Info`]).
/// Functions whose result is identically zero for a model are not generated; the
/// defaults here fill their buffers with zeros so that callers need not special-case
/// them (check the flags of [`Info`] to skip calling them at all).
///
/// The trait is object safe, so a program can hold models as `Box<dyn Mechanism>`.
pub trait Mechanism {
    /// Sizes, names, patterns and flags.
    fn info(&self) -> &'static Info;

    /// Value of parameter `index` (in the order of [`Info::parameters`]).
    fn parameter(&self, index: usize) -> f64;

    /// Sets parameter `index` (in the order of [`Info::parameters`]).
    fn set_parameter(&mut self, index: usize, value: f64);

    /// The default initial coordinates and velocities declared by the model (they need
    /// not satisfy the constraints; assembly makes them consistent).
    fn initial_state(&self, q: &mut [f64], qd: &mut [f64]) {
        q.fill(0.0);
        qd.fill(0.0);
    }

    /// The mass matrix `M(q, t) = ∂²T/∂q̇²`, as values of [`Info::mass_pattern`].
    fn mass_matrix(&self, t: f64, q: &[f64], out: &mut [f64]);

    /// The generalized force `Q = Q_e + Q_v − ∂V/∂q` (length `n`), with the quadratic
    /// velocity vector `Q_v = ∂T/∂q − (∂²T/∂q̇∂q) q̇ − ∂²T/∂q̇∂t`.
    fn forces(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]);

    /// The applied generalized forces `Q_e` declared by the model (`#[force]` items and
    /// the coefficients of a virtual work), length `n`. They are part of
    /// [`forces`](Self::forces); what remains, `forces − applied_forces`, is the part
    /// fixed by the kinetic and potential energy.
    ///
    /// The free-motion analysis ([`FreeMotion`](crate::FreeMotion)) uses the split to
    /// evaluate or replace the applied forces. The default writes zeros: a model that
    /// does not separate them has all of `forces` in the fixed part.
    fn applied_forces(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
        let _ = (t, q, qd);
        out.fill(0.0);
    }

    /// The free-motion residual of docs/theory.md §free-motion (S2-18) with the applied forces
    /// `applied` in place of the model's own (length `n`): for every constraint, holonomic
    /// rows first, $w = -\gamma + J M^{-1}(Q^0 + Q)$ with
    /// $Q^0 = $ `forces − applied_forces` (so $w = c + F A^{-1} h$ in the notation of
    /// \[S2\], $c = -\gamma_h$). Writes `m_h + m_nh` values into `out`.
    ///
    /// The generator emits it, as closed-form expressions, only when the mass matrix is
    /// diagonal or constant; it then returns `true`. The default writes nothing and
    /// returns `false`; [`FreeMotion`](crate::FreeMotion) computes the same residual
    /// numerically for any regular mass matrix.
    fn free_motion_residual(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        applied: &[f64],
        out: &mut [f64],
    ) -> bool {
        let _ = (t, q, qd, applied, out);
        false
    }

    /// The free-motion conditions `w = 0` as printable infix formulas, one per
    /// constraint (holonomic first), in terms of `t`, the coordinates, their velocities
    /// `x'` and the applied forces `Q_x`; empty unless
    /// [`free_motion_residual`](Self::free_motion_residual) is generated.
    fn free_motion_conditions(&self) -> &'static [&'static str] {
        &[]
    }

    /// The holonomic constraints `C(q, t)` (length `m_h`).
    fn holonomic(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let _ = (t, q);
        out.fill(0.0);
    }

    /// The holonomic Jacobian `C_q`, as values of [`Info::holonomic_pattern`].
    fn holonomic_jacobian(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let _ = (t, q);
        out.fill(0.0);
    }

    /// [`holonomic`](Self::holonomic) into `c` and
    /// [`holonomic_jacobian`](Self::holonomic_jacobian) into `cq` in one call, so that
    /// the generated code computes what they share (the sine and cosine of each angle,
    /// the same lengths) once. The generator emits it for every model with holonomic
    /// constraints; the default calls the two functions. The position projections and
    /// the monitors of the runtime need both at one point.
    fn holonomic_with_jacobian(&self, t: f64, q: &[f64], c: &mut [f64], cq: &mut [f64]) {
        self.holonomic(t, q, c);
        self.holonomic_jacobian(t, q, cq);
    }

    /// The time partial `C_t` (length `m_h`); zero for scleronomic constraints.
    fn holonomic_rate(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let _ = (t, q);
        out.fill(0.0);
    }

    /// `γ_h = −(C_q q̇)_q q̇ − 2 C_qt q̇ − C_tt`, so that `C_q q̈ = γ_h` (length `m_h`).
    fn holonomic_gamma(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
        let _ = (t, q, qd);
        out.fill(0.0);
    }

    /// The non-holonomic matrix `G(q, t)`, as values of [`Info::nonholonomic_pattern`].
    fn nonholonomic_matrix(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let _ = (t, q);
        out.fill(0.0);
    }

    /// The non-holonomic bias `g(q, t)` (length `m_nh`).
    fn nonholonomic_bias(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let _ = (t, q);
        out.fill(0.0);
    }

    /// `γ_nh = −(G q̇)_q q̇ − G_t q̇ − g_q q̇ − g_t`, so that `G q̈ = γ_nh` (length `m_nh`).
    fn nonholonomic_gamma(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
        let _ = (t, q, qd);
        out.fill(0.0);
    }

    /// Kinetic energy `T(q, q̇, t)`.
    fn kinetic_energy(&self, t: f64, q: &[f64], qd: &[f64]) -> f64;

    /// Potential energy `V(q, t)`.
    fn potential_energy(&self, t: f64, q: &[f64]) -> f64 {
        let _ = (t, q);
        0.0
    }

    /// Everything the index-1 equations need at `(t, q, q̇)` in one call, so that the
    /// generated code computes what the quantities share (the sines of the same angles,
    /// the same lengths) once; `C` only when `out.holonomic` asks for it. The default
    /// calls the separate functions.
    fn dynamics_terms(&self, t: f64, q: &[f64], qd: &[f64], out: DynamicsTerms<'_>) {
        if let Some(c) = out.holonomic {
            self.holonomic(t, q, c);
        }
        self.mass_matrix(t, q, out.mass);
        self.forces(t, q, qd, out.forces);
        self.holonomic_jacobian(t, q, out.holonomic_jacobian);
        self.holonomic_gamma(t, q, qd, out.holonomic_gamma);
        self.nonholonomic_matrix(t, q, out.nonholonomic_matrix);
        self.nonholonomic_gamma(t, q, qd, out.nonholonomic_gamma);
    }

    /// [`dynamics_terms`](Self::dynamics_terms) with the velocities corrected in
    /// between: writes `C_q` and `G` at `(t, q)`, calls `correct(cq, g, qd)` (which may
    /// change `qd`), then writes `M`, `Q`, `γ_h` and `γ_nh` at the corrected `qd` (and
    /// `C` at `(t, q)` when `out.holonomic` asks for it).
    /// Coordinate partitioning projects the velocities onto the constraints at the
    /// point with `C_q` and `G` this way, so that the generated code computes what the
    /// two parts share (the sines of the same angles) once. The default evaluates the
    /// Jacobians, calls `correct`, then [`dynamics_terms`](Self::dynamics_terms).
    // A callback with the slices it reads and the velocities it corrects.
    #[allow(clippy::type_complexity)]
    fn dynamics_terms_corrected(
        &self,
        t: f64,
        q: &[f64],
        qd: &mut [f64],
        out: DynamicsTerms<'_>,
        correct: &mut dyn FnMut(&[f64], &[f64], &mut [f64]),
    ) {
        self.holonomic_jacobian(t, q, out.holonomic_jacobian);
        self.nonholonomic_matrix(t, q, out.nonholonomic_matrix);
        correct(out.holonomic_jacobian, out.nonholonomic_matrix, qd);
        self.dynamics_terms(t, q, qd, out);
    }

    /// Solves the augmented system
    /// $[M\ J^\mathsf{T}; J\ 0][\ddot q; \lambda] = [Q; \gamma]$,
    /// $J = [C_q; G]$, in place: `x` holds $[Q; \gamma]$ (length `n + m_h + m_nh`) on
    /// entry and $[\ddot q; \lambda]$ on return, from the pattern values `mass`, `cq`
    /// and `g` (as written by [`dynamics_terms`](Self::dynamics_terms)).
    ///
    /// The generator emits it, specialized to the model's patterns, when that pays: where
    /// cheaper, first the null-space method on a partition of the coordinates chosen at
    /// compile time (elimination of $J$ with fixed pivots, the reduced system
    /// $N^\mathsf{T} M N$ of the size of the degrees of freedom), and the range-space
    /// code (a sparse $LDL^\mathsf{T}$ with the fill and the elimination order computed at
    /// compile time, coordinates first, then multipliers) where a pivot of the partition
    /// falls below its threshold. Every pivot is checked, and
    /// [`AugmentedSolve::Declined`] hands the system back to the general path
    /// ([`Dynamics`](crate::Dynamics)). The default returns
    /// [`AugmentedSolve::Unavailable`]. Allocates nothing.
    fn augmented_solve(
        &self,
        mass: &[f64],
        cq: &[f64],
        g: &[f64],
        x: &mut [f64],
    ) -> AugmentedSolve {
        let _ = (mass, cq, g, x);
        AugmentedSolve::Unavailable
    }

    /// Solves $[I\ J^\mathsf{T}; J\ 0][\Delta; \mu] = [0; r]$, $J = [C_q; G]$, in
    /// place: `x` (length `n + m_h + m_nh`) holds $r$ in its last `m_h + m_nh` entries
    /// on entry (its first `n` are not read: the coordinates' block of the right-hand
    /// side is zero), and $[\Delta; \mu]$ on return, from the pattern values `cq` and
    /// `g`. $\Delta = J^\mathsf{T}(J J^\mathsf{T})^{-1} r$ is the least change with
    /// $J\Delta = r$: with $r = -(J\dot q + [C_t; g])$, the orthogonal projection of
    /// $\dot q$ onto the velocity constraints (coordinate partitioning projects the
    /// velocities of every evaluation by it).
    ///
    /// The generator emits it like [`augmented_solve`](Self::augmented_solve) (the
    /// same factorization with the identity in place of $M$, its pivots checked the
    /// same way: dependent or nearly dependent rows return
    /// [`AugmentedSolve::Declined`]). The default returns
    /// [`AugmentedSolve::Unavailable`]. Allocates nothing.
    fn orthogonal_solve(&self, cq: &[f64], g: &[f64], x: &mut [f64]) -> AugmentedSolve {
        let _ = (cq, g, x);
        AugmentedSolve::Unavailable
    }

    /// The orthogonal projection of the velocities `qd` onto $J\dot q + [C_t; g] = 0$
    /// at a point with the pattern values `cq`, `g` and the rates `ct` ($C_t$, length
    /// `m_h`) and `bias` ($g$, length `m_nh`): the residuals
    /// $r = J\dot q + [C_t; g]$, then [`orthogonal_solve`](Self::orthogonal_solve) with
    /// $[0; -r]$, and $\dot q \mathrel{+}= \Delta$, in place.
    ///
    /// The generator emits it beside the orthogonal solve, with the residuals as
    /// straight-line sums over the patterns (each row's rate, then its entries in the
    /// pattern's order: the runtime's sums to the bit) and the solve's buffer on the
    /// stack. Returns what the solve returns, and [`AugmentedSolve::Declined`] with
    /// `qd` unchanged when a change is not finite. The default returns
    /// [`AugmentedSolve::Unavailable`] (the runtime then forms the residuals itself).
    /// Allocates nothing.
    fn orthogonal_projection(
        &self,
        cq: &[f64],
        g: &[f64],
        ct: &[f64],
        bias: &[f64],
        qd: &mut [f64],
    ) -> AugmentedSolve {
        let _ = (cq, g, ct, bias, qd);
        AugmentedSolve::Unavailable
    }

    /// The velocity residuals $[C_q\dot q + C_t;\ G\dot q + g]$ into `out` (length
    /// `m_h + m_nh`) from the pattern values `cq`, `g`, the rates `ct` ($C_t$) and
    /// `bias` ($g$) at a point and the velocities `qd`; `true` when written.
    ///
    /// The generator emits it for every model with constraint rows: each row's rate,
    /// then its entries in the pattern's order, added left to right (the runtime's
    /// row-by-row sums to the bit) as straight-line code. The default returns `false`
    /// and leaves `out` alone (the runtime then walks the patterns itself). Allocates
    /// nothing.
    fn velocity_residuals(
        &self,
        cq: &[f64],
        g: &[f64],
        ct: &[f64],
        bias: &[f64],
        qd: &[f64],
        out: &mut [f64],
    ) -> bool {
        let _ = (cq, g, ct, bias, qd, out);
        false
    }

    /// The row norms $\lVert (C_q)_i\rVert_\infty$ of the holonomic Jacobian into `out`
    /// (length `m_h`) from its pattern values `cq`; `true` when written.
    ///
    /// The generator emits it for every model with holonomic rows: each row's largest
    /// magnitude over its entries in the pattern's order, a NaN entry making the norm
    /// NaN (the runtime's walk of the pattern, whose maximum is exact, as straight-line
    /// code). The projections' convergence tests read these norms at every iterate.
    /// The default returns `false` and leaves `out` alone (the runtime then walks the
    /// pattern itself). Allocates nothing.
    fn holonomic_row_norms(&self, cq: &[f64], out: &mut [f64]) -> bool {
        let _ = (cq, out);
        false
    }

    /// The position map of partitioning's chart, $X = (N N^\mathsf{T})^{-1} N$ with
    /// $N = C_q$ (row-major `m_h × n`), into `map` from the pattern values `cq`;
    /// returns the pivot ratio of $N N^\mathsf{T}$ ($\min_k \rho_k / \max_k \rho_k$,
    /// $\rho_k = d_k / G_{kk}$ the pivots of its $L D L^\mathsf{T}$ relative to their
    /// diagonal entries), or `Some(0.0)` with `map` unfinished when a pivot is not
    /// positive (dependent rows, a non-finite entry).
    ///
    /// The generator emits it for models with holonomic rows within the budget of its
    /// solves: the Gram matrix from the products the pattern leaves, its factorization
    /// with the fill computed at compile time, and the `n` solves over the
    /// structurally non-zero entries, as straight-line code. The default returns `None`
    /// (the runtime then factors the Gram matrix itself). Allocates nothing.
    fn holonomic_normal_map(&self, cq: &[f64], map: &mut [f64]) -> Option<f64> {
        let _ = (cq, map);
        None
    }

    /// The poses of the frames of [`Info::frames`]: 12 values per frame, the origin
    /// `(x, y, z)` and then the rotation matrix to the global frame, row-major. Planar
    /// frames have `z = 0` and turn about the z axis.
    fn frame_poses(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let _ = (t, q);
        out.fill(0.0);
    }

    /// The global positions of the points of [`Info::points`], 3 values per point
    /// (`z = 0` in planar models).
    fn point_positions(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let _ = (t, q);
        out.fill(0.0);
    }

    /// How the model asks to be drawn: shapes over drawing points (see
    /// [`Drawing`](crate::Drawing)). The default draws nothing.
    fn drawing(&self) -> &'static crate::Drawing {
        &crate::Drawing::EMPTY
    }

    /// The values of [`drawing`](Self::drawing) at `(t, q)`: the global coordinates of
    /// its points, 3 per point, then its scalars ([`Drawing::len`](crate::Drawing::len)
    /// values).
    fn drawing_values(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let _ = (t, q);
        out.fill(0.0);
    }

    /// The masses of the bodies of [`Info::bodies`] (one value per body), at the
    /// current parameters; `t` and `q` are there for the rare mass that depends on them.
    fn body_masses(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let _ = (t, q);
        out.fill(0.0);
    }

    /// The named outputs of [`Info::outputs`].
    fn outputs(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
        let _ = (t, q, qd);
        out.fill(0.0);
    }

    /// The contact gaps of [`Info::contacts`] (non-negative while open).
    fn contact_gaps(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let _ = (t, q);
        out.fill(0.0);
    }

    /// The contact normal Jacobian `D = ∂gap/∂q`, as values of [`Info::contact_pattern`].
    fn contact_jacobian(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let _ = (t, q);
        out.fill(0.0);
    }

    /// The Jacobian with respect to `[q; q̇]` (columns `0..n`, then `n..2n`) of the
    /// stacked residuals
    ///
    /// ```text
    /// rows 0..n          M(q) a + C_qᵀ λ_h + Gᵀ λ_nh − Q(q, q̇, t)
    /// rows n..n+m_h      C_q a − γ_h
    /// next m_nh rows     G a − γ_nh
    /// next m_h rows      C_q q̇ + C_t
    /// next m_nh rows     G q̇ + g
    /// ```
    ///
    /// with `inputs = [a; λ_h; λ_nh]` held fixed (length `n + m_h + m_nh`), as values of
    /// [`Info::linearization`]. At a solution `(a, λ)` of the index-1 equations these are
    /// the partial derivatives of the linearized equations of motion; see
    /// [`linearize`](crate::linearize). Generated for `#[mechanism(linearize)]`; the default
    /// writes zeros.
    fn linearization_jacobian(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        inputs: &[f64],
        out: &mut [f64],
    ) {
        let _ = (t, q, qd, inputs);
        out.fill(0.0);
    }

    /// The time partials `∂gap/∂t` of the contacts (length [`Info::ncontacts`]), so that
    /// the normal velocity is `v_n = D q̇ + ∂gap/∂t`; zero for gaps that do not depend on
    /// time.
    fn contact_rate(&self, t: f64, q: &[f64], out: &mut [f64]) {
        let _ = (t, q);
        out.fill(0.0);
    }

    /// `γ_c = −(D q̇)_q q̇ − 2 D_t q̇ − gap_tt`, so that `D q̈ = γ_c` keeps a closed contact
    /// closed (length [`Info::ncontacts`]); used by resting contact.
    fn contact_gamma(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
        let _ = (t, q, qd);
        out.fill(0.0);
    }

    /// The values of data slot `index` ([`Info::data`]).
    fn data(&self, index: usize) -> &[f64] {
        let _ = index;
        &[]
    }

    /// Replaces the values of data slot `index`.
    ///
    /// # Errors
    /// [`DataError`] when there is no such slot, the length differs from the slot's, or a
    /// value is not finite.
    fn set_data(&mut self, index: usize, values: &[f64]) -> Result<(), DataError> {
        let _ = values;
        Err(DataError::NoSlot {
            model: self.info().name,
            index,
        })
    }
}
