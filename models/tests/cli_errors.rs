//! Bad input to the `pfaff` binary: one clear line on stderr and exit code 2.

mod common;

use common::{pfaff, stderr, stdout};

/// Runs `args`, checks exit code 2, empty stdout and a one-line error; returns it.
fn bad(args: &[&str]) -> String {
    let out = pfaff(args);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(stdout(&out), "", "{args:?}");
    assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
    assert!(err.starts_with("pfaff: error: "), "{err}");
    err
}

#[test]
fn unknown_model_suggests_the_near_name() {
    let err = bad(&["simulate", "andrew"]);
    assert!(
        err.contains("unknown model `andrew`, did you mean `andrews`?"),
        "{err}"
    );
    let err = bad(&["show", "pendlum"]);
    assert!(err.contains("did you mean `pendulum`?"), "{err}");
    let err = bad(&["linearize", "nothing_like_it"]);
    assert!(
        err.contains("unknown model `nothing_like_it`") && !err.contains("did you mean"),
        "{err}"
    );
    bad(&["work-precision", "andrew"]);
}

#[test]
fn unknown_parameter_suggests_the_near_name() {
    let err = bad(&["simulate", "pendulum", "--set", "lenght=2"]);
    assert!(err.contains("unknown parameter `lenght`"), "{err}");
    let err = bad(&["simulate", "andrews", "--set", "c1=4000"]);
    assert!(err.contains("did you mean `c0`?"), "{err}");
    let err = bad(&["linearize", "sleigh", "--set", "ix=1"]);
    assert!(err.contains("did you mean `ic`?"), "{err}");
}

#[test]
fn unknown_coordinate() {
    let err = bad(&["simulate", "sleigh", "--q0", "ph=1"]);
    assert!(
        err.contains("unknown coordinate `ph`") && err.contains("`phi`"),
        "{err}"
    );
    bad(&["simulate", "sleigh", "--qd0", "z=1"]);
}

#[test]
fn malformed_assignment() {
    let err = bad(&["simulate", "pendulum", "--set", "l"]);
    assert!(err.contains("expected NAME=VALUE"), "{err}");
    let err = bad(&["simulate", "pendulum", "--set", "l=two"]);
    assert!(err.contains("not a finite number"), "{err}");
    bad(&["simulate", "pendulum", "--q0", "=1"]);
}

#[test]
fn negative_or_invalid_numbers() {
    let err = bad(&["simulate", "pendulum", "--rtol", "-1e-6"]);
    assert!(err.contains("--rtol"), "{err}");
    let err = bad(&["simulate", "pendulum", "--atol", "-1"]);
    assert!(err.contains("--atol"), "{err}");
    bad(&["simulate", "pendulum", "--rtol", "0"]);
    bad(&["simulate", "pendulum", "--rtol", "abc"]);
    bad(&[
        "simulate",
        "pendulum",
        "--integrator",
        "rk4",
        "--step",
        "-0.1",
    ]);
    let err = bad(&[
        "simulate",
        "pendulum",
        "--samples",
        "100000000",
        "--csv",
        "x.csv",
    ]);
    assert!(err.contains("--samples 100000000"), "{err}");
    let err = bad(&["simulate", "pendulum", "--atol", "0"]);
    assert!(err.contains("--atol 0: expected a positive"), "{err}");
    let err = bad(&["simulate", "pendulum", "--repeat", "0"]);
    assert!(err.contains("--repeat 0"), "{err}");
    let err = bad(&["rhs-time", "pendulum", "--calls", "0"]);
    assert!(err.contains("--calls 0"), "{err}");
    bad(&["rhs-time", "andrew"]);
}

#[test]
fn end_time_before_the_start() {
    let err = bad(&["simulate", "pendulum", "--t-end", "-1"]);
    assert!(
        err.contains("--t-end -1 is before the start time 0"),
        "{err}"
    );
    // `--t-end 0` is valid: it analyses the initial state (tests/cli_outputs.rs).
    bad(&["work-precision", "pendulum", "--t-end", "-2"]);
    // Not a number is not a time, rather than a time before the start.
    for command in ["simulate", "work-precision"] {
        let err = bad(&[command, "pendulum", "--t-end", "NaN"]);
        assert!(err.contains("--t-end NaN is not a finite time"), "{err}");
    }
}

#[test]
fn unknown_choices_and_flags() {
    let err = bad(&["simulate", "pendulum", "--integrator", "adam"]);
    assert!(err.contains("adams"), "{err}");
    bad(&["simulate", "pendulum", "--formulation", "penalty"]);
    bad(&["simulate", "pendulum", "--bogus"]);
    bad(&["frobnicate"]);
    bad(&["simulate"]);
}

#[test]
fn speed_only_for_steady_motions() {
    let err = bad(&["linearize", "pendulum", "--speed", "1"]);
    assert!(err.contains("--speed"), "{err}");
}

#[test]
fn impossible_prescription() {
    // Both velocities of the pendulum cannot be prescribed against the link.
    let err = bad(&["simulate", "pendulum", "--qd0", "x=1", "--qd0", "y=1"]);
    assert!(err.contains("cannot assemble"), "{err}");
}

#[test]
fn help_succeeds() {
    let out = pfaff(&["--help"]);
    assert!(out.status.success());
    let text = stdout(&out);
    for cmd in ["list", "show", "simulate", "linearize", "work-precision"] {
        assert!(text.contains(cmd), "{text}");
    }
    let out = pfaff(&["simulate", "--help"]);
    assert!(out.status.success() && stdout(&out).contains("--formulation"));
}
