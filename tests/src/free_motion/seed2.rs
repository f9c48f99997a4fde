//! V1–V4 of docs/theory.md §verification with the library: the explicit multipliers of [S2]'s two
//! examples without applied forces (V1, V3), and their free motions (V2, V4) both as
//! modelled and with the forces the analysis designs, simulated with multipliers.

use pfaff::free_motion::{ForceDesign, Forced};
use pfaff::{
    AppliedForces, FreeMotion, FreeMotionParams, FreeMotionPoint, Mechanism, MechanismExt,
    ReactionAnalysis, Reactions, Workspace,
};
use pfaff_models::{seed2_example1 as ex1, seed2_example2 as ex2};

use super::sim::{samples, simulate};
use super::{assert_close, designed, inf_norm};

/// Solver tolerance of the simulations; docs/theory.md §verification: integrated results to 100 × that.
const TOL: f64 = 1e-12;

fn explicit<M: Mechanism>(model: &M, t: f64, q: &[f64], qd: &[f64]) -> FreeMotionPoint {
    let info = model.info();
    let mut ws = Workspace::new(info).unwrap();
    let mut fm = FreeMotion::new(info, FreeMotionParams::default());
    let mut p = FreeMotionPoint::new(info);
    fm.evaluate(model, &mut ws, t, q, qd, AppliedForces::Without, &mut p)
        .unwrap();
    p
}

/// The runtime's augmented solve of the model with its applied forces removed.
fn augmented<M: Mechanism>(model: M, t: f64, q: &[f64], qd: &[f64]) -> Reactions {
    let info = model.info();
    let bare = Forced::new(model, |_, _, _, out: &mut [f64]| out.fill(0.0));
    let mut ws = Workspace::new(info).unwrap();
    let mut ra = ReactionAnalysis::new(info, Default::default()).unwrap();
    let mut r = Reactions::new(info);
    ra.evaluate(&bare, &mut ws, t, q, qd, &mut r).unwrap();
    r
}

/// V1: Example 1 with Q = 0 at t = 1, q̇1 = 0.5 (any q, q̇2, q̇3):
/// λ[S2] = −1/14, R = λ (t, 2, −3); the augmented solve gives λ[S1] = +1/14.
#[test]
fn v1_example1_multipliers() {
    let mut worst = 0.0_f64;
    for (q, qd) in [
        ([0.3, -1.2, 2.0], [0.5, 0.0, 0.0]),
        ([1.0, 0.0, 0.0], [0.5, 1.7, -0.4]),
    ] {
        let p = explicit(&ex1::Model::default(), 1.0, &q, &qd);
        let l = -1.0 / 14.0;
        worst = worst.max(assert_close("λ[S2]", &p.lambda_s2, &[l], 1e-10));
        assert_close("R", &p.reaction, &[l, 2.0 * l, -3.0 * l], 1e-10);
        assert_close("W", &p.W, &[14.0], 1e-14);
        assert_close("w", &p.residual, &[1.0], 1e-14);
        let r = augmented(ex1::Model::default(), 1.0, &q, &qd);
        worst = worst.max(assert_close("λ[S1]", &r.lambda, &[1.0 / 14.0], 1e-10));
        assert_close("−Jᵀλ", r.get("f").unwrap().force, &p.reaction, 1e-14);
    }
    println!("V1: worst relative error {worst:.1e}");
}

/// V3: Example 2 with Q = 0 at t = 1, q1 = 1, q̇1 = 0.5: λ[S2] = −1.66030661896282,
/// R = λ (t², −1, −1).
#[test]
fn v3_example2_multipliers() {
    let (q, qd) = ([1.0, 0.4, -2.0], [0.5, 0.9, 0.1]);
    let p = explicit(&ex2::Model::default(), 1.0, &q, &qd);
    let l = -1.660_306_618_962_82;
    let err = assert_close("λ[S2]", &p.lambda_s2, &[l], 1e-10);
    assert_close("R", &p.reaction, &[l, -l, -l], 1e-10);
    let r = augmented(ex2::Model::default(), 1.0, &q, &qd);
    assert_close("λ[S1]", &r.lambda, &[-l], 1e-10);
    println!(
        "V3: λ[S2] = {:.15}, relative error {err:.1e}",
        p.lambda_s2[0]
    );
}

/// Exact motion of V2.
fn v2_exact(t: f64) -> ([f64; 3], [f64; 3]) {
    ([1.0 + t, t - t * t / 2.0, t], [1.0, 1.0 - t, 1.0])
}

/// V2 with the forces the analysis designs: at every state the force on `q2` alone
/// that makes the motion free (it comes out as the paper's Q2 = −q̇1). Simulated with
/// multipliers, |λ| stays below 1e-10 and the motion follows q = (1+t, t − t²/2, t).
#[test]
fn v2_designed_forces_simulated() {
    let designed = designed(
        ex1::Model::default(),
        ForceDesign::Components(&[1]),
        |s, qd| {
            assert!(s.exact);
            assert!((s.applied[1] + qd[0]).abs() <= 1e-15 * (1.0 + qd[0].abs()));
        },
    );
    let (q0, qd0) = v2_exact(0.0);
    let run = simulate(&designed, true, 0.0, &q0, &qd0, 2.0, TOL);
    let max_lambda = run.iter().map(|s| inf_norm(&s.lambda)).fold(0.0, f64::max);
    assert!(max_lambda < 1e-10, "max |λ| = {max_lambda:e}");
    let end = run.last().unwrap();
    assert_eq!(end.t, 2.0);
    let (q, qd) = v2_exact(2.0);
    let eq = assert_close("q(2)", &end.q, &q, 100.0 * TOL);
    let ev = assert_close("q̇(2)", &end.qd, &qd, 100.0 * TOL);
    let mut worst_path = 0.0_f64;
    for s in &run {
        let (q, _) = v2_exact(s.t);
        worst_path = worst_path.max(assert_close("q(t)", &s.q, &q, 100.0 * TOL));
    }
    // The analysis agrees: the recorded motion is free.
    let mut ws = Workspace::new(&ex1::INFO).unwrap();
    let mut check = FreeMotion::new(&ex1::INFO, FreeMotionParams::default());
    let report = check
        .check_along(
            &designed,
            &mut ws,
            samples(&run),
            AppliedForces::AsModeled,
            1e-10,
        )
        .unwrap();
    assert!(report.free, "{report:?}");
    println!(
        "V2 designed: {} steps, max |λ| = {max_lambda:.1e}, |Δq(2)| = {eq:.1e}, |Δq̇(2)| = {ev:.1e}, max |Δq(t)| = {worst_path:.1e}, max |w| = {:.1e}",
        run.len(),
        report.max_residual[0]
    );
}

/// V2 and V4 as modelled, integrated *without* multipliers ((S2-22), docs/theory.md §free-motion-analysis
/// step 4): the constraint and its rate stay at solver tolerance, V4 meets the
/// published table, and the analysis finds the motions free.
#[test]
fn v2_v4_free_without_multipliers() {
    // V2.
    let model = ex1::Model::default();
    let (mut q0, mut qd0) = ([0.0; 3], [0.0; 3]);
    model.initial_state(&mut q0, &mut qd0);
    let run = simulate(&model, false, 0.0, &q0, &qd0, 2.0, TOL);
    let end = run.last().unwrap();
    let (q, qd) = v2_exact(2.0);
    let e2 = assert_close("V2 q(2)", &end.q, &q, 100.0 * TOL);
    assert_close("V2 q̇(2)", &end.qd, &qd, 100.0 * TOL);
    // V4.
    let model = ex2::Model::default();
    model.initial_state(&mut q0, &mut qd0);
    let run4 = simulate(&model, false, 0.0, &q0, &qd0, 2.0, TOL);
    let table = [
        (
            1.0,
            [1.82166785217, 2.52166785217, -0.7],
            [0.703860785731, 4.54719649007, -0.2],
        ),
        (
            2.0,
            [2.49829082136, 10.8931632854, -0.9],
            [0.687451197515, 12.9429680755, -0.2],
        ),
    ];
    let mut e4 = 0.0_f64;
    for (t, q, qd) in table {
        let s = run4
            .iter()
            .find(|s| s.t == t)
            .map(|s| (s.q.clone(), s.qd.clone()))
            .unwrap_or_else(|| {
                // The table times are stop times: integrate to them exactly.
                let r = simulate(&model, false, 0.0, &q0, &qd0, t, TOL);
                let l = r.last().unwrap();
                (l.q.clone(), l.qd.clone())
            });
        // The table has 12 digits.
        e4 = e4.max(assert_close("V4 q", &s.0, &q, 1e-10));
        e4 = e4.max(assert_close("V4 q̇", &s.1, &qd, 1e-10));
        // q̇1 = 2 / (2 + sin t).
        assert!((s.1[0] - 2.0 / (2.0 + t.sin())).abs() < 100.0 * TOL);
    }
    let mut worst_f = 0.0_f64;
    for (m, run) in [
        (&ex1::Model::default() as &dyn Mechanism, &run),
        (&model, &run4),
    ] {
        for s in run {
            let r = m.residuals(s.t, &s.q, &s.qd);
            worst_f = worst_f.max(r.position.max(r.velocity));
        }
    }
    assert!(worst_f < 100.0 * TOL * 20.0, "max |f|, |ḟ| = {worst_f:e}");
    let mut ws = Workspace::new(&ex2::INFO).unwrap();
    let mut fm = FreeMotion::new(&ex2::INFO, FreeMotionParams::default());
    let report = fm
        .check_along(
            &model,
            &mut ws,
            samples(&run4),
            AppliedForces::AsModeled,
            1e-10,
        )
        .unwrap();
    assert!(report.free, "{report:?}");
    println!(
        "V2/V4 without multipliers: |Δq(2)| V2 {e2:.1e}, V4 table {e4:.1e}, max |f|,|ḟ| {worst_f:.1e}, V4 max |λ| {:.1e}",
        report.max_lambda
    );
}

/// V4 with designed forces: the force on `q2` alone that makes Example 2 free is the
/// V4 force; simulated with multipliers, λ stays at zero and the table is met.
#[test]
fn v4_designed_forces_simulated() {
    let designed = designed(
        ex2::Model::default(),
        ForceDesign::Components(&[1]),
        |_, _| {},
    );
    let (mut q0, mut qd0) = ([0.0; 3], [0.0; 3]);
    designed.initial_state(&mut q0, &mut qd0);
    let run = simulate(&designed, true, 0.0, &q0, &qd0, 2.0, TOL);
    let max_lambda = run.iter().map(|s| inf_norm(&s.lambda)).fold(0.0, f64::max);
    assert!(max_lambda < 1e-10, "max |λ| = {max_lambda:e}");
    let end = run.last().unwrap();
    let e = assert_close("q(2)", &end.q, &[2.49829082136, 10.8931632854, -0.9], 1e-10);
    println!("V4 designed: max |λ| = {max_lambda:.1e}, |Δq(2)| = {e:.1e}");
}
