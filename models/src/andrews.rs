//! Andrews' squeezing mechanism: seven rigid bodies in a plane, closed into two loops,
//! driven by a motor torque against a stiff spring (docs/models.md; Hairer & Wanner,
//! Solving Ordinary Differential Equations II, §VII.7).

/// Andrews' squeezing mechanism (Hairer & Wanner II, §VII.7): seven bodies, six
/// holonomic constraints, one degree of freedom.
///
/// The coordinates are the relative angles of the bodies. The kinetic energy is
/// $T = \tfrac12\dot q^\mathsf{T} M(q)\dot q$ with the mass matrix of the reference
/// formulation; its Coriolis terms (the reference forces $f_1, f_2, f_4, \dots, f_7$)
/// follow from $T$. The motor torque `mom` drives $\beta$; a spring of stiffness `c0`
/// and rest length `l0` between the point D of body 3 and the fixed point C acts on
/// $\gamma$. The default state is the consistent configuration of the reference at rest;
/// over $[0, 0.03]$ s the crank turns about 16 rad.
#[pfaff::mechanism]
pub mod andrews {
    /// Mass of body 1 [kg].
    const m1: f64 = 0.04325;
    /// Mass of body 2 [kg].
    const m2: f64 = 0.00365;
    /// Mass of body 3 [kg].
    const m3: f64 = 0.02373;
    /// Mass of body 4 [kg].
    const m4: f64 = 0.00706;
    /// Mass of body 5 [kg].
    const m5: f64 = 0.07050;
    /// Mass of body 6 [kg].
    const m6: f64 = 0.00706;
    /// Mass of body 7 [kg].
    const m7: f64 = 0.05498;
    /// Moment of inertia of body 1 [kg m²].
    const i1: f64 = 2.194e-6;
    /// Moment of inertia of body 2 [kg m²].
    const i2: f64 = 4.410e-7;
    /// Moment of inertia of body 3 [kg m²].
    const i3: f64 = 5.255e-6;
    /// Moment of inertia of body 4 [kg m²].
    const i4: f64 = 5.667e-7;
    /// Moment of inertia of body 5 [kg m²].
    const i5: f64 = 1.169e-5;
    /// Moment of inertia of body 6 [kg m²].
    const i6: f64 = 5.667e-7;
    /// Moment of inertia of body 7 [kg m²].
    const i7: f64 = 1.912e-5;
    /// Fixed point A, x [m].
    const xa: f64 = -0.06934;
    /// Fixed point A, y [m].
    const ya: f64 = -0.00227;
    /// Fixed point B (pivot of body 3), x [m].
    const xb: f64 = -0.03635;
    /// Fixed point B (pivot of body 3), y [m].
    const yb: f64 = 0.03273;
    /// Anchor C of the spring, x [m].
    const xc: f64 = 0.014;
    /// Anchor C of the spring, y [m].
    const yc: f64 = 0.072;
    /// Stiffness of the spring [N/m].
    const c0: f64 = 4530.0;
    /// Length of body 2 [m].
    const d: f64 = 28e-3;
    /// Distance from the joint with body 1 to the centre of mass of body 2 [m].
    const da: f64 = 115e-4;
    /// Length of body 4 [m].
    const e: f64 = 2e-2;
    /// Centre-of-mass offset on body 4: the centre is `e − ea` from its joint with body 5 [m].
    const ea: f64 = 1421e-5;
    /// Length of the crank, body 1 [m].
    const rr: f64 = 7e-3;
    /// Distance from the motor axis to the centre of mass of body 1 [m].
    const ra: f64 = 92e-5;
    /// Rest length of the spring [m].
    const l0: f64 = 7785e-5;
    /// Distance on body 3 from B to the joint with body 2 [m].
    const ss: f64 = 35e-3;
    /// Centre of mass of body 3, first body-frame component [m].
    const sa: f64 = 1874e-5;
    /// Centre of mass of body 3, second body-frame component [m].
    const sb: f64 = 1043e-5;
    /// Spring point D on body 3, second body-frame component [m].
    const sc: f64 = 18e-3;
    /// Spring point D on body 3, first body-frame component [m].
    const sd: f64 = 2e-2;
    /// Centre of mass of body 5, first body-frame component [m].
    const ta: f64 = 2308e-5;
    /// Centre of mass of body 5, second body-frame component [m].
    const tb: f64 = 916e-5;
    /// Length of body 7 [m].
    const u: f64 = 4e-2;
    /// Centre of mass of body 7, first body-frame component [m].
    const ua: f64 = 1228e-5;
    /// Centre of mass of body 7, second body-frame component [m].
    const ub: f64 = 449e-5;
    /// Length of body 6 [m].
    const zf: f64 = 2e-2;
    /// Length of body 5 [m].
    const zt: f64 = 4e-2;
    /// Centre-of-mass offset on body 6: the centre is `zf − fa` from its joint with body 7 [m].
    const fa: f64 = 1421e-5;
    /// Torque of the motor on body 1 [N m].
    const mom: f64 = 33e-3;

    /// Angle of the crank, body 1 [rad].
    static beta: Coordinate = Coordinate {
        q0: -0.06171389001427645,
        qd0: 0.0,
    };
    /// Angle of body 2 relative to body 1 [rad].
    static theta: Coordinate = Coordinate {};
    /// Angle of body 3 [rad].
    static gamma: Coordinate = Coordinate {
        q0: 0.45527981916307037,
        qd0: 0.0,
    };
    /// Angle of body 4 relative to body 5 [rad].
    static phi: Coordinate = Coordinate {
        q0: 0.22266839016588588,
        qd0: 0.0,
    };
    /// Angle of body 5 [rad].
    static delta: Coordinate = Coordinate {
        q0: 0.48736497954384256,
        qd0: 0.0,
    };
    /// Angle of body 6 relative to body 7 [rad].
    static omega: Coordinate = Coordinate {
        q0: -0.22266839016588588,
        qd0: 0.0,
    };
    /// Angle of body 7 [rad].
    static epsilon: Coordinate = Coordinate {
        q0: 1.2305474445498212,
        qd0: 0.0,
    };

    fn m11() -> f64 {
        m1 * ra.powi(2) + m2 * (rr.powi(2) - 2.0 * da * rr * theta.cos() + da.powi(2)) + i1 + i2
    }

    fn m12() -> f64 {
        m2 * (da.powi(2) - da * rr * theta.cos()) + i2
    }

    fn m22() -> f64 {
        m2 * da.powi(2) + i2
    }

    fn m33() -> f64 {
        m3 * (sa.powi(2) + sb.powi(2)) + i3
    }

    fn m44() -> f64 {
        m4 * (e - ea).powi(2) + i4
    }

    fn m45() -> f64 {
        m4 * ((e - ea).powi(2) + zt * (e - ea) * phi.sin()) + i4
    }

    fn m55() -> f64 {
        m4 * (zt.powi(2) + 2.0 * zt * (e - ea) * phi.sin() + (e - ea).powi(2))
            + m5 * (ta.powi(2) + tb.powi(2))
            + i4
            + i5
    }

    fn m66() -> f64 {
        m6 * (zf - fa).powi(2) + i6
    }

    fn m67() -> f64 {
        m6 * ((zf - fa).powi(2) - u * (zf - fa) * omega.sin()) + i6
    }

    fn m77() -> f64 {
        m6 * ((zf - fa).powi(2) - 2.0 * u * (zf - fa) * omega.sin() + u.powi(2))
            + m7 * (ua.powi(2) + ub.powi(2))
            + i6
            + i7
    }

    /// The mass matrix of the reference formulation; $T = \tfrac12\dot q^\mathsf{T}M\dot q$.
    fn mass_matrix() -> [[f64; 7]; 7] {
        [
            [m11(), m12(), 0.0, 0.0, 0.0, 0.0, 0.0],
            [m12(), m22(), 0.0, 0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, m33(), 0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, m44(), m45(), 0.0, 0.0],
            [0.0, 0.0, 0.0, m45(), m55(), 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0, 0.0, m66(), m67()],
            [0.0, 0.0, 0.0, 0.0, 0.0, m67(), m77()],
        ]
    }

    /// The motor torque on the crank.
    #[force(beta)]
    fn motor() -> f64 {
        mom
    }

    /// The spring between D on body 3 and the fixed point C: $-c_0 (L - l_0)\,\delta L$.
    #[virtual_work]
    fn spring() -> f64 {
        let xd = sd * gamma.cos() + sc * gamma.sin() + xb;
        let yd = sd * gamma.sin() - sc * gamma.cos() + yb;
        let len = ((xd - xc).powi(2) + (yd - yc).powi(2)).sqrt();
        -c0 * (len - l0) * delta(len)
    }

    /// Loop through B, x: the joint of bodies 2 and 3 seen from both sides.
    #[holonomic]
    fn loop_b_x() -> f64 {
        rr * beta.cos() - d * (beta + theta).cos() - ss * gamma.sin() - xb
    }

    /// Loop through B, y.
    #[holonomic]
    fn loop_b_y() -> f64 {
        rr * beta.sin() - d * (beta + theta).sin() + ss * gamma.cos() - yb
    }

    /// Loop through A via bodies 4 and 5, x.
    #[holonomic]
    fn loop_a5_x() -> f64 {
        rr * beta.cos() - d * (beta + theta).cos() - e * (phi + delta).sin() - zt * delta.cos() - xa
    }

    /// Loop through A via bodies 4 and 5, y.
    #[holonomic]
    fn loop_a5_y() -> f64 {
        rr * beta.sin() - d * (beta + theta).sin() + e * (phi + delta).cos() - zt * delta.sin() - ya
    }

    /// Loop through A via bodies 6 and 7, x.
    #[holonomic]
    fn loop_a7_x() -> f64 {
        rr * beta.cos()
            - d * (beta + theta).cos()
            - zf * (omega + epsilon).cos()
            - u * epsilon.sin()
            - xa
    }

    /// Loop through A via bodies 6 and 7, y.
    #[holonomic]
    fn loop_a7_y() -> f64 {
        rr * beta.sin() - d * (beta + theta).sin() - zf * (omega + epsilon).sin()
            + u * epsilon.cos()
            - ya
    }
}
