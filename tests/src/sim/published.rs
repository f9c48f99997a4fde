//! `andrews` and `car_axis` against the published reference solutions of the Test Set
//! for IVP Solvers (F. Mazzia, C. Magherini et al., University of Bari, release 2.4,
//! 2008; problems "andrews" and "caraxis"), not against pfaff's own runs.
//!
//! - **andrews**, t = 0.03: the seven angles of the reference solution, computed by the
//!   test set's authors with PSIDE at rtol = atol = 1e-14 (Cray double precision); the
//!   same problem as Hairer & Wanner, Solving ODEs II, §VII.7.
//! - **car_axis**, t = 3: the four positions of the reference solution, computed with
//!   GAMD in quadruple precision.
//!
//! Each model is run with every formulation and the adaptive integrators at rtol = atol
//! from 1e-4 to 1e-10; the largest absolute error of the final positions must stay
//! within a bound proportional to the tolerance plus the floor, and fall with the
//! tolerance from rtol 1e-6 on (each decade's error at most that of the decade before,
//! or within the floor; at 1e-4 and 1e-5 a final error is one sample of an error that
//! oscillates along the run: car_axis with Baumgarte + DOP853 ends at 4.3e-8 at rtol
//! 1e-4 and 8.5e-8 at 1e-5). The
//! floors are the references' own: the andrews values differ from every converged run
//! we have (pfaff's at rtol 1e-13 with partitioning and with projection, and SciPy's
//! DOP853 at 1e-13 on a separately written right-hand side, benchmarks/peers) by
//! 1.4e-9 in β and Θ (about 15.8 rad, a relative 9e-11, the order of PSIDE's 1e-14
//! tolerance amplified by the problem), while the converged runs agree with each other
//! to about 1e-12; the car axis reference is met to round-off.

use pfaff::sim::{Formulation, Method, Simulation};
use pfaff::Mechanism;
use pfaff_models::{andrews, car_axis};

/// The test set's reference positions of `andrews` at t = 0.03, in the order
/// (β, Θ, γ, Φ, δ, Ω, ε) of `andrews::Model`.
#[allow(clippy::excessive_precision)] // the digits as published
const ANDREWS: [f64; 7] = [
    0.158_107_711_962_990_4e2,
    -0.157_563_710_598_429_8e2,
    0.408_222_401_307_310_1e-1,
    -0.534_730_116_322_694_8,
    0.524_409_965_880_530_4,
    0.534_730_116_322_694_8,
    0.104_808_074_104_226_3e1,
];

/// The test set's reference positions of `car_axis` at t = 3, (x_l, y_l, x_r, y_r).
#[allow(clippy::excessive_precision)] // the digits as published
const CAR_AXIS: [f64; 4] = [
    0.493_455_784_275_402_809_122e-1,
    0.496_989_460_230_171_153_861,
    0.104_174_252_488_542_151_681e1,
    0.373_911_027_265_361_256_927,
];

/// Largest absolute error of the final positions of `model` run to `t_end` against
/// `reference`, or the error's message.
fn final_error(
    model: &dyn Mechanism,
    form: Formulation,
    method: Method,
    rtol: f64,
    t_end: f64,
    reference: &[f64],
) -> Result<f64, String> {
    let run = Simulation::new(model)
        .formulation(form)
        .integrator(method)
        .tolerances(rtol, rtol)
        .output_times(&[])
        .run(t_end)
        .map_err(|e| e.to_string())?;
    let (t, q, _) = run.final_state().ok_or("no final state")?;
    assert!((t - t_end).abs() <= 1e-12 * t_end, "ended at t = {t}");
    Ok(q.iter()
        .zip(reference)
        .fold(0.0_f64, |a, (x, r)| a.max((x - r).abs())))
}

const FORMULATIONS: [Formulation; 3] = [
    Formulation::Partitioning,
    Formulation::Projection,
    Formulation::baumgarte(),
];
const METHODS: [Method; 4] = [
    Method::Adams,
    Method::Dop853,
    Method::Dopri5,
    Method::Radau5,
];

/// Sweeps every formulation × adaptive integrator over rtol = 1e-4 … 1e-10 and checks
/// (module docs) each error against `slope · rtol + floor` and the fall with the
/// tolerance. Prints the table.
fn sweep(
    name: &str,
    model: &dyn Mechanism,
    t_end: f64,
    reference: &[f64],
    slope: fn(f64) -> f64,
    floor: f64,
) {
    let mut failures = Vec::new();
    for form in FORMULATIONS {
        for method in METHODS {
            let mut previous = f64::INFINITY;
            let mut line = format!("{name} {:>12} {:>7}:", form.name(), method.name());
            for k in 4..=10 {
                let rtol = 10f64.powi(-k);
                match final_error(model, form, method, rtol, t_end, reference) {
                    Ok(e) => {
                        line += &format!(" {e:.1e}");
                        let bound = slope(rtol) * rtol + floor;
                        if e > bound {
                            failures.push(format!(
                                "{} {} rtol {rtol:.0e}: error {e:.2e} above {bound:.2e}",
                                form.name(),
                                method.name(),
                            ));
                        }
                        if k >= 6 && e > previous.max(floor) {
                            failures.push(format!(
                                "{} {} rtol {rtol:.0e}: error {e:.2e} above the looser decade's {previous:.2e}",
                                form.name(),
                                method.name()
                            ));
                        }
                        previous = e;
                    }
                    Err(msg) => {
                        line += " failed";
                        failures.push(format!(
                            "{} {} rtol {rtol:.0e}: {msg}",
                            form.name(),
                            method.name()
                        ));
                    }
                }
            }
            eprintln!("{line}");
        }
    }
    assert!(failures.is_empty(), "{name}:\n{}", failures.join("\n"));
}

/// A converged run (rtol 1e-13, both formulations that project) meets the published
/// values to the reference's floor, and the sweep's errors fall to it.
#[test]
fn andrews_meets_the_test_set_reference() {
    let model = andrews::Model::default();
    for form in [Formulation::Partitioning, Formulation::Projection] {
        let e = final_error(&model, form, Method::Dop853, 1e-13, 0.03, &ANDREWS).unwrap();
        eprintln!("andrews {} dop853 rtol 1e-13: {e:.2e}", form.name());
        assert!(e < 2e-9, "{}: {e:e}", form.name());
    }
    sweep("andrews", &model, 0.03, &ANDREWS, slope_andrews, 2e-9);
}

/// The car axis meets the published values to round-off at rtol 1e-13, and the sweep's
/// errors fall with the tolerance.
#[test]
fn car_axis_meets_the_test_set_reference() {
    let model = car_axis::Model::default();
    for form in [Formulation::Partitioning, Formulation::Projection] {
        let e = final_error(&model, form, Method::Dop853, 1e-13, 3.0, &CAR_AXIS).unwrap();
        eprintln!("car_axis {} dop853 rtol 1e-13: {e:.2e}", form.name());
        assert!(e < 1e-11, "{}: {e:e}", form.name());
    }
    sweep("car_axis", &model, 3.0, &CAR_AXIS, slope_car_axis, 1e-11);
}

/// The bound of `andrews`' error in units of rtol. Measured (atol = rtol, every
/// formulation × Adams, DOP853, DOPRI5, Radau5): at most 2.7 × rtol from rtol 1e-6 on;
/// at 1e-4 and 1e-5 up to 6.9 × and 30 × (partitioning + DOP853 at 1e-5: 3.0e-4). There
/// the explicit methods cross the fast phase near t = 0.0105 in a few steps and the
/// error they leave is amplified by t = 0.03 according to its direction
/// (`proportionality.rs`), so neither the bound nor the fall with the tolerance is as
/// tight as from 1e-6 on, where the fall is checked.
fn slope_andrews(rtol: f64) -> f64 {
    if rtol > 5e-6 {
        40.0
    } else {
        5.0
    }
}

/// The bound of `car_axis`' error in units of rtol. Measured: at most 0.93 × rtol
/// (DOPRI5 at rtol 1e-4, the wheels' twenty oscillations on their springs).
fn slope_car_axis(_: f64) -> f64 {
    2.0
}
