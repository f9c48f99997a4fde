//! `spinup_beam` (Kane, Ryan & Banerjee 1987; benchmark-models.md): with geometric
//! stiffening the tip deflection stays bounded over [0, 20] s and oscillates about zero
//! after the spin-up; the linear floating-frame model without it diverges once the spin
//! rate passes the first bending frequency (the run ends with a typed error keeping the
//! trajectory, or far beyond the beam's length).

use pfaff::sim::{Formulation, Method, Simulation};
use pfaff::Mechanism;
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
    let (t, q, qd) = match Simulation::new(&model)
        .formulation(Formulation::Projection)
        .integrator(Method::Radau5)
        .tolerances(1e-6, 1e-8)
        .output_times(&times)
        .run(20.0)
    {
        Ok(run) => {
            let (t, q, qd) = run.final_state().unwrap();
            (t, q.to_vec(), qd.to_vec())
        }
        Err(e) => {
            let (t, q, qd) = e.partial.final_state().unwrap();
            println!("without stiffening the run ends at t = {t:.2}: {}", e.kind);
            (t, q.to_vec(), qd.to_vec())
        }
    };
    let w = tip(&model, t, &q, &qd);
    println!("without stiffening: tip deflection {w:e} m at t = {t:.2}");
    assert!(t > 15.0 && w.abs() > 10.0, "t = {t}, tip {w}");
}
