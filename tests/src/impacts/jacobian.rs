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

/// A test-only model with the body level's contacts: a point of `b1` on a tilted plane
/// that rises with time (a non-unit normal, an offset, a radius), and a point of `b1`
/// outside a disc about `b2`'s centre.
#[pfaff::mechanism]
pub mod surfaces {
    const e: f64 = 0.6;
    const rise: f64 = 0.1;
    static x1: Coordinate = Coordinate { q0: 0.1 };
    static y1: Coordinate = Coordinate { q0: 1.0 };
    static phi1: Coordinate = Coordinate { q0: 0.3 };
    static x2: Coordinate = Coordinate { q0: 1.0 };
    static y2: Coordinate = Coordinate { q0: 0.5 };
    static phi2: Coordinate = Coordinate {};
    static b1: Body = Body {
        origin: [x1, y1],
        angle: phi1,
        mass: 1.0,
        inertia: 0.1,
    };
    static b2: Body = Body {
        origin: [x2, y2],
        angle: phi2,
        mass: 2.0,
        inertia: 0.2,
    };
    /// `b1`'s point `(0.3, 0.1)`, a ball of radius 0.05, above the plane
    /// `(0.5, 2)·x/|(0.5, 2)| = rise·t`.
    static tilted: Contact = PointPlane {
        point: b1.point([0.3, 0.1]),
        normal: [0.5, 2.0],
        offset: rise * t,
        radius: 0.05,
        restitution: e,
    };
    /// `b1`'s point `(0.3, 0)` outside the disc of radius 0.2 about `b2`'s centre.
    static ball: Contact = PointSphere {
        point: b1.point([0.3, 0.0]),
        center: b2.origin(),
        radius: 0.2,
        restitution: e,
    };
}

/// The gaps of `PointPlane` and `PointSphere` are the signed distances, written out by
/// hand: `n̂·p − offset − radius` and `|p − c| − radius`.
#[test]
fn body_level_gaps_are_signed_distances() {
    let model = surfaces::Model::default();
    let info = model.info();
    assert_eq!(info.ncontacts(), 2);
    let mut rng = Rng::new(5);
    for _ in 0..20 {
        let q: Vec<f64> = (0..6).map(|_| rng.range(-1.0, 1.0)).collect();
        let t = rng.range(0.0, 2.0);
        let g = gaps(&model, t, &q);
        let (s, c) = q[2].sin_cos();
        let (px, py) = (q[0] + 0.3 * c - 0.1 * s, q[1] + 0.3 * s + 0.1 * c);
        let n = (0.25f64 + 4.0).sqrt();
        let tilted = (0.5 * px + 2.0 * py) / n - 0.1 * t - 0.05;
        let (bx, by) = (q[0] + 0.3 * c, q[1] + 0.3 * s);
        let ball = ((bx - q[3]).powi(2) + (by - q[4]).powi(2)).sqrt() - 0.2;
        assert!((g[0] - tilted).abs() < 1e-14, "{} vs {tilted}", g[0]);
        assert!((g[1] - ball).abs() < 1e-14, "{} vs {ball}", g[1]);
    }
}

#[test]
fn contact_jacobians_match_finite_differences() {
    let mut rng = Rng::new(11);
    let mut checked = 0;
    let extra = pfaff_models::Entry::new("moving_floor", "", || {
        Box::new(moving_floor::Model::default())
    });
    let surfaces =
        pfaff_models::Entry::new("surfaces", "", || Box::new(surfaces::Model::default()));
    for entry in pfaff_models::all().iter().chain([&extra, &surfaces]) {
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
