//! Bricard's orthogonal overconstrained 6R linkage (the mechanism of the IFToMM
//! benchmark A04): five links and six revolute joints closing a loop.

/// Bricard's orthogonal 6R linkage: five rods of length 1 m and mass 1 kg (square
/// section 0.1 m) and the ground, joined in a loop by six revolute joints whose
/// consecutive axes are perpendicular; gravity along −y.
///
/// Grübler's count gives no mobility (five relative joint angles, five closure
/// conditions), yet the linkage moves with one degree of freedom: the closure joint's
/// five rows are dependent everywhere, so the constraint Jacobian is rank-deficient at
/// every configuration. The rods are described in minimal coordinates, each frame
/// relative to the previous one through its joint angle, and the loop is closed by a
/// `Revolute` joint between the last rod and the ground. The declared configuration has
/// the joints at the corners `(0,0,0) → (1,0,0) → (1,1,0) → (1,1,1) → (0,1,1) →
/// (0,0,1)` of the unit cube, with axes y, z, x, y, z, x.
#[pfaff::mechanism]
pub mod bricard {
    /// Rod length [m].
    const l: f64 = 1.0;
    /// Rod mass [kg].
    const m: f64 = 1.0;
    /// Side of the rods' square section [m].
    const s: f64 = 0.1;
    /// Moment of inertia of a rod about its own axis [kg m²].
    const i_axial: f64 = m * (s * s + s * s) / 12.0;
    /// Moment of inertia of a rod about an axis across it at its centre [kg m²].
    const i_across: f64 = m * (l * l + s * s) / 12.0;
    /// Gravitational acceleration, along −y [m/s²].
    const g: f64 = 9.81;

    /// Angle of joint 1 (ground–rod 1, axis y) [rad].
    static q1: Coordinate = Coordinate { q0: 0.0, qd0: 1.0 };
    /// Angle of joint 2 (rod 1–rod 2, axis z) [rad].
    static q2: Coordinate = Coordinate {};
    /// Angle of joint 3 (rod 2–rod 3, axis x) [rad].
    static q3: Coordinate = Coordinate {};
    /// Angle of joint 4 (rod 3–rod 4, axis y) [rad].
    static q4: Coordinate = Coordinate {};
    /// Angle of joint 5 (rod 4–rod 5, axis z) [rad].
    static q5: Coordinate = Coordinate {};

    static gravity: Force = Gravity {
        acceleration: [0.0, -g, 0.0],
    };

    /// Rod 1, along its x axis from the origin.
    static rod1: Body = Body {
        origin: [0.0, 0.0, 0.0],
        rotation: rot_y(q1),
        mass: m,
        com: [0.5 * l, 0.0, 0.0],
        inertia: diag(i_axial, i_across, i_across),
    };
    /// Rod 2, along its y axis from the end of rod 1.
    static rod2: Body = Body {
        parent: rod1,
        origin: [l, 0.0, 0.0],
        rotation: rot_z(q2),
        mass: m,
        com: [0.0, 0.5 * l, 0.0],
        inertia: diag(i_across, i_axial, i_across),
    };
    /// Rod 3, along its z axis from the end of rod 2.
    static rod3: Body = Body {
        parent: rod2,
        origin: [0.0, l, 0.0],
        rotation: rot_x(q3),
        mass: m,
        com: [0.0, 0.0, 0.5 * l],
        inertia: diag(i_across, i_across, i_axial),
    };
    /// Rod 4, along its −x axis from the end of rod 3.
    static rod4: Body = Body {
        parent: rod3,
        origin: [0.0, 0.0, l],
        rotation: rot_y(q4),
        mass: m,
        com: [-0.5 * l, 0.0, 0.0],
        inertia: diag(i_axial, i_across, i_across),
    };
    /// Rod 5, along its −y axis from the end of rod 4.
    static rod5: Body = Body {
        parent: rod4,
        origin: [-l, 0.0, 0.0],
        rotation: rot_z(q5),
        mass: m,
        com: [0.0, -0.5 * l, 0.0],
        inertia: diag(i_across, i_axial, i_across),
    };

    /// The sixth joint closes the loop: the end of rod 5 turns about the global x axis
    /// at (0, 0, 1).
    static closure: Joint = Revolute {
        a: rod5,
        at_a: [0.0, -l, 0.0],
        axis_a: [1.0, 0.0, 0.0],
        b: ground,
        at_b: [0.0, 0.0, l],
        axis_b: [1.0, 0.0, 0.0],
    };

    /// Height of the far corner (the joint between rods 3 and 4) [m].
    #[output]
    fn corner_y() -> f64 {
        rod4.origin().y()
    }
}
