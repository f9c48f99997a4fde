//! Cost of one evaluation of a deformable body as its number of modes grows: the
//! spin-up beam (benchmark-models.md: l = 10, EA = 2.8e7, EI = 1.4e4, ρA = 1.2) of 16
//! clamped elements on a free hub, its invariants read from a beam data slot
//! (`Beam { .., modes: n }`), for n = 4, 8, 16. Timed: the generated `mass_matrix` and
//! `forces` at a state with every coordinate and velocity non-zero.
//!
//! `cargo bench -p pfaff-tests --bench flex_modes`

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use pfaff::Mechanism;

macro_rules! hub_beam {
    ($name:ident, $modes:literal, [$($p:ident),*]) => {
        #[pfaff::mechanism]
        mod $name {
            const l: f64 = 10.0;
            const ea: f64 = 2.8e7;
            const ei: f64 = 1.4e4;
            const rho_a: f64 = 1.2;
            static rod_fe: Data = Beam {
                elements: 16,
                length: l,
                rho_a: rho_a,
                ea: ea,
                ei: ei,
                modes: $modes,
            };
            static theta: Coordinate = Coordinate {};
            $(static $p: Coordinate = Coordinate {};)*
            static rod: Body = Deformable {
                origin: [0.0, 0.0],
                angle: theta,
                elastic: [$($p),*],
                data: rod_fe,
            };
        }
    };
}

hub_beam!(modes4, 4, [p1, p2, p3, p4]);
hub_beam!(modes8, 8, [p1, p2, p3, p4, p5, p6, p7, p8]);
hub_beam!(
    modes16,
    16,
    [p1, p2, p3, p4, p5, p6, p7, p8, p9, p10, p11, p12, p13, p14, p15, p16]
);

fn evaluation(c: &mut Criterion) {
    let models: [(usize, Box<dyn Mechanism>); 3] = [
        (4, Box::new(modes4::Model::default())),
        (8, Box::new(modes8::Model::default())),
        (16, Box::new(modes16::Model::default())),
    ];
    for (n, model) in &models {
        let info = model.info();
        let nq = info.nq();
        let q: Vec<f64> = (0..nq).map(|i| 1e-3 * (i as f64 + 1.0).sin()).collect();
        let qd: Vec<f64> = (0..nq).map(|i| 0.1 * (i as f64 + 2.0).cos()).collect();
        let mut m = vec![0.0; info.mass_pattern.len()];
        let mut f = vec![0.0; nq];
        c.bench_function(&format!("flex_modes/{n}/mass_matrix+forces"), |b| {
            b.iter(|| {
                model.mass_matrix(0.0, black_box(&q), &mut m);
                model.forces(0.0, black_box(&q), black_box(&qd), &mut f);
                black_box((&m, &f));
            });
        });
    }
}

criterion_group!(benches, evaluation);
criterion_main!(benches);
