//! Generator benchmarks: the time to expand each built-in model (calling the codegen
//! directly), the operation counts of the emitted code against the naive expression
//! trees, and the cost of one evaluation of M + forces + C_q + γ_h for `andrews`.
//!
//! `cargo bench -p pfaff-tests --bench codegen`

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use pfaff::Mechanism;

fn op_count_table() {
    println!("\noperation counts (naive tree = derivatives without simplification or sharing)");
    println!(
        "{:<16} {:>14} {:>16} {:>10} {:>12} {:>8}",
        "model", "naive tree", "simplified tree", "emitted", "naive/emit", "rhs"
    );
    for (name, args, tokens) in pfaff_tests::sources::model_sources_with_args() {
        let c = pfaff_codegen::measure::op_counts(args, tokens).expect("model expands");
        #[allow(clippy::cast_precision_loss)]
        let (naive, ratio) = c.naive_tree.map_or(("-".to_owned(), "-".to_owned()), |n| {
            (
                n.to_string(),
                format!("{:.1}x", n as f64 / c.emitted.max(1) as f64),
            )
        });
        println!(
            "{name:<16} {naive:>14} {:>16} {:>10} {ratio:>12} {:>8}",
            c.simplified_tree, c.emitted, c.rhs
        );
    }
    println!();
}

fn expand(c: &mut Criterion) {
    op_count_table();
    let mut group = c.benchmark_group("expand");
    for (name, args, tokens) in pfaff_tests::sources::model_sources_with_args() {
        group.bench_function(&name, |b| {
            b.iter(|| pfaff_codegen::expand(args.clone(), black_box(tokens.clone())));
        });
    }
    group.finish();
}

fn evaluate(c: &mut Criterion) {
    let model = pfaff_models::andrews::Model::default();
    let info = model.info();
    let n = info.nq();
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q, &mut qd);
    // A moving state, so the velocity terms are exercised.
    for (i, v) in qd.iter_mut().enumerate() {
        #[allow(clippy::cast_precision_loss)]
        let k = i as f64;
        *v = 10.0 * (k + 1.0).sin();
    }
    let mut m = vec![0.0; info.mass_pattern.len()];
    let mut f = vec![0.0; n];
    let mut cq = vec![0.0; info.holonomic_pattern.len()];
    let mut gamma = vec![0.0; info.nh()];
    c.bench_function("andrews/M+forces+C_q+gamma_h", |b| {
        b.iter(|| {
            let (q, qd) = (black_box(&q), black_box(&qd));
            model.mass_matrix(0.0, q, &mut m);
            model.forces(0.0, q, qd, &mut f);
            model.holonomic_jacobian(0.0, q, &mut cq);
            model.holonomic_gamma(0.0, q, qd, &mut gamma);
            black_box((&m, &f, &cq, &gamma));
        });
    });
}

criterion_group!(benches, expand, evaluate);
criterion_main!(benches);
