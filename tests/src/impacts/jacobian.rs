//! The generated contact derivatives of every built-in model with contacts against
//! finite differences of the generated gaps: $D = \partial\delta/\partial q$ by central
//! differences, $\delta_t$ by central differences in $t$, and
//! $\gamma_c = -\frac{d^2}{ds^2}\delta(q + s\dot q, t + s)$ by the second difference.

use pfaff::{scatter_row_major, Mechanism};

use crate::accuracy::util::Rng;

fn gaps(m: &dyn Mechanism, t: f64, q: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; m.info().ncontacts()];
    m.contact_gaps(t, q, &mut out);
    out
}

/// A test-only model whose gap depends on time and mixes coordinates: a ball above a
/// floor that moves up and down, with a bump in x.
#[pfaff::mechanism]
pub mod moving_floor {
    const amplitude: f64 = 0.1;
    const omega: f64 = 3.0;
    const e: f64 = 0.7;
    static x: Coordinate = Coordinate { q0: 0.2 };
    static y: Coordinate = Coordinate { q0: 1.0 };
    fn kinetic_energy() -> f64 {
        0.5 * (x.dot().powi(2) + y.dot().powi(2))
    }
    /// Height above the moving, bumpy floor.
    #[contact(e)]
    fn floor() -> f64 {
        y - amplitude * (omega * t).sin() - 0.2 * x.powi(2) * (t * x).cos()
    }
}

#[test]
fn contact_jacobians_match_finite_differences() {
    let mut rng = Rng::new(11);
    let mut checked = 0;
    let extra = pfaff_models::Entry {
        name: "moving_floor",
        summary: "",
        make: || Box::new(moving_floor::Model::default()),
    };
    for entry in pfaff_models::all().iter().chain([&extra]) {
        let model = (entry.make)();
        let info = model.info();
        let (n, nc) = (info.nq(), info.ncontacts());
        if nc == 0 {
            continue;
        }
        checked += 1;
        let (mut q0, mut qd0) = (vec![0.0; n], vec![0.0; n]);
        model.initial_state(&mut q0, &mut qd0);
        for _ in 0..8 {
            let q: Vec<f64> = q0.iter().map(|v| v + rng.range(-0.3, 0.3)).collect();
            let qd: Vec<f64> = (0..n).map(|_| rng.range(-1.0, 1.0)).collect();
            let t = rng.range(0.0, 3.0);
            let mut values = vec![0.0; info.contact_pattern.len()];
            model.contact_jacobian(t, &q, &mut values);
            let mut d = vec![0.0; nc * n];
            scatter_row_major(info.contact_pattern, &values, n, &mut d);
            let h = 1e-6;
            for j in 0..n {
                let (mut qp, mut qm) = (q.clone(), q.clone());
                qp[j] += h;
                qm[j] -= h;
                let (gp, gm) = (gaps(&*model, t, &qp), gaps(&*model, t, &qm));
                for c in 0..nc {
                    let fd = (gp[c] - gm[c]) / (2.0 * h);
                    assert!(
                        (fd - d[c * n + j]).abs() < 1e-7,
                        "{}: D[{c}, {j}] = {} against {fd}",
                        entry.name,
                        d[c * n + j]
                    );
                }
            }
            let mut rate = vec![0.0; nc];
            model.contact_rate(t, &q, &mut rate);
            let (gp, gm) = (gaps(&*model, t + h, &q), gaps(&*model, t - h, &q));
            for c in 0..nc {
                let fd = (gp[c] - gm[c]) / (2.0 * h);
                assert!((fd - rate[c]).abs() < 1e-7, "{}: rate {c}", entry.name);
            }
            let mut gamma = vec![0.0; nc];
            model.contact_gamma(t, &q, &qd, &mut gamma);
            let s = 1e-4;
            let along = |s: f64| {
                let qs: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a + s * b).collect();
                gaps(&*model, t + s, &qs)
            };
            let (gp, g0, gm) = (along(s), along(0.0), along(-s));
            for c in 0..nc {
                let fd = -(gp[c] - 2.0 * g0[c] + gm[c]) / (s * s);
                assert!(
                    (fd - gamma[c]).abs() < 1e-5 * (1.0 + gamma[c].abs()),
                    "{}: gamma {c} = {} against {fd}",
                    entry.name,
                    gamma[c]
                );
            }
        }
    }
    assert!(checked >= 8, "models with contacts: {checked}");
}
