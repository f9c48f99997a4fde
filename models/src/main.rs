//! The `pfaff` command-line program.
fn main() {}
