//! The `pfaff` command-line program over the built-in models: the command itself is
//! the library `pfaff-cli` (`cli/`), which a user's crate calls the same way with its
//! own models.
//!
//! Run without arguments it simulates the default scene (Andrews' squeezing mechanism)
//! and writes a plot; `pfaff --help` lists the commands.

fn main() -> std::process::ExitCode {
    pfaff_cli::main_with_default(pfaff_models::all(), "andrews")
}
