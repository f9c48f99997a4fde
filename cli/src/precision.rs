//! `pfaff work-precision`: every formulation × integrator over a tolerance sweep, by
//! [`pfaff::sim::work_precision`], against a closed form where the model has one and
//! otherwise against a run at rtol 1e-13 with partitioning and DOP853. A stiff model
//! (`Entry::stiff`) sweeps Radau5 over rtol 1e-3 … 1e-9 against a Radau5 run at rtol
//! 1e-12 (the explicit methods, held to their stability limit, only with
//! `--all-methods`).

use pfaff::sim::{format_table, work_precision, Formulation, Method, Reference, Simulation, Sweep};

use super::args::WorkPrecisionArgs;
use super::error::{failed, usage, CliError};
use super::{out, plot, setup};
use crate::Entry;

/// `pfaff work-precision`.
pub fn command(models: &[Entry], args: &WorkPrecisionArgs) -> Result<(), CliError> {
    let entry = setup::find_model(models, &args.model)?;
    let model = (entry.make)();
    let scene = entry.scene;
    let t_end = args.t_end.unwrap_or(scene.t_end);
    if !t_end.is_finite() || t_end <= 0.0 {
        let what = if t_end <= 0.0 {
            "is not after the start time 0"
        } else {
            "is not a finite time"
        };
        return Err(usage(format!(
            "--t-end {} {what}: expected a positive finite end time",
            super::time(t_end)
        )));
    }
    let (reference, source) = match scene.closed_form {
        Some(exact) => {
            let mut r = Reference::default();
            for (name, q, qd) in exact(model.as_ref(), t_end) {
                if q.is_finite() {
                    r.coordinates.push((name.to_owned(), q));
                }
                if qd.is_finite() {
                    r.velocities.push((name.to_owned(), qd));
                }
            }
            if let Some(times) = scene.impact_times {
                r.impacts = times(model.as_ref(), t_end)
                    .into_iter()
                    .map(|(c, t)| (c.to_owned(), t))
                    .collect();
            }
            (r, "the closed-form solution".to_owned())
        }
        None => {
            let (method, rtol, atol) = if entry.stiff {
                (Method::Radau5, 1e-12, 1e-14)
            } else {
                (Method::Dop853, 1e-13, 1e-15)
            };
            let run = Simulation::new(model.as_ref())
                .formulation(Formulation::Partitioning)
                .integrator(method)
                .tolerances(rtol, atol)
                .output_times(&[])
                .run(t_end)
                .map_err(|e| {
                    failed(format!(
                        "the reference run of `{}` failed: {}",
                        entry.name, e.kind
                    ))
                })?;
            (
                Reference::from_run(&run),
                format!(
                    "a run at rtol {rtol:e}, atol {atol:e} (partitioning + {})",
                    method.name()
                ),
            )
        }
    };
    let mut sweep = Sweep::standard(t_end);
    if entry.stiff && !args.all_methods {
        sweep.methods = vec![Method::Radau5];
        sweep.rtols = (3..=9).map(|k| 10f64.powi(-k)).collect();
    }
    let rows = work_precision(model.as_ref(), &sweep, &reference);
    out::line(format_args!(
        "work-precision of {} over [0, {}] s; error = largest |final q, q' - reference| over the largest |q|, |q'| of the reference (at least 1), reference: {source}",
        entry.name,
        super::time(t_end)
    ))?;
    if entry.stiff && !args.all_methods {
        out::line(format_args!(
            "stiff model: radau5 only (the explicit methods are held to their stability limit; --all-methods sweeps them too)"
        ))?;
    }
    if !reference.impacts.is_empty() {
        out::line(format_args!(
            "t_impact = largest |impact time - closed form| over the {} impacts of the span [s]",
            reference.impacts.len()
        ))?;
    }
    out::print(&format_table(&rows))?;
    // Each file is written on its own: a failure to write one is reported and does not
    // keep the other from being written.
    let mut failures = Vec::new();
    if let Some(path) = &args.csv {
        match write_csv(&rows, path) {
            Ok(()) => out::line(format_args!("table  {}", path.display()))?,
            Err(e) => failures.push(e),
        }
    }
    if let Some(path) = &args.plot {
        match plot::work_precision(entry.name, t_end, &rows, path) {
            Ok(()) => out::line(format_args!("plot   {}", path.display()))?,
            Err(e) => failures.push(e),
        }
    }
    out::failures(failures)
}

/// Writes the table of `rows` as CSV to `path` (atomically).
fn write_csv(rows: &[pfaff::sim::Row], path: &std::path::Path) -> Result<(), CliError> {
    out::write_file(path, |file| {
        let mut w = csv::Writer::from_writer(file);
        w.write_record([
            "formulation",
            "method",
            "rtol",
            "error",
            "impact_time_error",
            "rhs_evals",
            "steps",
            "jacobians",
            "repartitions",
            "wall_seconds",
            "failure",
        ])?;
        for r in rows {
            w.write_record([
                r.formulation.name().to_owned(),
                r.method.name().to_owned(),
                r.rtol.to_string(),
                r.error.to_string(),
                r.impact_error.map(|e| e.to_string()).unwrap_or_default(),
                r.rhs_evals.to_string(),
                r.steps.to_string(),
                r.jacobians.to_string(),
                r.repartitions.to_string(),
                r.wall_time.as_secs_f64().to_string(),
                r.failure.clone().unwrap_or_default(),
            ])?;
        }
        w.flush()
    })
}
