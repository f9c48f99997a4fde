//! What `pfaff simulate` reports beyond the state: the model's named outputs
//! (`#[output] fn`) at every recorded row, their range along the run, and the
//! accelerations at the final state.

use pfaff::sim::{Run, REDUNDANT_TOLERANCE};
use pfaff::{Dynamics, DynamicsParams, Mechanism, Workspace};

/// The outputs of `model` at `(t, q, q̇)`, in the order of `Info::outputs`.
pub fn values(model: &dyn Mechanism, t: f64, q: &[f64], qd: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; model.info().outputs.len()];
    if !out.is_empty() {
        model.outputs(t, q, qd, &mut out);
    }
    out
}

/// The outputs at every row of the run's trajectory: `rows[i][k]` is output `k` at row
/// `i`.
pub fn along(model: &dyn Mechanism, run: &Run) -> Vec<Vec<f64>> {
    let tr = &run.trajectory;
    (0..tr.len())
        .map(|i| values(model, tr.t[i], tr.q(i), tr.qd(i)))
        .collect()
}

/// The smallest and largest value of every output over `rows` (`None` without rows).
pub fn ranges(rows: &[Vec<f64>], count: usize) -> Option<Vec<(f64, f64)>> {
    let first = rows.first()?;
    let mut r: Vec<(f64, f64)> = first.iter().map(|&v| (v, v)).collect();
    for row in &rows[1..] {
        for (k, &v) in row.iter().enumerate().take(count) {
            r[k] = (r[k].0.min(v), r[k].1.max(v));
        }
    }
    Some(r)
}

/// The accelerations $\ddot q$ of the augmented solve $[M\ J^\mathsf{T}; J\ 0]$ at
/// `(t, q, q̇)`, with the redundancy tolerance a simulation uses (the state of a run
/// is on the constraints only to the integration tolerance).
///
/// # Errors
/// The solve's failure, as a message.
pub fn accelerations(
    model: &dyn Mechanism,
    t: f64,
    q: &[f64],
    qd: &[f64],
) -> Result<Vec<f64>, String> {
    let info = model.info();
    let mut ws = Workspace::new(info).map_err(|e| e.to_string())?;
    let params = DynamicsParams {
        redundant_tolerance: REDUNDANT_TOLERANCE,
        ..DynamicsParams::default()
    };
    let mut dynamics = Dynamics::new(info, params).map_err(|e| e.to_string())?;
    let mut qdd = vec![0.0; info.nq()];
    let mut lambda = vec![0.0; info.nh() + info.nnh()];
    dynamics
        .accelerations(model, &mut ws, t, q, qd, &mut qdd, &mut lambda)
        .map_err(|e| e.to_string())?;
    Ok(qdd)
}

/// The reaction of every joint of a body-level model at `(t, q)` with the multipliers
/// `lambda` of that state (`None` for models without joints).
pub fn joint_reactions(
    model: &dyn Mechanism,
    t: f64,
    q: &[f64],
    lambda: &[f64],
) -> Option<pfaff::JointReactions> {
    let info = model.info();
    if info.joints.is_empty() {
        return None;
    }
    let mut r = pfaff::JointReactions::new(info);
    r.evaluate(model, t, q, lambda);
    Some(r)
}
