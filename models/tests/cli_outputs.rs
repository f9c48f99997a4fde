//! What `pfaff simulate` reports beyond the state (named outputs, `final.qdd`, the
//! initial-state analysis of `--t-end 0`) and the body level of `pfaff show` / `list`,
//! checked against closed forms.

mod common;

use common::{pfaff, pfaff_in, scratch, stderr, stdout};
use serde_json::Value;

fn json(args: &[&str]) -> Value {
    let out = pfaff(args);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    serde_json::from_str(&stdout(&out)).unwrap()
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// docs/theory.md V12: the torque-free body's body-frame angular velocity is
/// $\bar\omega(t) = (\cos 2t, \sin 2t, 2)$.
fn omega(t: f64) -> [f64; 3] {
    [(2.0 * t).cos(), (2.0 * t).sin(), 2.0]
}

#[test]
fn free_body_outputs_follow_the_closed_form_of_v12() {
    let v = json(&[
        "simulate",
        "free_body",
        "--t-end",
        "1",
        "--integrator",
        "dop853",
        "--rtol",
        "1e-11",
        "--atol",
        "1e-13",
        "--json",
    ]);
    let fin = &v["final"]["outputs"];
    let w = omega(1.0);
    // docs/theory.md V12 at t = 1: (-0.416146836547, 0.909297426826, 2).
    for (name, expected) in ["omega_x", "omega_y", "omega_z"].iter().zip(w) {
        let got = num(&fin[*name]);
        assert!((got - expected).abs() < 1e-8, "{name}: {got} vs {expected}");
    }
    // The range along the run (every accepted step): ω̄_x = cos 2t falls from 1 to
    // cos 2, ω̄_z stays 2, ω̄_y = sin 2t stays within [0, 1].
    let r = &v["outputs"];
    assert!((num(&r["omega_x"]["max"]) - 1.0).abs() < 1e-12);
    assert!((num(&r["omega_x"]["min"]) - w[0]).abs() < 1e-8);
    assert!((num(&r["omega_z"]["min"]) - 2.0).abs() < 1e-8);
    assert!((num(&r["omega_z"]["max"]) - 2.0).abs() < 1e-8);
    assert!(num(&r["omega_y"]["min"]).abs() < 1e-12);
    assert!(num(&r["omega_y"]["max"]) <= 1.0 + 1e-8);
    // ω̄_y = sin 2t peaks at 1 (t = π/4); the steps of DOP853 land near but not on it.
    assert!(num(&r["omega_y"]["max"]) > 0.99);
    // The accelerations at the final state: no force, so the centre does not
    // accelerate.
    let qdd = &v["final"]["qdd"];
    for c in ["x", "y", "z"] {
        assert!(num(&qdd[c]).abs() < 1e-12, "{c}: {}", qdd[c]);
    }
}

#[test]
fn csv_has_output_columns_after_the_state() {
    let dir = scratch("outputs_csv");
    let out = pfaff_in(
        &dir,
        &[
            "simulate",
            "free_body",
            "--t-end",
            "1",
            "--integrator",
            "dop853",
            "--rtol",
            "1e-11",
            "--atol",
            "1e-13",
            "--csv",
            "run.csv",
            "--samples",
            "100",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(
        text.contains("omega_x"),
        "the summary prints the outputs:\n{text}"
    );
    let csv = std::fs::read_to_string(dir.join("run.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    // t, 7 coordinates, 7 velocities, then the outputs.
    assert_eq!(header[15..18], ["omega_x", "omega_y", "omega_z"]);
    assert_eq!(header[18], "lambda_body.normalization");
    let mut rows = 0;
    for line in lines {
        let row: Vec<f64> = line.split(',').map(|s| s.parse().unwrap()).collect();
        let w = omega(row[0]);
        for k in 0..3 {
            assert!(
                (row[15 + k] - w[k]).abs() < 1e-8,
                "t = {}: {} vs {}",
                row[0],
                row[15 + k],
                w[k]
            );
        }
        rows += 1;
    }
    assert_eq!(rows, 101);
}

#[test]
fn end_time_zero_analyses_the_initial_state() {
    // The pendulum at rest at angle θ0 from the downward vertical (x = l sin θ0,
    // y = -l cos θ0, l = 1): θ̈ = -(g/l) sin θ0, so ẍ = l cos θ0 θ̈ and ÿ = l sin θ0 θ̈.
    let g = 9.81;
    for (x0, y0) in [(0.6, -0.8), (1.0, 0.0)] {
        let (x, y) = (format!("x={x0}"), format!("y={y0}"));
        let v = json(&[
            "simulate", "pendulum", "--t-end", "0", "--q0", &x, "--q0", &y, "--json",
        ]);
        assert_eq!(v["t_end"], 0.0);
        assert_eq!(v["final"]["t"], 0.0);
        assert_eq!(v["stats"]["steps"], 0);
        let (s, c) = (x0, -y0);
        let thdd = -g * s;
        let qdd = &v["final"]["qdd"];
        let (xdd, ydd) = (num(&qdd["x"]), num(&qdd["y"]));
        assert!((xdd - c * thdd).abs() < 1e-12, "{xdd} vs {}", c * thdd);
        assert!((ydd - s * thdd).abs() < 1e-12, "{ydd} vs {}", s * thdd);
    }
    let out = pfaff(&["simulate", "pendulum", "--t-end", "0"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("0 steps"), "{text}");
    assert!(text.contains("y'' = -9.810000"), "{text}");
}

#[test]
fn show_lists_bodies_joints_points_and_outputs() {
    let out = pfaff(&["show", "slider_crank_bodies"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    let line = |start: &str| {
        text.lines()
            .find(|l| l.trim_start().starts_with(start))
            .unwrap_or_else(|| panic!("no line `{start}` in\n{text}"))
            .to_owned()
    };
    assert!(text.contains("bodies (3):"), "{text}");
    assert!(text.contains("joints (5):"), "{text}");
    assert!(text.contains("points (1):"), "{text}");
    assert!(text.contains("outputs (1):"), "{text}");
    // Masses from the model's parameters (m2 = 0.3 kg; `--set` is not read by show).
    let coupler = line("coupler    mass");
    assert!(coupler.contains("mass 0.3 "), "{coupler}");
    assert!(coupler.contains("frame coupler"), "{coupler}");
    let pin_a = line("pin_a ");
    assert!(pin_a.contains("PlanarRevolute"), "{pin_a}");
    assert!(pin_a.contains("crank - coupler"), "{pin_a}");
    assert!(
        pin_a.contains("holonomic rows: pin_a.x pin_a.y;"),
        "{pin_a}"
    );
    let guide = line("guide ");
    assert!(guide.contains("slider - ground"), "{guide}");
    assert!(line("tip ").contains("in frame crank"));
    assert!(line("slider_x ").contains("Position of the slider"));
    // A model written with coordinates has none of these.
    let text = stdout(&pfaff(&["show", "pendulum"]));
    for needle in ["bodies (0):", "joints (0):", "points (0):", "outputs (0):"] {
        assert!(text.contains(needle), "missing `{needle}` in\n{text}");
    }
}

#[test]
fn list_counts_bodies_and_joints() {
    let text = stdout(&pfaff(&["list"]));
    let cols = |name: &str| -> Vec<String> {
        let l = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .unwrap_or_else(|| panic!("`{name}` not listed"));
        l.split_whitespace().map(str::to_owned).collect()
    };
    assert!(text.lines().next().unwrap().contains("bodies joints"));
    // model nq hol nhol contacts t_end bodies joints
    assert_eq!(cols("slider_crank_bodies")[6..8], ["3", "5"]);
    assert_eq!(cols("sleigh_bodies")[6..8], ["1", "1"]);
    assert_eq!(cols("free_body")[6..8], ["1", "0"]);
    assert_eq!(cols("pendulum")[6..8], ["0", "0"]);
}
