//! The `parallelogram` (a redundant third crank) simulated over 5 s: drift makes the
//! redundant rows slightly inconsistent, which the acceleration solve must absorb in
//! the least-squares sense while naming the redundant constraint in the run.

use std::f64::consts::FRAC_PI_2;

use pfaff::sim::{Formulation, Method, Simulation};
use pfaff_models::parallelogram;

#[test]
fn parallelogram_simulates_with_projection_and_partitioning() {
    let model = parallelogram::Model::default();
    // Hanging, released 0.6 rad from the bottom: the swing stays clear of the flat
    // configurations θ = 0, ±π, where the x rows of all three pins coincide (rank 4,
    // a change point of the parallelogram, singular for every formulation). The
    // default state swings through them every half period.
    let (l, th) = (0.5, -FRAC_PI_2 + 0.6);
    let q0 = [th, th, th, l * th.cos(), l * th.sin(), 0.0];
    for (form, method, rtol) in [Formulation::Projection, Formulation::Partitioning]
        .into_iter()
        .flat_map(|f| Method::ADAPTIVE.map(|m| (f, m)))
        .flat_map(|(f, m)| [(f, m, 1e-4), (f, m, 1e-8)])
    {
        let run = Simulation::new(&model)
            .formulation(form)
            .integrator(method)
            .initial_state(&q0, &[0.0; 6])
            .tolerances(rtol, rtol)
            .output_every(0.1)
            .run(5.0)
            .unwrap_or_else(|e| panic!("{} {}: {e}", form.name(), method.name()));
        let m = &run.monitors;
        eprintln!(
            "{} {} {rtol:.0e}: redundant {:?} C {:.1e} Cd {:.1e} dE {:.1e}",
            form.name(),
            method.name(),
            run.redundant_constraints,
            m.max_position_violation,
            m.max_velocity_violation,
            m.max_energy_drift.unwrap_or(f64::NAN)
        );
        assert_eq!(run.trajectory.len(), 51);
        assert_eq!(
            run.redundant_constraints.len(),
            1,
            "{:?}",
            run.redundant_constraints
        );
        assert!(m.max_position_violation < 1e-10);
        assert!(m.max_energy_drift.unwrap() < 1e3 * rtol);
    }
}
