//! What the CLI's integration tests share: running the binary, the checks on its exit, a scratch
//! directory that removes itself, and the small scene the render and error tests vary.
//!
//! Each test file says `mod common;` and uses the part it needs.
#![allow(dead_code)]

use std::process::{Command, Output};

/// The `gonio` binary of this build.
pub fn gonio_command() -> Command {
    Command::new(env!("CARGO_BIN_EXE_gonio"))
}

/// Run `gonio ARGS` to the end and collect its output.
pub fn gonio(args: &[&str]) -> Output {
    gonio_command().args(args).output().expect("run gonio")
}

/// Exit code 0 (stderr shown otherwise).
pub fn ok(out: &Output) {
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
}

/// `gonio ARGS` failed as bad input must: exit code 2, `expect` on stderr, no panic. Returns stderr.
pub fn assert_bad_input(args: &[&str], expect: &str) -> String {
    let out = gonio(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(stderr.contains(expect), "{args:?}: expected {expect:?} in {stderr:?}");
    stderr
}

/// [`assert_bad_input`], and the message is one line (gonio's own errors; clap's usage errors are longer).
pub fn assert_one_line_error(args: &[&str], expect: &str) {
    let stderr = assert_bad_input(args, expect);
    assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
}

/// A 4×4 render of a sphere under a constant sky (`-D res=N` changes the size); the Python error tests
/// read the same file.
pub const SCENE: &str = include_str!("../data/sphere_sky.xml");

/// A fresh directory under the system's temporary directory, removed with everything in it when dropped.
pub use gonio::scratch::ScratchDir as Scratch;
