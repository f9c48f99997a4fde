//! Impacts (docs/theory.md §impacts): the contacts' generated derivatives against finite
//! differences, the impulse solve against the verification cases V13–V16 in both forms,
//! its energy balance and its typed failure at a singular configuration.

mod jacobian;
mod sim;
mod solve;
