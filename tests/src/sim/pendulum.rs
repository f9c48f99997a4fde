//! The `pendulum` model against its exact solution (docs/models.md), with every
//! formulation and integrator; convergence orders and tolerance proportionality.

use pfaff::sim::{Formulation, Method, Run, Simulation};
use pfaff_models::pendulum;

use super::exact;

/// Largest error of `x, y, ẋ, ẏ` over all rows against the exact solution, in the
/// mixed norm of `rtol = atol` runs: $\max_i |e_i| / (1 + |x_i|)$.
fn max_error(run: &Run) -> f64 {
    let tr = &run.trajectory;
    (0..tr.len())
        .map(|i| {
            let e = exact::pendulum(tr.t[i]);
            let (q, qd) = (tr.q(i), tr.qd(i));
            [q[0], q[1], qd[0], qd[1]]
                .iter()
                .zip(e)
                .fold(0.0_f64, |a, (v, x)| a.max((v - x).abs() / (1.0 + x.abs())))
        })
        .fold(0.0, f64::max)
}

/// Error of the final position only.
fn final_error(run: &Run) -> f64 {
    let (t, q, _) = run.final_state().unwrap();
    let e = exact::pendulum(t);
    (q[0] - e[0]).abs().max((q[1] - e[1]).abs())
}

#[test]
fn exact_solution_checks() {
    // sn(K | m) = 1, cn(K) = 0 and dn(K) = √(1 − m) (A&S 16.5.1); sn(0) = 0.
    let (sn, cn, dn) = exact::jacobi(exact::K_HALF, 0.5);
    assert!((sn - 1.0).abs() < 1e-15 && cn.abs() < 1e-8, "{sn} {cn}");
    assert!((dn - 0.5_f64.sqrt()).abs() < 1e-15, "{dn}");
    let (sn0, cn0, dn0) = exact::jacobi(0.0, 0.5);
    assert!(sn0 == 0.0 && cn0 == 1.0 && dn0 == 1.0);
    // sn² + cn² = 1 and dn² + m sn² = 1 at an arbitrary argument.
    let (s, c, d) = exact::jacobi(0.7, 0.5);
    assert!((s * s + c * c - 1.0).abs() < 1e-15);
    assert!((d * d + 0.5 * s * s - 1.0).abs() < 1e-15);
    // The exact pendulum returns to its start after one period
    // (docs/models.md: 2.36784194757624 s) and is at the bottom at a quarter.
    let e = exact::pendulum(exact::PENDULUM_PERIOD);
    assert!((e[0] - 1.0).abs() < 1e-12 && e[1].abs() < 1e-12, "{e:?}");
    let b = exact::pendulum(exact::PENDULUM_PERIOD / 4.0);
    assert!(b[0].abs() < 1e-12 && (b[1] + 1.0).abs() < 1e-12, "{b:?}");
    // Energy: ½v² + g y = 0 all along.
    let e = exact::pendulum(0.37);
    assert!((0.5 * (e[2] * e[2] + e[3] * e[3]) + 9.81 * e[1]).abs() < 1e-12);
}

#[test]
fn every_formulation_and_method_follows_the_exact_solution() {
    let model = pendulum::Model::default();
    let rtol = 1e-9;
    let mut failures = 0;
    for form in Formulation::ALL {
        for method in [
            Method::Rk4 { h: 1e-3 },
            Method::Dopri5,
            Method::Dop853,
            Method::Adams,
        ] {
            let run = Simulation::new(&model)
                .formulation(form)
                .integrator(method)
                .tolerances(rtol, rtol)
                .output_every(0.05)
                .run(3.0)
                .unwrap();
            let err = max_error(&run);
            let m = &run.monitors;
            eprintln!(
                "{:<12} {:<6} err {err:.2e} C {:.1e} Cd {:.1e} dE {:.1e} steps {} rhs {} repart {} restarts {}",
                form.name(),
                method.name(),
                m.max_position_violation,
                m.max_velocity_violation,
                m.max_energy_drift.unwrap(),
                run.stats.steps,
                run.stats.rhs_evals,
                run.stats.repartitions,
                run.stats.restarts,
            );
            assert_eq!(run.trajectory.len(), 61);
            // Integrated results: solver tolerance × 100 (docs/theory.md §verification); RK4 with
            // h = 1e-3 has a global error of order h⁴·ω⁴ ≈ 1e-10.
            let bound = 1e2;
            failures += usize::from(err >= bound * rtol);
            assert!(m.max_energy_drift.unwrap() < 1e3 * rtol);
            match form {
                Formulation::Partitioning => {
                    // The bob passes x = 0 and y = 0, where a fixed choice of dependent
                    // coordinate is singular; the chart of each step follows without a
                    // restart.
                    assert_eq!(run.stats.restarts, 0);
                    assert!(m.max_position_violation < 1e-11);
                    assert!(m.max_velocity_violation < 1e-11);
                }
                Formulation::Projection => {
                    assert_eq!(run.stats.repartitions, 0);
                    assert!(m.max_position_violation < 1e-11);
                    assert!(m.max_velocity_violation < 1e-11);
                }
                Formulation::Baumgarte { .. } => {
                    assert_eq!(run.stats.restarts, 0);
                    assert!(m.max_position_violation < 100.0 * rtol);
                }
                Formulation::Unconstrained => unreachable!("not in Formulation::ALL"),
            }
        }
    }
    // Integrated results: solver tolerance × 100 (docs/theory.md §verification), in the mixed norm.
    assert_eq!(failures, 0);
}

#[test]
fn rk4_error_drops_sixteenfold_per_halving() {
    let model = pendulum::Model::default();
    for form in Formulation::ALL {
        let errors: Vec<f64> = [0.01, 0.005, 0.0025, 0.00125]
            .iter()
            .map(|&h| {
                let run = Simulation::new(&model)
                    .formulation(form)
                    .integrator(Method::Rk4 { h })
                    .output_times(&[])
                    .run(1.0)
                    .unwrap();
                final_error(&run)
            })
            .collect();
        let ratios: Vec<f64> = errors.windows(2).map(|w| w[0] / w[1]).collect();
        eprintln!("{:<12} errors {errors:?} ratios {ratios:.1?}", form.name());
        for r in ratios {
            assert!((12.0..22.0).contains(&r), "{form:?}: {errors:?}");
        }
    }
}

#[test]
fn adaptive_errors_stay_within_ten_times_the_tolerance() {
    let model = pendulum::Model::default();
    for form in Formulation::ALL {
        for method in Method::ADAPTIVE {
            let mut line = String::new();
            let mut worst = 0.0_f64;
            for k in 4..=11 {
                let tol = 10f64.powi(-k);
                let run = Simulation::new(&model)
                    .formulation(form)
                    .integrator(method)
                    .tolerances(tol, tol)
                    .output_times(&[])
                    .run(0.4)
                    .unwrap();
                let err = final_error(&run);
                line.push_str(&format!(" {:.2}", err / tol));
                worst = worst.max(err / tol);
            }
            eprintln!("{:<12} {:<6} err/tol:{line}", form.name(), method.name());
            assert!(worst < 10.0, "{form:?} {method:?}: {line}");
        }
    }
}

#[test]
fn works_through_a_trait_object() {
    // The command-line program holds `Box<dyn Mechanism>`.
    let entry = pfaff_models::find("pendulum").unwrap();
    let model: Box<dyn pfaff::Mechanism> = (entry.make)();
    let mut calls = 0;
    let run = Simulation::new(model.as_ref())
        .formulation(Formulation::Partitioning)
        .integrator(Method::Adams)
        .tolerances(1e-8, 1e-10)
        .output_times(&[0.5, 1.0, 1.5])
        .on_progress(|_| calls += 1)
        .run(2.0)
        .unwrap();
    assert_eq!(run.trajectory.t, [0.0, 0.5, 1.0, 1.5, 2.0]);
    assert_eq!(calls as u64, run.stats.steps);
    assert!(max_error(&run) < 1e-6);
}

/// Coordinate partitioning with each adaptive method over a period at every tolerance
/// from 1e-3 to 1e-12: a Newton guess extrapolated over a long trial step once
/// converged to the mirror assembly (`x → −x`, a final error of 2) and the step was
/// accepted. Now the evaluation that switches branches rejects the attempt.
///
/// Bound: the error of the rows against the exact solution (mixed norm) stays below
/// `1e2·rtol` (global errors of adaptive codes run 10–100× the local tolerance over a
/// period), and the signs of `x` and `y` agree with the exact solution wherever it is
/// not near zero: never the mirror branch.
#[test]
fn partitioning_never_lands_on_the_mirror_branch() {
    let model = pendulum::Model::default();
    for method in Method::ADAPTIVE {
        for k in 3..=12 {
            let rtol = 10f64.powi(-k);
            let run = Simulation::new(&model)
                .formulation(Formulation::Partitioning)
                .integrator(method)
                .tolerances(rtol, rtol)
                .output_every(exact::PENDULUM_PERIOD / 40.0)
                .run(exact::PENDULUM_PERIOD)
                .unwrap();
            let tr = &run.trajectory;
            for i in 0..tr.len() {
                let e = exact::pendulum(tr.t[i]);
                for (v, x) in tr.q(i).iter().zip(&e[..2]) {
                    if x.abs() > 0.1 {
                        assert_eq!(
                            v.signum(),
                            x.signum(),
                            "{} rtol {rtol:e}: mirror branch at t = {}",
                            method.name(),
                            tr.t[i]
                        );
                    }
                }
            }
            let (err, fin) = (max_error(&run), final_error(&run));
            eprintln!(
                "{:<6} rtol {rtol:.0e}: max {err:.2e} final {fin:.2e} steps {} rejected {}",
                method.name(),
                run.stats.steps,
                run.stats.rejected
            );
            assert!(err < 1e2 * rtol, "{} rtol {rtol:e}: {err:e}", method.name());
        }
    }
}

/// DOP853 with projection: 12 evaluations per accepted step (stages 2–12, the FSAL
/// stage $f(t+h, y_{n+1})$, whose derivative the next step keeps through the
/// projection), 11 per rejected attempt and 1 at the start ($f(t_0)$; the first step
/// is given, so Hairer's `HINIT` does not run); the interpolant's three stages (14–16
/// of `dop853.f`) only when the run has rows to interpolate, on the same steps
/// (docs/decisions/0023-dense-output-only-where-interpolated.md). The first step,
/// a fifth of a period, is far too long for rtol 1e-8, so the run starts with
/// rejections.
#[test]
fn dop853_pays_for_dense_output_only_when_rows_interpolate() {
    let model = pendulum::Model::default();
    let run = |sim: Simulation<'_, _>| {
        sim.formulation(Formulation::Projection)
            .integrator(Method::Dop853)
            .initial_step(0.5)
            .tolerances(1e-8, 1e-8)
            .run(3.0)
            .unwrap()
    };
    let end = run(Simulation::new(&model).output_times(&[]));
    let steps = run(Simulation::new(&model).output_steps());
    let grid = run(Simulation::new(&model).output_every(0.01));
    let s = &end.stats;
    eprintln!(
        "steps {} rejected {} evaluations {} {} {}",
        s.steps, s.rejected, s.rhs_evals, steps.stats.rhs_evals, grid.stats.rhs_evals
    );
    assert!(s.steps > 20 && s.rejected > 0, "{s:?}");
    assert_eq!(s.rhs_evals, 12 * s.steps + 11 * s.rejected + 1);
    for other in [&steps, &grid] {
        assert_eq!(
            (other.stats.steps, other.stats.rejected),
            (s.steps, s.rejected)
        );
    }
    assert_eq!(steps.stats.rhs_evals, s.rhs_evals);
    assert_eq!(grid.stats.rhs_evals, s.rhs_evals + 3 * s.steps);
    assert_eq!(grid.trajectory.len(), 301);
    // The same steps: the final states agree but for the rounding of the interpolant
    // at its end point.
    let (a, b) = (end.final_state().unwrap(), grid.final_state().unwrap());
    assert_eq!(a.0, b.0);
    for (x, y) in a.1.iter().chain(a.2).zip(b.1.iter().chain(b.2)) {
        assert!((x - y).abs() <= 1e-12 * (1.0 + x.abs()), "{x} {y}");
    }
}

/// On a grid coarser than the steps, DOP853 prepares its interpolant only on the
/// steps that reach a row: three evaluations per row at most, not per step; the rows
/// follow the exact solution (docs/models.md) as the steps do.
#[test]
fn dop853_interpolates_only_on_steps_that_reach_a_row() {
    let model = pendulum::Model::default();
    let run = |sim: Simulation<'_, _>| {
        sim.formulation(Formulation::Projection)
            .integrator(Method::Dop853)
            .tolerances(1e-9, 1e-9)
            .run(30.0)
            .unwrap()
    };
    let end = run(Simulation::new(&model).output_times(&[]));
    let grid = run(Simulation::new(&model).output_every(3.0));
    let (s, g) = (&end.stats, &grid.stats);
    eprintln!(
        "steps {} evaluations {} -> {}, error {:.1e}",
        s.steps,
        s.rhs_evals,
        g.rhs_evals,
        max_error(&grid)
    );
    assert_eq!((g.steps, g.rejected), (s.steps, s.rejected));
    assert!(s.steps > 100, "{s:?}");
    let dense = (g.rhs_evals - s.rhs_evals) / 3;
    assert_eq!(g.rhs_evals, s.rhs_evals + 3 * dense);
    assert!(
        (1..=10).contains(&dense),
        "{dense} steps with the interpolant"
    );
    assert_eq!(grid.trajectory.len(), 11);
    // Integrated results: solver tolerance × 1e3 over ten periods.
    assert!(max_error(&grid) < 1e3 * 1e-9);
}
