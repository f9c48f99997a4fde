//! Impacts inside simulations (docs/theory.md §impacts-in-a-run): event location, the jump, the restart,
//! accumulation into resting contact and its release, simultaneous contacts, and a
//! singular impact as a typed error with the run kept. Closed forms are cited per test.

use pfaff::sim::{ContactEventKind, Formulation, Method, Run, SimErrorKind, Simulation};
use pfaff::{ImpactError, Mechanism, MechanismExt};
use pfaff_models::{bouncing_ball, falling_rod, newtons_cradle, pendulum_floor};

fn methods() -> Vec<Method> {
    vec![Method::Dopri5, Method::Dop853, Method::Adams]
}

fn formulations() -> Vec<Formulation> {
    vec![
        Formulation::Partitioning,
        Formulation::Projection,
        Formulation::baumgarte(),
        Formulation::Unconstrained,
    ]
}

fn run(model: &dyn Mechanism, f: Formulation, m: Method, t_end: f64) -> Run {
    Simulation::new(model)
        .formulation(f)
        .integrator(m)
        .tolerances(1e-10, 1e-12)
        .output_every(0.01)
        .run(t_end)
        .unwrap_or_else(|e| panic!("{} {f:?} {m:?}: {e}", model.info().name))
}

/// The bouncing ball (h = 1, e = 0.5, g = 9.81): impact n at
/// t_n = T (1 + 2 Σ_{k<n} e^k) with T = √(2h/g), rebound speed e^n √(2gh) (so the
/// rebound height is e^{2n} h), and the accumulation time T (1+e)/(1−e)
/// (docs/models.md), after which the ball rests on the ground.
#[test]
fn bouncing_ball_impact_times_heights_and_accumulation() {
    let model = bouncing_ball::Model::default();
    let (h, e, g) = (1.0_f64, 0.5_f64, 9.81_f64);
    let tt = (2.0 * h / g).sqrt();
    let v0 = (2.0 * g * h).sqrt();
    let t_inf = tt * (1.0 + e) / (1.0 - e);
    for f in formulations() {
        for m in methods() {
            let r = run(&model, f, m, 2.0);
            assert!(
                r.impacts.len() > 10,
                "{f:?} {m:?}: {} impacts",
                r.impacts.len()
            );
            let mut t_n = tt;
            for (n, imp) in r.impacts.iter().take(10).enumerate() {
                let k = i32::try_from(n).unwrap();
                assert!(
                    (imp.t - t_n).abs() < 1e-8,
                    "{f:?} {m:?}: impact {n} at {} against {t_n}",
                    imp.t
                );
                let v = e.powi(k + 1) * v0;
                assert!(
                    (imp.qd_after[0] - v).abs() < 1e-7,
                    "{f:?} {m:?}: rebound {n}"
                );
                let height = imp.qd_after[0].powi(2) / (2.0 * g);
                assert!((height - e.powi(2 * k + 2) * h).abs() < 1e-7);
                assert!(imp.energy_lost() > 0.0);
                t_n += 2.0 * e.powi(k + 1) * v0 / g;
            }
            let rest: Vec<_> = r
                .contact_events
                .iter()
                .filter(|c| c.kind == ContactEventKind::Rest)
                .collect();
            assert_eq!(rest.len(), 1, "{f:?} {m:?}: {:?}", r.contact_events);
            assert!(
                (rest[0].t - t_inf).abs() < 1e-6,
                "{f:?} {m:?}: rest at {} against {t_inf}",
                rest[0].t
            );
            let (_, q, qd) = r.final_state().unwrap();
            assert!(
                q[0].abs() < 1e-9 && qd[0].abs() < 1e-9,
                "{f:?} {m:?}: {q:?} {qd:?}"
            );
        }
    }
}

/// At rest on the ground, an upward pull `pull_rate·(t − pull_start)` lifts the ball
/// when it exceeds the weight, at t = pull_start + m g / pull_rate = 2 + 9.81/10; after
/// it, ÿ = (F − m g)/m = 10 (t − t_r), so y = (10/6)(t − t_r)³.
#[test]
fn bouncing_ball_releases_under_an_upward_pull() {
    let mut model = bouncing_ball::Model::default();
    let info = model.info();
    model.set_parameter(info.parameter_index("pull_rate").unwrap(), 10.0);
    let t_r = 2.0 + 9.81 / 10.0;
    for m in methods() {
        let r = run(&model, Formulation::Partitioning, m, 3.5);
        let release: Vec<_> = r
            .contact_events
            .iter()
            .filter(|c| c.kind == ContactEventKind::Release)
            .collect();
        assert_eq!(release.len(), 1, "{m:?}: {:?}", r.contact_events);
        assert!((release[0].t - t_r).abs() < 1e-6, "{m:?}: {}", release[0].t);
        let (t, q, _) = r.final_state().unwrap();
        let y = 10.0 / 6.0 * (t - t_r).powi(3);
        assert!((q[0] - y).abs() < 1e-6, "{m:?}: y = {} against {y}", q[0]);
    }
}

/// Falling rod (docs/models.md defaults): the lower end strikes at
/// t* = (v − speed)/g with v = √(speed² + 2 g gap); then P = (1+e) m v / (1 + 3cos²φ),
/// ẏ⁺ = −v + P/m, φ̇⁺ = −6 P cos φ/(m l).
#[test]
fn falling_rod_first_impact_against_the_closed_form() {
    let model = falling_rod::Model::default();
    let (speed, gap, g, e, phi) = (
        1.0_f64,
        0.01_f64,
        9.81_f64,
        0.5,
        std::f64::consts::FRAC_PI_4,
    );
    let v = (speed * speed + 2.0 * g * gap).sqrt();
    let t_star = (v - speed) / g;
    let p = (1.0 + e) * v / (1.0 + 3.0 * phi.cos().powi(2));
    for f in formulations() {
        for m in methods() {
            let r = run(&model, f, m, 0.05);
            let imp = &r.impacts[0];
            assert_eq!(imp.names, ["lower_end"]);
            assert!((imp.t - t_star).abs() < 1e-9, "{f:?} {m:?}: {}", imp.t);
            assert!((imp.impulses[0] - p).abs() < 1e-8);
            assert!((imp.qd_after[1] - (-v + p)).abs() < 1e-8);
            assert!((imp.qd_after[2] - (-6.0 * p * phi.cos())).abs() < 1e-8);
        }
    }
}

/// Newton's cradle, e = 1, equal masses: ball 1 strikes ball 2, which passes the
/// impulse to ball 3 at the same instant (the sequential law): ball 1 and ball 2 stop,
/// ball 3 leaves with ball 1's impact speed.
#[test]
fn newtons_cradle_one_ball_in_one_ball_out() {
    let model = newtons_cradle::Model::default();
    for m in methods() {
        let r = run(&model, Formulation::Partitioning, m, 0.4);
        assert!(r.impacts.len() >= 2, "{m:?}: {:?}", r.impacts.len());
        let (a, b) = (&r.impacts[0], &r.impacts[1]);
        assert_eq!(a.names, ["balls12"]);
        assert_eq!(b.names, ["balls23"]);
        assert_eq!(a.t, b.t);
        let w = a.qd_before[0];
        assert!(w > 0.0);
        let after = &b.qd_after;
        assert!(
            after[0].abs() < 1e-12 * w && after[1].abs() < 1e-12 * w,
            "{after:?}"
        );
        assert!((after[2] - w).abs() < 1e-12 * w, "{after:?}");
        assert!(a.energy_lost().abs() < 1e-12 && b.energy_lost().abs() < 1e-12);
    }
}

/// The double pendulum starts at V15's impact instant: the contact closed at t = 0 is
/// handled before the first step, with V15's result (φ̇⁺ = (11/52, −67/52)).
#[test]
fn contact_closed_at_the_start_is_an_impact_at_t0() {
    let model = pendulum_floor::Model::default();
    for f in [Formulation::Partitioning, Formulation::Projection] {
        for m in methods() {
            let r = run(&model, f, m, 0.1);
            let imp = &r.impacts[0];
            assert_eq!(imp.t, 0.0);
            assert!((imp.impulses[0] - 165.0 / 104.0).abs() < 1e-9);
            assert!((imp.qd_after[2] - 11.0 / 52.0).abs() < 1e-9);
            assert!((imp.qd_after[5] + 67.0 / 52.0).abs() < 1e-9);
            let qd0 = r.trajectory.qd(0);
            assert!(
                (qd0[2] - 11.0 / 52.0).abs() < 1e-9,
                "the first row is after the jump"
            );
        }
    }
}

/// The energy monitors of a run with impacts, one of them at t = 0 (`pendulum_floor`,
/// docs/theory.md V15): the initial energy is that of the state as given, before the jump
/// at t = 0; the impacts' losses are summed apart (their `energy_lost`, so
/// E_final = E_initial − lost up to the integration's drift), and the drift excludes
/// them.
#[test]
fn the_energy_monitor_sets_the_impacts_losses_apart() {
    let model = pendulum_floor::Model::default();
    let (mut q, mut qd) = (vec![0.0; 6], vec![0.0; 6]);
    model.initial_state(&mut q, &mut qd);
    for f in [Formulation::Partitioning, Formulation::Projection] {
        let r = run(&model, f, Method::Dop853, 0.2);
        let m = &r.monitors;
        let given = model.energy(0.0, &q, &qd);
        let e0 = m.energy_initial.unwrap();
        assert!(
            (e0 - given).abs() <= 1e-12 * given.abs().max(1.0),
            "{e0} {given}"
        );
        let lost: f64 = r.impacts.iter().map(|i| i.energy_lost()).sum();
        assert!(r.impacts[0].t == 0.0 && r.impacts[0].energy_lost() > 0.0);
        assert!(
            (m.energy_lost_in_impacts - lost).abs() <= 1e-12 * lost,
            "{m:?} {lost}"
        );
        let e1 = m.energy_final.unwrap();
        let drift = m.max_energy_drift.unwrap();
        assert!(drift < 1e-7, "{m:?}");
        assert!((e1 - (e0 - lost)).abs() <= drift + 1e-12, "{m:?}");
    }
}

/// A ball on a rail written twice (a redundant constraint the simulation accepts):
/// at the impact the rows of `[J; D]` are dependent, the impulses undetermined, and the
/// run stops with the typed error naming the two rail rows, the rows before it kept.
#[pfaff::mechanism]
pub mod twice_railed {
    const e: f64 = 0.5;
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate { q0: 0.5 };
    fn kinetic_energy() -> f64 {
        0.5 * (x.dot().powi(2) + y.dot().powi(2))
    }
    fn potential_energy() -> f64 {
        9.81 * y
    }
    /// The rail.
    #[holonomic]
    fn rail() -> f64 {
        x
    }
    /// The rail again.
    #[holonomic]
    fn rail_again() -> f64 {
        2.0 * x
    }
    /// The ground.
    #[contact(e)]
    fn floor() -> f64 {
        y
    }
}

#[test]
fn singular_impact_stops_the_run_with_the_constraints_named() {
    let model = twice_railed::Model::default();
    let t_hit = (2.0 * 0.5 / 9.81_f64).sqrt();
    let err = Simulation::new(&model)
        .formulation(Formulation::Projection)
        .output_every(0.01)
        .run(1.0)
        .expect_err("singular impact");
    match &err.kind {
        SimErrorKind::Impact(ImpactError::Singular { t, constraints }) => {
            assert!((t - t_hit).abs() < 1e-6, "{t}");
            assert!(constraints.contains(&"rail") && constraints.contains(&"rail_again"));
            assert!(!constraints.contains(&"floor"), "{constraints:?}");
        }
        other => panic!("{other:?}"),
    }
    let tr = &err.partial.trajectory;
    assert!(tr.len() > 10, "rows kept: {}", tr.len());
    assert!(*tr.t.last().unwrap() <= t_hit + 1e-9);
    // The work of the steps to the impact is reported with the run kept.
    let s = &err.partial.stats;
    assert!(s.steps > 0 && s.rhs_evals > s.steps, "{s:?}");
}

/// A coefficient of restitution outside [0, 1] is refused before the run starts (the
/// bouncing ball with e = 1.5 would otherwise fly 0.45 s to its first impact).
#[test]
fn a_restitution_outside_the_unit_interval_is_refused_at_the_start() {
    let mut model = bouncing_ball::Model::default();
    let e = model
        .info()
        .parameter_index("e")
        .expect("the model's restitution");
    model.set_parameter(e, 1.5);
    let err = Simulation::new(&model).run(1.0).expect_err("e = 1.5");
    assert!(
        matches!(
            err.kind,
            SimErrorKind::Impact(ImpactError::Restitution { contact: "floor", value }) if value == 1.5
        ),
        "{err}"
    );
    assert!(err.partial.trajectory.is_empty());
    assert_eq!(err.partial.stats.steps, 0);
}

/// RK4 at a fixed step locates the impacts on its dense output as well; the rest comes
/// when the remaining flights fit in a sample of a step (here within h of t∞).
#[test]
fn bouncing_ball_with_rk4() {
    let model = bouncing_ball::Model::default();
    let (h, e, g) = (1.0_f64, 0.5_f64, 9.81_f64);
    let tt = (2.0 * h / g).sqrt();
    let v0 = (2.0 * g * h).sqrt();
    let step = 1e-3;
    for f in formulations() {
        let r = run(&model, f, Method::Rk4 { h: step }, 2.0);
        let mut t_n = tt;
        for (n, imp) in r.impacts.iter().take(5).enumerate() {
            let k = i32::try_from(n).unwrap();
            assert!((imp.t - t_n).abs() < 1e-8, "{f:?}: impact {n} at {}", imp.t);
            t_n += 2.0 * e.powi(k + 1) * v0 / g;
        }
        let rest = r.contact_events[0];
        assert_eq!(rest.kind, ContactEventKind::Rest);
        assert!(
            (rest.t - tt * (1.0 + e) / (1.0 - e)).abs() < step,
            "{f:?}: {}",
            rest.t
        );
    }
}

/// The sleigh starts at V16's impact instant: inside a run, with every integrator and
/// formulation, the first row is after the jump (q̇⁺ of V16, G q̇⁺ = 0), and each impact
/// restarts the integrator (the Adams method from order 1).
#[test]
fn sleigh_wall_impact_inside_a_run() {
    let model = pfaff_models::sleigh_wall::Model::default();
    for f in formulations() {
        for m in methods() {
            let r = run(&model, f, m, 1.0);
            let imp = &r.impacts[0];
            assert_eq!(imp.t, 0.0);
            assert!((imp.impulses[0] - 1.370_464_752_9).abs() < 1e-9);
            assert!((imp.constraint_impulses[0] + 0.566_061_528_4).abs() < 1e-9);
            let qd0 = r.trajectory.qd(0);
            for (a, b) in qd0
                .iter()
                .zip([-0.035_722_354_8, 0.875_015_642_4, 2.585_489_841_4])
            {
                assert!((a - b).abs() < 1e-9, "{f:?} {m:?}: {qd0:?}");
            }
            if f != Formulation::Unconstrained {
                // (M q̈ = Q alone does not enforce the blade.)
                assert!(r.monitors.max_nonholonomic_violation < 1e-8, "{f:?} {m:?}");
            }
            assert!(r.stats.restarts as usize >= r.impacts.len() - 1);
        }
    }
}

/// A mass on a spring (ω = 2) released at x = 1 against a wall at x = −1/2, e = 1: its
/// flights are arcs of cosines, which no integrator follows exactly, so the impact
/// times carry the integration error. Closed form: x = cos 2t reaches the wall at
/// t₁ = π/3; the elastic impact turns the phase 2π/3 into 4π/3, and the next arc to
/// the wall lasts 2π/3, so t₂ = π.
#[pfaff::mechanism]
pub mod spring_wall {
    const k: f64 = 4.0;
    const e: f64 = 1.0;
    static x: Coordinate = Coordinate { q0: 1.0 };
    fn kinetic_energy() -> f64 {
        0.5 * x.dot().powi(2)
    }
    fn potential_energy() -> f64 {
        0.5 * k * x.powi(2)
    }
    /// The wall at x = −1/2.
    #[contact(e)]
    fn wall() -> f64 {
        x + 0.5
    }
}

/// The work-precision sweep measures the impact times against their closed form
/// (`Reference::impacts`), and that error falls with the tolerance: below `10 · rtol`
/// (the flight before an impact is about 1 s) for every formulation and adaptive
/// method, and by at least a factor 1e3 from rtol 1e-4 to 1e-10. Measured: DOPRI5
/// 1.4e-5, 9.0e-8, 1.8e-9, 1.1e-11 at rtol 1e-4, 1e-6, 1e-8, 1e-10; RADAU5 1.5e-6,
/// 1.7e-8, 1.7e-10, 1.8e-12 with its closings moved to its steps (`contacts::refine`);
/// located on its dense output alone (the collocation polynomial, of the stage order
/// 3) they are 1.4e-5, 1.8e-7, 1.4e-9, 9.1e-11.
#[test]
fn impact_time_error_falls_with_the_tolerance() {
    use pfaff::sim::{work_precision, Reference, Sweep};
    use std::f64::consts::PI;
    let model = spring_wall::Model::default();
    let t_end = 3.5;
    let reference = Reference {
        coordinates: vec![],
        velocities: vec![],
        impacts: vec![("wall".into(), PI / 3.0), ("wall".into(), PI)],
    };
    let sweep = Sweep {
        rtols: vec![1e-4, 1e-6, 1e-8, 1e-10],
        methods: vec![
            Method::Dopri5,
            Method::Dop853,
            Method::Adams,
            Method::Radau5,
        ],
        ..Sweep::standard(t_end)
    };
    let rows = work_precision(&model, &sweep, &reference);
    println!("{}", pfaff::sim::format_table(&rows));
    for r in &rows {
        let err = r.impact_error.expect("the reference has impacts");
        assert!(
            err <= 10.0 * r.rtol,
            "{} {}: impact time error {err:e} at rtol {:e}",
            r.formulation.name(),
            r.method.name(),
            r.rtol
        );
    }
    for f in &sweep.formulations {
        for m in &sweep.methods {
            let at = |rtol: f64| {
                rows.iter()
                    .find(|r| r.formulation == *f && r.method.name() == m.name() && r.rtol == rtol)
                    .and_then(|r| r.impact_error)
                    .expect("a row")
            };
            let (loose, tight) = (at(1e-4), at(1e-10));
            assert!(
                tight <= 1e-13 || tight * 1e3 <= loose,
                "{} {}: {loose:e} at 1e-4, {tight:e} at 1e-10",
                f.name(),
                m.name()
            );
        }
    }
    // A missed impact is an infinite error.
    let run = Simulation::new(&model).run(0.5).expect("runs");
    assert_eq!(reference.impact_time_error(&run), Some(f64::INFINITY));
}

/// A fixed-step RK4 run of the bouncing ball (h = 1, e = 0.5, g = 9.81; h_step = 2 ms)
/// merges the last, shortest flights of the accumulation into the rest: it strikes 12
/// times, not the 20 of the closed form (t_n = T(1 + 2 Σ_{k<n} e^k), T = √(2h/g), the
/// list that `pfaff work-precision bouncing_ball` uses). The impacts it did not strike
/// after coming to rest are compared with its rest time, a finite error below the
/// distance from its rest to the accumulation time t∞ = T(1 + e)/(1 − e), instead of
/// an infinite one.
#[test]
fn impacts_merged_into_the_rest_count_from_the_rest_time() {
    use pfaff::sim::Reference;
    let model = bouncing_ball::Model::default();
    let (e, g, h) = (0.5_f64, 9.81_f64, 1.0_f64);
    let t1 = (2.0 * h / g).sqrt();
    let mut impacts = Vec::new();
    let (mut t, mut flight) = (t1, 2.0 * t1);
    for _ in 0..20 {
        impacts.push(("floor".to_owned(), t));
        flight *= e;
        t += flight;
    }
    let t_inf = t1 * (1.0 + e) / (1.0 - e);
    let reference = Reference {
        coordinates: vec![],
        velocities: vec![],
        impacts,
    };
    let run = Simulation::new(&model)
        .integrator(Method::Rk4 { h: 0.002 })
        .output_times(&[])
        .run(2.0)
        .expect("runs");
    let rest = run
        .contact_events
        .iter()
        .find(|c| matches!(c.kind, ContactEventKind::Rest))
        .expect("the ball comes to rest");
    assert!(run.impacts.len() < 20, "{}", run.impacts.len());
    let err = reference
        .impact_time_error(&run)
        .expect("impacts to compare");
    println!(
        "{} impacts, rest at {}, error {err:e}",
        run.impacts.len(),
        rest.t
    );
    assert!(
        err.is_finite() && err <= t_inf - rest.t + 1e-12,
        "{err} {}",
        rest.t
    );
    assert!(err > 0.0);
}
