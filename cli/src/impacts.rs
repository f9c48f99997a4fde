//! Impacts in the reports of `pfaff simulate`: the text summary's lines, the `impacts`
//! and `contact_events` arrays of `--json`.

use std::fmt::Write as _;

use pfaff::sim::{ContactEventKind, Run};
use pfaff::Info;
use serde_json::{json, Map, Value};

/// Impacts listed one per line in the summary; the rest are counted.
const LISTED: usize = 12;

/// `impacts` of `--json`: one object per impact (time, contact, normal impulse, energy
/// lost, normal velocities, and the impulsive reaction of every named constraint).
pub fn json(info: &Info, run: &Run) -> Value {
    let constraints = || {
        info.holonomic
            .iter()
            .chain(info.nonholonomic)
            .map(|s| s.name)
    };
    Value::Array(
        run.impacts
            .iter()
            .map(|imp| {
                let reactions: Map<String, Value> = constraints()
                    .zip(&imp.constraint_impulses)
                    .map(|(n, v)| (n.to_owned(), json!(v)))
                    .collect();
                json!({
                    "t": imp.t,
                    "contact": imp.names.first().copied().unwrap_or(""),
                    "impulse": imp.impulses.first().copied().unwrap_or(0.0),
                    "energy_lost": imp.energy_lost(),
                    "normal_velocity_before": imp.normal_velocity_before.first().copied().unwrap_or(0.0),
                    "normal_velocity_after": imp.normal_velocity_after.first().copied().unwrap_or(0.0),
                    "constraint_impulses": reactions,
                })
            })
            .collect(),
    )
}

/// `contact_events` of `--json`: resting contacts and releases.
pub fn events_json(run: &Run) -> Value {
    Value::Array(
        run.contact_events
            .iter()
            .map(|e| {
                json!({
                    "t": e.t,
                    "contact": e.contact,
                    "kind": match e.kind {
                        ContactEventKind::Rest => "rest",
                        ContactEventKind::Release => "release",
                    },
                })
            })
            .collect(),
    )
}

/// The summary's lines about impacts (nothing for a model without contacts).
pub fn summary(info: &Info, run: &Run, w: &mut String) {
    if info.ncontacts() == 0 {
        return;
    }
    // From +0 (an empty `sum` of floats is −0, printed "-0"); `+ 0.0` below likewise
    // prints an impact's −0 as 0.
    let lost = run
        .impacts
        .iter()
        .map(pfaff::Impact::energy_lost)
        .fold(0.0, |a, e| a + e);
    let _ = writeln!(
        w,
        "impacts      {} ({} contact{}), energy lost {lost:.6e} J",
        run.impacts.len(),
        info.ncontacts(),
        if info.ncontacts() == 1 { "" } else { "s" }
    );
    for imp in run.impacts.iter().take(LISTED) {
        let _ = writeln!(
            w,
            "  t = {:<20} {:<12} impulse {:.6e}, energy lost {:.6e} J",
            super::time(imp.t),
            imp.names.first().copied().unwrap_or(""),
            imp.impulses.first().copied().unwrap_or(0.0),
            imp.energy_lost() + 0.0
        );
    }
    if run.impacts.len() > LISTED {
        let _ = writeln!(w, "  ... {} more", run.impacts.len() - LISTED);
    }
    for e in &run.contact_events {
        // Rest after impacts of that contact is their accumulation; a contact closed
        // without one (at rest on it from the start) simply rests.
        let struck = run
            .impacts
            .iter()
            .any(|i| i.t <= e.t && i.names.contains(&e.contact));
        let what = match e.kind {
            ContactEventKind::Rest if struck => "comes to rest (impacts accumulated)",
            ContactEventKind::Rest => "rests (closed without an impact)",
            ContactEventKind::Release => "releases (its normal force turned tensile)",
        };
        let _ = writeln!(
            w,
            "contact      {} {what} at t = {}",
            e.contact,
            super::time(e.t)
        );
    }
}
