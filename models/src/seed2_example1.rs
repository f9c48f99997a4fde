//! Example 1 of Chen, Wu and Mei (2016), "Free motion of holonomic system with
//! redundant coordinates" (docs/theory.md §free-motion-examples, cases V1 and V2).

/// Free motion with redundant coordinates, example 1 (docs/theory.md §free-motion-examples, V2).
///
/// Three unit masses, $T = \tfrac12(\dot q_1^2 + \dot q_2^2 + \dot q_3^2)$, on the moving
/// plane $f = t q_1 + 2 q_2 - 3 q_3 = 0$. The applied force $Q = (0, -\dot q_1, 0)$ makes the
/// free-motion condition $2\dot q_1 + t Q_1 + 2 Q_2 - 3 Q_3 = 0$ hold identically, so the
/// constraint force vanishes: from $q(0) = (1, 0, 0)$, $\dot q(0) = (1, 1, 1)$ the motion is
/// $q = (1 + t,\ t - t^2/2,\ t)$.
#[pfaff::mechanism]
pub mod seed2_example1 {
    /// First coordinate.
    static q1: Coordinate = Coordinate { q0: 1.0, qd0: 1.0 };
    /// Second coordinate.
    static q2: Coordinate = Coordinate { q0: 0.0, qd0: 1.0 };
    /// Third coordinate.
    static q3: Coordinate = Coordinate { q0: 0.0, qd0: 1.0 };

    fn kinetic_energy() -> f64 {
        0.5 * (q1.dot().powi(2) + q2.dot().powi(2) + q3.dot().powi(2))
    }

    /// The moving plane (S2-23).
    #[holonomic]
    fn f() -> f64 {
        t * q1 + 2.0 * q2 - 3.0 * q3
    }

    /// The force that makes the motion free, $Q_2 = -\dot q_1$ (V2).
    #[force(q2)]
    fn free_motion() -> f64 {
        -q1.dot()
    }
}
