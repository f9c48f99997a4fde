//! Slider crank with an elastic connecting rod (Simeon; Test Set for IVP Solvers
//! "crank"): a rigid crank, an elastic rod in the floating frame of reference and a rigid
//! slider, in the plane, the crank driven at `omega`. `flexible_crank` uses the test
//! set's precomputed invariants as docs/models.md prints them (π written 3.1415927,
//! the axial block of the modal mass 15 times the integral of its ansatz);
//! `flexible_crank_shapes` integrates the same rod's shape functions at compile time.

/// Slider crank with an elastic connecting rod, with the test set's invariants.
///
/// Coordinates `phi1` (crank angle), `phi2` (angle of the rod's frame, origin at the crank
/// tip, x axis along the undeformed rod), `x3` (slider), the rod's lateral modes `q1 q2`
/// ($w = q_1 \sin \pi\xi + q_2 \sin 2\pi\xi$, $\xi = x/l_2$) and axial ansatz `q3 q4`
/// ($u = 4\xi(1-\xi) q_3 + (2\xi^2-\xi) q_4$). The rod's mass, stiffness and shape
/// integrals are the test set's `MQ`, `KQ`, `BQ`, `c1`, `c2`, `c12`, `c21` with
/// $\rho\,bb\,hh\,l_2$ as the unit of mass; the shape functions serve the rod's points
/// (the joint at its tip, the drawing). Initial state: the test set's first consistent
/// set. The elastic modes are stiff (up to about 1e5 rad/s): use `Method::Radau5`.
#[pfaff::mechanism]
pub mod flexible_crank {
    /// Mass of the crank [kg].
    const m1: f64 = 0.36;
    /// Mass of the rod [kg].
    const m2: f64 = 0.151104;
    /// Mass of the slider [kg].
    const m3: f64 = 0.075552;
    /// Length of the crank [m].
    const l1: f64 = 0.15;
    /// Length of the rod [m].
    const l2: f64 = 0.30;
    /// Moment of inertia of the crank about its pivot [kg m²].
    const j1: f64 = 0.002727;
    /// Moment of inertia of the rod about its frame's origin (the crank tip) [kg m²].
    const j2: f64 = 0.0045339259;
    /// Young's modulus of the rod [Pa].
    const ee: f64 = 2.0e11;
    /// Poisson's ratio of the rod (not used by the planar beam).
    const nue: f64 = 0.3;
    /// Width of the rod's square cross-section [m].
    const bb: f64 = 0.008;
    /// Height of the rod's square cross-section [m].
    const hh: f64 = 0.008;
    /// Density of the rod [kg/m³].
    const rho: f64 = 7870.0;
    /// Gravitational acceleration, along −y [m/s²] (off in the test set).
    const grav: f64 = 0.0;
    /// Angular velocity of the crank [rad/s].
    const omega: f64 = 150.0;

    /// Crank angle [rad].
    static phi1: Coordinate = Coordinate {
        q0: 0.0,
        qd0: 150.0,
    };
    /// Angle of the rod's frame [rad].
    static phi2: Coordinate = Coordinate {
        q0: 0.0,
        qd0: -74.9957670,
    };
    /// Slider position [m].
    static x3: Coordinate = Coordinate {
        q0: 0.450016933,
        qd0: -0.268938672e-5,
    };
    /// First lateral mode of the rod [m].
    static q1: Coordinate = Coordinate {
        q0: 0.0,
        qd0: 0.444896105,
    };
    /// Second lateral mode of the rod [m].
    static q2: Coordinate = Coordinate {
        q0: 0.0,
        qd0: 0.463434311e-2,
    };
    /// Axial bubble mode of the rod [m].
    static q3: Coordinate = Coordinate {
        q0: 0.103339863e-4,
        qd0: -0.178591076e-5,
    };
    /// Axial displacement of the rod's far end [m].
    static q4: Coordinate = Coordinate {
        q0: 0.169327969e-4,
        qd0: -0.268938672e-5,
    };

    /// π as the test set writes it in its matrices.
    fn pi_ts() -> f64 {
        3.1415927
    }
    /// FACM = ρ bb hh l2, the test set's unit of modal mass [kg].
    fn facm() -> f64 {
        rho * bb * hh * l2
    }
    /// FACK = ee bb hh / l2, the test set's unit of stiffness [N/m].
    fn fack() -> f64 {
        ee * bb * hh / l2
    }
    /// ρ FACB = ρ bb hh l2, the unit of the shape integrals [kg].
    fn rfacb() -> f64 {
        rho * bb * hh * l2
    }

    static gravity: Force = Gravity {
        acceleration: [0.0, -grav],
    };

    /// The crank, pivoted at the origin (its centre of mass at mid-length).
    static crank: Body = Body {
        origin: [0.0, 0.0],
        angle: phi1,
        mass: m1,
        com: [0.5 * l1, 0.0],
        inertia: j1 - 0.25 * m1 * l1 * l1,
    };
    /// The elastic connecting rod, its frame at the crank tip.
    static rod: Body = Deformable {
        origin: [l1 * phi1.cos(), l1 * phi1.sin()],
        angle: phi2,
        elastic: [q1, q2, q3, q4],
        mass: m2,
        com: [0.5 * l2, 0.0],
        inertia: j2 - 0.25 * m2 * l2 * l2,
        position: |xi| [l2 * xi, 0.0],
        displacement: |xi| {
            [
                q3 * 4.0 * xi * (1.0 - xi) + q4 * (2.0 * xi * xi - xi),
                q1 * (PI * xi).sin() + q2 * (2.0 * PI * xi).sin(),
            ]
        },
        invariants: Invariants {
            // S̄ = ρ (c1; c2)
            s_bar: [
                [0.0, 0.0, 2.0 / 3.0 * rfacb(), 1.0 / 6.0 * rfacb()],
                [2.0 / pi_ts() * rfacb(), 0.0, 0.0, 0.0],
            ],
            // Ī_11 = ρ c12, Ī_12 = ρ c21 (the rod's centre line has x₂ = 0)
            i_bar: [
                [
                    [0.0, 0.0, 1.0 / 3.0 * l2 * rfacb(), 1.0 / 6.0 * l2 * rfacb()],
                    [
                        1.0 / pi_ts() * l2 * rfacb(),
                        -0.5 / pi_ts() * l2 * rfacb(),
                        0.0,
                        0.0,
                    ],
                ],
                [0.0, 0.0],
            ],
            // S̄_11: the axial block of MQ; S̄_22: its lateral block;
            // S̄_12 − S̄_21 = BQ.
            s_bar_kl: [
                [
                    [
                        [0.0, 0.0, 0.0, 0.0],
                        [0.0, 0.0, 0.0, 0.0],
                        [0.0, 0.0, 8.0 * facm(), facm()],
                        [0.0, 0.0, facm(), 2.0 * facm()],
                    ],
                    [
                        [0.0, 0.0, 0.0, 0.0],
                        [0.0, 0.0, 0.0, 0.0],
                        [16.0 / pi_ts().powi(3) * rfacb(), 0.0, 0.0, 0.0],
                        [
                            -(8.0 / pi_ts().powi(3) - 1.0 / pi_ts()) * rfacb(),
                            -0.5 / pi_ts() * rfacb(),
                            0.0,
                            0.0,
                        ],
                    ],
                ],
                [
                    [
                        [
                            0.0,
                            0.0,
                            16.0 / pi_ts().powi(3) * rfacb(),
                            -(8.0 / pi_ts().powi(3) - 1.0 / pi_ts()) * rfacb(),
                        ],
                        [0.0, 0.0, 0.0, -0.5 / pi_ts() * rfacb()],
                        [0.0, 0.0, 0.0, 0.0],
                        [0.0, 0.0, 0.0, 0.0],
                    ],
                    [
                        [0.5 * facm(), 0.0, 0.0, 0.0],
                        [0.0, 0.5 * facm(), 0.0, 0.0],
                        [0.0, 0.0, 0.0, 0.0],
                        [0.0, 0.0, 0.0, 0.0],
                    ],
                ],
            ],
        },
        stiffness: [
            [
                fack() * pi_ts().powi(4) / 24.0 * (hh / l2).powi(2),
                0.0,
                0.0,
                0.0,
            ],
            [
                0.0,
                fack() * pi_ts().powi(4) * 2.0 / 3.0 * (hh / l2).powi(2),
                0.0,
                0.0,
            ],
            [0.0, 0.0, 16.0 / 3.0 * fack(), -8.0 / 3.0 * fack()],
            [0.0, 0.0, -8.0 / 3.0 * fack(), 7.0 / 3.0 * fack()],
        ],
    };
    /// The slider on the x axis.
    static slider: Body = Body {
        origin: [x3, 0.0],
        angle: 0.0,
        mass: m3,
    };

    /// The rod's far end pinned to the slider.
    static pin_b: Joint = Revolute {
        a: rod,
        at_a: rod.material(1.0),
        b: slider,
    };
    /// The crank turns at `omega`.
    static driver: Joint = Driver {
        value: crank.angle(),
        motion: omega * t,
    };

    /// The rod's material point at a quarter of its length (drawn).
    static rod_quarter: Point = Point {
        frame: rod,
        at: rod.material(0.25),
    };
    /// The rod's mid-point (drawn).
    static rod_mid: Point = Point {
        frame: rod,
        at: rod.material(0.5),
    };
    /// The rod's material point at three quarters of its length (drawn).
    static rod_three_quarters: Point = Point {
        frame: rod,
        at: rod.material(0.75),
    };

    /// Lateral deflection of the rod's mid-point [m].
    #[output]
    fn mid_deflection() -> f64 {
        q1
    }
}

/// Slider crank with an elastic connecting rod whose invariants are integrated from its
/// shape functions at compile time.
///
/// The same mechanism, coordinates, parameters and initial state as `flexible_crank`;
/// the rod's shape integrals (E10) and its stiffness (the Euler–Bernoulli strain energy
/// $\frac12\int (EA\,u'^2 + EI\,w''^2)\,dx$ with $EA = ee\,bb\,hh$,
/// $EI = ee\,bb\,hh^3/12$) are the exact integrals of the shape functions. The rigid
/// inertia (`m2`, `j2`, centre of mass at mid-length) is the test set's. It differs from
/// `flexible_crank` in the axial block of the modal mass (the test set's is 15 times
/// the integral) and in π (the test set's 3.1415927).
#[pfaff::mechanism]
pub mod flexible_crank_shapes {
    /// Mass of the crank [kg].
    const m1: f64 = 0.36;
    /// Mass of the rod [kg].
    const m2: f64 = 0.151104;
    /// Mass of the slider [kg].
    const m3: f64 = 0.075552;
    /// Length of the crank [m].
    const l1: f64 = 0.15;
    /// Length of the rod [m].
    const l2: f64 = 0.30;
    /// Moment of inertia of the crank about its pivot [kg m²].
    const j1: f64 = 0.002727;
    /// Moment of inertia of the rod about its frame's origin (the crank tip) [kg m²].
    const j2: f64 = 0.0045339259;
    /// Young's modulus of the rod [Pa].
    const ee: f64 = 2.0e11;
    /// Poisson's ratio of the rod (not used by the planar beam).
    const nue: f64 = 0.3;
    /// Width of the rod's square cross-section [m].
    const bb: f64 = 0.008;
    /// Height of the rod's square cross-section [m].
    const hh: f64 = 0.008;
    /// Density of the rod [kg/m³].
    const rho: f64 = 7870.0;
    /// Gravitational acceleration, along −y [m/s²] (off in the test set).
    const grav: f64 = 0.0;
    /// Angular velocity of the crank [rad/s].
    const omega: f64 = 150.0;

    /// Crank angle [rad].
    static phi1: Coordinate = Coordinate {
        q0: 0.0,
        qd0: 150.0,
    };
    /// Angle of the rod's frame [rad].
    static phi2: Coordinate = Coordinate {
        q0: 0.0,
        qd0: -74.9957670,
    };
    /// Slider position [m].
    static x3: Coordinate = Coordinate {
        q0: 0.450016933,
        qd0: -0.268938672e-5,
    };
    /// First lateral mode of the rod [m].
    static q1: Coordinate = Coordinate {
        q0: 0.0,
        qd0: 0.444896105,
    };
    /// Second lateral mode of the rod [m].
    static q2: Coordinate = Coordinate {
        q0: 0.0,
        qd0: 0.463434311e-2,
    };
    /// Axial bubble mode of the rod [m].
    static q3: Coordinate = Coordinate {
        q0: 0.103339863e-4,
        qd0: -0.178591076e-5,
    };
    /// Axial displacement of the rod's far end [m].
    static q4: Coordinate = Coordinate {
        q0: 0.169327969e-4,
        qd0: -0.268938672e-5,
    };

    static gravity: Force = Gravity {
        acceleration: [0.0, -grav],
    };

    /// The crank, pivoted at the origin (its centre of mass at mid-length).
    static crank: Body = Body {
        origin: [0.0, 0.0],
        angle: phi1,
        mass: m1,
        com: [0.5 * l1, 0.0],
        inertia: j1 - 0.25 * m1 * l1 * l1,
    };
    /// The elastic connecting rod, its frame at the crank tip: an Euler–Bernoulli beam
    /// whose invariants and stiffness are integrated from the shape functions.
    static rod: Body = Deformable {
        origin: [l1 * phi1.cos(), l1 * phi1.sin()],
        angle: phi2,
        elastic: [q1, q2, q3, q4],
        mass: m2,
        com: [0.5 * l2, 0.0],
        inertia: j2 - 0.25 * m2 * l2 * l2,
        position: |xi| [l2 * xi, 0.0],
        displacement: |xi| {
            [
                q3 * 4.0 * xi * (1.0 - xi) + q4 * (2.0 * xi * xi - xi),
                q1 * (PI * xi).sin() + q2 * (2.0 * PI * xi).sin(),
            ]
        },
        span: 0.0..1.0,
        density: rho * bb * hh * l2,
        axial_rigidity: ee * bb * hh,
        bending_rigidity: ee * bb * hh.powi(3) / 12.0,
    };
    /// The slider on the x axis.
    static slider: Body = Body {
        origin: [x3, 0.0],
        angle: 0.0,
        mass: m3,
    };

    /// The rod's far end pinned to the slider.
    static pin_b: Joint = Revolute {
        a: rod,
        at_a: rod.material(1.0),
        b: slider,
    };
    /// The crank turns at `omega`.
    static driver: Joint = Driver {
        value: crank.angle(),
        motion: omega * t,
    };

    /// The rod's material point at a quarter of its length (drawn).
    static rod_quarter: Point = Point {
        frame: rod,
        at: rod.material(0.25),
    };
    /// The rod's mid-point (drawn).
    static rod_mid: Point = Point {
        frame: rod,
        at: rod.material(0.5),
    };
    /// The rod's material point at three quarters of its length (drawn).
    static rod_three_quarters: Point = Point {
        frame: rod,
        at: rod.material(0.75),
    };

    /// Lateral deflection of the rod's mid-point [m].
    #[output]
    fn mid_deflection() -> f64 {
        q1
    }
}
