//! Command-line arguments (clap derive).

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

/// Simulate constrained multibody systems written with pfaff.
///
/// Without a command, simulates the default model over its span (for the built-in
/// models Andrews' squeezing mechanism over its reference span of 0.03 s) with
/// coordinate partitioning and the Adams method, prints a summary and writes the plot
/// `pfaff-MODEL.svg` in the current directory.
#[derive(Debug, Parser)]
#[command(name = "pfaff", version, about, long_about)]
pub struct Cli {
    /// What to do (default: simulate the default scene).
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// List the built-in models with their sizes and a one-line description.
    List,
    /// Show a model: coordinates, parameters with defaults, constraints.
    Show {
        /// The model (see `pfaff list`).
        model: String,
        /// Print the code `#[pfaff::mechanism]` generates for the model instead
        /// (formatted; for models whose entry carries their source).
        #[arg(long)]
        code: bool,
    },
    /// Simulate a model and report, optionally writing a trajectory and a plot.
    Simulate(SimulateArgs),
    /// Eigenvalues of the linearized reduced (independent-state) system.
    Linearize(LinearizeArgs),
    /// Final error against work for every formulation and integrator over a sweep of
    /// tolerances.
    WorkPrecision(WorkPrecisionArgs),
    /// Time one index-1 right-hand side (M, Q, C_q, gamma and the solve of the augmented
    /// system) at the initial state.
    RhsTime(RhsTimeArgs),
}

/// How the constrained equations become an ODE.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FormulationArg {
    /// Coordinate partitioning in the tangent-space chart of the last step: every evaluation's positions and velocities corrected onto the constraints (no drift).
    Partitioning,
    /// Index-1 equations, positions and velocities projected after each step.
    Projection,
    /// Index-1 equations with Baumgarte stabilization (alpha = beta = 10/s).
    Baumgarte,
}

/// The integrator.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum IntegratorArg {
    /// Classical Runge-Kutta 4 with a fixed step (`--step`).
    Rk4,
    /// Dormand-Prince 5(4), adaptive.
    Dopri5,
    /// Dormand-Prince 8(5,3), adaptive.
    Dop853,
    /// Shampine-Gordon variable-order Adams, adaptive.
    Adams,
    /// Radau IIA of order 5, implicit, adaptive: for stiff models.
    Radau5,
}

/// A `NAME=VALUE` pair.
#[derive(Clone, Debug, PartialEq)]
pub struct Assignment {
    /// The name.
    pub name: String,
    /// The value.
    pub value: f64,
}

/// Parses `NAME=VALUE`; the value is a number, `pi`, `-pi`, `pi/N` or `N*pi`.
pub fn parse_assignment(s: &str) -> Result<Assignment, String> {
    let (name, value) = s
        .split_once('=')
        .ok_or_else(|| format!("expected NAME=VALUE, found `{s}`"))?;
    let name = name.trim();
    if name.is_empty() || !name.chars().all(|c| c.is_alphanumeric() || c == '_') {
        return Err(format!(
            "expected NAME=VALUE with a plain name, found `{s}`"
        ));
    }
    let value = parse_number(value.trim())
        .ok_or_else(|| format!("`{}` in `{s}` is not a finite number", value.trim()))?;
    Ok(Assignment {
        name: name.to_owned(),
        value,
    })
}

fn parse_number(s: &str) -> Option<f64> {
    let pi = std::f64::consts::PI;
    let (sign, body) = match s.strip_prefix('-') {
        Some(rest) => (-1.0, rest),
        None => (1.0, s),
    };
    let v = if body == "pi" {
        pi
    } else if let Some(d) = body.strip_prefix("pi/") {
        pi / d.parse::<f64>().ok()?
    } else if let Some(f) = body.strip_suffix("*pi") {
        f.parse::<f64>().ok()? * pi
    } else {
        body.parse::<f64>().ok()?
    };
    let v = sign * v;
    v.is_finite().then_some(v)
}

/// Parameter and initial-state overrides shared by `simulate` and `linearize`.
#[derive(Debug, Args)]
pub struct StateArgs {
    /// Set a parameter, e.g. `--set l=2` (repeatable; see `pfaff show MODEL`).
    #[arg(long = "set", value_name = "NAME=VALUE", value_parser = parse_assignment)]
    pub set: Vec<Assignment>,
    /// Set an initial coordinate, held during assembly (repeatable); the other
    /// coordinates are solved from the constraints. Given for every coordinate, the
    /// values are checked against the constraints instead (an error names the violated
    /// ones).
    #[arg(long = "q0", value_name = "NAME=VALUE", value_parser = parse_assignment)]
    pub q0: Vec<Assignment>,
    /// Set an initial velocity, held during assembly (repeatable); the dependent
    /// velocities are solved from the constraints. Given for every coordinate, the
    /// values are checked against the constraints instead.
    #[arg(long = "qd0", value_name = "NAME=VALUE", value_parser = parse_assignment)]
    pub qd0: Vec<Assignment>,
}

/// Arguments of `pfaff simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// The model (see `pfaff list`).
    pub model: String,
    /// End time in seconds; the start is 0 (default: a span chosen per model, see `pfaff list`).
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    pub t_end: Option<f64>,
    /// How the constraints are handled.
    #[arg(long, value_enum, value_name = "F", default_value_t = FormulationArg::Partitioning)]
    pub formulation: FormulationArg,
    /// The integrator (default: adams, radau5 for the models `pfaff list` marks stiff).
    #[arg(long, value_enum, value_name = "I")]
    pub integrator: Option<IntegratorArg>,
    /// Relative tolerance of the adaptive integrators.
    #[arg(
        long,
        value_name = "R",
        default_value_t = 1e-6,
        allow_negative_numbers = true
    )]
    pub rtol: f64,
    /// Absolute tolerance of the adaptive integrators.
    #[arg(
        long,
        value_name = "A",
        default_value_t = 1e-8,
        allow_negative_numbers = true
    )]
    pub atol: f64,
    /// Step size: the fixed step of rk4 (default t_end/1000), the first step of the
    /// adaptive methods.
    #[arg(long, value_name = "H", allow_negative_numbers = true)]
    pub step: Option<f64>,
    #[command(flatten)]
    pub state: StateArgs,
    /// Write t, q, q', lambda, constraint residuals and energy at each output time.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Write an SVG plot of the coordinates, the energy drift and the constraint
    /// violations against time.
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Write one self-contained HTML file that plays the run (no network needed; the
    /// trajectory is embedded in the JSON format of docs/trajectory-format.md).
    #[arg(long, value_name = "FILE.html")]
    pub animate: Option<PathBuf>,
    /// Number of output intervals for --csv and --plot (--animate uses at least its
    /// display rate).
    #[arg(long, value_name = "N", default_value_t = 500)]
    pub samples: usize,
    /// Print one JSON object on stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Run the simulation N times and report the best wall time (for timing; the runs
    /// are identical otherwise).
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub repeat: usize,
}

/// Arguments of `pfaff linearize`.
#[derive(Debug, Args)]
pub struct LinearizeArgs {
    /// The model (see `pfaff list`).
    pub model: String,
    #[command(flatten)]
    pub state: StateArgs,
    /// Forward speed of the steady motion, for models that define one (sleigh,
    /// rolling_disk, bicycle).
    #[arg(long, value_name = "V", allow_negative_numbers = true)]
    pub speed: Option<f64>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `pfaff work-precision`.
#[derive(Debug, Args)]
pub struct WorkPrecisionArgs {
    /// The model (see `pfaff list`).
    pub model: String,
    /// End time in seconds (default: the model's span).
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    pub t_end: Option<f64>,
    /// Write the table as CSV.
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Write an SVG plot of the error against wall time (log-log), one curve per
    /// method.
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// On a stiff model, sweep the explicit methods too (held to their stability limit,
    /// they may take very long or fail); other models always sweep every method.
    #[arg(long)]
    pub all_methods: bool,
}

/// Arguments of `pfaff rhs-time`.
#[derive(Debug, Args)]
pub struct RhsTimeArgs {
    /// The model (see `pfaff list`).
    pub model: String,
    #[command(flatten)]
    pub state: StateArgs,
    /// Evaluations per timed batch.
    #[arg(long, value_name = "N", default_value_t = 100_000)]
    pub calls: usize,
    /// Timed batches; the best one is reported.
    #[arg(long, value_name = "B", default_value_t = 5)]
    pub batches: usize,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn assignments() {
        let a = parse_assignment("l=2.5").unwrap();
        assert_eq!((a.name.as_str(), a.value), ("l", 2.5));
        assert_eq!(
            parse_assignment("phi=pi/2").unwrap().value,
            std::f64::consts::FRAC_PI_2
        );
        assert_eq!(
            parse_assignment("x=-pi").unwrap().value,
            -std::f64::consts::PI
        );
        assert!(parse_assignment("l")
            .unwrap_err()
            .contains("expected NAME=VALUE"));
        assert!(parse_assignment("l=abc")
            .unwrap_err()
            .contains("not a finite number"));
        assert!(parse_assignment("=1").is_err());
        assert!(parse_assignment("l=inf").is_err());
    }

    #[test]
    fn clap_definition_is_valid() {
        use clap::CommandFactory;
        Cli::command().debug_assert();
    }
}
