//! Errors of the program and how they reach the user: one line on stderr and an exit
//! code (2 for bad input, 1 for a failed computation or an I/O error).

use std::fmt;

/// A failure of the program.
#[derive(Debug)]
pub enum CliError {
    /// The input is wrong: unknown names, malformed values, impossible options.
    Usage(String),
    /// A computation or a file operation failed.
    Failed(String),
}

impl CliError {
    /// The process exit code.
    pub fn code(&self) -> u8 {
        match self {
            Self::Usage(_) => 2,
            Self::Failed(_) => 1,
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Usage(m) | Self::Failed(m) => f.write_str(m),
        }
    }
}

/// A usage error.
pub fn usage(message: impl Into<String>) -> CliError {
    CliError::Usage(message.into())
}

/// A failure.
pub fn failed(message: impl Into<String>) -> CliError {
    CliError::Failed(message.into())
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
