//! The file-system steps of a commit that must reach the disk in order:
//! `fsync` of files, of folders (bottom up) and of directories (their
//! entries: creations, renames, removals), and the renames and removals
//! themselves.
//!
//! Every step of [`super::write_atomically`] and of
//! [`super::OutputTransaction::commit`] goes through these functions; in
//! tests they also append to a per-thread log ([`record`]), so that the
//! order of the steps is checked, not only their outcome.

use std::path::Path;

/// Flushes the contents of the regular file `path` to the disk.
pub(crate) fn sync_file(path: &Path) -> std::io::Result<()> {
    record::step(record::Step::SyncFile, path);
    // Unix flushes through any descriptor (read-only works for a file a
    // strict umask made unwritable); Windows only through one that may write.
    std::fs::OpenOptions::new()
        .read(cfg!(unix))
        .write(!cfg!(unix))
        .open(path)?
        .sync_all()
}

/// Flushes the entries of the directory `dir` (names created, renamed or
/// removed in it) to the disk. A file system that cannot flush a directory
/// (it answers `EINVAL`, as some network file systems do) is taken as done;
/// on systems other than Unix, where a directory cannot be opened as a
/// file, this does nothing.
pub(crate) fn sync_dir(dir: &Path) -> std::io::Result<()> {
    record::step(record::Step::SyncDir, dir);
    #[cfg(unix)]
    {
        const EINVAL: i32 = 22;
        match std::fs::File::open(dir).and_then(|d| d.sync_all()) {
            Err(e) if e.raw_os_error() == Some(EINVAL) || e.kind() == std::io::ErrorKind::Unsupported => Ok(()),
            other => other,
        }
    }
    #[cfg(not(unix))]
    Ok(())
}

/// Flushes a folder output's staging folder: every file in it, every
/// folder below it (bottom up), then the folder itself.
pub(crate) fn sync_tree(path: &Path) -> std::io::Result<()> {
    let meta = std::fs::symlink_metadata(path)?;
    if meta.is_file() {
        return sync_file(path);
    }
    if !meta.is_dir() {
        return Ok(());
    }
    for entry in std::fs::read_dir(path)? {
        sync_tree(&entry?.path())?;
    }
    sync_dir(path)
}

/// Renames `from` to `to` (one directory, one file system).
pub(crate) fn rename(from: &Path, to: &Path) -> std::io::Result<()> {
    record::step(record::Step::Rename, from);
    #[cfg(test)]
    if record::fails(from) {
        return Err(std::io::Error::other("simulated failure"));
    }
    std::fs::rename(from, to)
}

/// Removes the file `path`.
pub(crate) fn remove_file(path: &Path) -> std::io::Result<()> {
    record::step(record::Step::Remove, path);
    std::fs::remove_file(path)
}

/// Flushes each directory of `dirs` (see [`sync_dir`]); the first failure
/// with the directory it concerns.
pub(crate) fn sync_dirs<'a>(
    dirs: impl IntoIterator<Item = &'a Path>,
) -> std::result::Result<(), (&'a Path, std::io::Error)> {
    for d in dirs {
        sync_dir(d).map_err(|e| (d, e))?;
    }
    Ok(())
}

/// The log of steps, in tests only (elsewhere the calls compile to nothing).
pub(crate) mod record {
    use std::path::Path;

    /// One step of a commit.
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    #[allow(dead_code)]
    pub(crate) enum Step {
        /// A writer filled a temporary file (logged by the caller).
        Write,
        SyncFile,
        SyncDir,
        Rename,
        Remove,
    }

    #[cfg(test)]
    thread_local! {
        static LOG: std::cell::RefCell<Option<Vec<(Step, std::path::PathBuf)>>> =
            const { std::cell::RefCell::new(None) };
        static FAIL: std::cell::RefCell<Option<std::path::PathBuf>> = const { std::cell::RefCell::new(None) };
    }

    /// Makes this thread's next renames of `from` fail (None: none fails).
    #[cfg(test)]
    pub(crate) fn fail_rename(from: Option<&Path>) {
        FAIL.with(|f| *f.borrow_mut() = from.map(Path::to_path_buf));
    }

    /// Whether a rename of `from` is to fail ([`fail_rename`]).
    #[cfg(test)]
    pub(crate) fn fails(from: &Path) -> bool {
        FAIL.with(|f| f.borrow().as_deref() == Some(from))
    }

    /// Appends `step` on `path` to this thread's log, if it is recording.
    #[inline]
    pub(crate) fn step(step: Step, path: &Path) {
        #[cfg(test)]
        LOG.with(|log| {
            if let Some(log) = log.borrow_mut().as_mut() {
                log.push((step, path.to_path_buf()));
            }
        });
        #[cfg(not(test))]
        let _ = (step, path);
    }

    /// Starts recording this thread's steps (forgetting earlier ones).
    #[cfg(test)]
    pub(crate) fn start() {
        LOG.with(|log| *log.borrow_mut() = Some(Vec::new()));
    }

    /// Stops recording and returns the steps since [`start`].
    #[cfg(test)]
    pub(crate) fn take() -> Vec<(Step, std::path::PathBuf)> {
        LOG.with(|log| log.borrow_mut().take().unwrap_or_default())
    }
}
