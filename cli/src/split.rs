//! The partition of coordinates and velocities (Algorithm P) at a state, as `show` and
//! `simulate` print it: holonomic constraints fix dependent coordinates, holonomic and
//! non-holonomic ones together fix dependent velocities, so a non-holonomic model has
//! fewer independent velocities than independent coordinates. The elastic coordinates
//! of deformable bodies are named, with where they fall.

use std::fmt::Write as _;

use pfaff::{Mechanism, Partition, PartitionParams, Preferences, Workspace};

/// The coordinates that move no body frame but move the model's points: the elastic
/// coordinates of its deformable bodies (the frames follow the reference coordinates
/// only). Empty for a model without frames.
fn elastic(model: &dyn Mechanism, t: f64, q: &[f64]) -> Vec<usize> {
    let info = model.info();
    if info.frames.is_empty() || info.points.is_empty() {
        return Vec::new();
    }
    let (nf, np) = (12 * info.frames.len(), 3 * info.points.len());
    let (mut f0, mut p0) = (vec![0.0; nf], vec![0.0; np]);
    model.frame_poses(t, q, &mut f0);
    model.point_positions(t, q, &mut p0);
    let mut out = Vec::new();
    let mut x = q.to_vec();
    for (i, &qi) in q.iter().enumerate() {
        let h = 1e-3 * (1.0 + qi.abs());
        x[i] = qi + h;
        let (mut f1, mut p1) = (vec![0.0; nf], vec![0.0; np]);
        model.frame_poses(t, &x, &mut f1);
        model.point_positions(t, &x, &mut p1);
        x[i] = qi;
        let moved = |a: &[f64], b: &[f64]| a.iter().zip(b).any(|(u, v)| u != v);
        if !moved(&f0, &f1) && moved(&p0, &p1) {
            out.push(i);
        }
    }
    out
}

/// Lines describing the partition at `(t, q)`, each starting with `prefix`; a line
/// saying why when Algorithm P fails there.
pub fn describe(model: &dyn Mechanism, t: f64, q: &[f64], prefix: &str) -> String {
    let info = model.info();
    let mut w = String::new();
    let names = |v: &[usize]| -> String {
        if v.is_empty() {
            "-".to_owned()
        } else {
            v.iter()
                .map(|&i| info.coordinates[i].name)
                .collect::<Vec<_>>()
                .join(" ")
        }
    };
    let p = Workspace::new(info)
        .map_err(|e| e.to_string())
        .and_then(|mut ws| {
            Partition::compute(
                model,
                &mut ws,
                t,
                q,
                Preferences::default(),
                &PartitionParams {
                    // Redundant holonomic rows remove no degree of freedom (not with
                    // non-holonomic constraints).
                    allow_redundant: info.nnh() == 0,
                    ..PartitionParams::default()
                },
            )
            .map_err(|e| e.to_string())
        });
    let p = match p {
        Ok(p) => p,
        Err(e) => {
            let _ = writeln!(w, "{prefix}partition    not available here: {e}");
            return w;
        }
    };
    let n = info.nq();
    let coords: Vec<usize> = (0..n).filter(|i| !p.dependent().contains(i)).collect();
    let _ = writeln!(
        w,
        "{prefix}partition    {} independent coordinates, {} independent velocities ({} coordinates, {} holonomic, {} non-holonomic constraints)",
        coords.len(),
        p.independent().len(),
        n,
        info.nh(),
        info.nnh()
    );
    let _ = writeln!(
        w,
        "{prefix}  dependent coordinates            {}",
        names(p.dependent())
    );
    let _ = writeln!(
        w,
        "{prefix}  independent, dependent velocity  {}",
        names(p.dependent_velocity())
    );
    let _ = writeln!(
        w,
        "{prefix}  independent velocities           {}",
        names(p.independent())
    );
    let el = elastic(model, t, q);
    if !el.is_empty() {
        let among = |v: &[usize]| {
            el.iter()
                .filter(|i| v.contains(i))
                .copied()
                .collect::<Vec<_>>()
        };
        let c = among(&coords);
        let v = among(p.independent());
        let _ = writeln!(
            w,
            "{prefix}  elastic coordinates              {} ({} among the independent coordinates: {}; {} among the independent velocities: {})",
            names(&el),
            c.len(),
            names(&c),
            v.len(),
            names(&v)
        );
    }
    w
}
