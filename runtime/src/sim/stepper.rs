//! Run-time choice of the integrator: an enum over the five methods, since
//! [`Integrator`] has generic methods and is not object safe.

use super::Method;
use crate::ode::{
    Adams, Dop853, Dopri5, Integrator, OdeError, OdeOptions, OdeStats, OdeSystem, Radau5, Rk4,
};

// One stepper lives per run, so the size of the largest variant (Adams' history) costs
// nothing worth a box.
#[allow(clippy::large_enum_variant)]
#[derive(Debug)]
pub(crate) enum Stepper {
    Rk4(Rk4),
    Dopri5(Dopri5),
    Dop853(Dop853),
    Adams(Adams),
    Radau5(Radau5),
}

macro_rules! each {
    ($self:expr, $i:ident => $body:expr) => {
        match $self {
            Stepper::Rk4($i) => $body,
            Stepper::Dopri5($i) => $body,
            Stepper::Dop853($i) => $body,
            Stepper::Adams($i) => $body,
            Stepper::Radau5($i) => $body,
        }
    };
}

impl Stepper {
    pub fn new(method: Method, dim: usize, opts: OdeOptions) -> Result<Self, OdeError> {
        Ok(match method {
            Method::Rk4 { h } => Self::Rk4(Rk4::new(dim, h)?.with_max_steps(opts.max_steps)),
            Method::Dopri5 => Self::Dopri5(Dopri5::new(dim, opts)?),
            Method::Dop853 => Self::Dop853(Dop853::new(dim, opts)?),
            Method::Adams => Self::Adams(Adams::new(dim, opts)?),
            Method::Radau5 => Self::Radau5(Radau5::new(dim, opts)?),
        })
    }

    pub fn reset<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t0: f64,
        y0: &[f64],
        h0: Option<f64>,
    ) -> Result<(), OdeError> {
        each!(self, i => i.reset(sys, t0, y0, h0))
    }

    pub fn step<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t_stop: Option<f64>,
    ) -> Result<f64, OdeError> {
        each!(self, i => i.step(sys, t_stop))
    }

    pub fn t(&self) -> f64 {
        each!(self, i => i.t())
    }

    pub fn y(&self) -> &[f64] {
        each!(self, i => i.y())
    }

    pub fn interpolate(&self, t: f64, out: &mut [f64]) -> Result<(), OdeError> {
        each!(self, i => i.interpolate(t, out))
    }

    /// DOP853 and DOPRI5 prepare their interpolants only on the steps that reach `t`
    /// (see [`Dop853::dense_output_from`], [`Dopri5::dense_output_from`]); the other
    /// methods have theirs on every step at no cost.
    pub fn dense_output_from(&mut self, t: Option<f64>) {
        match self {
            Self::Dop853(i) => i.dense_output_from(t),
            Self::Dopri5(i) => i.dense_output_from(t),
            _ => {}
        }
    }

    pub fn set_state(&mut self, y: &[f64]) -> Result<(), OdeError> {
        each!(self, i => i.set_state(y))
    }

    pub fn set_state_keeping_derivative(&mut self, y: &[f64]) -> Result<(), OdeError> {
        each!(self, i => i.set_state_keeping_derivative(y))
    }

    pub fn stats(&self) -> &OdeStats {
        each!(self, i => i.stats())
    }
}
