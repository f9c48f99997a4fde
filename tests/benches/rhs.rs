//! One right-hand side of each formulation next to the generated functions it calls,
//! in one run, per model:
//!
//! - `generated`: one call of the model's fused `dynamics_terms` ($M$, $Q$, $C_q$,
//!   $\gamma$, $G$, without $C$) and one of `holonomic` ($C$): what every formulation
//!   evaluates at least once per right-hand side (partitioning's correction evaluates
//!   $C$ at the predicted positions, the terms at the corrected ones);
//! - `terms`, `terms+C`: one call of `dynamics_terms` without $C$ and with it: what
//!   asking for $C$ (Baumgarte's shift, the projections after Adams) adds;
//! - `generated+solve`: `dynamics_terms` and the model's generated `augmented_solve`
//!   ($\ddot q$ and $\lambda$ from $M$, $Q$, $J$, $\gamma$): the index-1 right-hand
//!   side in generated code alone, the floor of every formulation's (projection's
//!   own floor: the calls its right-hand side makes);
//! - `floor/partitioning`, `floor/baumgarte`: the generated calls each of those
//!   formulations' right-hand sides makes, in sequence with nothing between them:
//!   partitioning's `holonomic` at the predicted positions, `dynamics_terms_corrected`
//!   at positions that wait for $C$ (a zero update: the dependence of the corrected
//!   positions on $C$ without the correction's work) with the generated
//!   `orthogonal_projection` of the velocities inside it, and the `augmented_solve`; Baumgarte's `dynamics_terms` with $C$ and the
//!   `augmented_solve` (the rates $C_t$, $g$ too where the model has them). A
//!   formulation's `rhs` over its floor is what the runtime adds;
//! - `partitioning`, `projection`, `baumgarte`: one `rhs` of [`StateSpace`] at a moving
//!   state off the constraint manifold by a predictor's error (an Euler step of 1e-3
//!   of the motion's time scale from a consistent state), alternating between two such
//!   states so that nothing is reused from the previous call; partitioning does its
//!   usual Newton update there. Each with the generated solve of the augmented system
//!   (`Auto`), and with the general path it replaces (`…/general`: the dense $LU$
//!   below the crossover, the sparse one from it), side by side in one run.
//!
//! Models: `pendulum`, `andrews`, `chain10` and `chain100` (the spatial chains of 10
//! and 100 rods on ball joints, Euler parameters: n = 70 and 700, 40 and 400
//! constraints). Another model is one entry of [`CASES`].
//!
//! `cargo bench -p pfaff-tests --bench rhs [-- andrews]`

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use pfaff::ode::OdeSystem;
use pfaff::sim::{Formulation, StateSpace};
use pfaff::{AugmentedSolve, DynamicsTerms, LinearSolver, Mechanism, DEFAULT_CROSSOVER};
use pfaff_tests::states::moving_state;

/// A model, and the time after which its state is moving (taken by a tight run from
/// its initial state) and its motion's time scale.
type Case = (&'static str, fn() -> Box<dyn Mechanism>, f64, f64);

const CASES: &[Case] = &[
    (
        "pendulum",
        || Box::new(pfaff_models::pendulum::Model::default()),
        0.3,
        0.3,
    ),
    (
        "andrews",
        || Box::new(pfaff_models::andrews::Model::default()),
        0.01,
        1e-3,
    ),
    (
        "chain10",
        || Box::new(pfaff_models::chain10::Model::default()),
        0.05,
        0.01,
    ),
    (
        "chain100",
        || Box::new(pfaff_models::chain100::Model::default()),
        0.05,
        0.01,
    ),
];

fn generated(c: &mut Criterion, name: &str, model: &dyn Mechanism, t: f64, q: &[f64], qd: &[f64]) {
    let info = model.info();
    let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
    let mut mass = vec![0.0; info.mass_pattern.len()];
    let mut forces = vec![0.0; n];
    let mut cq = vec![0.0; info.holonomic_pattern.len()];
    let mut gamma = vec![0.0; mh + mnh];
    let mut g = vec![0.0; info.nonholonomic_pattern.len()];
    let mut constraints = vec![0.0; mh];
    c.bench_function(&format!("{name}/generated"), |b| {
        b.iter(|| {
            let (gh, gnh) = gamma.split_at_mut(mh);
            model.dynamics_terms(
                black_box(t),
                black_box(q),
                black_box(qd),
                DynamicsTerms {
                    holonomic: None,
                    mass: &mut mass,
                    forces: &mut forces,
                    holonomic_jacobian: &mut cq,
                    holonomic_gamma: gh,
                    nonholonomic_matrix: &mut g,
                    nonholonomic_gamma: gnh,
                },
            );
            model.holonomic(black_box(t), black_box(q), &mut constraints);
            black_box((&mass, &forces, &constraints, &cq));
        });
    });
}

/// `{name}/terms` and `{name}/terms+C`: one call of `dynamics_terms` without and with
/// $C$ asked for, side by side: what $C$ adds to the fused call.
fn terms(c: &mut Criterion, name: &str, model: &dyn Mechanism, t: f64, q: &[f64], qd: &[f64]) {
    let info = model.info();
    let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
    let mut mass = vec![0.0; info.mass_pattern.len()];
    let mut forces = vec![0.0; n];
    let mut cq = vec![0.0; info.holonomic_pattern.len()];
    let mut gamma = vec![0.0; mh + mnh];
    let mut g = vec![0.0; info.nonholonomic_pattern.len()];
    let mut constraints = vec![0.0; mh];
    for with_c in [false, true] {
        let label = if with_c { "terms+C" } else { "terms" };
        c.bench_function(&format!("{name}/{label}"), |b| {
            b.iter(|| {
                let (gh, gnh) = gamma.split_at_mut(mh);
                model.dynamics_terms(
                    black_box(t),
                    black_box(q),
                    black_box(qd),
                    DynamicsTerms {
                        holonomic: with_c.then_some(&mut constraints[..]),
                        mass: &mut mass,
                        forces: &mut forces,
                        holonomic_jacobian: &mut cq,
                        holonomic_gamma: gh,
                        nonholonomic_matrix: &mut g,
                        nonholonomic_gamma: gnh,
                    },
                );
                black_box((&mass, &forces, &constraints, &cq));
            });
        });
    }
}

fn generated_solve(
    c: &mut Criterion,
    name: &str,
    model: &dyn Mechanism,
    t: f64,
    q: &[f64],
    qd: &[f64],
) {
    let info = model.info();
    let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
    let mut mass = vec![0.0; info.mass_pattern.len()];
    let mut cq = vec![0.0; info.holonomic_pattern.len()];
    let mut g = vec![0.0; info.nonholonomic_pattern.len()];
    let mut x = vec![0.0; n + mh + mnh];
    // Above the generator's budget (`chain100`) there is no generated solve: its
    // formulations take the sparse LU, measured below.
    if model.augmented_solve(&mass, &cq, &g, &mut x) == AugmentedSolve::Unavailable {
        eprintln!("{name}: no generated solve (above the generator's budget)");
        return;
    }
    // Baumgarte's floor: the terms with C (and the rates, where the model has them).
    let mut constraints = vec![0.0; mh];
    let (mut ct, mut bias) = (vec![0.0; mh], vec![0.0; mnh]);
    for (label, with_c) in [("generated+solve", false), ("floor/baumgarte", true)] {
        c.bench_function(&format!("{name}/{label}"), |b| {
            b.iter(|| {
                if with_c {
                    rates(model, t, q, &mut ct, &mut bias);
                }
                let (forces, gamma) = x.split_at_mut(n);
                let (gh, gnh) = gamma.split_at_mut(mh);
                model.dynamics_terms(
                    black_box(t),
                    black_box(q),
                    black_box(qd),
                    DynamicsTerms {
                        holonomic: with_c.then_some(&mut constraints[..]),
                        mass: &mut mass,
                        forces,
                        holonomic_jacobian: &mut cq,
                        holonomic_gamma: gh,
                        nonholonomic_matrix: &mut g,
                        nonholonomic_gamma: gnh,
                    },
                );
                let outcome = model.augmented_solve(&mass, &cq, &g, &mut x);
                assert_eq!(outcome, AugmentedSolve::Solved);
                black_box((&constraints, &ct, &bias, &x));
            });
        });
    }
}

/// The rates $C_t$ and $g$ at `(t, q)` into `ct` and `bias`, where the model has them.
fn rates(model: &dyn Mechanism, t: f64, q: &[f64], ct: &mut [f64], bias: &mut [f64]) {
    let info = model.info();
    if info.nh() > 0 && info.time.holonomic {
        model.holonomic_rate(t, q, ct);
    }
    if info.nnh() > 0 && !info.nonholonomic_homogeneous {
        model.nonholonomic_bias(t, q, bias);
    }
}

/// `{name}/floor/partitioning` (see the module docs).
fn floors(c: &mut Criterion, name: &str, model: &dyn Mechanism, t: f64, q: &[f64], qd: &[f64]) {
    let info = model.info();
    let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
    let mut mass = vec![0.0; info.mass_pattern.len()];
    let mut cq = vec![0.0; info.holonomic_pattern.len()];
    let mut g = vec![0.0; info.nonholonomic_pattern.len()];
    let mut constraints = vec![0.0; mh];
    let (mut ct, mut bias) = (vec![0.0; mh], vec![0.0; mnh]);
    let mut velocities = qd.to_vec();
    let mut x = vec![0.0; n + mh + mnh];
    let probe = model.orthogonal_projection(&cq, &g, &ct, &bias, &mut velocities);
    if model.augmented_solve(&mass, &cq, &g, &mut x) == AugmentedSolve::Unavailable
        || probe == AugmentedSolve::Unavailable
    {
        eprintln!("{name}: no generated solves (above the generator's budget), no floor");
        return;
    }
    let mut corrected = q.to_vec();
    c.bench_function(&format!("{name}/floor/partitioning"), |b| {
        b.iter(|| {
            model.holonomic(black_box(t), black_box(q), &mut constraints);
            // The terms are evaluated at positions corrected from C, so they wait for
            // it: the dependence without the correction's work (a zero update).
            let wait = constraints.first().map_or(0.0, |c| 0.0 * c);
            for (c, &qj) in corrected.iter_mut().zip(q) {
                *c = qj + wait;
            }
            rates(model, t, q, &mut ct, &mut bias);
            velocities.copy_from_slice(black_box(qd));
            let (forces, gamma) = x.split_at_mut(n);
            let (gh, gnh) = gamma.split_at_mut(mh);
            let mut outcome = AugmentedSolve::Unavailable;
            model.dynamics_terms_corrected(
                black_box(t),
                &corrected,
                &mut velocities,
                DynamicsTerms {
                    holonomic: None,
                    mass: &mut mass,
                    forces,
                    holonomic_jacobian: &mut cq,
                    holonomic_gamma: gh,
                    nonholonomic_matrix: &mut g,
                    nonholonomic_gamma: gnh,
                },
                &mut |cq, g, qd| outcome = model.orthogonal_projection(cq, g, &ct, &bias, qd),
            );
            assert_eq!(outcome, AugmentedSolve::Solved);
            let solved = model.augmented_solve(&mass, &cq, &g, &mut x);
            assert_eq!(solved, AugmentedSolve::Solved);
            black_box((&constraints, &x));
        });
    });
}

fn rhs(c: &mut Criterion) {
    for &(name, make, t, scale) in CASES {
        let model = make();
        let (q, qd) = moving_state(model.as_ref(), t);
        generated(c, name, model.as_ref(), t, &q, &qd);
        terms(c, name, model.as_ref(), t, &q, &qd);
        generated_solve(c, name, model.as_ref(), t, &q, &qd);
        floors(c, name, model.as_ref(), t, &q, &qd);
        let n = q.len();
        // The general path as before the generated solve: dense LU below the
        // crossover, sparse LU from it.
        let dim = n + model.info().nh() + model.info().nnh();
        let general = if dim < DEFAULT_CROSSOVER {
            LinearSolver::Dense
        } else {
            LinearSolver::SparseLu
        };
        for (form, solver) in Formulation::ALL
            .into_iter()
            .flat_map(|f| [(f, LinearSolver::Auto), (f, general)])
        {
            let mut sys = StateSpace::new(model.as_ref(), form, 1e-8, 1e-8)
                .expect("patterns")
                .linear_solver(solver)
                .expect("the solver");
            sys.start(t, &q, &qd).expect("a consistent state");
            let mut y0 = q.clone();
            y0.extend_from_slice(&qd);
            let mut f = vec![0.0; 2 * n];
            sys.rhs(t, &y0, &mut f).expect("an evaluation at the start");
            let h = 1e-3 * scale;
            let states: Vec<Vec<f64>> = [h, 2.0 * h]
                .iter()
                .map(|&h| y0.iter().zip(&f).map(|(y, f)| y + h * f).collect())
                .collect();
            let mut dy = vec![0.0; 2 * n];
            let mut k = 0;
            let label = if solver == LinearSolver::Auto {
                form.name().to_owned()
            } else {
                format!("{}/general", form.name())
            };
            c.bench_function(&format!("{name}/{label}"), |b| {
                b.iter(|| {
                    k ^= 1;
                    sys.rhs(black_box(t + h), black_box(&states[k]), &mut dy)
                        .expect("an evaluation");
                    black_box(&dy);
                });
            });
        }
    }
}

criterion_group!(benches, rhs);
criterion_main!(benches);
