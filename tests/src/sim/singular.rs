//! Integration through isolated rank drops of $C_q$: the `parallelogram` turning full
//! circles and the `parallelogram_row` (four windows on one coupler), whose flat
//! configurations $\theta = 0, \pi$ (all links collinear) make the pin_x rows coincide
//! for an instant while the motion stays on the parallelogram branch
//! (docs/decisions/0100-singular-configurations.md).
//!
//! Reference: on the branch every crank turns at the same angle $\theta$, $\varphi = 0$,
//! $x = l\cos\theta$, $y = l\sin\theta$, so the motion is that of the one-coordinate
//! system [`equivalent_crank`] with the inertia and the potential the models' energies
//! reduce to: with $n$ cranks of mass $m_k$ (inertia $m_k l^2/3$ about the pivot) and a
//! coupler of mass $m_c$ in translation,
//! $T = \frac12(n m_k/3 + m_c)l^2\dot\theta^2$, $V = (\frac n2 m_k + m_c)gl\sin\theta$.
//! It has no constraint, and is integrated by DOP853 at rtol = atol = 1e-13, checked
//! against its own energy integral and against classical Runge–Kutta.
//!
//! These runs complete on the current rank-drop handling; the failures met at rtol
//! 1e-10 and below over longer spans are recorded, not fixed, in the decision record.

use std::f64::consts::FRAC_PI_3;

use pfaff::sim::{Formulation, Method, Run, Simulation};
use pfaff::Mechanism;
use pfaff_models::{parallelogram, parallelogram_row};

/// The one-degree-of-freedom system equivalent to `cranks` cranks carrying a coupler on the
/// parallelogram branch (module docs), written from its energies.
#[pfaff::mechanism]
pub mod equivalent_crank {
    /// Number of cranks.
    const cranks: f64 = 3.0;
    const l: f64 = 0.5;
    const mk: f64 = 1.0;
    const mc: f64 = 2.0;
    const g: f64 = 9.81;

    static th: Coordinate = Coordinate {};

    fn kinetic_energy() -> f64 {
        0.5 * (cranks * mk / 3.0 + mc) * l * l * th.dot().powi(2)
    }

    fn potential_energy() -> f64 {
        (0.5 * cranks * mk + mc) * g * l * th.sin()
    }
}

/// Start angle and rate: over the top, full turns (the rate at the top is
/// $\sqrt{\omega_0^2 - 2(V(\pi/2) - V(\pi/3))/I}$, real for both models).
const THETA0: f64 = FRAC_PI_3;
const OMEGA0: f64 = 6.0;
/// Span: about 2.6 turns, five flat crossings (θ = 0 or π modulo 2π).
const T_END: f64 = 2.0;

/// $(\theta, \dot\theta)$ at `T_END` of the equivalent system of `cranks` cranks.
fn reference(cranks: usize) -> (f64, f64) {
    let mut model = equivalent_crank::Model::default();
    let index = model.info().parameter_index("cranks").unwrap();
    model.set_parameter(index, cranks as f64);
    let run = Simulation::new(&model)
        .formulation(Formulation::Unconstrained)
        .integrator(Method::Dop853)
        .initial_state(&[THETA0], &[OMEGA0])
        .tolerances(1e-13, 1e-13)
        .run(T_END)
        .unwrap();
    let last = run.trajectory.len() - 1;
    let (th, w) = (run.trajectory.q(last)[0], run.trajectory.qd(last)[0]);
    // Independent checks of the reference: its energy integral, and classical RK4
    // at h = 1e-5 on θ'' = −(n m_k/2 + m_c) g cos θ / ((n m_k/3 + m_c) l).
    let (l, mk, mc, g, nf) = (0.5, 1.0, 2.0, 9.81, cranks as f64);
    let inertia = (nf * mk / 3.0 + mc) * l * l;
    let k = (0.5 * nf * mk + mc) * g * l / inertia;
    let energy = |th: f64, w: f64| 0.5 * w * w + k * th.sin();
    assert!((energy(th, w) - energy(THETA0, OMEGA0)).abs() < 1e-11);
    let f = |th: f64, w: f64| (w, -k * th.cos());
    let (mut a, mut b, h) = (THETA0, OMEGA0, 1e-5);
    for _ in 0..(T_END / h).round() as usize {
        let k1 = f(a, b);
        let k2 = f(a + 0.5 * h * k1.0, b + 0.5 * h * k1.1);
        let k3 = f(a + 0.5 * h * k2.0, b + 0.5 * h * k2.1);
        let k4 = f(a + h * k3.0, b + h * k3.1);
        a += h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
        b += h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
    }
    assert!((a - th).abs() < 1e-10 && (b - w).abs() < 1e-9, "{a} {th}");
    (th, w)
}

/// The state of `cranks` cranks at angle θ turning at ω on the branch:
/// `[th_1 … th_n, x, y, phi]` and their rates.
fn branch_state(cranks: usize, th: f64, w: f64) -> (Vec<f64>, Vec<f64>) {
    let l = 0.5;
    let mut q = vec![th; cranks];
    q.extend([l * th.cos(), l * th.sin(), 0.0]);
    let mut qd = vec![w; cranks];
    qd.extend([-l * th.sin() * w, l * th.cos() * w, 0.0]);
    (q, qd)
}

/// The pairs integrated through the flat configurations.
const PAIRS: [(Formulation, Method); 7] = [
    (Formulation::Partitioning, Method::Adams),
    (Formulation::Partitioning, Method::Dop853),
    (Formulation::Partitioning, Method::Dopri5),
    (Formulation::Partitioning, Method::Radau5),
    (Formulation::Projection, Method::Adams),
    (Formulation::Projection, Method::Dop853),
    (Formulation::Projection, Method::Dopri5),
];

/// Runs `model` (`cranks` cranks) with every pair at rtol = atol = 1e-3, 1e-6, 1e-9 and
/// checks each run against the reference: completed, on the branch (crank angles equal,
/// coupler level), its final angle within a bound that follows the tolerance, and the
/// error falling as the tolerance falls.
fn through_flat_crossings(model: &dyn Mechanism, cranks: usize) {
    let (theta, omega) = reference(cranks);
    // Five flat crossings in the span: θ from π/3 to beyond 2.5 turns.
    let crossings = (theta / std::f64::consts::PI).floor() as i64;
    assert!(crossings >= 5, "{theta}");
    let (q0, qd0) = branch_state(cranks, THETA0, OMEGA0);
    for (form, method) in PAIRS {
        let mut errors = Vec::new();
        for rtol in [1e-3, 1e-6, 1e-9] {
            let run: Run = Simulation::new(model)
                .formulation(form)
                .integrator(method)
                .initial_state(&q0, &qd0)
                .tolerances(rtol, rtol)
                .run(T_END)
                .unwrap_or_else(|e| panic!("{} {} {rtol:.0e}: {e}", form.name(), method.name()));
            let last = run.trajectory.len() - 1;
            let (q, qd) = (run.trajectory.q(last), run.trajectory.qd(last));
            let th = &q[..cranks];
            let spread = th.iter().fold(0.0_f64, |a, t| a.max((t - th[0]).abs()));
            let phi = q[cranks + 2];
            let (e_theta, e_omega) = ((th[0] - theta).abs(), (qd[0] - omega).abs());
            let s = &run.stats;
            eprintln!(
                "{} {} {} {rtol:.0e}: θ error {e_theta:.1e}, θ' error {e_omega:.1e}, spread {spread:.1e}, φ {phi:.1e}; {} steps ({} rejected), {} evaluations, {} Newton, {} re-partitions",
                model.info().name,
                form.name(),
                method.name(),
                s.steps,
                s.rejected,
                s.rhs_evals,
                s.newton_iterations,
                s.repartitions
            );
            // On the branch: the cranks at one angle, the coupler level (the
            // constraints hold to the Newton tolerance at kept states).
            assert!(spread < 1e-9 * theta.abs(), "spread {spread:e}");
            assert!(phi.abs() < 1e-9, "φ = {phi:e}");
            // Against the reference: the integrator's error over five crossings, with
            // a floor for the crossings themselves (decision record 0100; measured
            // at rtol 1e-9: 1.5e-11 to 9.9e-8).
            let bound = 2e3 * rtol + 3e-7;
            assert!(e_theta < bound, "θ error {e_theta:e} > {bound:e}");
            errors.push(e_theta);
        }
        // The error falls with the tolerance, from the loosest to the tightest.
        assert!(
            errors[2] < errors[1] && errors[1] < errors[0],
            "{} {}: {errors:?}",
            form.name(),
            method.name()
        );
    }
}

#[test]
fn the_parallelogram_turns_through_its_flat_configurations() {
    through_flat_crossings(&parallelogram::Model::default(), 3);
}

#[test]
fn the_parallelogram_row_turns_through_its_flat_configurations() {
    // The model's own default state is the branch state of `branch_state`.
    let model = parallelogram_row::Model::default();
    let (q0, qd0) = branch_state(5, THETA0, OMEGA0);
    let (mut q, mut qd) = (vec![0.0; 8], vec![0.0; 8]);
    model.initial_state(&mut q, &mut qd);
    for (k, (a, b)) in q.iter().zip(&q0).enumerate() {
        assert!((a - b).abs() < 1e-15, "q[{k}] {a} {b}");
    }
    for (k, (a, b)) in qd.iter().zip(&qd0).enumerate() {
        assert!((a - b).abs() < 1e-14, "qd[{k}] {a} {b}");
    }
    through_flat_crossings(&model, 5);
}
