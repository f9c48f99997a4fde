//! The cost of one linearization of the Whipple bicycle about upright straight running
//! at 5 m/s: with the generated derivatives and with central differences, side by side.
//!
//! `cargo bench -p pfaff-tests --bench linearize`

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use pfaff::{linearize_with, LinearizeMethod, LinearizeParams, Mechanism, States};
use pfaff_models::bicycle;

fn bicycle_linearization(c: &mut Criterion) {
    let model = bicycle::Model::default();
    let info = model.info();
    let n = info.nq();
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    let idx = |name| info.coordinate_index(name).expect("coordinate");
    let v = 5.0;
    q[idx("z")] = -model.params.r_r;
    qd[idx("x")] = v;
    qd[idx("theta_r")] = -v / model.params.r_r;
    qd[idx("theta_f")] = -v / model.params.r_f;
    let states = States {
        ignorable: &["x", "y", "psi", "theta_r", "theta_f"],
        velocities: &["phi", "delta", "theta_r"],
    };
    let mut group = c.benchmark_group("bicycle_linearize");
    for method in [LinearizeMethod::Generated, LinearizeMethod::Differences] {
        let params = LinearizeParams {
            method,
            ..LinearizeParams::default()
        };
        group.bench_function(format!("{method}"), |b| {
            b.iter(|| {
                linearize_with(&model, 0.0, black_box(&q), black_box(&qd), states, &params)
                    .expect("linearizes")
            });
        });
    }
    group.finish();
}

criterion_group!(benches, bicycle_linearization);
criterion_main!(benches);
