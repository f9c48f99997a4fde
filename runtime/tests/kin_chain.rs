//! Dense and sparse augmented solves on the pendulum chain: agreement, automatic
//! choice, and the timing that sets the crossover.

mod common;

use std::time::Instant;

use common::Chain;
use pfaff::{
    Dynamics, DynamicsParams, LinearSolver, Mechanism, MechanismExt, SolverPath, Workspace,
    DEFAULT_CROSSOVER,
};

fn solve(chain: &Chain, solver: LinearSolver) -> (Vec<f64>, Vec<f64>, SolverPath) {
    let info = chain.info();
    let (q, qd) = chain.state();
    let mut ws = Workspace::new(info).unwrap();
    let params = DynamicsParams {
        solver,
        ..Default::default()
    };
    let mut d = Dynamics::new(info, params).unwrap();
    let (mut a, mut l) = (vec![0.0; info.nq()], vec![0.0; info.nh()]);
    let stats = d
        .accelerations(chain, &mut ws, 0.0, &q, &qd, &mut a, &mut l)
        .unwrap();
    (a, l, stats.path)
}

/// The dense LU, the sparse LDLᵀ (coordinates first, no pivoting) and the sparse LU
/// give the same accelerations and multipliers (to 1e-10 of their size).
#[test]
fn dense_and_sparse_agree() {
    for n in [1, 2, 5, 10, 20, 40, 80] {
        let chain = Chain::new(n);
        let (q, qd) = chain.state();
        let r = chain.residuals(0.0, &q, &qd);
        assert!(r.position < 1e-13 && r.velocity < 1e-13);
        let (ad, ld, pd) = solve(&chain, LinearSolver::Dense);
        assert_eq!(pd, SolverPath::Dense);
        let scale_a = ad.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
        let scale_l = ld.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
        for (solver, path) in [
            (LinearSolver::Sparse, SolverPath::SparseLdlt),
            (LinearSolver::SparseLu, SolverPath::Sparse),
        ] {
            let (as_, ls, ps) = solve(&chain, solver);
            assert_eq!(ps, path, "N = {n}");
            let da = ad
                .iter()
                .zip(&as_)
                .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
            let dl = ld
                .iter()
                .zip(&ls)
                .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
            println!("N = {n}, {path:?}: |qdd_d - qdd_s| = {da:e} (scale {scale_a:.3}), |lambda_d - lambda_s| = {dl:e} (scale {scale_l:.3})");
            assert!(da <= 1e-10 * scale_a && dl <= 1e-10 * scale_l);
        }
    }
}

#[test]
fn automatic_choice_switches_at_the_crossover() {
    for n in [2, 4, 5, 6, 7, 40] {
        let chain = Chain::new(n);
        let (_, _, path) = solve(&chain, LinearSolver::Auto);
        let dim = 3 * n;
        let expected = if dim < DEFAULT_CROSSOVER {
            SolverPath::Dense
        } else {
            SolverPath::SparseLdlt
        };
        assert_eq!(path, expected, "N = {n}, n + m = {dim}");
    }
}

/// Prints per-solve times of both paths (run with `--nocapture`); the crossover in
/// [`DEFAULT_CROSSOVER`] comes from these numbers.
#[test]
fn timing_dense_versus_sparse() {
    for n in [2, 3, 4, 6, 8, 12, 16, 24, 32, 64, 128] {
        let chain = Chain::new(n);
        let info = chain.info();
        let (q, qd) = chain.state();
        let mut ws = Workspace::new(info).unwrap();
        let (mut a, mut l) = (vec![0.0; info.nq()], vec![0.0; info.nh()]);
        let mut times = [0.0; 2];
        for (k, solver) in [LinearSolver::Dense, LinearSolver::Sparse]
            .into_iter()
            .enumerate()
        {
            let params = DynamicsParams {
                solver,
                ..Default::default()
            };
            let mut d = Dynamics::new(info, params).unwrap();
            let reps = (200_000 / (n * n)).clamp(20, 20_000);
            d.accelerations(&chain, &mut ws, 0.0, &q, &qd, &mut a, &mut l)
                .unwrap();
            let start = Instant::now();
            for _ in 0..reps {
                d.accelerations(&chain, &mut ws, 0.0, &q, &qd, &mut a, &mut l)
                    .unwrap();
            }
            times[k] = start.elapsed().as_secs_f64() / reps as f64 * 1e6;
        }
        println!(
            "N = {n:3} (n + m = {:3}): dense {:9.2} us, sparse {:9.2} us",
            3 * n,
            times[0],
            times[1]
        );
    }
}
