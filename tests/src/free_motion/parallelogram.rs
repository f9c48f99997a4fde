//! Redundant constraints: the parallelogram linkage with a third parallel crank. The
//! reactions returned are the minimum-norm ones (orthogonal to the self-stress of the
//! linkage, the null vector of $J^\mathsf{T}$), they still balance the equations of
//! motion, the explicit formula of [S2] with the pseudo-inverse of $W$ gives the same,
//! and the redundant constraint is named.

use pfaff::ode::{Dop853, Integrator, OdeOptions, OdeSystem, RhsError};
use pfaff::{
    AppliedForces, FreeMotion, FreeMotionParams, FreeMotionPoint, Mechanism, MechanismExt,
    ReactionAnalysis, Reactions, SolverPath, Workspace,
};
use pfaff_models::parallelogram;

use super::inf_norm;

/// An exact parallelogram state: cranks at `th` turning at `w`, coupler horizontal.
fn state(l: f64, th: f64, w: f64) -> ([f64; 6], [f64; 6]) {
    (
        [th, th, th, l * th.cos(), l * th.sin(), 0.0],
        [w, w, w, -l * th.sin() * w, l * th.cos() * w, 0.0],
    )
}

#[test]
fn minimum_norm_reactions_and_redundancy_reported() {
    let model = parallelogram::Model::default();
    let info = &parallelogram::INFO;
    let l = model.params.l;
    let mut ws = Workspace::new(info).unwrap();
    let mut ra = ReactionAnalysis::new(info, Default::default()).unwrap();
    let mut fm = FreeMotion::new(info, FreeMotionParams::default());
    let mut r = Reactions::new(info);
    let mut p = FreeMotionPoint::new(info);
    let (mut worst_orth, mut worst_eom, mut worst_s2) = (0.0_f64, 0.0_f64, 0.0_f64);
    for (th, w) in [
        (1.0471975511965976, 1.0),
        (0.3, -2.0),
        (2.2, 0.5),
        (-0.7, 3.0),
    ] {
        let (q, qd) = state(l, th, w);
        let stats = ra.evaluate(&model, &mut ws, 0.0, &q, &qd, &mut r).unwrap();
        assert_eq!(stats.path, SolverPath::Redundant);
        assert_eq!(stats.rank, 5);
        let redundant: Vec<_> = r.redundant().collect();
        assert_eq!(redundant.len(), 1, "{redundant:?}");
        assert!(r.get(redundant[0]).unwrap().redundant);

        // Self-stress of the linkage: Jᵀ z = 0 with
        // z = (cot θ, 1, −2 cot θ, −2, cot θ, 1) over (pin1_x, pin1_y, …, pin3_y).
        let c = th.cos() / th.sin();
        let z = [c, 1.0, -2.0 * c, -2.0, c, 1.0];
        let mut jac = vec![0.0; 36];
        model.holonomic_jacobian_dense_inplace(0.0, &q, &mut jac);
        let jtz: Vec<f64> = (0..6)
            .map(|j| (0..6).map(|k| jac[k * 6 + j] * z[k]).sum())
            .collect();
        assert!(inf_norm(&jtz) < 1e-14, "Jᵀz = {jtz:?}");
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let zl: f64 = z.iter().zip(&r.lambda).map(|(a, b)| a * b).sum();
        let orth = zl.abs() / (norm(&z) * norm(&r.lambda));
        worst_orth = worst_orth.max(orth);
        assert!(orth < 1e-12, "z·λ / |z||λ| = {orth:e}");

        // M q̈ + Jᵀλ = Q.
        let mut m = vec![0.0; 36];
        model.mass_matrix_dense_inplace(0.0, &q, &mut m);
        let mut f = [0.0; 6];
        model.forces(0.0, &q, &qd, &mut f);
        let total = r.total_force();
        for i in 0..6 {
            let mq: f64 = (0..6).map(|j| m[i * 6 + j] * r.qdd[j]).sum();
            let res = (mq - total[i] - f[i]).abs() / inf_norm(&f).max(1.0);
            worst_eom = worst_eom.max(res);
            assert!(res < 1e-12, "equation {i}: {res:e}");
        }

        // The explicit formula with W⁺ is the same minimum-norm multiplier.
        fm.evaluate(
            &model,
            &mut ws,
            0.0,
            &q,
            &qd,
            AppliedForces::AsModeled,
            &mut p,
        )
        .unwrap();
        assert_eq!(p.rank, 5);
        assert!(p.consistency < 1e-12 * inf_norm(&p.residual).max(1.0));
        let d: Vec<f64> = p
            .lambda()
            .iter()
            .zip(&r.lambda)
            .map(|(a, b)| a - b)
            .collect();
        let rel = inf_norm(&d) / inf_norm(&r.lambda);
        worst_s2 = worst_s2.max(rel);
        assert!(rel < 1e-10, "explicit vs augmented: {d:?}");
    }
    println!(
        "parallelogram: rank 5 of 6, redundant `{}`; z·λ/(|z||λ|) ≤ {worst_orth:.1e}, equations of motion {worst_eom:.1e}, explicit vs augmented {worst_s2:.1e}",
        r.redundant().next().unwrap()
    );
}

/// The exact motion of the linkage is one-dimensional (equal crank angles, coupler
/// horizontal): $(3 j_k + m_c l^2)\ddot\theta = -(\tfrac32 m_k + m_c) g l \cos\theta$.
/// Integrated as such, it gives states exactly on the constraint manifold, along which
/// the reactions are computed: the redundancy is reported at every state (with the
/// time it was first seen), and the accelerations agree with the reduced equation.
#[test]
fn redundancy_reported_along_a_trajectory() {
    struct Reduced {
        inertia: f64,
        moment: f64,
    }
    impl OdeSystem for Reduced {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
            dy[0] = y[1];
            dy[1] = -self.moment * y[0].cos() / self.inertia;
            Ok(())
        }
    }
    let model = parallelogram::Model::default();
    let info = &parallelogram::INFO;
    let p = model.params;
    let jk = p.mk * p.l * p.l / 3.0;
    let mut sys = Reduced {
        inertia: 3.0 * jk + p.mc * p.l * p.l,
        moment: (1.5 * p.mk + p.mc) * p.g * p.l,
    };
    let mut ode = Dop853::new(
        2,
        OdeOptions {
            h_max: 0.02,
            ..OdeOptions::with_tol(1e-12)
        },
    )
    .unwrap();
    ode.reset(&mut sys, 0.0, &[1.0471975511965976, 1.0], None)
        .unwrap();
    let mut states = vec![(0.0, state(p.l, 1.0471975511965976, 1.0))];
    while ode.t() < 1.5 {
        let t = ode.step(&mut sys, Some(1.5)).unwrap();
        states.push((t, state(p.l, ode.y()[0], ode.y()[1])));
    }
    let mut ws = Workspace::new(info).unwrap();
    let mut ra = ReactionAnalysis::new(info, Default::default()).unwrap();
    let history = ra
        .along(
            &model,
            &mut ws,
            states.iter().map(|(t, (q, qd))| (*t, &q[..], &qd[..])),
        )
        .unwrap();
    // Which of the dependent rows is dropped follows the pivoting and may change along
    // the motion; one is always named, and the history lists each with its first time.
    assert!(!history.redundant.is_empty());
    assert_eq!(history.redundant[0].1, 0.0);
    let (mut worst, mut worst_orth) = (0.0_f64, 0.0_f64);
    for (r, (_, (q, _))) in history.samples.iter().zip(&states) {
        assert_eq!(r.redundant().count(), 1, "t = {}", r.t);
        let mut dy = [0.0; 2];
        sys.rhs(r.t, &[q[0], 0.0], &mut dy).unwrap();
        worst = worst.max((r.qdd[0] - dy[1]).abs());
        let c = q[0].cos() / q[0].sin();
        let z = [c, 1.0, -2.0 * c, -2.0, c, 1.0];
        let zl: f64 = z.iter().zip(&r.lambda).map(|(a, b)| a * b).sum();
        worst_orth = worst_orth.max(zl.abs() / inf_norm(&r.lambda) / inf_norm(&z));
    }
    assert!(worst < 1e-12, "θ̈: {worst:e}");
    assert!(worst_orth < 1e-12, "z·λ: {worst_orth:e}");
    println!(
        "parallelogram motion: {} states, one constraint redundant at each ({:?}), max |λ| = {:.3}, |Δθ̈| ≤ {worst:.1e}, z·λ/(|z||λ|) ≤ {worst_orth:.1e}",
        history.samples.len(),
        history.redundant,
        history.max_abs_lambda()
    );
}
