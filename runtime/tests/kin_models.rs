//! The hand-written test models: derivatives against finite differences, and the
//! extension trait's conveniences.

mod common;

use common::{Chain, Pendulum, Sleigh, SliderCrank};
use pfaff::{Mechanism, MechanismExt};

fn assert_derivatives<M: Mechanism>(mech: &M, t: f64, q: &[f64], qd: &[f64]) {
    let c = mech.check_derivatives(t, q, qd);
    let name = mech.info().name;
    assert!(c.holonomic_jacobian < 1e-8, "{name}: C_q {c:?}");
    assert!(c.holonomic_rate < 1e-8, "{name}: C_t {c:?}");
    assert!(c.holonomic_gamma < 1e-5, "{name}: gamma_h {c:?}");
    assert!(c.nonholonomic_gamma < 1e-8, "{name}: gamma_nh {c:?}");
    assert!(c.mass_matrix < 1e-6, "{name}: M {c:?}");
}

#[test]
fn hand_derivatives_match_finite_differences() {
    let q9 = [0.1, -0.2, 0.7, 0.3, 0.05, -0.4, 0.5, 0.02, 0.03];
    let qd9 = [0.3, -1.0, 2.0, 0.5, 0.4, -3.0, 1.0, 0.2, -0.1];
    assert_derivatives(&SliderCrank::new(true), 0.3, &q9, &qd9);
    assert_derivatives(&SliderCrank::new(false), 0.3, &q9, &qd9);
    assert_derivatives(
        &Sleigh::default(),
        0.0,
        &[0.2, -0.1, 0.9],
        &[1.0, 0.3, -0.5],
    );
    assert_derivatives(&Pendulum::new(false), 0.0, &[0.3, -0.8], &[1.0, 0.2]);
    assert_derivatives(&Pendulum::new(true), 0.0, &[0.3, -0.8], &[1.0, 0.2]);
    let chain = Chain::new(6);
    let (q, qd) = chain.state();
    let q: Vec<f64> = q
        .iter()
        .enumerate()
        .map(|(i, v)| v + 0.01 * i as f64)
        .collect();
    assert_derivatives(&chain, 0.0, &q, &qd);
}

#[test]
fn energy_residuals_and_dense_matrices() {
    let p = Pendulum::new(false);
    let (q, qd) = ([0.6, -0.8], [0.8, 0.6]);
    assert!((p.energy(0.0, &q, &qd) - (0.5 - 0.8 * common::G)).abs() < 1e-14);
    let r = p.residuals(0.0, &q, &qd);
    assert!(r.position < 1e-15 && r.velocity < 1e-15 && r.nonholonomic == 0.0);
    let r = p.residuals(0.0, &[1.0, 1.0], &[1.0, 0.0]);
    assert!((r.position - 1.0).abs() < 1e-15 && (r.velocity - 2.0).abs() < 1e-15);
    let mut jac = [0.0; 4];
    Pendulum::new(true).holonomic_jacobian_dense_inplace(0.0, &q, &mut jac);
    assert_eq!(jac, [1.2, -1.6, 1.2, -1.6]);
    let s = Sleigh::default();
    let r = s.residuals(0.0, &[0.0; 3], &[1.0, 0.15, 0.5]);
    assert!(r.nonholonomic < 1e-15);
    let mut g = [0.0; 3];
    s.nonholonomic_matrix_dense_inplace(0.0, &[0.0; 3], &mut g);
    assert_eq!(g, [-0.0, 1.0, -0.3]);
    let mut m = [0.0; 9];
    s.mass_matrix_dense_inplace(0.0, &[0.0; 3], &mut m);
    assert_eq!(m, [2.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.05]);
}

#[test]
fn malformed_patterns_are_rejected() {
    static BAD: pfaff::Info = pfaff::Info {
        name: "bad",
        doc: "",
        coordinates: &[
            pfaff::Symbol { name: "x", doc: "" },
            pfaff::Symbol { name: "y", doc: "" },
        ],
        parameters: &[],
        holonomic: &[pfaff::Symbol { name: "c", doc: "" }],
        nonholonomic: &[],
        mass_pattern: &[(1, 1), (0, 0)],
        holonomic_pattern: &[(0, 0), (0, 2)],
        nonholonomic_pattern: &[],
        time: pfaff::TimeDependence {
            mass: false,
            forces: false,
            holonomic: false,
            nonholonomic: false,
        },
        nonholonomic_homogeneous: true,
        conservative: true,
        ..pfaff::Info::EMPTY
    };
    let err = pfaff::Workspace::new(&BAD).unwrap_err();
    println!("{err}");
    assert!(matches!(
        err,
        pfaff::EvalError::Pattern {
            entry: 1,
            reason: pfaff::PatternDefect::Unsorted,
            ..
        }
    ));
}
