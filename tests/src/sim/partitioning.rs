//! Coordinate partitioning (local tangent-space charts) against projection: as accurate
//! at every tolerance, and one or two Newton updates per evaluation.

use pfaff::sim::{Formulation, Method, Run, Simulation};
use pfaff_models::{andrews, pendulum};

use super::exact;

/// Three periods of the pendulum (docs/models.md: period 2.36784194757624 s).
const T_END: f64 = 3.0 * exact::PENDULUM_PERIOD;

/// The error floor of three periods in double precision: about 2000 steps at the
/// tightest tolerance, each adding a few units of round-off.
const ROUND_OFF: f64 = 2e-11;

/// Largest error of `x, y, ẋ, ẏ` over the rows against the exact solution.
fn max_error(run: &Run) -> f64 {
    let tr = &run.trajectory;
    (0..tr.len())
        .map(|i| {
            let e = exact::pendulum(tr.t[i]);
            let (q, qd) = (tr.q(i), tr.qd(i));
            [q[0], q[1], qd[0], qd[1]]
                .iter()
                .zip(e)
                .fold(0.0_f64, |a, (v, x)| a.max((v - x).abs()))
        })
        .fold(0.0, f64::max)
}

/// The largest error over three periods (rows every 1/200 of the span) with
/// partitioning is within 3× that of projection at every rtol from 1e-3 to 1e-12
/// (atol = rtol/100, RK4 with the step of the work-precision sweep,
/// `t_end·rtol^¼/10`). The largest error over the run, not the final one: at loose
/// tolerances a final error can be small by a lucky phase.
///
/// Exceptions: DOPRI5 at rtol 1e-3 takes steps of a sixth of a swing and both
/// formulations are off by 0.1–1 (measured: partitioning 0.77, projection 0.098); and
/// errors below [`ROUND_OFF`], where the run's round-off decides (measured at rtol
/// 1e-12: partitioning 4e-12 to 2e-11 with the four methods, projection 2e-12 to
/// 7e-11).
#[test]
fn partitioned_error_is_within_three_times_the_projected_one() {
    let model = pendulum::Model::default();
    let mut worst = 0.0_f64;
    for method in [
        Method::Rk4 { h: 0.0 },
        Method::Dopri5,
        Method::Dop853,
        Method::Adams,
    ] {
        for k in 3..=12 {
            let rtol = 10f64.powi(-k);
            let method = match method {
                Method::Rk4 { .. } => Method::Rk4 {
                    h: T_END * rtol.powf(0.25) / 10.0,
                },
                m => m,
            };
            let [part, proj] = [Formulation::Partitioning, Formulation::Projection].map(|f| {
                let run = Simulation::new(&model)
                    .formulation(f)
                    .integrator(method)
                    .tolerances(rtol, rtol / 100.0)
                    .output_every(T_END / 200.0)
                    .run(T_END)
                    .unwrap_or_else(|e| panic!("{} {} {rtol:e}: {e}", f.name(), method.name()));
                max_error(&run)
            });
            let ratio = part / proj;
            eprintln!(
                "{:<6} rtol {rtol:.0e}: partitioning {part:.2e} projection {proj:.2e} ratio {ratio:.2}",
                method.name()
            );
            if method == Method::Dopri5 && k == 3 {
                assert!(part < 1.0 && proj < 1.0, "{part:e} {proj:e}");
                continue;
            }
            if part <= ROUND_OFF {
                continue;
            }
            assert!(
                ratio < 3.0,
                "{} rtol {rtol:e}: ratio {ratio}",
                method.name()
            );
            worst = worst.max(ratio);
        }
    }
    eprintln!("largest ratio {worst:.2}");
}

/// Over `andrews` (0.03 s) at rtol = atol = 1e-8, the Newton updates of the chart
/// (and of the polish of accepted states) average at most 2 per evaluation of the
/// right-hand side, with every adaptive explicit method. Radau5 runs the chart to
/// round-off instead of to its tolerance (its Jacobian is made of differences of the
/// right-hand side, see docs/decisions/0026-implicit-integrator-radau5.md), which costs
/// about one update more: at most 3.
#[test]
fn andrews_takes_at_most_two_newton_updates_per_evaluation() {
    let model = andrews::Model::default();
    for method in Method::ADAPTIVE {
        let run = Simulation::new(&model)
            .formulation(Formulation::Partitioning)
            .integrator(method)
            .tolerances(1e-8, 1e-8)
            .output_times(&[])
            .run(0.03)
            .unwrap();
        let s = &run.stats;
        let per_eval = s.newton_iterations as f64 / s.rhs_evals as f64;
        eprintln!(
            "{:<6} {} updates / {} evaluations = {per_eval:.2}",
            method.name(),
            s.newton_iterations,
            s.rhs_evals
        );
        let bound = if method == Method::Radau5 { 3.0 } else { 2.0 };
        assert!(per_eval <= bound, "{}: {per_eval}", method.name());
        assert!(s.newton_iterations > 0);
    }
}

/// Output rows are corrected onto the constraints and their multipliers solved, work
/// that serves the output and not the integration: `Stats` counts it apart. The same
/// run of `andrews` (the command's default: partitioning + Adams, rtol 1e-6) with 500
/// rows and with none takes the same steps and evaluations and the same integration
/// work, within the final state's row (recorded as an output row in the first run and
/// as the last accepted state in the second); the rows' work appears only in the first.
#[test]
fn the_work_of_output_rows_is_counted_apart() {
    let model = andrews::Model::default();
    let run = |every: Option<f64>| {
        let sim = Simulation::new(&model)
            .formulation(Formulation::Partitioning)
            .integrator(Method::Adams)
            .tolerances(1e-6, 1e-8);
        match every {
            Some(dt) => sim.output_every(dt),
            None => sim.output_times(&[]),
        }
        .run(0.03)
        .unwrap()
        .stats
    };
    let (rows, none) = (run(Some(0.03 / 500.0)), run(None));
    eprintln!("with rows {rows:?}\nwithout   {none:?}");
    assert_eq!((rows.steps, rows.rhs_evals), (none.steps, none.rhs_evals));
    assert!(rows.newton_iterations.abs_diff(none.newton_iterations) <= 2);
    assert!(rows.factorizations.abs_diff(none.factorizations) <= 3);
    // At least the multipliers of each of the 500 rows.
    assert!(rows.output_factorizations >= 500, "{rows:?}");
    assert!(rows.output_newton_iterations > 0, "{rows:?}");
    assert_eq!(
        (none.output_newton_iterations, none.output_factorizations),
        (0, 0)
    );
}

/// The pendulum to t = 1000 s (422 periods) at rtol = atol = 1e-12 with partitioning,
/// with Adams (the command's default) and DOP853 (the library's default): the final
/// position within 1e-7 of the closed form (docs/models.md; the exact solution at
/// t = 1000 is x = −0.683230188552, y = −0.730203060423 by mpmath's `ellipfun`, which
/// `exact::pendulum` reproduces to 1e-12).
#[test]
fn pendulum_to_t_1000_stays_within_1e_7_of_the_closed_form() {
    let model = pendulum::Model::default();
    let e = exact::pendulum(1000.0);
    assert!((e[0] + 0.683_230_188_552).abs() < 1e-12, "{e:?}");
    assert!((e[1] + 0.730_203_060_423).abs() < 1e-12, "{e:?}");
    for method in [Method::Adams, Method::Dop853] {
        let run = Simulation::new(&model)
            .integrator(method)
            .tolerances(1e-12, 1e-12)
            .output_times(&[])
            .run(1000.0)
            .unwrap();
        let (t, q, _) = run.final_state().unwrap();
        assert_eq!(t, 1000.0);
        let err = (q[0] - e[0]).abs().max((q[1] - e[1]).abs());
        eprintln!(
            "{}: error {err:.2e}, {} steps, {:?}",
            method.name(),
            run.stats.steps,
            run.stats.wall_time
        );
        assert!(err < 1e-7, "{}: {err:e}", method.name());
    }
}
