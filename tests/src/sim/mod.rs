//! Simulation tests (`pfaff::sim`) on the built-in models and on a few models written
//! for these tests with `#[pfaff::mechanism]`.
//!
//! Every reference value cites its source: docs/theory.md (cases V10, V11),
//! docs/models.md (the pendulum's exact solution), or a closed form derived in the
//! test.

mod andrews;
mod declared;
mod exact;
mod faults;
mod guards;
mod models;
mod partitioning;
mod pendulum;
mod projection;
mod proportionality;
mod published;
mod redundant;
mod robustness;
mod rows;
mod singular;
mod sleigh;
mod slider_crank;
mod solve;
mod stiff;
mod units;
