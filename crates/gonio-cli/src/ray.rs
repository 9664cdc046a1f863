//! `--ray ADDRESS`: run a command on a Ray cluster through gonio's Python package (`python -m
//! gonio.distributed`, which uses Ray's Python API; docs/distributed.md). The Python is `$GONIO_PYTHON`, else
//! `python3` on the PATH; it must import `gonio.distributed` (`pip install "gonio[ray]"`), which is checked
//! first so that a missing package is one clear error. Ctrl-C reaches the Python process (it cancels the
//! tasks and keeps what was merged); gonio waits for it and exits with its code.

use gonio::Error;
use std::ffi::OsString;
use std::process::{Command, ExitCode};

fn ray_error(message: String) -> Error {
    Error::Spec { at: "--ray".into(), message }
}

/// Run `python -m gonio.distributed --address ADDRESS ARGS…` and exit with its code.
pub fn delegate(address: &str, args: Vec<OsString>) -> Result<ExitCode, Error> {
    let python = std::env::var_os("GONIO_PYTHON").unwrap_or_else(|| "python3".into());
    let shown = python.to_string_lossy().into_owned();
    let probe = Command::new(&python).args(["-c", "import gonio.distributed"]).output().map_err(|e| {
        ray_error(format!("--ray runs gonio's Python package, but `{shown}` cannot be started ({e}); set GONIO_PYTHON to a Python with `pip install \"gonio[ray]\"`"))
    })?;
    if !probe.status.success() {
        let stderr = String::from_utf8_lossy(&probe.stderr);
        let last = stderr.lines().rev().find(|l| !l.trim().is_empty()).unwrap_or("(no message)");
        return Err(ray_error(format!(
            "--ray runs gonio's Python package with Ray (`pip install \"gonio[ray]\"`), but `{shown} -c 'import gonio.distributed'` failed: {last} (set GONIO_PYTHON to choose the Python)"
        )));
    }
    // The terminal's Ctrl-C goes to the whole process group: the Python process handles it; gonio only waits.
    let _ = ctrlc::set_handler(|| {});
    let status = Command::new(&python)
        .args(["-m", "gonio.distributed", "--address", address])
        .args(args)
        .status()
        .map_err(|e| ray_error(format!("cannot start `{shown}`: {e}")))?;
    Ok(ExitCode::from(status.code().map_or(130, |c| u8::try_from(c).unwrap_or(1))))
}
