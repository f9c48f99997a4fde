//! The generated solve of the augmented system (`Mechanism::augmented_solve`, a sparse
//! $LDL^\mathsf{T}$ specialized to the patterns of $M$ and $J$) against the general
//! path of the runtime (the dense $LU$ with its rank decision, `LinearSolver::Dense`):
//! the same $\ddot q$ and $\lambda$ of (E31), docs/theory.md §augmented, on seeded random states, and
//! the general path taken whenever a pivot of the generated one is not safe.

use pfaff::sim::Simulation;
use pfaff::{
    AugmentedSolve, Dynamics, DynamicsParams, DynamicsTerms, Info, LinearSolver, Mechanism,
    SolverPath, Workspace,
};

use crate::accuracy::util::Rng;

/// The solution of (E31) at `(q, qd)` by `solver`: the path, $\ddot q$, $\lambda$.
fn solve(
    model: &dyn Mechanism,
    solver: LinearSolver,
    q: &[f64],
    qd: &[f64],
) -> Result<(SolverPath, Vec<f64>, Vec<f64>), pfaff::DynamicsError> {
    let info = model.info();
    let mut ws = Workspace::new(info).expect("a workspace");
    let params = DynamicsParams {
        solver,
        ..DynamicsParams::default()
    };
    let mut dynamics = Dynamics::new(info, params).expect("a solver");
    let mut qdd = vec![0.0; info.nq()];
    let mut lambda = vec![0.0; info.nh() + info.nnh()];
    let stats = dynamics.accelerations(model, &mut ws, 0.3, q, qd, &mut qdd, &mut lambda)?;
    Ok((stats.path, qdd, lambda))
}

/// $\max_i |a_i - b_i| / \max(\lVert b\rVert_\infty, s)$.
fn relative(a: &[f64], b: &[f64], s: f64) -> f64 {
    let scale = b.iter().fold(s.max(1e-300), |s, v| s.max(v.abs()));
    a.iter()
        .zip(b)
        .fold(0.0_f64, |e, (x, y)| e.max((x - y).abs()))
        / scale
}

/// The size of the multipliers the forces call for, $\lVert Q\rVert_\infty /
/// \lVert J\rVert_\infty$: the scale of $\lambda$'s error where $\lambda$ itself
/// vanishes (a free motion, `seed2_example2`).
fn multiplier_scale(model: &dyn Mechanism, q: &[f64], qd: &[f64]) -> f64 {
    let info = model.info();
    let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
    let mut mass = vec![0.0; info.mass_pattern.len()];
    let mut forces = vec![0.0; n];
    let mut cq = vec![0.0; info.holonomic_pattern.len()];
    let mut g = vec![0.0; info.nonholonomic_pattern.len()];
    let mut gamma = vec![0.0; mh + mnh];
    let (gh, gnh) = gamma.split_at_mut(mh);
    model.dynamics_terms(
        0.3,
        q,
        qd,
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
    let norm = |v: &[f64]| v.iter().fold(0.0_f64, |s, x| s.max(x.abs()));
    norm(&forces) / norm(&cq).max(norm(&g)).max(1e-300)
}

/// Seeded states near the model's initial state: positions moved by up to 0.05 (the
/// solve needs no consistency), velocities in [−1, 1].
fn states(model: &dyn Mechanism, count: usize, seed: u64) -> Vec<(Vec<f64>, Vec<f64>)> {
    let n = model.info().nq();
    let (mut q0, mut qd0) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q0, &mut qd0);
    let mut rng = Rng::new(seed);
    (0..count)
        .map(|_| {
            let q = q0.iter().map(|v| v + rng.range(-0.05, 0.05)).collect();
            (q, rng.vec(n, -1.0, 1.0))
        })
        .collect()
}

/// Compares the generated path with the dense one on 20 random states; returns how
/// many of them the generated path solved.
fn agree(model: &dyn Mechanism, seed: u64) -> usize {
    let name = model.info().name;
    let mut generated = 0;
    for (q, qd) in states(model, 20, seed) {
        let auto = solve(model, LinearSolver::Auto, &q, &qd);
        let dense = solve(model, LinearSolver::Dense, &q, &qd);
        match (auto, dense) {
            (Ok((path, qdd, lambda)), Ok((_, qdd_d, lambda_d))) => {
                generated += usize::from(path == SolverPath::Generated);
                let s = multiplier_scale(model, &q, &qd);
                let (eq, el) = (relative(&qdd, &qdd_d, 0.0), relative(&lambda, &lambda_d, s));
                assert!(
                    eq <= 1e-10 && el <= 1e-10,
                    "{name} ({path:?}): q̈ {eq:.1e}, λ {el:.1e} from the dense path"
                );
            }
            (Err(a), Err(d)) => assert_eq!(
                std::mem::discriminant(&a),
                std::mem::discriminant(&d),
                "{name}: {a} / {d}"
            ),
            (a, d) => panic!("{name}: generated {a:?}, dense {d:?}"),
        }
    }
    generated
}

#[test]
fn generated_solve_matches_the_dense_path() {
    // Every listed model has a generated solve, and it solves every state: planar and
    // spatial, relative and absolute coordinates, non-holonomic rows (sleigh,
    // rolling_disk, bicycle), a deformable body whose mass matrix comes from run-time
    // data (flexible_crank).
    for (name, seed) in [
        ("pendulum", 1),
        ("andrews", 2),
        ("car_axis", 3),
        ("slider_crank", 4),
        ("slider_crank_bodies", 5),
        ("bicycle", 6),
        ("sleigh", 7),
        ("rolling_disk", 8),
        ("flexible_crank", 9),
        // Euler parameters: M θ = 0, the normalization rows are added to M.
        ("free_body", 10),
        ("spatial_four_bar", 11),
        ("chain10", 12),
    ] {
        let entry = pfaff_models::find(name).expect("a built-in model");
        let model = (entry.make)();
        let n = agree(model.as_ref(), seed);
        eprintln!("{name}: generated path on {n} of 20 states");
        assert_eq!(n, 20, "{name}: the generated path declined a regular state");
    }
}

/// Consistent states along a run of `model` (one per 0.1 s over 1 s).
fn run_states(model: &dyn Mechanism) -> Vec<(Vec<f64>, Vec<f64>)> {
    let run = Simulation::new(model)
        .tolerances(1e-10, 1e-10)
        .output_every(0.1)
        .run(1.0)
        .expect("a run");
    let tr = &run.trajectory;
    (0..tr.len())
        .map(|i| (tr.q(i).to_vec(), tr.qd(i).to_vec()))
        .collect()
}

#[test]
fn redundant_constraints_take_the_general_path() {
    // Bricard's linkage: the closure joint's rows are dependent at every consistent
    // configuration (models/src/bricard.rs), so a pivot of the Schur complement
    // vanishes to rounding and the general path must decide the rank; the parallelogram
    // has one redundant crank.
    for name in ["bricard", "parallelogram", "parallelogram_row"] {
        let model = (pfaff_models::find(name).expect("a built-in model").make)();
        for (q, qd) in run_states(model.as_ref()) {
            let auto = solve(model.as_ref(), LinearSolver::Auto, &q, &qd).expect("a solution");
            let dense = solve(model.as_ref(), LinearSolver::Dense, &q, &qd).expect("a solution");
            assert_eq!(
                auto.0,
                SolverPath::Redundant,
                "{name}: the fallback is taken"
            );
            assert_eq!(
                auto, dense,
                "{name}: the fallback's result is the general path's"
            );
        }
    }
}

#[test]
fn a_massless_coordinate_is_solved_by_the_partition_or_the_general_path() {
    // slider_crank_bodies with a massless slider (m3 = 0): M is singular in the
    // slider's x and y, the augmented matrix is regular (the prismatic joint fixes y,
    // the coupler's pin x). The range-space code of the generated solve would decline at
    // the zero pivot of M; its partition of the coordinates (null-space method) needs
    // only the reduced mass N^T M N to be regular, which it is here, so the generated
    // solve serves (the dense path where a state's partition declines). Whichever
    // path, q̈ meets M q̈ + Jᵀλ = Q and J q̈ = γ, checked here directly.
    let mut model = pfaff_models::slider_crank_bodies::Model::default();
    let info = model.info();
    let m3 = info.parameter_index("m3").expect("the slider's mass");
    model.set_parameter(m3, 0.0);
    let mut generated = 0;
    for (q, qd) in states(&model, 10, 21) {
        let (n, mh) = (info.nq(), info.nh());
        let mut mass = vec![0.0; info.mass_pattern.len()];
        let mut cq = vec![0.0; info.holonomic_pattern.len()];
        let mut b = vec![0.0; n + mh];
        let (forces, gamma) = b.split_at_mut(n);
        model.dynamics_terms(
            0.3,
            &q,
            &qd,
            DynamicsTerms {
                holonomic: None,
                mass: &mut mass,
                forces,
                holonomic_jacobian: &mut cq,
                holonomic_gamma: gamma,
                nonholonomic_matrix: &mut [],
                nonholonomic_gamma: &mut [],
            },
        );
        let (path, qdd, lambda) = solve(&model, LinearSolver::Auto, &q, &qd).expect("a solution");
        generated += usize::from(path == SolverPath::Generated);
        assert!(matches!(
            path,
            SolverPath::Generated | SolverPath::Dense | SolverPath::Sparse
        ));
        // The residual of (E31), relative to the size of its terms.
        let mut r = b.clone();
        let mut size = b.iter().fold(0.0_f64, |s, v| s.max(v.abs()));
        for (&(i, j), v) in info.mass_pattern.iter().zip(&mass) {
            r[i as usize] -= v * qdd[j as usize];
            size = size.max((v * qdd[j as usize]).abs());
        }
        for (&(i, j), v) in info.holonomic_pattern.iter().zip(&cq) {
            r[j as usize] -= v * lambda[i as usize];
            r[n + i as usize] -= v * qdd[j as usize];
            size = size.max((v * lambda[i as usize]).abs());
        }
        let residual = r.iter().fold(0.0_f64, |s, v| s.max(v.abs()));
        assert!(
            residual <= 1e-12 * size,
            "residual {residual:e} of {size:e} ({path:?})"
        );
    }
    assert_eq!(generated, 10, "states the generated solve served");
}

/// The inputs of the generated solve at a seeded state near the start ([`states`]):
/// the pattern values of $M$, $C_q$ and $G$ and the right-hand side $[Q; \gamma]$.
struct SolveInputs {
    mass: Vec<f64>,
    cq: Vec<f64>,
    g: Vec<f64>,
    b: Vec<f64>,
}

fn solve_inputs(model: &dyn Mechanism, seed: u64) -> SolveInputs {
    let info = model.info();
    let (n, mh) = (info.nq(), info.nh());
    let (q, qd) = states(model, 1, seed).remove(0);
    // [M, Q, C_q, γ_h, G, γ_nh] as one call writes them.
    let all = terms(model, 0.3, &q, &qd, false);
    let (lm, lc, lg) = (
        info.mass_pattern.len(),
        info.holonomic_pattern.len(),
        info.nonholonomic_pattern.len(),
    );
    let (mass, rest) = all.split_at(lm);
    let (forces, rest) = rest.split_at(n);
    let (cq, rest) = rest.split_at(lc);
    let (gh, rest) = rest.split_at(mh);
    let (g, gnh) = rest.split_at(lg);
    SolveInputs {
        mass: mass.to_vec(),
        cq: cq.to_vec(),
        g: g.to_vec(),
        b: [forces, gh, gnh].concat(),
    }
}

/// The built-in models but those with redundant constraints (Bricard's linkage, the
/// parallelogram and the parallelogram row), whose augmented system the general path solves.
fn generated_solve_models() -> impl Iterator<Item = &'static pfaff_models::Entry> {
    let redundant = ["bricard", "parallelogram", "parallelogram_row"];
    pfaff_models::all()
        .iter()
        .filter(move |e| !redundant.contains(&e.name))
}

#[test]
fn every_built_in_model_agrees_with_the_dense_path() {
    // Off the constraint manifold the redundant rows of Bricard's linkage and of the
    // parallelogram are nearly, not exactly, dependent: both paths solve an
    // ill-conditioned system there and agree only to its condition; on the manifold see
    // `redundant_constraints_take_the_general_path`.
    for entry in generated_solve_models() {
        let model = (entry.make)();
        let n = agree(model.as_ref(), 11);
        eprintln!("{}: generated on {n} of 20", entry.name);
    }
}

/// The terms of one `dynamics_terms` call at `(q, qd)`, concatenated in the order of
/// [`DynamicsTerms`]' fields: with `C` first when `with_c`, without it (not asked for)
/// otherwise.
fn terms(model: &dyn Mechanism, t: f64, q: &[f64], qd: &[f64], with_c: bool) -> Vec<f64> {
    let info = model.info();
    let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
    let mut mass = vec![0.0; info.mass_pattern.len()];
    let mut forces = vec![0.0; n];
    let mut cq = vec![0.0; info.holonomic_pattern.len()];
    let mut gh = vec![0.0; mh];
    let mut g = vec![0.0; info.nonholonomic_pattern.len()];
    let mut gnh = vec![0.0; mnh];
    let mut c = vec![0.0; if with_c { mh } else { 0 }];
    model.dynamics_terms(
        t,
        q,
        qd,
        DynamicsTerms {
            holonomic: with_c.then_some(&mut c[..]),
            mass: &mut mass,
            forces: &mut forces,
            holonomic_jacobian: &mut cq,
            holonomic_gamma: &mut gh,
            nonholonomic_matrix: &mut g,
            nonholonomic_gamma: &mut gnh,
        },
    );
    [c, mass, forces, cq, gh, g, gnh].concat()
}

/// The separate functions' values in the order of [`terms`] with `C`.
fn separate_terms(model: &dyn Mechanism, t: f64, q: &[f64], qd: &[f64]) -> Vec<Vec<f64>> {
    let info = model.info();
    let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
    let mut c = vec![0.0; mh];
    let mut mass = vec![0.0; info.mass_pattern.len()];
    let mut forces = vec![0.0; n];
    let mut cq = vec![0.0; info.holonomic_pattern.len()];
    let mut gh = vec![0.0; mh];
    let mut g = vec![0.0; info.nonholonomic_pattern.len()];
    let mut gnh = vec![0.0; mnh];
    model.holonomic(t, q, &mut c);
    model.mass_matrix(t, q, &mut mass);
    model.forces(t, q, qd, &mut forces);
    model.holonomic_jacobian(t, q, &mut cq);
    model.holonomic_gamma(t, q, qd, &mut gh);
    model.nonholonomic_matrix(t, q, &mut g);
    model.nonholonomic_gamma(t, q, qd, &mut gnh);
    vec![c, mass, forces, cq, gh, g, gnh]
}

/// `dynamics_terms` (one schedule for every term, generated for every model) writes
/// what the separate functions write, with `C` asked for or not, on seeded random
/// states of every built-in model: the same expressions with their temporaries shared,
/// so equal up to rounding (a sine alone and one of `sin_cos` may differ in the last
/// bit), within 10⁻¹⁴ of each quantity's size (`max(1, ‖·‖∞)`; for `C`, of
/// (1 + ‖q‖∞) ‖C_q‖∞ as in `constraints_with_jacobian_equal_the_separate_functions`).
/// Without `C` the other terms are the same to the bit (the statements only `C` needs
/// are skipped, nothing else changes), and the fused `C_q` matches central differences
/// of the fused `C` (step `1e-6 (1 + |q_j|)`, within 10⁻⁵ ‖C_q‖∞, the tolerance of
/// `bodies/joints.rs`, where the separate functions are checked against differences).
#[test]
fn terms_equal_the_separate_functions_with_and_without_constraints() {
    let mut checked = 0;
    for (k, entry) in pfaff_models::all().iter().enumerate() {
        let model = (entry.make)();
        let info = model.info();
        let (n, mh) = (info.nq(), info.nh());
        let name = entry.name;
        for (j, (q, qd)) in states(model.as_ref(), 3, 60 + k as u64)
            .into_iter()
            .enumerate()
        {
            #[allow(clippy::cast_precision_loss)]
            let t = 0.1 * j as f64;
            let with = terms(model.as_ref(), t, &q, &qd, true);
            let without = terms(model.as_ref(), t, &q, &qd, false);
            assert!(
                with[mh..]
                    .iter()
                    .zip(&without)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
                    && with.len() == mh + without.len(),
                "{name}: the terms depend on whether C is asked for"
            );
            let separate = separate_terms(model.as_ref(), t, &q, &qd);
            let cq_size = separate[3].iter().fold(1.0_f64, |s, v| s.max(v.abs()));
            let reach = 1.0 + q.iter().fold(0.0_f64, |s, v| s.max(v.abs()));
            let mut at = 0;
            for (i, part) in separate.iter().enumerate() {
                let got = &with[at..at + part.len()];
                at += part.len();
                let size = if i == 0 {
                    reach * cq_size
                } else {
                    part.iter().fold(1.0_f64, |s, v| s.max(v.abs()))
                };
                let e = got
                    .iter()
                    .zip(part)
                    .fold(0.0_f64, |e, (x, y)| e.max((x - y).abs()));
                assert!(
                    e <= 1e-14 * size,
                    "{name}: term {i} off by {e:e} of {size:e}"
                );
            }
            // The fused C_q against central differences of the fused C.
            let mut dense = vec![0.0; mh * n];
            let offset = mh + info.mass_pattern.len() + n;
            for (&(r, col), v) in info
                .holonomic_pattern
                .iter()
                .zip(&with[offset..offset + info.holonomic_pattern.len()])
            {
                dense[r as usize * n + col as usize] = *v;
            }
            let mut qh = q.clone();
            for col in 0..n {
                let h = 1e-6 * (1.0 + q[col].abs());
                qh[col] = q[col] + h;
                let cp = terms(model.as_ref(), t, &qh, &qd, true);
                qh[col] = q[col] - h;
                let cm = terms(model.as_ref(), t, &qh, &qd, true);
                qh[col] = q[col];
                for r in 0..mh {
                    let fd = (cp[r] - cm[r]) / (2.0 * h);
                    let e = (fd - dense[r * n + col]).abs();
                    assert!(
                        e <= 1e-5 * cq_size,
                        "{name}: C_q[{r}][{col}] = {} against {fd} by differences",
                        dense[r * n + col]
                    );
                }
            }
        }
        checked += 1;
    }
    assert!(checked >= 20, "only {checked} models");
}

/// `dynamics_terms_corrected` (generated for models with constraint rows, the trait's
/// default otherwise) hands the correction `C_q` and `G` at `q` (equal to
/// `holonomic_jacobian` and `nonholonomic_matrix`) and writes every term at the
/// velocities as the correction left them: equal to `dynamics_terms` there, on seeded
/// random states of models with angles, lengths, driven coordinates (slider_crank),
/// non-holonomic rows (sleigh, rolling_disk, bicycle) and run-time data
/// (flexible_crank), with `C` asked for (then equal to `C` of `dynamics_terms`) and not.
#[test]
fn corrected_terms_equal_the_terms_at_the_corrected_velocities() {
    for (name, seed) in [
        ("pendulum", 21),
        ("andrews", 22),
        ("car_axis", 23),
        ("slider_crank", 24),
        ("sleigh", 25),
        ("rolling_disk", 26),
        ("bicycle", 27),
        ("flexible_crank", 28),
        ("spatial_four_bar", 29),
    ] {
        let model = (pfaff_models::find(name).expect("a built-in model").make)();
        let info = model.info();
        let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
        for (k, (q, qd)) in states(model.as_ref(), 6, seed).into_iter().enumerate() {
            #[allow(clippy::cast_precision_loss)]
            let t = 0.1 * k as f64;
            // C asked for on every other state.
            let with_c = k % 2 == 1;
            let mut cq = vec![0.0; info.holonomic_pattern.len()];
            let mut g = vec![0.0; info.nonholonomic_pattern.len()];
            model.holonomic_jacobian(t, &q, &mut cq);
            model.nonholonomic_matrix(t, &q, &mut g);
            let mut out = vec![0.0; info.mass_pattern.len()];
            let mut forces = vec![0.0; n];
            let mut cq_out = vec![0.0; cq.len()];
            let mut gh = vec![0.0; mh];
            let mut g_out = vec![0.0; g.len()];
            let mut gnh = vec![0.0; mnh];
            let mut c_out = vec![0.0; if with_c { mh } else { 0 }];
            let mut corrected = qd.clone();
            let mut seen = None;
            model.dynamics_terms_corrected(
                t,
                &q,
                &mut corrected,
                DynamicsTerms {
                    holonomic: with_c.then_some(&mut c_out[..]),
                    mass: &mut out,
                    forces: &mut forces,
                    holonomic_jacobian: &mut cq_out,
                    holonomic_gamma: &mut gh,
                    nonholonomic_matrix: &mut g_out,
                    nonholonomic_gamma: &mut gnh,
                },
                &mut |c, gm, v| {
                    seen = Some((c.to_vec(), gm.to_vec()));
                    // Any change of the velocities: a shear of them.
                    for (j, x) in v.iter_mut().enumerate() {
                        #[allow(clippy::cast_precision_loss)]
                        let s = 0.3 + 0.1 * j as f64;
                        *x = s * *x + 0.05;
                    }
                },
            );
            let (c, gm) = seen.expect("the correction is called");
            // The fused schedule shares other subexpressions than the separate
            // functions: equal up to rounding.
            assert!(relative(&c, &cq, 1.0) <= 1e-14, "{name}: C_q handed over");
            assert!(relative(&gm, &g, 1.0) <= 1e-14, "{name}: G handed over");
            assert_ne!(corrected, qd, "{name}: the velocities were changed");
            let expected = terms(model.as_ref(), t, &q, &corrected, with_c);
            let got = [c_out, out, forces, cq_out, gh, g_out, gnh].concat();
            let scale = expected.iter().fold(1.0_f64, |a, x| a.max(x.abs()));
            let e = relative(&got, &expected, scale);
            assert!(
                e <= 1e-14,
                "{name}: terms at the corrected velocities off by {e:e}"
            );
        }
    }
}

/// `holonomic_with_jacobian` (one schedule for `C` and `C_q`, generated for every model
/// with holonomic constraints) writes what `holonomic` and `holonomic_jacobian` write,
/// on seeded random states of every built-in model with holonomic constraints: the
/// same expressions with their temporaries shared, so equal up to rounding (a sine
/// alone and a sine of `sin_cos` may differ in the last bit), within
/// 10⁻¹⁴ (1 + ‖q‖∞) ‖C_q‖∞ for `C` and 10⁻¹⁴ ‖C_q‖∞ for `C_q`; most models agree to
/// the bit. The separate functions are checked against finite differences in
/// `bodies/joints.rs` and `flex/crank.rs` (`MechanismExt::check_derivatives`); the
/// fused `C_q` is checked here against central differences of the fused `C` too (step
/// `1e-6 (1 + |q_j|)`, within 10⁻⁵ ‖C_q‖∞, the tolerance of those tests).
#[test]
fn constraints_with_jacobian_equal_the_separate_functions() {
    let (mut checked, mut bitwise) = (0, 0);
    for (k, entry) in pfaff_models::all().iter().enumerate() {
        let model = (entry.make)();
        let info = model.info();
        let (n, mh) = (info.nq(), info.nh());
        if mh == 0 {
            continue;
        }
        let name = entry.name;
        let pattern = info.holonomic_pattern;
        for (j, (q, _)) in states(model.as_ref(), 5, 40 + k as u64)
            .into_iter()
            .enumerate()
        {
            #[allow(clippy::cast_precision_loss)]
            let t = 0.1 * j as f64;
            let (mut c, mut cq) = (vec![f64::NAN; mh], vec![f64::NAN; pattern.len()]);
            model.holonomic_with_jacobian(t, &q, &mut c, &mut cq);
            let (mut c_sep, mut cq_sep) = (vec![0.0; mh], vec![0.0; pattern.len()]);
            model.holonomic(t, &q, &mut c_sep);
            model.holonomic_jacobian(t, &q, &mut cq_sep);
            let size = cq.iter().fold(1.0_f64, |s, v| s.max(v.abs()));
            let reach = 1.0 + q.iter().fold(0.0_f64, |s, v| s.max(v.abs()));
            let off = |a: &[f64], b: &[f64]| {
                a.iter()
                    .zip(b)
                    .fold(0.0_f64, |e, (x, y)| e.max((x - y).abs()))
            };
            let (ec, ecq) = (off(&c, &c_sep), off(&cq, &cq_sep));
            assert!(ec <= 1e-14 * reach * size, "{name}: C off by {ec:e}");
            assert!(ecq <= 1e-14 * size, "{name}: C_q off by {ecq:e}");
            bitwise += usize::from(c == c_sep && cq == cq_sep);
            // C_q against central differences of the fused C.
            let mut dense = vec![0.0; mh * n];
            for (&(r, col), v) in pattern.iter().zip(&cq) {
                dense[r as usize * n + col as usize] = *v;
            }
            let (mut cp, mut cm, mut scratch) = (vec![0.0; mh], vec![0.0; mh], cq.clone());
            let mut qh = q.clone();
            for col in 0..n {
                let h = 1e-6 * (1.0 + q[col].abs());
                qh[col] = q[col] + h;
                model.holonomic_with_jacobian(t, &qh, &mut cp, &mut scratch);
                qh[col] = q[col] - h;
                model.holonomic_with_jacobian(t, &qh, &mut cm, &mut scratch);
                qh[col] = q[col];
                for r in 0..mh {
                    let fd = (cp[r] - cm[r]) / (2.0 * h);
                    let e = (fd - dense[r * n + col]).abs();
                    assert!(
                        e <= 1e-5 * size,
                        "{name}: C_q[{r}][{col}] = {} against {fd} by differences",
                        dense[r * n + col]
                    );
                }
            }
        }
        checked += 1;
    }
    assert!(
        checked >= 10,
        "only {checked} models with holonomic constraints"
    );
    eprintln!(
        "{checked} models, {bitwise} of {} states equal to the bit",
        5 * checked
    );
}

/// $M = \partial^2 T/\partial\dot q^2$ is symmetric (the order of the two derivatives
/// does not matter), and the generator gives each pair of mirror entries one
/// expression: on seeded random states of every built-in model the pattern of $M$ is
/// symmetric and `mass_matrix` and the $M$ of `dynamics_terms` are symmetric to the
/// bit (what the generated solve, which reads one triangle, and the symmetric
/// factorizations assume). Before, `flexible_pendulum`'s triangles came from different
/// expressions and differed in their last bits.
#[test]
fn every_mass_matrix_is_symmetric_to_the_bit() {
    let mut pairs = 0;
    for (k, entry) in pfaff_models::all().iter().enumerate() {
        let model = (entry.make)();
        let info = model.info();
        let pattern = info.mass_pattern;
        let mirror: Vec<usize> = pattern
            .iter()
            .map(|&(r, c)| {
                pattern
                    .iter()
                    .position(|&e| e == (c, r))
                    .unwrap_or_else(|| panic!("{}: M[{r}, {c}] has no mirror", info.name))
            })
            .collect();
        for (q, qd) in states(model.as_ref(), 4, 40 + k as u64) {
            let fused = terms(model.as_ref(), 0.2, &q, &qd, false);
            let mut separate = vec![0.0; pattern.len()];
            model.mass_matrix(0.2, &q, &mut separate);
            for mass in [&fused[..pattern.len()], &separate[..]] {
                for (e, &m) in mirror.iter().enumerate() {
                    assert_eq!(
                        mass[e].to_bits(),
                        mass[m].to_bits(),
                        "{}: M{:?} = {:e}, its mirror {:e}",
                        info.name,
                        pattern[e],
                        mass[e],
                        mass[m]
                    );
                    pairs += usize::from(e != m);
                }
            }
        }
    }
    assert!(pairs > 0, "no off-diagonal entry");
}

#[test]
fn a_non_finite_input_never_gives_a_finite_generated_solution() {
    // What lets a caller skip checking the terms before the generated solve: a NaN or
    // an infinity in any entry of M, C_q, G, Q or γ makes the solve decline (its pivot
    // tests are false for NaN and for an infinite pivot or diagonal) or leaves a
    // non-finite entry in [q̈; λ] (every input flows into the solution through +, −, ×
    // and ÷ by a tested pivot, and inf·0 is NaN). Each entry of each built-in model
    // with a generated solve, one at a time, at a random state; an entry of M with its
    // mirror (M is symmetric, and the solve reads one triangle).
    let mut models = 0;
    for entry in generated_solve_models() {
        let model = (entry.make)();
        let model = model.as_ref();
        let info = model.info();
        let SolveInputs { mass, cq, g, b } = solve_inputs(model, 31);
        let mut x = b.clone();
        match model.augmented_solve(&mass, &cq, &g, &mut x) {
            AugmentedSolve::Unavailable => continue,
            AugmentedSolve::Declined => panic!("{}: a regular state declined", info.name),
            AugmentedSolve::Solved => models += 1,
        }
        let inputs = [mass.len(), cq.len(), g.len(), b.len()];
        let mut tried = 0;
        for (which, &len) in inputs.iter().enumerate() {
            for entry in 0..len {
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                    let (mut mass, mut cq, mut g, mut x) =
                        (mass.clone(), cq.clone(), g.clone(), b.clone());
                    [&mut mass, &mut cq, &mut g, &mut x][which][entry] = bad;
                    if which == 0 {
                        let (r, c) = info.mass_pattern[entry];
                        let mirror = info.mass_pattern.iter().position(|&e| e == (c, r));
                        mass[mirror.expect("a symmetric pattern")] = bad;
                    }
                    let r = model.augmented_solve(&mass, &cq, &g, &mut x);
                    assert!(
                        r == AugmentedSolve::Declined || !x.iter().all(|v| v.is_finite()),
                        "{}: input {which} entry {entry} = {bad} gave a finite solution",
                        info.name
                    );
                    tried += 1;
                }
            }
        }
        assert!(tried > 0, "{}: no entry tried", info.name);
    }
    // Every built-in model but the three redundant ones has a generated solve.
    assert_eq!(
        models,
        pfaff_models::all().len() - 3,
        "models with a generated solve"
    );
}

/// The sparse $LDL^\mathsf{T}$ of the general path (coordinates first, no pivoting, the
/// Euler parameters' normalization rows added to $M$) against the sparse $LU$: on every
/// built-in model with constraints and on `chain100` (700 coordinates, 400
/// constraints, the model the $LDL^\mathsf{T}$ is for), at seeded states near the
/// initial one, the same $\ddot q$ and $\lambda$ to 1e-9 of their size; it serves the
/// chains and the other models with Euler parameters. The models with redundant
/// constraints are compared at consistent states (after a short tight run), where their
/// rows are dependent: there the $LDL^\mathsf{T}$'s pivot test hands the system to the
/// $LU$ and its rank decision. (Off the constraint manifold their $J$ has full rank but
/// pivots near 1e-8, where the two factorizations differ by the conditioning, about
/// 5e-8 for `bricard`.)
#[test]
fn the_sparse_ldlt_agrees_with_the_lu_and_leaves_dependent_rows_to_it() {
    const REDUNDANT: [&str; 3] = ["bricard", "parallelogram", "parallelogram_row"];
    let mut served = Vec::new();
    let models: Vec<(&str, Box<dyn Mechanism>)> = pfaff_models::all()
        .iter()
        .map(|e| (e.name, (e.make)()))
        .chain([(
            "chain100",
            Box::new(pfaff_models::chain100::Model::default()) as Box<dyn Mechanism>,
        )])
        .collect();
    for (k, (name, model)) in models.iter().enumerate() {
        let model = model.as_ref();
        if model.info().nh() + model.info().nnh() == 0 {
            continue;
        }
        let redundant = REDUNDANT.contains(name);
        let at = if redundant {
            vec![crate::states::moving_state(model, 0.05)]
        } else {
            states(
                model,
                if *name == "chain100" { 2 } else { 4 },
                700 + k as u64,
            )
        };
        for (q, qd) in at {
            let sparse = solve(model, LinearSolver::Sparse, &q, &qd);
            let lu = solve(model, LinearSolver::SparseLu, &q, &qd);
            let (path, qdd, lambda, qdd_lu, lambda_lu) = match (sparse, lu) {
                (Ok((path, qdd, lambda)), Ok((_, qdd_lu, lambda_lu))) => {
                    (path, qdd, lambda, qdd_lu, lambda_lu)
                }
                (Err(a), Err(b)) => {
                    assert_eq!(
                        std::mem::discriminant(&a),
                        std::mem::discriminant(&b),
                        "{name}: {a} / {b}"
                    );
                    continue;
                }
                (a, b) => panic!("{name}: LDLT path {a:?}, LU {b:?}"),
            };
            assert!(
                !(redundant && path == SolverPath::SparseLdlt),
                "{name}: dependent rows solved by the LDLT"
            );
            let s = multiplier_scale(model, &q, &qd);
            let (eq, el) = (
                relative(&qdd, &qdd_lu, 0.0),
                relative(&lambda, &lambda_lu, s),
            );
            assert!(
                eq < 1e-9 && el < 1e-9,
                "{name}: LDLT path against LU: qdd {eq:e}, lambda {el:e} ({path:?})"
            );
            if path == SolverPath::SparseLdlt && !served.contains(name) {
                served.push(*name);
            }
        }
    }
    println!("the LDLT served {served:?}");
    for name in [
        "chain100",
        "chain10",
        "andrews",
        "spatial_four_bar",
        "free_body",
        "bicycle",
    ] {
        assert!(served.contains(&name), "{name} not served by the LDLT");
    }
}

/// $J = [C_q; G]$'s entries as (row of all `m`, column, value), from the pattern values
/// `cq` and `g`, in the patterns' order.
fn jacobian_entries(info: &Info, cq: &[f64], g: &[f64]) -> Vec<(usize, usize, f64)> {
    let mh = info.nh();
    let entry = |offset: usize| {
        move |(&(r, c), &v): (&(u32, u32), &f64)| (offset + r as usize, c as usize, v)
    };
    info.holonomic_pattern
        .iter()
        .zip(cq)
        .map(entry(0))
        .chain(info.nonholonomic_pattern.iter().zip(g).map(entry(mh)))
        .collect()
}

/// The generated orthogonal solve (`Mechanism::orthogonal_solve`, the system
/// $[I\ J^\mathsf{T}; J\ 0][\Delta; \mu] = [0; r]$ that partitioning's velocity
/// projection solves at every evaluation) against its defining equations, which fix
/// the solution when $J$ has full rank: $J\Delta = r$ (the velocity constraints met)
/// and $\Delta + J^\mathsf{T}\mu = 0$ (the change in the range of $J^\mathsf{T}$: the
/// least change that meets them). On seeded states of every built-in model with
/// constraints but the redundant two, with seeded right-hand sides, both to 1e-12 of
/// the sizes involved; the coordinates' block of `x` on entry is garbage, which the
/// solve must not read. The redundant models, at consistent states (dependent rows),
/// decline. Checked to fail when the emitted solve writes its multipliers with the
/// wrong sign (pendulum: $\Delta + J^\mathsf{T}\mu$ is then $2\lVert\Delta\rVert$).
#[test]
fn the_orthogonal_solve_meets_its_defining_equations() {
    let mut served = Vec::new();
    for (k, entry) in pfaff_models::all().iter().enumerate() {
        let model = (entry.make)();
        let model = model.as_ref();
        let info = model.info();
        let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
        let m = mh + mnh;
        if m == 0 {
            continue;
        }
        let (hol, non) = (info.holonomic_pattern, info.nonholonomic_pattern);
        if ["bricard", "parallelogram", "parallelogram_row"].contains(&entry.name) {
            let (q, qd) = crate::states::moving_state(model, 0.05);
            let all = terms(model, 0.05, &q, &qd, false);
            let lm = info.mass_pattern.len();
            let cq = &all[lm + n..lm + n + hol.len()];
            let mut x = vec![0.0; n + m];
            x[n..].fill(1.0);
            assert_eq!(
                model.orthogonal_solve(cq, &[], &mut x),
                AugmentedSolve::Declined,
                "{}: dependent rows solved",
                entry.name
            );
            continue;
        }
        let mut rng = Rng::new(900 + k as u64);
        for (q, qd) in states(model, 5, 800 + k as u64) {
            let all = terms(model, 0.3, &q, &qd, false);
            let lm = info.mass_pattern.len();
            let (cq, rest) = all[lm + n..].split_at(hol.len());
            let g = &rest[mh..mh + non.len()];
            let r = rng.vec(m, -1.0, 1.0);
            let mut x = rng.vec(n, -1e3, 1e3);
            x.extend_from_slice(&r);
            match model.orthogonal_solve(cq, g, &mut x) {
                AugmentedSolve::Solved => {}
                other => panic!("{}: {other:?} at a regular state", entry.name),
            }
            let (delta, mu) = x.split_at(n);
            let entries = jacobian_entries(info, cq, g);
            let mut jd = vec![0.0; m];
            let mut range = delta.to_vec();
            let mut size = vec![0.0_f64; m];
            for &(i, c, v) in &entries {
                jd[i] += v * delta[c];
                size[i] = size[i].max((v * delta[c]).abs());
                range[c] += v * mu[i];
            }
            for i in 0..m {
                let e = (jd[i] - r[i]).abs() / size[i].max(r[i].abs());
                assert!(e <= 1e-12, "{}: (JΔ − r)[{i}] {e:.1e}", entry.name);
            }
            let scale = delta.iter().fold(0.0_f64, |s, d| s.max(d.abs()));
            let e = range.iter().fold(0.0_f64, |s, d| s.max(d.abs())) / scale;
            assert!(e <= 1e-12, "{}: Δ + Jᵀμ {e:.1e} of |Δ|", entry.name);
        }
        served.push(entry.name);
    }
    eprintln!("orthogonal solve served: {served:?}");
    assert!(served.len() >= 15, "models served: {served:?}");
}

/// A seeded point of a model with constraint rows for the velocity-level tests: the
/// pattern values of $C_q$ and $G$ at a seeded state, seeded rates $C_t$ and $g$ (so
/// that the rates' terms are exercised on scleronomic models too), and the state's
/// velocities.
struct VelocitySample {
    cq: Vec<f64>,
    g: Vec<f64>,
    ct: Vec<f64>,
    bias: Vec<f64>,
    qd: Vec<f64>,
}

/// `count` [`VelocitySample`]s of `model` from the seeds `seed` (states) and `seed + 100`
/// (rates).
fn velocity_samples(model: &dyn Mechanism, count: usize, seed: u64) -> Vec<VelocitySample> {
    let info = model.info();
    let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
    let (hol, non) = (info.holonomic_pattern, info.nonholonomic_pattern);
    let mut rng = Rng::new(seed + 100);
    states(model, count, seed)
        .into_iter()
        .map(|(q, qd)| {
            let all = terms(model, 0.3, &q, &qd, false);
            let lm = info.mass_pattern.len();
            let (cq, rest) = all[lm + n..].split_at(hol.len());
            let g = &rest[mh..mh + non.len()];
            VelocitySample {
                cq: cq.to_vec(),
                g: g.to_vec(),
                ct: rng.vec(mh, -1.0, 1.0),
                bias: rng.vec(mnh, -1.0, 1.0),
                qd,
            }
        })
        .collect()
}

/// The generated orthogonal projection (`Mechanism::orthogonal_projection`: the
/// residuals $r = J\dot q + [C_t; g]$ over the patterns, the orthogonal solve with
/// $[0; -r]$, $\dot q \mathrel{+}= \Delta$) against the same three steps written here
/// with the runtime's sums (each row's rate, then its entries in the pattern's order):
/// the projected velocities agree to the bit, and they meet the velocity constraints
/// to round-off, $|J\dot q + c|_i \le 10^{-12}$ of the row's products. On seeded states
/// of every built-in model with a generated orthogonal solve, with seeded rates (so that
/// the rates' terms are exercised on scleronomic models too); the redundant models
/// decline (with the velocities unchanged) where the solve declines.
#[test]
fn the_orthogonal_projection_is_the_runtime_one_to_the_bit() {
    let mut served = Vec::new();
    for (k, entry) in pfaff_models::all().iter().enumerate() {
        let model = (entry.make)();
        let model = model.as_ref();
        let info = model.info();
        let (n, mh, mnh) = (info.nq(), info.nh(), info.nnh());
        let m = mh + mnh;
        if m == 0 {
            continue;
        }
        let mut solved_here = false;
        for sample in velocity_samples(model, 4, 1800 + k as u64) {
            let VelocitySample {
                cq,
                g,
                ct,
                bias,
                qd,
            } = sample;
            let (cq, g) = (&cq[..], &g[..]);
            // The runtime's way: residuals row by row, then the solve.
            let mut x = vec![0.0; n + m];
            let mut residual: Vec<f64> = ct.iter().chain(&bias).copied().collect();
            for (i, c, v) in jacobian_entries(info, cq, g) {
                residual[i] += v * qd[c];
            }
            for (x, r) in x[n..].iter_mut().zip(&residual) {
                *x = -r;
            }
            let solved = model.orthogonal_solve(cq, g, &mut x);
            let mut projected = qd.clone();
            let outcome = model.orthogonal_projection(cq, g, &ct, &bias, &mut projected);
            if outcome == AugmentedSolve::Unavailable && solved == AugmentedSolve::Unavailable {
                break;
            }
            if ["bricard", "parallelogram", "parallelogram_row"].contains(&entry.name) {
                assert_eq!(outcome, solved, "{}", entry.name);
                if outcome == AugmentedSolve::Declined {
                    assert_eq!(projected, qd, "{}: changed on declining", entry.name);
                }
                continue;
            }
            assert_eq!(outcome, AugmentedSolve::Solved, "{}", entry.name);
            assert_eq!(solved, AugmentedSolve::Solved, "{}", entry.name);
            solved_here = true;
            let expected: Vec<f64> = qd.iter().zip(&x[..n]).map(|(v, d)| v + d).collect();
            assert_eq!(
                projected.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                expected.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                "{}: not the runtime's projection to the bit",
                entry.name
            );
            let mut after: Vec<f64> = ct.iter().chain(&bias).copied().collect();
            let mut size = after.iter().map(|r| r.abs()).collect::<Vec<_>>();
            for (i, c, v) in jacobian_entries(info, cq, g) {
                after[i] += v * projected[c];
                size[i] = size[i].max((v * projected[c]).abs());
            }
            for i in 0..m {
                let e = after[i].abs() / size[i].max(1e-300);
                assert!(
                    e <= 1e-12,
                    "{}: velocity residual [{i}] {e:.1e}",
                    entry.name
                );
            }
        }
        if solved_here {
            served.push(entry.name);
        }
    }
    eprintln!("orthogonal projection served: {served:?}");
    assert!(served.len() >= 15, "models served: {served:?}");
}

/// The generated row norms of $C_q$ are the dense rows' infinity norms (the maximum is
/// exact, so equal values; NaN where a row has a NaN entry, the other rows unchanged)
/// for every built-in model with holonomic rows, at seeded Jacobians. The runtime's own
/// walk of the pattern is checked against the same dense norms in `scale::tests`.
#[test]
fn the_generated_row_norms_are_the_dense_rows_norms() {
    let mut served = 0;
    for (k, entry) in pfaff_models::all().iter().enumerate() {
        let model = (entry.make)();
        let model = model.as_ref();
        let info = model.info();
        let (n, mh) = (info.nq(), info.nh());
        if mh == 0 {
            continue;
        }
        for sample in velocity_samples(model, 3, 3100 + k as u64) {
            let VelocitySample { mut cq, g, .. } = sample;
            for poisoned in [false, true] {
                if poisoned {
                    // The last entry of the first row's run.
                    let last = info
                        .holonomic_pattern
                        .iter()
                        .rposition(|&(r, _)| r == 0)
                        .expect("row 0 has an entry");
                    cq[last] = f64::NAN;
                }
                let mut dense = vec![0.0; mh * n];
                for (i, c, v) in jacobian_entries(info, &cq, &g) {
                    if i < mh {
                        dense[i * n + c] = v;
                    }
                }
                let mut got = vec![7.0; mh];
                assert!(
                    model.holonomic_row_norms(&cq, &mut got),
                    "{}: no generated row norms",
                    entry.name
                );
                for (i, &norm) in got.iter().enumerate() {
                    let row = &dense[i * n..(i + 1) * n];
                    let nan = row.iter().any(|v| v.is_nan());
                    let max = row.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                    assert!(
                        if nan { norm.is_nan() } else { norm == max },
                        "{} row {i}: {norm} against {max} (NaN entry: {nan})",
                        entry.name
                    );
                }
                if poisoned {
                    assert!(got[0].is_nan(), "{}", entry.name);
                }
            }
        }
        served += 1;
    }
    assert!(served >= 15, "models with holonomic rows: {served}");
}

/// The generated velocity residuals (`Mechanism::velocity_residuals`) against the
/// runtime's sums written here (each row's rate, then its entries in the pattern's
/// order, added left to right): the same bits, on seeded states of every built-in
/// model with constraint rows and seeded rates (the rates' terms exercised on
/// scleronomic models too); a row with a NaN rate gives NaN there and leaves the others
/// as they were. Every model with constraint rows has them (no budget: the sums are
/// linear in the patterns' entries).
#[test]
fn the_generated_velocity_residuals_are_the_runtime_sums_to_the_bit() {
    let mut served = 0;
    for (k, entry) in pfaff_models::all().iter().enumerate() {
        let model = (entry.make)();
        let model = model.as_ref();
        let info = model.info();
        let (mh, mnh) = (info.nh(), info.nnh());
        let m = mh + mnh;
        if m == 0 {
            continue;
        }
        for sample in velocity_samples(model, 3, 2800 + k as u64) {
            let VelocitySample {
                cq,
                g,
                mut ct,
                bias,
                qd,
            } = sample;
            let (cq, g) = (&cq[..], &g[..]);
            for poisoned in [false, true] {
                if poisoned {
                    if mh == 0 {
                        continue;
                    }
                    ct[mh - 1] = f64::NAN;
                }
                let mut expected: Vec<f64> = ct.iter().chain(&bias).copied().collect();
                for (i, c, v) in jacobian_entries(info, cq, g) {
                    expected[i] += v * qd[c];
                }
                let mut got = vec![7.0; m];
                assert!(
                    model.velocity_residuals(cq, g, &ct, &bias, &qd, &mut got),
                    "{}: no generated velocity residuals",
                    entry.name
                );
                assert_eq!(
                    got.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    expected.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    "{}: not the runtime's sums to the bit",
                    entry.name
                );
                if poisoned {
                    assert!(got[mh - 1].is_nan(), "{}", entry.name);
                }
            }
        }
        served += 1;
    }
    assert!(served >= 15, "models with constraint rows: {served}");
}

/// $G = N N^\mathsf{T}$ of the dense row-major `n_rows × n` matrix `a`.
fn dense_gram(a: &[f64], rows: usize, n: usize) -> Vec<f64> {
    let mut g = vec![0.0; rows * rows];
    for i in 0..rows {
        for k in 0..rows {
            g[i * rows + k] = (0..n).map(|c| a[i * n + c] * a[k * n + c]).sum();
        }
    }
    g
}

/// The pivot ratio $\min_k \rho_k / \max_k \rho_k$, $\rho_k = d_k / G_{kk}$, of the
/// dense $L D L^\mathsf{T}$ of `g` (`k × k`, symmetric positive definite), by the
/// textbook loops; 0 at a pivot that is not positive.
fn dense_ldl_ratio(g: &[f64], k: usize) -> f64 {
    let mut l = vec![0.0; k * k];
    let mut d = vec![0.0; k];
    let (mut least, mut most) = (f64::INFINITY, 0.0_f64);
    for j in 0..k {
        d[j] = g[j * k + j]
            - (0..j)
                .map(|p| l[j * k + p] * l[j * k + p] * d[p])
                .sum::<f64>();
        if d[j].is_nan() || d[j] <= 0.0 {
            return 0.0;
        }
        for i in j + 1..k {
            let s: f64 = (0..j).map(|p| l[i * k + p] * l[j * k + p] * d[p]).sum();
            l[i * k + j] = (g[i * k + j] - s) / d[j];
        }
        let rho = d[j] / g[j * k + j];
        least = least.min(rho);
        most = most.max(rho);
    }
    least / most
}

/// The generated position map of partitioning's chart
/// (`Mechanism::holonomic_normal_map`: $X = (N N^\mathsf{T})^{-1} N$, $N = C_q$, with
/// the pivot ratio of $N N^\mathsf{T}$) against its defining equation $N N^\mathsf{T}
/// X = N$ (to 1e-12 of the sizes involved) and the ratio of a dense $L D L^\mathsf{T}$
/// of the Gram matrix formed here (to 1e-9 relative), on seeded states of every built-in
/// model with holonomic rows but the redundant two; with a NaN entry the ratio is 0.
/// The redundant models at a consistent state (dependent rows) give a ratio at
/// round-off, which makes the runtime renew its rows. Checked to fail when the emitted
/// back substitution skips its last term (slider_crank: residual 1e-4).
#[test]
fn the_generated_normal_map_solves_the_gram_system() {
    let mut served = Vec::new();
    for (k, entry) in pfaff_models::all().iter().enumerate() {
        let model = (entry.make)();
        let model = model.as_ref();
        let info = model.info();
        let (n, mh) = (info.nq(), info.nh());
        if mh == 0 {
            continue;
        }
        let lm = info.mass_pattern.len();
        let hol = info.holonomic_pattern.len();
        let mut map = vec![0.0; mh * n];
        if ["bricard", "parallelogram", "parallelogram_row"].contains(&entry.name) {
            let (q, qd) = crate::states::moving_state(model, 0.05);
            let all = terms(model, 0.05, &q, &qd, false);
            let cq = &all[lm + n..lm + n + hol];
            if let Some(ratio) = model.holonomic_normal_map(cq, &mut map) {
                assert!(
                    ratio <= 1e-10,
                    "{}: dependent rows with ratio {ratio:.1e}",
                    entry.name
                );
            }
            continue;
        }
        let mut generated = false;
        for (q, qd) in states(model, 5, 4200 + k as u64) {
            let all = terms(model, 0.3, &q, &qd, false);
            let cq = all[lm + n..lm + n + hol].to_vec();
            map.fill(f64::NAN);
            let Some(ratio) = model.holonomic_normal_map(&cq, &mut map) else {
                break;
            };
            generated = true;
            let mut dense = vec![0.0; mh * n];
            for (i, c, v) in jacobian_entries(info, &cq, &[]) {
                dense[i * n + c] = v;
            }
            let g = dense_gram(&dense, mh, n);
            let expected = dense_ldl_ratio(&g, mh);
            assert!(
                (ratio - expected).abs() <= 1e-9 * expected,
                "{}: ratio {ratio:e} against {expected:e}",
                entry.name
            );
            let norm = |v: &[f64]| v.iter().fold(0.0_f64, |s, x| s.max(x.abs()));
            let size = norm(&g) * norm(&map) + norm(&dense);
            for i in 0..mh {
                for c in 0..n {
                    let gx: f64 = (0..mh).map(|j| g[i * mh + j] * map[j * n + c]).sum();
                    let e = (gx - dense[i * n + c]).abs() / size;
                    assert!(e <= 1e-12, "{}: (GX − N)[{i}, {c}] {e:.1e}", entry.name);
                }
            }
            let mut poisoned = cq.clone();
            poisoned[hol - 1] = f64::NAN;
            assert_eq!(
                model.holonomic_normal_map(&poisoned, &mut map),
                Some(0.0),
                "{}: a NaN entry",
                entry.name
            );
        }
        if generated {
            served.push(entry.name);
        }
    }
    eprintln!("normal map served: {served:?}");
    assert!(served.len() >= 15, "models served: {served:?}");
}

/// The residuals of $[M\ J^\mathsf{T}; J\ 0][\ddot q; \lambda] = b$ for the solution
/// `x`: the largest of the coordinates' rows relative to the largest of their terms,
/// and the same for the constraints' rows (a block has its own units; a row's own
/// terms may all vanish, where a row-wise ratio would compare round-off with itself).
fn augmented_residual(
    info: &Info,
    mass: &[f64],
    cq: &[f64],
    g: &[f64],
    b: &[f64],
    x: &[f64],
) -> f64 {
    let n = info.nq();
    let mut r = b.iter().map(|v| -v).collect::<Vec<_>>();
    let mut size = [0.0_f64; 2];
    for (i, v) in b.iter().enumerate() {
        size[usize::from(i >= n)] = size[usize::from(i >= n)].max(v.abs());
    }
    let mut add = |i: usize, v: f64| {
        r[i] += v;
        size[usize::from(i >= n)] = size[usize::from(i >= n)].max(v.abs());
    };
    for (&(i, j), &v) in info.mass_pattern.iter().zip(mass) {
        add(i as usize, v * x[j as usize]);
    }
    for (row, col, v) in jacobian_entries(info, cq, g) {
        add(row + n, v * x[col]);
        add(col, v * x[n + row]);
    }
    r.iter().enumerate().fold(0.0_f64, |e, (i, r)| {
        e.max(r.abs() / size[usize::from(i >= n)].max(1e-300))
    })
}

/// The generated solve tries a partition of the coordinates first (the null-space
/// method, `macros/codegen/src/emit/nullspace.rs`), chosen at compile time, and hands
/// the system to its range-space factorization where a pivot of that partition falls
/// below 1e-2 of its row. Each entry of $J$ of every model with a generated solve, in
/// turn, made 1e-9 of its size at a seeded state (a pivot of the partition among them,
/// which unchecked would grow the elimination by 1e9): wherever the solve solves, the
/// solution meets the augmented system to 1e-7 of its terms (backward error; the
/// range-space code's own pivot test, 1e-8 of the starting diagonal, admits growth to
/// 1e8, and slider_crank_bodies reaches 7e-10), and on the unmodified systems to
/// 1e-10. Checked to fail with the threshold set to 0 (pendulum, its one entry of $J$
/// in the chosen column made small: 8e-3).
#[test]
fn a_degraded_partition_hands_the_solve_to_the_range_space_code() {
    let mut solved = 0;
    for entry in generated_solve_models() {
        let model = (entry.make)();
        let model = model.as_ref();
        let info = model.info();
        let SolveInputs { mass, cq, g, b } = solve_inputs(model, 43);
        let (lc, lg) = (cq.len(), g.len());
        let mut x = b.clone();
        if model.augmented_solve(&mass, &cq, &g, &mut x) == AugmentedSolve::Unavailable {
            continue;
        }
        let e = augmented_residual(info, &mass, &cq, &g, &b, &x);
        assert!(
            e <= 1e-10,
            "{}: residual {e:.1e} at a regular state",
            info.name
        );
        for k in 0..lc + lg {
            let (mut cq, mut g) = (cq.clone(), g.clone());
            if k < lc {
                cq[k] *= 1e-9;
            } else {
                g[k - lc] *= 1e-9;
            }
            let mut x = b.clone();
            if model.augmented_solve(&mass, &cq, &g, &mut x) != AugmentedSolve::Solved {
                continue;
            }
            solved += 1;
            let e = augmented_residual(info, &mass, &cq, &g, &b, &x);
            assert!(
                e <= 1e-7,
                "{}: residual {e:.1e} with entry {k} of J made small",
                info.name
            );
        }
    }
    assert!(solved > 100, "systems solved: {solved}");
}
