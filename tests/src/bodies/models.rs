//! Body-level models that exercise every joint type and force element. Their states
//! need not be consistent: the tests compare derivatives at random states.

/// Spatial bodies (Euler parameters, successive rotations, a relative frame) joined by
/// every spatial joint, with a spring-damper, a point force and a torque.
#[pfaff::mechanism]
pub mod spatial_zoo {
    const m: f64 = 1.5;
    const k: f64 = 40.0;
    const c: f64 = 0.7;
    const len: f64 = 0.4;

    static x1: Coordinate = Coordinate {};
    static y1: Coordinate = Coordinate {};
    static z1: Coordinate = Coordinate {};
    static e0: Coordinate = Coordinate { q0: 1.0 };
    static e1: Coordinate = Coordinate {};
    static e2: Coordinate = Coordinate {};
    static e3: Coordinate = Coordinate {};
    static x2: Coordinate = Coordinate {};
    static y2: Coordinate = Coordinate {};
    static z2: Coordinate = Coordinate {};
    static psi: Coordinate = Coordinate {};
    static th: Coordinate = Coordinate {};
    static ph: Coordinate = Coordinate {};
    static s: Coordinate = Coordinate {};
    static r: Coordinate = Coordinate {};

    static gravity: Force = Gravity {
        acceleration: [0.0, 0.0, -9.81],
    };
    static b1: Body = Body {
        origin: [x1, y1, z1],
        rotation: euler_parameters(e0, e1, e2, e3),
        mass: m,
        inertia: [[0.3, 0.01, 0.02], [0.01, 0.4, 0.03], [0.02, 0.03, 0.5]],
        com: [0.1, 0.0, -0.05],
    };
    static b2: Body = Body {
        origin: [x2, y2, z2],
        rotation: rot_z(psi) * rot_x(th) * rot_y(ph),
        mass: 2.0,
        inertia: diag(0.2, 0.3, 0.25),
    };
    /// A frame relative to b2: slides by `s` along b2's x axis and turns by `r` about it.
    static b3: Body = Body {
        parent: b2,
        origin: [s, 0.1, 0.0],
        rotation: rot_x(r),
        mass: 0.5,
        inertia: diag(0.01, 0.02, 0.02),
    };

    static ball: Joint = Spherical {
        a: b1,
        at_a: [0.2, 0.0, 0.0],
        b: b2,
        at_b: [-0.2, 0.1, 0.0],
    };
    static hinge: Joint = Revolute {
        a: b1,
        at_a: [0.0, 0.3, 0.0],
        axis_a: [0.0, 0.0, 1.0],
        b: ground,
        at_b: [0.1, 0.2, 0.3],
        axis_b: [1.0, 1.0, 0.0],
    };
    static cross: Joint = Universal {
        a: b2,
        axis_a: [1.0, 0.0, 0.0],
        b: b3,
        at_b: [0.0, 0.2, 0.0],
        axis_b: [0.0, 1.0, 0.0],
    };
    static sleeve: Joint = Cylindrical {
        a: b3,
        axis_a: [0.0, 0.0, 1.0],
        b: b1,
        at_b: [0.0, 0.0, 0.1],
        axis_b: [0.0, 0.3, 1.0],
    };
    static slide: Joint = Prismatic {
        a: b2,
        at_a: [0.0, 0.0, 0.2],
        axis_a: [0.0, 1.0, 0.0],
        b: ground,
    };
    static weld: Joint = Fixed {
        a: b3,
        b: b1,
        at_b: [0.3, 0.0, 0.0],
    };
    static rod: Joint = Distance {
        a: b1,
        at_a: [0.0, 0.0, 0.4],
        b: b3,
        length: len,
    };
    static motor: Joint = Driver {
        value: r,
        motion: 2.0 * t + 0.1 * t * t,
    };
    static skate: Joint = KnifeEdge {
        a: b2,
        at_a: [0.1, 0.0, -0.2],
        lateral: [0.0, 1.0, 0.0],
    };
    static no_drift: Joint = ZeroVelocity {
        a: b3,
        at_a: [0.0, 0.1, 0.0],
        along: b1.axis([1.0, 0.0, 0.0]),
    };
    static wheel: Joint = RollingWheel {
        a: b1,
        axis: [0.0, 1.0, 0.0],
        radius: 0.3,
    };

    static spring: Force = SpringDamper {
        a: b1,
        at_a: [0.0, 0.1, 0.0],
        b: b3,
        stiffness: k,
        damping: c,
        rest_length: 0.25,
    };
    static push: Force = PointForce {
        a: b2,
        at_a: [0.1, 0.2, 0.3],
        force: [x1 * y2, 3.0 * t, b2.velocity([0.0, 0.0, 0.1]).z()],
    };
    static twist: Force = Torque {
        a: b3,
        torque: [0.5, -0.2 * psi, 1.0],
    };
    static tip: Point = Point {
        frame: b3,
        at: [0.2, 0.0, 0.1],
    };
}

/// Planar bodies, one of them relative to another, joined by every planar joint, with a
/// knife edge, a spring-damper, a point force and a torque.
#[pfaff::mechanism]
pub mod planar_zoo {
    static x1: Coordinate = Coordinate {};
    static y1: Coordinate = Coordinate {};
    static a1: Coordinate = Coordinate {};
    static x2: Coordinate = Coordinate {};
    static y2: Coordinate = Coordinate {};
    static a2: Coordinate = Coordinate {};
    static rel: Coordinate = Coordinate {};

    static gravity: Force = Gravity {
        acceleration: [0.0, -9.81],
    };
    static p1: Body = Body {
        origin: [x1, y1],
        angle: a1,
        mass: 1.0,
        inertia: 0.1,
        com: [0.05, 0.01],
    };
    static p2: Body = Body {
        origin: [x2, y2],
        angle: a2,
        mass: 2.0,
        inertia: 0.3,
    };
    static p3: Body = Body {
        parent: p1,
        origin: [0.4, 0.0],
        angle: rel,
        mass: 0.5,
        inertia: 0.02,
    };
    static pin: Joint = Revolute {
        a: p1,
        at_a: [0.1, 0.2],
        b: p2,
        at_b: [-0.3, 0.0],
    };
    static track: Joint = Prismatic {
        a: p2,
        at_a: [0.0, 0.1],
        axis_a: [1.0, 2.0],
        b: p3,
        angle: 0.2,
    };
    static glue: Joint = Fixed {
        a: p3,
        at_a: [0.1, 0.0],
        b: ground,
        at_b: [1.0, 1.0],
    };
    static tie: Joint = Distance {
        a: p2,
        at_a: [0.2, 0.0],
        b: ground,
        length: 1.0,
    };
    static turn: Joint = Driver {
        value: p3.angle() - p2.angle(),
        motion: t.sin(),
    };
    static blade: Joint = KnifeEdge {
        a: p2,
        at_a: [-0.2, 0.0],
        lateral: [0.0, 1.0],
    };
    static spring: Force = SpringDamper {
        a: p1,
        b: p2,
        at_b: [0.3, 0.0],
        stiffness: 10.0,
        damping: 0.5,
        rest_length: 0.5,
    };
    static push: Force = PointForce {
        a: p3,
        at_a: [0.1, 0.1],
        force: [1.0, x2],
    };
    static spin: Force = Torque {
        a: p2,
        torque: 0.3 * a1,
    };
}
