//! Output rows are functions of the run and the interpolant at their time, not of the
//! other rows: a row is corrected onto the constraints from the integrator's
//! interpolant without reading what the previous row's record left (the mass matrix
//! of the projection's metric) and without teaching the run anything (the chart's
//! contraction rate), so the rows common to two grids are the same bits.
//!
//! The cases are those where rows used to differ (ARCHITECTURE.md, "Rows depend on the
//! grid"): Euler parameters and non-holonomic rows with projection, where an
//! interpolant lies far enough off the manifold for the metric to show (row 0.5 s of
//! `free_body` with DOPRI5 at rtol 1e-3 moved by 4e-11 with 500 rows), and partitioning
//! with Adams (no dense stages), whose row corrections taught the chart its rate.

use pfaff::sim::{Formulation, Method, Simulation};
use pfaff::Mechanism;

/// The rows at `t` of a run written at `coarse` times and of the same run on a grid of
/// `fine` intervals (which holds those times), position and velocity bits.
fn rows_agree(model: &dyn Mechanism, form: Formulation, method: Method, rtol: f64, t_end: f64) {
    let coarse = [0.5 * t_end, t_end];
    let run = |mut sim: Simulation<'_, dyn Mechanism>| sim.run(t_end).expect("the run");
    let base = || {
        Simulation::new(model)
            .formulation(form)
            .integrator(method)
            .tolerances(rtol, rtol)
    };
    let few = run(base().output_times(&coarse));
    let many = run(base().output_every(t_end / 500.0));
    assert_eq!(
        few.stats.steps,
        many.stats.steps,
        "{} {form:?} {method:?}",
        model.info().name
    );
    for &t in &coarse {
        let (i, j) = (
            few.trajectory.row_at(t).unwrap(),
            many.trajectory.row_at(t).unwrap(),
        );
        assert_eq!(
            few.trajectory.t[i].to_bits(),
            many.trajectory.t[j].to_bits()
        );
        for (a, b) in [
            (few.trajectory.q(i), many.trajectory.q(j)),
            (few.trajectory.qd(i), many.trajectory.qd(j)),
        ] {
            let same = a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
            assert!(
                same,
                "{} {form:?} {method:?} rtol {rtol:e}, row at t = {t}: {a:?} with two rows, {b:?} with 500",
                model.info().name
            );
        }
    }
}

#[test]
fn projected_rows_do_not_depend_on_the_grid() {
    let body = pfaff_models::free_body::Model::default();
    let four_bar = pfaff_models::spatial_four_bar::Model::default();
    let disk = pfaff_models::rolling_disk::Model::default();
    for method in [Method::Dopri5, Method::Adams] {
        rows_agree(&body, Formulation::Projection, method, 1e-3, 1.0);
        rows_agree(&four_bar, Formulation::Projection, method, 1e-3, 2.0);
        rows_agree(&disk, Formulation::Projection, method, 1e-6, 5.0);
    }
}

#[test]
fn partitioned_rows_do_not_depend_on_the_grid() {
    let bricard = pfaff_models::bricard::Model::default();
    let four_bar = pfaff_models::spatial_four_bar::Model::default();
    rows_agree(
        &bricard,
        Formulation::Partitioning,
        Method::Adams,
        1e-6,
        10.0,
    );
    rows_agree(
        &four_bar,
        Formulation::Partitioning,
        Method::Adams,
        1e-6,
        2.0,
    );
}
