//! Example 2 of Chen, Wu and Mei (2016), "Free motion of holonomic system with
//! redundant coordinates" (docs/theory.md §free-motion-examples, cases V3 and V4).

/// Free motion with redundant coordinates, example 2 (docs/theory.md §free-motion-examples, V4).
///
/// A time-dependent inertia, $T = \tfrac12[(2 + \sin t)\dot q_1^2 + \dot q_2^2 + \dot q_3^2]$,
/// and the rheonomic constraint $f = t^2 q_1 - q_2 - q_3 = 0$. The applied force
/// $Q_2 = 2 q_1 + 4 t \dot q_1 - t^2 \cos t\,\dot q_1 / (2 + \sin t)$ satisfies the
/// free-motion condition (S2-26) identically, so the multiplier vanishes along the motion
/// from $q(0) = (1, 0.5, -0.5)$, $\dot q(0) = (1, 0.2, -0.2)$; then
/// $\dot q_1 = 2 / (2 + \sin t)$.
#[pfaff::mechanism]
pub mod seed2_example2 {
    /// First coordinate.
    static q1: Coordinate = Coordinate { q0: 1.0, qd0: 1.0 };
    /// Second coordinate.
    static q2: Coordinate = Coordinate { q0: 0.5, qd0: 0.2 };
    /// Third coordinate.
    static q3: Coordinate = Coordinate {
        q0: -0.5,
        qd0: -0.2,
    };

    fn kinetic_energy() -> f64 {
        0.5 * ((2.0 + t.sin()) * q1.dot().powi(2) + q2.dot().powi(2) + q3.dot().powi(2))
    }

    /// The moving constraint (S2-25).
    #[holonomic]
    fn f() -> f64 {
        t.powi(2) * q1 - q2 - q3
    }

    /// The force that makes the motion free (V4).
    #[force(q2)]
    fn free_motion() -> f64 {
        2.0 * q1 + 4.0 * t * q1.dot() - t.powi(2) * t.cos() * q1.dot() / (2.0 + t.sin())
    }
}
