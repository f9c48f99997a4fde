//! A parallelogram linkage with a redundant third crank: the textbook statically
//! indeterminate mechanism, for the reactions of redundant constraints.

/// Parallelogram linkage with three parallel cranks (one of them redundant).
///
/// Three equal cranks of length `l`, pivoted on the ground at $(-d, 0)$, $(0, 0)$ and
/// $(d, 0)$ with angles `th1`, `th2`, `th3` from the x axis, carry a coupler bar whose
/// centre is at $(x, y)$ and whose angle is `phi`; the crank tips are pinned to the
/// coupler at $-d$, $0$ and $d$ along its axis. Two cranks already make a parallelogram
/// with one degree of freedom; the third is parallel to them, so its two pin constraints
/// add one independent equation only: of the six constraints, one is redundant at every
/// configuration of the motion ($\varphi = 0$, equal crank angles). The individual pin
/// forces are then statically indeterminate; the runtime returns the minimum-norm split
/// and names the redundant constraint.
///
/// Mass data (our choice): uniform cranks of mass `mk` (inertia $m_k l^2/3$ about the
/// pivot), a uniform coupler of mass `mc` and length $2d$; gravity along −y. The default
/// state is $\theta_i = \pi/3$ turning at 1 rad/s, consistent with the constraints.
#[pfaff::mechanism]
pub mod parallelogram {
    /// Crank length [m].
    const l: f64 = 0.5;
    /// Spacing of the pivots, and of the pins along the coupler [m].
    const d: f64 = 0.4;
    /// Mass of each crank [kg].
    const mk: f64 = 1.0;
    /// Mass of the coupler [kg].
    const mc: f64 = 2.0;
    /// Gravitational acceleration, along −y [m/s²].
    const g: f64 = 9.81;

    /// Angle of the left crank [rad].
    static th1: Coordinate = Coordinate {
        q0: PI / 3.0,
        qd0: 1.0,
    };
    /// Angle of the middle crank [rad].
    static th2: Coordinate = Coordinate {
        q0: PI / 3.0,
        qd0: 1.0,
    };
    /// Angle of the right crank [rad].
    static th3: Coordinate = Coordinate {
        q0: PI / 3.0,
        qd0: 1.0,
    };
    /// Centre of the coupler, x [m].
    static x: Coordinate = Coordinate {
        q0: 0.5 * l,
        qd0: -0.8660254037844386 * l,
    };
    /// Centre of the coupler, y [m].
    static y: Coordinate = Coordinate {
        q0: 0.8660254037844386 * l,
        qd0: 0.5 * l,
    };
    /// Angle of the coupler [rad].
    static phi: Coordinate = Coordinate {};

    fn kinetic_energy() -> f64 {
        0.5 * (mk * l * l / 3.0) * (th1.dot().powi(2) + th2.dot().powi(2) + th3.dot().powi(2))
            + 0.5 * mc * (x.dot().powi(2) + y.dot().powi(2))
            + 0.5 * (mc * 4.0 * d * d / 12.0) * phi.dot().powi(2)
    }

    fn potential_energy() -> f64 {
        mk * g * 0.5 * l * (th1.sin() + th2.sin() + th3.sin()) + mc * g * y
    }

    /// Left crank tip pinned to the coupler, x.
    #[holonomic]
    fn pin1_x() -> f64 {
        x - d * phi.cos() + d - l * th1.cos()
    }

    /// Left crank tip pinned to the coupler, y.
    #[holonomic]
    fn pin1_y() -> f64 {
        y - d * phi.sin() - l * th1.sin()
    }

    /// Middle crank tip pinned to the coupler centre, x.
    #[holonomic]
    fn pin2_x() -> f64 {
        x - l * th2.cos()
    }

    /// Middle crank tip pinned to the coupler centre, y.
    #[holonomic]
    fn pin2_y() -> f64 {
        y - l * th2.sin()
    }

    /// Right crank tip pinned to the coupler, x.
    #[holonomic]
    fn pin3_x() -> f64 {
        x + d * phi.cos() - d - l * th3.cos()
    }

    /// Right crank tip pinned to the coupler, y.
    #[holonomic]
    fn pin3_y() -> f64 {
        y + d * phi.sin() - l * th3.sin()
    }
}
