//! Where the program's output goes: stdout through a writer that turns a closed pipe
//! into a quiet exit, and files written atomically.
//!
//! Standard output: `println!` panics when the reader has gone (`pfaff show
//! parallelogram | head -3`: Rust ignores SIGPIPE, so the write fails with `EPIPE`).
//! Every line of the program goes through [`print`] instead, which reports a closed
//! pipe as [`broken_pipe`]: the program then ends without a message and with status
//! 141, the status a shell reports for a process killed by SIGPIPE (128 + 13), so that
//! `set -o pipefail` scripts see the same as with any other Unix filter.
//!
//! Files: [`write_file`] writes into a temporary file in the target's directory and
//! renames it into place, so a reader never sees half a file and a failed write leaves
//! an existing file as it was.

use std::fmt;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use super::error::{failed, CliError};

/// The exit status of a program whose stdout was closed by its reader (that of a
/// process killed by SIGPIPE).
pub const BROKEN_PIPE_STATUS: u8 = 141;

/// The error of a write to stdout.
fn stdout_error(e: &io::Error) -> CliError {
    if e.kind() == io::ErrorKind::BrokenPipe {
        super::error::broken_pipe()
    } else {
        failed(format!("cannot write to stdout: {e}"))
    }
}

/// Writes `text` to stdout and flushes it.
///
/// # Errors
/// [`super::error::broken_pipe`] when the reader closed the pipe; another write error
/// as a failure.
pub fn print(text: &str) -> Result<(), CliError> {
    let mut o = io::stdout().lock();
    o.write_all(text.as_bytes())
        .and_then(|()| o.flush())
        .map_err(|e| stdout_error(&e))
}

/// Writes the formatted line `args` and a newline to stdout (see [`print`]).
///
/// # Errors
/// As [`print`].
pub fn line(args: fmt::Arguments<'_>) -> Result<(), CliError> {
    print(&format!("{args}\n"))
}

/// Writes `text` to stderr; a failure (stderr closed) is ignored, as there is nowhere
/// left to report it.
pub fn error_line(text: &str) {
    let mut e = io::stderr().lock();
    let _ = writeln!(e, "{text}");
}

/// The outcome of writing several files, each attempted whatever became of the
/// others: every failure but the last is printed on stderr here, the last is returned
/// (to end the program with status 1 and its message).
///
/// # Errors
/// The last failure, of kind `io`.
pub fn failures(mut failures: Vec<CliError>) -> Result<(), CliError> {
    let Some(last) = failures.pop() else {
        return Ok(());
    };
    for e in failures {
        error_line(&format!("pfaff: error: {e}"));
    }
    Err(last.kind("io"))
}

/// The temporary file [`write_file`] writes `path` into: hidden, beside it, named
/// after the process so that two runs do not share one.
fn temporary(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map_or_else(|| "output".into(), |n| n.to_string_lossy().into_owned());
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

/// Writes `path` atomically: `fill` writes the contents into a temporary file in the
/// same directory, which is then renamed onto `path`. On any failure the temporary
/// file is removed and `path` is left as it was.
///
/// # Errors
/// A failure to create, write or rename, as `cannot write `PATH`: REASON`.
pub fn write_file(
    path: &Path,
    fill: impl FnOnce(&mut io::BufWriter<std::fs::File>) -> io::Result<()>,
) -> Result<(), CliError> {
    let err = |e: io::Error| failed(format!("cannot write `{}`: {e}", path.display()));
    if path.is_dir() {
        return Err(err(io::Error::other("it is a directory")));
    }
    let tmp = temporary(path);
    let result = (|| {
        let file = std::fs::File::create(&tmp)?;
        let mut w = io::BufWriter::new(file);
        fill(&mut w)?;
        let file = w.into_inner().map_err(io::IntoInnerError::into_error)?;
        file.sync_all()?;
        drop(file);
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        err(e)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("pfaff-out-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn a_failed_fill_leaves_the_file_and_no_temporary() {
        let d = dir("fill");
        let path = d.join("keep.csv");
        std::fs::write(&path, "old\n").unwrap();
        let e = write_file(&path, |w| {
            w.write_all(b"half")?;
            Err(io::Error::other("interrupted"))
        })
        .unwrap_err();
        assert!(e.to_string().contains("keep.csv"), "{e}");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old\n");
        let left: Vec<_> = std::fs::read_dir(&d).unwrap().collect();
        assert_eq!(left.len(), 1, "{left:?}");
        write_file(&path, |w| w.write_all(b"new\n")).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new\n");
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn a_missing_directory_is_an_error_naming_the_file() {
        let d = dir("missing");
        let path = d.join("no").join("x.csv");
        let e = write_file(&path, |w| w.write_all(b"x")).unwrap_err();
        assert!(e.to_string().contains("x.csv"), "{e}");
        assert_eq!(e.code(), 1);
        let _ = std::fs::remove_dir_all(&d);
    }
}
