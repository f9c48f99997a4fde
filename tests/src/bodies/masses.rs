//! The generated `body_masses`: the mass of every body, following the parameters.

use pfaff::Mechanism;
use pfaff_models::slider_crank_bodies;

use super::models::spatial_zoo;

#[test]
fn body_masses_are_the_declared_masses() {
    // slider_crank_bodies declares m1 = 0.1, m2 = 0.3, m3 = 0.5 kg (the model source).
    let mut m = slider_crank_bodies::Model::default();
    let info = m.info();
    let q = [0.0; 9];
    let mut out = [0.0; 3];
    m.body_masses(0.0, &q, &mut out);
    assert_eq!(out, [0.1, 0.3, 0.5]);
    let k = info.parameter_index("m2").unwrap();
    m.set_parameter(k, 0.7);
    m.body_masses(0.0, &q, &mut out);
    assert_eq!(out, [0.1, 0.7, 0.5]);
    // spatial_zoo: a parameter, and two literals (tests/src/bodies/models.rs).
    let z = spatial_zoo::Model::default();
    let mut out = [0.0; 3];
    z.body_masses(0.0, &vec![0.0; z.info().nq()], &mut out);
    assert_eq!(out, [1.5, 2.0, 0.5]);
}
