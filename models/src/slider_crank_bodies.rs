//! The planar slider-crank of case V10 of docs/theory.md written with bodies and joints:
//! the same mechanism, coordinates and parameters as `slider_crank`, with the kinetic
//! energy, gravity and the nine constraints generated from the body level.

/// Planar slider-crank in absolute coordinates (docs/theory.md V10) from bodies and joints.
///
/// Each body's frame has its origin at the body's centre: the crank (length `a`) is
/// pinned to the ground at its left end, joined to the coupler (length `b`) at its right
/// end; the coupler's right end is pinned to the slider, which slides along the x axis
/// without turning; a driver prescribes the crank angle $\pi/6 + 10 t$. The generated
/// equations equal those of `slider_crank`, written by hand.
#[pfaff::mechanism]
pub mod slider_crank_bodies {
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

    static gravity: Force = Gravity {
        acceleration: [0.0, -g],
    };

    /// The crank, a uniform bar.
    static crank: Body = Body {
        origin: [x1, y1],
        angle: phi1,
        mass: m1,
        inertia: j1,
    };
    /// The coupler, a uniform bar.
    static coupler: Body = Body {
        origin: [x2, y2],
        angle: phi2,
        mass: m2,
        inertia: j2,
    };
    /// The slider block.
    static slider: Body = Body {
        origin: [x3, y3],
        angle: phi3,
        mass: m3,
        inertia: j3,
    };

    /// The crank pinned to the ground at O.
    static pin_o: Joint = Revolute {
        a: crank,
        at_a: [-0.5 * a, 0.0],
    };
    /// Crank tip and coupler joined at A.
    static pin_a: Joint = Revolute {
        a: crank,
        at_a: [0.5 * a, 0.0],
        b: coupler,
        at_b: [-0.5 * b, 0.0],
    };
    /// Coupler and slider joined at B.
    static pin_b: Joint = Revolute {
        a: coupler,
        at_a: [0.5 * b, 0.0],
        b: slider,
    };
    /// The slider moves along the x axis without turning.
    static guide: Joint = Prismatic {
        a: slider,
        axis_a: [1.0, 0.0],
    };
    /// The driver turns the crank at 10 rad/s from $\pi/6$.
    static driver: Joint = Driver {
        value: crank.angle(),
        motion: PI / 6.0 + 10.0 * t,
    };

    /// The crank tip A.
    static tip: Point = Point {
        frame: crank,
        at: [0.5 * a, 0.0],
    };

    /// Position of the slider along its guide [m].
    #[output]
    fn slider_x() -> f64 {
        slider.origin().x()
    }
}
