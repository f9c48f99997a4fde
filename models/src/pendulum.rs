//! The IFToMM A01 simple pendulum, written in redundant Cartesian coordinates so that
//! its single holonomic constraint exercises the multipliers (docs/models.md).

/// Simple pendulum in redundant Cartesian coordinates (IFToMM A01).
///
/// A point mass `m` on a massless rigid link of length `l` pivoted at the origin, with
/// gravity `g` along −y. The coordinates `x`, `y` of the bob are tied by the link,
/// $x^2 + y^2 - l^2 = 0$. It starts at rest at $x = l$, $y = 0$; the period is
/// $4K(1/2)\sqrt{l/g} = 2.36784194757624$ s for the defaults.
#[pfaff::mechanism(linearize)]
pub mod pendulum {
    /// Mass of the bob [kg].
    const m: f64 = 1.0;
    /// Length of the link [m].
    const l: f64 = 1.0;
    /// Gravitational acceleration, along −y [m/s²].
    const g: f64 = 9.81;

    /// Horizontal position of the bob [m].
    static x: Coordinate = Coordinate { q0: l, qd0: 0.0 };
    /// Vertical position of the bob [m].
    static y: Coordinate = Coordinate {};

    fn kinetic_energy() -> f64 {
        0.5 * m * (x.dot().powi(2) + y.dot().powi(2))
    }

    fn potential_energy() -> f64 {
        m * g * y
    }

    /// The link keeps the bob at distance `l` from the pivot.
    #[holonomic]
    fn rod() -> f64 {
        x.powi(2) + y.powi(2) - l.powi(2)
    }
}
