//! A row of parallelogram windows written with arrays: `N` windows, `2N + 1` links.

/// A row of `N = 4` parallelogram windows hanging from the ground: `N + 1` equal cranks
/// pinned to the ground at $(i d, 0)$ and `N` equal couplers, coupler `i` pinned to the
/// tips of cranks `i` and `i + 1`.
///
/// Every link is a uniform bar of mass per length `rho` in absolute planar coordinates
/// (centre `x`, `y` and angle): cranks `xc_i yc_i pc_i` (`i = 0 … N`, angle from the x
/// axis), couplers `xb_i yb_i pb_i` (`i = 0 … N − 1`). The `3N + 1` revolute joints
/// leave one degree of freedom: the cranks stay parallel and the couplers level. The row
/// is released at rest with the cranks hanging 30° off the vertical ($-\pi/3$ from the
/// x axis) and swings under gravity (along −y) between $-\pi/3$ and $-2\pi/3$, never
/// reaching the horizontal dead-centre. Written with arrays and loops
/// (`docs/arrays.md`): changing `N` changes the row.
#[pfaff::mechanism]
pub mod window_row {
    /// Number of windows.
    const N: usize = 4;
    /// Crank length [m].
    const l: f64 = 0.5;
    /// Window width: spacing of the ground pins and length of a coupler [m].
    const d: f64 = 0.3;
    /// Mass per length of every link [kg/m].
    const rho: f64 = 2.0;
    /// Gravitational acceleration, along −y [m/s²].
    const g: f64 = 9.81;

    /// Centre of a crank, x [m].
    static xc: [Coordinate; N + 1] = from_fn(|i| Coordinate {
        q0: i as f64 * d + 0.25 * l,
    });
    /// Centre of a crank, y [m].
    static yc: [Coordinate; N + 1] = [Coordinate {
        q0: -0.4330127018922193 * l,
    }; N + 1];
    /// Angle of a crank from the x axis [rad].
    static pc: [Coordinate; N + 1] = [Coordinate { q0: -PI / 3.0 }; N + 1];
    /// Centre of a coupler, x [m].
    static xb: [Coordinate; N] = from_fn(|i| Coordinate {
        q0: (i as f64 + 0.5) * d + 0.5 * l,
    });
    /// Centre of a coupler, y [m].
    static yb: [Coordinate; N] = [Coordinate {
        q0: -0.8660254037844386 * l,
    }; N];
    /// Angle of a coupler from the x axis [rad].
    static pb: [Coordinate; N] = [Coordinate {}; N];

    static gravity: Force = Gravity {
        acceleration: [0.0, -g],
    };

    /// A crank, a uniform bar.
    static crank: [Body; N + 1] = from_fn(|i| Body {
        origin: [xc[i], yc[i]],
        angle: pc[i],
        mass: rho * l,
        inertia: rho * l * l * l / 12.0,
    });
    /// A coupler, a uniform bar.
    static coupler: [Body; N] = from_fn(|i| Body {
        origin: [xb[i], yb[i]],
        angle: pb[i],
        mass: rho * d,
        inertia: rho * d * d * d / 12.0,
    });

    /// A crank's pin on the ground.
    static pivot: [Joint; N + 1] = from_fn(|i| Revolute {
        a: crank[i],
        at_a: [-0.5 * l, 0.0],
        at_b: [i as f64 * d, 0.0],
    });
    const _: () = for i in 0..N {
        /// A coupler's left end on the tip of the crank below it.
        static left: Joint = Revolute {
            a: coupler[i],
            at_a: [-0.5 * d, 0.0],
            b: crank[i],
            at_b: [0.5 * l, 0.0],
        };
        /// A coupler's right end on the tip of the next crank.
        static right: Joint = Revolute {
            a: coupler[i],
            at_a: [0.5 * d, 0.0],
            b: crank[i + 1],
            at_b: [0.5 * l, 0.0],
        };
    };

    /// Height of the couplers [m].
    #[output]
    fn height() -> f64 {
        yb[0]
    }
    /// The spread of the coupler angles, `Σ_i (pb_i − pb_0)²` over `i = 1 … N − 1`
    /// (zero on the constraints: the couplers turn together).
    #[output]
    fn spread() -> f64 {
        (1..N).map(|i| (pb[i] - pb[0]).powi(2)).sum()
    }
}
