//! # pfaff: constrained multibody dynamics from declarative models
//!
//! A model is written as an inline module annotated with [`mechanism`]. At compile time
//! the macro derives the mass matrix, the generalized forces, the constraint Jacobians
//! and the acceleration right-hand sides symbolically, and emits allocation-free Rust
//! that implements [`Mechanism`]. This crate holds the numerical machinery that turns
//! those functions into motion.
//!
//! Principal types:
//! - [`Mechanism`]: the trait generated code implements; [`Info`] describes a model.

pub use pfaff_macros::mechanism;

mod mechanism;
pub mod ode;

pub use mechanism::{Info, Mechanism, Parameter, Pattern, Symbol, TimeDependence};

/// Items used by generated code. Not part of the public API.
#[doc(hidden)]
pub mod __private {
    pub use crate::mechanism::{Info, Mechanism, Parameter, Symbol, TimeDependence};
}
