//! A non-holonomic constraint at a material point of a deformable body: the knife edge
//! at the free end of `flexible_sleigh`'s elastic tail (its equations are checked
//! against an independent derivation in `accuracy::flexible_sleigh`). Here: the energy
//! of the undamped, scleronomic run; the blade's row along runs of every formulation;
//! the partition of coordinates and velocities (independent velocities fewer than
//! independent coordinates, and which elastic coordinates are among them); the rigid
//! limit; and the impact of `flexible_sleigh_wall` against the impulse–momentum
//! balance.

use pfaff::sim::{Formulation, Method, Run, Simulation};
use pfaff::{
    ImpactSolver, Mechanism, MechanismExt, Partition, PartitionParams, Preferences, Workspace,
};
use pfaff_models::{flexible_sleigh, flexible_sleigh_wall};

use super::max_diff;
use crate::accuracy::flexible_sleigh::reference;

/// The sleigh's own span: 2 s, about 22 periods of the tail's first mode.
const T_END: f64 = 2.0;

fn run(model: &dyn Mechanism, f: Formulation, m: Method, rtol: f64) -> Run {
    Simulation::new(model)
        .formulation(f)
        .integrator(m)
        .tolerances(rtol, 1e-2 * rtol)
        .output_every(0.005)
        .run(T_END)
        .unwrap_or_else(|e| panic!("{f:?} {m:?} rtol {rtol:e}: {e}"))
}

/// Largest |E(t) − E(0)| / E(0) over the outputs.
fn energy_drift(r: &Run) -> f64 {
    let e0 = r.trajectory.energy(0).expect("energy");
    (0..r.trajectory.len())
        .map(|i| (r.trajectory.energy(i).expect("energy") - e0).abs() / e0)
        .fold(0.0, f64::max)
}

/// Undamped and scleronomic, with a knife edge (which does no work): `T + V` is a first
/// integral. Its drift stays within the integrator's tolerance and falls with `rtol`;
/// meanwhile the blade's reaction bends the tail (the strain energy is not zero).
#[test]
fn energy_is_conserved_and_its_drift_falls_with_rtol() {
    let model = flexible_sleigh::Model::default();
    for f in [Formulation::Partitioning, Formulation::Projection] {
        let mut drifts = Vec::new();
        for rtol in [1e-6, 1e-8, 1e-10] {
            let r = run(&model, f, Method::Dop853, rtol);
            let d = energy_drift(&r);
            let strain = (0..r.trajectory.len())
                .map(|i| model.potential_energy(r.trajectory.t[i], r.trajectory.q(i)))
                .fold(0.0, f64::max);
            let tip = r
                .trajectory
                .coordinate("p1")
                .unwrap()
                .iter()
                .fold(0.0_f64, |m, p| m.max(p.abs()));
            println!(
                "flexible_sleigh {} DOP853 rtol {rtol:e}: energy drift {d:.2e}, max strain energy {strain:.3e} J, max |p1| {tip:.3e}, {} steps",
                f.name(),
                r.stats.steps
            );
            assert!(d < 10.0 * rtol, "{f:?} rtol {rtol:e}: drift {d:e}");
            assert!(strain > 1e-5, "the tail is bent: max V = {strain:e}");
            drifts.push(d);
        }
        assert!(
            drifts[1] < drifts[0] && drifts[2] < drifts[1],
            "{f:?}: {drifts:?}"
        );
    }
}

/// The blade's row `G q̇` along runs: at round-off with partitioning (the dependent
/// velocity is solved from it) and projection (the velocities are projected onto it);
/// Baumgarte's stabilized acceleration-level row keeps it at the integration error.
#[test]
fn blade_holds_along_runs_of_every_formulation() {
    let model = flexible_sleigh::Model::default();
    for f in Formulation::ALL {
        let r = run(&model, f, Method::Dopri5, 1e-8);
        let worst = (0..r.trajectory.len())
            .map(|i| {
                model
                    .residuals(r.trajectory.t[i], r.trajectory.q(i), r.trajectory.qd(i))
                    .nonholonomic
            })
            .fold(0.0, f64::max);
        println!(
            "flexible_sleigh {}: max |G q'| over the outputs {worst:.2e}, monitor {:.2e}",
            f.name(),
            r.monitors.max_nonholonomic_violation
        );
        let bound = if matches!(f, Formulation::Baumgarte { .. }) {
            1e-6
        } else {
            1e-13
        };
        assert!(worst < bound, "{f:?}: |G q'| = {worst:e}");
        assert!(r.monitors.max_nonholonomic_violation < bound, "{f:?}");
    }
}

/// The paper's partitioning: no holonomic constraint, so all 6 coordinates are
/// independent, but the blade makes one velocity dependent: 5 independent velocities.
/// Complete pivoting on `G` picks the elastic coordinate with the largest entry (the
/// tip's lateral displacement per unit modal coordinate, 6.3 against the sled's 1 and
/// 0.3), so one elastic coordinate has a dependent velocity and the other two are
/// among the independent velocities; asked to keep the elastic velocities independent,
/// it takes the sled's lateral `y`.
#[test]
fn partition_has_fewer_independent_velocities_than_coordinates() {
    let model = flexible_sleigh::Model::default();
    let info = model.info();
    let n = info.nq();
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q, &mut qd);
    let mut ws = Workspace::new(info).unwrap();
    let params = PartitionParams::default();
    let p = Partition::compute(&model, &mut ws, 0.0, &q, Preferences::default(), &params)
        .expect("a partition");
    assert!(p.dependent().is_empty());
    assert_eq!(p.dependent_velocity().len(), 1);
    assert_eq!(p.independent().len(), 5);
    // n − m_h independent coordinates, n − m_h − m_nh independent velocities.
    assert_eq!(n - p.dependent().len(), 6);
    assert_eq!(p.independent().len(), n - info.nh() - info.nnh());
    // The largest |G_j| of the independent derivation.
    let g = reference(&model.params).nonholonomic_matrix(0.0, &q);
    let big = (0..n)
        .max_by(|&a, &b| g[a].abs().total_cmp(&g[b].abs()))
        .unwrap();
    println!("flexible_sleigh G at q0 = {g:?}; partition {:?}", p.names());
    assert!(big >= 3, "an elastic entry is the largest: {g:?}");
    assert_eq!(p.dependent_velocity(), &[big]);
    let elastic = ["p1", "p2", "p3"];
    let [_, eta, gamma] = p.names();
    assert!(elastic.contains(&eta[0]));
    assert_eq!(gamma.iter().filter(|c| elastic.contains(c)).count(), 2);
    // Preferring the elastic velocities independent.
    let prefs = Preferences {
        coordinates: &[],
        velocities: &[3, 4, 5],
    };
    let p = Partition::compute(&model, &mut ws, 0.0, &q, prefs, &params).unwrap();
    assert_eq!(p.names()[1], vec!["y"]);
}

/// A rigid sled with a rigid tail of the same mass distribution and the blade at its
/// end across the tail's axis: the limit of `flexible_sleigh` as `ei` grows.
#[pfaff::mechanism]
pub mod rigid_tail_sleigh {
    const m: f64 = 2.0;
    const ic: f64 = 0.05;
    const c: f64 = 0.1;
    const l: f64 = 0.2;
    const rho_a: f64 = 0.5;

    static x: Coordinate = Coordinate { qd0: 1.0 };
    static y: Coordinate = Coordinate { qd0: 0.6 };
    static phi: Coordinate = Coordinate { qd0: 2.0 };

    static sled: Body = Body {
        origin: [x, y],
        angle: phi,
        mass: m,
        inertia: ic,
    };
    static tail: Body = Body {
        origin: [x - c * phi.cos(), y - c * phi.sin()],
        angle: phi + PI,
        mass: rho_a * l,
        com: [0.5 * l, 0.0],
        inertia: rho_a * l * l * l / 12.0,
    };
    static blade: Joint = KnifeEdge {
        a: tail,
        at_a: [l, 0.0],
        lateral: [0.0, 1.0],
    };
}

/// Stiffening the tail (`ei` × 10, 100, 1000 from the same undeformed start) brings the
/// sled's motion to the rigid sleigh's: the largest difference of `(x, y, φ)` over
/// [0, 1] falls monotonically, about as 1/stiffness (the quasi-static deflection under
/// the blade's reaction, and the vibration the start excites, both scale as 1/EI).
#[test]
fn stiff_tail_approaches_the_rigid_sleigh() {
    let rigid = rigid_tail_sleigh::Model::default();
    let t_end = 1.0;
    let times: Vec<f64> = (1..=100).map(|i| f64::from(i) * 0.01).collect();
    let r = Simulation::new(&rigid)
        .formulation(Formulation::Projection)
        .integrator(Method::Dop853)
        .tolerances(1e-12, 1e-14)
        .output_times(&times)
        .run(t_end)
        .unwrap();
    let mut diffs = Vec::new();
    for factor in [10.0, 100.0, 1000.0] {
        let mut model = flexible_sleigh::Model::default();
        let k = model.info().parameter_index("ei").unwrap();
        model.set_parameter(k, 0.32 * factor);
        let f = Simulation::new(&model)
            .formulation(Formulation::Projection)
            .integrator(Method::Radau5)
            .tolerances(1e-10, 1e-12)
            .output_times(&times)
            .run(t_end)
            .unwrap();
        assert_eq!(f.trajectory.len(), r.trajectory.len());
        let d = (0..f.trajectory.len())
            .map(|i| max_diff(&f.trajectory.q(i)[..3], r.trajectory.q(i)))
            .fold(0.0_f64, f64::max);
        println!("flexible_sleigh EI × {factor}: max |(x, y, phi) − rigid| = {d:.3e}");
        diffs.push(d);
    }
    assert!(
        diffs[1] < 0.3 * diffs[0] && diffs[2] < 0.3 * diffs[1],
        "{diffs:?}"
    );
}

/// `flexible_sleigh_wall` at its impact instant: the augmented (E41) and partitioned
/// (E42) forms agree to round-off; the impulse–momentum balance
/// `M Δq' + Gᵀ Λ = Dᵀ P̂` holds with the generated `M`, `G` and contact normal; the
/// momentum in every direction the blade admits (`G δq = 0`) changes by the contact
/// impulse alone; Newton's law and the blade hold after; energy is lost (none at
/// `e = 1`); and the elastic velocities jump although the impulse acts on the rigid
/// sled.
#[test]
fn wall_impact_balances_impulse_and_momentum() {
    let mut model = flexible_sleigh_wall::Model::default();
    let info = model.info();
    let n = info.nq();
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q, &mut qd);
    let mut gap = [f64::NAN];
    model.contact_gaps(0.0, &q, &mut gap);
    assert!(gap[0].abs() < 1e-15, "touching: {gap:?}");
    let mut solver = ImpactSolver::new(info).unwrap();
    let e_index = info.parameter_index("e").unwrap();
    for e in [0.8, 0.0, 1.0, 0.35] {
        model.set_parameter(e_index, e);
        let a = solver.solve(&model, 0.0, &q, &qd, &[0]).expect("E41");
        let p = solver
            .solve_partitioned(&model, 0.0, &q, &qd, &[0])
            .expect("E42");
        let scale = max_abs(&a.qd_after).max(1.0);
        assert!(max_diff(&a.qd_after, &p.qd_after) < 1e-12 * scale, "e {e}");
        assert!((a.impulses[0] - p.impulses[0]).abs() < 1e-12 * a.impulses[0]);
        assert!(max_diff(&a.constraint_impulses, &p.constraint_impulses) < 1e-12);
        assert!(max_diff(&a.lambda_after, &p.lambda_after) < 1e-11);

        // M Δq' + Gᵀ Λ − Dᵀ P̂ = 0.
        let mut m = vec![0.0; n * n];
        model.mass_matrix_dense_inplace(0.0, &q, &mut m);
        let mut gs = vec![0.0; info.nonholonomic_pattern.len()];
        model.nonholonomic_matrix(0.0, &q, &mut gs);
        let g = dense(info.nonholonomic_pattern, &gs, 1, n);
        let mut ds = vec![0.0; info.contact_pattern.len()];
        model.contact_jacobian(0.0, &q, &mut ds);
        let d = dense(info.contact_pattern, &ds, 1, n);
        let dq: Vec<f64> = a.qd_after.iter().zip(&qd).map(|(x, y)| x - y).collect();
        let (big_p, big_l) = (a.impulses[0], a.constraint_impulses[0]);
        let balance: Vec<f64> = (0..n)
            .map(|i| {
                (0..n).map(|j| m[i * n + j] * dq[j]).sum::<f64>() + g[i] * big_l - d[i] * big_p
            })
            .collect();
        println!(
            "flexible_sleigh_wall e = {e}: P = {big_p:.10}, Lambda_nh = {big_l:.10}, q'+ = {:?}, lambda_nh {:.10} -> {:.10}, T {:.10} -> {:.10}, balance {:.1e}",
            a.qd_after,
            a.lambda_before[0],
            a.lambda_after[0],
            a.kinetic_before,
            a.kinetic_after,
            max_abs(&balance)
        );
        assert!(max_abs(&balance) < 1e-12 * big_p.max(1.0), "{balance:?}");
        // Momentum in the admissible directions: δq with G δq = 0 (the coordinate
        // directions made admissible by the dependent one, y).
        for j in [0, 2, 3, 4, 5] {
            let mut dqa = vec![0.0; n];
            dqa[j] = 1.0;
            dqa[1] = -g[j] / g[1];
            let lhs: f64 = (0..n)
                .map(|i| dqa[i] * (0..n).map(|k| m[i * n + k] * dq[k]).sum::<f64>())
                .sum();
            let rhs: f64 = (0..n).map(|i| dqa[i] * d[i]).sum::<f64>() * big_p;
            assert!((lhs - rhs).abs() < 1e-12 * big_p.max(1.0), "direction {j}");
        }
        // Newton's law, the blade, the energy.
        let vn = a.normal_velocity_before[0];
        assert!(vn < 0.0 && big_p > 0.0);
        assert!((a.normal_velocity_after[0] + e * vn).abs() < 1e-12);
        let r = model.residuals(0.0, &q, &a.qd_after);
        assert!(r.nonholonomic < 1e-13, "G q'+ = {:e}", r.nonholonomic);
        let t = a.kinetic_before;
        assert!(a.energy_lost() >= -1e-13 * t);
        if e == 1.0 {
            assert!(a.energy_lost().abs() < 1e-12 * t);
        } else {
            let m_eff = big_p / ((1.0 + e) * -vn);
            let want = 0.5 * (1.0 - e * e) * m_eff * vn * vn;
            assert!((a.energy_lost() - want).abs() < 1e-12 * t);
        }
        // The elastic velocities jump, and so does the blade's finite reaction.
        assert!(max_abs(&dq[3..]) > 1e-3, "Δp' = {:?}", &dq[3..]);
        assert!(a.multiplier_jump()[0].abs() > 1e-3);
    }
}

/// The impact inside runs of every formulation: located at t = 0, the same jump as the
/// solve, and the blade held after it.
#[test]
fn wall_impact_inside_runs() {
    let model = flexible_sleigh_wall::Model::default();
    let info = model.info();
    let n = info.nq();
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q, &mut qd);
    let a = ImpactSolver::new(info)
        .unwrap()
        .solve(&model, 0.0, &q, &qd, &[0])
        .unwrap();
    for f in Formulation::ALL {
        let r = Simulation::new(&model)
            .formulation(f)
            .integrator(Method::Dopri5)
            .tolerances(1e-9, 1e-11)
            .output_every(0.01)
            .run(0.5)
            .unwrap_or_else(|e| panic!("{f:?}: {e}"));
        let imp = &r.impacts[0];
        assert_eq!(imp.t, 0.0);
        assert!((imp.impulses[0] - a.impulses[0]).abs() < 1e-12);
        assert!(max_diff(r.trajectory.qd(0), &a.qd_after) < 1e-12);
        let bound = if matches!(f, Formulation::Baumgarte { .. }) {
            1e-6
        } else {
            1e-12
        };
        assert!(
            r.monitors.max_nonholonomic_violation < bound,
            "{f:?}: {:e}",
            r.monitors.max_nonholonomic_violation
        );
    }
}

fn max_abs(a: &[f64]) -> f64 {
    super::max_abs(a)
}

/// A pattern-valued matrix as dense row-major.
fn dense(pattern: pfaff::Pattern, values: &[f64], rows: usize, cols: usize) -> Vec<f64> {
    crate::accuracy::util::dense(pattern, values, rows, cols)
}
