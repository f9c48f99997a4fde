//! A row of four parallelogram windows on one coupler: a one-degree-of-freedom linkage
//! that turns full circles and passes two flat configurations per turn, where its
//! constraint Jacobian loses rank for an instant.

/// Row of four parallelogram windows: five equal cranks carrying one coupler.
///
/// Five cranks of length `l`, pivoted on the ground at $x = -2d, -d, 0, d, 2d$ with
/// angles `th1` … `th5` from the x axis, carry a coupler bar of length $4d$ whose centre
/// is at $(x, y)$ and whose angle is `phi`; the crank tips are pinned to the coupler at
/// $-2d, -d, 0, d, 2d$ along its axis. Each pair of neighbouring cranks, the ground and
/// the coupler between them form a parallelogram window. Two cranks already make a
/// linkage of one degree of freedom, so of the ten pin constraints three are redundant
/// at every configuration (rank 7 of 8 coordinates).
///
/// On the motion every crank turns at the same angle $\theta$, $\varphi = 0$,
/// $x = l\cos\theta$, $y = l\sin\theta$. At the flat configurations
/// $\theta = 0, \pi$ all links are collinear: the five pin_x rows of $C_q$ coincide and
/// the rank falls from 7 to 6 for an instant, while the motion stays on the
/// parallelogram branch (with three or more equal cranks $\varphi = 0$ is forced, there
/// is no other branch). The equivalent one-degree-of-freedom system has
/// $T = \frac12(5m_k/3 + m_c)l^2\dot\theta^2$ and $V = (\frac52 m_k + m_c)gl\sin\theta$.
///
/// Mass data (our choice, as the `parallelogram`'s): uniform cranks of mass `mk`
/// (inertia $m_k l^2/3$ about the pivot), a uniform coupler of mass `mc` and length
/// $4d$; gravity along −y. The default state is $\theta_i = \pi/3$ turning at 6 rad/s,
/// enough to go over the top: full turns, two flat crossings per turn.
#[pfaff::mechanism]
pub mod parallelogram_row {
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

    /// Angle of crank 1 (pivot at x = −2d) [rad].
    static th1: Coordinate = Coordinate {
        q0: PI / 3.0,
        qd0: 6.0,
    };
    /// Angle of crank 2 (pivot at x = −d) [rad].
    static th2: Coordinate = Coordinate {
        q0: PI / 3.0,
        qd0: 6.0,
    };
    /// Angle of crank 3 (pivot at x = 0) [rad].
    static th3: Coordinate = Coordinate {
        q0: PI / 3.0,
        qd0: 6.0,
    };
    /// Angle of crank 4 (pivot at x = d) [rad].
    static th4: Coordinate = Coordinate {
        q0: PI / 3.0,
        qd0: 6.0,
    };
    /// Angle of crank 5 (pivot at x = 2d) [rad].
    static th5: Coordinate = Coordinate {
        q0: PI / 3.0,
        qd0: 6.0,
    };
    /// Centre of the coupler, x [m].
    static x: Coordinate = Coordinate {
        q0: 0.5 * l,
        qd0: -6.0 * 0.8660254037844386 * l,
    };
    /// Centre of the coupler, y [m].
    static y: Coordinate = Coordinate {
        q0: 0.8660254037844386 * l,
        qd0: 6.0 * 0.5 * l,
    };
    /// Angle of the coupler [rad].
    static phi: Coordinate = Coordinate {};

    fn kinetic_energy() -> f64 {
        0.5 * (mk * l * l / 3.0)
            * (th1.dot().powi(2)
                + th2.dot().powi(2)
                + th3.dot().powi(2)
                + th4.dot().powi(2)
                + th5.dot().powi(2))
            + 0.5 * mc * (x.dot().powi(2) + y.dot().powi(2))
            + 0.5 * (mc * 16.0 * d * d / 12.0) * phi.dot().powi(2)
    }

    fn potential_energy() -> f64 {
        mk * g * 0.5 * l * (th1.sin() + th2.sin() + th3.sin() + th4.sin() + th5.sin()) + mc * g * y
    }

    /// Crank 1's tip pinned to the coupler, x.
    #[holonomic]
    fn pin1_x() -> f64 {
        x - 2.0 * d * phi.cos() + 2.0 * d - l * th1.cos()
    }

    /// Crank 1's tip pinned to the coupler, y.
    #[holonomic]
    fn pin1_y() -> f64 {
        y - 2.0 * d * phi.sin() - l * th1.sin()
    }

    /// Crank 2's tip pinned to the coupler, x.
    #[holonomic]
    fn pin2_x() -> f64 {
        x - d * phi.cos() + d - l * th2.cos()
    }

    /// Crank 2's tip pinned to the coupler, y.
    #[holonomic]
    fn pin2_y() -> f64 {
        y - d * phi.sin() - l * th2.sin()
    }

    /// Crank 3's tip pinned to the coupler centre, x.
    #[holonomic]
    fn pin3_x() -> f64 {
        x - l * th3.cos()
    }

    /// Crank 3's tip pinned to the coupler centre, y.
    #[holonomic]
    fn pin3_y() -> f64 {
        y - l * th3.sin()
    }

    /// Crank 4's tip pinned to the coupler, x.
    #[holonomic]
    fn pin4_x() -> f64 {
        x + d * phi.cos() - d - l * th4.cos()
    }

    /// Crank 4's tip pinned to the coupler, y.
    #[holonomic]
    fn pin4_y() -> f64 {
        y + d * phi.sin() - l * th4.sin()
    }

    /// Crank 5's tip pinned to the coupler, x.
    #[holonomic]
    fn pin5_x() -> f64 {
        x + 2.0 * d * phi.cos() - 2.0 * d - l * th5.cos()
    }

    /// Crank 5's tip pinned to the coupler, y.
    #[holonomic]
    fn pin5_y() -> f64 {
        y + 2.0 * d * phi.sin() - l * th5.sin()
    }
}
