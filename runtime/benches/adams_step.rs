//! The Adams method's own work per step (`pfaff::ode::Adams`: coefficients, predictor,
//! error estimates, corrector, differences, order and step selection), measured on
//! uncoupled harmonic oscillators whose right-hand side costs a few nanoseconds: the
//! time per step is the method's bookkeeping plus two such evaluations (PECE). State
//! sizes 4 (the pendulum's), 14 (`andrews`'), 56; rtol = atol = 1e-6, 1e-8, 1e-10; 20 s
//! of oscillation. Best of 300 runs each (the machine is shared).
//!
//! `cargo bench -p pfaff --bench adams_step`.

use std::time::Instant;

use pfaff::ode::{Adams, Integrator, OdeOptions, OdeSystem, RhsError, Tolerances};

/// `n/2` oscillators $\ddot x_j = -\omega_j^2 x_j$, $\omega_j = 1 + 0.3j$.
struct Oscillators {
    omega2: Vec<f64>,
}

impl OdeSystem for Oscillators {
    fn dim(&self) -> usize {
        2 * self.omega2.len()
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let m = self.omega2.len();
        let (x, v) = y.split_at(m);
        let (dx, dv) = dy.split_at_mut(m);
        dx.copy_from_slice(v);
        for ((a, x), w2) in dv.iter_mut().zip(x).zip(&self.omega2) {
            *a = -w2 * x;
        }
        Ok(())
    }
}

fn main() {
    println!("  n  rtol    steps  order  per run [us]  per step [ns]");
    for n in [4, 14, 56] {
        let m = n / 2;
        let mut sys = Oscillators {
            omega2: (0..m).map(|j| (1.0 + 0.3 * j as f64).powi(2)).collect(),
        };
        let y0: Vec<f64> = (0..n).map(|i| if i < m { 1.0 } else { 0.0 }).collect();
        for rtol in [1e-6, 1e-8, 1e-10] {
            let opts = OdeOptions {
                tol: Tolerances::new(rtol, rtol),
                ..OdeOptions::default()
            };
            let mut best = f64::INFINITY;
            let mut ode = Adams::new(n, opts.clone()).expect("valid options");
            for _ in 0..300 {
                ode = Adams::new(n, opts.clone()).expect("valid options");
                let start = Instant::now();
                ode.reset(&mut sys, 0.0, &y0, None).expect("finite start");
                ode.integrate_to(&mut sys, 20.0).expect("smooth problem");
                best = best.min(start.elapsed().as_secs_f64());
            }
            let steps = ode.stats().steps;
            println!(
                "{n:3}  {rtol:5.0e}  {steps:5}  {:5}  {:12.1}  {:13.1}",
                ode.last_order(),
                best * 1e6,
                best / steps as f64 * 1e9
            );
        }
    }
}
