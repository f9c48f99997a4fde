//! Impacts of free planar bodies: docs/theory.md V13 (one body on a floor) and V14 (two
//! bodies), with the input data of Nikravesh's examples 11.3 and 11.4.

/// A free planar body striking a floor with a corner (docs/theory.md V13).
///
/// Mass `m`, moment of inertia `j` about the centre of mass `(x, y)`, angle `phi`. The
/// contact point sits at body coordinates `(1, 0)`; the floor is `y = 0`. The default
/// state is V13's impact: `phi = 315°`, the point on the floor, $\dot q^- = (0, -6.5, 0)$;
/// with `e = 0.95` the impulse is $1.95 \cdot 6.5/51$.
#[pfaff::mechanism]
pub mod body_impact {
    /// Mass [kg].
    const m: f64 = 1.0;
    /// Moment of inertia about the centre of mass [kg m²].
    const j: f64 = 0.01;
    /// Coefficient of restitution.
    const e: f64 = 0.95;
    /// Gravitational acceleration, along −y [m/s²].
    const g: f64 = 9.81;

    /// Centre of mass, x [m].
    static x: Coordinate = Coordinate {};
    /// Centre of mass, y [m].
    static y: Coordinate = Coordinate {
        q0: FRAC_PI_4.sin(),
        qd0: -6.5,
    };
    /// Angle of the body [rad].
    static phi: Coordinate = Coordinate {
        q0: 7.0 * FRAC_PI_4,
    };

    fn kinetic_energy() -> f64 {
        0.5 * m * (x.dot().powi(2) + y.dot().powi(2)) + 0.5 * j * phi.dot().powi(2)
    }

    fn potential_energy() -> f64 {
        m * g * y
    }

    /// The corner at body `(1, 0)` above the floor.
    #[contact(e)]
    fn floor() -> f64 {
        y + phi.sin()
    }
}

/// Two free planar bodies colliding (docs/theory.md V14): a disk and a rod.
///
/// The disk (mass `m1`, inertia `j1`) touches the rod (mass `m2`, inertia `j2`) with its
/// point at body `(0.1, 0)`; the rod's contact point is at body `(0, 0.25)`. The normal
/// points from the rod to the disk along −x. The default state is V14's impact:
/// $\dot q^- = (2, 1, 0.5, 0, -1, 0)$, $v_n^- = -2$; with `e = 0.8` the impulse is
/// 0.732203389831.
#[pfaff::mechanism]
pub mod two_body_impact {
    /// Mass of the disk [kg].
    const m1: f64 = 0.5;
    /// Moment of inertia of the disk [kg m²].
    const j1: f64 = 0.0025;
    /// Mass of the rod [kg].
    const m2: f64 = 0.6;
    /// Moment of inertia of the rod [kg m²].
    const j2: f64 = 0.05;
    /// Coefficient of restitution.
    const e: f64 = 0.8;

    /// Disk centre, x [m].
    static x1: Coordinate = Coordinate { q0: -0.1, qd0: 2.0 };
    /// Disk centre, y [m].
    static y1: Coordinate = Coordinate { q0: 0.25, qd0: 1.0 };
    /// Disk angle [rad].
    static phi1: Coordinate = Coordinate { qd0: 0.5 };
    /// Rod centre, x [m].
    static x2: Coordinate = Coordinate {};
    /// Rod centre, y [m].
    static y2: Coordinate = Coordinate { qd0: -1.0 };
    /// Rod angle [rad].
    static phi2: Coordinate = Coordinate {};

    fn kinetic_energy() -> f64 {
        0.5 * m1 * (x1.dot().powi(2) + y1.dot().powi(2))
            + 0.5 * j1 * phi1.dot().powi(2)
            + 0.5 * m2 * (x2.dot().powi(2) + y2.dot().powi(2))
            + 0.5 * j2 * phi2.dot().powi(2)
    }

    /// The rod's point minus the disk's point along x (the normal from rod to disk is −x).
    #[contact(e)]
    fn touch() -> f64 {
        (x2 - 0.25 * phi2.sin()) - (x1 + 0.1 * phi1.cos())
    }
}
