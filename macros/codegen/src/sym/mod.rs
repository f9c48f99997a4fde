//! The symbolic engine: a hash-consed expression DAG ([`graph`]), the table of
//! operations ([`op`]), memoised differentiation ([`diff`]), numeric evaluation,
//! substitution and the simplification pass ([`transform`]), the sharing of partial
//! products in finished expressions ([`share`]), and an infix printer ([`display`]).

pub mod diff;
pub mod display;
pub mod graph;
pub mod op;
pub mod share;
pub mod transform;

pub use graph::{Deps, ExprId, Graph, Node, Var};
pub use op::Func;

#[cfg(test)]
mod tests;
