//! A spatial flexible pendulum: a beam of spatial Euler–Bernoulli elements hanging from a
//! ball joint, its floating frame oriented by Euler parameters, under gravity.

/// Spatial flexible pendulum: a uniform steel bar (12 mm × 8 mm, 1 m) hanging from a
/// ball joint at its end.
///
/// The bar is 8 spatial beam elements (docs/theory.md E20, §beam-elements) clamped to its floating
/// frame at the pivot (node 0) and reduced to its four lowest modes `p1 … p4` by
/// `pfaff::flex` when the model is built (`SpatialBeam` data slot): bending in the stiff
/// and the soft direction, twice each (clamped-free frequencies 42.0, 63.0, 263 and
/// 395 rad/s at the defaults, $1.8751^2\sqrt{EI/\rho A}/l^2$ for the first of each
/// plane). The frame's origin is the fixed pivot; its orientation is the Euler parameters
/// `e0 … e3` (normalization generated as the holonomic constraint `rod.normalization`),
/// with the bar along the frame's x axis. Gravity `g` acts along −z.
///
/// It starts at rest in its frame, the undeformed bar at `phi0` from the downward
/// vertical in the x–z plane, turning about the vertical at `spin` rad/s: a swing that
/// leaves its plane, whose bending the Coriolis and centrifugal loads excite. Output
/// `tip_deflection`: the tip's displacement perpendicular to the frame's x axis (the
/// bar's undeformed line) [m].
#[pfaff::mechanism]
pub mod flexible_pendulum {
    /// Length of the bar [m].
    const l: f64 = 1.0;
    /// Mass per unit length ρA [kg/m] (steel, 7850 kg/m³, 12 mm × 8 mm).
    const rho_a: f64 = 0.7536;
    /// Axial stiffness EA [N] (E = 2.1e11 Pa).
    const ea: f64 = 2.016e7;
    /// Bending stiffness EI_y [N m²] (deflection along the frame's z, the soft direction).
    const ei_y: f64 = 107.52;
    /// Bending stiffness EI_z [N m²] (deflection along the frame's y).
    const ei_z: f64 = 241.92;
    /// Torsional stiffness GJ [N m²] (G = 8.1e10 Pa, J = 0.196 b h³).
    const gj: f64 = 97.5;
    /// ρI_y [kg m] (rotary inertia of the section).
    const rho_iy: f64 = 4.019e-6;
    /// ρI_z [kg m].
    const rho_iz: f64 = 9.043e-6;
    /// Gravitational acceleration, along −z [m/s²].
    const g: f64 = 9.81;
    /// Initial angle of the bar from the downward vertical [rad].
    const phi0: f64 = 0.5;
    /// Initial rate of turn about the vertical [rad/s].
    const spin: f64 = 2.0;

    /// The bar's invariants: 8 spatial elements clamped at the pivot, 4 modes.
    static bar: Data = SpatialBeam {
        elements: 8,
        length: l,
        rho_a,
        ea,
        ei_y,
        ei_z,
        gj,
        rho_iy,
        rho_iz,
        modes: 4,
        reference: Clamped,
    };

    /// Euler parameter θ0.
    static e0: Coordinate = Coordinate {
        q0: (0.25 * PI - 0.5 * phi0).cos(),
    };
    /// Euler parameter θ1.
    static e1: Coordinate = Coordinate {
        qd0: -0.5 * spin * (0.25 * PI - 0.5 * phi0).sin(),
    };
    /// Euler parameter θ2.
    static e2: Coordinate = Coordinate {
        q0: (0.25 * PI - 0.5 * phi0).sin(),
    };
    /// Euler parameter θ3.
    static e3: Coordinate = Coordinate {
        qd0: 0.5 * spin * (0.25 * PI - 0.5 * phi0).cos(),
    };
    /// First mode (bending in the soft direction) [√kg m].
    static p1: Coordinate = Coordinate {};
    /// Second mode (bending in the stiff direction) [√kg m].
    static p2: Coordinate = Coordinate {};
    /// Third mode [√kg m].
    static p3: Coordinate = Coordinate {};
    /// Fourth mode [√kg m].
    static p4: Coordinate = Coordinate {};

    static gravity: Force = Gravity {
        acceleration: [0.0, 0.0, -g],
    };

    /// The bar: its floating frame at the pivot, x along the undeformed bar.
    static rod: Body = Deformable {
        origin: [0.0, 0.0, 0.0],
        rotation: euler_parameters(e0, e1, e2, e3),
        elastic: [p1, p2, p3, p4],
        data: bar,
    };

    /// A quarter of the bar.
    static quarter: Point = Point {
        frame: rod,
        at: rod.node(2),
    };
    /// The middle of the bar.
    static middle: Point = Point {
        frame: rod,
        at: rod.node(4),
    };
    /// Three quarters of the bar.
    static three_quarters: Point = Point {
        frame: rod,
        at: rod.node(6),
    };
    /// The tip.
    static tip: Point = Point {
        frame: rod,
        at: rod.node(8),
    };

    /// The tip's displacement perpendicular to the bar's undeformed line [m].
    #[output]
    fn tip_deflection() -> f64 {
        let u = rod.node(8);
        (u.y() * u.y() + u.z() * u.z()).sqrt()
    }
}
