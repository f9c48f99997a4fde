//! The car axle of Rentrop, Roche and Steinebach (1989): two wheel points on a massless
//! axle, one of them driven over a bumpy road, with rheonomic constraints
//! (docs/models.md).

/// Car axle (Rentrop, Roche, Steinebach 1989): rheonomic holonomic constraints.
///
/// Two points of mass $K = \texttt{mass}\,\varepsilon^2/2$ at $(x_l, y_l)$ and
/// $(x_r, y_r)$ are joined by a rigid axle of length `l`. The left point is held by a
/// spring to the origin; the right one by a spring to the road point
/// $(x_b, y_b)$ with $y_b = r\sin(w t)$, $x_b = \sqrt{l^2 - y_b^2}$. Both springs have unit
/// stiffness and rest length `l0`; gravity $K g$ pulls both points along −y. The left
/// point also stays on the line through the origin normal to $(x_b, y_b)$:
/// $x_b x_l + y_b y_l = 0$. The defaults are the consistent initial state of the
/// reference: $(x_l, y_l, x_r, y_r) = (0, l_0, l, l_0)$ with velocities
/// $(-l_0/l, 0, -l_0/l, 0)$; the benchmark runs over $[0, 3]$ s.
#[pfaff::mechanism]
pub mod car_axis {
    /// Small parameter: the wheel mass is $\texttt{mass}\,\varepsilon^2/2$.
    const eps: f64 = 1e-2;
    /// Mass scale [kg].
    const mass: f64 = 10.0;
    /// Length of the axle [m].
    const l: f64 = 1.0;
    /// Rest length of both springs [m].
    const l0: f64 = 0.5;
    /// Amplitude of the road excitation [m].
    const r: f64 = 0.1;
    /// Angular frequency of the road excitation [rad/s].
    const w: f64 = 10.0;
    /// Gravitational acceleration, along −y [m/s²].
    const g: f64 = 1.0;

    /// Left point, x [m].
    static xl: Coordinate = Coordinate {
        q0: 0.0,
        qd0: -l0 / l,
    };
    /// Left point, y [m].
    static yl: Coordinate = Coordinate { q0: l0, qd0: 0.0 };
    /// Right point, x [m].
    static xr: Coordinate = Coordinate {
        q0: l,
        qd0: -l0 / l,
    };
    /// Right point, y [m].
    static yr: Coordinate = Coordinate { q0: l0, qd0: 0.0 };

    /// Mass of each wheel point [kg].
    fn k() -> f64 {
        mass * eps.powi(2) / 2.0
    }

    /// Height of the road point [m].
    fn yb() -> f64 {
        r * (w * t).sin()
    }

    /// Abscissa of the road point [m].
    fn xb() -> f64 {
        (l.powi(2) - yb().powi(2)).sqrt()
    }

    fn kinetic_energy() -> f64 {
        0.5 * k() * (xl.dot().powi(2) + yl.dot().powi(2) + xr.dot().powi(2) + yr.dot().powi(2))
    }

    /// The two springs and gravity.
    fn potential_energy() -> f64 {
        let left = (xl.powi(2) + yl.powi(2)).sqrt();
        let right = ((xr - xb()).powi(2) + (yr - yb()).powi(2)).sqrt();
        0.5 * (left - l0).powi(2) + 0.5 * (right - l0).powi(2) + k() * g * (yl + yr)
    }

    /// The left point stays normal to the road point: $x_b x_l + y_b y_l = 0$.
    #[holonomic]
    fn road() -> f64 {
        xb() * xl + yb() * yl
    }

    /// The axle is rigid: $(x_l - x_r)^2 + (y_l - y_r)^2 - l^2 = 0$.
    #[holonomic]
    fn axle() -> f64 {
        (xl - xr).powi(2) + (yl - yr).powi(2) - l.powi(2)
    }
}
