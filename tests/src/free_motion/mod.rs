//! Constraint reactions and free motion (math-spec §8, [S2]): V1–V5, the designed
//! forces and their simulation, the symbolic conditions the generator prints, the
//! slider-crank reactions against Newton–Euler, and redundant constraints.
//!
//! - `models`: test mechanisms (the V5 model, a one-parameter family of Example 1).
//! - `sim`: a plain simulation on top of `Dynamics` and `ode::Dop853`, recording λ.
//! - one module per topic.
//!
//! Run `cargo test --release -p pfaff-tests free_motion -- --nocapture` to see the
//! observed errors.

mod models;
mod sim;



mod seed2;


mod v5;

/// `|x − expected| ≤ tol · max(1, |expected|)`, componentwise, with a message.
fn assert_close(what: &str, x: &[f64], expected: &[f64], tol: f64) -> f64 {
    assert_eq!(x.len(), expected.len(), "{what}: lengths");
    let mut worst = 0.0_f64;
    for (i, (a, b)) in x.iter().zip(expected).enumerate() {
        let err = (a - b).abs() / b.abs().max(1.0);
        worst = worst.max(err);
        assert!(err <= tol, "{what}[{i}] = {a:.15e}, expected {b:.15e} (error {err:.1e})");
    }
    worst
}

fn inf_norm(x: &[f64]) -> f64 {
    x.iter().fold(0.0_f64, |a, v| a.max(v.abs()))
}
