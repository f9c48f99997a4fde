//! Test mechanisms written with `#[pfaff::mechanism]`.

/// V5 of docs/theory.md §verification (defined with the accuracy tests, which check its generated
/// functions against the source expressions).
pub use crate::accuracy::coverage::v5;

/// Example 1 of [S2] as a family of moving planes $t q_1 + k q_2 - 3 q_3 = 0$, with the
/// force of V2, $Q_2 = -\dot q_1$: the free-motion condition is $(2 - k)\dot q_1 = 0$, so
/// $k = 2$ (the paper's plane) is the member that makes the motion free.
#[pfaff::mechanism]
pub mod plane_family {
    /// The coefficient of $q_2$ in the plane.
    const k: f64 = 1.0;

    /// First coordinate.
    static q1: Coordinate = Coordinate { q0: 1.0, qd0: 1.0 };
    /// Second coordinate.
    static q2: Coordinate = Coordinate { q0: 0.0, qd0: 1.0 };
    /// Third coordinate.
    static q3: Coordinate = Coordinate { q0: 0.0, qd0: 1.0 };

    fn kinetic_energy() -> f64 {
        0.5 * (q1.dot().powi(2) + q2.dot().powi(2) + q3.dot().powi(2))
    }

    /// The moving plane.
    #[holonomic]
    fn f() -> f64 {
        t * q1 + k * q2 - 3.0 * q3
    }

    /// The force of V2.
    #[force(q2)]
    fn push() -> f64 {
        -q1.dot()
    }
}
