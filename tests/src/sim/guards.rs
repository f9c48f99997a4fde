//! The guards that stop a run instead of returning a wrong answer or running on
//! without progress: typed errors with the partial run.

use pfaff::sim::{Formulation, Method, Monitored, SimErrorKind, Simulation};
use pfaff_models::{parallelogram, pendulum};

/// A fixed step of 1e-10 s over 1 s needs 1e10 steps, ten thousand times the default
/// limit of 1e6 attempts: the run stops after the first window of 10 000 attempts
/// (which advanced 1e-6 s, so the rest of the span needs about 1e10 more, beyond the
/// margin of a thousand times the attempts left) with `NoProgress`, instead of
/// spending the whole limit.
#[test]
fn a_run_that_cannot_finish_stops_after_one_window() {
    let model = pendulum::Model::default();
    let err = Simulation::new(&model)
        .integrator(Method::Rk4 { h: 1e-10 })
        .run(1.0)
        .unwrap_err();
    let SimErrorKind::NoProgress {
        window,
        advance,
        needed,
        budget,
        ..
    } = err.kind
    else {
        panic!("{err}");
    };
    assert_eq!(window, 10_000);
    assert!((advance - 1e-6).abs() < 1e-12, "{advance}");
    assert!(needed > 1000.0 * budget as f64, "{needed} {budget}");
    let s = err.partial.stats;
    assert_eq!(s.steps + s.rejected, 10_000);
    // The rows so far are kept, the last at the time the run stopped.
    let (t, _, _) = err.partial.final_state().expect("rows");
    assert_eq!(Some(t), err.t());
}

/// Baumgarte + Radau5 on the parallelogram over 1 s (default rtol 1e-6): the energy
/// fell from 15.24 J to -1.08 J and the run ended on another branch; now it stops
/// with `Diverged` on the energy drift, its last row the state where the drift
/// passed the bound.
#[test]
fn baumgarte_energy_drift_is_a_typed_error() {
    let model = parallelogram::Model::default();
    let err = Simulation::new(&model)
        .formulation(Formulation::baumgarte())
        .integrator(Method::Radau5)
        .run(1.0)
        .unwrap_err();
    let SimErrorKind::Diverged {
        t,
        quantity: Monitored::EnergyDrift,
        value,
        bound,
    } = err.kind
    else {
        panic!("{err}");
    };
    assert!(value > bound && t < 1.0, "{value} {bound} {t}");
    let tr = &err.partial.trajectory;
    let last = tr.len() - 1;
    assert_eq!(tr.t[last], t);
    let e0 = tr.energy(0).unwrap();
    assert!((tr.energy(last).unwrap() - e0).abs() > bound);
}

/// The same parallelogram with partitioning and projection, and with Baumgarte at
/// the model's default span, stays within the bounds (the guard does not trip on a
/// correct run).
#[test]
fn correct_runs_pass_the_guards() {
    let model = parallelogram::Model::default();
    for f in Formulation::ALL {
        for m in [Method::Radau5, Method::Dop853, Method::Adams] {
            let run = Simulation::new(&model)
                .formulation(f)
                .integrator(m)
                .run(0.45);
            assert!(run.is_ok(), "{f:?} {m:?}: {}", run.unwrap_err());
        }
    }
}
