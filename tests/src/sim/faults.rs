//! Typed failures, each with the partial run.

use pfaff::sim::{Formulation, Method, NonFiniteSource, SimErrorKind, Simulation};
use pfaff::{AssemblyError, KinematicsError, Mechanism, Quantity};
use pfaff_models::pendulum;

use super::models::{flywheel_crank, fragile_pendulum};

#[test]
fn inconsistent_initial_condition_is_an_assembly_error() {
    let model = pendulum::Model::default();
    // x = 2 with a link of length 1: no y satisfies x² + y² = 1. At the default guess
    // y = 0 the column ∂C/∂y vanishes, so the assembly moves y's guess and Newton then
    // fails on `rod`, which it names.
    let err = Simulation::new(&model)
        .prescribe_coordinate("x", 2.0)
        .run(1.0)
        .unwrap_err();
    assert!(
        matches!(
            &err.kind,
            SimErrorKind::Assembly(AssemblyError::Kinematics(
                KinematicsError::NewtonFailed { violated, .. }
            )) if violated == &["rod"]
        ),
        "{err}"
    );
    assert!(err.partial.trajectory.is_empty());
    // The free slider-crank with the slider prescribed beyond the reach a + b = 0.4:
    // x3 stays independent and Newton cannot meet the loop constraints.
    let crank = flywheel_crank::Model::default();
    let err = Simulation::new(&crank)
        .prescribe_coordinate("x3", 0.5)
        .run(1.0)
        .unwrap_err();
    assert!(
        matches!(
            err.kind,
            SimErrorKind::Assembly(AssemblyError::Kinematics(
                KinematicsError::NewtonFailed { .. } | KinematicsError::SingularDependent { .. }
            ))
        ),
        "{err}"
    );
    let err = Simulation::new(&model)
        .prescribe_coordinate("theta", 0.0)
        .run(1.0)
        .unwrap_err();
    assert!(matches!(
        err.kind,
        SimErrorKind::Assembly(AssemblyError::UnknownCoordinate { .. })
    ));
    let err = Simulation::new(&model)
        .initial_state(&[1.0], &[0.0, 0.0])
        .run(1.0)
        .unwrap_err();
    assert!(matches!(
        err.kind,
        SimErrorKind::InitialLength { found: 1, .. }
    ));
}

/// A negative mass: the pendulum's kinetic energy −(ẋ² + ẏ²)/2 is negative along the
/// rod's tangent, a typed error at the start that names the coordinate; a mass
/// matrix singular off the constraints (free_body's Euler parameters, `M θ = 0`) is
/// not one.
#[test]
fn a_negative_mass_is_a_typed_error_at_the_start() {
    let mut model = pendulum::Model::default();
    let m = model.info().parameter_index("m").unwrap();
    model.set_parameter(m, -1.0);
    for formulation in Formulation::ALL {
        let err = Simulation::new(&model)
            .formulation(formulation)
            .run(1.0)
            .unwrap_err();
        match err.kind {
            SimErrorKind::NegativeMass {
                t,
                coordinate,
                ratio,
            } => {
                assert_eq!(t, 0.0);
                // At (1, 0) the tangent is y's direction.
                assert_eq!(coordinate, "y");
                assert!(ratio < -0.5, "{ratio}");
            }
            ref other => panic!("{formulation:?}: {other}"),
        }
        assert!(err.partial.trajectory.is_empty());
    }
    let body = pfaff_models::free_body::Model::default();
    assert!(Simulation::new(&body).run(0.1).is_ok());
    assert_eq!(
        pfaff::inertia::negative_direction(
            &body,
            0.0,
            &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
            &[0.0; 7]
        ),
        Ok(None)
    );
}

#[test]
fn nan_parameter_is_a_non_finite_error() {
    let mut model = pendulum::Model::default();
    let l = model.info().parameter_index("l").unwrap();
    model.set_parameter(l, f64::NAN);
    let err = Simulation::new(&model).run(1.0).unwrap_err();
    assert!(
        matches!(
            err.kind,
            SimErrorKind::NonFinite {
                t: 0.0,
                source_of: NonFiniteSource::Model { .. }
            }
        ),
        "{err}"
    );
}

/// A zero rod: `x² + y² − l²` with `l = 0` holds only at the pivot, where its gradient
/// `(2x, 2y)` vanishes, so it exerts no force and gravity pulls the bob off it. Every
/// formulation ends in the typed error of an inconsistent redundant row, which names
/// the rod as degenerate (its gradient zero), not as implied by other constraints.
#[test]
fn a_degenerate_constraint_is_named_as_such() {
    let mut model = pendulum::Model::default();
    let l = model.info().parameter_index("l").unwrap();
    model.set_parameter(l, 0.0);
    for formulation in Formulation::ALL {
        let err = Simulation::new(&model)
            .formulation(formulation)
            .run(1.0)
            .unwrap_err();
        match &err.kind {
            SimErrorKind::Analysis(pfaff::Error::Dynamics(
                pfaff::DynamicsError::InconsistentRedundant {
                    constraints,
                    vanishing,
                    ..
                },
            )) => {
                assert_eq!(constraints, &["rod"], "{}", formulation.name());
                assert_eq!(vanishing, &["rod"], "{}", formulation.name());
                assert!(
                    err.to_string().contains("gradients of [\"rod\"] are zero"),
                    "{err}"
                );
            }
            other => panic!("{}: {other}", formulation.name()),
        }
    }
}

#[test]
fn nan_during_the_run_keeps_the_partial_trajectory() {
    let model = fragile_pendulum::Model::default();
    for form in Formulation::ALL {
        assert_named_non_finite(Simulation::new(&model), form, Quantity::Forces);
    }
}

/// Runs `sim` under `form` (DOPRI5, rtol 1e-8, atol 1e-10, rows every 0.01 s, to t = 2)
/// and asserts that it fails on a non-finite `quantity` of the model while the bob,
/// released at y = 0, goes below y = −0.5 (θ = 30° below the horizontal, well within
/// the first quarter period, 0.59 s), with the rows before it kept and finite.
fn assert_named_non_finite<M: Mechanism + ?Sized>(
    sim: Simulation<'_, M>,
    form: Formulation,
    quantity: Quantity,
) {
    let err = sim
        .formulation(form)
        .integrator(Method::Dopri5)
        .tolerances(1e-8, 1e-10)
        .output_every(0.01)
        .run(2.0)
        .unwrap_err();
    eprintln!("{:<12} {err}", form.name());
    let SimErrorKind::NonFinite { t, source_of } = err.kind else {
        panic!("{form:?}: {err}");
    };
    assert!(
        matches!(source_of, NonFiniteSource::Model { quantity: q, .. } if q == quantity),
        "{form:?}: {source_of:?}"
    );
    assert!(t > 0.1 && t < 0.6, "{form:?}: {t}");
    let tr = &err.partial.trajectory;
    assert!(tr.len() > 10, "{form:?}");
    let y = tr.coordinate("y").unwrap();
    assert!(
        y.iter().all(|v| v.is_finite() && *v > -0.5),
        "{form:?}: {y:?}"
    );
}

#[test]
fn step_limit_is_a_max_steps_error_with_the_partial_run() {
    let model = pendulum::Model::default();
    let err = Simulation::new(&model)
        .integrator(Method::Rk4 { h: 1e-3 })
        .max_steps(100)
        .run(1.0)
        .unwrap_err();
    assert!(
        matches!(err.kind, SimErrorKind::MaxSteps { steps: 100, .. }),
        "{err}"
    );
    // A row at the start and one per accepted step.
    assert_eq!(err.partial.stats.steps, 100);
    assert_eq!(err.partial.trajectory.len(), 101);
    assert!((err.t().unwrap() - 0.1).abs() < 1e-12);
}

#[test]
fn invalid_times_are_rejected() {
    let model = pendulum::Model::default();
    for (out, t_end) in [(vec![0.5, 0.2], 1.0), (vec![2.0], 1.0), (vec![], -1.0)] {
        let err = Simulation::new(&model)
            .output_times(&out)
            .run(t_end)
            .unwrap_err();
        assert!(
            matches!(err.kind, SimErrorKind::InvalidTimes { .. }),
            "{err}"
        );
    }
}

#[test]
fn a_grid_too_fine_for_memory_is_an_invalid_times_error() {
    // 1e12 rows (or usize::MAX for 1e-300) used to be reserved up front: an abort on a
    // failed allocation or a capacity-overflow panic.
    let model = pendulum::Model::default();
    for dt in [1e-300, 1e-12] {
        let err = Simulation::new(&model)
            .output_every(dt)
            .run(1.0)
            .unwrap_err();
        assert!(
            matches!(err.kind, SimErrorKind::InvalidTimes { value, .. } if value == dt),
            "{err}"
        );
    }
    // A fine grid that fits is still accepted.
    let run = Simulation::new(&model).output_every(1e-4).run(1.0).unwrap();
    assert_eq!(run.trajectory.len(), 10_001);
}

#[test]
fn a_non_positive_first_step_is_an_invalid_step_size() {
    // A negative step used to be taken for a backward integration and reported as an
    // end time behind the start.
    let model = pendulum::Model::default();
    for h in [-1e-3, 0.0, f64::NAN] {
        let err = Simulation::new(&model)
            .initial_step(h)
            .run(1.0)
            .unwrap_err();
        assert!(
            matches!(
                err.kind,
                SimErrorKind::Integrator(pfaff::ode::OdeError::InvalidStepSize { h: e })
                    if e.to_bits() == h.to_bits()
            ),
            "{err}"
        );
        assert_eq!(err.partial.trajectory.len(), 1);
    }
}

#[test]
fn a_non_finite_prescription_names_its_quantity_and_time() {
    // A NaN prescribed velocity used to be reported as a coordinate at t = NaN.
    let model = pendulum::Model::default();
    let err = Simulation::new(&model)
        .start_time(0.25)
        .prescribe_velocity("y", f64::NAN)
        .run(1.0)
        .unwrap_err();
    assert!(
        matches!(
            err.kind,
            SimErrorKind::NonFinite {
                t: 0.25,
                source_of: NonFiniteSource::Model {
                    quantity: Quantity::Velocities,
                    row: 1,
                    col: None
                }
            }
        ),
        "{err}"
    );
    let err = Simulation::new(&model)
        .prescribe_coordinate("x", f64::INFINITY)
        .run(1.0)
        .unwrap_err();
    assert!(
        matches!(
            err.kind,
            SimErrorKind::NonFinite {
                t: 0.0,
                source_of: NonFiniteSource::Model {
                    quantity: Quantity::Coordinates,
                    row: 0,
                    col: None
                }
            }
        ),
        "{err}"
    );
}

/// A first step below what the time resolves is raised to `sim::min_step`, so the
/// restarts after a re-partition (which start with it) do not stop the run (issue 9:
/// `--step 1e-20` stopped Adams, DOPRI5 and DOP853 at the first re-partition).
#[test]
fn a_first_step_the_time_cannot_resolve_is_raised() {
    let model = pendulum::Model::default();
    for method in Method::ADAPTIVE {
        let run = Simulation::new(&model)
            .integrator(method)
            .initial_step(1e-20)
            .run(7.0)
            .unwrap_or_else(|e| panic!("{}: {e}", method.name()));
        assert_eq!(run.final_state().unwrap().0, 7.0);
    }
    assert!(pfaff::sim::min_step(0.0, 7.0) > 10.0 * f64::EPSILON * 7.0);
}

#[test]
fn a_zero_span_is_the_assembled_initial_state() {
    // `run(t0)` assembles and records the start only; the pendulum from x = 1, y = 0
    // at rest hangs from a horizontal link: λ = 0 (no tension at rest, gravity
    // perpendicular to the link).
    let model = pendulum::Model::default();
    let run = Simulation::new(&model).output_every(0.1).run(0.0).unwrap();
    assert_eq!(run.trajectory.len(), 1);
    assert_eq!(run.stats.steps, 0);
    assert_eq!(run.trajectory.t[0], 0.0);
    assert_eq!(run.trajectory.q(0), &[1.0, 0.0]);
    assert!(run.trajectory.lambda(0)[0].abs() < 1e-15);
}

/// A bob on the unit circle under gravity, written by hand, whose $C_q$ is not finite
/// below $y = -0.5$ while $C$ stays finite there: the fused terms of partitioning hand
/// $C_q$ to the velocity projection before any check, so this is the case the
/// projection's fallback checks the terms for.
mod broken_jacobian {
    use pfaff::{Info, Mechanism, Symbol};

    pub struct Model;

    static INFO: Info = Info {
        name: "broken_jacobian",
        coordinates: &[Symbol { name: "x", doc: "" }, Symbol { name: "y", doc: "" }],
        holonomic: &[Symbol {
            name: "rod",
            doc: "",
        }],
        mass_pattern: &[(0, 0), (1, 1)],
        holonomic_pattern: &[(0, 0), (0, 1)],
        ..Info::EMPTY
    };

    impl Mechanism for Model {
        fn info(&self) -> &'static Info {
            &INFO
        }
        fn parameter(&self, _: usize) -> f64 {
            unreachable!("no parameters")
        }
        fn set_parameter(&mut self, _: usize, _: f64) {
            unreachable!("no parameters")
        }
        fn mass_matrix(&self, _: f64, _: &[f64], out: &mut [f64]) {
            out.fill(1.0);
        }
        fn forces(&self, _: f64, _: &[f64], _: &[f64], out: &mut [f64]) {
            out[0] = 0.0;
            out[1] = -9.81;
        }
        fn holonomic(&self, _: f64, q: &[f64], out: &mut [f64]) {
            out[0] = q[0] * q[0] + q[1] * q[1] - 1.0;
        }
        fn holonomic_jacobian(&self, _: f64, q: &[f64], out: &mut [f64]) {
            let broken = if q[1] < -0.5 { f64::NAN } else { 1.0 };
            out[0] = 2.0 * q[0] * broken;
            out[1] = 2.0 * q[1];
        }
        fn kinetic_energy(&self, _: f64, _: &[f64], qd: &[f64]) -> f64 {
            0.5 * (qd[0] * qd[0] + qd[1] * qd[1])
        }
    }
}

/// A non-finite $C_q$ with a finite $C$ is named as $C_q$, at the time the bob crosses
/// $y = -0.5$ (within the first quarter period, 0.59 s), with the run so far kept, in
/// every formulation (partitioning's fused terms reach the velocity projection
/// unchecked; its fallback checks them).
#[test]
fn a_non_finite_jacobian_with_finite_constraints_is_named() {
    let model = broken_jacobian::Model;
    for form in [
        Formulation::Partitioning,
        Formulation::Projection,
        Formulation::Baumgarte {
            alpha: 5.0,
            beta: 5.0,
        },
    ] {
        // Released at rest on the horizontal.
        let sim = Simulation::new(&model).initial_state(&[1.0, 0.0], &[0.0, 0.0]);
        assert_named_non_finite(sim, form, Quantity::HolonomicJacobian);
    }
}

/// A massless bob (`m = 0`): the kinetic energy vanishes, so the mass matrix is
/// singular along the rod's tangent while the rod's gradient $(2x, 2y)$ is regular.
/// Every formulation's first solve fails with the mass matrix named as the cause and
/// no constraint named as nearly dependent (the Jacobian's one row has pivot ratio 1).
#[test]
fn a_massless_bob_blames_the_mass_matrix() {
    let mut model = pendulum::Model::default();
    let m = model.info().parameter_index("m").unwrap();
    model.set_parameter(m, 0.0);
    for formulation in Formulation::ALL {
        let err = Simulation::new(&model)
            .formulation(formulation)
            .run(1.0)
            .unwrap_err();
        let message = err.to_string();
        match &err.kind {
            SimErrorKind::SingularMass {
                jacobian_ratio,
                nearly_dependent,
                ..
            } => {
                assert!(nearly_dependent.is_empty(), "{message}");
                assert!(*jacobian_ratio >= pfaff::NEARLY_DEPENDENT, "{message}");
                assert!(message.contains("mass matrix is singular"), "{message}");
            }
            other => panic!("{}: {other}", formulation.name()),
        }
    }
}

/// A driven slider-crank whose crank is longer than its coupler (`a = 0.35 > b = 0.3`)
/// locks when the crank tip rises to `b` above the guide: the coupler is vertical
/// (`phi2 = -pi/2`), so the vertical closure of the loop, `a sin(phi1) + b sin(phi2) =
/// 0`, no longer depends on `phi2` and restates the driver's prescription of `phi1`.
/// Its rows (`pin_o_y`, `pin_a_y`, `pin_b_y`, `guide_y`) and the driver are the
/// dependent set; the horizontal rows and the slider's angle take no part. The
/// failure names that set, not the one row complete pivoting happens to leave
/// without a pivot (it named `guide_y` alone).
#[test]
fn a_lock_names_the_dependent_set_of_constraints() {
    let mut model = pfaff_models::slider_crank::Model::default();
    let a = model.info().parameter_index("a").unwrap();
    model.set_parameter(a, 0.35);
    // The lock: sin(phi1) = b / a with phi1 = pi/6 + 10 t (the driver).
    let lock = ((0.3_f64 / 0.35).asin() - std::f64::consts::FRAC_PI_6) / 10.0;
    let check = |name: &str, t: f64, named: &[&str], err: &pfaff::sim::SimError| {
        assert!((t - lock).abs() < 1e-3, "{name}: t = {t}, lock at {lock}");
        let mut named = named.to_vec();
        named.sort_unstable();
        assert_eq!(
            named,
            ["driver", "guide_y", "pin_a_y", "pin_b_y", "pin_o_y"],
            "{name}: {err}"
        );
    };
    for formulation in [Formulation::Partitioning, Formulation::Projection] {
        let err = Simulation::new(&model)
            .formulation(formulation)
            .run(0.2)
            .unwrap_err();
        let SimErrorKind::Singular { t, constraints, .. } = &err.kind else {
            panic!("{}: {err}", formulation.name());
        };
        check(formulation.name(), *t, constraints, &err);
    }
    // Baumgarte's index-1 equations have no projection to fail: the accelerations grow
    // without bound at the lock and the step size falls to round-off there, which the
    // failure attributes to the same set.
    let err = Simulation::new(&model)
        .formulation(Formulation::Baumgarte {
            alpha: 10.0,
            beta: 10.0,
        })
        .run(0.2)
        .unwrap_err();
    let SimErrorKind::StepSizeTooSmall {
        t,
        nearly_dependent,
        ..
    } = &err.kind
    else {
        panic!("baumgarte: {err}");
    };
    check("baumgarte", *t, nearly_dependent, &err);
    assert!(err.to_string().contains("nearly dependent there"), "{err}");
}
