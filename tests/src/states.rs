//! States of the built-in models for tests and benchmarks.

use pfaff::sim::{Method, Simulation};
use pfaff::Mechanism;

/// The consistent state of `model` at `t` from its initial state: a run with DOP853 at
/// rtol 1e-12, atol 1e-14 (the positions and velocities of a moving mechanism).
///
/// # Panics
/// When the run fails.
#[must_use]
pub fn moving_state(model: &dyn Mechanism, t: f64) -> (Vec<f64>, Vec<f64>) {
    let run = Simulation::new(model)
        .integrator(Method::Dop853)
        .tolerances(1e-12, 1e-14)
        .output_times(&[])
        .run(t)
        .expect("the reference run");
    let (_, q, qd) = run.final_state().expect("a final row");
    (q.to_vec(), qd.to_vec())
}
