//! The command run on a model of this crate: `simulate double_pendulum` with `--json`,
//! `--csv` and `--animate`, whose outputs must parse and obey the physics of the model.
//!
//! Reference values: the model starts at rest with both links horizontal at y = 0, so
//! its energy T + V is 0 exactly and stays 0 (no applied force, no explicit time); the
//! links keep x1² + y1² = l1² and (x2 − x1)² + (y2 − y1)² = l2², l1 = l2 = 1 m.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

/// Tolerance of the checks against the closed forms: the runs below ask for rtol 1e-10.
const TOL: f64 = 1e-6;

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("own-model")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn run(dir: &Path, args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_own-model"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the program runs");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

const RUN: [&str; 8] = [
    "simulate",
    "double_pendulum",
    "--t-end",
    "3",
    "--rtol",
    "1e-10",
    "--atol",
    "1e-12",
];

fn links(x1: f64, y1: f64, x2: f64, y2: f64) -> (f64, f64) {
    (
        (x1 * x1 + y1 * y1).sqrt(),
        ((x2 - x1).powi(2) + (y2 - y1).powi(2)).sqrt(),
    )
}

#[test]
fn json_report_conserves_energy_and_keeps_the_links() {
    let dir = scratch("json");
    let mut args = RUN.to_vec();
    args.push("--json");
    let out = run(&dir, &args);
    let v: Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(v["model"], "double_pendulum");
    assert_eq!(v["t_end"].as_f64(), Some(3.0));
    let e0 = v["energy"]["initial"]
        .as_f64()
        .expect("a conservative model");
    let e1 = v["energy"]["final"].as_f64().unwrap();
    assert!(e0.abs() < 1e-12, "initial energy {e0}");
    assert!(e1.abs() < TOL, "final energy {e1}");
    let q = &v["final"]["q"];
    let c = |n: &str| q[n].as_f64().unwrap();
    let (a, b) = links(c("x1"), c("y1"), c("x2"), c("y2"));
    assert!((a - 1.0).abs() < TOL && (b - 1.0).abs() < TOL, "{a} {b}");
    // The bobs have moved: after 3 s the first is not where it started.
    assert!((c("x1") - 1.0).abs() > 1e-3, "{q}");
}

#[test]
fn csv_rows_conserve_energy_and_keep_the_links() {
    let dir = scratch("csv");
    let mut args = RUN.to_vec();
    args.extend(["--csv", "d.csv"]);
    run(&dir, &args);
    let text = std::fs::read_to_string(dir.join("d.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| {
        header
            .iter()
            .position(|h| *h == n)
            .unwrap_or_else(|| panic!("{n}"))
    };
    let (t, x1, y1, x2, y2, e) = (
        col("t"),
        col("x1"),
        col("y1"),
        col("x2"),
        col("y2"),
        col("energy"),
    );
    let mut rows = 0;
    let mut last_t = -1.0;
    let mut lowest = 0.0_f64;
    for line in lines {
        let r: Vec<f64> = line.split(',').map(|s| s.parse().unwrap()).collect();
        assert!(r[t] > last_t, "times increase: {line}");
        last_t = r[t];
        assert!(r[e].abs() < TOL, "energy {} at t = {}", r[e], r[t]);
        let (a, b) = links(r[x1], r[y1], r[x2], r[y2]);
        assert!((a - 1.0).abs() < TOL && (b - 1.0).abs() < TOL, "{line}");
        lowest = lowest.min(r[y2]);
        rows += 1;
    }
    assert_eq!(rows, 501, "500 intervals by default");
    assert!((last_t - 3.0).abs() < 1e-12);
    // The second bob falls (energy is converted into motion), but never below the
    // reach of the two links.
    assert!(lowest < -1.0 && lowest >= -2.0 - TOL, "{lowest}");
}

#[test]
fn animation_embeds_the_trajectory() {
    let dir = scratch("animate");
    let mut args = RUN.to_vec();
    args.extend(["--animate", "d.html"]);
    run(&dir, &args);
    let html = std::fs::read_to_string(dir.join("d.html")).unwrap();
    let open = "<script type=\"application/json\" id=\"pfaff-trajectory\">";
    let start = html.find(open).expect("the embedded trajectory") + open.len();
    let len = html[start..].find("</script>").unwrap();
    let v: Value = serde_json::from_str(&html[start..start + len]).expect("JSON");
    let times = v["times"].as_array().expect("times");
    assert_eq!(times.first().and_then(Value::as_f64), Some(0.0));
    assert_eq!(times.last().and_then(Value::as_f64), Some(3.0));
    assert_eq!(v["model"]["name"], "double_pendulum");
}

#[test]
fn show_code_prints_the_generated_module() {
    let dir = scratch("code");
    let out = run(&dir, &["show", "double_pendulum", "--code"]);
    let code = String::from_utf8(out.stdout).unwrap();
    assert!(code.contains("pub mod double_pendulum"), "{code}");
    assert!(
        code.contains("impl ::pfaff::Mechanism for Model") || code.contains("Mechanism for Model")
    );
}
