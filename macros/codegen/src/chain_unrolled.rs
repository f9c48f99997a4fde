//! The spatial N-link chain written out item by item, as a program had to write it
//! before the description language had arrays (it was the models' build script's
//! template). Kept for the tests: `models/src/chain.rs` writes the same chain with
//! arrays and loops, and `repeat_tests` checks that both emit the same code.

use std::fmt::Write;

/// The `#[pfaff::mechanism] pub mod NAME { … }` source of an `n`-link chain, with the
/// names and docs that the array form of `models/src/chain.rs` gives its elements.
///
/// # Panics
/// If `n` is 0.
#[must_use]
pub fn chain_source(name: &str, n: usize) -> String {
    assert!(n > 0, "a chain has at least one link");
    let mut s = String::new();
    let w = &mut s;
    let _ = writeln!(
        w,
        "/// Spatial chain of {n} rods.\n\
         #[pfaff::mechanism]\n\
         pub mod {name} {{"
    );
    let _ = writeln!(
        w,
        "    /// Mass of each rod [kg].\n    const m: f64 = 1.0;\n\
         \x20   /// Length of each rod [m].\n    const l: f64 = 0.1;\n\
         \x20   /// Gravitational acceleration [m/s²].\n    const g: f64 = 9.81;\n"
    );
    for i in 0..n {
        let _ = writeln!(
            w,
            "    /// Rod centre, x [m].\n    static x_{i}: Coordinate = Coordinate {{ q0: {i}.5 * l }};"
        );
        let _ = writeln!(
            w,
            "    /// Rod centre, y [m].\n    static y_{i}: Coordinate = Coordinate {{}};\n\
             \x20   /// Rod centre, z [m].\n    static z_{i}: Coordinate = Coordinate {{}};\n\
             \x20   /// Euler parameter θ0.\n    static e0_{i}: Coordinate = Coordinate {{ q0: 1.0 }};\n\
             \x20   /// Euler parameter θ1.\n    static e1_{i}: Coordinate = Coordinate {{}};\n\
             \x20   /// Euler parameter θ2.\n    static e2_{i}: Coordinate = Coordinate {{}};\n\
             \x20   /// Euler parameter θ3.\n    static e3_{i}: Coordinate = Coordinate {{}};"
        );
    }
    let _ = writeln!(
        w,
        "\n    static gravity: Force = Gravity {{\n        acceleration: [0.0, 0.0, -g],\n    }};"
    );
    for i in 0..n {
        let _ = writeln!(
            w,
            "    /// A rod.\n    static link_{i}: Body = Body {{\n\
             \x20       origin: [x_{i}, y_{i}, z_{i}],\n\
             \x20       rotation: euler_parameters(e0_{i}, e1_{i}, e2_{i}, e3_{i}),\n\
             \x20       mass: m,\n\
             \x20       inertia: diag(m * l * l / 1200.0, m * l * l / 12.0, m * l * l / 12.0),\n\
             \x20   }};"
        );
    }
    for i in 0..n {
        let (b, at_b) = if i == 0 {
            ("ground".to_string(), "[0.0, 0.0, 0.0]".to_string())
        } else {
            (format!("link_{}", i - 1), "[0.5 * l, 0.0, 0.0]".to_string())
        };
        let _ = writeln!(
            w,
            "    /// The ball joint at the base of a rod.\n    static joint_{i}: Joint = Spherical {{\n\
             \x20       a: link_{i},\n\
             \x20       at_a: [-0.5 * l, 0.0, 0.0],\n\
             \x20       b: {b},\n\
             \x20       at_b: {at_b},\n\
             \x20   }};"
        );
    }
    let _ = writeln!(
        w,
        "\n    /// Height of the free end [m].\n    #[output]\n    fn tip_z() -> f64 {{\n\
         \x20       link_{}.point([0.5 * l, 0.0, 0.0]).z()\n    }}\n}}",
        n - 1
    );
    s
}
