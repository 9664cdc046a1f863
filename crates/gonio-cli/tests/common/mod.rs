//! What the CLI's integration tests share: running the binary, the checks on its exit, a scratch
//! directory that removes itself, and the small scene the render and error tests vary.
//!
//! Each test file says `mod common;` and uses the part it needs.
#![allow(dead_code)]

use std::ops::Deref;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicUsize, Ordering};

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

/// A 4×4 render of a sphere under a constant sky (`-D res=N` changes the size).
pub const SCENE: &str = r#"<scene version="3.0.0">
    <default name="res" value="4"/>
    <integrator type="path"><integer name="max_depth" value="3"/></integrator>
    <sensor type="perspective">
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="$res"/><integer name="height" value="$res"/></film>
    </sensor>
    <emitter type="constant"/>
    <shape type="sphere"/>
</scene>"#;

/// A fresh directory under the system's temporary directory, removed with everything in it when dropped
/// (also when the test fails: the drop runs during the unwind). Dereferences to its path.
pub struct Scratch(PathBuf);

impl Scratch {
    /// `gonio-cli-test-TAG-PID-N`: unique per process and call, so tests running in parallel never share one.
    pub fn new(tag: &str) -> Scratch {
        static COUNT: AtomicUsize = AtomicUsize::new(0);
        let n = COUNT.fetch_add(1, Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("gonio-cli-test-{tag}-{}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create a scratch directory");
        Scratch(dir)
    }

    /// The path of `name` inside, as a string for a command line.
    pub fn arg(&self, name: &str) -> String {
        self.0.join(name).to_str().expect("a UTF-8 temporary directory").to_string()
    }
}

impl Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
