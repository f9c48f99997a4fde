//! A torque-free spatial rigid body with Euler parameters (docs/theory.md V12).

/// Torque-free rigid body oriented by Euler parameters (docs/theory.md V12).
///
/// Body-frame inertia $\bar I = \operatorname{diag}(1, 1, 2)$, unit mass, no gravity.
/// It starts at $\theta = (1, 0, 0, 0)$ with $\bar\omega(0) = (1, 0, 2)$, so
/// $\dot\theta(0) = \tfrac12 \bar E^\mathsf{T}\bar\omega = (0, 0.5, 0, 1)$. The
/// normalization $\theta^\mathsf{T}\theta = 1$ is generated as the holonomic constraint
/// `body.normalization`. Closed form: $\bar\omega(t) = (\cos 2t, \sin 2t, 2)$, rotational
/// energy 4.5, global angular momentum $(1, 0, 4)$.
#[pfaff::mechanism]
pub mod free_body {
    /// Mass [kg].
    const m: f64 = 1.0;
    /// Principal moments of inertia about the centre of mass [kg m²].
    const ixx: f64 = 1.0;
    const iyy: f64 = 1.0;
    const izz: f64 = 2.0;

    /// Centre of mass, x [m].
    static x: Coordinate = Coordinate {};
    /// Centre of mass, y [m].
    static y: Coordinate = Coordinate {};
    /// Centre of mass, z [m].
    static z: Coordinate = Coordinate {};
    /// Euler parameter θ0.
    static e0: Coordinate = Coordinate { q0: 1.0 };
    /// Euler parameter θ1.
    static e1: Coordinate = Coordinate { qd0: 0.5 };
    /// Euler parameter θ2.
    static e2: Coordinate = Coordinate {};
    /// Euler parameter θ3.
    static e3: Coordinate = Coordinate { qd0: 1.0 };

    /// The body.
    static body: Body = Body {
        origin: [x, y, z],
        rotation: euler_parameters(e0, e1, e2, e3),
        mass: m,
        inertia: diag(ixx, iyy, izz),
    };

    /// Body-frame angular velocity, x [rad/s].
    #[output]
    fn omega_x() -> f64 {
        let w = body.rotation().transpose() * body.angular_velocity();
        w.x()
    }
    /// Body-frame angular velocity, y [rad/s].
    #[output]
    fn omega_y() -> f64 {
        let w = body.rotation().transpose() * body.angular_velocity();
        w.y()
    }
    /// Body-frame angular velocity, z [rad/s].
    #[output]
    fn omega_z() -> f64 {
        let w = body.rotation().transpose() * body.angular_velocity();
        w.z()
    }
}
