//! The `pfaff` command as a library: `list`, `show`, `simulate` (summary, `--json`,
//! `--csv`, `--plot` SVG, `--animate` HTML), `linearize`, `work-precision` and
//! `rhs-time` for any list of models, the built-in ones (the `pfaff` program of
//! `pfaff-models`) or a user's own:
//!
//! ```ignore
//! #[pfaff::mechanism]
//! pub mod double_pendulum { /* … */ }
//!
//! fn main() -> std::process::ExitCode {
//!     pfaff_cli::main(&[pfaff_cli::model!(double_pendulum).span(5.0, "a few swings")])
//! }
//! ```
//!
//! An [`Entry`] is the name, summary and constructor of a model with what the commands
//! know beyond its `Info` (its [`Scene`]: default span, steady motion, closed form);
//! every part has a default. [`main`] parses the process arguments, runs the command
//! and maps errors to one line on stderr and an exit code: 0 success, 1 a failed
//! computation or I/O, 2 bad input, 141 stdout closed by its reader (see `out`).
//!
//! The modules: argument definitions in `args`, one module per command, and the shared
//! parts (`setup`, `plot`, `scene`, `error`, `out`).

mod animate;
mod args;
pub mod entry;
mod error;
mod impacts;
mod linearize;
mod list;
mod out;
mod outputs;
mod plot;
mod precision;
mod rhs_time;
mod scene;
mod setup;
mod simulate;
mod split;

use std::process::ExitCode;

use clap::error::ErrorKind;
use clap::Parser;

use args::{Cli, Command, FormulationArg, SimulateArgs, StateArgs};
use error::CliError;

pub use entry::Entry;
pub use scene::{ClosedForm, ImpactTimes, Scene, Steady};

/// The default scene: `model` over its span with the method of the seed paper
/// (coordinate partitioning and the Adams method, Radau5 if the model is stiff),
/// plotted to `pfaff-MODEL.svg`.
fn default_scene(model: &str) -> SimulateArgs {
    SimulateArgs {
        model: model.to_owned(),
        t_end: None,
        formulation: FormulationArg::Partitioning,
        integrator: None,
        rtol: 1e-6,
        atol: 1e-8,
        step: None,
        state: StateArgs {
            set: Vec::new(),
            q0: Vec::new(),
            qd0: Vec::new(),
        },
        csv: None,
        plot: Some(format!("pfaff-{model}.svg").into()),
        animate: None,
        samples: 500,
        json: false,
        repeat: 1,
    }
}

fn dispatch(models: &[Entry], default: &str, cli: &Cli) -> Result<(), CliError> {
    match &cli.command {
        None => {
            let args = default_scene(default);
            simulate::command(models, &args)?;
            out::print("\n(`pfaff --help` lists the commands; `pfaff list` the models.)\n")
        }
        Some(Command::List) => out::print(&list::list(models)),
        Some(Command::Show { model, code: false }) => out::print(&list::show(models, model)?),
        Some(Command::Show { model, code: true }) => out::print(&list::code(models, model)?),
        Some(Command::Simulate(args)) => simulate::command(models, args),
        Some(Command::Linearize(args)) => linearize::command(models, args),
        Some(Command::WorkPrecision(args)) => precision::command(models, args),
        Some(Command::RhsTime(args)) => rhs_time::command(models, args),
    }
}

/// Collapses clap's multi-line message into one line.
fn one_line(e: &clap::Error) -> String {
    let text = e.to_string();
    let lines: Vec<&str> = text
        .lines()
        .map(str::trim)
        .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
        .filter(|l| !l.is_empty())
        .collect();
    // A line that ends in a colon introduces the next (clap's "were not provided:"
    // before the missing argument): joined with a space, not "; ".
    let mut one = String::new();
    for l in lines {
        if !one.is_empty() {
            one.push_str(if one.ends_with(':') { " " } else { "; " });
        }
        one.push_str(l);
    }
    one.trim_start_matches("error: ").to_owned()
}

/// Joins `--flag -1e-6` into `--flag=-1e-6`: clap takes `-1e-6` for a short option
/// (its negative-number check does not cover exponents), and a negative value should
/// reach the validation that explains what is expected.
fn join_negative_values(args: impl Iterator<Item = String>) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for arg in args {
        let negative = arg.len() > 1
            && arg.starts_with('-')
            && arg[1..].starts_with(|c: char| c.is_ascii_digit() || c == '.');
        match out.last_mut() {
            Some(prev) if negative && prev.starts_with("--") && !prev.contains('=') => {
                prev.push('=');
                prev.push_str(&arg);
            }
            _ => out.push(arg),
        }
    }
    out
}

/// Runs the command on the process arguments over `models`; without a command it
/// simulates the first of them (see [`main_with_default`]).
///
/// With `--json` anywhere among the arguments, stdout holds exactly one JSON object
/// whatever the exit code: the command's report, or `{"error": {"kind", "message"}}`
/// when it failed before it had one.
pub fn main(models: &[Entry]) -> ExitCode {
    let default = models.first().map_or("", |e| e.name);
    main_with_default(models, default)
}

/// As [`main`], with `default` the model simulated when no command is given.
pub fn main_with_default(models: &[Entry], default: &str) -> ExitCode {
    run(models, default, std::env::args())
}

/// As [`main_with_default`], on the arguments `args` (the first is the program's name).
pub fn run(models: &[Entry], default: &str, args: impl Iterator<Item = String>) -> ExitCode {
    let args = join_negative_values(args);
    let json = args.iter().skip(1).any(|a| a == "--json");
    let cli = match Cli::try_parse_from(&args) {
        Ok(cli) => cli,
        Err(e) => {
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
                let _ = e.print();
                return ExitCode::SUCCESS;
            }
            let message = format!("{} (see `pfaff --help`)", one_line(&e));
            if json {
                if let Err(e) = out::line(format_args!("{}", error::usage(message.clone()).json()))
                {
                    if e.is_broken_pipe() {
                        return ExitCode::from(e.code());
                    }
                }
            }
            out::error_line(&format!("pfaff: error: {message}"));
            return ExitCode::from(2);
        }
    };
    match dispatch(models, default, &cli) {
        Ok(()) => ExitCode::SUCCESS,
        // Stdout closed by its reader: nothing more to say, and nowhere to say it.
        Err(e) if e.is_broken_pipe() => ExitCode::from(e.code()),
        Err(e) => {
            if json && !e.is_reported() {
                if let Err(p) = out::line(format_args!("{}", e.json())) {
                    if p.is_broken_pipe() {
                        return ExitCode::from(p.code());
                    }
                }
            }
            out::error_line(&format!("pfaff: error: {e}"));
            ExitCode::from(e.code())
        }
    }
}

/// A time for the reports: as written (`7.10352584272872`, `3`) unless it is so small or
/// so large that its digits would fill the line (`1e-300`, not 300 zeros).
fn time(t: f64) -> String {
    if t == 0.0 || (1e-4..1e16).contains(&t.abs()) || !t.is_finite() {
        format!("{t}")
    } else {
        format!("{t:e}")
    }
}
