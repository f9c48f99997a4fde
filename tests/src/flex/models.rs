//! Deformable bodies for the property tests V6 and V7 of docs/theory.md §verification and for the rigid
//! limit. Their states need not be consistent: the tests compare quantities at random
//! states.

/// V6: a free planar frame carrying the two-node Euler–Bernoulli element of docs/theory.md
/// §beam-elements (E18) with its six nodal coordinates, integrated from its shape functions; the
/// centre line is offset by `off` from the frame's x axis, so that every invariant of
/// E10 is non-zero. No stiffness: the forces are `Q_v`.
#[pfaff::mechanism]
pub mod planar_element {
    /// Element length [m].
    const l: f64 = 0.7;
    /// Mass per unit length [kg/m].
    const rho_a: f64 = 2.5;
    /// Offset of the centre line [m].
    const off: f64 = 0.05;

    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    static th: Coordinate = Coordinate {};
    static u1: Coordinate = Coordinate {};
    static v1: Coordinate = Coordinate {};
    static t1: Coordinate = Coordinate {};
    static u2: Coordinate = Coordinate {};
    static v2: Coordinate = Coordinate {};
    static t2: Coordinate = Coordinate {};

    /// The element, ξ = x/l.
    static beam: Body = Deformable {
        origin: [x, y],
        angle: th,
        elastic: [u1, v1, t1, u2, v2, t2],
        span: 0.0..1.0,
        position: |xi| [l * xi, off],
        density: rho_a * l,
        displacement: |xi| {
            [
                (1.0 - xi) * u1 + xi * u2,
                (1.0 - 3.0 * xi * xi + 2.0 * xi.powi(3)) * v1
                    + l * (xi - 2.0 * xi * xi + xi.powi(3)) * t1
                    + (3.0 * xi * xi - 2.0 * xi.powi(3)) * v2
                    + l * (xi.powi(3) - xi * xi) * t2,
            ]
        },
    };
}

/// V7: a free spatial frame (Euler parameters) carrying a body with three elastic
/// coordinates whose shape functions mix polynomials, trigonometric and hyperbolic
/// functions, along an off-axis line with a varying density.
#[pfaff::mechanism]
pub mod spatial_flexible {
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    static z: Coordinate = Coordinate {};
    static e0: Coordinate = Coordinate { q0: 1.0 };
    static e1: Coordinate = Coordinate {};
    static e2: Coordinate = Coordinate {};
    static e3: Coordinate = Coordinate {};
    static f1: Coordinate = Coordinate {};
    static f2: Coordinate = Coordinate {};
    static f3: Coordinate = Coordinate {};

    static body: Body = Deformable {
        origin: [x, y, z],
        rotation: euler_parameters(e0, e1, e2, e3),
        elastic: [f1, f2, f3],
        span: 0.0..1.0,
        position: |s| [0.8 * s, 0.1, -0.05 + 0.2 * s],
        density: |s| 1.5 + s,
        displacement: |s| {
            [
                f1 * s * s + f3 * 0.3 * s,
                f2 * (2.0 * s).sin() + f3 * s,
                f3 * (1.0 - s.cos()) + f1 * (0.5 * s).sinh() - f2 * s.exp() * 0.2,
            ]
        },
    };
}

/// The slider crank of `flexible_crank` with a rigid connecting rod (the same mass and
/// inertia about the crank tip): the limit of the elastic rod as its stiffness grows.
#[pfaff::mechanism]
pub mod rigid_crank {
    const m1: f64 = 0.36;
    const m2: f64 = 0.151104;
    const m3: f64 = 0.075552;
    const l1: f64 = 0.15;
    const l2: f64 = 0.30;
    const j1: f64 = 0.002727;
    const j2: f64 = 0.0045339259;
    const omega: f64 = 150.0;

    static phi1: Coordinate = Coordinate { qd0: 150.0 };
    static phi2: Coordinate = Coordinate { qd0: -75.0 };
    static x3: Coordinate = Coordinate { q0: 0.45 };

    static crank: Body = Body {
        origin: [0.0, 0.0],
        angle: phi1,
        mass: m1,
        com: [0.5 * l1, 0.0],
        inertia: j1 - 0.25 * m1 * l1 * l1,
    };
    static rod: Body = Body {
        origin: [l1 * phi1.cos(), l1 * phi1.sin()],
        angle: phi2,
        mass: m2,
        com: [0.5 * l2, 0.0],
        inertia: j2 - 0.25 * m2 * l2 * l2,
    };
    static slider: Body = Body {
        origin: [x3, 0.0],
        angle: 0.0,
        mass: m3,
    };
    static pin_b: Joint = Revolute {
        a: rod,
        at_a: [l2, 0.0],
        b: slider,
    };
    static driver: Joint = Driver {
        value: crank.angle(),
        motion: omega * t,
    };
}
