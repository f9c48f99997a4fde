//! Errors of the program and how they reach the user: one line on stderr and an exit
//! code (2 for bad input, 1 for a failed computation or an I/O error), and with
//! `--json` one object on stdout (see [`CliError::json`]).

use std::fmt;

use serde_json::{json, Value};

/// A failure of the program.
#[derive(Debug)]
pub struct CliError {
    code: u8,
    kind: &'static str,
    message: String,
    /// The command already printed its JSON object (with this error in it).
    reported: bool,
}

impl CliError {
    /// The process exit code.
    pub fn code(&self) -> u8 {
        self.code
    }

    /// The same error with another `kind` for the JSON report.
    #[must_use]
    pub fn kind(mut self, kind: &'static str) -> Self {
        self.kind = kind;
        self
    }

    /// Marks the error as already reported in the JSON object on stdout.
    #[must_use]
    pub fn reported(mut self) -> Self {
        self.reported = true;
        self
    }

    /// Whether the JSON object on stdout already carries the error.
    pub fn is_reported(&self) -> bool {
        self.reported
    }

    /// Whether stdout was closed by its reader: the program ends quietly.
    pub fn is_broken_pipe(&self) -> bool {
        self.kind == "broken_pipe"
    }

    /// The `error` entry of a JSON report: `kind` and `message`.
    pub fn entry(&self) -> Value {
        json!({"kind": self.kind, "message": self.message})
    }

    /// The whole JSON report of a command that failed before it had anything else to
    /// say: `{"error": {"kind", "message"}}`.
    pub fn json(&self) -> Value {
        json!({"error": self.entry()})
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

/// A usage error (exit code 2, kind `usage`).
pub fn usage(message: impl Into<String>) -> CliError {
    CliError {
        code: 2,
        kind: "usage",
        message: message.into(),
        reported: false,
    }
}

/// A failure (exit code 1, kind `failed`).
pub fn failed(message: impl Into<String>) -> CliError {
    CliError {
        code: 1,
        kind: "failed",
        message: message.into(),
        reported: false,
    }
}

/// Stdout closed by its reader (`pfaff list | head -1`): the program ends without a
/// message, with the status of a process killed by SIGPIPE (see `out`).
pub fn broken_pipe() -> CliError {
    CliError {
        code: super::out::BROKEN_PIPE_STATUS,
        kind: "broken_pipe",
        message: "stdout was closed".to_owned(),
        reported: true,
    }
}

/// `", did you mean `x`?"` when one of `candidates` is close to `name` (edit distance at
/// most a third of the length, at least 1), else an empty string.
pub fn suggestion<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> String {
    let limit = (name.chars().count() / 3).max(1);
    candidates
        .into_iter()
        .map(|c| (distance(name, c), c))
        .filter(|&(d, _)| d <= limit)
        // Ties go to the longest common prefix (`c1` is nearer `c0` than `m1`).
        .min_by_key(|&(d, c)| (d, usize::MAX - prefix(name, c)))
        .map(|(_, c)| format!(", did you mean `{c}`?"))
        .unwrap_or_default()
}

fn prefix(a: &str, b: &str) -> usize {
    a.chars().zip(b.chars()).take_while(|(x, y)| x == y).count()
}

/// Levenshtein distance.
fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggests_near_names() {
        assert_eq!(distance("andrew", "andrews"), 1);
        assert_eq!(
            suggestion("andrew", ["pendulum", "andrews"]),
            ", did you mean `andrews`?"
        );
        assert_eq!(suggestion("zzz", ["pendulum", "andrews"]), "");
        assert_eq!(suggestion("c1", ["m1", "c0"]), ", did you mean `c0`?");
        assert_eq!(suggestion("c", ["c0", "m1"]), ", did you mean `c0`?");
    }
}
