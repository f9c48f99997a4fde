//! Test problems with known solutions, for tests and benchmarks of the integrators.
//!
//! Input: none beyond the parameters. Output: [`OdeSystem`]s with an initial state and
//! the exact solution where one exists in closed form.
//! Invariants: `y0()` has length `dim()`; `exact(t)` equals `y0()` at $t = 0$.

use super::system::{OdeSystem, RhsError};

/// Exponential decay $y' = -\lambda y$, $y(0) = 1$: $y = e^{-\lambda t}$.
#[derive(Clone, Copy, Debug)]
pub struct Decay {
    /// Decay rate $\lambda$.
    pub lambda: f64,
}

impl Decay {
    /// The initial state.
    pub fn y0(&self) -> [f64; 1] {
        [1.0]
    }
    /// The exact solution.
    pub fn exact(&self, t: f64) -> [f64; 1] {
        [(-self.lambda * t).exp()]
    }
}

impl OdeSystem for Decay {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        dy[0] = -self.lambda * y[0];
        Ok(())
    }
}

/// Harmonic oscillator $y'' = -\omega^2 y$ as a first-order system, $y(0) = 1$,
/// $y'(0) = 0$: $(y, y') = (\cos\omega t, -\omega\sin\omega t)$.
#[derive(Clone, Copy, Debug)]
pub struct Oscillator {
    /// Angular frequency $\omega$.
    pub omega: f64,
}

impl Oscillator {
    /// The initial state.
    pub fn y0(&self) -> [f64; 2] {
        [1.0, 0.0]
    }
    /// The exact solution.
    pub fn exact(&self, t: f64) -> [f64; 2] {
        let w = self.omega;
        [(w * t).cos(), -w * (w * t).sin()]
    }
}

impl OdeSystem for Oscillator {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        dy[0] = y[1];
        dy[1] = -self.omega * self.omega * y[0];
        Ok(())
    }
}

/// The non-autonomous scalar problem $y' = y\cos t$, $y(0) = 1$: $y = e^{\sin t}$.
#[derive(Clone, Copy, Debug, Default)]
pub struct ExpSin;

impl ExpSin {
    /// The initial state.
    pub fn y0(&self) -> [f64; 1] {
        [1.0]
    }
    /// The exact solution.
    pub fn exact(&self, t: f64) -> [f64; 1] {
        [t.sin().exp()]
    }
}

impl OdeSystem for ExpSin {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        dy[0] = y[0] * t.cos();
        Ok(())
    }
}

/// The Kepler problem $\ddot x = -x/|x|^3$ with state $(x_1, x_2, \dot x_1, \dot x_2)$,
/// started at pericentre with eccentricity $e$: $x = (1 - e, 0)$,
/// $\dot x = (0, \sqrt{(1+e)/(1-e)})$. The orbit has semi-major axis 1, so period $2\pi$.
#[derive(Clone, Copy, Debug)]
pub struct Kepler {
    /// Eccentricity $e \in [0, 1)$.
    pub e: f64,
}

impl Kepler {
    /// The initial state (and the state after every period).
    pub fn y0(&self) -> [f64; 4] {
        let e = self.e;
        [1.0 - e, 0.0, 0.0, ((1.0 + e) / (1.0 - e)).sqrt()]
    }
    /// The energy $\tfrac12|\dot x|^2 - 1/|x|$, equal to $-\tfrac12$ on the orbit.
    pub fn energy(y: &[f64]) -> f64 {
        0.5 * (y[2] * y[2] + y[3] * y[3]) - 1.0 / y[0].hypot(y[1])
    }
}

impl OdeSystem for Kepler {
    fn dim(&self) -> usize {
        4
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        let r = y[0].hypot(y[1]);
        let r3 = r * r * r;
        dy[0] = y[2];
        dy[1] = y[3];
        dy[2] = -y[0] / r3;
        dy[3] = -y[1] / r3;
        Ok(())
    }
}

/// The blow-up $y' = y^2$, $y(0) = 1$: $y = 1/(1 - t)$, infinite at $t = 1$.
#[derive(Clone, Copy, Debug, Default)]
pub struct BlowUp;

impl OdeSystem for BlowUp {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
        dy[0] = y[0] * y[0];
        Ok(())
    }
}
