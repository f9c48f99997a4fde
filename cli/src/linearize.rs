//! `pfaff linearize`: eigenvalues of the linearized reduced system about a state, by
//! [`pfaff::linearize`].

use std::fmt::Write as _;

use pfaff::{linearize_with, LinearizeParams, States};
use serde_json::json;

use super::args::LinearizeArgs;
use super::error::{failed, usage, CliError};
use super::setup;
use crate::Entry;

/// `pfaff linearize`.
pub fn command(models: &[Entry], args: &LinearizeArgs) -> Result<(), CliError> {
    let entry = setup::find_model(models, &args.model)?;
    let model = setup::build(entry, &args.state.set)?;
    let scene = entry.scene;
    let mut guesses: Vec<(&str, f64)> = Vec::new();
    let mut velocities: Vec<(&str, f64)> = Vec::new();
    let mut ignorable: &[&str] = &[];
    let mut independent: &[&str] = &[];
    let mut about = "the initial state".to_owned();
    if let Some(steady) = scene.steady {
        guesses.extend(steady.coordinates);
        velocities.extend(steady.velocities);
        ignorable = steady.ignorable;
        independent = steady.independent_velocities;
        about = steady.summary.to_owned();
        if let Some((coordinate, default)) = steady.speed {
            let v = args.speed.unwrap_or(default);
            if !v.is_finite() {
                return Err(usage(format!(
                    "invalid --speed {v}: expected a finite number"
                )));
            }
            let ratio = steady.speed_ratio.map_or(1.0, |f| f(model.as_ref()));
            velocities.push((coordinate, ratio * v));
            about = format!("{about} at speed {v}");
        }
    }
    if args.speed.is_some() && scene.steady.and_then(|s| s.speed).is_none() {
        let with: Vec<&str> = models
            .iter()
            .filter(|e| e.scene.steady.and_then(|s| s.speed).is_some())
            .map(|e| e.name)
            .collect();
        return Err(usage(format!(
            "model `{}` defines no steady forward motion, so --speed does not apply (it does for: {})",
            entry.name,
            if with.is_empty() { "none of the models".to_owned() } else { with.join(", ") }
        )));
    }
    // The steady motion's values are guesses; --q0/--qd0 are held (and win), and then
    // the operating point is the state they give, not the steady motion.
    let given: Vec<String> = (args
        .state
        .q0
        .iter()
        .map(|a| format!("{} = {}", a.name, a.value)))
    .chain(
        args.state
            .qd0
            .iter()
            .map(|a| format!("{}' = {}", a.name, a.value)),
    )
    .collect();
    if !given.is_empty() {
        about = format!(
            "the state given by {} (the rest assembled)",
            given.join(", ")
        );
    }
    let init = setup::assemble(model.as_ref(), &args.state, &guesses, &velocities)?;
    let lin = linearize_with(
        model.as_ref(),
        0.0,
        &init.q,
        &init.qd,
        States {
            ignorable,
            velocities: independent,
        },
        &LinearizeParams::default(),
    )
    .map_err(|e| failed(format!("cannot linearize `{}`: {e}", entry.name)).kind("linearize"))?;
    let d = lin.states.len();
    let rows: Vec<Vec<f64>> = (0..d)
        .map(|i| (0..d).map(|j| lin.entry(i, j)).collect())
        .collect();
    if args.json {
        let info = model.info();
        let named = |v: &[f64]| -> serde_json::Map<String, serde_json::Value> {
            info.coordinates
                .iter()
                .zip(v)
                .map(|(c, x)| (c.name.to_owned(), json!(x)))
                .collect()
        };
        let value = json!({
            "model": entry.name,
            "operating_point": {"about": about, "q": named(&lin.q), "qd": named(&lin.qd)},
            "states": lin.states.iter().map(ToString::to_string).collect::<Vec<_>>(),
            "eigenvalues": lin.eigenvalues.iter().map(|e| json!({"re": e.re, "im": e.im})).collect::<Vec<_>>(),
            "state_matrix": rows,
            "method": lin.method.to_string(),
            "error_estimate": lin.error_estimate,
        });
        return super::out::line(format_args!("{value}"));
    }
    let mut w = String::new();
    let _ = writeln!(w, "{} linearized about {} (t = 0)", entry.name, about);
    let point: Vec<String> = model
        .info()
        .coordinates
        .iter()
        .enumerate()
        .map(|(i, c)| {
            format!(
                "{} = {:.6}, {}' = {:.6}",
                c.name, lin.q[i], c.name, lin.qd[i]
            )
        })
        .collect();
    let _ = writeln!(w, "operating point  {}", point.join("; "));
    let [beta, eta, gamma] = &lin.partition;
    let _ = writeln!(
        w,
        "partition        dependent {beta:?}, dependent velocity {eta:?}, independent {gamma:?}"
    );
    if !ignorable.is_empty() {
        let _ = writeln!(
            w,
            "dropped          {ignorable:?} (ignorable; largest coupling into the kept rows {:.1e})",
            lin.dropped_coupling
        );
    }
    let names: Vec<String> = lin.states.iter().map(ToString::to_string).collect();
    let _ = writeln!(w, "state            ({})", names.join(", "));
    let _ = writeln!(w, "state matrix");
    for row in &rows {
        let cells: Vec<String> = row.iter().map(|v| format!("{v:>14.6e}")).collect();
        let _ = writeln!(w, "  {}", cells.join(" "));
    }
    let _ = writeln!(w, "eigenvalues");
    for e in &lin.eigenvalues {
        let _ = writeln!(w, "  {:>16.9e} {:+.9e} i", e.re, e.im);
    }
    let _ = writeln!(
        w,
        "{}",
        match lin.method {
            pfaff::LinearizeMethod::Differences => format!(
                "central differences, error estimate max|A_h - A_2h| = {:.1e}",
                lin.error_estimate
            ),
            _ => "generated derivatives (exact up to rounding)".to_owned(),
        }
    );
    for note in &init.notes {
        let _ = writeln!(w, "note             {note}");
    }
    super::out::print(&w)
}
