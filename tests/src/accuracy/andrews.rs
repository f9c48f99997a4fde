//! `andrews` against its source expressions, and against the reference formulation of
//! Hairer & Wanner, Solving Ordinary Differential Equations II, §VII.7 (the same
//! formulation as the "andrews" problem of the Bari test set for IVP solvers).
//!
//! The angle order of q is (β, Θ, γ, Φ, δ, Ω, ε) in both. The reference forces are
//! - f1 = mom − m2 da rr Θ̇(Θ̇ + 2β̇) sin Θ, f2 = m2 da rr β̇² sin Θ,
//! - f3 = Fx (sc cos γ − sd sin γ) + Fy (sd cos γ + sc sin γ),
//!   (Fx, Fy) = −c0 (L − l0)/L (xd − xc, yd − yc),
//! - f4 = m4 zt (e − ea) δ̇² cos Φ, f5 = −m4 zt (e − ea) Φ̇(Φ̇ + 2δ̇) cos Φ,
//! - f6 = −m6 u (zf − fa) ε̇² cos Ω, f7 = m6 u (zf − fa) Ω̇(Ω̇ + 2ε̇) cos Ω.
//!
//! Check of f1, f2, f4–f7 against the Lagrange operator of T = ½ q̇ᵀMq̇ (done by hand):
//! in the (β, Θ) block, ∂M11/∂Θ = 2k sin Θ and ∂M12/∂Θ = k sin Θ with k = m2 da rr, so
//! ∂T/∂Θ = k sin Θ (β̇² + β̇Θ̇) and Ṁq̇ = k sin Θ (2β̇Θ̇ + Θ̇², β̇Θ̇); hence
//! Q_v = ∂T/∂q − Ṁq̇ = (−k Θ̇(Θ̇ + 2β̇) sin Θ, k β̇² sin Θ) = (f1 − mom, f2). The (Φ, δ)
//! block: M45 = … + k' sin Φ, M55 = … + 2k' sin Φ with k' = m4 zt (e − ea), so
//! ∂T/∂Φ = k' cos Φ (δ̇² + Φ̇δ̇) and Ṁq̇ = k' cos Φ (Φ̇δ̇, Φ̇² + 2Φ̇δ̇); hence
//! Q_v = (k' δ̇² cos Φ, −k' Φ̇(Φ̇ + 2δ̇) cos Φ) = (f4, f5). The (Ω, ε) block is the same
//! with k'' = −m6 u (zf − fa) in place of k' and Ω, ε in place of Φ, δ: (f6, f7).
//! f3 is −c0 (L − l0) ∂L/∂γ, the virtual work of the spring.

use pfaff::{Mechanism as _, TimeDependence};
use pfaff_models::andrews::{Model, Params, INFO};

use super::check::{check_info, check_parameters, perturb, Expected, State};
use super::reference::Reference;
use super::sweep;
use super::util::{dense, max_abs, Rng};

/// The consistent initial values of docs/models.md (to double precision).
const Q0: [f64; 7] = [
    -0.061_713_890_014_276_45,
    0.0,
    0.455_279_819_163_070_37,
    0.222_668_390_165_885_88,
    0.487_364_979_543_842_56,
    -0.222_668_390_165_885_88,
    1.230_547_444_549_821_2,
];

macro_rules! reference_parameters {
    ($($field:ident),* $(,)?) => {
        /// The parameters of the reference formulation (docs/models.md).
        #[derive(Clone, Copy, Debug)]
        struct Hw {
            $($field: f64,)*
        }

        impl Hw {
            fn new(p: &Params) -> Self {
                Self { $($field: p.$field,)* }
            }
        }
    };
}

reference_parameters!(
    m1, m2, m3, m4, m5, m6, m7, i1, i2, i3, i4, i5, i6, i7, xa, ya, xb, yb, xc, yc, c0, d, da, e,
    ea, rr, ra, l0, ss, sa, sb, sc, sd, ta, tb, u, ua, ub, zf, zt, fa, mom,
);

impl Hw {
    /// The mass matrix of docs/models.md (Hairer & Wanner's M).
    #[allow(clippy::similar_names)]
    fn mass(&self, q: &[f64]) -> [[f64; 7]; 7] {
        let Hw {
            m1,
            m2,
            m3,
            m4,
            m5,
            m6,
            m7,
            i1,
            i2,
            i3,
            i4,
            i5,
            i6,
            i7,
            da,
            e,
            ea,
            rr,
            ra,
            sa,
            sb,
            ta,
            tb,
            u,
            ua,
            ub,
            zf,
            zt,
            fa,
            ..
        } = *self;
        let (cth, sph, som) = (q[1].cos(), q[3].sin(), q[5].sin());
        let mut m = [[0.0; 7]; 7];
        m[0][0] = m1 * ra * ra + m2 * (rr * rr - 2.0 * da * rr * cth + da * da) + i1 + i2;
        m[1][0] = m2 * (da * da - da * rr * cth) + i2;
        m[1][1] = m2 * da * da + i2;
        m[2][2] = m3 * (sa * sa + sb * sb) + i3;
        m[3][3] = m4 * (e - ea).powi(2) + i4;
        m[4][3] = m4 * ((e - ea).powi(2) + zt * (e - ea) * sph) + i4;
        m[4][4] = m4 * (zt * zt + 2.0 * zt * (e - ea) * sph + (e - ea).powi(2))
            + m5 * (ta * ta + tb * tb)
            + i4
            + i5;
        m[5][5] = m6 * (zf - fa).powi(2) + i6;
        m[6][5] = m6 * ((zf - fa).powi(2) - u * (zf - fa) * som) + i6;
        m[6][6] = m6 * ((zf - fa).powi(2) - 2.0 * u * (zf - fa) * som + u * u)
            + m7 * (ua * ua + ub * ub)
            + i6
            + i7;
        m[0][1] = m[1][0];
        m[3][4] = m[4][3];
        m[5][6] = m[6][5];
        m
    }

    /// The spring point D on body 3 and the length L = |D − C|.
    fn spring(&self, gamma: f64) -> (f64, f64, f64) {
        let xd = self.sd * gamma.cos() + self.sc * gamma.sin() + self.xb;
        let yd = self.sd * gamma.sin() - self.sc * gamma.cos() + self.yb;
        let len = ((xd - self.xc).powi(2) + (yd - self.yc).powi(2)).sqrt();
        (xd, yd, len)
    }

    /// Hairer & Wanner's force vector f and, per row, the size of the terms it sums
    /// (the Coriolis rows: k (|q̇a| + |q̇b|)² with the row's coefficient k), against which
    /// the comparison is relative.
    fn forces(&self, q: &[f64], v: &[f64]) -> ([f64; 7], [f64; 7]) {
        let Hw {
            m2,
            m4,
            m6,
            c0,
            da,
            e,
            ea,
            rr,
            l0,
            sc,
            sd,
            u,
            zf,
            zt,
            fa,
            xc,
            yc,
            mom,
            ..
        } = *self;
        let (bep, thp, php, dep, omp, epp) = (v[0], v[1], v[3], v[4], v[5], v[6]);
        let (sith, coga, siga, coph, coom) =
            (q[1].sin(), q[2].cos(), q[2].sin(), q[3].cos(), q[5].cos());
        let (xd, yd, len) = self.spring(q[2]);
        let force = -c0 * (len - l0) / len;
        let (fx, fy) = (force * (xd - xc), force * (yd - yc));
        let k1 = m2 * da * rr * sith;
        let k4 = m4 * zt * (e - ea) * coph;
        let k6 = m6 * u * (zf - fa) * coom;
        let f = [
            mom - k1 * thp * (thp + 2.0 * bep),
            k1 * bep * bep,
            fx * (sc * coga - sd * siga) + fy * (sd * coga + sc * siga),
            k4 * dep * dep,
            -k4 * php * (php + 2.0 * dep),
            -k6 * epp * epp,
            k6 * omp * (omp + 2.0 * epp),
        ];
        let sq = |a: f64, b: f64| (a.abs() + b.abs()).powi(2);
        let scale = [
            mom.abs() + k1.abs() * sq(bep, thp),
            k1.abs() * sq(bep, thp),
            (fx * (sc * coga - sd * siga)).abs() + (fy * (sd * coga + sc * siga)).abs(),
            k4.abs() * sq(php, dep),
            k4.abs() * sq(php, dep),
            k6.abs() * sq(omp, epp),
            k6.abs() * sq(omp, epp),
        ];
        (f, scale)
    }

    /// The six loop-closure constraints of docs/models.md.
    fn constraints(&self, q: &[f64]) -> [f64; 6] {
        let Hw {
            xa,
            ya,
            xb,
            yb,
            d,
            e,
            rr,
            ss,
            u,
            zf,
            zt,
            ..
        } = *self;
        let (be, th, ga, ph, de, om, ep) = (q[0], q[1], q[2], q[3], q[4], q[5], q[6]);
        let x = rr * be.cos() - d * (be + th).cos();
        let y = rr * be.sin() - d * (be + th).sin();
        [
            x - ss * ga.sin() - xb,
            y + ss * ga.cos() - yb,
            x - e * (ph + de).sin() - zt * de.cos() - xa,
            y + e * (ph + de).cos() - zt * de.sin() - ya,
            x - zf * (om + ep).cos() - u * ep.sin() - xa,
            y - zf * (om + ep).sin() + u * ep.cos() - ya,
        ]
    }
}

/// The expressions of `models/src/andrews.rs`, re-typed: T = ½ q̇ᵀMq̇ with the M of
/// docs/models.md, the motor torque on β, the spring as the virtual work
/// −c0 (L − l0) δL, and the six constraints.
fn reference(p: &Params) -> Reference {
    let hw = Hw::new(p);
    let mut r = Reference::new(7, move |_, q, v| {
        let m = hw.mass(q);
        0.5 * (0..7)
            .map(|i| (0..7).map(|j| v[i] * m[i][j] * v[j]).sum::<f64>())
            .sum::<f64>()
    })
    .force(0, move |_, _, _| hw.mom)
    .virtual_work(
        move |_, q, _| -hw.c0 * (hw.spring(q[2]).2 - hw.l0),
        move |_, q| hw.spring(q[2]).2,
    );
    for i in 0..6 {
        r = r.holonomic(move |_, q| hw.constraints(q)[i]);
    }
    r
}

fn sample(rng: &mut Rng) -> State {
    State {
        t: rng.range(0.0, 0.03),
        q: rng.vec(7, -std::f64::consts::PI, std::f64::consts::PI),
        qd: rng.vec(7, -2.0, 2.0),
    }
}

#[test]
fn info() {
    check_parameters!(
        m1 = 0.04325,
        m2 = 0.00365,
        m3 = 0.02373,
        m4 = 0.00706,
        m5 = 0.07050,
        m6 = 0.00706,
        m7 = 0.05498,
        i1 = 2.194e-6,
        i2 = 4.410e-7,
        i3 = 5.255e-6,
        i4 = 5.667e-7,
        i5 = 1.169e-5,
        i6 = 5.667e-7,
        i7 = 1.912e-5,
        xa = -0.06934,
        ya = -0.00227,
        xb = -0.03635,
        yb = 0.03273,
        xc = 0.014,
        yc = 0.072,
        c0 = 4530.0,
        d = 28e-3,
        da = 115e-4,
        e = 2e-2,
        ea = 1421e-5,
        rr = 7e-3,
        ra = 92e-5,
        l0 = 7785e-5,
        ss = 35e-3,
        sa = 1874e-5,
        sb = 1043e-5,
        sc = 18e-3,
        sd = 2e-2,
        ta = 2308e-5,
        tb = 916e-5,
        u = 4e-2,
        ua = 1228e-5,
        ub = 449e-5,
        zf = 2e-2,
        zt = 4e-2,
        fa = 1421e-5,
        mom = 33e-3,
    );
    check_info(
        &Model::default(),
        &Expected {
            name: "andrews",
            coordinates: &["beta", "theta", "gamma", "phi", "delta", "omega", "epsilon"],
            holonomic: &[
                "loop_b_x",
                "loop_b_y",
                "loop_a5_x",
                "loop_a5_y",
                "loop_a7_x",
                "loop_a7_y",
            ],
            nonholonomic: &[],
            time: TimeDependence::default(),
            homogeneous: true,
            conservative: false,
            q0: &Q0,
            qd0: &[0.0; 7],
        },
    );
    // The non-zero entries of M listed in docs/models.md, both triangles.
    let mass: &[(u32, u32)] = &[
        (0, 0),
        (0, 1),
        (1, 0),
        (1, 1),
        (2, 2),
        (3, 3),
        (3, 4),
        (4, 3),
        (4, 4),
        (5, 5),
        (5, 6),
        (6, 5),
        (6, 6),
    ];
    assert_eq!(INFO.mass_pattern, mass);
}

#[test]
fn derivatives() {
    sweep(
        "andrews",
        0x5eed_0009,
        Model::default,
        |m| reference(&m.params),
        sample,
    );
}

/// The Coriolis terms are small beside the spring (1e-6 against 1): switch the spring
/// and the motor off so that the differences check them at full relative accuracy.
#[test]
fn derivatives_without_spring_and_motor() {
    let make = || {
        let mut model = Model::default();
        model.params.c0 = 0.0;
        model.params.mom = 0.0;
        model
    };
    sweep(
        "andrews (c0 = mom = 0)",
        0x5eed_000a,
        make,
        |m| reference(&m.params),
        sample,
    );
}

/// The generated M and Q against Hairer & Wanner's M and f, directly, at random states
/// with velocities up to 10³ rad/s (the scale of the benchmark's motion) and perturbed
/// parameters: 1e-12 relative per entry, against √(M_ii M_jj) for M (a bound on |M_ij|
/// for a positive definite M) and against the size of the terms of each row for f.
#[test]
#[allow(non_snake_case)]
fn matches_hairer_wanner() {
    const TOL: f64 = 1e-12;
    let mut rng = Rng::new(0x5eed_000b);
    let (mut worst_m, mut worst_f): (f64, f64) = (0.0, 0.0);
    for k in 0..200 {
        let mut model = Model::default();
        if k % 2 == 1 {
            perturb(&mut model, &mut rng, 0.2);
        }
        let hw = Hw::new(&model.params);
        let q = rng.vec(7, -std::f64::consts::PI, std::f64::consts::PI);
        let speed = 10f64.powf(rng.range(0.0, 3.0));
        let v = rng.vec(7, -speed, speed);
        let mut M = vec![f64::NAN; INFO.mass_pattern.len()];
        model.mass_matrix(0.0, &q, &mut M);
        let M = dense(INFO.mass_pattern, &M, 7, 7);
        let M_ref = hw.mass(&q);
        for i in 0..7 {
            for j in 0..7 {
                let scale = (M_ref[i][i] * M_ref[j][j]).abs().sqrt();
                let err = (M[i * 7 + j] - M_ref[i][j]).abs() / scale;
                worst_m = worst_m.max(err);
                assert!(
                    err <= TOL,
                    "M[{i}][{j}] = {} vs {} at q = {q:?}",
                    M[i * 7 + j],
                    M_ref[i][j]
                );
            }
        }
        let mut Q = [f64::NAN; 7];
        model.forces(0.0, &q, &v, &mut Q);
        let (f, scale) = hw.forces(&q, &v);
        for i in 0..7 {
            let err = (Q[i] - f[i]).abs() / scale[i].max(f64::MIN_POSITIVE);
            worst_f = worst_f.max(err);
            assert!(
                err <= TOL,
                "Q[{i}] = {:e} vs f = {:e} at q = {q:?}, q̇ = {v:?}",
                Q[i],
                f[i]
            );
        }
    }
    println!("andrews vs Hairer & Wanner: M {worst_m:.1e}, f {worst_f:.1e} (tol {TOL:.0e})");
}

/// The default state is the consistent one of docs/models.md: |C| at rounding level
/// (the lengths are ~5e-2 m, so a few ulps are ~1e-17 m; 1e-15 leaves a factor ~100).
#[test]
fn initial_state_is_consistent() {
    let model = Model::default();
    let (mut q, mut qd) = ([0.0; 7], [0.0; 7]);
    model.initial_state(&mut q, &mut qd);
    let mut c = [f64::NAN; 6];
    model.holonomic(0.0, &q, &mut c);
    let c_ref = Hw::new(&model.params).constraints(&q);
    println!(
        "andrews: |C(q0)| = {:.1e} (reference closure {:.1e})",
        max_abs(&c),
        max_abs(&c_ref)
    );
    assert!(max_abs(&c) < 1e-15, "C(q0) = {c:?}");
    assert!(max_abs(&c_ref) < 1e-15, "C_ref(q0) = {c_ref:?}");
    assert_eq!(qd, [0.0; 7]);
}
