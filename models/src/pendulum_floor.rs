//! The double pendulum of docs/theory.md V15 striking a floor: an impact with holonomic
//! constraints and impulsive joint reactions.

/// Double pendulum of two uniform rods striking a floor with its tip (docs/theory.md V15).
///
/// Rods of length `l`, mass `m` and moment of inertia `m l²/12`, in Cartesian
/// coordinates of their centres and their angles; rod 1 is pinned to the ground at the
/// origin, rod 2 to the far end of rod 1. The floor lies `depth` below the pivot. The
/// default state is the instant of V15's impact: $\varphi = (-60°, -120°)$,
/// $\dot\varphi = (-1, 2)$, tip on the floor moving down at 1.5 m/s; with `e = 0.5` the
/// normal impulse is $165/104$ and $\dot\varphi^+ = (11/52, -67/52)$.
#[pfaff::mechanism]
pub mod pendulum_floor {
    /// Length of each rod [m].
    const l: f64 = 1.0;
    /// Mass of each rod [kg].
    const m: f64 = 1.0;
    /// Gravitational acceleration, along −y [m/s²].
    const g: f64 = 9.81;
    /// Coefficient of restitution of the floor.
    const e: f64 = 0.5;
    /// Depth of the floor below the pivot [m] (default √3: the tip of the V15 state).
    const depth: f64 = 2.0 * FRAC_PI_3.sin();

    /// Centre of rod 1, x [m].
    static x1: Coordinate = Coordinate {
        q0: 0.5 * l * FRAC_PI_3.cos(),
        qd0: -0.5 * l * FRAC_PI_3.sin(),
    };
    /// Centre of rod 1, y [m].
    static y1: Coordinate = Coordinate {
        q0: -0.5 * l * FRAC_PI_3.sin(),
        qd0: -0.5 * l * FRAC_PI_3.cos(),
    };
    /// Angle of rod 1 [rad].
    static phi1: Coordinate = Coordinate {
        q0: -FRAC_PI_3,
        qd0: -1.0,
    };
    /// Centre of rod 2, x [m].
    static x2: Coordinate = Coordinate {
        q0: l * FRAC_PI_3.cos() - 0.5 * l * FRAC_PI_3.cos(),
        qd0: 0.0,
    };
    /// Centre of rod 2, y [m].
    static y2: Coordinate = Coordinate {
        q0: -1.5 * l * FRAC_PI_3.sin(),
        qd0: -l,
    };
    /// Angle of rod 2 [rad].
    static phi2: Coordinate = Coordinate {
        q0: -2.0 * FRAC_PI_3,
        qd0: 2.0,
    };

    fn kinetic_energy() -> f64 {
        0.5 * m * (x1.dot().powi(2) + y1.dot().powi(2) + x2.dot().powi(2) + y2.dot().powi(2))
            + m * l.powi(2) / 24.0 * (phi1.dot().powi(2) + phi2.dot().powi(2))
    }

    fn potential_energy() -> f64 {
        m * g * (y1 + y2)
    }

    /// Rod 1 pinned to the ground at the origin, x.
    #[holonomic]
    fn pin_x() -> f64 {
        x1 - 0.5 * l * phi1.cos()
    }
    /// Rod 1 pinned to the ground at the origin, y.
    #[holonomic]
    fn pin_y() -> f64 {
        y1 - 0.5 * l * phi1.sin()
    }
    /// Rods 1 and 2 pinned together, x.
    #[holonomic]
    fn joint_x() -> f64 {
        x1 + 0.5 * l * phi1.cos() - x2 + 0.5 * l * phi2.cos()
    }
    /// Rods 1 and 2 pinned together, y.
    #[holonomic]
    fn joint_y() -> f64 {
        y1 + 0.5 * l * phi1.sin() - y2 + 0.5 * l * phi2.sin()
    }

    /// The tip of rod 2 above the floor.
    #[contact(e)]
    fn floor() -> f64 {
        y2 + 0.5 * l * phi2.sin() + depth
    }
}
