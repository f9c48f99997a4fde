//! The impulse solve (docs/theory.md §impulse-solve, Algorithm I-solve) on the verification cases
//! V13–V16 of docs/theory.md §verification: the augmented form (E41) and the partitioned form (E42)
//! against the published numbers to 1e-9, and against each other.

use pfaff::{Impact, ImpactError, ImpactSolver, Mechanism, MechanismExt};
use pfaff_models::{body_impact, pendulum_floor, sleigh_wall, two_body_impact};

use crate::accuracy::util::Rng;

const TOL: f64 = 1e-9;

fn close(what: &str, got: f64, want: f64) {
    assert!(
        (got - want).abs() <= TOL,
        "{what}: {got} against {want} (difference {:e})",
        got - want
    );
}

fn close_all(what: &str, got: &[f64], want: &[f64]) {
    assert_eq!(got.len(), want.len(), "{what}: lengths");
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        close(&format!("{what}[{i}]"), *g, *w);
    }
}

/// Both forms at the model's default state (the impact instant of its case), checked
/// to agree with each other to 1e-12.
fn both(model: &dyn Mechanism) -> (Impact, Impact) {
    let info = model.info();
    let n = info.nq();
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q, &mut qd);
    let gaps = {
        let mut g = vec![0.0; info.ncontacts()];
        model.contact_gaps(0.0, &q, &mut g);
        g
    };
    assert!(
        gaps[0].abs() < 1e-14,
        "{}: the default state touches: {gaps:?}",
        info.name
    );
    let mut solver = ImpactSolver::new(info).expect("solver");
    let a = solver.solve(model, 0.0, &q, &qd, &[0]).expect("augmented");
    let p = solver
        .solve_partitioned(model, 0.0, &q, &qd, &[0])
        .expect("partitioned");
    let agree = |what: &str, x: &[f64], y: &[f64]| {
        for (u, v) in x.iter().zip(y) {
            assert!(
                (u - v).abs() < 1e-12,
                "{}: {what} {x:?} against {y:?}",
                info.name
            );
        }
    };
    agree("q'+", &a.qd_after, &p.qd_after);
    agree("impulse", &a.impulses, &p.impulses);
    agree("Lambda", &a.constraint_impulses, &p.constraint_impulses);
    agree("lambda+", &a.lambda_after, &p.lambda_after);
    (a, p)
}

#[test]
fn v13_single_free_body() {
    let model = body_impact::Model::default();
    let (a, _) = both(&model);
    close("P", a.impulses[0], 1.95 * 6.5 / 51.0);
    close("P (printed)", a.impulses[0], 0.248_529_411_765);
    close_all(
        "q'+",
        &a.qd_after,
        &[0.0, -6.251_470_588_235, 17.573_683_238_312],
    );
    close("v_n-", a.normal_velocity_before[0], -6.5);
    close("v_n+", a.normal_velocity_after[0], 6.175);
    close("T-", a.kinetic_before, 21.125);
    close("T+", a.kinetic_after, 21.084_613_970_588);
    // ½(1 − e²) m_eff v_n² with m_eff = 1/51.
    close(
        "energy lost",
        a.energy_lost(),
        0.5 * (1.0 - 0.95_f64.powi(2)) / 51.0 * 6.5 * 6.5,
    );
}

#[test]
fn v14_two_free_bodies() {
    let model = two_body_impact::Model::default();
    let (a, _) = both(&model);
    close("v_n-", a.normal_velocity_before[0], -2.0);
    close("v_n+", a.normal_velocity_after[0], 1.6);
    close("P", a.impulses[0], 0.732_203_389_831);
    close_all(
        "q'+",
        &a.qd_after,
        &[
            0.535_593_220_339,
            1.0,
            0.5,
            1.220_338_983_051,
            -1.0,
            -3.661_016_949_153,
        ],
    );
    close("T-", a.kinetic_before, 1.550_312_5);
    close("T+", a.kinetic_after, 1.403_871_822_034);
}

#[test]
fn v15_holonomic_constraints_and_impulsive_joint_reactions() {
    let model = pendulum_floor::Model::default();
    let info = model.info();
    let (a, _) = both(&model);
    let s3 = 3.0_f64.sqrt();
    close("P", a.impulses[0], 165.0 / 104.0);
    close_all(
        "q'+",
        &a.qd_after,
        &[
            11.0 * s3 / 208.0,
            11.0 / 208.0,
            11.0 / 52.0,
            -45.0 * s3 / 208.0,
            89.0 / 208.0,
            -67.0 / 52.0,
        ],
    );
    close_all(
        "Lambda_h",
        &a.constraint_impulses,
        &[
            -0.149_889_012_2,
            -0.144_230_769_2,
            -0.374_722_530_5,
            -0.158_653_846_2,
        ],
    );
    close(
        "Lambda by name",
        a.constraint_impulse(info, "joint_x").unwrap(),
        -0.374_722_530_5,
    );
    close("v_n+", a.normal_velocity_after[0], 0.75);
    close("T-", a.kinetic_before, 0.833_333_333_3);
    close("T+", a.kinetic_after, 0.238_381_410_3);
    // J q'+ = 0.
    let r = model.residuals(0.0, &a.q, &a.qd_after);
    assert!(r.velocity < 1e-14, "J q'+ = {:e}", r.velocity);
}

/// V15's augmented ≡ embedded check: the same impact solved in the joint coordinates
/// (φ1, φ2) gives φ'+ = (11/52, −67/52) and the same impulse.
#[pfaff::mechanism]
pub mod double_pendulum_joint {
    const e: f64 = 0.5;
    const depth: f64 = 2.0 * FRAC_PI_3.sin();
    static phi1: Coordinate = Coordinate {
        q0: -FRAC_PI_3,
        qd0: -1.0,
    };
    static phi2: Coordinate = Coordinate {
        q0: -2.0 * FRAC_PI_3,
        qd0: 2.0,
    };
    fn kinetic_energy() -> f64 {
        // Rod 1 about its pivot: ½ (1/3) φ1'²; rod 2: centre velocity and spin.
        let x2d = -phi1.sin() * phi1.dot() - 0.5 * phi2.sin() * phi2.dot();
        let y2d = phi1.cos() * phi1.dot() + 0.5 * phi2.cos() * phi2.dot();
        phi1.dot().powi(2) / 6.0 + 0.5 * (x2d.powi(2) + y2d.powi(2)) + phi2.dot().powi(2) / 24.0
    }
    /// The tip above the floor.
    #[contact(e)]
    fn floor() -> f64 {
        phi1.sin() + phi2.sin() + depth
    }
}

#[test]
fn v15_in_joint_coordinates() {
    let model = double_pendulum_joint::Model::default();
    let (a, _) = both(&model);
    close("P", a.impulses[0], 165.0 / 104.0);
    close_all("phi'+", &a.qd_after, &[11.0 / 52.0, -67.0 / 52.0]);
    close("T+", a.kinetic_after, 0.238_381_410_3);
}

#[test]
fn v16_nonholonomic_constraint_and_the_jump_of_its_reaction() {
    let model = sleigh_wall::Model::default();
    let info = model.info();
    let (a, _) = both(&model);
    close("v_n-", a.normal_velocity_before[0], -0.691_025_403_784);
    close("P", a.impulses[0], 1.370_464_752_9);
    close("Lambda_nh", a.constraint_impulses[0], -0.566_061_528_4);
    close(
        "Lambda by name",
        a.constraint_impulse(info, "blade").unwrap(),
        -0.566_061_528_4,
    );
    close_all(
        "q'+",
        &a.qd_after,
        &[-0.035_722_354_8, 0.875_015_642_4, 2.585_489_841_4],
    );
    close("v_n+", a.normal_velocity_after[0], 0.552_820_323_0);
    close("T-", a.kinetic_before, 1.028_75);
    close("T+", a.kinetic_after, 0.934_047_404_1);
    close("lambda_nh-", a.lambda_before[0], -0.217_391_304_3);
    close("lambda_nh+", a.lambda_after[0], -0.457_037_437_8);
    close("jump", a.multiplier_jump()[0], -0.239_646_133_4);
    close_all(
        "q''-",
        &a.qdd_before,
        &[-0.054_347_826_1, 0.094_133_196_1, -1.304_347_826_1],
    );
    close_all(
        "q''+",
        &a.qdd_after,
        &[-0.114_259_359_4, 0.197_903_015_8, -2.742_224_626_6],
    );
    // G q'+ = 0.
    let r = model.residuals(0.0, &a.q, &a.qd_after);
    assert!(r.nonholonomic < 1e-14, "G q'+ = {:e}", r.nonholonomic);
}

/// Energy never increases across an impact, e = 1 conserves it, e = 0 leaves the
/// contact at rest, and the loss is the effective-mass formula ½(1 − e²) m_eff v_n²
/// (docs/theory.md §impulse-solve, with m_eff from the impulse: P = (1 + e) m_eff |v_n|).
#[test]
fn energy_balance_over_random_impacts() {
    let mut rng = Rng::new(7);
    let models: Vec<Box<dyn Mechanism>> = vec![
        Box::new(body_impact::Model::default()),
        Box::new(two_body_impact::Model::default()),
        Box::new(pendulum_floor::Model::default()),
        Box::new(sleigh_wall::Model::default()),
    ];
    for mut model in models {
        let info = model.info();
        let n = info.nq();
        let (mut q, mut qd0) = (vec![0.0; n], vec![0.0; n]);
        model.initial_state(&mut q, &mut qd0);
        let e_index = info.contacts[0].restitution as usize;
        let mut solver = ImpactSolver::new(info).expect("solver");
        for k in 0..24 {
            let e = match k % 4 {
                0 => 0.0,
                1 => 1.0,
                _ => rng.uniform(),
            };
            model.set_parameter(e_index, e);
            // A consistent velocity: the default one scaled and pushed along the
            // null space by the solve itself (an impact with a random e from it).
            let scale = rng.range(0.2, 3.0);
            let qd: Vec<f64> = qd0.iter().map(|v| v * scale).collect();
            let a = solver.solve(&*model, 0.0, &q, &qd, &[0]).expect("solve");
            let t = a.kinetic_before;
            assert!(
                a.energy_lost() >= -1e-13 * t,
                "{} e = {e}: energy gained {:e}",
                info.name,
                -a.energy_lost()
            );
            let vn = a.normal_velocity_before[0];
            assert!(vn < 0.0 && a.impulses[0] > 0.0);
            let m_eff = a.impulses[0] / ((1.0 + e) * -vn);
            let expected = 0.5 * (1.0 - e * e) * m_eff * vn * vn;
            assert!(
                (a.energy_lost() - expected).abs() < 1e-12 * t,
                "{}: loss {} against {expected}",
                info.name,
                a.energy_lost()
            );
            if e == 1.0 {
                assert!(a.energy_lost().abs() < 1e-12 * t);
            }
            if e == 0.0 {
                assert!(a.normal_velocity_after[0].abs() < 1e-12 * -vn);
            }
            let p = solver
                .solve_partitioned(&*model, 0.0, &q, &qd, &[0])
                .expect("E42");
            for (u, v) in a.qd_after.iter().zip(&p.qd_after) {
                assert!((u - v).abs() < 1e-12 * (1.0 + u.abs()));
            }
        }
    }
}

/// With both rods hanging straight down, the tip can only move sideways: the contact
/// normal is a combination of the pins' rows, the impulses are not determined, and the
/// solve says which rows are dependent.
#[test]
fn singular_configuration_is_a_typed_error_naming_the_constraints() {
    let mut model = pendulum_floor::Model::default();
    let info = model.info();
    model.set_parameter(info.parameter_index("depth").unwrap(), 2.0);
    let h = -std::f64::consts::FRAC_PI_2;
    let q = [0.0, -0.5, h, 0.0, -1.5, h];
    let qd = [0.0; 6];
    let mut solver = ImpactSolver::new(info).expect("solver");
    for r in [
        solver.solve(&model, 0.0, &q, &qd, &[0]),
        solver.solve_partitioned(&model, 0.0, &q, &qd, &[0]),
    ] {
        match r {
            Err(ImpactError::Singular { constraints, .. }) => {
                assert!(constraints.contains(&"floor"), "{constraints:?}");
                assert!(constraints.contains(&"pin_y"), "{constraints:?}");
                assert!(constraints.contains(&"joint_y"), "{constraints:?}");
                assert!(!constraints.contains(&"pin_x"), "{constraints:?}");
            }
            other => panic!("expected a singular impact, got {other:?}"),
        }
    }
}
