//! Hand-written reference of a model: its source expressions re-typed as closures over
//! `f64`, and every generated quantity derived from them by central differences.
//!
//! The derivations follow the definitions of `runtime/src/mechanism.rs` and docs/theory.md
//! §constraints and §redundant-coordinates: $M = \partial^2T/\partial\dot q^2$;
//! $Q = Q_e - \partial V/\partial q + \partial T/\partial q - T_{\dot qq}\dot q - T_{\dot qt}$;
//! $\gamma_h = -(C_q\dot q)_q\dot q - 2C_{qt}\dot q - C_{tt}$;
//! $\gamma_{nh} = -[(G\dot q)_q\dot q + G_t\dot q + g_q\dot q + g_t]$. The last three are
//! evaluated along the acceleration-free motion $q(s) = q + s\dot q$, time $t + s$, on which
//! $\ddot q = 0$: there $\tfrac{d}{ds}\partial T/\partial\dot q = T_{\dot qq}\dot q + T_{\dot qt}$,
//! $\tfrac{d^2}{ds^2}C = (C_q\dot q)_q\dot q + 2C_{qt}\dot q + C_{tt} = -\gamma_h$ and
//! $\tfrac{d}{ds}(G\dot q + g) = -\gamma_{nh}$.

use super::util::{along, d1, d2, gradient, shifted};

/// A function of the state, `f(t, q, q̇)`.
type StateFn = Box<dyn Fn(f64, &[f64], &[f64]) -> f64>;
/// A function of the configuration, `f(t, q)`.
type ConfigFn = Box<dyn Fn(f64, &[f64]) -> f64>;

/// The source expressions of a model.
pub struct Reference {
    n: usize,
    kinetic: StateFn,
    potential: Option<ConfigFn>,
    forces: Vec<(usize, StateFn)>,
    virtual_work: Vec<(StateFn, ConfigFn)>,
    holonomic: Vec<ConfigFn>,
    nonholonomic: Vec<StateFn>,
}

impl Reference {
    /// A model with `n` coordinates and kinetic energy `T(t, q, q̇)`.
    pub fn new(n: usize, kinetic: impl Fn(f64, &[f64], &[f64]) -> f64 + 'static) -> Self {
        Self {
            n,
            kinetic: Box::new(kinetic),
            potential: None,
            forces: Vec::new(),
            virtual_work: Vec::new(),
            holonomic: Vec::new(),
            nonholonomic: Vec::new(),
        }
    }

    /// The potential energy `V(t, q)` (`fn potential_energy`).
    pub fn potential(mut self, v: impl Fn(f64, &[f64]) -> f64 + 'static) -> Self {
        self.potential = Some(Box::new(v));
        self
    }

    /// A generalized force on coordinate `index` (`#[force(coordinate)]`).
    pub fn force(mut self, index: usize, f: impl Fn(f64, &[f64], &[f64]) -> f64 + 'static) -> Self {
        self.forces.push((index, Box::new(f)));
        self
    }

    /// A virtual-work term `coefficient · δ(expression)` (`#[virtual_work]`).
    pub fn virtual_work(
        mut self,
        coefficient: impl Fn(f64, &[f64], &[f64]) -> f64 + 'static,
        expression: impl Fn(f64, &[f64]) -> f64 + 'static,
    ) -> Self {
        self.virtual_work
            .push((Box::new(coefficient), Box::new(expression)));
        self
    }

    /// A holonomic constraint `C_i(t, q)` (`#[holonomic]`), in row order.
    pub fn holonomic(mut self, c: impl Fn(f64, &[f64]) -> f64 + 'static) -> Self {
        self.holonomic.push(Box::new(c));
        self
    }

    /// A non-holonomic constraint, linear in `q̇` (`#[nonholonomic]`), in row order.
    pub fn nonholonomic(mut self, c: impl Fn(f64, &[f64], &[f64]) -> f64 + 'static) -> Self {
        self.nonholonomic.push(Box::new(c));
        self
    }

    pub fn nq(&self) -> usize {
        self.n
    }

    pub fn nh(&self) -> usize {
        self.holonomic.len()
    }

    pub fn nnh(&self) -> usize {
        self.nonholonomic.len()
    }

    pub fn kinetic_energy(&self, t: f64, q: &[f64], qd: &[f64]) -> f64 {
        (self.kinetic)(t, q, qd)
    }

    pub fn potential_energy(&self, t: f64, q: &[f64]) -> f64 {
        self.potential.as_ref().map_or(0.0, |v| v(t, q))
    }

    /// `M = ∂²T/∂q̇²`, dense row-major, by nested first differences.
    pub fn mass_matrix(&self, t: f64, q: &[f64], qd: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut m = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                m[i * n + j] = d1(|s| {
                    let v = shifted(qd, j, s);
                    d1(|r| (self.kinetic)(t, q, &shifted(&v, i, r)))
                });
            }
        }
        m
    }

    /// `Q_e`: the direct forces plus the coefficients of `δq` in the virtual work.
    pub fn applied(&self, t: f64, q: &[f64], qd: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.n];
        for (i, f) in &self.forces {
            out[*i] += f(t, q, qd);
        }
        for (coefficient, expression) in &self.virtual_work {
            let c = coefficient(t, q, qd);
            let grad = gradient(|x| expression(t, x), q);
            for (o, g) in out.iter_mut().zip(grad) {
                *o += c * g;
            }
        }
        out
    }

    /// Magnitude of the values the applied-force reference is computed from (`|c|·|e|`
    /// of each virtual-work term, `|f|` of each force): the scale of its rounding error.
    pub fn applied_scale(&self, t: f64, q: &[f64], qd: &[f64]) -> f64 {
        let direct = self.forces.iter().map(|(_, f)| f(t, q, qd).abs());
        let work = self
            .virtual_work
            .iter()
            .map(|(c, e)| (c(t, q, qd) * e(t, q)).abs());
        direct.chain(work).sum()
    }

    /// The Lagrange operator with the applied forces:
    /// `Q = Q_e − ∂V/∂q + ∂T/∂q − d/ds ∂T/∂q̇ (t + s, q + s q̇, q̇)`.
    pub fn forces(&self, t: f64, q: &[f64], qd: &[f64]) -> Vec<f64> {
        let applied = self.applied(t, q, qd);
        let dv = gradient(|x| self.potential_energy(t, x), q);
        let dt = gradient(|x| (self.kinetic)(t, x, qd), q);
        (0..self.n)
            .map(|i| {
                let rate = d1(|s| {
                    let x = along(q, qd, s);
                    d1(|r| (self.kinetic)(t + s, &x, &shifted(qd, i, r)))
                });
                applied[i] - dv[i] + dt[i] - rate
            })
            .collect()
    }

    pub fn holonomic_values(&self, t: f64, q: &[f64]) -> Vec<f64> {
        self.holonomic.iter().map(|c| c(t, q)).collect()
    }

    /// `C_q`, dense row-major.
    pub fn holonomic_jacobian(&self, t: f64, q: &[f64]) -> Vec<f64> {
        self.holonomic
            .iter()
            .flat_map(|c| gradient(|x| c(t, x), q))
            .collect()
    }

    /// `C_t`.
    pub fn holonomic_rate(&self, t: f64, q: &[f64]) -> Vec<f64> {
        self.holonomic.iter().map(|c| d1(|s| c(t + s, q))).collect()
    }

    /// `γ_h = −d²/ds² C(t + s, q + s q̇)`.
    pub fn holonomic_gamma(&self, t: f64, q: &[f64], qd: &[f64]) -> Vec<f64> {
        self.holonomic
            .iter()
            .map(|c| -d2(|s| c(t + s, &along(q, qd, s))))
            .collect()
    }

    /// `G = ∂(G q̇ + g)/∂q̇`, dense row-major.
    pub fn nonholonomic_matrix(&self, t: f64, q: &[f64]) -> Vec<f64> {
        let zero = vec![0.0; self.n];
        self.nonholonomic
            .iter()
            .flat_map(|c| gradient(|v| c(t, q, v), &zero))
            .collect()
    }

    /// `g`: the constraint expression at `q̇ = 0`.
    pub fn nonholonomic_bias(&self, t: f64, q: &[f64]) -> Vec<f64> {
        let zero = vec![0.0; self.n];
        self.nonholonomic.iter().map(|c| c(t, q, &zero)).collect()
    }

    /// The constraint expressions at the state.
    pub fn nonholonomic_values(&self, t: f64, q: &[f64], qd: &[f64]) -> Vec<f64> {
        self.nonholonomic.iter().map(|c| c(t, q, qd)).collect()
    }

    /// `γ_nh = −d/ds (G q̇ + g)(t + s, q + s q̇)` at fixed `q̇`.
    pub fn nonholonomic_gamma(&self, t: f64, q: &[f64], qd: &[f64]) -> Vec<f64> {
        self.nonholonomic
            .iter()
            .map(|c| -d1(|s| c(t + s, &along(q, qd, s), qd)))
            .collect()
    }
}
