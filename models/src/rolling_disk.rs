//! A thin uniform disk rolling without slip on a horizontal plane.

/// Thin uniform disk rolling without slip on the plane `z = 0` (docs/models.md).
///
/// The disk's frame has its origin at the centre `(x, y, z)` and turns by the heading
/// `psi` about the vertical, the lean `phi` about the new x axis and the spin `theta`
/// about the disk's axis, the frame's y axis. A `RollingWheel` joint generates the
/// holonomic contact condition (the lowest point of the rim on the plane, which fixes
/// `z = radius·cos(phi)`) and the two no-slip conditions on the contact point's
/// velocity. Upright rolling along x at speed `v` has `theta' = v / radius`; it is stable
/// above the critical speed `√(g·radius/3)` (thin disk, A = m r²/4, C = m r²/2) and
/// unstable below it (`pfaff linearize rolling_disk --speed V`).
#[pfaff::mechanism(linearize)]
pub mod rolling_disk {
    /// Mass [kg].
    const m: f64 = 1.0;
    /// Radius [m].
    const radius: f64 = 0.3;
    /// Gravitational acceleration, along −z [m/s²].
    const g: f64 = 9.81;
    /// Diametral moment of inertia about the centre [kg m²].
    const a: f64 = m * radius * radius / 4.0;
    /// Axial moment of inertia about the centre [kg m²].
    const c: f64 = m * radius * radius / 2.0;

    /// Centre, x [m].
    static x: Coordinate = Coordinate { q0: 0.0, qd0: 2.0 };
    /// Centre, y [m].
    static y: Coordinate = Coordinate {};
    /// Centre, z [m].
    static z: Coordinate = Coordinate { q0: radius };
    /// Heading about the vertical [rad].
    static psi: Coordinate = Coordinate {};
    /// Lean about the heading's x axis [rad].
    static phi: Coordinate = Coordinate { q0: 0.05 };
    /// Spin about the disk's axis [rad].
    static theta: Coordinate = Coordinate {
        q0: 0.0,
        qd0: 2.0 / radius,
    };

    static gravity: Force = Gravity {
        acceleration: [0.0, 0.0, -g],
    };

    /// The disk; its axis is the frame's y axis.
    static disk: Body = Body {
        origin: [x, y, z],
        rotation: rot_z(psi) * rot_x(phi) * rot_y(theta),
        mass: m,
        inertia: diag(a, c, a),
    };

    /// Rolling without slip on the plane z = 0.
    static contact: Joint = RollingWheel {
        a: disk,
        axis: [0.0, 1.0, 0.0],
        radius,
    };

    /// Height of the centre above the plane [m].
    #[output]
    fn height() -> f64 {
        z
    }
}
