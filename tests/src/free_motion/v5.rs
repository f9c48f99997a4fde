//! V5 of docs/theory.md §verification: the general multiplier formula of [S2] with every term of $h$
//! active ($T_2$ with $\partial A/\partial q$ and $\partial A/\partial t$, $T_1$, $T_0$,
//! rheonomic constraints, forces), against the published numbers and against the
//! augmented solve.

use pfaff::{
    AppliedForces, FreeMotion, FreeMotionParams, FreeMotionPoint, Mechanism, ReactionAnalysis,
    Reactions, Workspace,
};

use super::models::v5;
use super::{assert_close, inf_norm};

const T: f64 = 0.7;
const Q: [f64; 3] = [0.3, -0.2, 0.5];
const QD: [f64; 3] = [0.1, 0.4, -0.3];

fn point() -> FreeMotionPoint {
    let model = v5::Model::default();
    let mut ws = Workspace::new(&v5::INFO).unwrap();
    let mut fm = FreeMotion::new(&v5::INFO, FreeMotionParams::default());
    let mut p = FreeMotionPoint::new(&v5::INFO);
    fm.evaluate(
        &model,
        &mut ws,
        T,
        &Q,
        &QD,
        AppliedForces::AsModeled,
        &mut p,
    )
    .unwrap();
    p
}

/// The numbers of V5 to 1e-10 (they are given to 12 digits).
#[test]
fn v5_explicit_formula() {
    let p = point();
    let a = [1.04, 0.0, 0.15, 0.0, 2.764842187284, 0.0, 0.15, 0.0, 1.0];
    let mut mass = vec![0.0; 9];
    pfaff::MechanismExt::mass_matrix_dense_inplace(&v5::Model::default(), T, &Q, &mut mass);
    let mut worst = assert_close("A", &mass, &a, 1e-10);
    worst = worst.max(assert_close(
        "h",
        &p.h,
        &[-0.150600946738, 0.225687074895, 0.182799684421],
        1e-10,
    ));
    worst = worst.max(assert_close("c", &p.c, &[-0.22, -0.781014155990], 1e-10));
    worst = worst.max(assert_close(
        "w",
        &p.residual,
        &[-0.325970443868, -0.821303717501],
        1e-10,
    ));
    worst = worst.max(assert_close(
        "λ[S2]",
        &p.lambda_s2,
        &[0.0963089844036, 0.640763782118],
        1e-10,
    ));
    worst = worst.max(assert_close(
        "q̈",
        &p.qdd,
        &[0.453561512162, 0.0990441944051, 0.508295022498],
        1e-10,
    ));
    assert_eq!(p.rank, 2);
    // F q̈ + c = 0.
    let mut cq = vec![0.0; v5::INFO.holonomic_pattern.len()];
    v5::Model::default().holonomic_jacobian(T, &Q, &mut cq);
    let mut f = [0.0; 6];
    pfaff::scatter_row_major(v5::INFO.holonomic_pattern, &cq, 3, &mut f);
    for b in 0..2 {
        let fq: f64 = (0..3).map(|s| f[b * 3 + s] * p.qdd[s]).sum();
        assert!((fq + p.c[b]).abs() < 1e-14, "F q̈ + c = {:e}", fq + p.c[b]);
    }
    println!("V5: largest relative deviation from the published digits {worst:.1e}");
}

/// The same λ (with the opposite sign) and q̈ from the augmented solve of the runtime
/// (Lagrange's equations of the first kind solved directly).
#[test]
fn v5_matches_augmented_solve() {
    let p = point();
    let model = v5::Model::default();
    let mut ws = Workspace::new(&v5::INFO).unwrap();
    let mut ra = ReactionAnalysis::new(&v5::INFO, Default::default()).unwrap();
    let mut r = Reactions::new(&v5::INFO);
    ra.evaluate(&model, &mut ws, T, &Q, &QD, &mut r).unwrap();
    let lambda = p.lambda();
    let dl: Vec<f64> = lambda.iter().zip(&r.lambda).map(|(a, b)| a - b).collect();
    let da: Vec<f64> = p.qdd.iter().zip(&r.qdd).map(|(a, b)| a - b).collect();
    assert!(inf_norm(&dl) < 1e-14, "λ: {dl:?}");
    assert!(inf_norm(&da) < 1e-14, "q̈: {da:?}");
    let s2: Vec<f64> = r
        .lambda_s2()
        .iter()
        .zip(&p.lambda_s2)
        .map(|(a, b)| a - b)
        .collect();
    assert!(inf_norm(&s2) < 1e-14, "λ[S2]: {s2:?}");
    // The [S2] constraint force R = Fᵀλ[S2] is the total −Jᵀλ of the runtime.
    let total = r.total_force();
    let dr: Vec<f64> = total.iter().zip(&p.reaction).map(|(a, b)| a - b).collect();
    assert!(inf_norm(&dr) < 1e-14, "R: {dr:?}");
    println!(
        "V5 vs augmented solve: |Δλ| = {:.1e}, |Δq̈| = {:.1e}, |ΔR| = {:.1e}",
        inf_norm(&dl),
        inf_norm(&da),
        inf_norm(&dr)
    );
}

/// Not diagonal and not constant: the generator emits no free-motion residual.
#[test]
fn v5_has_no_symbolic_residual() {
    let model = v5::Model::default();
    assert!(model.free_motion_conditions().is_empty());
    let mut out = [0.0; 2];
    assert!(!model.free_motion_residual(T, &Q, &QD, &[0.0; 3], &mut out));
    // The declared applied forces are the three constants.
    let mut applied = [0.0; 3];
    model.applied_forces(T, &Q, &QD, &mut applied);
    assert_eq!(applied, [0.2, -0.1, 0.05]);
}
