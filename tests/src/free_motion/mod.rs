//! Constraint reactions and free motion (docs/theory.md §redundant-coordinates, [S2]): V1–V5, the designed
//! forces and their simulation, the symbolic conditions the generator prints, the
//! slider-crank reactions against Newton–Euler, and redundant constraints.
//!
//! - `models`: test mechanisms (the V5 model, a one-parameter family of Example 1).
//! - `sim`: a plain simulation on top of `Dynamics` and `ode::Dop853`, recording λ.
//! - one module per topic.
//!
//! Run `cargo test --release -p pfaff-tests free_motion -- --nocapture` to see the
//! observed errors.

use std::cell::RefCell;

use pfaff::free_motion::{ForceDesign, ForceSolution, Forced};
use pfaff::{FreeMotion, FreeMotionParams, Mechanism, Workspace};

mod models;
mod sim;

mod design;
mod parallelogram;
mod seed2;
mod slider_crank;
mod symbolic;

mod v5;

/// `|x − expected| ≤ tol · max(1, |expected|)`, componentwise, with a message.
fn assert_close(what: &str, x: &[f64], expected: &[f64], tol: f64) -> f64 {
    assert_eq!(x.len(), expected.len(), "{what}: lengths");
    let mut worst = 0.0_f64;
    for (i, (a, b)) in x.iter().zip(expected).enumerate() {
        let err = (a - b).abs() / b.abs().max(1.0);
        worst = worst.max(err);
        assert!(
            err <= tol,
            "{what}[{i}] = {a:.15e}, expected {b:.15e} (error {err:.1e})"
        );
    }
    worst
}

/// `model` with its applied forces replaced, at every state, by the forces the
/// free-motion analysis designs ([`FreeMotion::free_forces`] with `design`); `inspect`
/// sees each design with the state's velocities.
fn designed<M: Mechanism + Clone>(
    model: M,
    design: ForceDesign<'static>,
    inspect: impl Fn(&ForceSolution, &[f64]),
) -> impl Mechanism {
    let info = model.info();
    let analysis = RefCell::new((
        FreeMotion::new(info, FreeMotionParams::default()),
        Workspace::new(info).unwrap(),
    ));
    let plain = model.clone();
    Forced::new(
        model,
        move |t: f64, q: &[f64], qd: &[f64], out: &mut [f64]| {
            let (fm, ws) = &mut *analysis.borrow_mut();
            let s = fm.free_forces(&plain, ws, t, q, qd, design).unwrap();
            inspect(&s, qd);
            out.copy_from_slice(&s.applied);
        },
    )
}

fn inf_norm(x: &[f64]) -> f64 {
    x.iter().fold(0.0_f64, |a, v| a.max(v.abs()))
}

/// SplitMix64 with a fixed seed (the tests never use an unseeded source).
struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Self {
        Self(seed)
    }

    #[allow(clippy::cast_precision_loss)]
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    fn vec(&mut self, n: usize, lo: f64, hi: f64) -> Vec<f64> {
        (0..n).map(|_| self.range(lo, hi)).collect()
    }
}
