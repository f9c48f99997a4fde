//! `spinup_beam` (Kane, Ryan & Banerjee 1987; docs/models.md): with geometric
//! stiffening the tip deflection stays bounded over [0, 20] s and oscillates about zero
//! after the spin-up; the linear floating-frame model without it diverges once the spin
//! rate passes the first bending frequency (the run ends with a typed error keeping the
//! trajectory, or far beyond the beam's length).

use pfaff::sim::{Formulation, Method, Simulation};
use pfaff::{linearize, LinearizeParams, Mechanism};
use pfaff_models::spinup_beam;

fn tip(model: &dyn Mechanism, t: f64, q: &[f64], qd: &[f64]) -> f64 {
    let mut out = [0.0];
    model.outputs(t, q, qd, &mut out);
    out[0]
}

#[test]
fn stiffening_keeps_the_tip_bounded_and_its_absence_diverges() {
    let times: Vec<f64> = (1..=200).map(|i| f64::from(i) * 0.1).collect();
    let mut model = spinup_beam::Model::default();
    let k = model.info().parameter_index("stiffening").unwrap();
    let run = Simulation::new(&model)
        .formulation(Formulation::Projection)
        .integrator(Method::Radau5)
        .tolerances(1e-6, 1e-8)
        .output_times(&times)
        .run(20.0)
        .expect("the stiffened beam runs");
    let tr = &run.trajectory;
    let tips: Vec<(f64, f64)> = (0..tr.len())
        .map(|i| (tr.t[i], tip(&model, tr.t[i], tr.q(i), tr.qd(i))))
        .collect();
    let worst = tips.iter().fold(0.0_f64, |m, (_, w)| m.max(w.abs()));
    println!("with stiffening: largest |tip deflection| {worst:.4} m");
    assert!(worst < 1.0, "{worst}");
    // After the spin-up: oscillation about zero (mean small against the amplitude,
    // both signs taken).
    let after: Vec<f64> = tips
        .iter()
        .filter(|(t, _)| *t > 15.5)
        .map(|p| p.1)
        .collect();
    let mean = after.iter().sum::<f64>() / after.len() as f64;
    let amp = after.iter().fold(0.0_f64, |m, w| m.max(w.abs()));
    println!("after the spin-up: mean {mean:e} m, amplitude {amp:e} m");
    assert!(after.iter().any(|w| *w > 0.0) && after.iter().any(|w| *w < 0.0));
    assert!(mean.abs() < 0.3 * amp, "{mean} {amp}");

    model.set_parameter(k, 0.0);
    let (t, q, qd, stopped) = match Simulation::new(&model)
        .formulation(Formulation::Projection)
        .integrator(Method::Radau5)
        .tolerances(1e-6, 1e-8)
        .output_times(&times)
        .run(20.0)
    {
        Ok(run) => {
            let (t, q, qd) = run.final_state().unwrap();
            (t, q.to_vec(), qd.to_vec(), false)
        }
        Err(e) => {
            // The monitor of the coordinates' size stops the divergence (the tip beyond
            // 1e6 times the motion's scale at the start), with the run so far kept.
            assert!(
                matches!(
                    e.kind,
                    pfaff::sim::SimErrorKind::Diverged {
                        quantity: pfaff::sim::Monitored::Coordinates { .. },
                        ..
                    }
                ),
                "{}",
                e.kind
            );
            let (t, q, qd) = e.partial.final_state().unwrap();
            println!("without stiffening the run ends at t = {t:.2}: {}", e.kind);
            (t, q.to_vec(), qd.to_vec(), true)
        }
    };
    let w = tip(&model, t, &q, &qd);
    println!("without stiffening: tip deflection {w:e} m at t = {t:.2}");
    assert!((t > 15.0 || stopped) && w.abs() > 10.0, "t = {t}, tip {w}");
}

/// The spin-up beam of `spinup_beam` built from 16 beam elements (a `Beam` data slot)
/// instead of shape functions: clamped at the hub, reduced to the four lowest bending
/// modes and the first axial one (mode 8 in ascending order of frequency, 759 rad/s);
/// geometric stiffening from the elements' centrifugal geometric stiffness
/// (`stiffening` on a body that reads a beam slot: `−s θ̇² K_Ω q_f`).
#[pfaff::mechanism]
pub mod spinup_elements {
    const l: f64 = 10.0;
    const ea: f64 = 2.8e7;
    const ei: f64 = 1.4e4;
    const rho_a: f64 = 1.2;
    const ts: f64 = 15.0;
    const omega_s: f64 = 6.0;
    const stiffening: f64 = 1.0;

    static beam_fe: Data = Beam {
        elements: 16,
        length: l,
        rho_a,
        ea,
        ei,
        modes: [0, 1, 2, 3, 8],
        reference: Clamped,
    };
    static p1: Coordinate = Coordinate {};
    static p2: Coordinate = Coordinate {};
    static p3: Coordinate = Coordinate {};
    static p4: Coordinate = Coordinate {};
    static p5: Coordinate = Coordinate {};

    fn s() -> f64 {
        0.5 * (t + ts - (t - ts).abs())
    }
    fn hub() -> f64 {
        omega_s / ts
            * (0.5 * s() * s() + (ts / (2.0 * PI)).powi(2) * ((2.0 * PI * s() / ts).cos() - 1.0))
            + omega_s * (t - s())
    }

    static beam: Body = Deformable {
        origin: [0.0, 0.0],
        angle: hub(),
        elastic: [p1, p2, p3, p4, p5],
        data: beam_fe,
        stiffening,
    };

    /// The tip's displacement perpendicular to the rotating frame's x axis [m].
    #[output]
    fn tip_deflection() -> f64 {
        beam.node(16).y()
    }
}

fn tips(model: &dyn Mechanism, times: &[f64]) -> Vec<f64> {
    let run = Simulation::new(model)
        .formulation(Formulation::Partitioning)
        .integrator(Method::Radau5)
        .tolerances(1e-8, 1e-10)
        .output_times(times)
        .run(20.0)
        .expect("the stiffened beam runs");
    let tr = &run.trajectory;
    times
        .iter()
        .map(|&t| {
            let i = (0..tr.len())
                .find(|&i| (tr.t[i] - t).abs() < 1e-12)
                .expect("a row at each output time");
            tip(model, t, tr.q(i), tr.qd(i))
        })
        .collect()
}

/// The fifth kept mode is the first axial one: π/2 √(EA/ρA)/l = 758.8 rad/s (clamped-free
/// bar; 16 linear elements approach it from above).
#[test]
fn element_spinup_keeps_the_first_axial_mode() {
    let model = spinup_elements::Model::default();
    let flat = pfaff::flex::Invariants::flat_len(2, 5);
    let k_ff = &model.data(0)[flat - 25..flat];
    let w5 = k_ff[4 * 5 + 4].sqrt();
    let closed = std::f64::consts::FRAC_PI_2 * (2.8e7_f64 / 1.2).sqrt() / 10.0;
    println!("fifth mode {w5} rad/s, first axial (closed form) {closed}");
    assert!(w5 >= closed && w5 / closed - 1.0 < 2e-3, "{w5} {closed}");
}

/// The lowest in-plane frequency about the steady rotation (the linearization at
/// t = 20 s, after the spin-up) of the element-built beam (stiffened by `K_Ω`, about its
/// undeformed state) and of the shape functions' (stiffened by the nonlinear strain,
/// about the axial stretch at the end of a run, bending zero). At Ω = 1 rad/s both are
/// the rotating cantilever's ω² = ω₀² + (K − 1)Ω² with Southwell's coefficient
/// K = 1.1933 of the first mode (uniform beam, hub radius 0: the Rayleigh quotient
/// ∫½(1 − ξ²)φ'²/∫φ² of the clamped-free mode, evaluated here; first order in Ω²),
/// ω₀ = 3.7977 rad/s (docs/models.md); at Ω = 6 rad/s, where the first-order
/// formula no longer holds, they agree with each other. Without stiffening the
/// rotation softens the beam, ω² = ω₀² − Ω² < 0 at 6 rad/s: the divergence.
#[test]
fn rotating_frequency_is_southwells() {
    let (w0, k_s) = (3.7977_f64, 1.1933_f64);
    let lowest = |model: &dyn Mechanism, q: &[f64]| {
        let n = q.len();
        let lin = linearize(
            model,
            20.0,
            q,
            &vec![0.0; n],
            &[],
            &LinearizeParams::default(),
        )
        .unwrap();
        lin.eigenvalues
            .iter()
            .filter(|e| e.im > 1e-6)
            .map(|e| e.im)
            .fold(f64::INFINITY, f64::min)
    };
    let mut found = Vec::new();
    for omega in [1.0, 6.0] {
        let mut elements = spinup_elements::Model::default();
        let k = elements.info().parameter_index("omega_s").unwrap();
        elements.set_parameter(k, omega);
        let we = lowest(&elements, &[0.0; 5]);
        let mut shapes = spinup_beam::Model::default();
        let k = shapes.info().parameter_index("omega_s").unwrap();
        shapes.set_parameter(k, omega);
        let run = Simulation::new(&shapes)
            .integrator(Method::Radau5)
            .tolerances(1e-8, 1e-10)
            .output_times(&[])
            .run(20.0)
            .unwrap();
        let (_, q, _) = run.final_state().unwrap();
        let mut q = q.to_vec();
        q[..4].iter_mut().for_each(|w| *w = 0.0);
        let ws = lowest(&shapes, &q);
        let closed = (w0 * w0 + (k_s - 1.0) * omega * omega).sqrt();
        println!(
            "rotating at {omega} rad/s: elements {we}, shape functions {ws}, first-order Southwell {closed} rad/s"
        );
        found.push((we, ws, closed));
    }
    let (we, ws, closed) = found[0];
    assert!((we / closed - 1.0).abs() < 1e-3, "{we} {closed}");
    assert!((ws / closed - 1.0).abs() < 1e-3, "{ws} {closed}");
    let (we, ws, _) = found[1];
    assert!((we / ws - 1.0).abs() < 1e-3, "{we} {ws}");

    let mut off = spinup_elements::Model::default();
    let k = off.info().parameter_index("stiffening").unwrap();
    off.set_parameter(k, 0.0);
    let lin = linearize(
        &off,
        20.0,
        &[0.0; 5],
        &[0.0; 5],
        &[],
        &LinearizeParams::default(),
    )
    .unwrap();
    let unstable = lin.eigenvalues.iter().fold(0.0_f64, |m, e| m.max(e.re));
    let growth = (36.0 - w0 * w0).sqrt();
    println!("without stiffening: largest growth rate {unstable} (ω² = ω₀² − Ω²: {growth})");
    assert!(
        (unstable / growth - 1.0).abs() < 5e-3,
        "{unstable} {growth}"
    );
}

/// Element-built spin-up (centrifugal geometric stiffness) against the shape functions'
/// (nonlinear axial strain): both bounded, with tip deflections over [0, 20] s within
/// 12 % of the largest (measured: peaks 0.574 and 0.526 m, largest difference 0.049 m
/// during the spin-up, both oscillating about zero by a few mm after it). They differ at
/// the spin-up's large deflections, where the nonlinear strain also carries the tension
/// of the bent beam's foreshortening that the cubic axial ansatz does not take up,
/// which the linear geometric stiffness omits; about the steady rotation they agree to
/// 1e-3 (`rotating_frequency_is_southwells`). Without stiffening the element model
/// diverges like the shape-function one.
#[test]
fn element_spinup_agrees_with_the_shape_functions_and_diverges_without_stiffening() {
    let times: Vec<f64> = (1..=200).map(|i| f64::from(i) * 0.1).collect();
    let elements = spinup_elements::Model::default();
    let shapes = spinup_beam::Model::default();
    let a = tips(&elements, &times);
    let b = tips(&shapes, &times);
    let worst = b.iter().fold(0.0_f64, |m, w| m.max(w.abs()));
    let worst_a = a.iter().fold(0.0_f64, |m, w| m.max(w.abs()));
    println!("largest |tip|: elements {worst_a}, shapes {worst}");
    let diff = a
        .iter()
        .zip(&b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
    println!(
        "elements vs shape functions: largest |tip| {worst:.4} m, largest difference {diff:e} m ({:e} of it)",
        diff / worst
    );
    assert!(a.iter().all(|w| w.abs() < 1.0));
    assert!(diff < 0.12 * worst, "{diff} {worst}");

    let mut model = elements;
    let k = model.info().parameter_index("stiffening").unwrap();
    model.set_parameter(k, 0.0);
    let (t, q, qd, stopped) = match Simulation::new(&model)
        .formulation(Formulation::Partitioning)
        .integrator(Method::Radau5)
        .tolerances(1e-6, 1e-8)
        .output_times(&times)
        .run(20.0)
    {
        Ok(run) => {
            let (t, q, qd) = run.final_state().unwrap();
            (t, q.to_vec(), qd.to_vec(), false)
        }
        Err(e) => {
            // The monitor of the coordinates' size stops the divergence (the tip beyond
            // 1e6 times the motion's scale at the start), with the run so far kept.
            assert!(
                matches!(
                    e.kind,
                    pfaff::sim::SimErrorKind::Diverged {
                        quantity: pfaff::sim::Monitored::Coordinates { .. },
                        ..
                    }
                ),
                "{}",
                e.kind
            );
            let (t, q, qd) = e.partial.final_state().unwrap();
            println!(
                "elements without stiffening: the run ends at t = {t:.2}: {}",
                e.kind
            );
            (t, q.to_vec(), qd.to_vec(), true)
        }
    };
    let w = tip(&model, t, &q, &qd);
    println!("elements without stiffening: tip deflection {w:e} m at t = {t:.2}");
    assert!((t > 15.0 || stopped) && w.abs() > 10.0, "t = {t}, tip {w}");
}
