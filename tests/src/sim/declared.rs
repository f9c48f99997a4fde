//! Declared initial velocities and the constraints (issue 9): a velocity that the
//! constraints allow is kept, one they determine from the others is reported with the
//! value used, never silently dropped.

use pfaff::sim::Simulation;

/// `x` declared moving at 1, `y` tied to it.
#[pfaff::mechanism]
pub mod tied {
    static x: Coordinate = Coordinate { q0: 0.0, qd0: 1.0 };
    static y: Coordinate = Coordinate {};
    fn kinetic_energy() -> f64 {
        0.5 * (x.dot().powi(2) + y.dot().powi(2))
    }
    #[holonomic]
    fn tie() -> f64 {
        y - x
    }
}

/// `x` declared at 1 and `y` at 3, tied: both cannot hold.
#[pfaff::mechanism]
pub mod conflicting {
    static x: Coordinate = Coordinate { q0: 0.0, qd0: 1.0 };
    static y: Coordinate = Coordinate { q0: 0.0, qd0: 3.0 };
    fn kinetic_energy() -> f64 {
        0.5 * (x.dot().powi(2) + y.dot().powi(2))
    }
    #[holonomic]
    fn tie() -> f64 {
        y - x
    }
}

#[test]
fn a_declared_velocity_the_constraints_allow_is_kept() {
    let model = tied::Model::default();
    let run = Simulation::new(&model).output_every(0.5).run(1.0).unwrap();
    // Free motion at the declared speed: x = y = t (closed form).
    let (t, q, qd) = run.final_state().unwrap();
    assert_eq!(t, 1.0);
    assert!(
        (q[0] - 1.0).abs() < 1e-12 && (q[1] - 1.0).abs() < 1e-12,
        "{q:?}"
    );
    assert!(
        (qd[0] - 1.0).abs() < 1e-12 && (qd[1] - 1.0).abs() < 1e-12,
        "{qd:?}"
    );
    assert!(run.overridden_velocities.is_empty());
}

#[test]
fn a_declared_velocity_the_constraints_override_is_reported() {
    let model = conflicting::Model::default();
    let run = Simulation::new(&model).run(1.0).unwrap();
    assert_eq!(
        run.overridden_velocities.len(),
        1,
        "{:?}",
        run.overridden_velocities
    );
    let o = run.overridden_velocities[0];
    let (declared, other) = if o.coordinate == "x" {
        (1.0, 3.0)
    } else {
        (3.0, 1.0)
    };
    assert_eq!(o.declared, declared);
    assert!((o.used - other).abs() < 1e-12, "{o:?}");
    let note = o.to_string();
    assert!(note.contains("is determined by the constraints") && note.contains(o.coordinate));
    let (_, _, qd) = run.final_state().unwrap();
    assert!(
        (qd[0] - other).abs() < 1e-12 && (qd[1] - other).abs() < 1e-12,
        "{qd:?}"
    );
}
