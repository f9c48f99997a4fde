//! V10: kinematics of the planar slider-crank with partitioning (Algorithms P and K).

mod common;

use std::f64::consts::FRAC_PI_6;

use common::SliderCrank;
use pfaff::{
    Dynamics, DynamicsParams, Kinematics, KinematicsParams, LinearSolver, Mechanism, MechanismExt,
    Preferences, Prescription, SolverPath, Workspace,
};

#[allow(clippy::approx_constant)] // the table of docs/theory.md V10, verbatim
const Q: [f64; 9] = [
    0.043301270189,
    0.025,
    0.523598775598,
    0.234504534956,
    0.025,
    -0.167448079220,
    0.382406529533,
    0.0,
    0.0,
];
const QD: [f64; 9] = [
    -0.25,
    0.433012701892,
    10.0,
    -0.573192505471,
    0.433012701892,
    -2.927700218846,
    -0.646385010942,
    0.0,
    0.0,
];
const QDD: [f64; 9] = [
    -4.330127018922,
    -2.5,
    0.0,
    -9.541629189204,
    -2.5,
    15.454249229321,
    -10.423004340564,
    0.0,
    0.0,
];

fn assert_close(got: &[f64], want: &[f64], tol: f64, what: &str) {
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(
            (g - w).abs() <= tol * (1.0 + w.abs()),
            "{what}[{i}]: got {g}, want {w}"
        );
    }
}

fn perturbed_guess() -> ([f64; 9], [f64; 9]) {
    let mut q = Q;
    for (i, v) in q.iter_mut().enumerate() {
        if i != 2 {
            *v += if i % 2 == 0 { 0.01 } else { -0.01 };
        }
    }
    (q, [0.0; 9])
}

#[test]
fn v10_assembly_from_perturbed_guess_converges_quadratically() {
    let mech = SliderCrank::new(false);
    let info = mech.info();
    let mut ws = Workspace::new(info).unwrap();
    let mut kin = Kinematics::new(info, KinematicsParams::default());
    let (mut q, mut qd) = perturbed_guess();
    let report = kin
        .assemble(
            &mech,
            &mut ws,
            0.0,
            &mut q,
            &mut qd,
            &Prescription {
                coordinates: &[("phi1", FRAC_PI_6)],
                velocities: &[("phi1", 10.0)],
            },
        )
        .unwrap();
    let hist = kin.residual_history().to_vec();
    println!("V10 Newton: {report:?}\n  residual history {hist:?}");
    assert_eq!(report.newton.iterations, 4);
    assert!(report.newton.residual < 1e-15);
    // Quadratic convergence: r_{k+1} ≤ K r_k² while above round-off.
    for w in hist.windows(2) {
        if w[1] > 1e-14 {
            assert!(w[1] <= 20.0 * w[0] * w[0], "not quadratic: {hist:?}");
        }
    }
    assert_close(&q, &Q, 1e-10, "q");
    assert_close(&qd, &QD, 1e-10, "qd");
    assert!(report.velocity_residual < 1e-13);
    let p = kin.partition().unwrap();
    assert_eq!(p.dependent().len(), 8);
    assert_eq!(p.independent(), &[2]);
    // |det C_β| at the solution (the check run reports 0.2958).
    let at_solution = pfaff::Partition::compute(
        &mech,
        &mut ws,
        0.0,
        &q,
        Preferences {
            coordinates: &[2],
            velocities: &[],
        },
        &Default::default(),
    )
    .unwrap();
    println!("  |det C_beta| = {}", at_solution.abs_det_dependent());
    assert!((at_solution.abs_det_dependent() - 0.2958).abs() < 5e-4);
}

#[test]
fn v10_driven_velocities_and_accelerations() {
    let mech = SliderCrank::new(true);
    let info = mech.info();
    let mut ws = Workspace::new(info).unwrap();
    let mut kin = Kinematics::new(info, KinematicsParams::default());
    let (mut q, mut qd) = perturbed_guess();
    q[2] += 0.01; // the driver now fixes phi1 too
    let report = kin
        .assemble(
            &mech,
            &mut ws,
            0.0,
            &mut q,
            &mut qd,
            &Prescription::default(),
        )
        .unwrap();
    println!("V10 driven assembly: {report:?}");
    assert_eq!(kin.partition().unwrap().dependent().len(), 9);
    assert_close(&q, &Q, 1e-10, "q");
    assert_close(&qd, &QD, 1e-10, "qd");
    let (mut qdd, mut lambda) = ([0.0; 9], [0.0; 9]);
    for (solver, path) in [
        (LinearSolver::Dense, SolverPath::Dense),
        (LinearSolver::SparseLu, SolverPath::Sparse),
        (LinearSolver::Sparse, SolverPath::SparseLdlt),
    ] {
        let params = DynamicsParams {
            solver,
            ..Default::default()
        };
        let mut dynamics = Dynamics::new(info, params).unwrap();
        let stats = dynamics
            .accelerations(&mech, &mut ws, 0.0, &q, &qd, &mut qdd, &mut lambda)
            .unwrap();
        assert_eq!(stats.path, path);
        assert_close(&qdd, &QDD, 1e-9, "qdd");
    }
    // The multipliers balance the equations of motion: M q̈ + C_qᵀ λ = Q.
    let mut jac = vec![0.0; 81];
    mech.holonomic_jacobian_dense_inplace(0.0, &q, &mut jac);
    let mut f = [0.0; 9];
    mech.forces(0.0, &q, &qd, &mut f);
    for j in 0..9 {
        let jt: f64 = (0..9).map(|i| jac[i * 9 + j] * lambda[i]).sum();
        assert!((mech.mass[j] * qdd[j] + jt - f[j]).abs() < 1e-12);
    }
}

#[test]
fn v10_analytic_slider_position() {
    let mech = SliderCrank::new(false);
    let info = mech.info();
    let mut ws = Workspace::new(info).unwrap();
    let mut kin = Kinematics::new(info, KinematicsParams::default());
    let mut q = Q;
    let mut qd = QD;
    kin.assemble(
        &mech,
        &mut ws,
        0.0,
        &mut q,
        &mut qd,
        &Prescription {
            coordinates: &[("phi1", FRAC_PI_6)],
            velocities: &[],
        },
    )
    .unwrap();
    let (a, b) = (mech.a, mech.b);
    for k in 1..=20 {
        // Small steps of the independent coordinate, K1 from the previous solution.
        let phi = FRAC_PI_6 + 0.05 * f64::from(k);
        q[2] = phi;
        let stats = kin.position(&mech, &mut ws, 0.0, &mut q).unwrap();
        let xb = a * phi.cos() + (b * b - a * a * phi.sin().powi(2)).sqrt();
        assert!((q[6] - xb).abs() < 1e-12, "phi {phi}: {} vs {xb}", q[6]);
        assert!(stats.iterations <= 5);
    }
}

#[test]
fn dead_centre_triggers_repartition() {
    let mech = SliderCrank::new(false);
    let info = mech.info();
    let mut ws = Workspace::new(info).unwrap();
    let mut kin = Kinematics::new(info, KinematicsParams::default());
    // Drive by the slider: keep x3 independent at phi1 = 1.
    let mut q = mech.configuration(1.0);
    let mut qd = [0.0; 9];
    let x3 = q[6];
    kin.assemble(
        &mech,
        &mut ws,
        0.0,
        &mut q,
        &mut qd,
        &Prescription {
            coordinates: &[("x3", x3)],
            velocities: &[],
        },
    )
    .unwrap();
    assert_eq!(kin.partition().unwrap().independent(), &[6]);
    let reference = kin.partition().unwrap().reference_condition();
    // Away from the dead centre the monitor stays quiet.
    let q_mid = mech.configuration(0.5);
    assert!(!kin.monitor(&mech, &mut ws, 0.0, &q_mid).unwrap());
    // At the dead centre x3 cannot determine phi1.
    let q_dead = mech.configuration(1e-7);
    let now = kin.condition(&mech, &mut ws, 0.0, &q_dead).unwrap();
    println!("dead centre: reference {reference:?}, now {now:?}");
    assert!(now.holonomic < 1e-3 * reference.holonomic);
    assert!(kin.monitor(&mech, &mut ws, 0.0, &q_dead).unwrap());
    assert_eq!(kin.repartitions(), 1);
    let p = kin.partition().unwrap();
    assert!(p.dependent().contains(&6), "x3 must become dependent");
    let after = kin.condition(&mech, &mut ws, 0.0, &q_dead).unwrap();
    assert!(after.holonomic > 1e-3);
}

#[test]
fn impossible_prescription_names_coordinate_and_constraints() {
    let mech = SliderCrank::new(false);
    let info = mech.info();
    let mut ws = Workspace::new(info).unwrap();
    let mut kin = Kinematics::new(info, KinematicsParams::default());
    let (mut q, mut qd) = (Q, QD);
    let err = kin
        .assemble(
            &mech,
            &mut ws,
            0.0,
            &mut q,
            &mut qd,
            &Prescription {
                coordinates: &[("y3", 0.1)],
                velocities: &[],
            },
        )
        .unwrap_err();
    println!("{err}");
    match err {
        pfaff::AssemblyError::Partition(pfaff::PartitionError::PrescribedCoordinate {
            coordinate,
            constraints,
            ..
        }) => {
            assert_eq!(coordinate, "y3");
            assert!(constraints.contains(&"slider_y"));
        }
        other => panic!("unexpected {other:?}"),
    }
    // Two independent velocities on a one-degree-of-freedom mechanism.
    let err = kin
        .assemble(
            &mech,
            &mut ws,
            0.0,
            &mut q,
            &mut qd,
            &Prescription {
                coordinates: &[],
                velocities: &[("phi1", 10.0), ("x3", 1.0)],
            },
        )
        .unwrap_err();
    println!("{err}");
    assert!(matches!(
        err,
        pfaff::AssemblyError::Partition(pfaff::PartitionError::PrescribedVelocity { .. })
    ));
}
