//! Helpers shared by the tests of the `pfaff` binary (`tests/common/`, not a test target).

#![allow(dead_code)] // each test binary uses a subset

use std::path::PathBuf;
use std::process::{Command, Output};

/// Runs the built `pfaff` with `args` in `dir` (created if needed).
pub fn pfaff_in(dir: &std::path::Path, args: &[&str]) -> Output {
    std::fs::create_dir_all(dir).unwrap();
    Command::new(env!("CARGO_BIN_EXE_pfaff"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the pfaff binary runs")
}

/// Runs the built `pfaff` with `args` in a shared scratch directory (for commands that
/// write no files).
pub fn pfaff(args: &[&str]) -> Output {
    pfaff_in(
        &PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli"),
        args,
    )
}

/// A fresh scratch directory for one test.
pub fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("cli")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).unwrap()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8(o.stderr.clone()).unwrap()
}

/// Checks that `path` holds an SVG document with drawn lines.
pub fn assert_svg(path: &std::path::Path) {
    let svg = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(svg.starts_with("<svg"), "{}", &svg[..svg.len().min(80)]);
    assert!(svg.trim_end().ends_with("</svg>"));
    assert!(
        svg.contains("<polyline"),
        "no curve drawn in {}",
        path.display()
    );
}
