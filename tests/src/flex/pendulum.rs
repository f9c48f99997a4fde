//! `flexible_pendulum`: a bar of spatial beam elements (docs/theory.md E20, §beam-elements) on a ball
//! joint, Euler parameters, gravity. Checked against closed forms: the clamped-free and
//! pinned-free bending frequencies of the Euler–Bernoulli beam, energy conservation, the
//! rigid physical pendulum's period as the bar stiffens, and the generated forces against
//! differences of the potential energy.

use pfaff::sim::{Formulation, Method, Simulation};
use pfaff::{linearize, LinearizeParams};
use pfaff::{Mechanism, MechanismExt};
use pfaff_models::flexible_pendulum;

/// Roots of the Euler–Bernoulli beam's frequency equations: clamped-free
/// (cos β cosh β = −1) and pinned-free (tan β = tanh β), first elastic mode.
const BETA_CLAMPED: f64 = 1.875_104_068_711_961;
const BETA_PINNED: f64 = 3.926_602_312_047_919;

fn param(model: &flexible_pendulum::Model, name: &str) -> f64 {
    model.parameter(model.info().parameter_index(name).unwrap())
}

fn set(model: &mut flexible_pendulum::Model, name: &str, v: f64) {
    let k = model.info().parameter_index(name).unwrap();
    model.set_parameter(k, v);
}

/// The reduced stiffness in the slot is diag(ω²) of the clamped bar (the floating
/// frame's reference condition): its first frequency in each plane is
/// β₁²√(EI/ρA)/l² to the discretization error of 8 elements (and the section's rotary
/// inertia, about 2e-5 here).
#[test]
fn modes_are_the_clamped_bars() {
    let model = flexible_pendulum::Model::default();
    let (l, rho_a) = (param(&model, "l"), param(&model, "rho_a"));
    let closed = |ei: f64| BETA_CLAMPED.powi(2) * (ei / rho_a).sqrt() / (l * l);
    let data = model.data(0);
    // K_ff is the slot's last n² values of the invariants (d = 3, n = 4).
    let flat = pfaff::flex::Invariants::flat_len(3, 4);
    let k_ff = &data[flat - 16..flat];
    let w1 = k_ff[0].sqrt();
    let w2 = k_ff[5].sqrt();
    let (c1, c2) = (closed(param(&model, "ei_y")), closed(param(&model, "ei_z")));
    println!("clamped: ω1 = {w1} (closed form {c1}), ω2 = {w2} ({c2})");
    assert!((w1 / c1 - 1.0).abs() < 1e-4, "{w1} {c1}");
    assert!((w2 / c2 - 1.0).abs() < 1e-4, "{w2} {c2}");
}

/// Without gravity, hanging at rest, the free bar on its pivot vibrates at the
/// pinned-free frequencies β²√(EI/ρA)/l², β = 3.92660 (tan β = tanh β): the
/// linearization's frequencies in each plane. The bar's motion is spanned by the
/// frame's rotation and the four clamped modes, a Ritz basis of the pinned-free mode,
/// so the frequencies are approached from above (measured: 1.1e-3 and 1.0e-3).
#[test]
fn pinned_free_frequencies_from_the_linearization() {
    let mut model = flexible_pendulum::Model::default();
    set(&mut model, "g", 0.0);
    set(&mut model, "spin", 0.0);
    set(&mut model, "phi0", 0.0);
    let n = model.info().nq();
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q, &mut qd);
    let lin = linearize(&model, 0.0, &q, &qd, &[], &LinearizeParams::default()).unwrap();
    let mut w: Vec<f64> = lin
        .eigenvalues
        .iter()
        .map(|e| e.im)
        .filter(|&im| im > 1.0)
        .collect();
    w.sort_by(f64::total_cmp);
    let (l, rho_a) = (param(&model, "l"), param(&model, "rho_a"));
    let closed = |ei: f64| BETA_PINNED.powi(2) * (ei / rho_a).sqrt() / (l * l);
    let (c1, c2) = (closed(param(&model, "ei_y")), closed(param(&model, "ei_z")));
    println!("pinned-free: {w:?}, closed forms {c1}, {c2}");
    assert!(w.len() >= 2, "{w:?}");
    for (got, want) in [(w[0], c1), (w[1], c2)] {
        assert!(got >= want * (1.0 - 1e-9), "{got} below {want}");
        assert!(got / want - 1.0 < 2e-3, "{got} {want}");
    }
}

/// No damping: the energy of the swinging, turning, bending bar is conserved to the
/// integration's tolerance over three swings.
#[test]
fn energy_is_conserved() {
    let model = flexible_pendulum::Model::default();
    let times: Vec<f64> = (1..=500).map(|i| f64::from(i) * 0.01).collect();
    let run = Simulation::new(&model)
        .integrator(Method::Dop853)
        .tolerances(1e-10, 1e-12)
        .output_times(&times)
        .run(5.0)
        .expect("the pendulum runs");
    let tr = &run.trajectory;
    let e0 = model.energy(tr.t[0], tr.q(0), tr.qd(0));
    let last = tr.len() - 1;
    let e1 = model.energy(tr.t[last], tr.q(last), tr.qd(last));
    // The scale of the energy: the bar's weight times its length.
    let scale = param(&model, "rho_a") * param(&model, "l") * 9.81 * param(&model, "l");
    let mut tip = [0.0];
    model.outputs(tr.t[last], tr.q(last), tr.qd(last), &mut tip);
    println!(
        "energy {e0} -> {e1} J, drift {:e} of m g l; {} steps; final tip deflection {:e} m",
        (e1 - e0) / scale,
        run.stats.steps,
        tip[0]
    );
    assert!(((e1 - e0) / scale).abs() < 1e-8, "{e0} {e1}");
    // The bar did bend.
    let bent = (0..tr.len()).any(|i| {
        model.outputs(tr.t[i], tr.q(i), tr.qd(i), &mut tip);
        tip[0] > 1e-4
    });
    assert!(bent);
}

/// Period of a planar small swing (spin 0, φ0 = 0.05): the times between downward
/// crossings of the vertical by the bar's frame, averaged over the run.
fn swing_period(model: &flexible_pendulum::Model) -> f64 {
    let times: Vec<f64> = (1..=6000).map(|i| f64::from(i) * 1e-3).collect();
    let run = Simulation::new(model)
        .integrator(Method::Radau5)
        .formulation(Formulation::Partitioning)
        .tolerances(1e-10, 1e-12)
        .output_times(&times)
        .run(6.0)
        .expect("the pendulum runs");
    let tr = &run.trajectory;
    // The world x-component of the frame's x axis (the bar), A₁₁ = e0² + e1² − e2² − e3²:
    // the sine of the swing.
    let swing = |i: usize| {
        let q = tr.q(i);
        q[0] * q[0] + q[1] * q[1] - q[2] * q[2] - q[3] * q[3]
    };
    let mut crossings = Vec::new();
    for i in 1..tr.len() {
        let (a, b) = (swing(i - 1), swing(i));
        if a > 0.0 && b <= 0.0 {
            crossings.push(tr.t[i - 1] + (tr.t[i] - tr.t[i - 1]) * a / (a - b));
        }
    }
    assert!(crossings.len() >= 3, "{crossings:?}");
    (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64
}

/// As the bar stiffens (every stiffness × s), its swing approaches the rigid physical
/// pendulum's: T = 2π√(J/(m g l/2)) (1 + φ0²/16 + 11φ0⁴/3072), J = ρA l³/3 + ρI_y l
/// about the pivot (the section turns about the frame's y axis in this swing).
#[test]
fn stiff_limit_is_the_rigid_pendulum() {
    let mut model = flexible_pendulum::Model::default();
    set(&mut model, "spin", 0.0);
    let phi0 = 0.05;
    set(&mut model, "phi0", phi0);
    let (l, rho_a, g) = (
        param(&model, "l"),
        param(&model, "rho_a"),
        param(&model, "g"),
    );
    let j = rho_a * l.powi(3) / 3.0 + param(&model, "rho_iy") * l;
    let m = rho_a * l;
    let rigid = std::f64::consts::TAU
        * (j / (m * g * l / 2.0)).sqrt()
        * (1.0 + phi0 * phi0 / 16.0 + 11.0 * phi0.powi(4) / 3072.0);
    let base: Vec<f64> = ["ea", "ei_y", "ei_z", "gj"]
        .iter()
        .map(|p| param(&model, p))
        .collect();
    let mut errors = Vec::new();
    for s in [1.0, 100.0] {
        for (p, b) in ["ea", "ei_y", "ei_z", "gj"].iter().zip(&base) {
            set(&mut model, p, b * s);
        }
        let t = swing_period(&model);
        println!(
            "stiffness × {s}: period {t} s, rigid {rigid} s, relative {:e}",
            t / rigid - 1.0
        );
        errors.push((t / rigid - 1.0).abs());
    }
    assert!(errors[1] < 2e-5, "{errors:?}");
    assert!(errors[1] < errors[0], "{errors:?}");
}

/// The generated forces are −∂V/∂q of the potential energy (gravity on the elastic
/// bar's first moment and ½ q_fᵀK_ff q_f) at rest, where Q_v vanishes: central
/// differences at random states.
#[test]
fn forces_are_the_potential_energys_gradient() {
    let model = flexible_pendulum::Model::default();
    let n = model.info().nq();
    let mut rng = super::Rng(5);
    for _ in 0..5 {
        let mut q: Vec<f64> = (0..n).map(|_| rng.next()).collect();
        let norm = q[..4].iter().map(|x| x * x).sum::<f64>().sqrt();
        q[..4].iter_mut().for_each(|x| *x /= norm);
        q[4..].iter_mut().for_each(|x| *x *= 1e-2);
        let mut f = vec![0.0; n];
        model.forces(0.0, &q, &vec![0.0; n], &mut f);
        for i in 0..n {
            let h = 1e-6;
            let (mut a, mut b) = (q.clone(), q.clone());
            a[i] += h;
            b[i] -= h;
            let d = (model.potential_energy(0.0, &a) - model.potential_energy(0.0, &b)) / (2.0 * h);
            let scale = f.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
            assert!(
                (f[i] + d).abs() < 1e-7 * scale,
                "Q[{i}] = {} vs −∂V = {}",
                f[i],
                -d
            );
        }
    }
}
