//! The trait boundary between generated code and the runtime.
//!
//! `#[pfaff::mechanism]` emits one `impl Mechanism` per model. Everything crosses the
//! boundary as plain `f64` slices with caller-owned output buffers, so generated code
//! never allocates and never names a linear-algebra type. Matrices are written as the
//! values of their structurally non-zero entries, in the order of the pattern that
//! [`Info`] exports (row-major, sorted by row then column).
//!
//! Sign convention (math-spec §1): the equations of motion are
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

/// Static description of a model: sizes, names, patterns and structural flags.
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

    /// The free-motion residual of math-spec §8.6 (S2-18) with the applied forces
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
}
