//! Standard output for every command. [`out!`] and [`outln!`] write like `print!` and `println!`, which
//! panic when the write fails: `gonio check --all | head -1` printed `failed printing to stdout: Broken
//! pipe` with a panic message once `head` had its line (2026-11, issue 8). Here a reader that closed the
//! pipe ends gonio quietly with [`CLOSED_STDOUT`], and any other failure (a full disk behind `>`) is one
//! `gonio: error:` line with exit code 2. `#![deny(clippy::print_stdout)]` in `main.rs` keeps `println!`
//! out of the binary.

use std::io::{self, Write};

/// The exit code when the reader closed standard output: 128 + SIGPIPE (13), the status a shell reports
/// for a program stopped by the signal, as C programs are.
pub const CLOSED_STDOUT: i32 = 141;

/// Write formatted text to standard output; on a closed pipe exit quietly, on another error exit with
/// one line on stderr. Use through [`out!`] and [`outln!`].
pub fn write(args: std::fmt::Arguments, newline: bool) {
    let mut out = io::stdout().lock();
    let result = out.write_fmt(args).and_then(|()| if newline { out.write_all(b"\n") } else { Ok(()) });
    if let Err(e) = result {
        if e.kind() == io::ErrorKind::BrokenPipe {
            std::process::exit(CLOSED_STDOUT);
        }
        eprintln!("gonio: error: cannot write to standard output: {e}");
        std::process::exit(2);
    }
}

/// `print!` that ends gonio quietly when standard output is closed (see the module doc).
macro_rules! out {
    ($($arg:tt)*) => { $crate::stdout::write(format_args!($($arg)*), false) };
}

/// `println!` that ends gonio quietly when standard output is closed (see the module doc).
macro_rules! outln {
    () => { $crate::stdout::write(format_args!(""), true) };
    ($($arg:tt)*) => { $crate::stdout::write(format_args!($($arg)*), true) };
}

pub(crate) use {out, outln};
