//! Unit scaling (issue 9): a model and the same model in other units give the same
//! dimensionless trajectory, under every formulation and integrator.
//!
//! A change of units multiplies masses by μ, lengths by L and times by τ; then
//! gravity becomes g L/τ², velocities of lengths L/τ, of angles 1/τ, Baumgarte's gains
//! 1/τ, a fixed step τ. The equations of motion in the new units are the old ones, so
//! every decision of the runtime (partition, pivots, Newton convergence, redundancy) is
//! expected to come out the same and the trajectories to agree to the tolerance. The
//! scale triples are the corners of the ranges (μ ∈ [1e-6, 1e6],
//! L ∈ [1e-3, 1e3], τ ∈ [1e-3, 1e3]) and triples drawn from a seeded generator.

use std::f64::consts::FRAC_PI_2;

use pfaff::sim::{Formulation, Method, Run, Simulation};

/// The kind of a coordinate: how it scales.
#[derive(Clone, Copy, PartialEq)]
enum Unit {
    Length,
    Angle,
}

/// A model with its parameters by unit and a state clear of singular configurations.
struct Case {
    name: &'static str,
    /// (parameter, mass exponent, length exponent, time exponent).
    parameters: &'static [(&'static str, i32, i32, i32)],
    coordinates: &'static [Unit],
    q0: Vec<f64>,
    qd0: Vec<f64>,
    t_end: f64,
    /// A configuration of static equilibrium (hanging at rest), where the eigenvalues
    /// of the linearization do not depend on the coordinates chosen.
    equilibrium: Vec<f64>,
}

fn cases() -> Vec<Case> {
    let (l, th) = (0.5, -FRAC_PI_2 + 0.6);
    vec![
        Case {
            name: "pendulum",
            parameters: &[("m", 1, 0, 0), ("l", 0, 1, 0), ("g", 0, 1, -2)],
            coordinates: &[Unit::Length, Unit::Length],
            q0: vec![1.0, 0.0],
            qd0: vec![0.0, 0.0],
            t_end: 1.5,
            equilibrium: vec![0.0, -1.0],
        },
        // The parallelogram hanging and swinging clear of its flat configurations
        // (as in `redundant.rs`): angles and lengths, and a redundant constraint.
        Case {
            name: "parallelogram",
            parameters: &[
                ("l", 0, 1, 0),
                ("d", 0, 1, 0),
                ("mk", 1, 0, 0),
                ("mc", 1, 0, 0),
                ("g", 0, 1, -2),
            ],
            coordinates: &[
                Unit::Angle,
                Unit::Angle,
                Unit::Angle,
                Unit::Length,
                Unit::Length,
                Unit::Angle,
            ],
            q0: vec![th, th, th, l * th.cos(), l * th.sin(), 0.0],
            qd0: vec![0.5, 0.5, 0.5, -0.5 * l * th.sin(), 0.5 * l * th.cos(), 0.0],
            t_end: 1.0,
            equilibrium: vec![-FRAC_PI_2, -FRAC_PI_2, -FRAC_PI_2, 0.0, -l, 0.0],
        },
    ]
}

/// A change of units.
#[derive(Clone, Copy, Debug)]
struct Scale {
    mass: f64,
    length: f64,
    time: f64,
}

impl Scale {
    fn of(&self, unit: Unit) -> f64 {
        match unit {
            Unit::Length => self.length,
            Unit::Angle => 1.0,
        }
    }
}

/// The corners of the ranges and a few seeded draws (log-uniform).
fn scales() -> Vec<Scale> {
    let mut out = Vec::new();
    for (mass, length, time) in [(1e-6, 1e-3, 1e3), (1e6, 1e3, 1e-3), (1e6, 1e-3, 1.0)] {
        out.push(Scale { mass, length, time });
    }
    let mut rng = crate::accuracy::util::Rng::new(0x9E37_79B9_7F4A_7C15);
    let mut uniform = move || rng.uniform();
    for _ in 0..2 {
        out.push(Scale {
            mass: 10f64.powf(-6.0 + 12.0 * uniform()),
            length: 10f64.powf(-3.0 + 6.0 * uniform()),
            time: 10f64.powf(-3.0 + 6.0 * uniform()),
        });
    }
    out
}

const RTOL: f64 = 1e-9;

/// The model of `case` with its parameters and initial state in the units `s`.
fn scaled(case: &Case, s: Scale) -> (Box<dyn pfaff::Mechanism>, Vec<f64>, Vec<f64>) {
    let entry = pfaff_models::find(case.name).unwrap();
    let mut model = (entry.make)();
    let info = model.info();
    for &(name, em, el, et) in case.parameters {
        let i = info.parameter_index(name).unwrap();
        let v = model.parameter(i) * s.mass.powi(em) * s.length.powi(el) * s.time.powi(et);
        model.set_parameter(i, v);
    }
    let q: Vec<f64> = (case.q0.iter().zip(case.coordinates))
        .map(|(v, &u)| v * s.of(u))
        .collect();
    let qd: Vec<f64> = (case.qd0.iter().zip(case.coordinates))
        .map(|(v, &u)| v * s.of(u) / s.time)
        .collect();
    (model, q, qd)
}

/// Runs `case` in the units `s` and returns the run.
fn run(case: &Case, s: Scale, form: Formulation, method: Method) -> Result<Run, String> {
    let (model, q, qd) = scaled(case, s);
    let form = match form {
        Formulation::Baumgarte { alpha, beta } => Formulation::Baumgarte {
            alpha: alpha / s.time,
            beta: beta / s.time,
        },
        f => f,
    };
    let method = match method {
        Method::Rk4 { h } => Method::Rk4 { h: h * s.time },
        m => m,
    };
    // A pure relative tolerance in effect: atol far below rtol·|y| in every unit.
    let smallest_unit = [1.0, s.length, s.length / s.time, 1.0 / s.time]
        .into_iter()
        .fold(f64::INFINITY, f64::min);
    let atol = RTOL * 1e-6 * smallest_unit;
    let run = Simulation::new(model.as_ref())
        .formulation(form)
        .integrator(method)
        .tolerances(RTOL, atol)
        .initial_state(&q, &qd)
        .output_every(case.t_end * s.time / 10.0)
        .run(case.t_end * s.time);
    run.map_err(|e| e.to_string())
}

#[test]
fn dimensionless_trajectories_do_not_depend_on_units() {
    let unit = Scale {
        mass: 1.0,
        length: 1.0,
        time: 1.0,
    };
    let forms = Formulation::ALL;
    let methods = [
        Method::Rk4 { h: 1e-3 },
        Method::Dopri5,
        Method::Dop853,
        Method::Adams,
    ];
    let mut worst = 0.0_f64;
    for case in cases() {
        for form in forms {
            for method in methods {
                let reference = run(&case, unit, form, method)
                    .unwrap_or_else(|e| panic!("{} {:?} {:?}: {e}", case.name, form, method));
                let tr0 = &reference.trajectory;
                for s in scales() {
                    let label = format!("{} {} {} {s:?}", case.name, form.name(), method.name());
                    let r = run(&case, s, form, method).unwrap_or_else(|e| panic!("{label}: {e}"));
                    let tr = &r.trajectory;
                    assert_eq!(tr.len(), tr0.len(), "{label}");
                    for k in 0..tr.len() {
                        assert!(
                            (tr.t[k] / s.time - tr0.t[k]).abs() <= 1e-12 * case.t_end,
                            "{label}"
                        );
                        for (j, &u) in case.coordinates.iter().enumerate() {
                            let q = tr.q(k)[j] / s.of(u);
                            let qd = tr.qd(k)[j] / s.of(u) * s.time;
                            let dq = (q - tr0.q(k)[j]).abs();
                            let dqd = (qd - tr0.qd(k)[j]).abs();
                            worst = worst.max(dq).max(dqd);
                            // The solutions agree to a few hundred times the tolerance:
                            // the step sequences differ by the rounding of the scaled
                            // numbers only, and the error control bounds the rest.
                            assert!(
                                dq < 1e-6 && dqd < 1e-6,
                                "{label}, t = {}, coordinate {j}: q {q} vs {}, q' {qd} vs {}",
                                tr0.t[k],
                                tr0.q(k)[j],
                                tr0.qd(k)[j]
                            );
                        }
                    }
                }
            }
        }
    }
    eprintln!("largest difference of the dimensionless states: {worst:.1e}");
}

/// The linearization about each case's equilibrium: eigenvalues scale as 1/τ (the
/// difference steps follow the units). Away from an equilibrium the eigenvalues of the
/// reduced system depend on which coordinates are independent, and that choice may
/// change with the units of mixed coordinates.
#[test]
fn linearizations_do_not_depend_on_units() {
    let unit = Scale {
        mass: 1.0,
        length: 1.0,
        time: 1.0,
    };
    for case in cases() {
        let at_rest = Case {
            q0: case.equilibrium.clone(),
            qd0: vec![0.0; case.equilibrium.len()],
            equilibrium: Vec::new(),
            ..case
        };
        let lin = |s: Scale| {
            let (model, q, qd) = scaled(&at_rest, s);
            pfaff::linearize(model.as_ref(), 0.0, &q, &qd, &[], &Default::default())
                .unwrap_or_else(|e| panic!("{} {s:?}: {e}", case.name))
        };
        let reference = lin(unit);
        let size = reference
            .eigenvalues
            .iter()
            .fold(0.0_f64, |m, e| m.max(e.re.hypot(e.im)));
        for s in scales() {
            let l = lin(s);
            assert_eq!(l.eigenvalues.len(), reference.eigenvalues.len());
            for (a, b) in l.eigenvalues.iter().zip(&reference.eigenvalues) {
                let (re, im) = (a.re * s.time, a.im * s.time);
                assert!(
                    (re - b.re).abs().max((im - b.im).abs()) <= 1e-6 * size,
                    "{} {s:?}: {re} {im} vs {} {}",
                    at_rest.name,
                    b.re,
                    b.im
                );
            }
        }
    }
}
