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

/// The crank angle of the parallelogram from its one-degree-of-freedom equation, the
/// reference of the runs through the flat configurations: on the motion $\varphi = 0$,
/// $x = l\cos\theta$, $y = l\sin\theta$, so the model's energies
/// (models/src/parallelogram.rs) reduce to $T = \frac12(m_k + m_c)l^2\dot\theta^2$ and
/// $V = (\frac32 m_k + m_c)gl\sin\theta$, and
/// $\ddot\theta = -\frac{(3m_k/2 + m_c)\,g}{(m_k + m_c)\,l}\cos\theta$. Integrated by
/// classical Runge–Kutta with $h = 10^{-5}$ (error $O(h^4)$, below $10^{-13}$ here:
/// $\theta(2) = -0.52337739598091$ against $-0.5233773959809127$ from SciPy's DOP853 at
/// rtol $10^{-14}$).
fn crank_angle(theta0: f64, omega0: f64, t_end: f64) -> (f64, f64) {
    let (mk, mc, l, g) = (1.0, 2.0, 0.5, 9.81);
    let k = (1.5 * mk + mc) * g / ((mk + mc) * l);
    let f = |th: f64, w: f64| (w, -k * th.cos());
    let steps = (t_end / 1e-5).round() as usize;
    let h = t_end / steps as f64;
    let (mut th, mut w) = (theta0, omega0);
    for _ in 0..steps {
        let k1 = f(th, w);
        let k2 = f(th + 0.5 * h * k1.0, w + 0.5 * h * k1.1);
        let k3 = f(th + 0.5 * h * k2.0, w + 0.5 * h * k2.1);
        let k4 = f(th + h * k3.0, w + h * k3.1);
        th += h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
        w += h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
    }
    (th, w)
}

#[test]
fn parallelogram_runs_through_its_flat_configurations() {
    // The default state (θ = π/3 turning at 1 rad/s) swings over the top: the cranks
    // pass the flat configurations θ = 0 (t ≈ 0.497) and θ = −π (t ≈ 0.880), where the
    // three pin_x rows coincide and C_q has rank 4 instead of 5 while the solution set
    // stays one smooth curve. Every analysis drops the rows the shared rank rule calls
    // dependent there and takes them back after
    // (docs/decisions/0036-through-a-rank-drop.md). Loose and tight tolerances, both
    // formulations, every adaptive integrator.
    // The tight one is 1e-11: below it an accepted state can land so near the flat
    // crossing at t ≈ 1.69006 that every attempt from it fails the dropped rows' check.
    // The driver then takes the step that reached it back and redoes it shorter
    // (`tight_runs_through_the_flat_crossings_take_failing_steps_back`), which saves
    // most such runs but not all: projection + DOP853 at 1e-12 and projection + Adams
    // at 5e-13 still end there with the typed error, over [0, 3] s
    // (docs/decisions/0036-through-a-rank-drop.md), a known defect of the rank-drop
    // handling, not a bound of
    // this test.
    let model = parallelogram::Model::default();
    let (theta, omega) = crank_angle(std::f64::consts::FRAC_PI_3, 1.0, 2.0);
    assert!((theta - -0.523_377_395_980_912_7).abs() < 1e-12, "{theta}");
    for (form, method, rtol) in [Formulation::Projection, Formulation::Partitioning]
        .into_iter()
        .flat_map(|f| Method::ADAPTIVE.map(|m| (f, m)))
        .flat_map(|(f, m)| [(f, m, 1e-4), (f, m, 1e-8), (f, m, 1e-11)])
    {
        let run = Simulation::new(&model)
            .formulation(form)
            .integrator(method)
            .tolerances(rtol, rtol)
            .run(2.0)
            .unwrap_or_else(|e| panic!("{} {} {rtol:.0e}: {e}", form.name(), method.name()));
        let last = run.trajectory.len() - 1;
        let (q, qd) = (run.trajectory.q(last), run.trajectory.qd(last));
        let (e_theta, e_omega) = ((q[1] - theta).abs(), (qd[1] - omega).abs());
        let drift = run.monitors.max_energy_drift.unwrap();
        eprintln!(
            "{} {} {rtol:.0e}: θ error {e_theta:.1e}, θ' error {e_omega:.1e}, energy drift {drift:.1e}, φ {:.1e}, re-partitions {}",
            form.name(),
            method.name(),
            q[5],
            run.stats.repartitions
        );
        // The error is the integrator's, down to a floor of about 1e-8 set by the
        // rank drop itself: there C_q fixes φ only to the square root of the Newton
        // tolerance (docs/decisions/0036-through-a-rank-drop.md).
        let bound = 1e3 * rtol + 5e-8;
        assert!(
            e_theta < bound && e_omega < 3.0 * bound,
            "{e_theta:e} {e_omega:e}"
        );
        assert!(drift < bound * 15.0, "{drift:e}");
        assert!(q[5].abs() < 1e-9, "φ = {:e}", q[5]);
    }
}

/// The parallelogram with a longer third crank whose pivot is raised so that the three
/// cranks meet the coupler when upright: at θ = π/2 the three pin_y rows are dependent
/// (rank 5 of 6), but the motion the velocities start is not possible (the cranks turn
/// at ẋ/l and ẋ/l₃, and the pin_y rows' accelerations then ask for ÿ = −ẋ²/l and
/// ÿ = −ẋ²/l₃): the mechanism locks, and the redundant rows are inconsistent.
#[pfaff::mechanism]
pub mod locked_parallelogram {
    const l: f64 = 0.5;
    const l3: f64 = 0.6;
    const d: f64 = 0.4;
    const mk: f64 = 1.0;
    const mc: f64 = 2.0;
    const g: f64 = 9.81;

    static th1: Coordinate = Coordinate {};
    static th2: Coordinate = Coordinate {};
    static th3: Coordinate = Coordinate {};
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    static phi: Coordinate = Coordinate {};

    fn kinetic_energy() -> f64 {
        0.5 * (mk * l * l / 3.0) * (th1.dot().powi(2) + th2.dot().powi(2))
            + 0.5 * (mk * l3 * l3 / 3.0) * th3.dot().powi(2)
            + 0.5 * mc * (x.dot().powi(2) + y.dot().powi(2))
            + 0.5 * (mc * 4.0 * d * d / 12.0) * phi.dot().powi(2)
    }

    fn potential_energy() -> f64 {
        mk * g * 0.5 * (l * th1.sin() + l * th2.sin() + l3 * th3.sin()) + mc * g * y
    }

    #[holonomic]
    fn pin1_x() -> f64 {
        x - d * phi.cos() + d - l * th1.cos()
    }

    #[holonomic]
    fn pin1_y() -> f64 {
        y - d * phi.sin() - l * th1.sin()
    }

    #[holonomic]
    fn pin2_x() -> f64 {
        x - l * th2.cos()
    }

    #[holonomic]
    fn pin2_y() -> f64 {
        y - l * th2.sin()
    }

    #[holonomic]
    fn pin3_x() -> f64 {
        x + d * phi.cos() - d - l3 * th3.cos()
    }

    #[holonomic]
    fn pin3_y() -> f64 {
        y + d * phi.sin() - (l - l3) - l3 * th3.sin()
    }
}

#[test]
fn an_inconsistent_redundant_set_is_still_an_error() {
    use pfaff::sim::SimErrorKind;
    let model = locked_parallelogram::Model::default();
    let (l, l3) = (0.5, 0.6);
    let h = std::f64::consts::FRAC_PI_2;
    let q0 = [h, h, h, 0.0, l, 0.0];
    // ẋ = −l: the cranks' tips move along x only, θ̇ᵢ = −ẋ/lᵢ.
    let qd0 = [1.0, 1.0, l / l3, -l, 0.0, 0.0];
    for form in [Formulation::Projection, Formulation::Partitioning] {
        for rtol in [1e-4, 1e-12] {
            let err = Simulation::new(&model)
                .formulation(form)
                .initial_state(&q0, &qd0)
                .tolerances(rtol, rtol)
                .run(0.1)
                .unwrap_err();
            eprintln!("{} {rtol:.0e}: {err}", form.name());
            let SimErrorKind::Analysis(pfaff::Error::Dynamics(
                pfaff::DynamicsError::InconsistentRedundant {
                    ref constraints,
                    residual,
                    t,
                    ref vanishing,
                },
            )) = err.kind
            else {
                panic!("{}: {err}", form.name());
            };
            // The typed error carries the time its message names.
            assert_eq!(err.t(), Some(t));
            assert!(!constraints.is_empty() && constraints.iter().all(|c| c.ends_with("_y")));
            // Dependent rows, not degenerate ones: none of their gradients vanishes.
            assert!(vanishing.is_empty(), "{vanishing:?}");
            // ẋ²|1/l − 1/l₃| = 0.0833 m/s², of order 1 against the tolerance.
            assert!(residual > 1e-2, "{residual:e}");
        }
    }
}

/// A run that fails at a state it kept ends its partial run at that state. The case is
/// the known failure of `parallelogram_runs_through_its_flat_configurations`' note:
/// projection + DOP853 at rtol = atol = 1e-12 over [0, 3] s keeps a state next to the
/// flat crossing at t ≈ 1.69006 from which every evaluation fails the dropped rows'
/// check. The partial run used to end at t = 0 (the analysis at the kept state failed,
/// so no row was recorded, and the error named no time): it must end at the last
/// accepted state, with its positions and velocities and NaN multipliers, and the
/// error must carry its time. Should that failure be fixed, this test needs another
/// run that fails at its kept state.
#[test]
fn a_run_failing_at_its_kept_state_ends_its_partial_run_there() {
    let model = parallelogram::Model::default();
    let err = Simulation::new(&model)
        .formulation(Formulation::Projection)
        .integrator(Method::Dop853)
        .tolerances(1e-12, 1e-12)
        .output_times(&[])
        .run(3.0)
        .unwrap_err();
    eprintln!("{err}");
    let t = err.t().expect("the failure's time");
    assert!((1.6900..1.6901).contains(&t), "{t}");
    let tr = &err.partial.trajectory;
    let last = tr.len() - 1;
    let t_last = tr.t[last];
    assert!(t_last <= t && t - t_last < 1e-6, "{t_last} against {t}");
    assert!(tr.q(last).iter().chain(tr.qd(last)).all(|x| x.is_finite()));
    // The cranks are at the flat configuration θ = −π.
    assert!(
        (tr.q(last)[1] + std::f64::consts::PI).abs() < 1e-4,
        "{:?}",
        tr.q(last)
    );
    assert!(tr.lambda(last).iter().all(|l| l.is_nan()));
}

/// Runs that ended at a flat crossing before the driver took failing steps back
/// (`sim::driver`, `MAX_STEP_BACKS`): an accepted state next to the crossing from which
/// every attempt failed (partitioning + Adams at 2e-13 and 1e-13: the step size's
/// underflow at t ≈ 1.69006; projection + Adams at 2e-13: the same; partitioning +
/// Radau5 at 5e-11 and 2e-11: the chart's Newton iteration stalling at t ≈ 0.4973).
/// They now run through the crossings to t = 3 s, with the accuracy of the module's
/// other tight runs: the crank angle against the reference of `crank_angle`.
#[test]
fn tight_runs_through_the_flat_crossings_take_failing_steps_back() {
    let model = parallelogram::Model::default();
    let (theta, omega) = crank_angle(std::f64::consts::FRAC_PI_3, 1.0, 3.0);
    for (form, method, rtol) in [
        (Formulation::Partitioning, Method::Adams, 2e-13),
        (Formulation::Partitioning, Method::Adams, 1e-13),
        (Formulation::Projection, Method::Adams, 2e-13),
        (Formulation::Partitioning, Method::Radau5, 5e-11),
        (Formulation::Partitioning, Method::Radau5, 2e-11),
    ] {
        let run = Simulation::new(&model)
            .formulation(form)
            .integrator(method)
            .tolerances(rtol, rtol)
            .output_times(&[])
            .run(3.0)
            .unwrap_or_else(|e| panic!("{} {} {rtol:.0e}: {e}", form.name(), method.name()));
        let last = run.trajectory.len() - 1;
        let (q, qd) = (run.trajectory.q(last), run.trajectory.qd(last));
        let (e_theta, e_omega) = ((q[1] - theta).abs(), (qd[1] - omega).abs());
        eprintln!(
            "{} {} {rtol:.0e}: θ error {e_theta:.1e}, θ' error {e_omega:.1e}, restarts {}",
            form.name(),
            method.name(),
            run.stats.restarts
        );
        // The floor of the crossings (`parallelogram_runs_through_its_flat_configurations`)
        // over [0, 3] s: runs that never failed reach 2e-11 to 1.9e-8 in θ at rtol
        // 1e-11 to 1e-13; those that step back 4e-11 to 7e-8 (measured), the restart
        // being made at a crossing, where C_q fixes φ only to the square root of the
        // Newton tolerance.
        let bound = 1e3 * rtol + 1e-7;
        assert!(
            e_theta < bound && e_omega < 3.0 * bound,
            "{e_theta:e} {e_omega:e}"
        );
        assert!(q[5].abs() < 1e-9, "φ = {:e}", q[5]);
    }
}
