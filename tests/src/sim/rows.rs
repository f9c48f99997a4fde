//! Output rows are functions of the run and the interpolant at their time, not of the
//! other rows: a row is corrected onto the constraints from the integrator's
//! interpolant without reading what the previous row's record left (the mass matrix
//! of the projection's metric) and without teaching the run anything (the chart's
//! contraction rate), so the rows common to two grids are the same bits.
//!
//! Nor do the steps depend on the rows: DOP853 evaluates three dense stages on the
//! steps where the run interpolates, and those neither leave the step's projection
//! their mass matrix nor teach the chart its rate ([`pfaff::ode::OdeSystem::aside`]).
//!
//! The cases are those where rows used to differ
//! (docs/decisions/0023-dense-output-only-where-interpolated.md): projection on Euler
//! parameters, non-holonomic rows and
//! `andrews` (row 0.5 s of `free_body` with DOPRI5 at rtol 1e-3 moved by 4e-11 with 500
//! rows, the final row of `andrews` with DOP853 by 4.4e-7), and partitioning, whose
//! row corrections and dense stages taught the chart its rate.

use pfaff::sim::{Formulation, Method, Simulation};
use pfaff::Mechanism;

/// How far DOP853's rows may differ, relative to $\max(1, |x|)$. A step that prepares
/// the interpolant leaves the point at its last dense stage, so the step's correction
/// evaluates $C$ and $C_q$ at the kept state by the separate generated functions where
/// a step without it has them from the fused terms of its FSAL stage: the same
/// expressions in another schedule, equal to round-off, which `andrews`' velocities
/// (up to 1424 rad/s) carry to 1.5e-11 at the end of its span (the rows differed by
/// 4.4e-7 in the positions when the correction took the dense stage's mass matrix).
const ROUND_OFF: f64 = 1e-9;

/// The rows at `t` of a run written at two times and of the same run on a grid of 500
/// intervals (which holds those times): position and velocity bits, or within
/// [`ROUND_OFF`] for DOP853, and the same steps.
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
            let same = a.iter().zip(b).all(|(x, y)| match method {
                Method::Dop853 => (x - y).abs() <= ROUND_OFF * x.abs().max(1.0),
                _ => x.to_bits() == y.to_bits(),
            });
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
    let andrews = pfaff_models::andrews::Model::default();
    let form = Formulation::Projection;
    for method in [Method::Dopri5, Method::Dop853, Method::Adams] {
        rows_agree(&body, form, method, 1e-3, 1.0);
        rows_agree(&disk, form, method, 1e-6, 5.0);
        rows_agree(&andrews, form, method, 1e-3, 0.03);
    }
    // Not DOP853: on this loop of Euler parameters round-off grows to 1e-7 at rtol 1e-3.
    for method in [Method::Dopri5, Method::Adams] {
        rows_agree(&four_bar, form, method, 1e-3, 2.0);
    }
}

#[test]
fn partitioned_rows_do_not_depend_on_the_grid() {
    let bricard = pfaff_models::bricard::Model::default();
    let four_bar = pfaff_models::spatial_four_bar::Model::default();
    let pendulum = pfaff_models::pendulum::Model::default();
    let form = Formulation::Partitioning;
    let andrews = pfaff_models::andrews::Model::default();
    rows_agree(&bricard, form, Method::Adams, 1e-6, 10.0);
    rows_agree(&four_bar, form, Method::Adams, 1e-6, 2.0);
    // DOP853's round-off (see `ROUND_OFF`) on models that do not amplify it (Bricard's
    // loop and the four-bar's Euler parameters do: 1e-11 to 3e-4 at rtol 1e-3).
    for method in [Method::Dop853, Method::Adams] {
        rows_agree(&pendulum, form, method, 1e-3, 7.0);
        rows_agree(&andrews, form, method, 1e-6, 0.03);
    }
}
