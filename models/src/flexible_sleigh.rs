//! A Chaplygin sleigh whose blade sits at the free end of an elastic tail: a
//! non-holonomic constraint at a material point of a deformable body (the subject of
//! Rismantab-Sany & Shabana, "Impulsive motion of non-holonomic deformable multibody
//! systems", J. Sound Vib. 127(2), 1988), free and striking a wall.

/// Chaplygin sleigh on an elastic tail: a knife edge at a material point of a deformable
/// body.
///
/// A rigid sled (mass `m`, moment of inertia `ic` about its centre of mass, frame at the
/// centre of mass `(x, y)`, heading `phi`) carries a uniform elastic tail of length `l`
/// clamped at the sled's point `c` behind the centre of mass and pointing backwards. The
/// tail is `elements` planar Euler–Bernoulli beam elements (`rho_a`, `ea`, `ei`) clamped
/// to its floating frame at its root and reduced to its three lowest modes `p1 p2 p3`
/// when the model is built (clamped-free bending at 70.3, 441 and 1234 rad/s at the
/// defaults, $\beta_k^2\sqrt{EI/\rho A}/l^2$). The blade is at the tail's free end and
/// turns with the end's section: the material point at node `elements` has no velocity
/// across the blade, whose direction is the tail's axis turned by the end's elastic
/// rotation (`tail.node_rotation(..)`). The constraint's coefficients therefore depend
/// on the elastic coordinates, and the elastic velocities enter it: of the 6
/// coordinates all are independent, of the 6 velocities 5.
///
/// It starts undeformed, moving forward at `v0` and turning at `spin` (the blade's
/// lateral velocity zero): the blade's reaction bends the tail and excites its modes.
/// Undamped and scleronomic: the energy is conserved. With `ei → ∞` it tends to the
/// rigid sleigh of mass `m + rho_a l` whose blade is `c + l` behind the sled's centre
/// of mass.
#[pfaff::mechanism]
pub mod flexible_sleigh {
    /// Mass of the sled [kg].
    const m: f64 = 2.0;
    /// Moment of inertia of the sled about its centre of mass [kg m²].
    const ic: f64 = 0.05;
    /// Distance from the sled's centre of mass back to the tail's root [m].
    const c: f64 = 0.1;
    /// Length of the tail [m].
    const l: f64 = 0.2;
    /// Mass per unit length of the tail [kg/m].
    const rho_a: f64 = 0.5;
    /// Axial stiffness of the tail EA [N].
    const ea: f64 = 1.0e6;
    /// Bending stiffness of the tail EI [N m²].
    const ei: f64 = 0.32;
    /// Initial forward speed [m/s].
    const v0: f64 = 1.0;
    /// Initial rate of turn [rad/s].
    const spin: f64 = 2.0;

    /// The tail: 6 planar beam elements clamped at its root, 3 modes.
    static tail_fe: Data = Beam {
        elements: 6,
        length: l,
        rho_a,
        ea,
        ei,
        modes: 3,
        reference: Clamped,
    };

    /// Position of the sled's centre of mass along x [m].
    static x: Coordinate = Coordinate { q0: 0.0, qd0: v0 };
    /// Position of the sled's centre of mass along y [m].
    static y: Coordinate = Coordinate {
        q0: 0.0,
        qd0: (c + l) * spin,
    };
    /// Heading: angle from the x axis to the sled's axis [rad].
    static phi: Coordinate = Coordinate { q0: 0.0, qd0: spin };
    /// First bending mode of the tail [√kg m].
    static p1: Coordinate = Coordinate {};
    /// Second bending mode of the tail [√kg m].
    static p2: Coordinate = Coordinate {};
    /// Third bending mode of the tail [√kg m].
    static p3: Coordinate = Coordinate {};

    /// The sled, its frame at its centre of mass.
    static sled: Body = Body {
        origin: [x, y],
        angle: phi,
        mass: m,
        inertia: ic,
    };
    /// The elastic tail, its frame at its root on the sled, x along the tail (backwards).
    static tail: Body = Deformable {
        origin: [x - c * phi.cos(), y - c * phi.sin()],
        angle: phi + PI,
        elastic: [p1, p2, p3],
        data: tail_fe,
    };

    /// The blade at the tail's free end: no velocity across the blade, which turns with
    /// the end's section.
    static blade: Joint = KnifeEdge {
        a: tail,
        at_a: tail.node(6),
        lateral: [-tail.node_rotation(6).sin(), tail.node_rotation(6).cos()],
    };

    /// A third of the tail (drawn).
    static tail_third: Point = Point {
        frame: tail,
        at: tail.node(2),
    };
    /// Two thirds of the tail (drawn).
    static tail_two_thirds: Point = Point {
        frame: tail,
        at: tail.node(4),
    };
    /// The blade point (drawn).
    static tail_end: Point = Point {
        frame: tail,
        at: tail.node(6),
    };

    /// Lateral deflection of the blade point from the tail's undeformed line [m].
    #[output]
    fn tip_deflection() -> f64 {
        tail.node(6).y()
    }
}

/// The sleigh of `flexible_sleigh` whose front tip strikes a wall: an impact of a
/// deformable body under a non-holonomic constraint.
///
/// The sled and tail of `flexible_sleigh`, the sled's front tip `tip` ahead of its centre
/// of mass on its axis, the wall the line `x = wall`. The default state is the instant
/// of impact of the rigid `sleigh_wall` (heading 30°, forward speed 1, turning rate 0.5,
/// tip on the wall, tail undeformed and at rest in its frame). The impulse acts on the
/// rigid sled only, but the sled's and the tail's inertia are coupled and the blade's
/// constraint involves the elastic velocities: the elastic velocities jump at the
/// impact, and so do the blade's finite reaction and the tail's vibration.
#[pfaff::mechanism]
pub mod flexible_sleigh_wall {
    /// Mass of the sled [kg].
    const m: f64 = 2.0;
    /// Moment of inertia of the sled about its centre of mass [kg m²].
    const ic: f64 = 0.05;
    /// Distance from the sled's centre of mass back to the tail's root [m].
    const c: f64 = 0.1;
    /// Length of the tail [m].
    const l: f64 = 0.2;
    /// Mass per unit length of the tail [kg/m].
    const rho_a: f64 = 0.5;
    /// Axial stiffness of the tail EA [N].
    const ea: f64 = 1.0e6;
    /// Bending stiffness of the tail EI [N m²].
    const ei: f64 = 0.32;
    /// Distance from the sled's centre of mass forward to its tip [m].
    const tip: f64 = 0.4;
    /// Position of the wall, x [m].
    const wall: f64 = tip * FRAC_PI_6.cos();
    /// Coefficient of restitution of the wall.
    const e: f64 = 0.8;

    /// The tail: 6 planar beam elements clamped at its root, 3 modes.
    static tail_fe: Data = Beam {
        elements: 6,
        length: l,
        rho_a,
        ea,
        ei,
        modes: 3,
        reference: Clamped,
    };

    /// Position of the sled's centre of mass along x [m].
    static x: Coordinate = Coordinate {
        q0: 0.0,
        qd0: FRAC_PI_6.cos() - 0.5 * (c + l) * FRAC_PI_6.sin(),
    };
    /// Position of the sled's centre of mass along y [m].
    static y: Coordinate = Coordinate {
        q0: 0.0,
        qd0: FRAC_PI_6.sin() + 0.5 * (c + l) * FRAC_PI_6.cos(),
    };
    /// Heading: angle from the x axis to the sled's axis [rad].
    static phi: Coordinate = Coordinate {
        q0: FRAC_PI_6,
        qd0: 0.5,
    };
    /// First bending mode of the tail [√kg m].
    static p1: Coordinate = Coordinate {};
    /// Second bending mode of the tail [√kg m].
    static p2: Coordinate = Coordinate {};
    /// Third bending mode of the tail [√kg m].
    static p3: Coordinate = Coordinate {};

    /// The sled, its frame at its centre of mass.
    static sled: Body = Body {
        origin: [x, y],
        angle: phi,
        mass: m,
        inertia: ic,
    };
    /// The elastic tail, its frame at its root on the sled, x along the tail (backwards).
    static tail: Body = Deformable {
        origin: [x - c * phi.cos(), y - c * phi.sin()],
        angle: phi + PI,
        elastic: [p1, p2, p3],
        data: tail_fe,
    };

    /// The blade at the tail's free end: no velocity across the blade, which turns with
    /// the end's section.
    static blade: Joint = KnifeEdge {
        a: tail,
        at_a: tail.node(6),
        lateral: [-tail.node_rotation(6).sin(), tail.node_rotation(6).cos()],
    };

    /// The sled's front tip against the wall `x = wall` (normal −x).
    static front: Contact = PointPlane {
        point: sled.point([tip, 0.0]),
        normal: [-1.0, 0.0],
        offset: -wall,
        restitution: e,
    };

    /// A third of the tail (drawn).
    static tail_third: Point = Point {
        frame: tail,
        at: tail.node(2),
    };
    /// Two thirds of the tail (drawn).
    static tail_two_thirds: Point = Point {
        frame: tail,
        at: tail.node(4),
    };
    /// The blade point (drawn).
    static tail_end: Point = Point {
        frame: tail,
        at: tail.node(6),
    };

    /// Lateral deflection of the blade point from the tail's undeformed line [m].
    #[output]
    fn tip_deflection() -> f64 {
        tail.node(6).y()
    }
}
