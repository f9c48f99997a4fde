//! The body level of `#[mechanism]`: agreement with hand-written models, the Euler-parameter
//! free body (docs/theory.md V12), and every joint type against finite differences.

mod bricard;
mod chain;
mod drawing;
mod joints;
mod masses;
mod models;
mod poses;
mod reactions;

use pfaff::sim::{Formulation, Method, Simulation};
use pfaff::{Mechanism, MechanismExt};
use pfaff_models::{free_body, slider_crank, slider_crank_bodies};

/// Largest absolute difference of two slices.
fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
}

/// `slider_crank_bodies` generates the equations typed by hand in `slider_crank`: the
/// same mass matrix, forces and energies at random states, and trajectories that agree to
/// 1e-10 under the same method.
#[test]
fn slider_crank_from_bodies_equals_the_hand_written_model() {
    let (hand, bodies) = (
        slider_crank::Model::default(),
        slider_crank_bodies::Model::default(),
    );
    let mut seed = 7_u64;
    let mut rnd = || {
        seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    for _ in 0..20 {
        let q: Vec<f64> = (0..9).map(|_| rnd()).collect();
        let qd: Vec<f64> = (0..9).map(|_| rnd()).collect();
        let (mut m1, mut m2) = ([0.0; 81], [0.0; 81]);
        hand.mass_matrix_dense_inplace(0.3, &q, &mut m1);
        bodies.mass_matrix_dense_inplace(0.3, &q, &mut m2);
        assert!(max_diff(&m1, &m2) < 1e-15);
        let (mut f1, mut f2) = ([0.0; 9], [0.0; 9]);
        hand.forces(0.3, &q, &qd, &mut f1);
        bodies.forces(0.3, &q, &qd, &mut f2);
        assert!(max_diff(&f1, &f2) < 1e-14, "{f1:?} {f2:?}");
        let dv = hand.potential_energy(0.3, &q) - bodies.potential_energy(0.3, &q);
        assert!(dv.abs() < 1e-15);
    }
    let run = |m: &dyn Mechanism| {
        Simulation::new(m)
            .formulation(Formulation::Projection)
            .integrator(Method::Dop853)
            .tolerances(1e-12, 1e-14)
            .output_every(0.05)
            .run(1.0)
            .expect("the driven slider-crank runs")
    };
    let (a, b) = (run(&hand), run(&bodies));
    assert_eq!(a.trajectory.len(), b.trajectory.len());
    let mut worst = 0.0_f64;
    for i in 0..a.trajectory.len() {
        worst = worst.max(max_diff(a.trajectory.q(i), b.trajectory.q(i)));
        worst = worst.max(max_diff(a.trajectory.qd(i), b.trajectory.qd(i)));
    }
    assert!(worst < 1e-10, "largest difference along the run {worst:e}");
}

/// docs/theory.md V12: the torque-free body with Ī = diag(1, 1, 2) and ω̄(0) = (1, 0, 2) keeps
/// T = 4.5 and the global angular momentum A Ī ω̄ = (1, 0, 4) over 100 s with θᵀθ = 1,
/// and ω̄(t) = (cos 2t, sin 2t, 2) (closed form of the symmetric top, docs/theory.md V12).
#[test]
fn free_body_keeps_energy_and_angular_momentum_v12() {
    let model = free_body::Model::default();
    let info = model.info();
    assert_eq!(info.holonomic[0].name, "body.normalization");
    let times: Vec<f64> = (0..=100).map(f64::from).collect();
    let run = Simulation::new(&model)
        .formulation(Formulation::Projection)
        .integrator(Method::Dop853)
        .tolerances(1e-11, 1e-13)
        .output_times(&times)
        .run(100.0)
        .expect("the free body runs");
    let tr = &run.trajectory;
    let mut worst_t = 0.0_f64;
    let mut worst_h = 0.0_f64;
    let mut worst_norm = 0.0_f64;
    let mut worst_w = 0.0_f64;
    for i in 0..tr.len() {
        let (t, q, qd) = (tr.t[i], tr.q(i), tr.qd(i));
        worst_t = worst_t.max((model.kinetic_energy(t, q, qd) - 4.5).abs());
        let e: f64 = q[3..7].iter().map(|x| x * x).sum();
        worst_norm = worst_norm.max((e - 1.0).abs());
        // ω̄ from the generated outputs; angular momentum A Ī ω̄ from the pose.
        let mut w = [0.0; 3];
        model.outputs(t, q, qd, &mut w);
        let exact = [(2.0 * t).cos(), (2.0 * t).sin(), 2.0];
        worst_w = worst_w.max(max_diff(&w, &exact));
        let mut pose = [0.0; 12];
        model.frame_poses(t, q, &mut pose);
        let l_body = [w[0], w[1], 2.0 * w[2]];
        let a = &pose[3..];
        let l: Vec<f64> = (0..3)
            .map(|r| (0..3).map(|c| a[3 * r + c] * l_body[c]).sum())
            .collect();
        worst_h = worst_h.max(max_diff(&l, &[1.0, 0.0, 4.0]));
    }
    assert!(worst_t < 1e-8, "energy error {worst_t:e}");
    assert!(worst_h < 1e-8, "angular momentum error {worst_h:e}");
    assert!(worst_norm < 1e-10, "normalization error {worst_norm:e}");
    assert!(worst_w < 1e-7, "angular velocity error {worst_w:e}");
}

/// `sleigh_bodies` (a body on a `KnifeEdge`) generates the hand-written sleigh's
/// equations: the same `M`, `G` and `γ_nh` at random states, and the same motion.
#[test]
fn sleigh_from_a_knife_edge_equals_the_hand_written_model() {
    use pfaff_models::{sleigh, sleigh_bodies};
    let (hand, bodies) = (sleigh::Model::default(), sleigh_bodies::Model::default());
    for k in 0..10 {
        let s = f64::from(k);
        let q = [0.3 * s.sin(), 0.2 * s.cos(), 0.7 * s];
        let qd = [s.cos(), 0.5 - 0.1 * s, 0.4 * s.sin()];
        let (mut g1, mut g2) = ([0.0; 3], [0.0; 3]);
        hand.nonholonomic_matrix_dense_inplace(0.0, &q, &mut g1);
        bodies.nonholonomic_matrix_dense_inplace(0.0, &q, &mut g2);
        assert!(max_diff(&g1, &g2) < 1e-15, "{g1:?} {g2:?}");
        let (mut c1, mut c2) = ([0.0; 1], [0.0; 1]);
        hand.nonholonomic_gamma(0.0, &q, &qd, &mut c1);
        bodies.nonholonomic_gamma(0.0, &q, &qd, &mut c2);
        assert!(max_diff(&c1, &c2) < 1e-15);
        let (mut m1, mut m2) = ([0.0; 9], [0.0; 9]);
        hand.mass_matrix_dense_inplace(0.0, &q, &mut m1);
        bodies.mass_matrix_dense_inplace(0.0, &q, &mut m2);
        assert!(max_diff(&m1, &m2) < 1e-15);
    }
    let run = |m: &dyn Mechanism| {
        Simulation::new(m)
            .integrator(Method::Dop853)
            .tolerances(1e-11, 1e-13)
            .output_every(0.5)
            .run(5.0)
            .expect("the sleigh runs")
    };
    let (a, b) = (run(&hand), run(&bodies));
    let (_, qa, _) = a.final_state().expect("a final state");
    let (_, qb, _) = b.final_state().expect("a final state");
    assert!(max_diff(qa, qb) < 1e-10, "{qa:?} {qb:?}");
}
