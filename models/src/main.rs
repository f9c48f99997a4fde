//! The `pfaff` command-line program: built-in scenes, a machine-readable summary,
//! trajectories, plots, linearization and work-precision diagrams.
//!
//! Run without arguments it simulates the default scene (Andrews' squeezing mechanism)
//! and writes a plot; `pfaff --help` lists the commands. The modules live in
//! `models/src/cli/`: argument definitions in `args`, one module per command, and the
//! shared parts (`setup`, `plot`, `scene`, `error`).

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
