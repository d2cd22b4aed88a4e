//! Standard output and standard error of the commands, written so that a reader that
//! goes away or a full disk never ends a command with a panic (`println!` and
//! `eprintln!` panic on any write error, exit 101 with a backtrace hint).
//!
//! - **stdout** (results: CSV, `table info`, paths written) goes through [`print()`].
//!   A closed pipe (`strata table info T | head -5`) is quiet success: the reader has
//!   what it wanted, the rest of the output is dropped, the command finishes the rest of
//!   its work (output files it writes after stdout are still committed) and exits 0, as
//!   a `head` user expects. (Rust ignores SIGPIPE, so the other convention, dying of the
//!   signal with the shell's status 141, would need libc and would cut those files
//!   short.) Any other write error, such as a full disk (`> /dev/full`), is an error:
//!   `cannot write to standard output: No space left on device`, exit 1.
//! - **stderr** (log lines, warnings, the final error line) goes through
//!   [`eprint_line`], which drops what cannot be written: there is nowhere left to
//!   report it, and the exit status still tells failure from success.

use std::fmt::Display;
use std::io::{self, BufWriter, Write};

use thiserror::Error;

/// Standard output could not be written (other than a closed pipe, which is no error).
#[derive(Debug, Error)]
#[error("cannot write to standard output: {}", os_message(.0))]
pub struct StdoutError(pub io::Error);

/// The message of `e` without std's ` (os error N)` suffix.
fn os_message(e: &io::Error) -> String {
    let s = e.to_string();
    match (e.raw_os_error(), s.rfind(" (os error ")) {
        (Some(_), Some(i)) => s[..i].to_string(),
        _ => s,
    }
}

/// A writer that turns a closed pipe into silence: after the first `BrokenPipe` every
/// write "succeeds" and writes nothing. Other errors pass through.
#[derive(Debug)]
struct PipeTolerant<W> {
    inner: W,
    closed: bool,
}

impl<W: Write> PipeTolerant<W> {
    fn new(inner: W) -> Self {
        PipeTolerant {
            inner,
            closed: false,
        }
    }

    fn filter<T>(&mut self, r: io::Result<T>, dropped: T) -> io::Result<T> {
        match r {
            Err(e) if e.kind() == io::ErrorKind::BrokenPipe => {
                self.closed = true;
                Ok(dropped)
            }
            r => r,
        }
    }
}

impl<W: Write> Write for PipeTolerant<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if self.closed {
            return Ok(buf.len());
        }
        let r = self.inner.write(buf);
        self.filter(r, buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        if self.closed {
            return Ok(());
        }
        let r = self.inner.flush();
        self.filter(r, ())
    }
}

/// Runs `f` on `out` (buffered, a closed pipe silenced) and flushes.
fn print_to<W: Write>(
    out: W,
    f: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), StdoutError> {
    let mut w = BufWriter::new(PipeTolerant::new(out));
    f(&mut w).and_then(|()| w.flush()).map_err(StdoutError)
}

/// Writes a command's results to standard output through `f` (buffered; see the module
/// docs: a closed pipe is quiet success, any other write error a [`StdoutError`]).
pub fn print(f: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> Result<(), StdoutError> {
    print_to(io::stdout().lock(), f)
}

/// Writes `text` to standard output (see [`print()`]).
pub fn print_str(text: &str) -> Result<(), StdoutError> {
    print(|w| w.write_all(text.as_bytes()))
}

/// Prints one line on standard error; a line that cannot be written (a full disk, a
/// closed pipe) is dropped, never a panic.
pub fn eprint_line(line: impl Display) {
    let text = format!("{line}\n");
    let _ = io::stderr().lock().write_all(text.as_bytes());
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Accepts `room` bytes, then fails every write with the OS error `raw`.
    struct Failing {
        room: usize,
        got: Vec<u8>,
        raw: i32,
    }

    impl Write for Failing {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            if self.room == 0 {
                return Err(io::Error::from_raw_os_error(self.raw));
            }
            let n = buf.len().min(self.room);
            self.room -= n;
            self.got.extend_from_slice(&buf[..n]);
            Ok(n)
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    fn lines(w: &mut dyn Write) -> io::Result<()> {
        for i in 0..100_000 {
            writeln!(w, "line {i}")?;
        }
        Ok(())
    }

    /// A closed pipe ends the output quietly; a full disk is one error naming stdout
    /// and the OS's message without the errno suffix.
    #[test]
    fn broken_pipe_is_quiet_and_full_disk_an_error() {
        const EPIPE: i32 = 32;
        const ENOSPC: i32 = 28;
        let mut pipe = Failing {
            room: 10,
            got: Vec::new(),
            raw: EPIPE,
        };
        print_to(&mut pipe, lines).unwrap();
        assert_eq!(pipe.got, b"line 0\nlin");
        let mut full = Failing {
            room: 0,
            got: Vec::new(),
            raw: ENOSPC,
        };
        let e = print_to(&mut full, lines).unwrap_err().to_string();
        assert_eq!(
            e,
            "cannot write to standard output: No space left on device"
        );
    }
}
