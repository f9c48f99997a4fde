//! A spatial four-bar linkage (RSUR) in absolute coordinates with Euler parameters.

/// Spatial four-bar linkage in the seed's absolute coordinates: three bodies, each with
/// its frame's origin and Euler parameters, joined by revolute, spherical and universal
/// joints; one degree of freedom, swinging under gravity (−z).
///
/// The crank turns about the global x axis at the origin; its pin, 0.2 m along its y
/// axis, is a spherical joint with the coupler. The coupler's other end, `l2` along its
/// x axis, is a universal joint with the rocker's tip (the coupler's y axis across the
/// rocker's z axis), which removes the coupler's spin about its own line. The rocker
/// turns about the global z axis at `(0.6, 0.4, 0)`. The declared state is the
/// configuration with the crank vertical and the rocker pointing along −x, where the
/// coupler runs from `(0, 0, 0.2)` to `(0.3, 0.4, 0)`; the crank starts at 2 rad/s.
/// Constraints: 2 × 5 revolute rows, 3 spherical, 4 universal and 3 normalizations, 20
/// rows for 21 coordinates.
#[pfaff::mechanism]
pub mod spatial_four_bar {
    /// Crank length [m].
    const l1: f64 = 0.2;
    /// Coupler length [m].
    const l2: f64 = 0.5385164807134504;
    /// Rocker length [m].
    const l3: f64 = 0.3;
    /// Crank mass [kg].
    const m1: f64 = 1.0;
    /// Coupler mass [kg].
    const m2: f64 = 2.0;
    /// Rocker mass [kg].
    const m3: f64 = 1.5;
    /// Moment of inertia of a slender rod about an axis across it at its centre, per
    /// unit mass and squared length.
    const rod: f64 = 1.0 / 12.0;
    /// Moment of inertia about a rod's own axis [kg m²] (thin rods, small but non-zero).
    const axial: f64 = 1e-4;
    /// Gravitational acceleration, along −z [m/s²].
    const g: f64 = 9.81;

    /// Crank frame origin, x [m].
    static x1: Coordinate = Coordinate {};
    /// Crank frame origin, y [m].
    static y1: Coordinate = Coordinate {};
    /// Crank frame origin, z [m].
    static z1: Coordinate = Coordinate {};
    /// Crank Euler parameter θ0.
    static a0: Coordinate = Coordinate {
        q0: 0.7071067811865476,
        qd0: -0.7071067811865476,
    };
    /// Crank Euler parameter θ1.
    static a1: Coordinate = Coordinate {
        q0: 0.7071067811865476,
        qd0: 0.7071067811865476,
    };
    /// Crank Euler parameter θ2.
    static a2: Coordinate = Coordinate {};
    /// Crank Euler parameter θ3.
    static a3: Coordinate = Coordinate {};
    /// Coupler frame origin (the spherical joint), x [m].
    static x2: Coordinate = Coordinate {};
    /// Coupler frame origin, y [m].
    static y2: Coordinate = Coordinate {};
    /// Coupler frame origin, z [m].
    static z2: Coordinate = Coordinate { q0: l1 };
    /// Coupler Euler parameter θ0.
    static b0: Coordinate = Coordinate {
        q0: 0.8782884926686126,
    };
    /// Coupler Euler parameter θ1.
    static b1: Coordinate = Coordinate {
        q0: -0.08457145447179014,
    };
    /// Coupler Euler parameter θ2.
    static b2: Coordinate = Coordinate {
        q0: 0.16914290894358025,
    };
    /// Coupler Euler parameter θ3.
    static b3: Coordinate = Coordinate {
        q0: 0.4391442463343064,
    };
    /// Rocker frame origin (its pivot), x [m].
    static x3: Coordinate = Coordinate { q0: 0.6 };
    /// Rocker frame origin, y [m].
    static y3: Coordinate = Coordinate { q0: 0.4 };
    /// Rocker frame origin, z [m].
    static z3: Coordinate = Coordinate {};
    /// Rocker Euler parameter θ0.
    static c0: Coordinate = Coordinate {};
    /// Rocker Euler parameter θ1.
    static c1: Coordinate = Coordinate {};
    /// Rocker Euler parameter θ2.
    static c2: Coordinate = Coordinate {};
    /// Rocker Euler parameter θ3.
    static c3: Coordinate = Coordinate { q0: 1.0 };

    static gravity: Force = Gravity {
        acceleration: [0.0, 0.0, -g],
    };

    /// The crank, a rod along its y axis from the pivot.
    static crank: Body = Body {
        origin: [x1, y1, z1],
        rotation: euler_parameters(a0, a1, a2, a3),
        mass: m1,
        com: [0.0, 0.5 * l1, 0.0],
        inertia: diag(rod * m1 * l1 * l1, axial, rod * m1 * l1 * l1),
    };
    /// The coupler, a rod along its x axis from the crank pin.
    static coupler: Body = Body {
        origin: [x2, y2, z2],
        rotation: euler_parameters(b0, b1, b2, b3),
        mass: m2,
        com: [0.5 * l2, 0.0, 0.0],
        inertia: diag(axial, rod * m2 * l2 * l2, rod * m2 * l2 * l2),
    };
    /// The rocker, a rod along its x axis from its pivot.
    static rocker: Body = Body {
        origin: [x3, y3, z3],
        rotation: euler_parameters(c0, c1, c2, c3),
        mass: m3,
        com: [0.5 * l3, 0.0, 0.0],
        inertia: diag(axial, rod * m3 * l3 * l3, rod * m3 * l3 * l3),
    };

    /// The crank turns about the global x axis at the origin.
    static crank_pivot: Joint = Revolute {
        a: crank,
        axis_a: [1.0, 0.0, 0.0],
        b: ground,
        axis_b: [1.0, 0.0, 0.0],
    };
    /// The crank pin.
    static crank_pin: Joint = Spherical {
        a: crank,
        at_a: [0.0, l1, 0.0],
        b: coupler,
    };
    /// The coupler's far end on the rocker's tip.
    static rocker_pin: Joint = Universal {
        a: coupler,
        at_a: [l2, 0.0, 0.0],
        axis_a: [0.0, 1.0, 0.0],
        b: rocker,
        at_b: [l3, 0.0, 0.0],
        axis_b: [0.0, 0.0, 1.0],
    };
    /// The rocker turns about the global z axis at (0.6, 0.4, 0).
    static rocker_pivot: Joint = Revolute {
        a: rocker,
        axis_a: [0.0, 0.0, 1.0],
        b: ground,
        at_b: [0.6, 0.4, 0.0],
        axis_b: [0.0, 0.0, 1.0],
    };

    /// Crank angle from the y axis about x [rad].
    #[output]
    fn crank_angle() -> f64 {
        let pin = crank.point([0.0, 1.0, 0.0]);
        pin.z().atan2(pin.y())
    }
}
