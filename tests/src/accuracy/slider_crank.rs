//! `slider_crank` (docs/theory.md V10) against its source expressions, and the kinematics of
//! the V10 table computed from the generated functions.

use std::f64::consts::PI;

use pfaff::{Mechanism as _, TimeDependence};
use pfaff_models::slider_crank::{Model, Params, INFO};

use super::check::{check_info, check_parameters, Expected, State};
use super::reference::Reference;
use super::sweep;
use super::util::{dense, max_abs, max_diff, solve};

/// The V10 configuration at t = 0 (φ2 = −arcsin(1/6)), q and q̇, to double precision
/// (the table of docs/theory.md V10 gives them to 12 digits).
const Q0: [f64; 9] = [
    0.043_301_270_189_221_93,
    0.025,
    PI / 6.0,
    0.234_504_534_955_934_26,
    0.025,
    -0.167_448_079_219_689_32,
    0.382_406_529_533_424_7,
    0.0,
    0.0,
];
const QD0: [f64; 9] = [
    -0.25,
    0.433_012_701_892_219_3,
    10.0,
    -0.573_192_505_471_14,
    0.433_012_701_892_219_3,
    -2.927_700_218_845_599_6,
    -0.646_385_010_942_28,
    0.0,
    0.0,
];

/// The expressions of `models/src/slider_crank.rs`, re-typed:
/// q = (x1, y1, φ1, x2, y2, φ2, x3, y3, φ3).
fn reference(p: &Params) -> Reference {
    let &Params {
        a,
        b,
        m1,
        j1,
        m2,
        j2,
        m3,
        j3,
        g,
    } = p;
    Reference::new(9, move |_, _, v| {
        0.5 * m1 * (v[0].powi(2) + v[1].powi(2))
            + 0.5 * j1 * v[2].powi(2)
            + 0.5 * m2 * (v[3].powi(2) + v[4].powi(2))
            + 0.5 * j2 * v[5].powi(2)
            + 0.5 * m3 * (v[6].powi(2) + v[7].powi(2))
            + 0.5 * j3 * v[8].powi(2)
    })
    .potential(move |_, q| g * (m1 * q[1] + m2 * q[4] + m3 * q[7]))
    .holonomic(move |_, q| q[0] - 0.5 * a * q[2].cos())
    .holonomic(move |_, q| q[1] - 0.5 * a * q[2].sin())
    .holonomic(move |_, q| q[0] + 0.5 * a * q[2].cos() - q[3] + 0.5 * b * q[5].cos())
    .holonomic(move |_, q| q[1] + 0.5 * a * q[2].sin() - q[4] + 0.5 * b * q[5].sin())
    .holonomic(move |_, q| q[3] + 0.5 * b * q[5].cos() - q[6])
    .holonomic(move |_, q| q[4] + 0.5 * b * q[5].sin() - q[7])
    .holonomic(|_, q| q[7])
    .holonomic(|_, q| q[8])
    .holonomic(|t, q| q[2] - (PI / 6.0 + 10.0 * t))
}

#[test]
fn info() {
    // The mass data are our choice (see the model's doc).
    check_parameters!(
        a = 0.1,
        b = 0.3,
        m1 = 0.1,
        j1 = 0.1 * 0.1 * 0.1 / 12.0,
        m2 = 0.3,
        j2 = 0.3 * 0.3 * 0.3 / 12.0,
        m3 = 0.5,
        j3 = 0.5 * (0.04 * 0.04 + 0.02 * 0.02) / 12.0,
        g = 9.81,
    );
    check_info(
        &Model::default(),
        &Expected {
            name: "slider_crank",
            coordinates: &["x1", "y1", "phi1", "x2", "y2", "phi2", "x3", "y3", "phi3"],
            holonomic: &[
                "pin_o_x",
                "pin_o_y",
                "pin_a_x",
                "pin_a_y",
                "pin_b_x",
                "pin_b_y",
                "guide_y",
                "guide_phi",
                "driver",
            ],
            nonholonomic: &[],
            time: TimeDependence {
                holonomic: true,
                ..TimeDependence::default()
            },
            homogeneous: true,
            // The driver does work: T + V is not conserved.
            conservative: false,
            q0: &Q0,
            qd0: &QD0,
        },
    );
}

#[test]
fn derivatives() {
    sweep(
        "slider_crank",
        0x5eed_0004,
        Model::default,
        |m| reference(&m.params),
        |rng| {
            let mut q = rng.vec(9, -0.5, 0.5);
            for i in [2, 5, 8] {
                q[i] = rng.range(-PI, PI);
            }
            State {
                t: rng.range(0.0, 1.0),
                q,
                qd: rng.vec(9, -2.0, 2.0),
            }
        },
    );
}

/// docs/theory.md V10 at t = 0: the default state satisfies the constraints at position and
/// velocity level, and the velocities and accelerations solved from the generated
/// `C_q q̇ = −C_t`, `C_q q̈ = γ_h` reproduce the table (1e-9 relative, the docs/theory.md
/// tolerance for algebraic results; the table has 12 decimals).
#[test]
fn v10_kinematics() {
    let model = Model::default();
    let (mut q, mut qd) = ([0.0; 9], [0.0; 9]);
    model.initial_state(&mut q, &mut qd);
    let mut c = [f64::NAN; 9];
    model.holonomic(0.0, &q, &mut c);
    assert!(max_abs(&c) < 1e-15, "C(q0) = {c:?}");

    let mut values = vec![f64::NAN; INFO.holonomic_pattern.len()];
    model.holonomic_jacobian(0.0, &q, &mut values);
    let cq = dense(INFO.holonomic_pattern, &values, 9, 9);
    let mut ct = [f64::NAN; 9];
    model.holonomic_rate(0.0, &q, &mut ct);
    let velocity = solve(&cq, &ct.map(|v| -v));
    let mut gamma = [f64::NAN; 9];
    model.holonomic_gamma(0.0, &q, &velocity, &mut gamma);
    let acceleration = solve(&cq, &gamma);

    // docs/theory.md V10 table.
    let table_qd = [
        -0.25,
        0.433_012_701_892,
        10.0,
        -0.573_192_505_471,
        0.433_012_701_892,
        -2.927_700_218_846,
        -0.646_385_010_942,
        0.0,
        0.0,
    ];
    let table_qdd = [
        -4.330_127_018_922,
        -2.5,
        0.0,
        -9.541_629_189_204,
        -2.5,
        15.454_249_229_321,
        -10.423_004_340_564,
        0.0,
        0.0,
    ];
    let rel = |x: &[f64], y: &[f64]| max_diff(x, y) / max_abs(y);
    println!(
        "slider_crank V10: |C(q0)| {:.1e}, q̇ vs defaults {:.1e}, q̇ vs table {:.1e}, q̈ vs table {:.1e}",
        max_abs(&c),
        rel(&velocity, &qd),
        rel(&velocity, &table_qd),
        rel(&acceleration, &table_qdd)
    );
    assert!(
        rel(&velocity, &qd) < 1e-14,
        "q̇ {velocity:?} vs defaults {qd:?}"
    );
    assert!(rel(&velocity, &table_qd) < 1e-9, "q̇ {velocity:?}");
    assert!(rel(&acceleration, &table_qdd) < 1e-9, "q̈ {acceleration:?}");
}
