//! `pfaff rhs-time`: the cost of one index-1 right-hand side of a model, measured alone.
//!
//! One evaluation is [`Dynamics::accelerations`] at the assembled initial state: the
//! generated $M$, $Q$, $C_q$ and $\gamma$, and the solve of the augmented system (E31)
//! for $\ddot q$ and $\lambda$ — what the projection and Baumgarte formulations evaluate
//! at every stage of a step. The reported time is the best over `--batches` batches of
//! `--calls` evaluations, divided by `--calls`; it is meant to be set beside the cost of
//! the same right-hand side in other tools (`benchmarks/peers/`).

use std::hint::black_box;
use std::time::Instant;

use pfaff::{Dynamics, DynamicsParams, SolverPath, Workspace};
use serde_json::json;

use super::args::RhsTimeArgs;
use super::error::{failed, usage, CliError};
use super::setup;
use crate::Entry;

/// `pfaff rhs-time`.
pub fn command(models: &[Entry], args: &RhsTimeArgs) -> Result<(), CliError> {
    if args.calls == 0 || args.batches == 0 {
        return Err(usage(format!(
            "invalid --calls {} --batches {}: expected at least 1 of each",
            args.calls, args.batches
        )));
    }
    let entry = setup::find_model(models, &args.model)?;
    let model = setup::build(entry, &args.state.set)?;
    let init = setup::assemble(model.as_ref(), &args.state, &[], &[])?;
    let info = model.info();
    let mut ws = Workspace::new(info).map_err(|e| failed(e.to_string()))?;
    let mut dynamics =
        Dynamics::new(info, DynamicsParams::default()).map_err(|e| failed(e.to_string()))?;
    let mut qdd = vec![0.0; info.nq()];
    let mut lambda = vec![0.0; info.nh() + info.nnh()];
    let mut evaluate = |q: &[f64], qd: &[f64]| {
        dynamics
            .accelerations(model.as_ref(), &mut ws, 0.0, q, qd, &mut qdd, &mut lambda)
            .map_err(|e| failed(format!("the right-hand side of `{}`: {e}", info.name)))
    };
    let path = evaluate(&init.q, &init.qd)?.path;
    let mut best = f64::INFINITY;
    for _ in 0..args.batches {
        let start = Instant::now();
        for _ in 0..args.calls {
            evaluate(black_box(&init.q), black_box(&init.qd))?;
        }
        best = best.min(start.elapsed().as_secs_f64() / args.calls as f64);
    }
    let path = match path {
        SolverPath::Generated => "generated",
        SolverPath::Dense => "dense",
        SolverPath::Sparse => "sparse",
        SolverPath::SparseLdlt => "sparse LDLT",
        SolverPath::Redundant => "redundant",
    };
    if args.json {
        super::out::line(format_args!(
            "{}",
            json!({
                "model": info.name,
                "calls": args.calls,
                "batches": args.batches,
                "solver": path,
                "seconds_per_call": best,
            })
        ))
    } else {
        super::out::line(format_args!(
            "{}: index-1 right-hand side (M, Q, C_q, gamma and the {path} augmented solve) \
             {:.3} us per call, best of {} batches of {} calls at the initial state",
            info.name,
            best * 1e6,
            args.batches,
            args.calls
        ))
    }
}
