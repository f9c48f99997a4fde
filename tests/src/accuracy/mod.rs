//! Accuracy of the generated code: each built-in model against its own source
//! expressions, re-typed by hand as closures and differentiated numerically.
//!
//! - `util`: seeded random numbers, difference stencils with their error estimates.
//! - `reference`: a model's expressions and every generated quantity derived from them.
//! - `check`: the comparison at random states, the tolerances, the `Info` checks.
//! - one module per model, with the model-specific references (Hairer & Wanner's
//!   formulation of `andrews`, the V10 table of `slider_crank`, the multipliers of V1–V4).
//!
//! Run `cargo test --release -p pfaff-tests accuracy -- --nocapture` to see the largest
//! error of every quantity.

mod check;
mod reference;
pub(crate) mod util;

mod andrews;
mod car_axis;
pub(crate) mod coverage;
pub(crate) mod flexible_sleigh;
mod pendulum;
mod seed2;
mod sleigh;
mod slider_crank;

use check::{perturb, Checker, State};
use pfaff::Mechanism;
use reference::Reference;
use util::Rng;

/// Random states per model and parameter set.
const STATES: usize = 24;
/// Every other state runs with all parameters perturbed by up to ±20 %, so that a
/// parameter wired to the wrong place cannot hide behind its default value.
const SPREAD: f64 = 0.2;

/// Checks `make()` against `reference` at [`STATES`] states drawn by `sample`.
fn sweep<M: Mechanism>(
    label: &str,
    seed: u64,
    make: impl Fn() -> M,
    reference: impl Fn(&M) -> Reference,
    sample: impl Fn(&mut Rng) -> State,
) {
    let mut rng = Rng::new(seed);
    let mut checker = Checker::new(label, make().info());
    for k in 0..STATES {
        let mut model = make();
        if k % 2 == 1 {
            perturb(&mut model, &mut rng, SPREAD);
        }
        let state = sample(&mut rng);
        checker.state(&model, &reference(&model), &state);
    }
    checker.finish();
}
