//! Models written for the simulation tests.
#![allow(clippy::unreadable_literal)]

/// The slider-crank of docs/theory.md V10 without its driver: one degree of freedom, a
/// heavy crank (flywheel, `j1` = 10 kg m² against 1e-3 for the other bodies), no
/// gravity, so it spins through both dead centres at an almost constant rate.
#[pfaff::mechanism]
pub mod flywheel_crank {
    const a: f64 = 0.1;
    const b: f64 = 0.3;
    const m1: f64 = 0.1;
    const j1: f64 = 10.0;
    const m2: f64 = 0.3;
    const j2: f64 = m2 * b * b / 12.0;
    const m3: f64 = 0.5;
    const j3: f64 = m3 * (0.04 * 0.04 + 0.02 * 0.02) / 12.0;

    static x1: Coordinate = Coordinate {
        q0: 0.04330127018922193,
    };
    static y1: Coordinate = Coordinate { q0: 0.025 };
    static phi1: Coordinate = Coordinate {
        q0: PI / 6.0,
        qd0: 10.0,
    };
    static x2: Coordinate = Coordinate {
        q0: 0.23450453495593426,
    };
    static y2: Coordinate = Coordinate { q0: 0.025 };
    static phi2: Coordinate = Coordinate {
        q0: -0.16744807921968932,
    };
    static x3: Coordinate = Coordinate {
        q0: 0.3824065295334247,
    };
    static y3: Coordinate = Coordinate {};
    static phi3: Coordinate = Coordinate {};

    fn kinetic_energy() -> f64 {
        0.5 * m1 * (x1.dot().powi(2) + y1.dot().powi(2))
            + 0.5 * j1 * phi1.dot().powi(2)
            + 0.5 * m2 * (x2.dot().powi(2) + y2.dot().powi(2))
            + 0.5 * j2 * phi2.dot().powi(2)
            + 0.5 * m3 * (x3.dot().powi(2) + y3.dot().powi(2))
            + 0.5 * j3 * phi3.dot().powi(2)
    }

    #[holonomic]
    fn pin_o_x() -> f64 {
        x1 - 0.5 * a * phi1.cos()
    }
    #[holonomic]
    fn pin_o_y() -> f64 {
        y1 - 0.5 * a * phi1.sin()
    }
    #[holonomic]
    fn pin_a_x() -> f64 {
        x1 + 0.5 * a * phi1.cos() - x2 + 0.5 * b * phi2.cos()
    }
    #[holonomic]
    fn pin_a_y() -> f64 {
        y1 + 0.5 * a * phi1.sin() - y2 + 0.5 * b * phi2.sin()
    }
    #[holonomic]
    fn pin_b_x() -> f64 {
        x2 + 0.5 * b * phi2.cos() - x3
    }
    #[holonomic]
    fn pin_b_y() -> f64 {
        y2 + 0.5 * b * phi2.sin() - y3
    }
    #[holonomic]
    fn guide_y() -> f64 {
        y3
    }
    #[holonomic]
    fn guide_phi() -> f64 {
        phi3
    }
}

/// The slider-crank of docs/theory.md V10 driven by its slider, $x_3 = x_{3,0} + v t$
/// (`v` = 0.1 m/s). The slider reaches the crank's reach $a + b = 0.4$ at
/// $t^\ast = (0.4 - 0.38240652953342)/0.1 = 0.17593470466577$ s; past it the
/// constraints have no solution.
#[pfaff::mechanism]
pub mod slider_driven_crank {
    const a: f64 = 0.1;
    const b: f64 = 0.3;
    const m1: f64 = 0.1;
    const j1: f64 = m1 * a * a / 12.0;
    const m2: f64 = 0.3;
    const j2: f64 = m2 * b * b / 12.0;
    const m3: f64 = 0.5;
    const j3: f64 = m3 * (0.04 * 0.04 + 0.02 * 0.02) / 12.0;
    const x30: f64 = 0.3824065295334247;
    const v: f64 = 0.1;

    static x1: Coordinate = Coordinate {
        q0: 0.04330127018922193,
    };
    static y1: Coordinate = Coordinate { q0: 0.025 };
    static phi1: Coordinate = Coordinate { q0: PI / 6.0 };
    static x2: Coordinate = Coordinate {
        q0: 0.23450453495593426,
    };
    static y2: Coordinate = Coordinate { q0: 0.025 };
    static phi2: Coordinate = Coordinate {
        q0: -0.16744807921968932,
    };
    static x3: Coordinate = Coordinate { q0: x30, qd0: v };
    static y3: Coordinate = Coordinate {};
    static phi3: Coordinate = Coordinate {};

    fn kinetic_energy() -> f64 {
        0.5 * m1 * (x1.dot().powi(2) + y1.dot().powi(2))
            + 0.5 * j1 * phi1.dot().powi(2)
            + 0.5 * m2 * (x2.dot().powi(2) + y2.dot().powi(2))
            + 0.5 * j2 * phi2.dot().powi(2)
            + 0.5 * m3 * (x3.dot().powi(2) + y3.dot().powi(2))
            + 0.5 * j3 * phi3.dot().powi(2)
    }

    #[holonomic]
    fn pin_o_x() -> f64 {
        x1 - 0.5 * a * phi1.cos()
    }
    #[holonomic]
    fn pin_o_y() -> f64 {
        y1 - 0.5 * a * phi1.sin()
    }
    #[holonomic]
    fn pin_a_x() -> f64 {
        x1 + 0.5 * a * phi1.cos() - x2 + 0.5 * b * phi2.cos()
    }
    #[holonomic]
    fn pin_a_y() -> f64 {
        y1 + 0.5 * a * phi1.sin() - y2 + 0.5 * b * phi2.sin()
    }
    #[holonomic]
    fn pin_b_x() -> f64 {
        x2 + 0.5 * b * phi2.cos() - x3
    }
    #[holonomic]
    fn pin_b_y() -> f64 {
        y2 + 0.5 * b * phi2.sin() - y3
    }
    #[holonomic]
    fn guide_y() -> f64 {
        y3
    }
    #[holonomic]
    fn guide_phi() -> f64 {
        phi3
    }
    /// The slider is pushed outwards at constant speed.
    #[holonomic]
    fn slider_driver() -> f64 {
        x3 - (x30 + v * t)
    }
}

/// The pendulum with a weak extra potential $k\sqrt{y + d}$ that is undefined below
/// $y = -d$ (`d` = 0.5): released at rest at $y = 0$, the bob crosses $y = -0.5$
/// within the first quarter period, where the force becomes NaN.
#[pfaff::mechanism]
pub mod fragile_pendulum {
    const m: f64 = 1.0;
    const l: f64 = 1.0;
    const g: f64 = 9.81;
    const k: f64 = 1e-3;
    const d: f64 = 0.5;

    static x: Coordinate = Coordinate { q0: l };
    static y: Coordinate = Coordinate {};

    fn kinetic_energy() -> f64 {
        0.5 * m * (x.dot().powi(2) + y.dot().powi(2))
    }
    fn potential_energy() -> f64 {
        m * g * y + k * (y + d).sqrt()
    }
    #[holonomic]
    fn rod() -> f64 {
        x.powi(2) + y.powi(2) - l.powi(2)
    }
}

/// A double pendulum of point masses in Cartesian coordinates with a mass ratio of
/// 1e8 (`m1` = 1e4, `m2` = 1e-4), both links of length 1.
#[pfaff::mechanism]
pub mod heavy_light_pendulum {
    const m1: f64 = 1e4;
    const m2: f64 = 1e-4;
    const g: f64 = 9.81;

    static x1: Coordinate = Coordinate { q0: 1.0 };
    static y1: Coordinate = Coordinate {};
    static x2: Coordinate = Coordinate { q0: 1.0 };
    static y2: Coordinate = Coordinate { q0: -1.0 };

    fn kinetic_energy() -> f64 {
        0.5 * m1 * (x1.dot().powi(2) + y1.dot().powi(2))
            + 0.5 * m2 * (x2.dot().powi(2) + y2.dot().powi(2))
    }
    fn potential_energy() -> f64 {
        g * (m1 * y1 + m2 * y2)
    }
    #[holonomic]
    fn rod1() -> f64 {
        x1.powi(2) + y1.powi(2) - 1.0
    }
    #[holonomic]
    fn rod2() -> f64 {
        (x2 - x1).powi(2) + (y2 - y1).powi(2) - 1.0
    }
}
