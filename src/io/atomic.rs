//! All-or-nothing file writes.
//!
//! [`write_atomically`] lets a writer fill a temporary file beside the target
//! and renames it into place only when the writer succeeded. Readers of the
//! target therefore see either the old file or the complete new one, never a
//! partial file, and a failed write leaves nothing behind.
//!
//! [`OutputTransaction`] does the same for all outputs of a command at once:
//! every path checked first (no two outputs at one path, no symbolic link,
//! FIFO, socket, device node or directory replaced), every output written
//! to its temporary, then all renamed into place — or, on a failure, every
//! previous file restored.
//!
//! Hidden siblings carry the writing process's id: `.NAME.tmp-PID-N`
//! (temporary files), `.NAME.bak-PID-N` (previous files during a commit),
//! `.NAME.partial-PID-N` (folders being filled) and
//! `.alpenglow-commit-PID-N.journal`. When a run is killed they stay
//! behind; [`clean_stale`], called by [`OutputTransaction`] for every
//! directory it writes into, removes those of dead processes (and rolls
//! back a commit that was interrupted). Every sibling name fits in 255
//! bytes, whatever the output's name ([`names`]).
//!
//! # Durability: the order of `fsync`s
//!
//! A rename is atomic for every process, but after a power loss the disk
//! holds only what was flushed, and a file system may write a rename to the
//! disk before the data of the file renamed, or the entries of one directory
//! before those of another. So every step that a later step relies on is
//! flushed (`fsync`, [`durable`]) before that step:
//!
//! [`write_atomically`]: write the temporary → `fsync` it → rename it onto
//! the target → `fsync` the directory. Without the first `fsync` the
//! rename could reach the disk before the data and leave an empty or
//! partial target; without the second the function could return before the
//! new name is on the disk.
//!
//! [`OutputTransaction::commit`]:
//! 1. write every temporary (staging) → `fsync` each (a staging folder:
//!    every file and folder in it, bottom up). The journal will name them,
//!    and what it names must be complete.
//! 2. write the journal of every directory (each with [`write_atomically`],
//!    so written → `fsync`ed → renamed → its directory `fsync`ed). From
//!    here on a power loss is rolled back by the next run, so the journal
//!    must be on the disk before the first rename.
//! 3. move old targets aside and rename every temporary into place →
//!    `fsync` every directory. The renames must be on the disk before the
//!    commit point: otherwise a power loss after it could leave some
//!    outputs old and some new, with no journal left to roll them back.
//! 4. remove the journals (removing the first directory's one is the commit
//!    point) → `fsync` every directory. The removal must be on the disk
//!    before the backups go: otherwise a power loss could leave a journal
//!    that the next run rolls back with its backups already gone — old
//!    outputs lost, new ones removed.
//! 5. remove the backups (not flushed: a backup that a power loss brings
//!    back is a stale sibling of a dead process, and [`clean_stale`]
//!    removes it).
//!
//! A failure before the commit point rolls back (renames undone, then
//! `fsync`ed) before its journals are removed, and so does [`clean_stale`]
//! when it recovers a killed commit.
//!
//! # Which process wrote a journal
//!
//! A journal records its process's id and start time (on Linux field 22
//! of `/proc/PID/stat`, clock ticks since boot). Its process is the same as
//! a running one only when both match, so a commit whose process id now
//! belongs to another process is still rolled back (see [`clean_stale`]).

mod durable;
mod journal;
mod names;
mod stale;
mod transaction;

pub use stale::clean_stale;
pub use transaction::OutputTransaction;

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// Removes the temporary file on drop unless disarmed (covers early returns
/// and panics inside the writer).
struct TempGuard {
    path: PathBuf,
    armed: bool,
}

impl Drop for TempGuard {
    fn drop(&mut self) {
        if self.armed {
            // Best effort: the file may never have been created.
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// The temporary path used while writing `path`:
/// `.{file name}.tmp-{process id}-{counter}` in the same directory.
fn temp_path(dir: &Path, file_name: &std::ffi::OsStr) -> PathBuf {
    names::sibling(
        &dir.join(file_name),
        file_name,
        names::Sibling::Temp,
        std::process::id(),
        names::next_id(),
    )
}

/// Writes `path` atomically.
///
/// Calls `write` with a temporary path in the same directory as `path`
/// (named `.{file name}.tmp-{pid}-{n}`, hidden on Unix), then renames the
/// temporary file onto `path`. Because the rename happens within one
/// directory (one file system), it replaces any existing file in one step.
///
/// On failure — the writer returns an error, the writer panics, or the
/// rename fails — the temporary file is removed and `path` is untouched.
///
/// Errors (one line, naming `path`): `path` has no file name or one longer
/// than 255 bytes, its parent
/// directory does not exist or is not a directory, `path` is an existing
/// directory or anything else but a regular file (a symbolic link, FIFO,
/// socket or device node is never replaced), the writer did not create the
/// temporary file, or the rename
/// failed. Errors returned by `write` are passed through unchanged, so
/// writers should name `path` (not the temporary path) in their messages.
pub fn write_atomically(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let file_name = path
        .file_name()
        .ok_or_else(|| Error::output(path, "the path does not name a file"))?;
    let units = names::name_units(file_name);
    if units > names::NAME_MAX {
        return Err(Error::output(
            path,
            format!(
                "the file name is {units} bytes long; file systems take at most {}",
                names::NAME_MAX
            ),
        ));
    }
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !dir.exists() {
        return Err(Error::output(
            path,
            format!("directory {} does not exist", dir.display()),
        ));
    }
    if !dir.is_dir() {
        return Err(Error::output(path, format!("{} is not a directory", dir.display())));
    }
    if let Ok(meta) = std::fs::symlink_metadata(path) {
        if let Some(thing) = transaction::non_regular(&meta) {
            return Err(Error::output(
                path,
                format!("it is {thing}; only a regular file is replaced"),
            ));
        }
    }

    let mut guard = TempGuard {
        path: temp_path(dir, file_name),
        armed: true,
    };
    write(&guard.path)?;
    durable::record::step(durable::record::Step::Write, &guard.path);
    if !guard.path.is_file() {
        return Err(Error::output(
            path,
            "internal error: the writer did not create the temporary file",
        ));
    }
    durable::sync_file(&guard.path).map_err(|e| {
        Error::output(
            path,
            format!(
                "cannot flush {} to the disk: {}",
                guard.path.display(),
                super::one_line(e)
            ),
        )
    })?;
    durable::rename(&guard.path, path).map_err(|e| {
        Error::output(
            path,
            format!(
                "cannot rename {} into place: {}",
                guard.path.display(),
                super::one_line(e)
            ),
        )
    })?;
    guard.armed = false;
    // The new name is visible; a failed flush of it is reported but leaves it.
    durable::sync_dir(dir).map_err(|e| {
        Error::output(
            path,
            format!(
                "cannot flush directory {} to the disk: {}",
                dir.display(),
                super::one_line(e)
            ),
        )
    })
}

/// Writes `bytes` to `path` atomically (see `write_atomically`).
pub fn write_bytes_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomically(path, |tmp| {
        std::fs::write(tmp, bytes).map_err(|e| {
            Error::output(
                path,
                format!("writing the temporary file failed: {}", super::one_line(e)),
            )
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh empty directory for test `name` of this process.
    pub(in crate::io::atomic) fn scratch_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("alpenglow-atomic-{}-{}", std::process::id(), name));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// The names in `dir`, sorted.
    pub(in crate::io::atomic) fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn success_replaces_file_and_leaves_no_temp() {
        let dir = scratch_dir("ok");
        let target = dir.join("a.txt");
        std::fs::write(&target, b"old").unwrap();
        write_bytes_atomically(&target, b"new").unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        assert_eq!(entries(&dir), vec!["a.txt".to_string()]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn failure_keeps_old_file_and_removes_temp() {
        let dir = scratch_dir("fail");
        let target = dir.join("a.txt");
        std::fs::write(&target, b"old").unwrap();
        let err = write_atomically(&target, |tmp| {
            std::fs::write(tmp, b"partial").unwrap();
            Err(Error::output(&target, "simulated failure"))
        })
        .unwrap_err();
        assert!(err.to_string().contains("simulated failure"));
        assert_eq!(std::fs::read(&target).unwrap(), b"old");
        assert_eq!(entries(&dir), vec!["a.txt".to_string()]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn panic_in_writer_removes_temp() {
        let dir = scratch_dir("panic");
        let target = dir.join("b.bin");
        let result = std::panic::catch_unwind(|| {
            let _ = write_atomically(&target, |tmp| {
                std::fs::write(tmp, b"partial").unwrap();
                panic!("writer panicked");
            });
        });
        assert!(result.is_err());
        assert!(entries(&dir).is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn missing_directory_is_a_clear_error() {
        let dir = scratch_dir("missing");
        let target = dir.join("nope").join("x.png");
        let err = write_bytes_atomically(&target, b"x").unwrap_err().to_string();
        assert!(err.contains("does not exist"), "{err}");
        assert!(err.contains("x.png"), "{err}");
        assert!(!dir.join("nope").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn links_and_directories_are_never_replaced() {
        let dir = scratch_dir("link");
        std::fs::write(dir.join("real"), b"real").unwrap();
        std::os::unix::fs::symlink(dir.join("real"), dir.join("link")).unwrap();
        let err = write_bytes_atomically(&dir.join("link"), b"x").unwrap_err().to_string();
        assert!(err.contains("symbolic link"), "{err}");
        let err = write_bytes_atomically(&dir, b"x").unwrap_err().to_string();
        assert!(err.contains("a directory"), "{err}");
        assert!(std::fs::symlink_metadata(dir.join("link"))
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(entries(&dir), ["link", "real"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn writer_that_creates_nothing_is_an_error() {
        let dir = scratch_dir("nothing");
        let err = write_atomically(&dir.join("y"), |_| Ok(())).unwrap_err();
        assert!(err.to_string().contains("temporary file"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
