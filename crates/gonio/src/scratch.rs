//! A scratch directory for the unit tests: unique per process and use, removed when dropped, so that
//! `cargo test` leaves nothing behind in the system's temporary directory.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// A fresh, empty directory under `std::env::temp_dir()`, deleted with its contents on drop.
#[derive(Debug)]
pub struct ScratchDir(PathBuf);

impl ScratchDir {
    /// A new directory named after `tag`, the process and a counter (tests run in parallel threads).
    pub fn new(tag: &str) -> Self {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("gonio-{tag}-{}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("a scratch directory in the temporary directory");
        ScratchDir(dir)
    }

    /// The directory.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.0
    }

    /// `name` inside the directory.
    #[must_use]
    pub fn join(&self, name: impl AsRef<Path>) -> PathBuf {
        self.0.join(name)
    }
}

impl std::ops::Deref for ScratchDir {
    type Target = Path;

    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for ScratchDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for ScratchDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A file written into its own [`ScratchDir`], removed with it when dropped.
#[derive(Debug)]
pub struct ScratchFile {
    path: PathBuf,
    _dir: ScratchDir,
}

impl ScratchFile {
    /// `contents` written to a file called `name` in a new scratch directory.
    pub fn new(name: &str, contents: &[u8]) -> Self {
        let dir = ScratchDir::new("file");
        let path = dir.join(name);
        std::fs::write(&path, contents).expect("a file in the scratch directory");
        ScratchFile { path, _dir: dir }
    }
}

impl std::ops::Deref for ScratchFile {
    type Target = Path;

    fn deref(&self) -> &Path {
        &self.path
    }
}

impl AsRef<Path> for ScratchFile {
    fn as_ref(&self) -> &Path {
        &self.path
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scratch_directories_are_unique_and_removed() {
        let (a, b) = (ScratchDir::new("scratch"), ScratchDir::new("scratch"));
        assert_ne!(a.path(), b.path());
        std::fs::write(a.join("x.txt"), "x").unwrap();
        let kept = a.path().to_path_buf();
        drop(a);
        assert!(!kept.exists() && b.path().is_dir());
        let f = ScratchFile::new("a.txt", b"abc");
        assert_eq!(std::fs::read(&*f).unwrap(), b"abc");
        let kept = f.to_path_buf();
        drop(f);
        assert!(!kept.exists() && !kept.parent().unwrap().exists());
    }
}
