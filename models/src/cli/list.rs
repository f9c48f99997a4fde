//! `pfaff list` and `pfaff show MODEL`.

use std::fmt::Write as _;

use super::error::CliError;
use super::scene::Scene;
use super::setup;

/// Contacts are not modelled yet; the column is there so scripts need not change.
const CONTACTS: usize = 0;

/// The table of `pfaff list`.
pub fn list() -> String {
    let mut w = String::new();
    let _ = writeln!(
        w,
        "{:<16} {:>3} {:>4} {:>5} {:>8} {:>8}  description",
        "model", "nq", "hol", "nhol", "contacts", "t_end"
    );
    for e in pfaff_models::all() {
        let model = (e.make)();
        let info = model.info();
        let _ = writeln!(
            w,
            "{:<16} {:>3} {:>4} {:>5} {:>8} {:>8}  {}",
            e.name,
            info.nq(),
            info.nh(),
            info.nnh(),
            CONTACTS,
            Scene::of(e.name)
                .t_end
                .to_string()
                .chars()
                .take(8)
                .collect::<String>(),
            e.summary
        );
    }
    let _ = writeln!(
        w,
        "\nnq coordinates, hol holonomic and nhol non-holonomic constraints; t_end the default span [s] of `pfaff simulate`"
    );
    w
}

fn first_line(doc: &str) -> &str {
    doc.lines().next().unwrap_or("").trim()
}

/// The description of `pfaff show MODEL`.
pub fn show(name: &str) -> Result<String, CliError> {
    let entry = setup::find_model(name)?;
    let model = (entry.make)();
    let info = model.info();
    let mut w = String::new();
    let _ = writeln!(w, "{}: {}", info.name, entry.summary);
    let (n, mut q0, mut qd0) = (info.nq(), Vec::new(), Vec::new());
    q0.resize(n, 0.0);
    qd0.resize(n, 0.0);
    model.initial_state(&mut q0, &mut qd0);
    let _ = writeln!(w, "\ncoordinates ({n}), with the default initial guess:");
    for (i, c) in info.coordinates.iter().enumerate() {
        let _ = writeln!(
            w,
            "  {:<10} q0 = {:<22} qd0 = {:<12} {}",
            c.name,
            q0[i],
            qd0[i],
            first_line(c.doc)
        );
    }
    let _ = writeln!(
        w,
        "\nparameters ({}), set with --set NAME=VALUE:",
        info.parameters.len()
    );
    for p in info.parameters {
        let _ = writeln!(
            w,
            "  {:<10} = {:<12} {}",
            p.name,
            p.default,
            first_line(p.doc)
        );
    }
    let _ = writeln!(w, "\nholonomic constraints ({}):", info.nh());
    for c in info.holonomic {
        let _ = writeln!(w, "  {:<10} {}", c.name, first_line(c.doc));
    }
    let _ = writeln!(w, "\nnon-holonomic constraints ({}):", info.nnh());
    for c in info.nonholonomic {
        let _ = writeln!(w, "  {:<10} {}", c.name, first_line(c.doc));
    }
    let _ = writeln!(w, "\ncontacts ({CONTACTS})");
    let scene = Scene::of(info.name);
    let _ = writeln!(w, "default span: 0 to {} s ({})", scene.t_end, scene.span);
    if let Some(s) = scene.steady {
        let _ = writeln!(
            w,
            "linearize about: {}{}",
            s.summary,
            s.speed.map_or(String::new(), |(c, v)| format!(
                " (--speed sets the forward speed through {c}', default {v})"
            ))
        );
    }
    Ok(w)
}
