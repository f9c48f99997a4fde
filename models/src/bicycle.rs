//! The Whipple bicycle benchmark of Meijaard, Papadopoulos, Ruina and Schwab (2007).

/// Whipple bicycle (Meijaard, Papadopoulos, Ruina, Schwab 2007), built from its
/// parameter table (docs/models.md), in the paper's axes: x forward, y right, z
/// down, the ground the plane `z = 0`.
///
/// Four rigid bodies: the rear wheel R, the rear frame with the rider B, the front
/// fork with the handlebar H and the front wheel F. The rear frame's origin is the rear
/// wheel's centre `(x, y, z)`; it turns by the yaw `psi` about z, the lean `phi` about
/// the new x axis and the pitch `theta` about the new y axis. The front frame turns
/// relative to the rear frame by the steer angle `delta` about the steer axis, tilted by
/// `lambda` from the vertical and meeting the ground the trail `c` ahead of the front
/// contact point. The wheels spin by `theta_r` and `theta_f` about their axles. In the
/// reference configuration (all angles 0) the bodies' axes are the global ones, so the
/// inertia tensors of the table are those of the bodies' frames.
///
/// Two `RollingWheel` joints generate the two holonomic contact conditions (which fix
/// `z` and `theta`) and the four no-slip conditions. Linearized about upright straight
/// running at speed `v` (`pfaff linearize bicycle --speed V`), the lean and steer obey
/// the benchmark's `M q̈ + v C1 q̇ + (g K0 + v² K2) q = 0`. It is drawn with z down
/// (`Scene { up }`), the frame and fork as tubes through their joints.
#[pfaff::mechanism(linearize)]
pub mod bicycle {
    /// Wheel base [m].
    const w: f64 = 1.02;
    /// Trail [m].
    const c: f64 = 0.08;
    /// Steer axis tilt from the vertical [rad].
    const lambda: f64 = PI / 10.0;
    /// Gravitational acceleration, along +z (down) [m/s²].
    const g: f64 = 9.81;
    /// Rear wheel radius [m].
    const r_r: f64 = 0.3;
    /// Rear wheel mass [kg].
    const m_r: f64 = 2.0;
    /// Rear wheel diametral moment of inertia [kg m²].
    const i_rxx: f64 = 0.0603;
    /// Rear wheel axial moment of inertia [kg m²].
    const i_ryy: f64 = 0.12;
    /// Rear body centre of mass, x [m].
    const x_b: f64 = 0.3;
    /// Rear body centre of mass, z [m].
    const z_b: f64 = -0.9;
    /// Rear body mass [kg].
    const m_b: f64 = 85.0;
    /// Rear body inertia about its centre of mass, xx [kg m²].
    const i_bxx: f64 = 9.2;
    /// Rear body inertia, xz [kg m²].
    const i_bxz: f64 = 2.4;
    /// Rear body inertia, yy [kg m²].
    const i_byy: f64 = 11.0;
    /// Rear body inertia, zz [kg m²].
    const i_bzz: f64 = 2.8;
    /// Front assembly centre of mass, x [m].
    const x_h: f64 = 0.9;
    /// Front assembly centre of mass, z [m].
    const z_h: f64 = -0.7;
    /// Front assembly mass [kg].
    const m_h: f64 = 4.0;
    /// Front assembly inertia about its centre of mass, xx [kg m²].
    const i_hxx: f64 = 0.05892;
    /// Front assembly inertia, xz [kg m²].
    const i_hxz: f64 = -0.00756;
    /// Front assembly inertia, yy [kg m²].
    const i_hyy: f64 = 0.06;
    /// Front assembly inertia, zz [kg m²].
    const i_hzz: f64 = 0.00708;
    /// Front wheel radius [m].
    const r_f: f64 = 0.35;
    /// Front wheel mass [kg].
    const m_f: f64 = 3.0;
    /// Front wheel diametral moment of inertia [kg m²].
    const i_fxx: f64 = 0.1405;
    /// Front wheel axial moment of inertia [kg m²].
    const i_fyy: f64 = 0.28;

    /// Rear wheel centre, x [m].
    static x: Coordinate = Coordinate { q0: 0.0, qd0: 4.6 };
    /// Rear wheel centre, y [m].
    static y: Coordinate = Coordinate {};
    /// Rear wheel centre, z (down) [m].
    static z: Coordinate = Coordinate { q0: -r_r };
    /// Yaw of the rear frame [rad].
    static psi: Coordinate = Coordinate {};
    /// Lean (roll) of the rear frame, positive to the right [rad].
    static phi: Coordinate = Coordinate { q0: 0.0, qd0: 0.5 };
    /// Pitch of the rear frame [rad].
    static theta: Coordinate = Coordinate {};
    /// Steer angle about the steer axis [rad].
    static delta: Coordinate = Coordinate {};
    /// Rear wheel rotation [rad].
    static theta_r: Coordinate = Coordinate {
        q0: 0.0,
        qd0: -4.6 / r_r,
    };
    /// Front wheel rotation [rad].
    static theta_f: Coordinate = Coordinate {
        q0: 0.0,
        qd0: -4.6 / r_f,
    };

    static gravity: Force = Gravity {
        acceleration: [0.0, 0.0, g],
    };

    /// Rear frame with the rider; its origin is the rear wheel's centre.
    static rear_frame: Body = Body {
        origin: [x, y, z],
        rotation: rot_z(psi) * rot_x(phi) * rot_y(theta),
        mass: m_b,
        com: [x_b, 0.0, z_b + r_r],
        inertia: [[i_bxx, 0.0, i_bxz], [0.0, i_byy, 0.0], [i_bxz, 0.0, i_bzz]],
    };
    /// Rear wheel.
    static rear_wheel: Body = Body {
        parent: rear_frame,
        origin: [0.0, 0.0, 0.0],
        rotation: rot_y(theta_r),
        mass: m_r,
        inertia: diag(i_rxx, i_ryy, i_rxx),
    };
    /// Front fork and handlebar; its origin is where the steer axis meets the ground in
    /// the reference configuration, and it turns by `delta` about the steer axis.
    static front_frame: Body = Body {
        parent: rear_frame,
        origin: [w + c, 0.0, r_r],
        rotation: rot_y(lambda) * rot_z(delta) * rot_y(-lambda),
        mass: m_h,
        com: [x_h - w - c, 0.0, z_h],
        inertia: [[i_hxx, 0.0, i_hxz], [0.0, i_hyy, 0.0], [i_hxz, 0.0, i_hzz]],
    };
    /// Front wheel.
    static front_wheel: Body = Body {
        parent: front_frame,
        origin: [-c, 0.0, -r_f],
        rotation: rot_y(theta_f),
        mass: m_f,
        inertia: diag(i_fxx, i_fyy, i_fxx),
    };

    /// Rear wheel rolling on the ground.
    static rear_contact: Joint = RollingWheel {
        a: rear_wheel,
        axis: [0.0, 1.0, 0.0],
        radius: r_r,
        up: [0.0, 0.0, -1.0],
    };
    /// Front wheel rolling on the ground.
    static front_contact: Joint = RollingWheel {
        a: front_wheel,
        axis: [0.0, 1.0, 0.0],
        radius: r_f,
        up: [0.0, 0.0, -1.0],
    };

    /// The benchmark's axes have z down.
    static view: Drawing = Scene {
        up: [0.0, 0.0, -1.0],
    };
    /// The rear frame as drawn (rear-frame coordinates, origin at the rear hub, z
    /// down): the chain and seat stays from the hub to the bottom bracket and the
    /// saddle, and the tubes to the head tube on the steer axis.
    static rear_stays: Drawing = Link {
        frame: rear_frame,
        points: [
            [0.0, 0.0, 0.0],
            [0.4, 0.0, 0.03],
            [0.3, 0.0, -0.65],
            [0.0, 0.0, 0.0],
        ],
        color: "#2c3e50",
    };
    static rear_tubes: Drawing = Link {
        frame: rear_frame,
        points: [
            [0.3, 0.0, -0.65],
            [w + c - (r_r + 0.55) * lambda.tan(), 0.0, -0.55],
            [w + c - (r_r + 0.3) * lambda.tan(), 0.0, -0.3],
            [0.4, 0.0, 0.03],
        ],
        color: "#2c3e50",
    };
    /// The fork and handlebar as drawn (front-frame coordinates: origin where the
    /// steer axis meets the ground, z down): from the front hub to the crown on the
    /// steer axis, up the axis to the stem, and the bar across.
    static fork: Drawing = Link {
        frame: front_frame,
        points: [
            [-c, 0.0, -r_f],
            [-0.6 * lambda.tan(), 0.0, -0.6],
            [-1.0 * lambda.tan(), 0.0, -1.0],
        ],
        color: "#c0392b",
    };
    static handlebar: Drawing = Link {
        frame: front_frame,
        points: [
            [-1.0 * lambda.tan() - 0.08, -0.28, -1.0],
            [-1.0 * lambda.tan(), 0.0, -1.0],
            [-1.0 * lambda.tan() - 0.08, 0.28, -1.0],
        ],
        color: "#c0392b",
    };

    /// Forward speed of the rear wheel's centre along the rear frame's heading [m/s].
    #[output]
    fn speed() -> f64 {
        x.dot() * psi.cos() + y.dot() * psi.sin()
    }
}
