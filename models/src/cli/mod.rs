//! The `pfaff` program: argument parsing, dispatch to one module per command, and the
//! mapping of errors to one line on stderr and an exit code (0 success, 1 a failed
//! computation or I/O, 2 bad input).

mod animate;
mod args;
mod error;
mod impacts;
mod linearize;
mod list;
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

use args::{Cli, Command, FormulationArg, IntegratorArg, SimulateArgs, StateArgs};
use error::CliError;

/// The default scene: Andrews' squeezing mechanism over its reference span with the
/// method of the seed paper (coordinate partitioning and the Adams method).
fn default_scene() -> SimulateArgs {
    SimulateArgs {
        model: "andrews".to_owned(),
        t_end: None,
        formulation: FormulationArg::Partitioning,
        integrator: Some(IntegratorArg::Adams),
        rtol: 1e-6,
        atol: 1e-8,
        step: None,
        state: StateArgs {
            set: Vec::new(),
            q0: Vec::new(),
            qd0: Vec::new(),
        },
        csv: None,
        plot: Some("pfaff-andrews.svg".into()),
        animate: None,
        samples: 500,
        json: false,
        repeat: 1,
    }
}

fn dispatch(cli: &Cli) -> Result<(), CliError> {
    match &cli.command {
        None => {
            let args = default_scene();
            simulate::command(&args)?;
            println!("\n(`pfaff --help` lists the commands; `pfaff list` the models.)");
            Ok(())
        }
        Some(Command::List) => {
            print!("{}", list::list());
            Ok(())
        }
        Some(Command::Show { model }) => {
            print!("{}", list::show(model)?);
            Ok(())
        }
        Some(Command::Simulate(args)) => simulate::command(args),
        Some(Command::Linearize(args)) => linearize::command(args),
        Some(Command::WorkPrecision(args)) => precision::command(args),
        Some(Command::RhsTime(args)) => rhs_time::command(args),
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

/// Runs the program. With `--json` anywhere among the arguments, stdout holds exactly
/// one JSON object whatever the exit code: the command's report, or
/// `{"error": {"kind", "message"}}` when it failed before it had one.
pub fn main() -> ExitCode {
    let args = join_negative_values(std::env::args());
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
                println!("{}", error::usage(message.clone()).json());
            }
            eprintln!("pfaff: error: {message}");
            return ExitCode::from(2);
        }
    };
    match dispatch(&cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            if json && !e.is_reported() {
                println!("{}", e.json());
            }
            eprintln!("pfaff: error: {e}");
            ExitCode::from(e.code())
        }
    }
}

/// A time for the reports: as written (`7.10352584272872`, `3`) unless it is so small or
/// so large that its digits would fill the line (`1e-300`, not 300 zeros).
pub(crate) fn time(t: f64) -> String {
    if t == 0.0 || (1e-4..1e16).contains(&t.abs()) || !t.is_finite() {
        format!("{t}")
    } else {
        format!("{t:e}")
    }
}
