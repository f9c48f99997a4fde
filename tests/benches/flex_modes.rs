//! Cost of a deformable body as its number of modes grows: the spin-up beam
//! (docs/models.md: l = 10, EA = 2.8e7, EI = 1.4e4, ρA = 1.2) of 32 clamped
//! elements on a free hub, its invariants read from a beam data slot
//! (`Beam { .., modes: n }`), for n = 4, 16 and 64 (issue 12). Timed:
//! the generated `mass_matrix` and `forces` at a state with every coordinate and
//! velocity non-zero, and a step of a simulation (100 fixed RK4 steps of 1e-5 s with
//! coordinate partitioning, four index-1 right-hand sides each: M, Q, the solve).
//!
//! The mode count is a literal of the source: it fixes the generated code. The
//! contractions of the slot's blocks with `q_f` and `q̇_f` are loops from 8 modes on
//! (`macros/codegen/src/sched/runs.rs`), so the 64-mode body compiles (before, rustc failed
//! with SIGSEGV after 12 minutes on this file; docs/decisions/0015-run-time-data-slots.md).
//!
//! `cargo bench -p pfaff-tests --bench flex_modes`

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use pfaff::sim::{Method, Simulation};
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
                elements: 32,
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
hub_beam!(
    modes16,
    16,
    [p1, p2, p3, p4, p5, p6, p7, p8, p9, p10, p11, p12, p13, p14, p15, p16]
);
hub_beam!(
    modes64,
    64,
    [
        p1, p2, p3, p4, p5, p6, p7, p8, p9, p10, p11, p12, p13, p14, p15, p16, p17, p18, p19, p20,
        p21, p22, p23, p24, p25, p26, p27, p28, p29, p30, p31, p32, p33, p34, p35, p36, p37, p38,
        p39, p40, p41, p42, p43, p44, p45, p46, p47, p48, p49, p50, p51, p52, p53, p54, p55, p56,
        p57, p58, p59, p60, p61, p62, p63, p64
    ]
);

fn evaluation(c: &mut Criterion) {
    let models: [(usize, Box<dyn Mechanism>); 3] = [
        (4, Box::new(modes4::Model::default())),
        (16, Box::new(modes16::Model::default())),
        (64, Box::new(modes64::Model::default())),
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
        c.bench_function(&format!("flex_modes/{n}/100_rk4_steps"), |b| {
            b.iter(|| {
                let run = Simulation::new(model.as_ref())
                    .integrator(Method::Rk4 { h: 1e-5 })
                    .output_times(&[])
                    .run(1e-3)
                    .expect("the hub beam runs");
                black_box(run.stats.steps)
            });
        });
    }
}

criterion_group!(benches, evaluation);
criterion_main!(benches);
