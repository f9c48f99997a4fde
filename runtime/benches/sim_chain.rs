//! Dense/sparse crossover of the simulation on a chain of N planar point-mass
//! pendulums in Cartesian coordinates (`tests/common`): cost per RK4 step (four
//! augmented solves, Baumgarte formulation) for N = 2 … 1000 with the dense and the
//! sparse linear solver, measured as the difference of two run lengths so that the
//! one-time assembly (dense Algorithm P) is excluded. The sparse path should grow about
//! linearly in N.
//!
//! `cargo bench -p pfaff --bench sim_chain`.

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use common::Chain;
use pfaff::sim::{Formulation, Method, Simulation};
use pfaff::{DynamicsParams, LinearSolver};

/// Wall time of a run of `steps` RK4 steps, set-up (assembly) included.
fn timed(chain: &Chain, solver: LinearSolver, steps: usize) -> f64 {
    let (q, qd) = chain.state();
    let h = 1e-3;
    let start = Instant::now();
    let run = Simulation::new(chain)
        .formulation(Formulation::baumgarte())
        .integrator(Method::Rk4 { h })
        .dynamics(DynamicsParams {
            solver,
            ..DynamicsParams::default()
        })
        .initial_state(&q, &qd)
        .output_times(&[])
        .run(h * steps as f64)
        .expect("chain run");
    // Rounding of h·steps may add one short last step.
    assert!(run.stats.steps as usize >= steps && run.stats.steps as usize <= steps + 1);
    start.elapsed().as_secs_f64()
}

/// Cost per step without the one-time set-up (assembly runs the dense Algorithm P):
/// the difference between runs of `2 steps` and `steps` steps.
fn per_step(chain: &Chain, solver: LinearSolver, steps: usize) -> f64 {
    (timed(chain, solver, 2 * steps) - timed(chain, solver, steps)) / steps as f64
}

fn main() {
    println!(
        "{:>5} {:>6} {:>14} {:>14} {:>12}",
        "N", "n+m", "dense [µs]", "sparse [µs]", "sparse/N [µs]"
    );
    for n in [2, 4, 8, 16, 32, 64, 128, 256, 512, 1000] {
        let chain = Chain::new(n);
        let steps = (20_000 / n).clamp(200, 2000);
        let dense = if n <= 128 {
            format!(
                "{:14.1}",
                per_step(&chain, LinearSolver::Dense, steps.min(200)) * 1e6
            )
        } else {
            format!("{:>14}", "-")
        };
        let sparse = per_step(&chain, LinearSolver::Sparse, steps) * 1e6;
        println!(
            "{n:>5} {:>6} {dense} {sparse:14.1} {:12.3}",
            3 * n,
            sparse / n as f64
        );
    }
}
