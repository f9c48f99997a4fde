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

/// `window_row` (written with arrays: 4 parallelogram windows, 5 cranks and 4 couplers
/// on 13 revolute joints) is a compound pendulum: the couplers translate with speed
/// `l φ̇`, the cranks turn about their pivots, so `T = ½ J φ̇²` with
/// `J = (N+1) ρ l l²/3 + N ρ d l²` and `V = k sin φ` with
/// `k = g ((N+1) ρ l l/2 + N ρ d l)`. Released at rest at `φ = −π/3`, 30° off the
/// hanging equilibrium, it swings to the other turning point `−2π/3` in half the
/// period of the pendulum of amplitude `θ₀ = π/6`: `T/2 = 2 K(sin(θ₀/2)) / ω₀`,
/// `ω₀² = k/J` (closed form; `K` by the arithmetic-geometric mean).
#[test]
fn a_row_of_windows_swings_as_a_compound_pendulum() {
    use pfaff::Mechanism;
    let model = pfaff_models::window_row::Model::default();
    let info = model.info();
    let names: Vec<&str> = info.coordinates.iter().map(|c| c.name).collect();
    assert_eq!(names.len(), 27, "9 bars, 3 coordinates each: {names:?}");
    assert_eq!(info.holonomic.len(), 26, "13 revolute joints");
    let pc0 = names.iter().position(|n| *n == "pc_0").expect("pc_0");
    let pc4 = names.iter().position(|n| *n == "pc_4").expect("pc_4");
    // Parameters of models/src/window_row.rs.
    let (n, l, d, rho, g): (f64, f64, f64, f64, f64) = (4.0, 0.5, 0.3, 2.0, 9.81);
    let j = (n + 1.0) * rho * l * l * l / 3.0 + n * rho * d * l * l;
    let k = g * ((n + 1.0) * rho * l * l / 2.0 + n * rho * d * l);
    let w0 = (k / j).sqrt();
    let theta0 = std::f64::consts::PI / 6.0;
    let (mut a, mut b) = (1.0_f64, (1.0 - (theta0 / 2.0).sin().powi(2)).sqrt());
    for _ in 0..30 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    let kk = std::f64::consts::PI / (2.0 * a);
    let half = 2.0 * kk / w0;
    for formulation in [Formulation::Projection, Formulation::Partitioning] {
        let run = Simulation::new(&model)
            .formulation(formulation)
            .integrator(Method::Dop853)
            .tolerances(1e-10, 1e-12)
            .output_times(&[])
            .run(half)
            .unwrap_or_else(|e| panic!("{formulation:?}: {e}"));
        let (_, q, qd) = run.final_state().expect("a final row");
        let target = -2.0 * std::f64::consts::PI / 3.0;
        eprintln!(
            "window_row {formulation:?}: phi(T/2) = {:.12} (closed form {target:.12}), \
             phi' = {:.1e}, |C| {:.1e}",
            q[pc0], qd[pc0], run.monitors.max_position_violation
        );
        assert!(
            (q[pc0] - target).abs() < 1e-7,
            "{formulation:?}: {}",
            q[pc0]
        );
        assert!((q[pc4] - q[pc0]).abs() < 1e-9, "the cranks stay parallel");
        assert!(qd[pc0].abs() < 1e-5, "a turning point: {}", qd[pc0]);
        assert!(run.monitors.max_position_violation < 1e-10);
    }
}
