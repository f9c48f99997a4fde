//! The slider-crank: docs/theory.md V10 through the simulation (assembly and the driven
//! motion), a free slider-crank with a flywheel through its dead centres, and a
//! slider-driven crank pushed past its reach.

use std::f64::consts::PI;

use pfaff::sim::{Formulation, Method, SimErrorKind, Simulation};
use pfaff::Mechanism;
use pfaff_models::slider_crank;

use super::models::{flywheel_crank, slider_driven_crank};

/// docs/theory.md V10, table at t = 0: `q` and `q̇`.
#[allow(clippy::approx_constant)] // the table's digits, not a constant
const V10_Q: [f64; 9] = [
    0.043301270189,
    0.025,
    0.523_598_775_598, // π/6 to the 12 decimals of the table
    0.234504534956,
    0.025,
    -0.167448079220,
    0.382406529533,
    0.0,
    0.0,
];
const V10_QD: [f64; 9] = [
    -0.25,
    0.433012701892,
    10.0,
    -0.573192505471,
    0.433012701892,
    -2.927700218846,
    -0.646385010942,
    0.0,
    0.0,
];

/// docs/theory.md V10: $x_B = a\cos\varphi + \sqrt{b^2 - a^2\sin^2\varphi}$ and its rate for
/// $\varphi = \pi/6 + 10t$.
fn slider(t: f64) -> (f64, f64) {
    let (a, b) = (0.1_f64, 0.3_f64);
    let phi = PI / 6.0 + 10.0 * t;
    let r = (b * b - a * a * phi.sin().powi(2)).sqrt();
    let x = a * phi.cos() + r;
    let xd = (-a * phi.sin() - a * a * phi.sin() * phi.cos() / r) * 10.0;
    (x, xd)
}

#[test]
fn v10_driven_motion_with_every_formulation() {
    let model = slider_crank::Model::default();
    // Start from a perturbed guess (±0.01 on every coordinate but the crank angle, as
    // in V10), so the assembly does the work.
    let (mut q, mut qd) = ([0.0; 9], [0.0; 9]);
    model.initial_state(&mut q, &mut qd);
    for (i, v) in q.iter_mut().enumerate() {
        if i != 2 {
            *v += if i % 2 == 0 { 0.01 } else { -0.01 };
        }
    }
    for form in Formulation::ALL {
        let run = Simulation::new(&model)
            .formulation(form)
            .integrator(Method::Dop853)
            .tolerances(1e-10, 1e-12)
            .initial_state(&q, &qd)
            .output_every(0.01)
            .run(1.0)
            .unwrap();
        let tr = &run.trajectory;
        assert_eq!(tr.len(), 101);
        // Algebraic results at t = 0: 1e-9 relative (docs/theory.md §verification); the table has 12
        // decimals.
        for j in 0..9 {
            assert!((tr.q(0)[j] - V10_Q[j]).abs() < 1e-11, "q[{j}] {form:?}");
            assert!(
                (tr.qd(0)[j] - V10_QD[j]).abs() < 1e-9 * 10.0,
                "qd[{j}] {form:?}"
            );
        }
        let mut worst = 0.0_f64;
        for i in 0..tr.len() {
            let (x, xd) = slider(tr.t[i]);
            worst = worst
                .max((tr.q(i)[6] - x).abs())
                .max((tr.qd(i)[6] - xd).abs() / 10.0);
        }
        eprintln!(
            "{:<12} slider error {worst:.1e} C {:.1e} steps {} rhs {}",
            form.name(),
            run.monitors.max_position_violation,
            run.stats.steps,
            run.stats.rhs_evals
        );
        assert!(worst < 1e-8, "{form:?}: {worst:e}");
        if form == Formulation::Partitioning {
            // No degree of freedom: all nine coordinates dependent, no re-partition.
            assert_eq!(run.stats.repartitions, 0);
            assert!(run.monitors.max_position_violation < 1e-12);
        }
    }
}

#[test]
fn flywheel_spins_through_dead_centres_with_partitioning() {
    let model = flywheel_crank::Model::default();
    let mut finals = Vec::new();
    for form in [Formulation::Partitioning, Formulation::Projection] {
        // The slider position and speed of V10 (φ1 = π/6, φ̇1 = 10) are prescribed, so
        // x3 is independent at assembly; it is singular at each dead centre
        // (dx3/dφ1 = 0), which the tangent chart of each step never notices.
        let run = Simulation::new(&model)
            .prescribe_coordinate("x3", V10_Q[6])
            .prescribe_velocity("x3", V10_QD[6])
            .formulation(form)
            .integrator(Method::Dop853)
            .tolerances(1e-9, 1e-11)
            .output_every(0.01)
            .run(2.0)
            .unwrap();
        let phi = run.trajectory.coordinate("phi1").unwrap();
        let m = &run.monitors;
        let e0 = m.energy_initial.unwrap();
        eprintln!(
            "{:<12} phi1(2) {:.9} C {:.1e} Cd {:.1e} dE/E {:.1e} steps {} rhs {} repart {} restarts {}",
            form.name(),
            phi[phi.len() - 1],
            m.max_position_violation,
            m.max_velocity_violation,
            m.max_energy_drift.unwrap() / e0,
            run.stats.steps,
            run.stats.rhs_evals,
            run.stats.repartitions,
            run.stats.restarts
        );
        // About 10 rad/s for 2 s: past six dead centres (φ1 = kπ).
        let dead_centres = ((phi[phi.len() - 1] / PI).floor() - (phi[0] / PI).floor()) as i64;
        assert!(dead_centres >= 6, "{dead_centres}");
        assert!(m.max_position_violation < 1e-10);
        assert!(m.max_velocity_violation < 1e-10);
        assert!(m.max_energy_drift.unwrap() / e0 < 1e-7);
        assert_eq!(run.stats.restarts, 0);
        finals.push(phi[phi.len() - 1]);
    }
    assert!((finals[0] - finals[1]).abs() < 1e-6, "{finals:?}");
}

#[test]
fn slider_driven_past_the_reach_fails_with_time_and_constraints() {
    let model = slider_driven_crank::Model::default();
    // a + b = 0.4 is reached at t* = 0.17593470466577 s (see the model).
    let t_star = (0.4 - 0.382_406_529_533_424_7) / 0.1;
    for form in [Formulation::Partitioning, Formulation::Projection] {
        let err = Simulation::new(&model)
            .formulation(form)
            .integrator(Method::Dopri5)
            .tolerances(1e-8, 1e-10)
            .output_every(0.01)
            .run(0.5)
            .unwrap_err();
        eprintln!("{:<12} {err}", form.name());
        let t = err.t().unwrap();
        assert!(t > t_star - 0.01 && t < t_star + 0.01, "{t}");
        match &err.kind {
            SimErrorKind::NewtonFailed { constraints, .. }
            | SimErrorKind::Singular { constraints, .. } => {
                assert!(!constraints.is_empty(), "{err}");
            }
            other => panic!("{form:?}: unexpected {other:?}"),
        }
        let tr = &err.partial.trajectory;
        assert!(tr.len() >= 17, "{}", tr.len());
        assert!(*tr.t.last().unwrap() < t_star);
        assert!(tr.q.iter().all(|v| v.is_finite()));
    }
}
