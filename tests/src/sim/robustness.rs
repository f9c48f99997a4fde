//! Extremes: tolerances from 1e-2 to 1e-13, a million steps, a mass ratio of 1e8.

use pfaff::sim::{Formulation, Method, Simulation};
use pfaff_models::pendulum;

use super::exact;
use super::models::heavy_light_pendulum;

#[test]
fn every_tolerance_from_1e_2_to_1e_13_completes() {
    let model = pendulum::Model::default();
    for form in Formulation::ALL {
        for method in Method::ADAPTIVE {
            let mut line = String::new();
            for k in 2..=13 {
                let tol = 10f64.powi(-k);
                let run = Simulation::new(&model)
                    .formulation(form)
                    .integrator(method)
                    .tolerances(tol, tol)
                    .output_times(&[])
                    .run(1.0)
                    .unwrap_or_else(|e| panic!("{form:?} {method:?} {tol:e}: {e}"));
                let (t, q, _) = run.final_state().unwrap();
                assert_eq!(t, 1.0);
                let e = exact::pendulum(1.0);
                let err = (q[0] - e[0]).abs().max((q[1] - e[1]).abs());
                line.push_str(&format!(" {err:.0e}"));
                if k == 13 {
                    assert!(err < 1e-10, "{form:?} {method:?}: {err:e}");
                }
            }
            eprintln!("{:<12} {:<6}{line}", form.name(), method.name());
        }
    }
}

#[test]
fn a_million_steps_hold_the_constraints() {
    let model = pendulum::Model::default();
    for form in Formulation::ALL {
        let run = Simulation::new(&model)
            .formulation(form)
            .integrator(Method::Rk4 { h: 1e-4 })
            .output_every(1.0)
            .run(100.0)
            .unwrap();
        let m = &run.monitors;
        eprintln!(
            "{:<12} steps {} C {:.1e} Cd {:.1e} dE {:.1e} repart {} wall {:?}",
            form.name(),
            run.stats.steps,
            m.max_position_violation,
            m.max_velocity_violation,
            m.max_energy_drift.unwrap(),
            run.stats.repartitions,
            run.stats.wall_time
        );
        assert_eq!(run.stats.steps, 1_000_000);
        assert_eq!(run.stats.rhs_evals, 4_000_000);
        assert_eq!(run.trajectory.len(), 101);
        match form {
            Formulation::Baumgarte { .. } => {
                // Damped, not removed: bounded by the truncation error that feeds it.
                assert!(m.max_position_violation < 1e-9);
                assert!(m.max_velocity_violation < 1e-8);
            }
            _ => {
                assert!(m.max_position_violation < 1e-11);
                assert!(m.max_velocity_violation < 1e-11);
            }
        }
        assert!(m.max_energy_drift.unwrap() < 1e-8);
    }
}

#[test]
fn mass_ratio_of_1e8() {
    let model = heavy_light_pendulum::Model::default();
    let mut finals = Vec::new();
    for form in Formulation::ALL {
        let run = Simulation::new(&model)
            .formulation(form)
            .integrator(Method::Dop853)
            .tolerances(1e-10, 1e-12)
            .output_every(0.1)
            .run(2.0)
            .unwrap();
        let m = &run.monitors;
        let (_, q, _) = run.final_state().unwrap();
        eprintln!(
            "{:<12} q {q:.6?} C {:.1e} dE/(m1 g l) {:.1e} steps {} repart {}",
            form.name(),
            m.max_position_violation,
            m.max_energy_drift.unwrap() / 9.81e4,
            run.stats.steps,
            run.stats.repartitions
        );
        assert!(m.max_position_violation < 1e-8);
        assert!(m.max_energy_drift.unwrap() / 9.81e4 < 1e-8);
        finals.push(q.to_vec());
    }
    // The light bob's motion agrees between formulations.
    for f in &finals[1..] {
        for (a, b) in f.iter().zip(&finals[0]) {
            assert!((a - b).abs() < 1e-6, "{finals:?}");
        }
    }
}
