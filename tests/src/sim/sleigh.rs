//! docs/theory.md V11: the Chaplygin sleigh (`sleigh` model) against its closed form at
//! t = 1, 2, 5, with every formulation; tolerance: solver tolerance × 100 (docs/theory.md
//! §verification), plus the 5e-13 rounding of the tabulated values.

use pfaff::sim::{Formulation, Method, Simulation};
use pfaff_models::sleigh;

use super::exact::SLEIGH_V11;

#[test]
fn v11_closed_form_with_every_formulation() {
    let model = sleigh::Model::default();
    let rtol = 1e-10;
    for form in Formulation::ALL {
        for method in [Method::Dopri5, Method::Dop853, Method::Adams] {
            let run = Simulation::new(&model)
                .formulation(form)
                .integrator(method)
                .tolerances(rtol, rtol)
                .output_times(&[1.0, 2.0, 5.0])
                .run(5.0)
                .unwrap();
            let tr = &run.trajectory;
            assert_eq!(tr.t, [0.0, 1.0, 2.0, 5.0]);
            let mut worst = 0.0_f64;
            for (i, &(t, v, w, phi)) in SLEIGH_V11.iter().enumerate() {
                let (q, qd) = (tr.q(i + 1), tr.qd(i + 1));
                assert_eq!(tr.t[i + 1], t);
                // Forward speed along the body axis, turning rate, heading.
                let speed = qd[0] * q[2].cos() + qd[1] * q[2].sin();
                for (got, want) in [(speed, v), (qd[2], w), (q[2], phi)] {
                    worst = worst.max((got - want).abs());
                }
            }
            let m = &run.monitors;
            eprintln!(
                "{:<12} {:<6} worst {worst:.1e} nh {:.1e} dE {:.1e} steps {} rhs {} repart {}",
                form.name(),
                method.name(),
                m.max_nonholonomic_violation,
                m.max_energy_drift.unwrap(),
                run.stats.steps,
                run.stats.rhs_evals,
                run.stats.repartitions
            );
            assert!(
                worst <= 100.0 * rtol + 5e-13,
                "{form:?} {method:?}: {worst:e}"
            );
            // E = ½ m v² + ½ J ω² = 1.02875 (docs/theory.md V11).
            assert!((m.energy_initial.unwrap() - 1.02875).abs() < 1e-12);
            assert!(m.max_energy_drift.unwrap() < 100.0 * rtol);
            match form {
                Formulation::Baumgarte { .. } => {
                    assert!(m.max_nonholonomic_violation < 100.0 * rtol);
                }
                _ => assert!(m.max_nonholonomic_violation < 1e-13),
            }
            // The sleigh has no holonomic constraint: nothing to violate.
            assert_eq!(m.max_position_violation, 0.0);
        }
    }
}
