//! `car_axis` (docs/models.md; Rentrop, Roche & Steinebach 1989) against its
//! source expressions.

use pfaff::TimeDependence;
use pfaff_models::car_axis::{Model, Params, INFO};

use super::check::{check_info, check_parameters, Expected, State};
use super::reference::Reference;
use super::sweep;

/// The expressions of `models/src/car_axis.rs`, re-typed: q = (x_l, y_l, x_r, y_r).
fn reference(p: &Params) -> Reference {
    let (eps, mass, l, l0, r, w, g) = (p.eps, p.mass, p.l, p.l0, p.r, p.w, p.g);
    let k = mass * eps.powi(2) / 2.0;
    let yb = move |t: f64| r * (w * t).sin();
    let xb = move |t: f64| (l.powi(2) - yb(t).powi(2)).sqrt();
    Reference::new(4, move |_, _, v| {
        0.5 * k * v.iter().map(|v| v * v).sum::<f64>()
    })
    .potential(move |t, q| {
        let left = (q[0].powi(2) + q[1].powi(2)).sqrt();
        let right = ((q[2] - xb(t)).powi(2) + (q[3] - yb(t)).powi(2)).sqrt();
        0.5 * (left - l0).powi(2) + 0.5 * (right - l0).powi(2) + k * g * (q[1] + q[3])
    })
    .holonomic(move |t, q| xb(t) * q[0] + yb(t) * q[1])
    .holonomic(move |_, q| (q[0] - q[2]).powi(2) + (q[1] - q[3]).powi(2) - l.powi(2))
}

#[test]
fn info() {
    check_parameters!(
        eps = 1e-2,
        mass = 10.0,
        l = 1.0,
        l0 = 0.5,
        r = 0.1,
        w = 10.0,
        g = 1.0
    );
    check_info(
        &Model::default(),
        &Expected {
            name: "car_axis",
            coordinates: &["xl", "yl", "xr", "yr"],
            holonomic: &["road", "axle"],
            nonholonomic: &[],
            time: TimeDependence {
                mass: false,
                forces: true,
                holonomic: true,
                nonholonomic: false,
            },
            homogeneous: true,
            conservative: false,
            q0: &[0.0, 0.5, 1.0, 0.5],
            qd0: &[-0.5, 0.0, -0.5, 0.0],
        },
    );
}

#[test]
fn derivatives() {
    sweep(
        "car_axis",
        0x5eed_0003,
        Model::default,
        |m| reference(&m.params),
        |rng| State {
            t: rng.range(0.0, 3.0),
            q: rng.vec(4, -1.5, 1.5),
            qd: rng.vec(4, -2.0, 2.0),
        },
    );
}

/// The defaults are the consistent initial state of the reference: C = 0 and
/// C_q q̇ + C_t = 0 at t = 0.
#[test]
fn initial_state_is_consistent() {
    use pfaff::Mechanism as _;
    let model = Model::default();
    let (mut q, mut qd) = ([0.0; 4], [0.0; 4]);
    model.initial_state(&mut q, &mut qd);
    let reference = reference(&model.params);
    let c = reference.holonomic_values(0.0, &q);
    let cq = reference.holonomic_jacobian(0.0, &q);
    let ct = reference.holonomic_rate(0.0, &q);
    let velocity: Vec<f64> = (0..2)
        .map(|i| (0..4).map(|j| cq[i * 4 + j] * qd[j]).sum::<f64>() + ct[i])
        .collect();
    assert!(c.iter().all(|c| c.abs() < 1e-15), "C = {c:?}");
    // First differences: tolerance TOL_D1-sized.
    assert!(
        velocity.iter().all(|v| v.abs() < 1e-9),
        "C_q q̇ + C_t = {velocity:?}"
    );
}
