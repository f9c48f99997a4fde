//! Integration, accuracy and snapshot tests of pfaff.
//!
//! One test binary: this library, compiled with `cfg(test)`, holds every module.

pub mod sources;
pub mod states;

#[cfg(test)]
mod accuracy;
#[cfg(test)]
mod bodies;
#[cfg(test)]
mod cli;
#[cfg(test)]
mod flex;
#[cfg(test)]
mod free_motion;
#[cfg(test)]
mod fuzz;
#[cfg(test)]
mod impacts;
#[cfg(test)]
mod linear;
#[cfg(test)]
mod replay;
#[cfg(test)]
mod run_data;
#[cfg(test)]
mod sim;
#[cfg(test)]
mod snapshots;
#[cfg(test)]
mod ui;

/// The chapter `docs/free-motion.md`; its code blocks run as doctests.
#[doc = include_str!("../../docs/free-motion.md")]
pub mod free_motion_chapter {}
