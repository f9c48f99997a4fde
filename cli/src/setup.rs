//! From names on the command line to a configured model and a consistent initial
//! state.
//!
//! Input: a model name, `--set`, `--q0`, `--qd0`. Output: the model with its parameters
//! set, and $(q, \dot q)$ satisfying the constraints with the given values held.
//! A coordinate given with `--q0` that the constraints must determine (both `x` and `y`
//! of a pendulum, say) is used as the starting guess of Newton's method instead of
//! being held; a note says so when the value moved. The non-zero initial velocities
//! declared by the model (`qd0`) are held where the constraints allow it; one that the
//! constraints determine from the others gets a note with the value used.

use crate::Entry;
use pfaff::{
    AssemblyError, Kinematics, KinematicsParams, Mechanism, PartitionError, PartitionParams,
};
use pfaff::{Prescription, Workspace};

use super::args::{Assignment, StateArgs};
use super::error::{failed, suggestion, usage, CliError};

/// The model of `models` called `name`.
pub fn find_model<'a>(models: &'a [Entry], name: &str) -> Result<&'a Entry, CliError> {
    models.iter().find(|e| e.name == name).ok_or_else(|| {
        let hint = suggestion(name, models.iter().map(|e| e.name));
        usage(format!(
            "unknown model `{name}`{hint} (`pfaff list` shows the models)"
        ))
    })
}

/// Builds the model of `entry` with the parameters of `sets`.
pub fn build(entry: &Entry, sets: &[Assignment]) -> Result<Box<dyn Mechanism>, CliError> {
    let mut model = (entry.make)();
    let info = model.info();
    for a in sets {
        let i = info.parameter_index(&a.name).ok_or_else(|| {
            let names = info.parameters.iter().map(|p| p.name);
            let hint = suggestion(&a.name, names.clone());
            let list: Vec<&str> = names.collect();
            usage(if list.is_empty() {
                format!(
                    "unknown parameter `{}`: model `{}` has no parameters",
                    a.name, info.name
                )
            } else {
                format!(
                    "unknown parameter `{}` of model `{}`{hint} (parameters: {})",
                    a.name,
                    info.name,
                    list.join(", ")
                )
            })
        })?;
        model.set_parameter(i, a.value);
    }
    Ok(model)
}

/// Checks that every name of `list` is a coordinate of `model`.
fn check_coordinates(
    model: &dyn Mechanism,
    list: &[Assignment],
    flag: &str,
) -> Result<(), CliError> {
    let info = model.info();
    for a in list {
        if info.coordinate_index(&a.name).is_none() {
            let names = info.coordinates.iter().map(|c| c.name);
            let hint = suggestion(&a.name, names.clone());
            let all: Vec<&str> = names.collect();
            return Err(usage(format!(
                "unknown coordinate `{}` in {flag} for model `{}`{hint} (coordinates: {})",
                a.name,
                info.name,
                all.join(", ")
            )));
        }
    }
    let mut seen: Vec<&str> = Vec::new();
    for a in list {
        if seen.contains(&a.name.as_str()) {
            return Err(usage(format!(
                "coordinate `{}` is given twice in {flag}",
                a.name
            )));
        }
        seen.push(&a.name);
    }
    Ok(())
}

/// A consistent initial state.
#[derive(Debug)]
pub struct InitialState {
    /// Coordinates.
    pub q: Vec<f64>,
    /// Velocities.
    pub qd: Vec<f64>,
    /// Notes for the user (values used as guesses that moved).
    pub notes: Vec<String>,
}

/// Assembles $(q, \dot q)$ at $t = 0$ from the model's initial state, overridden by
/// `state.q0` / `state.qd0` (held) and `guesses` (starting values only).
pub fn assemble(
    model: &dyn Mechanism,
    state: &StateArgs,
    guesses: &[(&str, f64)],
    guess_velocities: &[(&str, f64)],
) -> Result<InitialState, CliError> {
    let info = model.info();
    check_coordinates(model, &state.q0, "--q0")?;
    check_coordinates(model, &state.qd0, "--qd0")?;
    let n = info.nq();
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q, &mut qd);
    if !guesses.is_empty() || !guess_velocities.is_empty() {
        // A steady motion is a complete operating point: the velocities it names, and
        // the others at rest or as its constraints make them, not the model's declared
        // initial velocities.
        qd.fill(0.0);
    }
    for &(name, v) in guesses {
        if let Some(i) = info.coordinate_index(name) {
            q[i] = v;
        }
    }
    for &(name, v) in guess_velocities {
        if let Some(i) = info.coordinate_index(name) {
            qd[i] = v;
        }
    }
    for a in &state.q0 {
        q[info.coordinate_index(&a.name).expect("checked")] = a.value;
    }
    let mut held: Vec<(&str, f64)> = state
        .q0
        .iter()
        .map(|a| (a.name.as_str(), a.value))
        .collect();
    let velocities: Vec<(&str, f64)> = state
        .qd0
        .iter()
        .map(|a| (a.name.as_str(), a.value))
        .collect();
    let mut ws = Workspace::new(info).map_err(|e| failed(e.to_string()))?;
    // Redundant constraints (the parallelogram's third crank) are dropped from the
    // position and velocity equations, as the simulation does.
    let params = KinematicsParams {
        partition: PartitionParams {
            allow_redundant: true,
            ..PartitionParams::default()
        },
        ..KinematicsParams::default()
    };
    let mut kin = Kinematics::new(info, params);
    let mut notes = Vec::new();
    loop {
        let (mut qa, mut qda) = (q.clone(), qd.clone());
        let prescription = Prescription {
            coordinates: &held,
            velocities: &velocities,
        };
        match kin.assemble_declared(model, &mut ws, 0.0, &mut qa, &mut qda, &prescription) {
            Ok((report, overridden)) => {
                notes.extend(overridden.iter().map(ToString::to_string));
                for m in &report.moved_guesses {
                    let i = info.coordinate_index(m.coordinate).expect("a coordinate");
                    notes.push(format!(
                        "{m}; assembled to {} (give `--q0 {}=VALUE` too to choose another solution)",
                        qa[i], m.coordinate
                    ));
                }
                let size = qa.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                for a in &state.q0 {
                    let i = info.coordinate_index(&a.name).expect("checked");
                    if (qa[i] - a.value).abs() > 1e-9 * size.max(a.value.abs()) {
                        notes.push(format!(
                            "`{}` is determined by the constraints: {} was used as a guess, assembled to {}",
                            a.name, a.value, qa[i]
                        ));
                    }
                }
                return Ok(InitialState {
                    q: qa,
                    qd: qda,
                    notes,
                });
            }
            Err(AssemblyError::Partition(PartitionError::PrescribedCoordinate {
                coordinate,
                ..
            })) if held.iter().any(|h| h.0 == coordinate) => {
                // Keep the value as a guess, let Newton move it if it must.
                held.retain(|h| h.0 != coordinate);
            }

            Err(e) => {
                return Err(
                    usage(format!("cannot assemble a consistent initial state: {e}"))
                        .kind("assembly"),
                );
            }
        }
    }
}
