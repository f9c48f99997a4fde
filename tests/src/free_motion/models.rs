//! Test mechanisms written with `#[pfaff::mechanism]`.

/// V5 of math-spec §10: a kinetic energy with $T_2$, $T_1$ and $T_0$ terms, an
/// explicitly time-dependent inertia, two rheonomic constraints and constant forces.
#[pfaff::mechanism]
pub mod v5 {
    /// First coordinate.
    static q1: Coordinate = Coordinate {};
    /// Second coordinate.
    static q2: Coordinate = Coordinate {};
    /// Third coordinate.
    static q3: Coordinate = Coordinate {};

    fn kinetic_energy() -> f64 {
        0.5 * ((1.0 + q2.powi(2)) * q1.dot().powi(2)
            + (2.0 + t.cos()) * q2.dot().powi(2)
            + q3.dot().powi(2)
            + q1 * q1.dot() * q3.dot())
            + t * q2 * q1.dot()
            + q1.sin() * q3.dot()
            + t * q3.powi(2) / 3.0
    }

    /// $f_1 = q_1^2 + q_2 q_3 - t$.
    #[holonomic]
    fn f1() -> f64 {
        q1.powi(2) + q2 * q3 - t
    }

    /// $f_2 = q_1 + \sin(t) q_3$.
    #[holonomic]
    fn f2() -> f64 {
        q1 + t.sin() * q3
    }

    /// $Q_1$.
    #[force(q1)]
    fn force1() -> f64 {
        0.2
    }

    /// $Q_2$.
    #[force(q2)]
    fn force2() -> f64 {
        -0.1
    }

    /// $Q_3$.
    #[force(q3)]
    fn force3() -> f64 {
        0.05
    }
}

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
