//! The inverse problems of docs/theory.md §free-motion and §free-motion-analysis step 3: applied forces that make a
//! motion free (minimum norm, would-be constraint forces, chosen components, and the
//! report when the components cannot do it), and the member of a family of constraints
//! that makes it free.

use pfaff::free_motion::{ForceDesign, ParameterSearch, Sample};
use pfaff::{
    AppliedForces, FreeMotion, FreeMotionError, FreeMotionParams, FreeMotionPoint, Mechanism,
    MechanismExt, Workspace,
};
use pfaff_models::{seed2_example1 as ex1, seed2_example2 as ex2};

use super::models::{plane_family, v5};
use super::sim::simulate;
use super::{designed, inf_norm, Rng};

/// On V5 (two constraints, full inertia): both designs zero the residual, the
/// minimum-norm one is the shorter, and they differ by a force in ker K that does not
/// act on the constraints.
#[test]
#[allow(non_snake_case)]
fn force_designs_on_v5() {
    let model = v5::Model::default();
    let mut ws = Workspace::new(&v5::INFO).unwrap();
    let mut fm = FreeMotion::new(&v5::INFO, FreeMotionParams::default());
    let (t, q, qd) = (0.7, [0.3, -0.2, 0.5], [0.1, 0.4, -0.3]);
    let min = fm
        .free_forces(&model, &mut ws, t, &q, &qd, ForceDesign::MinimumNorm)
        .unwrap();
    let cf = fm
        .free_forces(&model, &mut ws, t, &q, &qd, ForceDesign::ConstraintForces)
        .unwrap();
    assert!(min.exact && cf.exact && min.rank == 2 && cf.rank == 2);
    let mut p = FreeMotionPoint::new(&v5::INFO);
    for s in [&min, &cf] {
        fm.evaluate(
            &model,
            &mut ws,
            t,
            &q,
            &qd,
            AppliedForces::Replaced(&s.applied),
            &mut p,
        )
        .unwrap();
        assert!(p.max_residual() < 1e-15, "w = {:?}", p.residual);
        assert!(inf_norm(&p.lambda_s2) < 1e-14);
    }
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    assert!(norm(&min.applied) <= norm(&cf.applied));
    let K = p.K.clone();
    let diff: Vec<f64> = min
        .applied
        .iter()
        .zip(&cf.applied)
        .map(|(a, b)| a - b)
        .collect();
    for b in 0..2 {
        let kd: f64 = (0..3).map(|s| K[b * 3 + s] * diff[s]).sum();
        assert!(kd.abs() < 1e-15);
    }
    // Two components for two conditions: exact; one component: least squares, reported.
    let two = fm
        .free_forces(
            &model,
            &mut ws,
            t,
            &q,
            &qd,
            ForceDesign::Components(&[0, 2]),
        )
        .unwrap();
    assert!(two.exact && two.applied[1] == 0.0);
    let one = fm
        .free_forces(&model, &mut ws, t, &q, &qd, ForceDesign::Components(&[1]))
        .unwrap();
    assert!(
        !one.exact && one.rank == 1 && one.residual > 1e-3,
        "{one:?}"
    );
    println!(
        "V5 designs: |Q| minimum norm {:.6}, constraint forces {:.6}; Q on q2 alone leaves |w| = {:.3e}",
        norm(&min.applied),
        norm(&cf.applied),
        one.residual
    );
    assert!(matches!(
        fm.free_forces(&model, &mut ws, t, &q, &qd, ForceDesign::Components(&[3])),
        Err(FreeMotionError::Component { index: 3, n: 3, .. })
    ));
}

/// Example 2 at t = 0: the force on q1 enters w with t²/(2 + sin t) = 0, so it cannot
/// make the motion free there; the design says so and leaves |w| = |2 q1|.
#[test]
fn unsolvable_component_is_reported() {
    let model = ex2::Model::default();
    let mut ws = Workspace::new(&ex2::INFO).unwrap();
    let mut fm = FreeMotion::new(&ex2::INFO, FreeMotionParams::default());
    let s = fm
        .free_forces(
            &model,
            &mut ws,
            0.0,
            &[0.8, 0.0, 0.0],
            &[0.3, 0.0, 0.0],
            ForceDesign::Components(&[0]),
        )
        .unwrap();
    assert!(!s.exact);
    assert_eq!(s.rank, 0);
    assert!((s.residual - 1.6).abs() < 1e-15, "{s:?}");
    let later = fm
        .free_forces(
            &model,
            &mut ws,
            0.5,
            &[0.8, 0.0, 0.0],
            &[0.3, 0.0, 0.0],
            ForceDesign::Components(&[0]),
        )
        .unwrap();
    assert!(later.exact);
}

/// The minimum-norm design simulated on Example 1: another free motion than V2's (the
/// forces are not the paper's), with the multiplier at zero and the constraint kept.
#[test]
fn minimum_norm_forces_simulated() {
    let designed = designed(ex1::Model::default(), ForceDesign::MinimumNorm, |_, _| {});
    let (mut q0, mut qd0) = ([0.0; 3], [0.0; 3]);
    designed.initial_state(&mut q0, &mut qd0);
    let run = simulate(&designed, true, 0.0, &q0, &qd0, 2.0, 1e-12);
    let max_lambda = run.iter().map(|s| inf_norm(&s.lambda)).fold(0.0, f64::max);
    assert!(max_lambda < 1e-10, "max |λ| = {max_lambda:e}");
    let drift = run
        .iter()
        .map(|s| designed.residuals(s.t, &s.q, &s.qd).position)
        .fold(0.0, f64::max);
    assert!(drift < 1e-10);
    let end = run.last().unwrap();
    println!("Example 1, minimum-norm forces: max |λ| = {max_lambda:.1e}, |f| ≤ {drift:.1e}, q(2) = {:?}", end.q);
}

fn random_samples(n: usize, count: usize, seed: u64) -> Vec<Sample> {
    let mut rng = Rng::new(seed);
    (0..count)
        .map(|_| {
            let t = rng.range(0.0, 3.0);
            Sample::new(t, &rng.vec(n, -2.0, 2.0), &rng.vec(n, -2.0, 2.0))
        })
        .collect()
}

/// The family of planes t q1 + k q2 − 3 q3 = 0 under the force Q2 = −q̇1: the condition
/// is (2 − k) q̇1 = 0 at every state, so exactly k = 2 (the paper's plane) is free.
#[test]
fn family_of_constraints() {
    let mut model = plane_family::Model::default();
    let mut ws = Workspace::new(&plane_family::INFO).unwrap();
    let mut fm = FreeMotion::new(&plane_family::INFO, FreeMotionParams::default());
    let samples = random_samples(3, 8, 0xf4ee_0002);
    let search = ParameterSearch::new(0, -5.0, 5.0);
    let sol = fm
        .solve_parameter(
            &mut model,
            &mut ws,
            &search,
            &samples,
            AppliedForces::AsModeled,
        )
        .unwrap();
    assert_eq!(sol.roots.len(), 1, "{sol:?}");
    assert!((sol.roots[0] - 2.0).abs() < 1e-12, "{sol:?}");
    assert_eq!(model.params.k, 1.0, "the parameter is restored");
    // Printed with the parameter: (2 − k) q̇1 once Q2 = −q̇1 is substituted.
    assert_eq!(
        plane_family::FREE_MOTION,
        ["2*q1' + t*Q_q1 + k*Q_q2 - 3*Q_q3"]
    );
    // A constant push on q2 instead: w = 2 q̇1 + k cannot vanish at all samples.
    let none = fm
        .solve_parameter(
            &mut model,
            &mut ws,
            &search,
            &samples,
            AppliedForces::Replaced(&[0.0, 1.0, 0.0]),
        )
        .unwrap();
    assert!(none.roots.is_empty() && none.residual > 0.1, "{none:?}");
    println!(
        "plane family: k = {:.15} ({} evaluations, residual {:.1e}); constant push: no root, best k = {:.3} leaves {:.3}",
        sol.roots[0], sol.evaluations, sol.residual, none.best, none.residual
    );
    // Errors.
    let bad = ParameterSearch::new(3, -5.0, 5.0);
    assert!(matches!(
        fm.solve_parameter(
            &mut model,
            &mut ws,
            &bad,
            &samples,
            AppliedForces::AsModeled
        ),
        Err(FreeMotionError::Parameter {
            index: 3,
            count: 1,
            ..
        })
    ));
    let empty = ParameterSearch::new(0, 1.0, 1.0);
    assert!(matches!(
        fm.solve_parameter(
            &mut model,
            &mut ws,
            &empty,
            &samples,
            AppliedForces::AsModeled
        ),
        Err(FreeMotionError::Search { .. })
    ));
    assert!(matches!(
        fm.solve_parameter(&mut model, &mut ws, &search, &[], AppliedForces::AsModeled),
        Err(FreeMotionError::NoSamples)
    ));
}

/// A singular mass matrix is an error that says what to do instead.
#[test]
fn singular_mass_is_reported() {
    // `b` carries no inertia.
    #[pfaff::mechanism]
    mod massless {
        static a: Coordinate = Coordinate {};
        static b: Coordinate = Coordinate {};
        fn kinetic_energy() -> f64 {
            0.5 * a.dot().powi(2)
        }
        #[holonomic]
        fn tie() -> f64 {
            a - b
        }
    }
    let m = massless::Model::default();
    let mut ws = Workspace::new(&massless::INFO).unwrap();
    let mut fm = FreeMotion::new(&massless::INFO, FreeMotionParams::default());
    let mut p = FreeMotionPoint::new(&massless::INFO);
    let e = fm
        .evaluate(
            &m,
            &mut ws,
            0.0,
            &[0.0; 2],
            &[0.0; 2],
            AppliedForces::AsModeled,
            &mut p,
        )
        .unwrap_err();
    assert!(matches!(e, FreeMotionError::SingularMass { .. }), "{e}");
    assert!(m.free_motion_conditions().is_empty());
    println!("{e}");
}
