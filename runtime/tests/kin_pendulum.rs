//! The Cartesian pendulum: singular partition, redundant constraints, Newton failure,
//! assembly errors and non-finite input.

mod common;

use common::Pendulum;
use pfaff::{
    AssemblyError, Dynamics, DynamicsParams, EvalError, Kinematics, KinematicsError,
    KinematicsParams, LinearSolver, Mechanism, PartitionError, Prescription, Quantity, SolverPath,
    StateLevel, Workspace,
};

#[test]
fn hanging_pendulum_forces_repartition_to_y() {
    let mech = Pendulum::new(false);
    let mut ws = Workspace::new(mech.info()).unwrap();
    let mut kin = Kinematics::new(mech.info(), KinematicsParams::default());
    let q0 = [1.2_f64.sin(), -1.2_f64.cos()];
    let p = kin.repartition(&mech, &mut ws, 0.0, &q0).unwrap();
    assert_eq!(p.names()[0], ["x"]);
    let reference = p.reference_condition();
    assert!((reference.holonomic - 1.0).abs() < 1e-15);
    // Swing down to x = 0: C_β = 2x vanishes.
    let mut q = [0.3, -0.9];
    kin.position(&mech, &mut ws, 0.0, &mut q).unwrap(); // moves x (y fixed)
    assert!((q[0] * q[0] + q[1] * q[1] - 1.0).abs() < 1e-14);
    assert!(!kin.monitor(&mech, &mut ws, 0.0, &q).unwrap());
    let hanging = [0.0, -1.0];
    let now = kin.condition(&mech, &mut ws, 0.0, &hanging).unwrap();
    assert_eq!(now.holonomic, 0.0);
    assert!(kin.monitor(&mech, &mut ws, 0.0, &hanging).unwrap());
    assert_eq!(kin.repartitions(), 1);
    assert_eq!(kin.partition().unwrap().names()[0], ["y"]);
    // K1 with x fixed near the bottom now works.
    let mut q = [0.01, -0.98];
    let stats = kin.position(&mech, &mut ws, 0.0, &mut q).unwrap();
    assert!(
        (q[1] + (1.0 - 0.0001_f64).sqrt()).abs() < 1e-14,
        "{stats:?}"
    );
}

#[test]
fn singular_dependent_block_during_newton_is_typed() {
    let mech = Pendulum::new(false);
    let mut ws = Workspace::new(mech.info()).unwrap();
    let mut kin = Kinematics::new(mech.info(), KinematicsParams::default());
    kin.repartition(&mech, &mut ws, 0.0, &[0.9, -0.4]).unwrap();
    let mut q = [0.0, -0.5];
    let err = kin.position(&mech, &mut ws, 0.0, &mut q).unwrap_err();
    assert!(
        matches!(err, KinematicsError::SingularDependent { iteration: 1, .. }),
        "{err}"
    );
}

#[test]
fn newton_failure_names_the_violated_constraint() {
    let mech = Pendulum::new(false);
    let mut ws = Workspace::new(mech.info()).unwrap();
    let mut kin = Kinematics::new(mech.info(), KinematicsParams::default());
    kin.repartition(&mech, &mut ws, 0.0, &[0.1, -0.99]).unwrap(); // β = {y}
    let mut q = [1.5, -0.5]; // |x| > l: no y satisfies the rod
    let err = kin.position(&mech, &mut ws, 0.25, &mut q).unwrap_err();
    println!("{err}");
    match err {
        KinematicsError::NewtonFailed {
            t,
            iterations,
            residual,
            violated,
        } => {
            assert_eq!(t, 0.25);
            assert_eq!(iterations, 25);
            assert!(residual > 1.0);
            assert_eq!(violated, ["rod"]);
        }
        other => panic!("unexpected {other:?}"),
    }
    // Assembly from an impossible prescription reports the same failure.
    let (mut q, mut qd) = ([0.5, -0.5], [0.0; 2]);
    let err = kin
        .assemble(
            &mech,
            &mut ws,
            0.0,
            &mut q,
            &mut qd,
            &Prescription {
                coordinates: &[("x", 1.5)],
                velocities: &[],
            },
        )
        .unwrap_err();
    println!("{err}");
    assert!(matches!(
        err,
        AssemblyError::Kinematics(KinematicsError::NewtonFailed { .. })
    ));
}

#[test]
fn assembly_errors_are_clear() {
    let mech = Pendulum::new(false);
    let mut ws = Workspace::new(mech.info()).unwrap();
    let mut kin = Kinematics::new(mech.info(), KinematicsParams::default());
    let (mut q, mut qd) = ([0.5, -0.5], [0.0; 2]);
    let mut run = |p: Prescription<'_>| {
        kin.assemble(&mech, &mut ws, 0.0, &mut q, &mut qd, &p)
            .unwrap_err()
    };
    // Every coordinate given, off the circle: the residual x² + y² − l² = 0.25 − 1.
    let err = run(Prescription {
        coordinates: &[("x", 0.3), ("y", -0.4)],
        velocities: &[],
    });
    println!("{err}");
    match &err {
        AssemblyError::Inconsistent { level, violated } => {
            assert_eq!(*level, StateLevel::Positions);
            assert_eq!(violated.len(), 1);
            assert_eq!(violated[0].constraint, "rod");
            assert!((violated[0].residual + 0.75).abs() < 1e-15);
        }
        other => panic!("{other:?}"),
    }
    assert!(err.to_string().contains("`rod` by -7.500e-1"), "{err}");
    // Every velocity given, not tangent at the assembled position: C_q q̇ = 2x·1 + 2y·0
    // with x ≥ 0.3 on the circle.
    let err = run(Prescription {
        coordinates: &[],
        velocities: &[("x", 1.0), ("y", 0.0)],
    });
    println!("{err}");
    match &err {
        AssemblyError::Inconsistent { level, violated } => {
            assert_eq!(*level, StateLevel::Velocities);
            assert_eq!(violated[0].constraint, "rod");
            assert!(violated[0].residual >= 0.6, "{violated:?}");
        }
        other => panic!("{other:?}"),
    }
    let err = run(Prescription {
        coordinates: &[("theta", 0.6)],
        velocities: &[],
    });
    println!("{err}");
    assert!(matches!(err, AssemblyError::UnknownCoordinate { .. }));
    // A valid one: x = 0.6, x' = 0.8 on the lower branch.
    let (mut q, mut qd) = ([0.5, -0.5], [0.0; 2]);
    kin.assemble(
        &mech,
        &mut ws,
        0.0,
        &mut q,
        &mut qd,
        &Prescription {
            coordinates: &[("x", 0.6)],
            velocities: &[("x", 0.8)],
        },
    )
    .unwrap();
    assert!((q[1] + 0.8).abs() < 1e-14 && (qd[1] - 0.6).abs() < 1e-14);
}

/// Assembles the Cartesian pendulum from the guess `q` (at rest) with the coordinates
/// `held`: the report, positions and velocities.
fn assemble_from(q: [f64; 2], held: &[(&str, f64)]) -> (pfaff::AssemblyReport, [f64; 2], [f64; 2]) {
    let mech = Pendulum::new(false);
    let mut ws = Workspace::new(mech.info()).unwrap();
    let mut kin = Kinematics::new(mech.info(), KinematicsParams::default());
    let (mut q, mut qd) = (q, [0.0; 2]);
    let prescription = Prescription {
        coordinates: held,
        velocities: &[],
    };
    let report = kin
        .assemble(&mech, &mut ws, 0.0, &mut q, &mut qd, &prescription)
        .unwrap();
    (report, q, qd)
}

/// Holding `x` from a guess where `y` is not determined (y = 0, where ∂C/∂y = 2y
/// vanishes) holds it anyway: the guess of `y` is moved by `GUESS_NUDGE` toward the
/// lower potential energy (down: gravity along −y), reported, and Newton reaches the
/// branch y = −0.8 (x² + y² = 1). The prescribed value is never traded for a guess.
#[test]
fn a_prescription_from_a_singular_guess_is_held() {
    let (report, q, _) = assemble_from([1.0, 0.0], &[("x", 0.6)]);
    assert_eq!(q[0], 0.6);
    assert!((q[1] + 0.8).abs() < 1e-14, "{q:?}");
    assert_eq!(
        report.moved_guesses,
        [pfaff::MovedGuess {
            coordinate: "y",
            guess: 0.0,
            moved_to: -pfaff::GUESS_NUDGE,
        }]
    );
    // From a guess that serves, nothing is moved.
    let (report, q, _) = assemble_from([0.5, -0.5], &[("x", 0.6)]);
    assert!(report.moved_guesses.is_empty());
    assert!((q[1] + 0.8).abs() < 1e-14, "{q:?}");
}

/// Holding `y = −1` (hanging straight down) from the guess x = 1 asks Newton for the
/// double root of x² = 0, where the dependent block 2x vanishes: the updates only halve
/// x, so they never settle below the tolerance, but the constraint is met to it
/// (x ≈ 3e-8 after 25 updates, x² ≈ 9e-16). The assembly accepts that state: the
/// positions meet the constraints, which is what is asked of them.
#[test]
fn a_prescription_at_a_double_root_is_assembled() {
    let (report, q, qd) = assemble_from([1.0, 0.0], &[("y", -1.0)]);
    println!("{report:?} {q:?}");
    assert_eq!(q[1], -1.0);
    // Met to the tolerance (1e-14 relative to the row's norm 2): |x| ≤ √(2e-14).
    assert!((q[0] * q[0] + q[1] * q[1] - 1.0).abs() <= 2e-14);
    assert!(q[0].abs() < 2e-7, "{q:?}");
    assert_eq!(qd, [0.0, 0.0]);
}

/// A full state (every coordinate and velocity) on the constraints is kept as given,
/// bit for bit, within the consistency tolerance: x = 0.6, y = −0.8 (x² + y² = 1 up to
/// round-off) turning at 1.5 rad/s, and the same off by 1e-10 relative.
#[test]
fn a_full_consistent_state_is_accepted_as_given() {
    let mech = Pendulum::new(false);
    let mut ws = Workspace::new(mech.info()).unwrap();
    let mut kin = Kinematics::new(mech.info(), KinematicsParams::default());
    for off in [0.0, 1e-10] {
        let given = ([0.6 * (1.0 + off), -0.8], [0.8 * 1.5, 0.6 * 1.5]);
        let (mut q, mut qd) = ([0.0, -1.0], [0.0; 2]);
        let report = kin
            .assemble(
                &mech,
                &mut ws,
                0.0,
                &mut q,
                &mut qd,
                &Prescription {
                    coordinates: &[("x", given.0[0]), ("y", given.0[1])],
                    velocities: &[("x", given.1[0]), ("y", given.1[1])],
                },
            )
            .unwrap();
        assert_eq!((q, qd), given);
        assert_eq!(report.newton.iterations, 0);
        assert!(report.newton.residual <= 2.0 * off + 1e-15);
    }
    // Off by 1e-6: the check fails, at the positions first.
    let (mut q, mut qd) = ([0.0; 2], [0.0; 2]);
    let err = kin
        .assemble(
            &mech,
            &mut ws,
            0.0,
            &mut q,
            &mut qd,
            &Prescription {
                coordinates: &[("x", 0.6 * (1.0 + 1e-6)), ("y", -0.8)],
                velocities: &[("x", 1.2), ("y", 0.9)],
            },
        )
        .unwrap_err();
    assert!(matches!(
        err,
        AssemblyError::Inconsistent {
            level: StateLevel::Positions,
            ..
        }
    ));
}

/// A solver that found the duplicated row keeps that split for the next solves: at a
/// second state it must give what a fresh solver gives there (the same equations on the
/// same rows), and on a configuration where the kept rows no longer suffice it must start
/// over from the full system instead of answering from the stale split.
#[test]
fn kept_split_of_redundant_rows_matches_a_fresh_solve() {
    let dup = Pendulum::new(true);
    let states = [
        ([0.6, -0.8], [0.8 * 1.5, 0.6 * 1.5]),
        ([0.8, -0.6], [0.6 * 0.5, 0.8 * 0.5]),
        ([-0.28, -0.96], [0.0, 0.0]),
    ];
    let mut ws = Workspace::new(dup.info()).unwrap();
    let mut kept = Dynamics::new(dup.info(), DynamicsParams::default()).unwrap();
    for (q, qd) in states {
        let (mut a, mut l) = ([0.0; 2], [0.0; 2]);
        let stats = kept
            .accelerations(&dup, &mut ws, 0.0, &q, &qd, &mut a, &mut l)
            .unwrap();
        let mut fresh = Dynamics::new(dup.info(), DynamicsParams::default()).unwrap();
        let (mut a1, mut l1) = ([0.0; 2], [0.0; 2]);
        fresh
            .accelerations(&dup, &mut ws, 0.0, &q, &qd, &mut a1, &mut l1)
            .unwrap();
        assert_eq!(stats.path, SolverPath::Redundant);
        for (x, y) in a.iter().chain(&l).zip(a1.iter().chain(&l1)) {
            assert!(
                (x - y).abs() < 1e-13 * (1.0 + y.abs()),
                "{a:?} {l:?} vs {a1:?} {l1:?}"
            );
        }
    }
    // At the origin both rows vanish and the kept split's reduced matrix is singular:
    // the solve starts over and reports rank 0 with free fall and no multipliers.
    let (mut a, mut l) = ([0.0; 2], [0.0; 2]);
    let stats = kept
        .accelerations(&dup, &mut ws, 0.0, &[0.0, 0.0], &[0.0; 2], &mut a, &mut l)
        .unwrap();
    assert_eq!((stats.path, stats.rank), (SolverPath::Redundant, 0));
    assert!(a[0].abs() < 1e-15 && (a[1] + common::G).abs() < 1e-14);
    assert_eq!(l, [0.0, 0.0], "{l:?}");
}

#[test]
fn duplicated_constraint_gives_minimum_norm_multipliers() {
    let single = Pendulum::new(false);
    let dup = Pendulum::new(true);
    let (q, qd) = ([0.6, -0.8], [0.8 * 1.5, 0.6 * 1.5]);
    let mut ws1 = Workspace::new(single.info()).unwrap();
    let mut d1 = Dynamics::new(single.info(), DynamicsParams::default()).unwrap();
    let (mut a1, mut l1) = ([0.0; 2], [0.0; 1]);
    d1.accelerations(&single, &mut ws1, 0.0, &q, &qd, &mut a1, &mut l1)
        .unwrap();
    for solver in [LinearSolver::Dense, LinearSolver::Sparse] {
        let mut ws = Workspace::new(dup.info()).unwrap();
        let params = DynamicsParams {
            solver,
            ..Default::default()
        };
        let mut d = Dynamics::new(dup.info(), params).unwrap();
        let (mut a, mut l) = ([0.0; 2], [0.0; 2]);
        let stats = d
            .accelerations(&dup, &mut ws, 0.0, &q, &qd, &mut a, &mut l)
            .unwrap();
        let names: Vec<_> = d.redundant_constraints().collect();
        println!("{solver:?}: {stats:?}, redundant {names:?}, lambda {l:?} (single {l1:?})");
        assert_eq!(stats.path, SolverPath::Redundant);
        assert_eq!(stats.rank, 1);
        assert_eq!(names.len(), 1);
        assert!(names[0] == "rod" || names[0] == "rod_copy");
        assert!((a[0] - a1[0]).abs() < 1e-12 && (a[1] - a1[1]).abs() < 1e-12);
        // Equal split: the least-norm λ with λ₁ + λ₂ = λ_single.
        assert!((l[0] - l[1]).abs() < 1e-12);
        assert!((l[0] + l[1] - l1[0]).abs() < 1e-12);
    }
    // Algorithm P refuses the duplicated rows and names them.
    let mut ws = Workspace::new(dup.info()).unwrap();
    let err = pfaff::Partition::compute(
        &dup,
        &mut ws,
        0.0,
        &q,
        Default::default(),
        &Default::default(),
    )
    .unwrap_err();
    println!("{err}");
    assert!(matches!(
        err,
        PartitionError::RedundantHolonomic { rank: 1, rows: 2, ref constraints, .. } if constraints.len() == 1
    ));
}

#[test]
fn inconsistent_redundant_constraints_are_reported() {
    // Both rows of the duplicated pendulum, but a γ that contradicts the copy.
    struct Bad(Pendulum);
    impl Mechanism for Bad {
        fn info(&self) -> &'static pfaff::Info {
            self.0.info()
        }
        fn parameter(&self, i: usize) -> f64 {
            self.0.parameter(i)
        }
        fn set_parameter(&mut self, i: usize, v: f64) {
            self.0.set_parameter(i, v);
        }
        fn mass_matrix(&self, t: f64, q: &[f64], out: &mut [f64]) {
            self.0.mass_matrix(t, q, out);
        }
        fn forces(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
            self.0.forces(t, q, qd, out);
        }
        fn holonomic_jacobian(&self, t: f64, q: &[f64], out: &mut [f64]) {
            self.0.holonomic_jacobian(t, q, out);
        }
        fn holonomic_gamma(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
            self.0.holonomic_gamma(t, q, qd, out);
            out[1] += 1.0;
        }
        fn kinetic_energy(&self, t: f64, q: &[f64], qd: &[f64]) -> f64 {
            self.0.kinetic_energy(t, q, qd)
        }
    }
    let mech = Bad(Pendulum::new(true));
    let mut ws = Workspace::new(mech.info()).unwrap();
    let mut d = Dynamics::new(mech.info(), DynamicsParams::default()).unwrap();
    let (mut a, mut l) = ([0.0; 2], [0.0; 2]);
    let err = d
        .accelerations(&mech, &mut ws, 0.0, &[0.6, -0.8], &[0.0; 2], &mut a, &mut l)
        .unwrap_err();
    println!("{err}");
    assert!(matches!(
        err,
        pfaff::DynamicsError::InconsistentRedundant { .. }
    ));
}

#[test]
fn non_finite_inputs_and_outputs_are_reported() {
    let mech = Pendulum::new(false);
    let mut ws = Workspace::new(mech.info()).unwrap();
    let mut d = Dynamics::new(mech.info(), DynamicsParams::default()).unwrap();
    let (mut a, mut l) = ([0.0; 2], [0.0; 1]);
    let err = d
        .accelerations(
            &mech,
            &mut ws,
            0.0,
            &[f64::NAN, -1.0],
            &[0.0; 2],
            &mut a,
            &mut l,
        )
        .unwrap_err();
    println!("{err}");
    assert!(matches!(
        err,
        pfaff::DynamicsError::Eval(EvalError::NonFinite {
            quantity: Quantity::Coordinates,
            row: 0,
            ..
        })
    ));
    let err = d
        .accelerations(
            &mech,
            &mut ws,
            0.0,
            &[0.6, -0.8],
            &[f64::INFINITY, 0.0],
            &mut a,
            &mut l,
        )
        .unwrap_err();
    assert!(matches!(
        err,
        pfaff::DynamicsError::Eval(EvalError::NonFinite {
            quantity: Quantity::Velocities,
            ..
        })
    ));
    // At the origin C_q = 0: the augmented matrix is singular. At rest the zero row is
    // consistent (rank 0, λ = 0, free fall); in motion it contradicts γ. Never a NaN.
    let stats = d
        .accelerations(&mech, &mut ws, 0.0, &[0.0, 0.0], &[0.0; 2], &mut a, &mut l)
        .unwrap();
    assert_eq!((stats.path, stats.rank), (SolverPath::Redundant, 0));
    assert_eq!(l, [0.0]);
    assert!(a[0].abs() < 1e-15 && (a[1] + common::G).abs() < 1e-14);
    let err = d
        .accelerations(
            &mech,
            &mut ws,
            0.0,
            &[0.0, 0.0],
            &[1.0, 0.0],
            &mut a,
            &mut l,
        )
        .unwrap_err();
    println!("{err}");
    assert!(matches!(
        err,
        pfaff::DynamicsError::InconsistentRedundant { .. }
    ));
    let mut kin = Kinematics::new(mech.info(), KinematicsParams::default());
    let err = kin
        .repartition(&mech, &mut ws, 0.0, &[0.0, 0.0])
        .unwrap_err();
    println!("{err}");
    assert!(matches!(
        err,
        PartitionError::RedundantHolonomic { rank: 0, .. }
    ));
    let err: pfaff::Error = err.into();
    assert!(err.to_string().contains("rod"));
}

#[test]
fn residual_history_describes_the_last_call_even_when_it_fails_early() {
    // The history of a K1 rejected on a NaN input used to be the previous call's, and
    // the simulation counted those iterations again as Newton iterations.
    let mech = Pendulum::new(false);
    let mut ws = Workspace::new(mech.info()).unwrap();
    let mut kin = Kinematics::new(mech.info(), KinematicsParams::default());
    kin.repartition(&mech, &mut ws, 0.0, &[0.6, -0.8]).unwrap();
    let mut q = [0.3, -0.9];
    let stats = kin.position(&mech, &mut ws, 0.0, &mut q).unwrap();
    assert!(stats.iterations > 0);
    assert_eq!(kin.residual_history().len(), stats.iterations + 1);
    let mut q = [f64::NAN, -0.9];
    let err = kin.position(&mech, &mut ws, 0.0, &mut q).unwrap_err();
    assert!(matches!(err, KinematicsError::Eval(_)), "{err}");
    assert!(
        kin.residual_history().is_empty(),
        "{:?}",
        kin.residual_history()
    );
}
