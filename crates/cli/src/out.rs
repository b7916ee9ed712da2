//! Printing that never panics. `println!` panics when standard output is a
//! closed pipe (`flexmb info SCENE | head -1`: Rust ignores SIGPIPE, so the
//! write fails with BrokenPipe), and `eprintln!` likewise on a closed
//! standard error. Here a failed write to either stream is not an error of
//! the command: the rest of that stream's printout is dropped quietly, the
//! computation goes on, its files are written and the exit code is what it
//! would have been. (Resetting SIGPIPE to its default would instead kill the
//! process at the first print after the reader left, before `simulate` or
//! `static` had written their files.)

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

/// Standard output has failed once (e.g. a closed pipe): print no more.
static STDOUT_GONE: AtomicBool = AtomicBool::new(false);
/// Standard error has failed once.
static STDERR_GONE: AtomicBool = AtomicBool::new(false);

/// Writes `line` and a newline to `stream` unless it has failed before; a
/// failure marks it gone.
fn write_line(mut stream: impl Write, gone: &AtomicBool, line: &str) {
    if gone.load(Ordering::Relaxed) {
        return;
    }
    if writeln!(stream, "{line}")
        .and_then(|_| stream.flush())
        .is_err()
    {
        gone.store(true, Ordering::Relaxed);
    }
}

/// Prints a line on standard output (see the module comment).
pub(crate) fn outln(line: &str) {
    write_line(std::io::stdout().lock(), &STDOUT_GONE, line);
}

/// Prints a line on standard error (see the module comment).
pub(crate) fn errln(line: &str) {
    write_line(std::io::stderr().lock(), &STDERR_GONE, line);
}

/// `println!` that never panics: [`outln`] of the formatted line.
macro_rules! say {
    ($($arg:tt)*) => {
        $crate::out::outln(&format!($($arg)*))
    };
}
pub(crate) use say;
