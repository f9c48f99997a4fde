//! The `pfaff` binary at the extremes (issue 9): parameters far from the defaults, step
//! sizes and tolerances the time cannot honour, redundant constraints, failed runs, and
//! `--json` for every exit code. One test per case of the table.

mod common;

use common::{pfaff, stderr, stdout};
use serde_json::Value;

/// Runs `args` with `--json` and returns the exit code and the one object on stdout.
fn json(args: &[&str]) -> (Option<i32>, Value) {
    let mut all = args.to_vec();
    all.push("--json");
    let out = pfaff(&all);
    let text = stdout(&out);
    assert_eq!(text.trim().lines().count(), 1, "{args:?}: {text:?}");
    let v: Value = serde_json::from_str(&text)
        .unwrap_or_else(|e| panic!("{args:?}: stdout is not JSON ({e}): {text}"));
    assert!(v.is_object(), "{args:?}: {v}");
    (out.status.code(), v)
}

fn final_q(v: &Value, name: &str) -> f64 {
    v["final"]["q"][name].as_f64().unwrap()
}

/// The mass cancels out of the pendulum: masses of 1e-6, 1 and 1e6 kg give the same
/// motion (they failed at t = 0 above 1e5 kg: an absolute pivot threshold).
#[test]
fn pendulum_mass_cancels_at_every_scale() {
    let base = json(&["simulate", "pendulum", "--t-end", "2"]);
    assert_eq!(base.0, Some(0), "{}", base.1);
    for m in ["1e-6", "1e6", "1e9"] {
        let (code, v) = json(&[
            "simulate",
            "pendulum",
            "--t-end",
            "2",
            "--set",
            &format!("m={m}"),
        ]);
        assert_eq!(code, Some(0), "m = {m}: {v}");
        for c in ["x", "y"] {
            let (a, b) = (final_q(&base.1, c), final_q(&v, c));
            assert!((a - b).abs() < 1e-9, "m = {m}, {c}: {a} vs {b}");
        }
    }
}

/// Linearized about hanging at rest, the pendulum of 1e8 kg has the eigenvalues
/// ±i√(g/l) of every pendulum (it failed with "the mass matrix is singular").
#[test]
fn heavy_pendulum_linearizes() {
    let (code, v) = json(&["linearize", "pendulum", "--set", "m=1e8"]);
    assert_eq!(code, Some(0), "{v}");
    let im = v["eigenvalues"][1]["im"].as_f64().unwrap();
    assert!((im - 9.81f64.sqrt()).abs() < 1e-6, "{im}");
}

/// A 1 km pendulum: the residual of `x² + y² − l²` cannot fall below the rounding of
/// l² = 1e6, and the Newton test is relative to it (it failed with residual 1.2e-10).
#[test]
fn long_pendulum_runs() {
    let (code, v) = json(&["simulate", "pendulum", "--set", "l=1e3"]);
    assert_eq!(code, Some(0), "{v}");
    let (x, y) = (final_q(&v, "x"), final_q(&v, "y"));
    assert!(
        ((x * x + y * y).sqrt() - 1e3).abs() < 1e-9 * 1e3,
        "{x}, {y}"
    );
}

/// The parallelogram's third crank is redundant: it simulates under every formulation
/// and linearizes (both exited 2 on an "impossible prescription" nobody had made).
#[test]
fn parallelogram_simulates_and_linearizes() {
    for f in ["partitioning", "projection", "baumgarte"] {
        let (code, v) = json(&["simulate", "parallelogram", "--formulation", f]);
        assert_eq!(code, Some(0), "{f}: {v}");
        // The cranks stay parallel.
        let (a, b) = (final_q(&v, "th1"), final_q(&v, "th3"));
        assert!((a - b).abs() < 1e-8, "{f}: {a} vs {b}");
    }
    let out = pfaff(&["simulate", "parallelogram"]);
    let text = stdout(&out);
    assert!(text.contains("(1 degree of freedom)"), "{text}");
    let (code, v) = json(&["linearize", "parallelogram"]);
    assert_eq!(code, Some(0), "{v}");
    assert_eq!(v["states"].as_array().unwrap().len(), 2, "{v}");
}

/// A run that fails midway: the slider-crank with a coupler shorter than its crank
/// (`--set b=0.09`, `a = 0.1`) locks up where the driven crank asks for a configuration
/// that does not exist: the loop closes only while $|a \sin\varphi_1| \le b$, so at
/// $\varphi_1 = \arcsin(b/a)$ (the crank reaches it at $t = (\arcsin 0.9 - \pi/6)/10$,
/// from its drive $\varphi_1 = \pi/6 + 10t$) $C_q$ loses rank and the run must stop.
/// For each formulation the text summary says where it stopped and shows the state
/// there, and the JSON agrees (the summary used to say "stopped at 0 s" and show the
/// initial state; projection's last state was lost when its projection failed there).
/// (The isosceles crank, `b = a`, used here before, folds with the slider at the pivot
/// and continues on the branch $x_3 = 2a\cos\varphi_1$ with every formulation since
/// the velocities of partitioning are projected in one solve.)
#[test]
fn failed_run_reports_where_it_stopped() {
    let lock = (0.9_f64.asin() - std::f64::consts::PI / 6.0) / 10.0;
    for method in [
        ["--integrator", "dop853"],
        ["--formulation", "projection"],
        ["--formulation", "baumgarte"],
    ] {
        let mut args = vec![
            "simulate",
            "slider_crank",
            "--set",
            "b=0.09",
            "--t-end",
            "2",
        ];
        args.extend(method);
        let out = pfaff(&args);
        assert_eq!(out.status.code(), Some(1), "{method:?}: {}", stderr(&out));
        let text = stdout(&out);
        let line = text
            .lines()
            .find(|l| l.starts_with("stopped at   t = "))
            .unwrap_or_else(|| panic!("{method:?}: no state at the stop in\n{text}"));
        let t: f64 = line["stopped at   t = ".len()..]
            .split(':')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        assert!(
            (t - lock).abs() < 1e-5,
            "{method:?}: {line}, lock-up at {lock}"
        );
        assert!(text.contains(&format!(", stopped at {t} s")), "{text}");
        let (code, v) = json(&args);
        assert_eq!(code, Some(1));
        assert_eq!(v["error"]["stopped_at"].as_f64(), Some(t), "{v}");
        assert_eq!(v["final"]["t"].as_f64(), Some(t), "{v}");
        let phi1 = final_q(&v, "phi1");
        assert!(
            (phi1 - 0.9_f64.asin()).abs() < 1e-4,
            "{method:?}: phi1 {phi1}"
        );
    }
}

/// A first step of 1e-20 s, which the time cannot resolve, is raised with a note, and
/// every adaptive integrator completes (they stopped at the first re-partition).
#[test]
fn tiny_first_step_is_raised_with_a_note() {
    for i in ["adams", "dopri5", "dop853"] {
        let out = pfaff(&["simulate", "pendulum", "--step", "1e-20", "--integrator", i]);
        assert!(out.status.success(), "{i}: {}", stderr(&out));
        let text = stdout(&out);
        assert!(
            text.contains("note         --step 1e-20 is below the smallest step"),
            "{i}: {text}"
        );
    }
}

/// rtol above 1 asks for no correct digit: refused (it ran a million attempts at t = 0).
#[test]
fn rtol_above_one_is_refused() {
    let out = pfaff(&["simulate", "pendulum", "--rtol", "1e150"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("expected at most 1"),
        "{}",
        stderr(&out)
    );
    let (code, v) = json(&["simulate", "pendulum", "--rtol", "2"]);
    assert_eq!(code, Some(2));
    assert_eq!(v["error"]["kind"], "usage", "{v}");
}

/// With `--json`, stdout is one object for bad input, an unknown flag, a failed
/// assembly, a failed run and a write error, each with an `error` entry.
#[test]
fn json_is_one_object_for_every_exit_code() {
    let cases: [(&[&str], i32, &str); 11] = [
        (&["simulate", "pendulum", "--set", "zz=1"], 2, "usage"),
        (&["simulate", "pendulum", "--bogus"], 2, "usage"),
        (&["linearize", "pendulum", "--set", "zz=1"], 2, "usage"),
        (
            &["simulate", "pendulum", "--qd0", "x=1", "--qd0", "y=1"],
            2,
            "assembly",
        ),
        (
            &["simulate", "pendulum", "--set", "m=0"],
            1,
            "singular_mass",
        ),
        (
            &["simulate", "pendulum", "--csv", "/nonexistent/dir/a.csv"],
            1,
            "io",
        ),
        // A ball started half a metre into its floor, and a floor raised into the
        // double pendulum's tip (it was impacts, a resting contact and a Newton
        // failure that said every residual was within the tolerance).
        (
            &["simulate", "bouncing_ball", "--q0", "y=-0.5"],
            1,
            "initial_penetration",
        ),
        (
            &["simulate", "pendulum_floor", "--set", "depth=1.6"],
            1,
            "initial_penetration",
        ),
        // A negative mass or moment of inertia: a kinetic energy negative along the
        // constraints (the runs went on, the pendulum's motion unchanged and its
        // energy of the wrong sign).
        (
            &["simulate", "pendulum", "--set", "m=-1"],
            1,
            "negative_mass",
        ),
        (
            &["simulate", "andrews", "--set", "i1=-1"],
            1,
            "negative_mass",
        ),
        (
            &["simulate", "free_body", "--set", "izz=-1"],
            1,
            "negative_mass",
        ),
    ];
    for (args, code, kind) in cases {
        let (found, v) = json(args);
        assert_eq!(found, Some(code), "{args:?}: {v}");
        assert_eq!(v["error"]["kind"], kind, "{args:?}: {v}");
        assert!(v["error"]["message"]
            .as_str()
            .is_some_and(|m| !m.is_empty()));
    }
}

/// A massless pendulum: the failure names the coordinate whose acceleration is
/// undetermined, and the summary does not claim that energy is not conserved.
#[test]
fn massless_pendulum_names_the_coordinate() {
    let out = pfaff(&["simulate", "pendulum", "--set", "m=0"]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("coordinates involved: [\"y\"]"), "{err}");
    let text = stdout(&out);
    assert!(!text.contains("not conserved"), "{text}");
    assert!(text.contains("energy       not computed"), "{text}");
}

/// Linearized about a state given with --q0, the label says so (it said "hanging at
/// rest" with the bob horizontal).
#[test]
fn linearize_label_names_the_given_state() {
    let out = pfaff(&["linearize", "pendulum", "--q0", "x=1", "--q0", "y=0"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(!text.contains("hanging at rest"), "{text}");
    assert!(
        text.contains("linearized about the state given by x = 1, y = 0"),
        "{text}"
    );
    let (_, v) = json(&["linearize", "pendulum"]);
    assert_eq!(v["operating_point"]["about"], "hanging at rest", "{v}");
    assert_eq!(v["operating_point"]["q"]["y"], -1.0, "{v}");
}

/// Times far below a second or far above are written in exponent form in the summary
/// and in the errors: `--t-end 1e-300` printed 300 zeros twice, and an error at
/// 7.6e-12 s read `t = 0.000000000007612119398285161`.
#[test]
fn tiny_and_huge_times_are_written_with_an_exponent() {
    let out = pfaff(&["simulate", "pendulum", "--t-end", "1e-300"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("span         0 to 1e-300 s"), "{text}");
    assert!(text.contains("final        t = 1e-300:"), "{text}");
    assert!(!text.contains(&"0".repeat(20)), "{text}");
    // An ordinary span stays as written.
    let out = pfaff(&["simulate", "pendulum", "--t-end", "3"]);
    assert!(
        stdout(&out).contains("span         0 to 3 s"),
        "{}",
        stdout(&out)
    );
    // The zero-length pendulum fails within the first microsecond: its error's time.
    let out = pfaff(&["simulate", "pendulum", "--set", "l=0"]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("e-"), "{err}");
    assert!(!err.contains("t = 0.0000"), "{err}");
}
