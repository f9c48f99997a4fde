//! `sleigh` (docs/models.md, docs/theory.md V11) against its source expressions.

use pfaff::TimeDependence;
use pfaff_models::sleigh::{Model, Params, INFO};

use super::check::{check_info, check_parameters, Expected, State};
use super::reference::Reference;
use super::sweep;

/// The expressions of `models/src/sleigh.rs`, re-typed: q = (x, y, φ).
fn reference(p: &Params) -> Reference {
    let (m, ic, a) = (p.m, p.ic, p.a);
    Reference::new(3, move |_, _, v| {
        0.5 * m * (v[0].powi(2) + v[1].powi(2)) + 0.5 * ic * v[2].powi(2)
    })
    .nonholonomic(move |_, q, v| -q[2].sin() * v[0] + q[2].cos() * v[1] - a * v[2])
}

#[test]
fn info() {
    check_parameters!(m = 2.0, ic = 0.05, a = 0.3);
    check_info(
        &Model::default(),
        &Expected {
            name: "sleigh",
            coordinates: &["x", "y", "phi"],
            holonomic: &[],
            nonholonomic: &["blade"],
            time: TimeDependence::default(),
            homogeneous: true,
            conservative: true,
            // V11: q0 = 0, q̇0 = (1, 0.15, 0.5).
            q0: &[0.0, 0.0, 0.0],
            qd0: &[1.0, 0.15, 0.5],
        },
    );
}

#[test]
fn derivatives() {
    sweep(
        "sleigh",
        0x5eed_0002,
        Model::default,
        |m| reference(&m.params),
        |rng| State {
            t: rng.range(0.0, 10.0),
            q: vec![
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
                rng.range(-std::f64::consts::PI, std::f64::consts::PI),
            ],
            qd: rng.vec(3, -2.0, 2.0),
        },
    );
}
