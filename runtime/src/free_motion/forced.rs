//! A model whose declared applied forces are replaced by a function of the state.
//!
//! Input: a [`Mechanism`] and a function $Q(t, q, \dot q)$. Output: a [`Mechanism`]
//! whose [`forces`](Mechanism::forces) are the model's minus its
//! [`applied_forces`](Mechanism::applied_forces) plus $Q$, so that the forces designed by
//! [`FreeMotion::free_forces`](super::FreeMotion::free_forces) can be simulated with
//! [`Dynamics`](crate::Dynamics) or the simulation layer. Everything else is the
//! model's.

use std::cell::RefCell;
use std::fmt;

use crate::{Info, Mechanism};

/// `model` with its declared applied forces replaced by `applied(t, q, q̇, out)`.
pub struct Forced<M, F> {
    /// The wrapped model.
    pub model: M,
    applied: F,
    scratch: RefCell<Vec<f64>>,
}

impl<M: Mechanism, F: Fn(f64, &[f64], &[f64], &mut [f64])> Forced<M, F> {
    /// Wraps `model`; `applied` writes $Q$ (length $n$) into its last argument.
    pub fn new(model: M, applied: F) -> Self {
        let n = model.info().nq();
        Self {
            model,
            applied,
            scratch: RefCell::new(vec![0.0; n]),
        }
    }
}

impl<M: fmt::Debug, F> fmt::Debug for Forced<M, F> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Forced")
            .field("model", &self.model)
            .finish_non_exhaustive()
    }
}

impl<M: Mechanism, F: Fn(f64, &[f64], &[f64], &mut [f64])> Mechanism for Forced<M, F> {
    fn info(&self) -> &'static Info {
        self.model.info()
    }
    fn parameter(&self, index: usize) -> f64 {
        self.model.parameter(index)
    }
    fn set_parameter(&mut self, index: usize, value: f64) {
        self.model.set_parameter(index, value);
    }
    fn initial_state(&self, q: &mut [f64], qd: &mut [f64]) {
        self.model.initial_state(q, qd);
    }
    fn mass_matrix(&self, t: f64, q: &[f64], out: &mut [f64]) {
        self.model.mass_matrix(t, q, out);
    }
    fn forces(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
        self.model.forces(t, q, qd, out);
        let mut s = self.scratch.borrow_mut();
        self.model.applied_forces(t, q, qd, &mut s);
        for (o, a) in out.iter_mut().zip(s.iter()) {
            *o -= a;
        }
        (self.applied)(t, q, qd, &mut s);
        for (o, a) in out.iter_mut().zip(s.iter()) {
            *o += a;
        }
    }
    fn applied_forces(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
        (self.applied)(t, q, qd, out);
    }
    fn free_motion_residual(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        applied: &[f64],
        out: &mut [f64],
    ) -> bool {
        // The fixed part of the forces is the model's, so its residual applies as is.
        self.model.free_motion_residual(t, q, qd, applied, out)
    }
    fn free_motion_conditions(&self) -> &'static [&'static str] {
        self.model.free_motion_conditions()
    }
    fn holonomic(&self, t: f64, q: &[f64], out: &mut [f64]) {
        self.model.holonomic(t, q, out);
    }
    fn holonomic_jacobian(&self, t: f64, q: &[f64], out: &mut [f64]) {
        self.model.holonomic_jacobian(t, q, out);
    }
    fn holonomic_with_jacobian(&self, t: f64, q: &[f64], c: &mut [f64], cq: &mut [f64]) {
        self.model.holonomic_with_jacobian(t, q, c, cq);
    }
    fn holonomic_rate(&self, t: f64, q: &[f64], out: &mut [f64]) {
        self.model.holonomic_rate(t, q, out);
    }
    fn holonomic_gamma(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
        self.model.holonomic_gamma(t, q, qd, out);
    }
    fn nonholonomic_matrix(&self, t: f64, q: &[f64], out: &mut [f64]) {
        self.model.nonholonomic_matrix(t, q, out);
    }
    fn nonholonomic_bias(&self, t: f64, q: &[f64], out: &mut [f64]) {
        self.model.nonholonomic_bias(t, q, out);
    }
    fn nonholonomic_gamma(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
        self.model.nonholonomic_gamma(t, q, qd, out);
    }
    fn kinetic_energy(&self, t: f64, q: &[f64], qd: &[f64]) -> f64 {
        self.model.kinetic_energy(t, q, qd)
    }
    fn potential_energy(&self, t: f64, q: &[f64]) -> f64 {
        self.model.potential_energy(t, q)
    }
}
