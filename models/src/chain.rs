//! The spatial chains `chain10` and `chain100`: N slender rods on ball joints in
//! absolute coordinates with Euler parameters, written once per length with arrays and
//! loops (`docs/arrays.md`).
//!
//! Rod `i` (0-based) is a slender rod of length `l` and mass `m` with its centre at
//! `(x_i, y_i, z_i)` and its orientation given by the Euler parameters `e0_i … e3_i`
//! (seven coordinates per rod, declared rod by rod). Ball joints join each rod's base
//! `(−l/2, 0, 0)` to the previous rod's tip `(l/2, 0, 0)`, the first to the ground at the
//! origin. Gravity acts along −z. The chain starts at rest, straight along x
//! (horizontal), so the initial state satisfies every constraint exactly.

/// Spatial chain of 10 rods joined by spherical joints, hanging from the origin
/// (absolute coordinates, Euler parameters).
///
/// Released at rest from the horizontal; gravity along −z.
#[pfaff::mechanism]
pub mod chain10 {
    /// Number of rods.
    const N: usize = 10;
    /// Mass of each rod [kg].
    const m: f64 = 1.0;
    /// Length of each rod [m].
    const l: f64 = 0.1;
    /// Gravitational acceleration [m/s²].
    const g: f64 = 9.81;

    const _: () = for i in 0..N {
        /// Rod centre, x [m].
        static x: Coordinate = Coordinate {
            q0: (i as f64 + 0.5) * l,
        };
        /// Rod centre, y [m].
        static y: Coordinate = Coordinate {};
        /// Rod centre, z [m].
        static z: Coordinate = Coordinate {};
        /// Euler parameter θ0.
        static e0: Coordinate = Coordinate { q0: 1.0 };
        /// Euler parameter θ1.
        static e1: Coordinate = Coordinate {};
        /// Euler parameter θ2.
        static e2: Coordinate = Coordinate {};
        /// Euler parameter θ3.
        static e3: Coordinate = Coordinate {};
    };

    static gravity: Force = Gravity {
        acceleration: [0.0, 0.0, -g],
    };
    /// A rod.
    static link: [Body; N] = from_fn(|i| Body {
        origin: [x[i], y[i], z[i]],
        rotation: euler_parameters(e0[i], e1[i], e2[i], e3[i]),
        mass: m,
        inertia: diag(m * l * l / 1200.0, m * l * l / 12.0, m * l * l / 12.0),
    });
    /// The ball joint at the base of a rod.
    static joint: [Joint; N] = from_fn(|i| Spherical {
        a: link[i],
        at_a: [-0.5 * l, 0.0, 0.0],
        b: if i == 0 { ground } else { link[i - 1] },
        at_b: if i == 0 {
            [0.0, 0.0, 0.0]
        } else {
            [0.5 * l, 0.0, 0.0]
        },
    });

    /// Height of the free end [m].
    #[output]
    fn tip_z() -> f64 {
        link[N - 1].point([0.5 * l, 0.0, 0.0]).z()
    }
}

/// Spatial chain of 100 rods joined by spherical joints, hanging from the origin
/// (absolute coordinates, Euler parameters): `chain10` with `N = 100`, for scaling
/// measurements.
///
/// Released at rest from the horizontal; gravity along −z.
#[pfaff::mechanism]
pub mod chain100 {
    /// Number of rods.
    const N: usize = 100;
    /// Mass of each rod [kg].
    const m: f64 = 1.0;
    /// Length of each rod [m].
    const l: f64 = 0.1;
    /// Gravitational acceleration [m/s²].
    const g: f64 = 9.81;

    const _: () = for i in 0..N {
        /// Rod centre, x [m].
        static x: Coordinate = Coordinate {
            q0: (i as f64 + 0.5) * l,
        };
        /// Rod centre, y [m].
        static y: Coordinate = Coordinate {};
        /// Rod centre, z [m].
        static z: Coordinate = Coordinate {};
        /// Euler parameter θ0.
        static e0: Coordinate = Coordinate { q0: 1.0 };
        /// Euler parameter θ1.
        static e1: Coordinate = Coordinate {};
        /// Euler parameter θ2.
        static e2: Coordinate = Coordinate {};
        /// Euler parameter θ3.
        static e3: Coordinate = Coordinate {};
    };

    static gravity: Force = Gravity {
        acceleration: [0.0, 0.0, -g],
    };
    /// A rod.
    static link: [Body; N] = from_fn(|i| Body {
        origin: [x[i], y[i], z[i]],
        rotation: euler_parameters(e0[i], e1[i], e2[i], e3[i]),
        mass: m,
        inertia: diag(m * l * l / 1200.0, m * l * l / 12.0, m * l * l / 12.0),
    });
    /// The ball joint at the base of a rod.
    static joint: [Joint; N] = from_fn(|i| Spherical {
        a: link[i],
        at_a: [-0.5 * l, 0.0, 0.0],
        b: if i == 0 { ground } else { link[i - 1] },
        at_b: if i == 0 {
            [0.0, 0.0, 0.0]
        } else {
            [0.5 * l, 0.0, 0.0]
        },
    });

    /// Height of the free end [m].
    #[output]
    fn tip_z() -> f64 {
        link[N - 1].point([0.5 * l, 0.0, 0.0]).z()
    }
}
