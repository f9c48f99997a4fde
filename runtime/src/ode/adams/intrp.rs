//! A port of Shampine & Gordon's `INTRP`.
//!
//! Input: the state after an accepted step: $(x, y)$, the order `kold` of that step,
//! the differences $\phi$ and `psi`. Output: $y(x_{\text{out}})$ from the Adams
//! polynomial of that step.
//! Invariants: allocation-free (13-element stack arrays); exact at $x_{\text{out}} = x$.

// Index loops mirror the 1-based loops of ode.f so the port can be checked line by line.
#![allow(clippy::needless_range_loop)]

use super::Adams;

impl Adams {
    /// Writes the interpolant at `xout` into `out` (`kold >= 1`).
    pub(super) fn intrp(&self, xout: f64, out: &mut [f64]) {
        let n = self.y.len();
        let hi = xout - self.x;
        let ki = self.kold + 1;
        let kip1 = ki + 1;
        let mut g = [0.0f64; 14];
        let mut w = [0.0f64; 14];
        g[1] = 1.0;
        for (i, wi) in w.iter_mut().enumerate().take(ki + 1).skip(1) {
            *wi = 1.0 / i as f64;
        }
        let mut term = 0.0;
        for j in 2..=ki {
            let psijm1 = self.c.psi[j - 1];
            let gamma = (hi + term) / psijm1;
            let eta = hi / psijm1;
            for i in 1..=(kip1 - j) {
                w[i] = gamma * w[i] - eta * w[i + 1];
            }
            g[j] = w[1];
            term = psijm1;
        }
        out.fill(0.0);
        for j in 1..=ki {
            let i = kip1 - j;
            let c = (i - 1) * n;
            for (o, phi) in out.iter_mut().zip(&self.phi[c..c + n]) {
                *o += g[i] * phi;
            }
        }
        for (o, y) in out.iter_mut().zip(&self.y) {
            *o = y + hi * *o;
        }
    }
}
