//! V11: the Chaplygin sleigh (non-holonomic partition and augmented solve).

mod common;

use common::Sleigh;
use pfaff::{
    Dynamics, DynamicsParams, Kinematics, KinematicsParams, Mechanism, MechanismExt, Prescription,
    SolverPath, Workspace,
};

#[test]
fn v11_partition_at_zero_heading() {
    let mech = Sleigh::default();
    let mut ws = Workspace::new(mech.info()).unwrap();
    let mut kin = Kinematics::new(mech.info(), KinematicsParams::default());
    let p = kin.repartition(&mech, &mut ws, 0.0, &[0.0; 3]).unwrap();
    let [beta, eta, gamma] = p.names();
    assert!(beta.is_empty());
    assert_eq!(eta, ["y"]);
    assert_eq!(gamma.len(), 2);
    assert!(gamma.contains(&"x") && gamma.contains(&"phi"));
    // K2: y' from the knife edge.
    let mut qd = [1.0, 0.0, 0.5];
    kin.velocity(&mech, &mut ws, 0.0, &[0.0; 3], &mut qd)
        .unwrap();
    assert!((qd[1] - 0.15).abs() < 1e-15);
}

#[test]
fn v11_accelerations_match_the_closed_form() {
    let mech = Sleigh::default();
    let mut ws = Workspace::new(mech.info()).unwrap();
    let mut dynamics = Dynamics::new(mech.info(), DynamicsParams::default()).unwrap();
    let (m, a, j) = (mech.m, mech.a, mech.jc + mech.m * mech.a * mech.a);
    for &phi in &[0.0, 0.5, std::f64::consts::FRAC_PI_6, 2.0] {
        let (v, w) = (1.0, 0.5);
        let q = [0.3, -0.2, phi];
        let qd = [
            v * phi.cos() - a * w * phi.sin(),
            v * phi.sin() + a * w * phi.cos(),
            w,
        ];
        let (mut qdd, mut lambda) = ([0.0; 3], [0.0; 1]);
        let stats = dynamics
            .accelerations(&mech, &mut ws, 0.0, &q, &qd, &mut qdd, &mut lambda)
            .unwrap();
        assert_eq!(stats.path, SolverPath::Dense);
        // v̇ = cos φ ẍ + sin φ ÿ + (lateral velocity) ω, with lateral velocity a ω.
        let vdot = phi.cos() * qdd[0] + phi.sin() * qdd[1] + a * w * w;
        assert!((vdot - a * w * w).abs() < 1e-12, "vdot {vdot}");
        assert!(
            (qdd[2] + m * a * v * w / j).abs() < 1e-12,
            "wdot {}",
            qdd[2]
        );
        // V16: λ_nh = −0.2173913043 for this body-frame state.
        assert!(
            (lambda[0] + 0.217_391_304_3).abs() < 1e-9,
            "lambda {}",
            lambda[0]
        );
    }
}

/// Fixed-step RK4 on (q, q̇) with accelerations from the augmented solve, against the
/// closed form of V11 at t = 1 and t = 2.
#[test]
fn v11_motion_from_augmented_accelerations() {
    let mech = Sleigh::default();
    let info = mech.info();
    let mut ws = Workspace::new(info).unwrap();
    let mut kin = Kinematics::new(info, KinematicsParams::default());
    let mut dynamics = Dynamics::new(info, DynamicsParams::default()).unwrap();
    let (mut q, mut qd) = ([0.0; 3], [1.0, 0.0, 0.0]);
    kin.assemble(
        &mech,
        &mut ws,
        0.0,
        &mut q,
        &mut qd,
        &Prescription {
            coordinates: &[],
            velocities: &[("x", 1.0), ("phi", 0.5)],
        },
    )
    .unwrap();
    assert_eq!(qd, [1.0, 0.15, 0.5]);
    let e0 = mech.energy(0.0, &q, &qd);
    assert!((e0 - 1.02875).abs() < 1e-14);
    let mut f = |y: &[f64; 6]| -> [f64; 6] {
        let (mut qdd, mut l) = ([0.0; 3], [0.0; 1]);
        dynamics
            .accelerations(&mech, &mut ws, 0.0, &y[..3], &y[3..], &mut qdd, &mut l)
            .unwrap();
        [y[3], y[4], y[5], qdd[0], qdd[1], qdd[2]]
    };
    let mut y = [q[0], q[1], q[2], qd[0], qd[1], qd[2]];
    let h = 1e-3;
    let expected = [
        (1.0, 1.014_200_804_33, 0.176_360_706_663),
        (2.0, 1.014_272_774_73, 0.188_903_202_544),
    ];
    let mut step = 0;
    for &(t_end, v_ref, phi_ref) in &expected {
        while (step as f64) * h < t_end - 1e-12 {
            let k1 = f(&y);
            let add = |y: &[f64; 6], k: &[f64; 6], s: f64| -> [f64; 6] {
                std::array::from_fn(|i| y[i] + s * k[i])
            };
            let k2 = f(&add(&y, &k1, h / 2.0));
            let k3 = f(&add(&y, &k2, h / 2.0));
            let k4 = f(&add(&y, &k3, h));
            y = std::array::from_fn(|i| {
                y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
            step += 1;
        }
        let v = y[2].cos() * y[3] + y[2].sin() * y[4];
        println!(
            "t = {t_end}: v = {v} (ref {v_ref}), phi = {} (ref {phi_ref})",
            y[2]
        );
        assert!((v - v_ref).abs() < 1e-9);
        assert!((y[2] - phi_ref).abs() < 1e-9);
        let r = mech.residuals(0.0, &y[..3], &y[3..]);
        assert!(r.nonholonomic < 1e-9);
        assert!((mech.energy(0.0, &y[..3], &y[3..]) - e0).abs() < 1e-9);
    }
}
