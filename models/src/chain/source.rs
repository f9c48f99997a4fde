//! The source of the spatial N-link chain, `N` substituted: one template for every `N`.
//!
//! Used by the build script (which writes `chain10` and `chain100` into `OUT_DIR` for
//! `include!`) and by benchmarks that expand chains of other lengths. A model is a
//! `#[pfaff::mechanism]` module; the description language has no repetition, so the
//! repetition happens here, before the generator sees the source.

use std::fmt::Write;

/// The `#[pfaff::mechanism] pub mod NAME { … }` source of an `n`-link chain.
///
/// Link `i` (1-based) is a slender rod of length `l` and mass `m` with its centre at
/// `(x_i, y_i, z_i)` and its orientation given by the Euler parameters `e0_i … e3_i`
/// (absolute coordinates, seven per link). Spherical joints join the rod's tip `(l/2, 0,
/// 0)` to the next rod's base `(−l/2, 0, 0)`; the first base is on the ground at the
/// origin. Gravity acts along −z. The chain starts at rest, straight along x
/// (horizontal), so the initial state satisfies every constraint exactly.
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
        "/// Spatial chain of {n} rods joined by spherical joints, hanging from the origin \
         (absolute coordinates, Euler parameters).\n\
         ///\n\
         /// Released at rest from the horizontal; gravity along −z. Generated from \
         `models/src/chain/source.rs` with N = {n}.\n\
         #[pfaff::mechanism]\n\
         pub mod {name} {{"
    );
    let _ = writeln!(
        w,
        "    /// Mass of each rod [kg].\n    const m: f64 = 1.0;\n\
         \x20   /// Length of each rod [m].\n    const l: f64 = 0.1;\n\
         \x20   /// Gravitational acceleration [m/s²].\n    const g: f64 = 9.81;\n"
    );
    for i in 1..=n {
        let _ = writeln!(
            w,
            "    /// Rod {i}: centre, x [m].\n    static x{i}: Coordinate = Coordinate {{ q0: {}.5 * l }};",
            i - 1
        );
        let _ = writeln!(
            w,
            "    /// Rod {i}: centre, y [m].\n    static y{i}: Coordinate = Coordinate {{}};\n\
             \x20   /// Rod {i}: centre, z [m].\n    static z{i}: Coordinate = Coordinate {{}};\n\
             \x20   /// Rod {i}: Euler parameter θ0.\n    static e0_{i}: Coordinate = Coordinate {{ q0: 1.0 }};\n\
             \x20   /// Rod {i}: Euler parameter θ1.\n    static e1_{i}: Coordinate = Coordinate {{}};\n\
             \x20   /// Rod {i}: Euler parameter θ2.\n    static e2_{i}: Coordinate = Coordinate {{}};\n\
             \x20   /// Rod {i}: Euler parameter θ3.\n    static e3_{i}: Coordinate = Coordinate {{}};"
        );
    }
    let _ = writeln!(
        w,
        "\n    static gravity: Force = Gravity {{\n        acceleration: [0.0, 0.0, -g],\n    }};"
    );
    for i in 1..=n {
        let _ = writeln!(
            w,
            "    /// Rod {i}.\n    static link{i}: Body = Body {{\n\
             \x20       origin: [x{i}, y{i}, z{i}],\n\
             \x20       rotation: euler_parameters(e0_{i}, e1_{i}, e2_{i}, e3_{i}),\n\
             \x20       mass: m,\n\
             \x20       inertia: diag(m * l * l / 1200.0, m * l * l / 12.0, m * l * l / 12.0),\n\
             \x20   }};"
        );
    }
    for i in 1..=n {
        let (b, at_b) = if i == 1 {
            ("ground".to_string(), "[0.0, 0.0, 0.0]".to_string())
        } else {
            (format!("link{}", i - 1), "[0.5 * l, 0.0, 0.0]".to_string())
        };
        let _ = writeln!(
            w,
            "    /// The ball joint at the base of rod {i}.\n    static joint{i}: Joint = Spherical {{\n\
             \x20       a: link{i},\n\
             \x20       at_a: [-0.5 * l, 0.0, 0.0],\n\
             \x20       b: {b},\n\
             \x20       at_b: {at_b},\n\
             \x20   }};"
        );
    }
    let _ = writeln!(
        w,
        "\n    /// Height of the free end [m].\n    #[output]\n    fn tip_z() -> f64 {{\n\
         \x20       link{n}.point([0.5 * l, 0.0, 0.0]).z()\n    }}\n}}"
    );
    s
}
