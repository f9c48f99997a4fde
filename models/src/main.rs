//! The `pfaff` command-line program.
use clap as _;
use csv as _;
use indicatif as _;
use plotters as _;
use serde as _;
use serde_json as _;
fn main() {}
