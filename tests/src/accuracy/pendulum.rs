//! `pendulum` (docs/models.md, IFToMM A01) against its source expressions.

use pfaff::TimeDependence;
use pfaff_models::pendulum::{Model, Params, INFO};

use super::check::{check_info, check_parameters, Expected, State};
use super::reference::Reference;
use super::sweep;

/// The expressions of `models/src/pendulum.rs`, re-typed: q = (x, y).
fn reference(p: &Params) -> Reference {
    let (m, l, g) = (p.m, p.l, p.g);
    Reference::new(2, move |_, _, v| 0.5 * m * (v[0].powi(2) + v[1].powi(2)))
        .potential(move |_, q| m * g * q[1])
        .holonomic(move |_, q| q[0].powi(2) + q[1].powi(2) - l.powi(2))
}

#[test]
fn info() {
    check_parameters!(m = 1.0, l = 1.0, g = 9.81);
    check_info(
        &Model::default(),
        &Expected {
            name: "pendulum",
            coordinates: &["x", "y"],
            holonomic: &["rod"],
            nonholonomic: &[],
            time: TimeDependence::default(),
            homogeneous: true,
            conservative: true,
            q0: &[1.0, 0.0],
            qd0: &[0.0, 0.0],
        },
    );
}

#[test]
fn derivatives() {
    sweep(
        "pendulum",
        0x5eed_0001,
        Model::default,
        |m| reference(&m.params),
        |rng| State {
            t: rng.range(0.0, 10.0),
            q: rng.vec(2, -1.5, 1.5),
            qd: rng.vec(2, -2.0, 2.0),
        },
    );
}
