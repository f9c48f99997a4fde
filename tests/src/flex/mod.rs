//! Deformable bodies in the floating frame of reference (docs/theory.md §floating-frame): the property
//! tests V6 (planar) and V7 (spatial) against the kinetic energy integrated independently
//! here and against E13/E14, Simeon's slider crank with an elastic rod against the test
//! set's own equations (docs/models.md), and the rigid limit.

mod crank;
mod models;
mod nonholonomic;
mod pendulum;
mod shapes;
mod spinup;

/// Largest absolute difference of two slices.
fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
}

/// Largest absolute entry.
fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0_f64, |m, x| m.max(x.abs()))
}

/// A deterministic generator of numbers in [−1, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
    fn vec(&mut self, n: usize) -> Vec<f64> {
        (0..n).map(|_| self.next()).collect()
    }
}

/// `∫₀¹ f(ξ) dξ` by composite five-point Gauss–Legendre quadrature on 64 panels (exact
/// for polynomials of degree 9 on each panel; for the smooth shape functions here the
/// error is at round-off).
fn quad(f: &mut dyn FnMut(f64) -> f64) -> f64 {
    const X: [f64; 5] = [
        0.0,
        -0.538_469_310_105_683_1,
        0.538_469_310_105_683_1,
        -0.906_179_845_938_664,
        0.906_179_845_938_664,
    ];
    const W: [f64; 5] = [
        0.568_888_888_888_888_9,
        0.478_628_670_499_366_5,
        0.478_628_670_499_366_5,
        0.236_926_885_056_189_1,
        0.236_926_885_056_189_1,
    ];
    let panels = 64;
    let h = 1.0 / f64::from(panels);
    let mut sum = 0.0;
    for p in 0..panels {
        let c = (f64::from(p) + 0.5) * h;
        for k in 0..5 {
            sum += W[k] * f(c + 0.5 * h * X[k]) * 0.5 * h;
        }
    }
    sum
}
