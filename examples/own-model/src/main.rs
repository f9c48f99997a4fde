//! A model written outside pfaff's workspace, given the whole `pfaff` command by the
//! library `pfaff-cli`: `cargo run --release -- simulate double_pendulum --plot d.svg`,
//! `-- show double_pendulum --code`, `-- linearize double_pendulum`, …

/// Double pendulum: two point masses on rigid massless links, in Cartesian coordinates.
///
/// The first bob hangs from the origin on a link of length `l1`, the second from the
/// first on a link of length `l2`; gravity `g` acts along −y. Both links start
/// horizontal, at rest, so the energy $T + V$ is 0 throughout.
#[pfaff::mechanism]
pub mod double_pendulum {
    /// Mass of the first bob [kg].
    const m1: f64 = 1.0;
    /// Mass of the second bob [kg].
    const m2: f64 = 1.0;
    /// Length of the first link [m].
    const l1: f64 = 1.0;
    /// Length of the second link [m].
    const l2: f64 = 1.0;
    /// Gravitational acceleration, along −y [m/s²].
    const g: f64 = 9.81;

    /// Horizontal position of the first bob [m].
    static x1: Coordinate = Coordinate { q0: 1.0 };
    /// Vertical position of the first bob [m].
    static y1: Coordinate = Coordinate {};
    /// Horizontal position of the second bob [m].
    static x2: Coordinate = Coordinate { q0: 2.0 };
    /// Vertical position of the second bob [m].
    static y2: Coordinate = Coordinate {};

    fn kinetic_energy() -> f64 {
        0.5 * m1 * (x1.dot().powi(2) + y1.dot().powi(2))
            + 0.5 * m2 * (x2.dot().powi(2) + y2.dot().powi(2))
    }
    fn potential_energy() -> f64 {
        m1 * g * y1 + m2 * g * y2
    }

    /// The first link keeps the first bob at distance l1 from the origin.
    #[holonomic]
    fn link1() -> f64 {
        x1.powi(2) + y1.powi(2) - l1.powi(2)
    }
    /// The second link keeps the bobs at distance l2.
    #[holonomic]
    fn link2() -> f64 {
        (x2 - x1).powi(2) + (y2 - y1).powi(2) - l2.powi(2)
    }
}

fn main() -> std::process::ExitCode {
    pfaff_cli::main(&[pfaff_cli::model!(double_pendulum)
        .span(5.0, "a few chaotic swings")
        .source(include_str!("main.rs"))])
}
