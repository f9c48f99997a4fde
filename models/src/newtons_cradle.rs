//! Newton's cradle: three balls on strings, two contacts closed at rest
//! (docs/models.md).

/// Newton's cradle with three equal balls (docs/models.md).
///
/// Balls of mass `m` and radius `r` hang on strings of length `l` from pivots `2r`
/// apart, so that they touch at rest; `theta1`–`theta3` are the string angles from the
/// vertical. Ball 1 starts at `-angle`, the others at rest, touching. The contacts
/// `balls12` and `balls23` are the distances between neighbouring surfaces.
///
/// **Simultaneous contacts.** The simulation applies the sequential law: at an impact
/// the closed contact with the most negative normal velocity strikes alone (Newton
/// restitution on that pair, every other contact free), and the pass repeats until no
/// closed contact approaches. For `e = 1` and equal masses ball 1 stops, ball 2 takes
/// its velocity and passes it at once to ball 3: one ball in, one ball out, as the toy
/// does. (Simultaneous Newton restitution on both contacts would send balls 2 and 3
/// off together at two thirds of the speed and ball 1 back at one third.)
#[pfaff::mechanism]
pub mod newtons_cradle {
    /// Mass of each ball [kg].
    const m: f64 = 0.1;
    /// Radius of each ball [m].
    const r: f64 = 0.02;
    /// Length of each string [m].
    const l: f64 = 0.5;
    /// Coefficient of restitution between balls.
    const e: f64 = 1.0;
    /// Gravitational acceleration, along −y [m/s²].
    const g: f64 = 9.81;
    /// Initial angle of ball 1, to the left [rad].
    const angle: f64 = 0.5;

    /// String angle of ball 1 from the vertical [rad].
    static theta1: Coordinate = Coordinate { q0: -angle };
    /// String angle of ball 2 from the vertical [rad].
    static theta2: Coordinate = Coordinate {};
    /// String angle of ball 3 from the vertical [rad].
    static theta3: Coordinate = Coordinate {};

    fn kinetic_energy() -> f64 {
        0.5 * m * l.powi(2) * (theta1.dot().powi(2) + theta2.dot().powi(2) + theta3.dot().powi(2))
    }

    fn potential_energy() -> f64 {
        -m * g * l * (theta1.cos() + theta2.cos() + theta3.cos())
    }

    /// Gap between the surfaces of balls 1 and 2.
    #[contact(e)]
    fn balls12() -> f64 {
        ((2.0 * r + l * theta2.sin() - l * theta1.sin()).powi(2)
            + (l * theta2.cos() - l * theta1.cos()).powi(2))
        .sqrt()
            - 2.0 * r
    }

    /// Gap between the surfaces of balls 2 and 3.
    #[contact(e)]
    fn balls23() -> f64 {
        ((2.0 * r + l * theta3.sin() - l * theta2.sin()).powi(2)
            + (l * theta3.cos() - l * theta2.cos()).powi(2))
        .sqrt()
            - 2.0 * r
    }
}
