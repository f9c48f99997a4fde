//! `pfaff list` and `pfaff show MODEL`.

use std::fmt::Write as _;

use super::error::{failed, usage, CliError};
use super::setup;
use crate::Entry;

/// The table of `pfaff list`.
pub fn list(models: &[Entry]) -> String {
    let mut w = String::new();
    // The name column as wide as the longest name.
    let width = models
        .iter()
        .map(|e| e.name.len())
        .max()
        .unwrap_or(0)
        .max("model".len());
    let _ = writeln!(
        w,
        "{:<width$} {:>3} {:>4} {:>5} {:>8} {:>8} {:>6} {:>6}  description",
        "model", "nq", "hol", "nhol", "contacts", "t_end", "bodies", "joints"
    );
    for e in models {
        let model = (e.make)();
        let summary = e.description(model.as_ref());
        let info = model.info();
        let _ = writeln!(
            w,
            "{:<width$} {:>3} {:>4} {:>5} {:>8} {:>8} {:>6} {:>6}  {}",
            e.name,
            info.nq(),
            info.nh(),
            info.nnh(),
            info.ncontacts(),
            e.scene
                .t_end
                .to_string()
                .chars()
                .take(8)
                .collect::<String>(),
            info.bodies.len(),
            info.joints.len(),
            if e.stiff {
                format!("{summary} [stiff]")
            } else {
                summary
            }
        );
    }
    let _ = writeln!(
        w,
        "\nnq coordinates, hol holonomic and nhol non-holonomic constraints; t_end the default span [s] of `pfaff simulate`;\nbodies and joints of the models written at the body level;\n[stiff]: simulated with radau5 by default, work-precision sweeps radau5 only"
    );
    w
}

fn first_line(doc: &str) -> &str {
    doc.lines().next().unwrap_or("").trim()
}

/// The description of `pfaff show MODEL`.
pub fn show(models: &[Entry], name: &str) -> Result<String, CliError> {
    let entry = setup::find_model(models, name)?;
    let model = (entry.make)();
    let info = model.info();
    let mut w = String::new();
    let _ = writeln!(w, "{}: {}", info.name, entry.description(model.as_ref()));
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
    let _ = writeln!(w, "\nat the default initial guess:");
    w.push_str(&super::split::describe(model.as_ref(), 0.0, &q0, "  "));
    body_level(&mut w, model.as_ref(), &q0);
    let _ = writeln!(w, "\ncontacts ({}):", info.ncontacts());
    for c in info.contacts {
        let e = info.parameters[c.restitution as usize].name;
        let _ = writeln!(
            w,
            "  {:<10} restitution {:<6} {}",
            c.name,
            e,
            first_line(c.doc)
        );
    }
    let scene = entry.scene;
    let _ = writeln!(w, "default span: 0 to {} s ({})", scene.t_end, scene.span);
    if entry.stiff {
        let _ = writeln!(
            w,
            "stiff: `simulate` uses radau5 unless --integrator says otherwise; `work-precision` sweeps radau5 (--all-methods: every method)"
        );
    }
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

/// A joint's rows, `name (first..last)` of one kind of constraint, or `-`.
fn rows(names: &[pfaff::Symbol], (start, len): (u32, u32)) -> String {
    let (a, n) = (start as usize, len as usize);
    match names.get(a..a + n) {
        Some([]) | None => "-".to_owned(),
        Some(rows) => rows.iter().map(|s| s.name).collect::<Vec<_>>().join(" "),
    }
}

/// The body level of `pfaff show`: bodies, joints, points, outputs.
fn body_level(w: &mut String, model: &dyn pfaff::Mechanism, q0: &[f64]) {
    let info = model.info();
    let frame = |k: Option<u32>| {
        k.and_then(|k| info.frames.get(k as usize))
            .map_or("ground", |f| f.name)
    };
    let mut masses = vec![0.0; info.bodies.len()];
    if !masses.is_empty() {
        model.body_masses(0.0, q0, &mut masses);
    }
    let _ = writeln!(w, "\nbodies ({}):", info.bodies.len());
    for (b, m) in info.bodies.iter().zip(&masses) {
        let _ = writeln!(
            w,
            "  {:<10} mass {:<10} frame {:<10} {}",
            b.name,
            m,
            frame(Some(b.frame)),
            first_line(b.doc)
        );
    }
    let _ = writeln!(w, "\njoints ({}):", info.joints.len());
    for j in info.joints {
        let _ = writeln!(
            w,
            "  {:<10} {:<16} {} - {}; holonomic rows: {}; non-holonomic rows: {}",
            j.name,
            format!("{:?}", j.kind),
            frame(j.frames[0]),
            frame(j.frames[1]),
            rows(info.holonomic, j.holonomic),
            rows(info.nonholonomic, j.nonholonomic),
        );
    }
    let _ = writeln!(w, "\npoints ({}):", info.points.len());
    for p in info.points {
        let _ = writeln!(
            w,
            "  {:<10} in frame {:<10} {}",
            p.name,
            frame(Some(p.frame)),
            first_line(p.doc)
        );
    }
    let _ = writeln!(w, "\noutputs ({}):", info.outputs.len());
    for o in info.outputs {
        let _ = writeln!(w, "  {:<10} {}", o.name, first_line(o.doc));
    }
}

/// The generated code of `pfaff show --code MODEL`: the model's source (carried by its
/// entry) expanded by [`pfaff_codegen::expand_source`] and formatted by prettyplease.
pub fn code(models: &[Entry], name: &str) -> Result<String, CliError> {
    let entry = setup::find_model(models, name)?;
    let source = entry.source.ok_or_else(|| {
        usage(format!(
            "model `{name}` carries no source: its entry needs `.source(include_str!(\"FILE.rs\"))` for --code"
        ))
    })?;
    let located = |e: syn::Error| {
        let at = e.span().start();
        failed(format!(
            "cannot expand model `{name}` (line {}, column {} of its source): {e}",
            at.line,
            at.column + 1
        ))
    };
    let tokens = pfaff_codegen::expand_source(source, name).map_err(located)?;
    let file: syn::File = syn::parse2(tokens).map_err(located)?;
    Ok(prettyplease::unparse(&file))
}
