//! `pfaff simulate` and the default scene: run a simulation, then report it as a short
//! summary or one JSON object, and optionally as CSV rows and an SVG plot.

use std::fmt::Write as _;
use std::path::Path;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use pfaff::sim::{min_step, Formulation, Method, Run, SimError, SimErrorKind, Simulation};
use pfaff::{Mechanism, MechanismExt};
use serde_json::{json, Map, Value};

use super::args::{FormulationArg, IntegratorArg, SimulateArgs};
use super::error::{failed, usage, CliError};
use super::scene::Scene;
use super::{animate, impacts, out, outputs, plot, setup};
use crate::Entry;

/// A validated simulation request.
pub struct Request<'a> {
    pub args: &'a SimulateArgs,
    pub t_end: f64,
    pub formulation: Formulation,
    pub method: Method,
    /// The step size of `--step`, raised to what the span resolves.
    pub step: Option<f64>,
    /// Notes on input that was changed (a step raised).
    pub notes: Vec<String>,
}

fn formulation(f: FormulationArg) -> Formulation {
    match f {
        FormulationArg::Partitioning => Formulation::Partitioning,
        FormulationArg::Projection => Formulation::Projection,
        FormulationArg::Baumgarte => Formulation::baumgarte(),
    }
}

/// Most output intervals of `--samples`: the written record and the plot grow with it
/// (2×10⁷ samples with `--plot` took 3.3 GB).
const MAX_SAMPLES: usize = 1_000_000;

fn positive(flag: &str, v: f64) -> Result<(), CliError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(usage(format!(
            "invalid {flag} {v}: expected a positive finite number"
        )))
    }
}

/// Checks the numbers of `args` and picks the defaults.
/// A stiff model (`Entry::stiff`) defaults to Radau5, the others to Adams.
pub fn request<'a>(
    args: &'a SimulateArgs,
    scene: &Scene,
    stiff: bool,
) -> Result<Request<'a>, CliError> {
    positive("--rtol", args.rtol)?;
    if args.rtol > 1.0 {
        return Err(usage(format!(
            "invalid --rtol {:e}: expected at most 1 (a larger relative tolerance asks for no correct digit)",
            args.rtol
        )));
    }
    positive("--atol", args.atol)?;
    let t_end = args.t_end.unwrap_or(scene.t_end);
    if !t_end.is_finite() || t_end < 0.0 {
        let what = if t_end < 0.0 {
            "is before the start time 0"
        } else {
            "is not a finite time"
        };
        return Err(usage(format!(
            "--t-end {} {what}: expected a finite end time, at least 0 (0 analyses the initial state)",
            super::time(t_end)
        )));
    }
    let mut notes = Vec::new();
    if let Some(h) = args.step {
        positive("--step", h)?;
    }
    let step = args.step.map(|h| {
        // A zero span takes no step; the floor is then that of a unit span.
        let min = min_step(0.0, if t_end > 0.0 { t_end } else { 1.0 });
        if h < min {
            notes.push(format!(
                "--step {h:e} is below the smallest step the time resolves over [0, {}] s: {min:e} was used",
                super::time(t_end)
            ));
        }
        if t_end > 0.0 && h > t_end {
            notes.push(format!(
                "--step {h:e} is longer than the span [0, {}] s: the first step is the span",
                super::time(t_end)
            ));
        }
        h.max(min)
    });
    if args.rtol < 4.0 * f64::EPSILON {
        notes.push(format!(
            "--rtol {:e} is below what double precision resolves (about 1e-15 relative): the run's error is set by round-off, not by the tolerance",
            args.rtol
        ));
    }
    if args.samples == 0 || args.samples > MAX_SAMPLES {
        return Err(usage(format!(
            "invalid --samples {}: expected 1 to {MAX_SAMPLES} (longer records are for the library's `Trajectory`)",
            args.samples
        )));
    }
    if args.repeat == 0 {
        return Err(usage("invalid --repeat 0: expected at least 1"));
    }
    let default = if stiff {
        IntegratorArg::Radau5
    } else {
        IntegratorArg::Adams
    };
    let method = match args.integrator.unwrap_or(default) {
        IntegratorArg::Rk4 => Method::Rk4 {
            h: step.unwrap_or(if t_end > 0.0 { t_end / 1000.0 } else { 1e-3 }),
        },
        IntegratorArg::Dopri5 => Method::Dopri5,
        IntegratorArg::Dop853 => Method::Dop853,
        IntegratorArg::Adams => Method::Adams,
        IntegratorArg::Radau5 => Method::Radau5,
    };
    Ok(Request {
        args,
        t_end,
        formulation: formulation(args.formulation),
        method,
        step,
        notes,
    })
}

/// A finished (or failed) simulation with what the reports need.
pub struct Outcome {
    pub run: Run,
    pub error: Option<SimErrorKind>,
    /// The wall time of the run, the best of `--repeat` runs.
    pub wall: Duration,
    pub notes: Vec<String>,
}

/// Accepted steps between two looks at the clock for the progress bar.
const PROGRESS_EVERY: u32 = 64;

/// Runs the simulation of `req` on `model`, `--repeat` times from the same initial
/// state: the outcome is the last run's, with the best wall time. A failed run ends the
/// repetitions.
pub fn run(model: &dyn Mechanism, req: &Request<'_>, dense: bool) -> Result<Outcome, CliError> {
    let init = setup::assemble(model, &req.args.state, &[], &[])?;
    // Parsed once for every repetition (outside the timed region, as before).
    let style =
        ProgressStyle::with_template("{spinner} t = {msg} s [{bar:40}] {percent}% ({elapsed})")
            .expect("valid template")
            .progress_chars("=> ");
    let (mut result, mut wall) = run_once(model, req, &init.q, &init.qd, dense, &style);
    for _ in 1..req.args.repeat {
        if result.is_err() {
            break;
        }
        let (next, elapsed) = run_once(model, req, &init.q, &init.qd, dense, &style);
        result = next;
        wall = wall.min(elapsed);
    }
    let (run, error) = match result {
        Ok(run) => (run, None),
        Err(e) => (*e.partial, Some(e.kind)),
    };
    Ok(Outcome {
        run,
        error,
        wall,
        notes: req.notes.iter().cloned().chain(init.notes).collect(),
    })
}

/// One run from `(q0, qd0)` and its wall time: the simulation's own, from building it
/// (with its assembly of the given state and its setup) to the end of its run; the
/// progress bar's creation is outside it.
fn run_once(
    model: &dyn Mechanism,
    req: &Request<'_>,
    q0: &[f64],
    qd0: &[f64],
    dense: bool,
    style: &ProgressStyle,
) -> (Result<Run, SimError>, Duration) {
    let bar = ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::stderr());
    bar.set_style(style.clone());
    let start = Instant::now();
    let t_end = req.t_end;
    let shown = bar.clone();
    let mut calls = 0_u32;
    let mut sim = Simulation::new(model)
        .formulation(req.formulation)
        .integrator(req.method)
        .tolerances(req.args.rtol, req.args.atol)
        .initial_state(q0, qd0)
        .on_progress(move |t| {
            // Only runs that last show a bar (indicatif hides it when stderr is not a
            // terminal). The clock is read every PROGRESS_EVERY steps, not on every
            // step: a step costs a few microseconds, a clock read up to a tenth of that.
            calls = calls.wrapping_add(1);
            if calls % PROGRESS_EVERY == 0 && start.elapsed() > Duration::from_millis(300) {
                shown.set_message(format!("{t:.4e}"));
                shown.set_position((t / t_end * 1000.0) as u64);
            }
        });
    if let (Some(h), false) = (req.step, matches!(req.method, Method::Rk4 { .. })) {
        sim = sim.initial_step(h);
    }
    sim = if dense && t_end > 0.0 {
        let samples = if req.args.animate.is_some() {
            animate::grid(req.args.samples, t_end)
        } else {
            req.args.samples
        };
        sim.output_every(t_end / samples as f64)
    } else if !model.info().outputs.is_empty() {
        // The range of the outputs along the run is taken over the recorded rows.
        sim.output_steps()
    } else {
        sim.output_times(&[])
    };
    let result = sim.run(t_end);
    drop(sim);
    bar.finish_and_clear();
    (result, start.elapsed())
}

/// The `kind` of a failure in the JSON report.
fn kind_name(kind: &SimErrorKind) -> &'static str {
    match kind {
        SimErrorKind::InvalidTimes { .. } => "invalid_times",
        SimErrorKind::InitialLength { .. } => "initial_length",
        SimErrorKind::Assembly(_) => "assembly",
        SimErrorKind::InitialPenetration { .. } => "initial_penetration",
        SimErrorKind::NegativeMass { .. } => "negative_mass",
        SimErrorKind::NewtonFailed { .. } => "newton_failed",
        SimErrorKind::Singular { .. } => "singular",
        SimErrorKind::SingularMass { .. } => "singular_mass",
        SimErrorKind::StepSizeTooSmall { .. } => "step_size_too_small",
        SimErrorKind::MaxSteps { .. } => "max_steps",
        SimErrorKind::Diverged { .. } => "diverged",
        SimErrorKind::SingularConfiguration { .. } => "singular_configuration",
        SimErrorKind::BaumgarteUnstable { .. } => "baumgarte_unstable",
        SimErrorKind::NoProgress { .. } => "no_progress",
        SimErrorKind::NonFinite { .. } => "non_finite",
        SimErrorKind::Analysis(_) => "analysis",
        SimErrorKind::Integrator(_) => "integrator",
        SimErrorKind::Impact(_) => "impact",
    }
}

fn named(names: impl Iterator<Item = &'static str>, values: &[f64]) -> Value {
    Value::Object(
        names
            .zip(values)
            .map(|(n, &v)| (n.to_owned(), json!(v)))
            .collect::<Map<_, _>>(),
    )
}

/// Energies at the first and last rows, when the model conserves energy.
fn energies(model: &dyn Mechanism, run: &Run) -> Option<(f64, f64)> {
    let m = &run.monitors;
    match (m.energy_initial, m.energy_final) {
        (Some(a), Some(b)) => Some((a, b)),
        _ if model.info().conservative && !run.trajectory.is_empty() => {
            let tr = &run.trajectory;
            let last = tr.len() - 1;
            Some((
                model.energy(tr.t[0], tr.q(0), tr.qd(0)),
                model.energy(tr.t[last], tr.q(last), tr.qd(last)),
            ))
        }
        _ => None,
    }
}

/// The reactions of the joints as JSON: per joint its kind, the wrench on its first
/// frame (force and torque about the frame's origin, global and body axes; `null` for a
/// driver, which has no frames), the fit's relative residual and the number of wrench
/// components the multipliers determine.
fn joints_json(r: &pfaff::JointReactions) -> Value {
    Value::Object(
        r.iter()
            .map(|j| {
                let wrench = j.first.map_or(Value::Null, |w| {
                    json!({
                        "force": w.force,
                        "torque": w.torque,
                        "force_body": w.force_body,
                        "torque_body": w.torque_body,
                    })
                });
                let v = json!({
                    "kind": format!("{:?}", j.kind),
                    "first": wrench,
                    "residual": j.residual,
                    "rank": j.rank,
                    "components": j.components,
                });
                (j.name.to_owned(), v)
            })
            .collect::<Map<_, _>>(),
    )
}

/// The JSON report (see the README for its keys).
pub fn json_report(model: &dyn Mechanism, req: &Request<'_>, out: &Outcome) -> Value {
    let info = model.info();
    let run = &out.run;
    let constraints = info
        .holonomic
        .iter()
        .chain(info.nonholonomic)
        .map(|s| s.name);
    let last = run.trajectory.len().checked_sub(1);
    let output_names = || info.outputs.iter().map(|s| s.name);
    let final_ = last.map_or(Value::Null, |i| {
        let tr = &run.trajectory;
        let (t, q, qd) = (tr.t[i], tr.q(i), tr.qd(i));
        let qdd = outputs::accelerations(model, t, q, qd).map_or(Value::Null, |a| {
            named(info.coordinates.iter().map(|s| s.name), &a)
        });
        let joints = outputs::joint_reactions(model, t, q, tr.lambda(i))
            .map_or(Value::Null, |r| joints_json(&r));
        json!({
            "t": t,
            "q": named(info.coordinates.iter().map(|s| s.name), q),
            "qd": named(info.coordinates.iter().map(|s| s.name), qd),
            "qdd": qdd,
            "lambda": named(constraints, tr.lambda(i)),
            "joints": joints,
            "outputs": named(output_names(), &outputs::values(model, t, q, qd)),
        })
    });
    let rows = outputs::along(model, run);
    let ranges = outputs::ranges(&rows, info.outputs.len()).unwrap_or_default();
    let output_ranges = Value::Object(
        output_names()
            .zip(ranges)
            .map(|(n, (lo, hi))| (n.to_owned(), json!({"min": lo, "max": hi})))
            .collect::<Map<_, _>>(),
    );
    let s = &run.stats;
    let m = &run.monitors;
    let mut obj = json!({
        "model": info.name,
        "formulation": req.formulation.name(),
        "integrator": req.method.name(),
        "rtol": req.args.rtol,
        "atol": req.args.atol,
        "t_end": req.t_end,
        "final": final_,
        "outputs": output_ranges,
        "stats": {
            "steps": s.steps,
            "rejected": s.rejected,
            "rhs_evals": s.rhs_evals,
            "newton_iterations": s.newton_iterations,
            "factorizations": s.factorizations,
            "output_newton_iterations": s.output_newton_iterations,
            "output_factorizations": s.output_factorizations,
            "repartitions": s.repartitions,
            "jacobians": s.jacobians,
            "stage_factorizations": s.stage_factorizations,
            "stage_newton_iterations": s.stage_newton_iterations,
        },
        "max_violation": {
            "position": m.max_position_violation,
            "velocity": m.max_velocity_violation,
            "nonholonomic": m.max_nonholonomic_violation,
        },
        "energy": energies(model, run).map_or(Value::Null, |(a, b)| json!({"initial": a, "final": b, "lost_in_impacts": m.energy_lost_in_impacts})),
        "wall_seconds": out.wall.as_secs_f64(),
        "impacts": impacts::json(info, run),
        "contact_events": impacts::events_json(run),
    });
    if let Some(kind) = &out.error {
        // The rest of the object is the partial run; `stopped_at` is the time of its
        // last state (`final`), `t` the time the failure is tied to.
        obj["error"] = json!({
            "kind": kind_name(kind),
            "message": kind.to_string(),
            "t": kind.t(),
            "stopped_at": run.final_state().map(|f| f.0),
        });
    }
    obj
}

/// The human summary.
pub fn summary(model: &dyn Mechanism, req: &Request<'_>, entry: &Entry, out: &Outcome) -> String {
    let info = model.info();
    let run = &out.run;
    let (s, m) = (&run.stats, &run.monitors);
    let mut w = String::new();
    let _ = writeln!(w, "{}: {}", info.name, entry.description(model));
    // Redundant constraints (found by the run) remove no degree of freedom.
    let rank = info.nh() - run.redundant_constraints.len().min(info.nh());
    let dof = info.nq() - rank.min(info.nq());
    let dof = dof - info.nnh().min(dof);
    let _ = writeln!(
        w,
        "  {} coordinates, {} holonomic and {} non-holonomic constraints ({dof} degree{} of freedom)",
        info.nq(),
        info.nh(),
        info.nnh(),
        if dof == 1 { "" } else { "s" }
    );
    if !run.trajectory.is_empty() {
        w.push_str(&super::split::describe(
            model,
            run.trajectory.t[0],
            run.trajectory.q(0),
            "  ",
        ));
    }
    let tol = match req.method {
        // RK4 halves an attempt whose evaluation failed recoverably (a Newton failure of
        // the chart); the next step has the nominal size again.
        Method::Rk4 { h } if s.rejected > 0 => format!(
            "fixed step {h:e} s ({} attempt{} halved after a failed evaluation)",
            s.rejected,
            if s.rejected == 1 { "" } else { "s" }
        ),
        Method::Rk4 { h } => format!("fixed step {h:e} s"),
        _ => format!("rtol {:e}, atol {:e}", req.args.rtol, req.args.atol),
    };
    let span = if req.args.t_end.is_some() {
        ""
    } else {
        entry.scene.span
    };
    let _ = writeln!(
        w,
        "method       {} + {}, {tol}",
        req.formulation.name(),
        req.method.name()
    );
    let reached = run.final_state().map_or(0.0, |f| f.0);
    let _ = writeln!(
        w,
        "span         0 to {} s{}{}",
        super::time(req.t_end),
        if span.is_empty() {
            String::new()
        } else {
            format!(" ({span})")
        },
        if out.error.is_some() {
            format!(", stopped at {} s", super::time(reached))
        } else {
            String::new()
        }
    );
    let _ = writeln!(
        w,
        "work         {} steps ({} rejected), {} rhs evaluations, {} Newton iterations, {} factorizations, {} re-partitions",
        s.steps, s.rejected, s.rhs_evals, s.newton_iterations, s.factorizations, s.repartitions
    );
    if s.output_factorizations > 0 {
        let rows = run.trajectory.len();
        let _ = writeln!(
            w,
            "output rows  {rows} rows, {} Newton iterations, {} factorizations (their corrections onto the constraints and multipliers, apart from the integration's)",
            s.output_newton_iterations, s.output_factorizations
        );
    }
    if s.jacobians > 0 {
        let _ = writeln!(
            w,
            "implicit     {} Jacobians, {} factorizations, {} Newton iterations of the stages",
            s.jacobians, s.stage_factorizations, s.stage_newton_iterations
        );
    }
    let _ = writeln!(w, "wall time    {:.3} ms", out.wall.as_secs_f64() * 1e3);
    let _ = writeln!(
        w,
        "violations   position {:.2e}, velocity {:.2e}{}",
        m.max_position_violation,
        m.max_velocity_violation,
        if info.nnh() > 0 {
            format!(", non-holonomic {:.2e}", m.max_nonholonomic_violation)
        } else {
            String::new()
        }
    );
    match (energies(model, run), m.max_energy_drift) {
        (Some((a, b)), drift) => {
            // The drift of the integration: the impacts' losses set apart.
            let lost = m.energy_lost_in_impacts;
            let in_impacts = if lost != 0.0 {
                format!(", {lost:.10e} J lost in impacts")
            } else {
                String::new()
            };
            let _ = writeln!(
                w,
                "energy       {a:.10e} -> {b:.10e} J{in_impacts}, drift {:.2e} (largest {:.2e})",
                b - a + lost,
                drift.unwrap_or((b - a + lost).abs())
            );
        }
        (None, _) => {
            let _ = writeln!(w, "energy       {}", no_energy(info, run));
        }
    }
    impacts::summary(info, run, &mut w);
    match run.final_state() {
        Some((t, q, qd)) => {
            let list: Vec<String> = info
                .coordinates
                .iter()
                .zip(q.iter().zip(qd))
                .map(|(c, (v, vd))| format!("{} = {v:.6} ({}' = {vd:.6})", c.name, c.name))
                .collect();
            let label = if out.error.is_some() {
                "stopped at  "
            } else {
                "final       "
            };
            let _ = writeln!(w, "{label} t = {}: {}", super::time(t), list.join(", "));
        }
        None => {
            let _ = writeln!(
                w,
                "stopped at   the start: no consistent state was computed"
            );
        }
    }
    if let Some(i) = run.trajectory.len().checked_sub(1) {
        let tr = &run.trajectory;
        if let Some(r) = outputs::joint_reactions(model, tr.t[i], tr.q(i), tr.lambda(i)) {
            let _ = writeln!(
                w,
                "joints       force [N] and torque [N m] on the first frame, about its origin, global axes, at the last state"
            );
            for j in r.iter() {
                match j.first {
                    Some(f) => {
                        let _ = writeln!(
                            w,
                            "  {:<12} F = ({:.6e}, {:.6e}, {:.6e})  T = ({:.6e}, {:.6e}, {:.6e})",
                            j.name,
                            f.force[0],
                            f.force[1],
                            f.force[2],
                            f.torque[0],
                            f.torque[1],
                            f.torque[2]
                        );
                    }
                    None => {
                        let _ = writeln!(
                            w,
                            "  {:<12} no frames (a driver): see lambda in --json",
                            j.name
                        );
                    }
                }
            }
        }
    }
    if let (Some((t, q, qd)), true) = (run.final_state(), req.t_end == 0.0) {
        // The initial state analysed: its accelerations.
        let line = match outputs::accelerations(model, t, q, qd) {
            Ok(a) => info
                .coordinates
                .iter()
                .zip(a)
                .map(|(c, v)| format!("{}'' = {v:.6}", c.name))
                .collect::<Vec<_>>()
                .join(", "),
            Err(e) => format!("not computed: {e}"),
        };
        let _ = writeln!(w, "accelerations {line}");
    }
    if let (Some((t, q, qd)), false) = (run.final_state(), info.outputs.is_empty()) {
        let finals = outputs::values(model, t, q, qd);
        let rows = outputs::along(model, run);
        let ranges = outputs::ranges(&rows, finals.len()).unwrap_or_default();
        let _ = writeln!(
            w,
            "outputs      final value (smallest, largest along the run)"
        );
        for ((s, v), (lo, hi)) in info.outputs.iter().zip(&finals).zip(ranges) {
            let _ = writeln!(w, "  {:<12} {v:.9e} ({lo:.6e}, {hi:.6e})", s.name);
        }
    }
    w
}

/// Why the summary reports no energy.
fn no_energy(model: &pfaff::Info, run: &Run) -> &'static str {
    let t = model.time;
    if model.conservative {
        if run.trajectory.is_empty() {
            "not computed: the run stopped before its first state"
        } else {
            "not computed"
        }
    } else if t.mass || t.forces || t.holonomic || t.nonholonomic {
        "not conserved (the model depends explicitly on time): no drift to report"
    } else {
        "not conserved (applied forces, or kinetic energy terms linear in the velocities): no drift to report"
    }
}

/// Writes the CSV of the trajectory: `t`, the coordinates, the velocities (`NAME'`),
/// the model's named outputs, the multipliers (`lambda_NAME`), `position_violation`,
/// `velocity_violation` and `energy` (atomically: see [`out::write_file`]).
pub fn write_csv(model: &dyn Mechanism, run: &Run, path: &Path) -> Result<(), CliError> {
    let info = model.info();
    out::write_file(path, |file| {
        let mut w = csv::Writer::from_writer(file);
        let mut header = vec!["t".to_owned()];
        header.extend(info.coordinates.iter().map(|c| c.name.to_owned()));
        header.extend(info.coordinates.iter().map(|c| format!("{}'", c.name)));
        header.extend(info.outputs.iter().map(|c| c.name.to_owned()));
        header.extend(
            info.holonomic
                .iter()
                .chain(info.nonholonomic)
                .map(|c| format!("lambda_{}", c.name)),
        );
        header.extend(["position_violation", "velocity_violation", "energy"].map(String::from));
        w.write_record(&header)?;
        let tr = &run.trajectory;
        for i in 0..tr.len() {
            let mut rec: Vec<String> = vec![tr.t[i].to_string()];
            rec.extend(tr.q(i).iter().map(f64::to_string));
            rec.extend(tr.qd(i).iter().map(f64::to_string));
            rec.extend(
                outputs::values(model, tr.t[i], tr.q(i), tr.qd(i))
                    .iter()
                    .map(f64::to_string),
            );
            rec.extend(tr.lambda(i).iter().map(f64::to_string));
            rec.push(tr.position_violation[i].to_string());
            rec.push(tr.velocity_violation[i].to_string());
            rec.push(model.energy(tr.t[i], tr.q(i), tr.qd(i)).to_string());
            w.write_record(&rec)?;
        }
        w.flush()
    })
}

/// `pfaff simulate`.
pub fn command(models: &[Entry], args: &SimulateArgs) -> Result<(), CliError> {
    let entry = setup::find_model(models, &args.model)?;
    let model = setup::build(entry, &args.state.set)?;
    let req = request(args, &entry.scene, entry.stiff)?;
    let dense = args.csv.is_some() || args.plot.is_some() || args.animate.is_some();
    let out = run(model.as_ref(), &req, dense)?;
    report(model.as_ref(), &req, entry, &out)
}

/// Prints the report of `out` and writes the requested files. With `--json` the one
/// object on stdout carries the first failure (of the run, else of a file).
///
/// Each file is written on its own (atomically, see [`out::write_file`]): a failure to
/// write one is reported on stderr and does not keep the others from being written. A
/// run that stopped before its first state writes no file, so that files of an earlier
/// run are left as they were.
pub fn report(
    model: &dyn Mechanism,
    req: &Request<'_>,
    entry: &Entry,
    out: &Outcome,
) -> Result<(), CliError> {
    let args = req.args;
    let requested = [
        ("trajectory", &args.csv),
        ("plot", &args.plot),
        ("animation", &args.animate),
    ];
    let mut written: Vec<(&str, &Path)> = Vec::new();
    let mut failures = Vec::new();
    let mut notes = out.notes.clone();
    if out.run.trajectory.is_empty() {
        if requested.iter().any(|(_, p)| p.is_some()) {
            notes.push(
                "no file written: the run computed no state (existing files are left as they were)"
                    .to_owned(),
            );
        }
    } else {
        for (what, path) in requested {
            let Some(path) = path else { continue };
            let result = match what {
                "trajectory" => write_csv(model, &out.run, path),
                "plot" => plot::trajectory(model, &out.run, path),
                _ => animate::write(model, &out.run, animation_meta(req, out), path),
            };
            match result {
                Ok(()) => written.push((what, path)),
                Err(e) => failures.push(e),
            }
        }
    }
    let files = out::failures(failures);
    let result = match (&out.error, files) {
        (Some(kind), files) => {
            if let Err(e) = files {
                out::error_line(&format!("pfaff: error: {e}"));
            }
            Err(failed(format!(
                "simulation of `{}` failed: {kind}",
                model.info().name
            ))
            .kind(kind_name(kind)))
        }
        (None, files) => files,
    };
    if args.json {
        let mut obj = json_report(model, req, out);
        if let (Err(e), None) = (&result, &out.error) {
            obj["error"] = e.entry();
        }
        out::line(format_args!("{obj}"))?;
        for note in &notes {
            out::error_line(&format!("pfaff: note: {note}"));
        }
        return result.map_err(CliError::reported);
    }
    let mut text = summary(model, req, entry, out);
    for note in &notes {
        let _ = writeln!(text, "note         {note}");
    }
    for (what, path) in written {
        let _ = writeln!(text, "{what:<12} {}", path.display());
    }
    out::print(&text)?;
    result
}

/// How the run was made, for the `run` object of the animation's trajectory.
fn animation_meta(req: &Request<'_>, out: &Outcome) -> Map<String, Value> {
    let mut m = Map::new();
    m.insert("formulation".into(), json!(req.formulation.name()));
    m.insert("integrator".into(), json!(req.method.name()));
    m.insert("rtol".into(), json!(req.args.rtol));
    m.insert("atol".into(), json!(req.args.atol));
    m.insert("t_end".into(), json!(req.t_end));
    m.insert("steps".into(), json!(out.run.stats.steps));
    m.insert("repartitions".into(), json!(out.run.stats.repartitions));
    if let Some(kind) = &out.error {
        m.insert("error".into(), json!(kind.to_string()));
    }
    m
}
