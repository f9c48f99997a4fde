//! The Chaplygin sleigh: a rigid body on a knife edge, the simplest non-holonomic
//! mechanism (docs/models.md, case V11 of docs/theory.md).

/// Chaplygin sleigh: a planar rigid body sliding on a knife edge (docs/theory.md V11).
///
/// The centre of mass is at $(x, y)$ and the body axis makes the angle $\varphi$ with
/// the x axis. The blade sits a distance `a` behind the centre of mass on the body axis
/// and cannot slip sideways:
/// $-\sin\varphi\,\dot x + \cos\varphi\,\dot y - a\dot\varphi = 0$.
/// The defaults start at the origin with forward speed 1 and turning rate 0.5; the
/// turning rate then decays while the forward speed tends to
/// $V = \sqrt{v_0^2 + (i_c + m a^2)\,\omega_0^2/m} = 1.014273138755$.
#[pfaff::mechanism(linearize)]
pub mod sleigh {
    /// Mass [kg].
    const m: f64 = 2.0;
    /// Moment of inertia about the centre of mass [kg m²].
    const ic: f64 = 0.05;
    /// Distance from the centre of mass back to the blade [m].
    const a: f64 = 0.3;

    /// Position of the centre of mass along x [m] (initial forward speed 1 m/s).
    static x: Coordinate = Coordinate { q0: 0.0, qd0: 1.0 };
    /// Position of the centre of mass along y [m] (the blade's sideways speed is zero).
    static y: Coordinate = Coordinate {
        q0: 0.0,
        qd0: 0.5 * a,
    };
    /// Heading: angle from the x axis to the body axis [rad].
    static phi: Coordinate = Coordinate { q0: 0.0, qd0: 0.5 };

    fn kinetic_energy() -> f64 {
        0.5 * m * (x.dot().powi(2) + y.dot().powi(2)) + 0.5 * ic * phi.dot().powi(2)
    }

    /// The blade point has no velocity across the blade.
    #[nonholonomic]
    fn blade() -> f64 {
        -phi.sin() * x.dot() + phi.cos() * y.dot() - a * phi.dot()
    }
}
