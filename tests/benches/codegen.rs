//! Generator benchmarks: the time to expand each built-in model (calling the codegen
//! directly), the operation counts of the emitted code against the naive expression
//! trees, the cost of one evaluation of M + forces + C_q + γ_h for `andrews`, and the
//! expansion of a long sum at two lengths (near-linear growth).
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

/// `Σ i·x^i` with `n` terms as a potential.
fn power_sum(n: i32) -> proc_macro2::TokenStream {
    let mut e = quote::quote!(x);
    for i in 2..=n {
        let c = proc_macro2::Literal::i32_unsuffixed(i);
        e = quote::quote!(#e + #c * x.powi(#c));
    }
    quote::quote!(
        mod m {
            static x: Coordinate = Coordinate {};
            fn kinetic_energy() -> f64 {
                0.5 * x.dot().powi(2)
            }
            fn potential_energy() -> f64 {
                #e
            }
        }
    )
}

/// A long sum expands in near-linear time: 1,500 and 6,000 terms side by side (the
/// ratio of the two times is about 4 when linear, 4.8 for n log n, 16 when quadratic;
/// the expansion was quadratic once, 5.1 s for 6,000 terms).
fn long_sum(c: &mut Criterion) {
    let mut group = c.benchmark_group("long_sum");
    group.sample_size(10);
    for n in [1500, 6000] {
        let src = power_sum(n);
        group.bench_function(format!("{n}_terms"), |b| {
            b.iter(|| {
                pfaff_codegen::expand(proc_macro2::TokenStream::new(), black_box(src.clone()))
            });
        });
    }
    group.finish();
}

criterion_group!(benches, expand, evaluate, long_sum);
criterion_main!(benches);
