//! Outputs that lose nothing: the files of `pfaff simulate` are written atomically and
//! independently, a run that computed nothing leaves existing files alone, and a reader
//! that closes stdout early ends the program quietly (status 141) in every command.

mod common;

use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};

use common::{assert_svg, pfaff_in, scratch, stderr, stdout};
use serde_json::Value;

/// The files left in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Runs `pfaff args` in `dir` with stdout a pipe whose reader is closed as soon as the
/// program has started, and returns its exit status and stderr. The reader is closed
/// right after the spawn, before the program has set up; should the program still
/// have written everything first (a loaded machine), the run is repeated: a closed
/// pipe must be met at least once in ten tries.
fn closed_stdout(dir: &Path, args: &[&str]) -> (i32, String) {
    std::fs::create_dir_all(dir).unwrap();
    for _ in 0..10 {
        let mut child = Command::new(env!("CARGO_BIN_EXE_pfaff"))
            .args(args)
            .current_dir(dir)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("the pfaff binary runs");
        drop(child.stdout.take());
        let mut err = String::new();
        child
            .stderr
            .take()
            .unwrap()
            .read_to_string(&mut err)
            .unwrap();
        let status = child.wait().unwrap();
        assert!(
            !err.contains("panicked") && !err.contains("Broken pipe"),
            "{args:?}: {err}"
        );
        let code = status.code().expect("an exit status, not a signal");
        if code != 0 {
            return (code, err);
        }
    }
    panic!("{args:?}: the program wrote all its output before the reader closed, ten times");
}

#[test]
fn every_command_ends_quietly_when_its_reader_closes_stdout() {
    let dir = scratch("closed_stdout");
    let commands: &[&[&str]] = &[
        &[],
        &["list"],
        &["show", "parallelogram"],
        &["simulate", "pendulum"],
        &["simulate", "pendulum", "--json"],
        &["simulate", "pendulum", "--csv", "p.csv", "--plot", "p.svg"],
        &["linearize", "pendulum"],
        &["linearize", "pendulum", "--json"],
        &["rhs-time", "pendulum", "--calls", "10", "--batches", "1"],
        &[
            "rhs-time",
            "pendulum",
            "--calls",
            "10",
            "--batches",
            "1",
            "--json",
        ],
        &["work-precision", "seed2_example1", "--t-end", "0.1"],
        // A usage error with --json prints its JSON object on stdout.
        &["simulate", "no_such_model", "--json"],
    ];
    for args in commands {
        let (code, err) = closed_stdout(&dir, args);
        assert_eq!(code, 141, "{args:?}: {err}");
        assert!(err.is_empty(), "{args:?}: a message on stderr: {err}");
    }
    // The files of the run were still written, whole.
    assert_svg(&dir.join("p.svg"));
    let csv = std::fs::read_to_string(dir.join("p.csv")).unwrap();
    assert!(csv.starts_with("t,x,y,"), "{}", &csv[..40.min(csv.len())]);
}

#[test]
fn a_run_that_computed_nothing_leaves_existing_files_alone() {
    let dir = scratch("computed_nothing");
    let old = [
        ("keep.csv", "t,x\n0,1\n"),
        ("keep.svg", "<svg>old</svg>\n"),
        ("keep.html", "<html>old</html>\n"),
    ];
    for (name, text) in old {
        std::fs::write(dir.join(name), text).unwrap();
    }
    for json in [false, true] {
        let mut args = vec![
            "simulate",
            "pendulum",
            "--set",
            "m=0",
            "--csv",
            "keep.csv",
            "--plot",
            "keep.svg",
            "--animate",
            "keep.html",
        ];
        if json {
            args.push("--json");
        }
        let out = pfaff_in(&dir, &args);
        assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
        if json {
            let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
            assert!(v["error"]["kind"].is_string(), "{v}");
            assert!(stderr(&out).contains("no file written"), "{}", stderr(&out));
        } else {
            assert!(stdout(&out).contains("no file written"), "{}", stdout(&out));
        }
        for (name, text) in old {
            assert_eq!(std::fs::read_to_string(dir.join(name)).unwrap(), text);
        }
        // No temporary file left behind.
        assert_eq!(listing(&dir), ["keep.csv", "keep.html", "keep.svg"]);
    }
}

#[test]
fn an_unwritable_output_is_reported_and_the_others_are_written() {
    let dir = scratch("unwritable");
    let bad = dir.join("no_such_directory").join("x.csv");
    let bad = bad.to_str().unwrap();
    let out = pfaff_in(
        &dir,
        &[
            "simulate",
            "pendulum",
            "--csv",
            bad,
            "--plot",
            "p.svg",
            "--animate",
            "a.html",
        ],
    );
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("cannot write") && err.contains("x.csv"),
        "{err}"
    );
    let text = stdout(&out);
    // The summary, and the files that were written.
    assert!(text.contains("energy"), "{text}");
    assert!(text.contains("plot         p.svg"), "{text}");
    assert!(text.contains("animation    a.html"), "{text}");
    assert!(!text.contains("x.csv"), "{text}");
    assert_svg(&dir.join("p.svg"));
    let html = std::fs::read_to_string(dir.join("a.html")).unwrap();
    assert!(html.contains("pfaff-trajectory") && html.trim_end().ends_with("</html>"));

    // Two unwritable files: both are reported, the one that can be written is.
    let bad_svg = dir.join("no_such_directory").join("y.svg");
    let out = pfaff_in(
        &dir,
        &[
            "simulate",
            "pendulum",
            "--csv",
            bad,
            "--plot",
            bad_svg.to_str().unwrap(),
            "--animate",
            "b.html",
            "--json",
        ],
    );
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(err.contains("x.csv") && err.contains("y.svg"), "{err}");
    let v: Value = serde_json::from_str(&stdout(&out)).unwrap();
    assert_eq!(v["error"]["kind"], "io", "{v}");
    assert!(v["final"]["q"]["x"].is_f64(), "{v}");
    assert!(dir.join("b.html").is_file());
    assert_eq!(listing(&dir), ["a.html", "b.html", "p.svg"]);
}
