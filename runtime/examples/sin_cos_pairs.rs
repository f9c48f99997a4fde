//! Seven angles' sines and cosines (those of `andrews`), as seven calls of
//! `pfaff::math::sin_cos` and as three calls of `sin_cos2` and one of `sin_cos`: time
//! per set and a check that both give the same sums. `cargo run --release -p pfaff
//! --example sin_cos_pairs`.

use pfaff::math::{sin_cos, sin_cos2};
use std::hint::black_box;
use std::time::Instant;

/// Angles of the size of `andrews`' (two cranks that turn through about 16 rad).
const ANGLES: [f64; 7] = [15.8, -15.7, 0.04, -0.53, 0.52, 0.53, 1.05];

fn singles(n: u32) -> f64 {
    let mut acc = 0.0;
    for k in 0..n {
        let d = black_box(f64::from(k) * 1e-9);
        for &a in &ANGLES {
            let (s, c) = sin_cos(a + d);
            acc += s * c;
        }
    }
    acc
}

fn pairs(n: u32) -> f64 {
    let mut acc = 0.0;
    for k in 0..n {
        let d = black_box(f64::from(k) * 1e-9);
        for p in 0..3 {
            let ((s0, c0), (s1, c1)) = sin_cos2(ANGLES[2 * p] + d, ANGLES[2 * p + 1] + d);
            acc += s0 * c0;
            acc += s1 * c1;
        }
        let (s, c) = sin_cos(ANGLES[6] + d);
        acc += s * c;
    }
    acc
}

fn main() {
    let n = 10_000_000;
    for pass in 1..=3 {
        let t = Instant::now();
        let a = singles(n);
        let t1 = t.elapsed().as_secs_f64() * 1e9 / f64::from(n);
        let t = Instant::now();
        let b = pairs(n);
        let t2 = t.elapsed().as_secs_f64() * 1e9 / f64::from(n);
        assert_eq!(
            a.to_bits(),
            b.to_bits(),
            "the pairs are bitwise the singles"
        );
        println!(
            "pass {pass}: 7 × sin_cos {t1:.1} ns, 3 × sin_cos2 + sin_cos {t2:.1} ns ({:.2})",
            t2 / t1
        );
    }
}
