//! Every model of the registry runs with its defaults under `simulate`, `linearize` and
//! `work-precision` (issue 9), so that a new model cannot land broken.

mod common;

use std::process::{Command, Stdio};

use common::{pfaff, stderr, stdout};
use serde_json::Value;

fn names() -> Vec<&'static str> {
    pfaff_models::all().iter().map(|e| e.name).collect()
}

fn stiff(name: &str) -> bool {
    pfaff_models::find(name).is_some_and(|e| e.stiff)
}

#[test]
fn every_model_simulates_and_linearizes_with_its_defaults() {
    for name in names() {
        let out = pfaff(&["simulate", name, "--json"]);
        assert!(out.status.success(), "simulate {name}: {}", stderr(&out));
        let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
        assert!(v.get("error").is_none(), "simulate {name}: {v}");
        assert!(v["final"]["t"].as_f64().is_some(), "simulate {name}: {v}");
        // A stiff model runs with Radau5 unless told otherwise.
        let method = if stiff(name) { "radau5" } else { "adams" };
        assert_eq!(v["integrator"], method, "simulate {name}: {v}");
        // Every model has an operating point: its steady motion, or its initial state.
        let out = pfaff(&["linearize", name, "--json"]);
        assert!(out.status.success(), "linearize {name}: {}", stderr(&out));
        let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
        let eigenvalues = v["eigenvalues"].as_array().unwrap();
        assert_eq!(
            eigenvalues.len(),
            v["states"].as_array().unwrap().len(),
            "linearize {name}: {v}"
        );
        assert!(
            eigenvalues
                .iter()
                .all(|e| e["re"].is_f64() && e["im"].is_f64()),
            "linearize {name}: {v}"
        );
    }
}

#[test]
fn every_model_runs_work_precision_with_its_defaults() {
    // All at once: each sweep is single-threaded, and together they fill the cores.
    let children: Vec<_> = names()
        .into_iter()
        .map(|name| {
            let child = Command::new(env!("CARGO_BIN_EXE_pfaff"))
                .args(["work-precision", name])
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .expect("the pfaff binary runs");
            (name, child)
        })
        .collect();
    for (name, child) in children {
        let out = child.wait_with_output().unwrap();
        assert!(
            out.status.success(),
            "work-precision {name}: {}",
            stderr(&out)
        );
        let text = stdout(&out);
        // One row per tolerance of the sweep, 1e-3 to 1e-12; a stiff model sweeps
        // Radau5 alone, 1e-3 to 1e-9, and every row of it finishes.
        let (methods, sweep): (&[&str], usize) = if stiff(name) {
            (&["radau5"], 7)
        } else {
            (&["rk4", "dopri5", "dop853", "adams", "radau5"], 10)
        };
        for formulation in ["partitioning", "projection", "baumgarte"] {
            for method in ["rk4", "dopri5", "dop853", "adams", "radau5"] {
                let rows: Vec<&str> = text
                    .lines()
                    .filter(|l| {
                        let mut cols = l.split_whitespace();
                        cols.next() == Some(formulation) && cols.next() == Some(method)
                    })
                    .collect();
                let want = if methods.contains(&method) { sweep } else { 0 };
                assert_eq!(
                    rows.len(),
                    want,
                    "work-precision {name}, {formulation} {method}:\n{text}"
                );
                if stiff(name) {
                    assert!(
                        rows.iter().all(|r| !r.contains("FAILED")),
                        "work-precision {name}, {formulation} {method}:\n{text}"
                    );
                }
            }
        }
    }
}
