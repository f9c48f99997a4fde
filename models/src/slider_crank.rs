//! The planar slider-crank of case V10 of docs/theory.md, in absolute coordinates: three
//! bodies, each with the position of its centre and its angle.

/// Planar slider-crank in absolute coordinates (docs/theory.md V10), driven at constant speed.
///
/// The crank (body 1, length `a`) is pinned at the origin O; its centre is at
/// $\tfrac a2 u(\varphi_1)$ with $u(\varphi) = (\cos\varphi, \sin\varphi)$. The coupler
/// (body 2, length `b`) joins the crank tip A to the slider (body 3) at B, and the slider
/// moves along the x axis without rotating. The driver prescribes
/// $\varphi_1 = \pi/6 + 10 t$, so the nine constraints leave no degree of freedom.
///
/// Mass data (our choice; V10 is a kinematic case): the crank and the coupler are uniform
/// bars of 1 kg/m, the slider is a 4 cm × 2 cm block of 0.5 kg. Gravity acts along −y.
/// The default state is the V10 configuration at $t = 0$ ($\varphi_2 = -\arcsin(1/6)$),
/// with consistent velocities.
#[pfaff::mechanism]
pub mod slider_crank {
    /// Length of the crank [m].
    const a: f64 = 0.1;
    /// Length of the coupler [m].
    const b: f64 = 0.3;
    /// Mass of the crank [kg].
    const m1: f64 = 0.1;
    /// Moment of inertia of the crank about its centre [kg m²] (uniform bar).
    const j1: f64 = m1 * a * a / 12.0;
    /// Mass of the coupler [kg].
    const m2: f64 = 0.3;
    /// Moment of inertia of the coupler about its centre [kg m²] (uniform bar).
    const j2: f64 = m2 * b * b / 12.0;
    /// Mass of the slider [kg].
    const m3: f64 = 0.5;
    /// Moment of inertia of the slider about its centre [kg m²] (4 cm × 2 cm block).
    const j3: f64 = m3 * (0.04 * 0.04 + 0.02 * 0.02) / 12.0;
    /// Gravitational acceleration, along −y [m/s²].
    const g: f64 = 9.81;

    /// Centre of the crank, x [m].
    static x1: Coordinate = Coordinate {
        q0: 0.04330127018922193,
        qd0: -0.25,
    };
    /// Centre of the crank, y [m].
    static y1: Coordinate = Coordinate {
        q0: 0.025,
        qd0: 0.4330127018922193,
    };
    /// Angle of the crank [rad].
    static phi1: Coordinate = Coordinate {
        q0: PI / 6.0,
        qd0: 10.0,
    };
    /// Centre of the coupler, x [m].
    static x2: Coordinate = Coordinate {
        q0: 0.23450453495593426,
        qd0: -0.57319250547114,
    };
    /// Centre of the coupler, y [m].
    static y2: Coordinate = Coordinate {
        q0: 0.025,
        qd0: 0.4330127018922193,
    };
    /// Angle of the coupler [rad].
    static phi2: Coordinate = Coordinate {
        q0: -0.16744807921968932,
        qd0: -2.9277002188455996,
    };
    /// Centre of the slider, x [m].
    static x3: Coordinate = Coordinate {
        q0: 0.3824065295334247,
        qd0: -0.64638501094228,
    };
    /// Centre of the slider, y [m].
    static y3: Coordinate = Coordinate {};
    /// Angle of the slider [rad].
    static phi3: Coordinate = Coordinate {};

    fn kinetic_energy() -> f64 {
        0.5 * m1 * (x1.dot().powi(2) + y1.dot().powi(2))
            + 0.5 * j1 * phi1.dot().powi(2)
            + 0.5 * m2 * (x2.dot().powi(2) + y2.dot().powi(2))
            + 0.5 * j2 * phi2.dot().powi(2)
            + 0.5 * m3 * (x3.dot().powi(2) + y3.dot().powi(2))
            + 0.5 * j3 * phi3.dot().powi(2)
    }

    fn potential_energy() -> f64 {
        g * (m1 * y1 + m2 * y2 + m3 * y3)
    }

    /// Crank pinned at O, x: $x_1 - \tfrac a2\cos\varphi_1 = 0$.
    #[holonomic]
    fn pin_o_x() -> f64 {
        x1 - 0.5 * a * phi1.cos()
    }

    /// Crank pinned at O, y: $y_1 - \tfrac a2\sin\varphi_1 = 0$.
    #[holonomic]
    fn pin_o_y() -> f64 {
        y1 - 0.5 * a * phi1.sin()
    }

    /// Crank tip and coupler joined at A, x.
    #[holonomic]
    fn pin_a_x() -> f64 {
        x1 + 0.5 * a * phi1.cos() - x2 + 0.5 * b * phi2.cos()
    }

    /// Crank tip and coupler joined at A, y.
    #[holonomic]
    fn pin_a_y() -> f64 {
        y1 + 0.5 * a * phi1.sin() - y2 + 0.5 * b * phi2.sin()
    }

    /// Coupler and slider joined at B, x.
    #[holonomic]
    fn pin_b_x() -> f64 {
        x2 + 0.5 * b * phi2.cos() - x3
    }

    /// Coupler and slider joined at B, y.
    #[holonomic]
    fn pin_b_y() -> f64 {
        y2 + 0.5 * b * phi2.sin() - y3
    }

    /// The slider stays on the x axis.
    #[holonomic]
    fn guide_y() -> f64 {
        y3
    }

    /// The slider does not rotate.
    #[holonomic]
    fn guide_phi() -> f64 {
        phi3
    }

    /// The driver turns the crank at 10 rad/s from $\pi/6$.
    #[holonomic]
    fn driver() -> f64 {
        phi1 - (PI / 6.0 + 10.0 * t)
    }
}
