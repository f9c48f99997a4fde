//! `chain100`: the spatial chain of 100 rods (issue 10 §6, built for N = 10 and
//! N = 100). Released at rest from the horizontal, it falls under gravity; a run must
//! keep its 400 constraints and its energy, with the same tolerances as `chain10`.

use pfaff::sim::{Formulation, Method, Simulation};
use pfaff_models::{chain10, chain100};

/// The largest constraint violation and the energy drift over `N m g l` (the energy
/// scale of the fall: the initial energy is 0 with the chain at z = 0) of 0.1 s.
fn fall(model: &dyn pfaff::Mechanism, links: f64, formulation: Formulation) -> (f64, f64) {
    let run = Simulation::new(model)
        .formulation(formulation)
        .integrator(Method::Dop853)
        .tolerances(1e-9, 1e-11)
        .run(0.1)
        .unwrap_or_else(|e| panic!("{formulation:?}: {e}"));
    let m = run.monitors;
    // m = 1 kg, l = 0.1 m, g = 9.81 m/s² (models/src/chain/source.rs).
    let scale = links * 1.0 * 9.81 * 0.1;
    (
        m.max_position_violation,
        m.max_energy_drift.expect("conservative") / scale,
    )
}

#[test]
fn hundred_links_keep_their_joints_and_energy() {
    for formulation in [Formulation::Projection, Formulation::Partitioning] {
        for (name, model, links) in [
            (
                "chain10",
                &chain10::Model::default() as &dyn pfaff::Mechanism,
                10.0,
            ),
            ("chain100", &chain100::Model::default(), 100.0),
        ] {
            let (c, drift) = fall(model, links, formulation);
            eprintln!("{name} {formulation:?}: |C| {c:.1e}, energy drift / (N m g l) {drift:.1e}");
            assert!(c < 1e-11, "{name} {formulation:?}: |C| = {c:e}");
            assert!(
                drift < 1e-7,
                "{name} {formulation:?}: energy drift {drift:e}"
            );
        }
    }
}

/// The two formulations agree on `chain100`'s motion: the final positions of the 0.1 s
/// fall at rtol 1e-9 with projection (its step-end projection by the sparse
/// $LDL^\mathsf{T}$) and with partitioning (its chart applied by the sparse factor of
/// $[I\ N^\mathsf{T}; N\ 0]$, the model having 400 rows) within 1e-9 of each other
/// (measured 6.8e-13 at atol 1e-9; here atol 1e-11).
#[test]
fn hundred_links_fall_alike_in_both_formulations() {
    let model = chain100::Model::default();
    let end = |formulation| {
        let run = Simulation::new(&model)
            .formulation(formulation)
            .integrator(Method::Dop853)
            .tolerances(1e-9, 1e-11)
            .output_times(&[])
            .run(0.1)
            .unwrap_or_else(|e| panic!("{formulation:?}: {e}"));
        let (_, q, _) = run.final_state().expect("a final row");
        q.to_vec()
    };
    let (a, b) = (end(Formulation::Projection), end(Formulation::Partitioning));
    let d = a
        .iter()
        .zip(&b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
    let n = a.len();
    let (mut q0, mut qd0) = (vec![0.0; n], vec![0.0; n]);
    pfaff::Mechanism::initial_state(&model, &mut q0, &mut qd0);
    let moved = a
        .iter()
        .zip(&q0)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
    eprintln!("chain100: final positions differ by {d:.1e} (moved by up to {moved:.3})");
    assert!(moved > 1e-2, "the chain fell: moved by {moved:e}");
    assert!(d < 1e-9, "chain100: the formulations differ by {d:e}");
}
