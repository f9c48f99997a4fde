//! Generic integrators for $y' = f(t, y)$, independent of mechanisms.
//!
//! Input: an [`OdeSystem`] and an initial state. Output: accepted steps one at a time,
//! dense output on the last step, work counters.
//! Invariants: no integrator allocates while stepping (all scratch is sized by the
//! constructor); every NaN or infinity is reported as [`OdeError::NonFinite`]; after any
//! error the last accepted state stays readable; a
//! [recoverable](RhsError::recoverable) failure of the right-hand side rejects the
//! attempt and shortens the step, and is returned only when the step size underflows.
//!
//! | integrator | method | error control | dense output |
//! |---|---|---|---|
//! | [`Rk4`] | classical Runge–Kutta 4 | none (fixed step) | order 3 from the stages |
//! | [`Dopri5`] | Dormand–Prince 5(4), FSAL | mixed RMS norm, PI controller | order 4 |
//! | [`Dop853`] | Dormand–Prince 8(5,3) | mixed RMS norm, 5th/3rd-order estimator | order 7 |
//! | [`Adams`] | Shampine–Gordon `STEP`, orders 1–12, PECE | weighted 2-norm, see there | `INTRP` |
//! | [`Radau5`] | Radau IIA order 5, implicit (stiff), simplified Newton, FD Jacobian | RMS norm, order-3 estimate, Gustafsson | collocation polynomial |
//!
//! All implement [`Integrator`]: [`reset`](Integrator::reset) (also a hard restart),
//! [`step`](Integrator::step) (one accepted step, never past `t_stop`),
//! [`interpolate`](Integrator::interpolate), [`set_state`](Integrator::set_state) and
//! [`stats`](Integrator::stats). [`EventLocator`] finds zero crossings of an event
//! function on the dense output, for impacts and other discontinuities.

mod adams;
mod common;
mod dop853;
mod dop853_tableau;
mod dopri5;
mod error;
mod events;
mod integrator;
mod options;
mod radau;
mod rk4;
mod rk_driver;
pub mod samples;
mod system;

pub use adams::Adams;
pub use dop853::Dop853;
pub use dopri5::Dopri5;
pub use error::{OdeError, Quantity};
pub use events::{Crossing, EventLocator};
pub use integrator::Integrator;
pub use options::{OdeOptions, OdeStats, Tolerances};
pub use radau::Radau5;
pub use rk4::Rk4;
pub use system::{OdeSystem, RhsError};
