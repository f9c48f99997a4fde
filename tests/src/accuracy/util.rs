//! Seeded random numbers, finite differences and small dense helpers for the accuracy
//! tests.
//!
//! Every random state comes from [`Rng`] with a fixed seed, so a failure reproduces
//! exactly. The difference quotients are fourth-order central stencils with a fixed step;
//! their error estimates, which the tolerances of [`super::check`] are built on, are
//! stated next to each one.

/// SplitMix64 (Steele, Lea & Flood 2014): a tiny generator of good quality, seeded
/// explicitly; the tests never use an unseeded source.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform on `[0, 1)` with 53 random bits.
    #[allow(clippy::cast_precision_loss)]
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform on `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// `n` values uniform on `[lo, hi)`.
    pub fn vec(&mut self, n: usize, lo: f64, hi: f64) -> Vec<f64> {
        (0..n).map(|_| self.range(lo, hi)).collect()
    }
}

/// Step of the difference stencils. Every model's variables are O(1) in the sampled
/// states, so a fixed step serves all of them.
pub const H: f64 = 1e-3;

/// `f'(0)` by the five-point central stencil
/// $f' \approx [f(-2h) - 8f(-h) + 8f(h) - f(2h)]/(12h)$.
///
/// Truncation error $h^4 |f^{(5)}|/30 \approx 3\cdot10^{-14}|f^{(5)}|$; rounding error
/// about $\tfrac{18}{12}\,\varepsilon|f|/h \approx 3\cdot10^{-13}|f|$.
pub fn d1(f: impl Fn(f64) -> f64) -> f64 {
    (f(-2.0 * H) - 8.0 * f(-H) + 8.0 * f(H) - f(2.0 * H)) / (12.0 * H)
}

/// `f''(0)` by the five-point central stencil
/// $f'' \approx [-f(-2h) + 16f(-h) - 30f(0) + 16f(h) - f(2h)]/(12h^2)$.
///
/// Truncation error $h^4 |f^{(6)}|/90 \approx 10^{-14}|f^{(6)}|$; rounding error about
/// $\tfrac{64}{12}\,\varepsilon|f|/h^2 \approx 1.2\cdot10^{-9}|f|$.
pub fn d2(f: impl Fn(f64) -> f64) -> f64 {
    (-f(-2.0 * H) + 16.0 * f(-H) - 30.0 * f(0.0) + 16.0 * f(H) - f(2.0 * H)) / (12.0 * H * H)
}

/// `x + s e_i`.
pub fn shifted(x: &[f64], i: usize, s: f64) -> Vec<f64> {
    let mut y = x.to_vec();
    y[i] += s;
    y
}

/// `x + s v`.
pub fn along(x: &[f64], v: &[f64], s: f64) -> Vec<f64> {
    x.iter().zip(v).map(|(a, b)| a + s * b).collect()
}

/// The gradient of `f` at `x` by [`d1`] in each coordinate.
pub fn gradient(f: impl Fn(&[f64]) -> f64, x: &[f64]) -> Vec<f64> {
    (0..x.len()).map(|i| d1(|s| f(&shifted(x, i, s)))).collect()
}

/// Largest absolute value (0 for an empty slice).
pub fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// Largest absolute difference; NaN anywhere (an output the code under test did not
/// write) makes it NaN, which fails every comparison.
pub fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "length mismatch");
    a.iter().zip(b).fold(0.0, |m: f64, (x, y)| {
        let d = (x - y).abs();
        if d.is_nan() || m.is_nan() {
            f64::NAN
        } else {
            m.max(d)
        }
    })
}

/// Scatters pattern values into a dense row-major `rows × cols` matrix.
pub fn dense(pattern: &[(u32, u32)], values: &[f64], rows: usize, cols: usize) -> Vec<f64> {
    assert_eq!(
        pattern.len(),
        values.len(),
        "pattern and values differ in length"
    );
    let mut out = vec![0.0; rows * cols];
    for (&(r, c), &v) in pattern.iter().zip(values) {
        out[r as usize * cols + c as usize] = v;
    }
    out
}

/// Solves the dense `n × n` system `a x = b` (row-major) by Gaussian elimination with
/// partial pivoting; panics when it is singular.
pub fn solve(a: &[f64], b: &[f64]) -> Vec<f64> {
    let n = b.len();
    assert_eq!(a.len(), n * n);
    let mut a = a.to_vec();
    let mut x = b.to_vec();
    for k in 0..n {
        let p = (k..n)
            .max_by(|&i, &j| a[i * n + k].abs().total_cmp(&a[j * n + k].abs()))
            .expect("non-empty range");
        assert!(a[p * n + k] != 0.0, "singular matrix");
        if p != k {
            for j in 0..n {
                a.swap(k * n + j, p * n + j);
            }
            x.swap(k, p);
        }
        for i in k + 1..n {
            let f = a[i * n + k] / a[k * n + k];
            for j in k..n {
                a[i * n + j] -= f * a[k * n + j];
            }
            x[i] -= f * x[k];
        }
    }
    for k in (0..n).rev() {
        let s: f64 = (k + 1..n).map(|j| a[k * n + j] * x[j]).sum();
        x[k] = (x[k] - s) / a[k * n + k];
    }
    x
}

#[test]
fn rng_is_reproducible_and_uniform() {
    let mut a = Rng::new(7);
    let mut b = Rng::new(7);
    let xs: Vec<f64> = (0..10_000).map(|_| a.uniform()).collect();
    assert!(xs
        .iter()
        .all(|&x| (0.0..1.0).contains(&x) && x == b.uniform()));
    let mean = xs.iter().sum::<f64>() / 1e4;
    assert!((mean - 0.5).abs() < 0.01, "mean {mean}");
}

#[test]
fn stencils_reach_their_error_estimates() {
    // exp at 0: all derivatives are 1, so the errors are the estimates themselves.
    assert!((d1(f64::exp) - 1.0).abs() < 1e-12);
    assert!((d2(f64::exp) - 1.0).abs() < 1e-8);
    let x = solve(&[2.0, 1.0, 1.0, 3.0], &[3.0, 4.0]);
    assert!(max_diff(&x, &[1.0, 1.0]) < 1e-15);
}
