//! Work-precision sweeps: final error against work for every formulation × integrator
//! over a range of tolerances.
//!
//! Input: a mechanism, a [`Sweep`] and a [`Reference`] (named coordinates and velocities
//! at the end time). Output: one [`Row`] per run, failed runs included, and a plain-text
//! table ([`format_table`]). The command-line program reuses both.

use std::fmt::Write as _;
use std::time::Duration;

use super::{Formulation, Method, Run, Simulation};
use crate::Mechanism;

/// Reference values at the end time, by coordinate name.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Reference {
    /// `(coordinate, value)`.
    pub coordinates: Vec<(String, f64)>,
    /// `(coordinate, velocity)`.
    pub velocities: Vec<(String, f64)>,
    /// `(contact, time)` of the impacts from the start, in time order, for models with
    /// impacts whose times are known (a closed form); empty: not measured.
    pub impacts: Vec<(String, f64)>,
}

impl Reference {
    /// All coordinates and velocities of the final row of `run`.
    #[must_use]
    pub fn from_run(run: &Run) -> Self {
        let info = run.trajectory.info();
        let Some((_, q, qd)) = run.final_state() else {
            return Self::default();
        };
        let named = |v: &[f64]| {
            info.coordinates
                .iter()
                .zip(v)
                .map(|(s, &x)| (s.name.to_owned(), x))
                .collect()
        };
        Self {
            coordinates: named(q),
            velocities: named(qd),
            impacts: Vec::new(),
        }
    }

    /// The largest error of the impact times of `run` against [`impacts`](Self::impacts):
    /// the `k`-th reference impact of a contact is compared with the `k`-th strike of
    /// that contact in the run. A reference impact the run does not have is compared
    /// with the time the run's contact came to rest, if it did before it (the run
    /// merged the last bounces of an accumulation into the rest: a fixed-step RK4 does
    /// so a few short flights early, and the error is how early), and is otherwise an
    /// infinite error (a missed impact). Strikes after the listed ones are not compared
    /// (a closed form lists the impacts it can resolve: the accumulating bounces of a
    /// ball are finitely many to a run). `None` when there is nothing to compare.
    #[must_use]
    pub fn impact_time_error(&self, run: &Run) -> Option<f64> {
        if self.impacts.is_empty() {
            return None;
        }
        let mut err = 0.0_f64;
        let mut seen: Vec<(&str, usize)> = Vec::new();
        for (name, t) in &self.impacts {
            let k = match seen.iter_mut().find(|(n, _)| n == name) {
                Some((_, k)) => {
                    *k += 1;
                    *k
                }
                None => {
                    seen.push((name, 0));
                    0
                }
            };
            let found = run
                .impacts
                .iter()
                .filter(|i| i.names.contains(&name.as_str()))
                .nth(k);
            let rest = || {
                run.contact_events.iter().find(|e| {
                    e.contact == name.as_str()
                        && matches!(e.kind, super::ContactEventKind::Rest)
                        && e.t <= *t
                })
            };
            // The strike, or else the rest that took its place (looked for only then).
            match found.map(|i| i.t).or_else(|| rest().map(|e| e.t)) {
                Some(at) => err = err.max((at - t).abs()),
                None => return Some(f64::INFINITY),
            }
        }
        Some(err)
    }

    /// The error of the final row of `run`: the largest difference from the reference
    /// values, positions and velocities each relative to the largest magnitude of their
    /// kind in the reference (at least 1), so that fast velocities (`andrews` turns at
    /// about 1,000 rad/s) do not hide the positions' error and the figure reads against
    /// rtol. `NaN` for an unknown name or an empty run.
    #[must_use]
    pub fn error(&self, run: &Run) -> f64 {
        let info = run.trajectory.info();
        let Some((_, q, qd)) = run.final_state() else {
            return f64::NAN;
        };
        let mut err = 0.0_f64;
        for (list, v) in [(&self.coordinates, q), (&self.velocities, qd)] {
            let scale = list.iter().fold(1.0_f64, |a, (_, x)| a.max(x.abs()));
            for (name, x) in list {
                match info.coordinate_index(name) {
                    Some(j) => err = err.max((v[j] - x).abs() / scale),
                    None => return f64::NAN,
                }
            }
        }
        err
    }
}

/// What to sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    /// End time (the start is 0, from the model's initial state).
    pub t_end: f64,
    /// Relative tolerances; `atol = rtol × atol_ratio`. For RK4 the fixed step is
    /// $h = t_\text{end}\,\text{rtol}^{1/4}/10$.
    pub rtols: Vec<f64>,
    /// `atol / rtol`.
    pub atol_ratio: f64,
    /// Formulations.
    pub formulations: Vec<Formulation>,
    /// Integrators (the step of [`Method::Rk4`] is replaced as said above).
    pub methods: Vec<Method>,
}

impl Sweep {
    /// rtol = 1e-3 … 1e-12 by decades, atol = rtol/100, every formulation and method.
    #[must_use]
    pub fn standard(t_end: f64) -> Self {
        Self {
            t_end,
            rtols: (3..=12).map(|k| 10f64.powi(-k)).collect(),
            atol_ratio: 1e-2,
            formulations: Formulation::ALL.to_vec(),
            methods: vec![
                Method::Rk4 { h: 0.0 },
                Method::Dopri5,
                Method::Dop853,
                Method::Adams,
                Method::Radau5,
            ],
        }
    }
}

/// One run of a sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// Formulation.
    pub formulation: Formulation,
    /// Integrator (with the step actually used for RK4).
    pub method: Method,
    /// Relative tolerance.
    pub rtol: f64,
    /// Final error against the reference, relative ([`Reference::error`]; `NaN` when
    /// the run failed).
    pub error: f64,
    /// Largest error of the impact times against the reference's
    /// ([`Reference::impact_time_error`]); `None` when the reference has none.
    pub impact_error: Option<f64>,
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
    /// Accepted steps.
    pub steps: u64,
    /// Jacobians formed by an implicit integrator (their evaluations are in `rhs_evals`).
    pub jacobians: u64,
    /// Re-partitions.
    pub repartitions: u64,
    /// Wall-clock time.
    pub wall_time: Duration,
    /// The error message of a failed run.
    pub failure: Option<String>,
}

/// Runs every formulation × method × tolerance of `sweep` on `mech` from its initial
/// state and measures the final error against `reference`.
pub fn work_precision<M: Mechanism + ?Sized>(
    mech: &M,
    sweep: &Sweep,
    reference: &Reference,
) -> Vec<Row> {
    let mut rows = Vec::new();
    for &formulation in &sweep.formulations {
        for &method in &sweep.methods {
            for &rtol in &sweep.rtols {
                let method = match method {
                    Method::Rk4 { .. } => Method::Rk4 {
                        h: sweep.t_end * rtol.powf(0.25) / 10.0,
                    },
                    m => m,
                };
                let result = Simulation::new(mech)
                    .formulation(formulation)
                    .integrator(method)
                    .tolerances(rtol, rtol * sweep.atol_ratio)
                    .output_times(&[])
                    .run(sweep.t_end);
                let (run, failure) = match result {
                    Ok(run) => (run, None),
                    Err(e) => {
                        let msg = e.kind.to_string();
                        (*e.partial, Some(msg))
                    }
                };
                rows.push(Row {
                    formulation,
                    method,
                    rtol,
                    error: if failure.is_some() {
                        f64::NAN
                    } else {
                        reference.error(&run)
                    },
                    impact_error: reference.impact_time_error(&run).map(|e| {
                        if failure.is_some() {
                            f64::NAN
                        } else {
                            e
                        }
                    }),
                    rhs_evals: run.stats.rhs_evals,
                    steps: run.stats.steps,
                    jacobians: run.stats.jacobians,
                    repartitions: run.stats.repartitions,
                    wall_time: run.stats.wall_time,
                    failure,
                });
            }
        }
    }
    rows
}

/// A plain-text table of `rows`, one line each.
#[must_use]
pub fn format_table(rows: &[Row]) -> String {
    let mut s = String::new();
    // The impact-time column only for sweeps that measure it.
    let impacts = rows.iter().any(|r| r.impact_error.is_some());
    let _ = write!(
        s,
        "{:<13} {:<7} {:>8} {:>10}",
        "formulation", "method", "rtol", "error"
    );
    if impacts {
        let _ = write!(s, " {:>10}", "t_impact");
    }
    let _ = writeln!(
        s,
        " {:>9} {:>8} {:>6} {:>6} {:>11}",
        "rhs", "steps", "jac", "repart", "wall [ms]"
    );
    for r in rows {
        let _ = write!(
            s,
            "{:<13} {:<7} {:>8.0e} {:>10.2e}",
            r.formulation.name(),
            r.method.name(),
            r.rtol,
            r.error,
        );
        if impacts {
            let _ = write!(s, " {:>10.2e}", r.impact_error.unwrap_or(f64::NAN));
        }
        let _ = write!(
            s,
            " {:>9} {:>8} {:>6} {:>6} {:>11.3}",
            r.rhs_evals,
            r.steps,
            r.jacobians,
            r.repartitions,
            r.wall_time.as_secs_f64() * 1e3
        );
        if let Some(f) = &r.failure {
            let _ = write!(s, "  FAILED: {f}");
        }
        s.push('\n');
    }
    s
}
