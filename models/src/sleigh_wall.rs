//! The Chaplygin sleigh of docs/theory.md V11 striking a wall: an impact with a
//! non-holonomic constraint (docs/theory.md V16).

/// Chaplygin sleigh whose front tip strikes a wall (docs/theory.md V16).
///
/// The sleigh of `sleigh` (mass `m`, inertia `ic`, blade `a` behind the centre of mass)
/// with its front tip `tip` ahead of the centre of mass on the body axis; the wall is the
/// line `x = wall`. The default state is the instant of V16's impact: heading 30°,
/// forward speed 1, turning rate 0.5, tip on the wall. With `e = 0.8` the impulse is
/// 1.3704647529, the blade's impulsive reaction −0.5660615284, and the finite
/// multiplier of the blade jumps from −0.2173913043 to −0.4570374378.
#[pfaff::mechanism]
pub mod sleigh_wall {
    /// Mass [kg].
    const m: f64 = 2.0;
    /// Moment of inertia about the centre of mass [kg m²].
    const ic: f64 = 0.05;
    /// Distance from the centre of mass back to the blade [m].
    const a: f64 = 0.3;
    /// Distance from the centre of mass forward to the tip [m].
    const tip: f64 = 0.4;
    /// Position of the wall, x [m].
    const wall: f64 = tip * FRAC_PI_6.cos();
    /// Coefficient of restitution of the wall.
    const e: f64 = 0.8;

    /// Position of the centre of mass along x [m].
    static x: Coordinate = Coordinate {
        q0: 0.0,
        qd0: FRAC_PI_6.cos() - 0.5 * a * FRAC_PI_6.sin(),
    };
    /// Position of the centre of mass along y [m].
    static y: Coordinate = Coordinate {
        q0: 0.0,
        qd0: FRAC_PI_6.sin() + 0.5 * a * FRAC_PI_6.cos(),
    };
    /// Heading: angle from the x axis to the body axis [rad].
    static phi: Coordinate = Coordinate {
        q0: FRAC_PI_6,
        qd0: 0.5,
    };

    fn kinetic_energy() -> f64 {
        0.5 * m * (x.dot().powi(2) + y.dot().powi(2)) + 0.5 * ic * phi.dot().powi(2)
    }

    /// The blade point has no velocity across the blade.
    #[nonholonomic]
    fn blade() -> f64 {
        -phi.sin() * x.dot() + phi.cos() * y.dot() - a * phi.dot()
    }

    /// The front tip's distance to the wall.
    #[contact(e)]
    fn front() -> f64 {
        wall - x - tip * phi.cos()
    }
}
