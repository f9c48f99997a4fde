//! The `pfaff` binary, command by command: what a user sees and what scripts parse.

mod common;

use common::{assert_svg, pfaff, pfaff_in, scratch, stderr, stdout};
use serde_json::Value;
use std::time::Instant;

/// How far the default run of `andrews` (partitioning + Adams, rtol 1e-6, atol 1e-8) may
/// end from the test set's beta(0.03): twice the rtol (measured: 7.0e-7; the error of
/// every method at rtol 1e-6 is at most 2.7 × rtol, tests/src/sim/published.rs).
const ANDREWS_DEFAULT_ERROR: f64 = 2e-6;

#[test]
fn default_scene_simulates_andrews_and_writes_a_plot() {
    let dir = scratch("default_scene");
    let out = pfaff_in(&dir, &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    for needle in [
        "andrews:",
        "partitioning + adams",
        "rhs evaluations",
        "Newton iterations",
        "re-partitions",
        "wall time",
        "violations",
        "energy",
        "pfaff-andrews.svg",
    ] {
        assert!(text.contains(needle), "missing `{needle}` in\n{text}");
    }
    assert_svg(&dir.join("pfaff-andrews.svg"));
}

#[test]
fn list_shows_every_model_with_its_sizes() {
    let out = pfaff(&["list"]);
    assert!(out.status.success());
    let text = stdout(&out);
    for entry in pfaff_models::all() {
        let line = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(entry.name))
            .unwrap_or_else(|| panic!("`{}` not listed", entry.name));
        assert!(line.contains(entry.summary), "{line}");
    }
    let sleigh = text.lines().find(|l| l.starts_with("sleigh ")).unwrap();
    let cols: Vec<&str> = sleigh.split_whitespace().take(5).collect();
    assert_eq!(cols, ["sleigh", "3", "0", "1", "0"]);
    let andrews = text.lines().find(|l| l.starts_with("andrews ")).unwrap();
    let cols: Vec<&str> = andrews.split_whitespace().take(5).collect();
    assert_eq!(cols, ["andrews", "7", "6", "0", "0"]);
}

#[test]
fn show_lists_coordinates_parameters_and_constraints() {
    let out = pfaff(&["show", "andrews"]);
    assert!(out.status.success());
    let text = stdout(&out);
    for needle in [
        "beta",
        "epsilon",
        "c0",
        "4530",
        "mom",
        "holonomic constraints (6)",
    ] {
        assert!(text.contains(needle), "missing `{needle}`");
    }
}

/// Every key of the JSON summary, as documented.
fn check_keys(v: &Value, with_error: bool) {
    let mut keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    keys.sort_unstable();
    let mut expected = vec![
        "atol",
        "contact_events",
        "energy",
        "final",
        "impacts",
        "formulation",
        "integrator",
        "max_violation",
        "model",
        "outputs",
        "rtol",
        "stats",
        "t_end",
        "wall_seconds",
    ];
    if with_error {
        expected.push("error");
    }
    expected.sort_unstable();
    assert_eq!(keys, expected);
    let mut stats: Vec<&str> = v["stats"]
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    stats.sort_unstable();
    assert_eq!(
        stats,
        [
            "factorizations",
            "jacobians",
            "newton_iterations",
            "output_factorizations",
            "output_newton_iterations",
            "rejected",
            "repartitions",
            "rhs_evals",
            "stage_factorizations",
            "stage_newton_iterations",
            "steps"
        ]
    );
    let mut viol: Vec<&str> = v["max_violation"]
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    viol.sort_unstable();
    assert_eq!(viol, ["nonholonomic", "position", "velocity"]);
}

#[test]
fn simulate_json_is_one_object_with_the_documented_keys() {
    let start = Instant::now();
    let out = pfaff(&[
        "simulate",
        "pendulum",
        "--t-end",
        "1",
        "--integrator",
        "dop853",
        "--rtol",
        "1e-9",
        "--atol",
        "1e-11",
        "--json",
    ]);
    let elapsed = start.elapsed().as_secs_f64();
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert_eq!(text.trim().lines().count(), 1, "{text}");
    let v: Value = serde_json::from_str(&text).unwrap();
    check_keys(&v, false);
    assert_eq!(v["model"], "pendulum");
    assert_eq!(v["formulation"], "partitioning");
    assert_eq!(v["integrator"], "dop853");
    assert_eq!(v["rtol"], 1e-9);
    assert_eq!(v["t_end"], 1.0);
    let fin = &v["final"];
    assert_eq!(fin["t"], 1.0);
    let mut keys: Vec<&str> = fin
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    keys.sort_unstable();
    assert_eq!(keys, ["joints", "lambda", "outputs", "q", "qd", "qdd", "t"]);
    assert!(fin["joints"].is_null(), "pendulum has no joints");
    let (x, y) = (
        fin["q"]["x"].as_f64().unwrap(),
        fin["q"]["y"].as_f64().unwrap(),
    );
    assert!((x * x + y * y - 1.0).abs() < 1e-9);
    assert!(fin["lambda"]["rod"].is_f64());
    assert!(v["stats"]["steps"].as_u64().unwrap() > 0);
    let e = &v["energy"];
    let drift = e["final"].as_f64().unwrap() - e["initial"].as_f64().unwrap();
    assert!(drift.abs() < 1e-5, "{drift}");
    // The run's own time, inside the process's.
    let wall = v["wall_seconds"].as_f64().unwrap();
    assert!(
        wall > 0.0 && wall <= elapsed,
        "{wall} s of a process of {elapsed} s"
    );
}

#[test]
fn simulate_energy_is_null_for_a_driven_model() {
    let out = pfaff(&["simulate", "andrews", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
    check_keys(&v, false);
    assert!(v["energy"].is_null());
    // The Test Set for IVP Solvers (Mazzia & Magherini, release 2.4, "andrews"):
    // beta(0.03) = 15.81077119629904, computed with PSIDE at 1e-14. The default run
    // (rtol 1e-6) is within ANDREWS_DEFAULT_ERROR of it.
    let beta = v["final"]["q"]["beta"].as_f64().unwrap();
    assert!(
        (beta - 15.810_771_196_299_04).abs() < ANDREWS_DEFAULT_ERROR,
        "{beta}"
    );
}

#[test]
fn simulate_repeat_reports_the_same_run() {
    let args = [
        "simulate", "andrews", "--rtol", "1e-8", "--atol", "1e-8", "--json",
    ];
    let once: Value = serde_json::from_str(&stdout(&pfaff(&args))).unwrap();
    let start = Instant::now();
    let out = pfaff(&[&args[..], &["--repeat", "3"]].concat());
    let elapsed = start.elapsed().as_secs_f64();
    assert!(out.status.success(), "{}", stderr(&out));
    let thrice: Value = serde_json::from_str(&stdout(&out)).unwrap();
    check_keys(&thrice, false);
    // The runs are deterministic: the same work and the same final state.
    assert_eq!(once["stats"], thrice["stats"]);
    assert_eq!(once["final"], thrice["final"]);
    // The best of three runs, each inside the one process.
    let best = thrice["wall_seconds"].as_f64().unwrap();
    assert!(
        best > 0.0 && 3.0 * best <= elapsed,
        "{best} s, process {elapsed} s"
    );
}

#[test]
fn rhs_time_reports_the_cost_of_one_evaluation() {
    let out = pfaff(&["rhs-time", "andrews", "--calls", "1000", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
    let mut keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    keys.sort_unstable();
    assert_eq!(
        keys,
        ["batches", "calls", "model", "seconds_per_call", "solver"]
    );
    assert_eq!(v["model"], "andrews");
    assert_eq!(v["calls"], 1000);
    // The model's generated solve of the augmented system (its pivots are safe at the
    // initial state).
    assert_eq!(v["solver"], "generated");
    let s = v["seconds_per_call"].as_f64().unwrap();
    assert!(s > 0.0 && s < 1e-3, "{s}");
    let text = stdout(&pfaff(&["rhs-time", "pendulum", "--calls", "10"]));
    assert!(
        text.starts_with("pendulum: index-1 right-hand side") && text.contains("us per call"),
        "{text}"
    );
}

#[test]
fn simulate_failure_reports_the_error_and_the_partial_run() {
    // A massless sleigh: the augmented matrix is singular from the start.
    let out = pfaff(&[
        "simulate", "sleigh", "--set", "m=0", "--set", "ic=0", "--json",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("singular"), "{err}");
    let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
    check_keys(&v, true);
    let mut keys: Vec<&str> = v["error"]
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    keys.sort_unstable();
    assert_eq!(keys, ["kind", "message", "stopped_at", "t"]);
    assert_eq!(v["error"]["kind"], "singular_mass");
    assert_eq!(v["error"]["t"], 0.0);
    // Nothing consistent was computed: no last state.
    assert!(v["error"]["stopped_at"].is_null());
    assert!(v["final"].is_null());
    // The massless coordinates are named.
    let message = v["error"]["message"].as_str().unwrap();
    assert!(message.contains("coordinates involved"), "{message}");
}

#[test]
fn simulate_writes_csv_and_plot() {
    let dir = scratch("csv_plot");
    let out = pfaff_in(
        &dir,
        &[
            "simulate",
            "andrews",
            "--samples",
            "50",
            "--csv",
            "a.csv",
            "--plot",
            "a.svg",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let csv = std::fs::read_to_string(dir.join("a.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    // t, 7 q, 7 q', 6 lambda, 2 residuals, energy.
    assert_eq!(header.len(), 1 + 7 + 7 + 6 + 3);
    assert_eq!(header[0], "t");
    assert_eq!(header[1], "beta");
    assert_eq!(header[8], "beta'");
    assert!(header[15].starts_with("lambda_"));
    assert_eq!(
        &header[21..],
        ["position_violation", "velocity_violation", "energy"]
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 51);
    assert!(rows.iter().all(|r| r.len() == header.len()));
    assert_eq!(rows[0][0], 0.0);
    assert!((rows[50][0] - 0.03).abs() < 1e-15);
    assert!(rows.iter().all(|r| r[21] < 1e-10));
    assert_svg(&dir.join("a.svg"));
}

#[test]
fn simulate_holds_prescribed_initial_values() {
    // x prescribed; y follows from the link (y = -sqrt(1 - 0.36)), started below.
    let out = pfaff(&[
        "simulate", "pendulum", "--t-end", "0.5", "--q0", "x=0.6", "--set", "l=1", "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
    assert!(v["final"]["q"]["x"].as_f64().unwrap().abs() < 0.6);
    // At the start: x as given, y on the lower branch (the default guess y = 0 leaves
    // y undetermined; it moves toward the lower potential energy).
    let out = pfaff(&[
        "simulate", "pendulum", "--t-end", "0", "--q0", "x=0.6", "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
    assert_eq!(v["final"]["q"]["x"].as_f64(), Some(0.6));
    assert!(
        (v["final"]["q"]["y"].as_f64().unwrap() + 0.8).abs() < 1e-14,
        "{v}"
    );
}

#[test]
fn simulate_takes_a_full_consistent_state_and_names_what_an_inconsistent_one_violates() {
    // x² + y² = 1 and x ẋ + y ẏ = 0: kept as given, so the initial energy is
    // g y + ½(ẋ² + ẏ²) = −7.848 + 1.125.
    let out = pfaff(&[
        "simulate", "pendulum", "--t-end", "0.5", "--q0", "x=0.6", "--q0", "y=-0.8", "--qd0",
        "x=1.2", "--qd0", "y=0.9", "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
    let e0 = v["energy"]["initial"].as_f64().unwrap();
    assert!((e0 + 6.723).abs() < 1e-12, "{e0}");
    // 0.36 + 0.81 − 1 = 0.17 off the link.
    let out = pfaff(&[
        "simulate", "pendulum", "--t-end", "0.5", "--q0", "x=0.6", "--q0", "y=-0.9",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(err.contains("`rod` by 1.700e-1"), "{err}");
}

#[test]
fn every_formulation_and_integrator_runs() {
    for f in ["partitioning", "projection", "baumgarte"] {
        for i in ["rk4", "dopri5", "dop853", "adams", "radau5"] {
            let out = pfaff(&[
                "simulate",
                "sleigh",
                "--formulation",
                f,
                "--integrator",
                i,
                "--t-end",
                "1",
                "--json",
            ]);
            assert!(out.status.success(), "{f} {i}: {}", stderr(&out));
            let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
            assert_eq!(
                (v["formulation"].as_str(), v["integrator"].as_str()),
                (Some(f), Some(i))
            );
            // docs/theory.md V11 at t = 1: phi = 0.176360706663.
            let phi = v["final"]["q"]["phi"].as_f64().unwrap();
            assert!((phi - 0.176_360_706_663).abs() < 1e-3, "{f} {i}: {phi}");
        }
    }
}

#[test]
fn linearize_pendulum_json() {
    let out = pfaff(&[
        "linearize",
        "pendulum",
        "--q0",
        "x=0",
        "--q0",
        "y=-1",
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
    let eig = v["eigenvalues"].as_array().unwrap();
    assert_eq!(eig.len(), 2);
    let w = 9.81f64.sqrt();
    for (e, sign) in eig.iter().zip([-1.0, 1.0]) {
        assert!(e["re"].as_f64().unwrap().abs() < 1e-7 * w);
        assert!((e["im"].as_f64().unwrap() - sign * w).abs() < 1e-7 * w);
    }
    let a = v["state_matrix"].as_array().unwrap();
    assert_eq!(a.len(), 2);
    assert!(a.iter().all(|r| r.as_array().unwrap().len() == 2));
}

#[test]
fn linearize_sleigh_at_a_speed() {
    let out = pfaff(&["linearize", "sleigh", "--speed", "3", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
    let re: Vec<f64> = v["eigenvalues"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["re"].as_f64().unwrap())
        .collect();
    let (m, ic, a, speed) = (2.0, 0.05, 0.3, 3.0);
    let decay = -m * a * speed / (ic + m * a * a);
    assert!((re[0] - decay).abs() < 1e-7 * decay.abs(), "{re:?}");
    assert!(re[1].abs() < 1e-7, "{re:?}");
    let text = stdout(&pfaff(&["linearize", "sleigh", "--speed", "3"]));
    assert!(
        text.contains("eigenvalues") && text.contains("dropped"),
        "{text}"
    );
}

/// The steady motion is the whole operating point: the model's declared initial
/// velocities (the bicycle starts with a lean rate, the sleigh turning) do not leak
/// into it. At 5 m/s the bicycle's eigenvalues are those of Meijaard et al. (2007) as
/// quoted in docs/models.md, plus the neutral forward speed.
#[test]
fn linearize_bicycle_at_its_benchmark_speed() {
    let out = pfaff(&["linearize", "bicycle", "--speed", "5", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
    assert_eq!(v["method"], "generated derivatives");
    assert_eq!(v["operating_point"]["qd"]["phi"].as_f64(), Some(0.0));
    let eig: Vec<(f64, f64)> = v["eigenvalues"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| (e["re"].as_f64().unwrap(), e["im"].as_f64().unwrap()))
        .collect();
    let want = [
        (-14.078_389_692_798_22, 0.0),
        (-0.775_341_882_195_85, -4.464_867_713_788_23),
        (-0.775_341_882_195_85, 4.464_867_713_788_23),
        (-0.322_866_429_004_09, 0.0),
        (0.0, 0.0),
    ];
    assert_eq!(eig.len(), want.len(), "{eig:?}");
    for (g, w) in eig.iter().zip(want) {
        assert!(
            (g.0 - w.0).abs() < 1e-9 && (g.1 - w.1).abs() < 1e-9,
            "{eig:?}"
        );
    }
    let sleigh = pfaff(&["linearize", "sleigh", "--speed", "2", "--json"]);
    let v: Value = serde_json::from_str(&stdout(&sleigh)).unwrap();
    assert_eq!(v["operating_point"]["qd"]["phi"].as_f64(), Some(0.0));
    assert_eq!(v["operating_point"]["qd"]["x"].as_f64(), Some(2.0));
}

#[test]
fn work_precision_table_csv_and_plot() {
    let dir = scratch("work_precision");
    let out = pfaff_in(
        &dir,
        &[
            "work-precision",
            "seed2_example1",
            "--t-end",
            "1",
            "--csv",
            "wp.csv",
            "--plot",
            "wp.svg",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("closed-form"), "{text}");
    for f in ["partitioning", "projection", "baumgarte"] {
        for i in ["rk4", "dopri5", "dop853", "adams", "radau5"] {
            assert!(
                text.lines().any(|l| l.starts_with(f) && l.contains(i)),
                "no {f} {i} row in\n{text}"
            );
        }
    }
    let csv = std::fs::read_to_string(dir.join("wp.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert_eq!(
        header,
        "formulation,method,rtol,error,impact_time_error,rhs_evals,steps,jacobians,repartitions,wall_seconds,failure"
    );
    assert_eq!(csv.lines().count(), 1 + 3 * 5 * 10);
    assert_svg(&dir.join("wp.svg"));
}

#[test]
fn progress_bar_stays_hidden_when_stderr_is_not_a_terminal() {
    // Long enough (well over the 0.3 s before a bar appears) with stderr piped.
    let out = pfaff(&[
        "simulate",
        "pendulum",
        "--t-end",
        "6000",
        "--integrator",
        "dop853",
        "--rtol",
        "1e-10",
        "--atol",
        "1e-12",
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
    assert!(v["stats"]["steps"].as_u64().unwrap() > 0);
    assert_eq!(stderr(&out), "");
}

/// `--json` reports each joint's wrench at the last state; on `slider_crank_bodies` the
/// slider's free-body diagram closes: it moves along x only, so the vertical forces on
/// it (the guide's, the coupler's through `pin_b`, gravity) sum to zero, and the
/// horizontal ones to m3·ẍ3 (Newton's second law; ẍ3 from the report's `qdd`).
#[test]
fn json_reports_joint_reactions_that_balance_on_the_slider() {
    let out = pfaff(&[
        "simulate",
        "slider_crank_bodies",
        "--t-end",
        "0.37",
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
    let fin = &v["final"];
    let joints = &fin["joints"];
    let force = |j: &str, k: usize| joints[j]["first"]["force"][k].as_f64().unwrap();
    // The guide's first frame is the slider; pin_b acts on its second frame (the
    // slider) with the opposite of its force on the coupler.
    let (m3, g) = (0.5, 9.81);
    let xdd3 = fin["qdd"]["x3"].as_f64().unwrap();
    let fy = force("guide", 1) - force("pin_b", 1) - m3 * g;
    let fx = force("guide", 0) - force("pin_b", 0);
    assert!(fy.abs() < 1e-9, "vertical balance {fy:e}");
    assert!((fx - m3 * xdd3).abs() < 1e-9, "{fx} against {}", m3 * xdd3);
    for (name, j) in joints.as_object().unwrap() {
        assert!(j["residual"].as_f64().unwrap() < 1e-9, "{name}: {j}");
    }
    assert!(joints["driver"]["first"].is_null());
    // The text summary lists them too.
    let text = stdout(&pfaff(&[
        "simulate",
        "slider_crank_bodies",
        "--t-end",
        "0.37",
    ]));
    assert!(text.contains("joints") && text.contains("pin_b"), "{text}");
}
