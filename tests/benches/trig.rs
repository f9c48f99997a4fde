//! The sine and cosine generated code calls (`pfaff::math`) next to the standard
//! library's (glibc's `sin`, `cos`; `f64::sin_cos`, which LLVM turns into one `sincos`
//! call), in one run: 1024 arguments per iteration, uniform in `[−π, π]` (the range of
//! a joint angle) and in `(−10³, 10³)`, reported per call.
//!
//! - `…/independent`: the results summed, so calls overlap (throughput);
//! - `…/chained`: each argument depends on the previous result (latency).
//!
//! `cargo bench -p pfaff-tests --bench trig`

use std::f64::consts::PI;
use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};

/// `n` reproducible arguments uniform in `(−a, a)` (a linear congruential stream).
fn arguments(n: usize, a: f64) -> Vec<f64> {
    let mut s = 0x2545_F491_4F6C_DD1Du64;
    (0..n)
        .map(|_| {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let u = (s >> 11) as f64 / (1u64 << 53) as f64;
            a * (2.0 * u - 1.0)
        })
        .collect()
}

type Pair = fn(f64) -> (f64, f64);

fn trig(c: &mut Criterion) {
    let fns: [(&str, Pair); 6] = [
        ("std/sin", |x| (x.sin(), 0.0)),
        ("pfaff/sin", |x| (pfaff::math::sin(x), 0.0)),
        ("std/cos", |x| (x.cos(), 0.0)),
        ("pfaff/cos", |x| (pfaff::math::cos(x), 0.0)),
        ("std/sin_cos", |x| x.sin_cos()),
        ("pfaff/sin_cos", pfaff::math::sin_cos),
    ];
    for (range, a) in [("pi", PI), ("1e3", 1e3)] {
        let xs = arguments(1024, a);
        let mut group = c.benchmark_group(format!("trig/{range}"));
        group.throughput(Throughput::Elements(xs.len() as u64));
        for (name, f) in fns {
            group.bench_function(format!("{name}/independent"), |b| {
                b.iter(|| {
                    let mut acc = 0.0;
                    for &x in black_box(&xs) {
                        let (s, c) = f(x);
                        acc += s + c;
                    }
                    acc
                })
            });
            group.bench_function(format!("{name}/chained"), |b| {
                b.iter(|| {
                    // The next argument waits for this result; 0·r keeps its value.
                    let mut r = 0.0;
                    for &x in black_box(&xs) {
                        let (s, c) = f(x + 0.0 * r);
                        r = s + c;
                    }
                    r
                })
            });
        }
        group.finish();
    }
}

criterion_group!(benches, trig);
criterion_main!(benches);
