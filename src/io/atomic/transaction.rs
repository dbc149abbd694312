//! [`OutputTransaction`]: every output of a command appears together, or
//! none does and what was there before stays.

use std::path::{Path, PathBuf};

use super::durable;
use super::journal::{self, Entry, Kind, Writer};
use super::names::{self, next_id, parent_dir, Sibling};
use crate::error::{Error, Result};
use crate::io::one_line;

/// The outputs of one command, written as a transaction.
///
/// 1. [`OutputTransaction::add_file`] / [`OutputTransaction::add_dir`]
///    check every path before any work: its file name fits the file
///    system's limit (255 bytes), its directory exists and takes a new file
///    (its temporary is created and removed again), no two
///    outputs name one file (compared by canonical directory and file
///    name), and what is at the path now is absent or a regular file (an
///    empty real directory for a folder output) — symbolic links, FIFOs,
///    sockets and device nodes are never replaced. Adding a path also
///    cleans up after killed runs in its directory (`super::clean_stale`).
/// 2. [`OutputTransaction::stage`] writes each output to a hidden temporary
///    sibling (`.NAME.tmp-PID-N`; a folder is filled in `.NAME.partial-PID-N`).
/// 3. [`OutputTransaction::commit`] flushes every temporary to the disk,
///    writes a commit journal (`.alpenglow-commit-PID-N.journal`, with the
///    process's start time) into every directory involved, moves existing
///    targets aside (`.NAME.bak-PID-N`), renames every temporary into
///    place, removes the journals (the commit point: the journal of the
///    first output's directory) and then the backups, flushing the
///    directories between these steps (the order and why: `super`). When
///    a rename fails, every target is restored from its backup and the new
///    files are removed, so a failure never deletes what was there before.
///
/// Dropping a transaction without committing removes its temporaries.
///
/// If the process is killed during the commit's renames (they take
/// microseconds, after all the writing), the old and new files may be
/// visible side by side until the next alpenglow run that writes into one of
/// those directories: it finds the journal of the dead process and rolls the
/// transaction back (every old file restored, every new one removed). A kill
/// at any other time leaves the old outputs in place, with at most hidden
/// temporaries that the next run removes. The same holds after a power
/// loss, as every step is on the disk before the next one relies on it.
#[derive(Debug)]
pub struct OutputTransaction {
    pid: u32,
    /// This process's start time, for the journal.
    start: Option<u64>,
    outputs: Vec<Output>,
    committed: bool,
}

#[derive(Debug)]
struct Output {
    entry: Entry,
    /// The path as given (for messages).
    shown: PathBuf,
    /// The option or role it belongs to (for messages).
    what: String,
    staged: bool,
}

impl Default for OutputTransaction {
    fn default() -> Self {
        OutputTransaction::new()
    }
}

/// What is at `path` when it is not a regular file; None when it is one or
/// nothing is there.
pub(crate) fn non_regular(meta: &std::fs::Metadata) -> Option<&'static str> {
    let t = meta.file_type();
    if t.is_file() {
        return None;
    }
    if t.is_symlink() {
        return Some("a symbolic link");
    }
    if t.is_dir() {
        return Some("a directory");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return Some("a FIFO (named pipe)");
        }
        if t.is_socket() {
            return Some("a socket");
        }
        if t.is_block_device() || t.is_char_device() {
            return Some("a device node");
        }
    }
    Some("not a regular file")
}

/// What is wrong with replacing `path` (with metadata `meta`) by an output
/// of `kind`; None when it may be replaced.
fn target_problem(kind: Kind, meta: &std::fs::Metadata, path: &Path) -> Result<Option<&'static str>> {
    Ok(match kind {
        Kind::File => non_regular(meta),
        Kind::Dir if !meta.is_dir() => Some(non_regular(meta).unwrap_or("a file")),
        Kind::Dir => std::fs::read_dir(path)
            .map_err(|e| Error::output(path, one_line(e)))?
            .next()
            .is_some()
            .then_some("a directory that is not empty"),
    })
}

/// The error refusing to replace `thing` at `path` by the output `what`.
fn refusal(path: &Path, what: &str, kind: Kind, thing: &str) -> Error {
    let only = match kind {
        Kind::File => "only a regular file is replaced",
        Kind::Dir => "only an empty directory is replaced",
    };
    Error::output(
        path,
        format!("{what} names {thing}; {only} (remove it or choose another path)"),
    )
}

/// Removes whatever is at `path` (a file, a link, a folder and its contents).
pub(crate) fn remove_any(path: &Path) -> std::io::Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.is_dir() => std::fs::remove_dir_all(path),
        Ok(_) => std::fs::remove_file(path),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
    }
}

pub(crate) fn exists(path: &Path) -> bool {
    std::fs::symlink_metadata(path).is_ok()
}

impl OutputTransaction {
    /// An empty transaction of this process.
    pub fn new() -> Self {
        let me = super::stale::this_process();
        let mut tx = OutputTransaction::with_pid(me.pid);
        tx.start = me.start;
        tx
    }

    /// A transaction whose hidden files carry `pid` (tests simulate a
    /// killed process with a pid that does not exist).
    pub(crate) fn with_pid(pid: u32) -> Self {
        OutputTransaction {
            pid,
            start: None,
            outputs: Vec::new(),
            committed: false,
        }
    }

    /// Checks `path` as the file output `what` (an option name such as
    /// `--out`, used in messages) and reserves it. Errors (one line, naming
    /// `path` and `what`): no file name, a file name longer than 255 bytes,
    /// a missing directory or one where no file can be created, a path
    /// another output of this transaction already names, or something other
    /// than a regular file at the path.
    pub fn add_file(&mut self, path: &Path, what: &str) -> Result<()> {
        self.add(path, what, Kind::File)
    }

    /// Checks `path` as the folder output `what`: absent, or an empty
    /// directory (not a link to one). Otherwise as [`OutputTransaction::add_file`].
    pub fn add_dir(&mut self, path: &Path, what: &str) -> Result<()> {
        self.add(path, what, Kind::Dir)
    }

    fn add(&mut self, path: &Path, what: &str, kind: Kind) -> Result<()> {
        let file_name = path
            .file_name()
            .ok_or_else(|| Error::output(path, format!("{what} does not name a file")))?;
        let units = names::name_units(file_name);
        if units > names::NAME_MAX {
            return Err(Error::output(
                path,
                format!(
                    "{what}: the file name is {units} bytes long; file systems take at most {}",
                    names::NAME_MAX
                ),
            ));
        }
        let dir = parent_dir(path);
        if !dir.is_dir() {
            return Err(Error::output(
                path,
                format!("{what}: directory {} does not exist", dir.display()),
            ));
        }
        let canonical = dir
            .canonicalize()
            .map_err(|e| Error::output(path, format!("{what}: {}", one_line(e))))?
            .join(file_name);
        if let Some(other) = self.outputs.iter().find(|o| o.entry.target == canonical) {
            return Err(Error::output(
                path,
                format!(
                    "{what} names the same file as {}; give each output its own path",
                    other.what
                ),
            ));
        }
        if let Ok(meta) = std::fs::symlink_metadata(path) {
            if let Some(thing) = target_problem(kind, &meta, path)? {
                return Err(refusal(path, what, kind, thing));
            }
        }
        super::clean_stale(dir);
        let entry = Entry {
            kind,
            n: next_id(),
            existed: false,
            target: canonical,
        };
        probe(&entry.sibling(entry.temp_kind(), self.pid), path, what)?;
        self.outputs.push(Output {
            entry,
            shown: path.to_path_buf(),
            what: what.to_string(),
            staged: false,
        });
        Ok(())
    }

    /// The output added as `path`: by the path as given, else by its
    /// canonical form. Its folder may have vanished since it was added:
    /// that is the output's error, naming it, not an internal one.
    fn find(&mut self, path: &Path, kind: Kind) -> Result<&mut Output> {
        if let Some(k) = self
            .outputs
            .iter()
            .position(|o| o.shown == path && o.entry.kind == kind)
        {
            let output = &mut self.outputs[k];
            let dir = parent_dir(&output.entry.target);
            if !dir.is_dir() {
                return Err(Error::output(
                    path,
                    format!("its folder {} no longer exists", dir.display()),
                ));
            }
            return Ok(output);
        }
        let dir = parent_dir(path);
        let canonical = match dir.canonicalize() {
            Ok(d) => path.file_name().map(|n| d.join(n)),
            Err(e) => {
                return Err(Error::output(
                    path,
                    format!("its folder {}: {}", dir.display(), one_line(e)),
                ))
            }
        };
        self.outputs
            .iter_mut()
            .find(|o| Some(&o.entry.target) == canonical.as_ref() && o.entry.kind == kind)
            .ok_or_else(|| Error::output(path, "internal error: the output was not added to the transaction"))
    }

    /// Writes the output `path` (added with [`OutputTransaction::add_file`]):
    /// calls `write` with its temporary path, which `write` must create.
    /// Errors of `write` pass through; on any error the temporary is removed.
    pub fn stage(&mut self, path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
        let pid = self.pid;
        let output = self.find(path, Kind::File)?;
        let temp = output.entry.sibling(Sibling::Temp, pid);
        let result = write(&temp).and_then(|()| match std::fs::symlink_metadata(&temp) {
            Ok(m) if m.is_file() => Ok(()),
            _ => Err(Error::output(
                path,
                "internal error: the writer did not create the temporary file",
            )),
        });
        if result.is_err() {
            let _ = remove_any(&temp);
        }
        result?;
        output.staged = true;
        Ok(())
    }

    /// Writes `bytes` as the output `path` (see [`OutputTransaction::stage`]).
    pub fn stage_bytes(&mut self, path: &Path, bytes: &[u8]) -> Result<()> {
        self.stage(path, |temp| {
            std::fs::write(temp, bytes)
                .map_err(|e| Error::output(path, format!("writing the temporary file failed: {}", one_line(e))))
        })
    }

    /// Creates the staging folder of the folder output `path` (added with
    /// [`OutputTransaction::add_dir`]) and returns it, for the caller to fill.
    pub fn stage_dir(&mut self, path: &Path) -> Result<PathBuf> {
        let pid = self.pid;
        let output = self.find(path, Kind::Dir)?;
        let temp = output.entry.sibling(Sibling::Partial, pid);
        std::fs::create_dir(&temp)
            .map_err(|e| Error::output(path, format!("cannot create {}: {}", temp.display(), one_line(e))))?;
        output.staged = true;
        Ok(temp)
    }

    /// Renames every staged output into place (see the type's
    /// documentation); on failure restores what was there before. Errors
    /// when an added output was never staged, or a rename failed.
    pub fn commit(mut self) -> Result<()> {
        if let Some(o) = self.outputs.iter().find(|o| !o.staged) {
            return Err(Error::output(
                &o.shown,
                format!("internal error: {} was never written", o.what),
            ));
        }
        if self.outputs.is_empty() {
            self.committed = true;
            return Ok(());
        }
        // The targets again, as late as possible: anything may have changed while rendering.
        for o in &mut self.outputs {
            o.entry.existed = match std::fs::symlink_metadata(&o.entry.target) {
                Ok(meta) => {
                    if let Some(thing) = target_problem(o.entry.kind, &meta, &o.entry.target)? {
                        return Err(refusal(&o.shown, &o.what, o.entry.kind, thing));
                    }
                    true
                }
                Err(_) => false,
            };
        }
        // Steps 1 to 5 of the order in the module documentation (`super`).
        for o in &self.outputs {
            let temp = o.entry.sibling(o.entry.temp_kind(), self.pid);
            durable::sync_tree(&temp).map_err(|e| {
                Error::output(
                    &o.shown,
                    format!("cannot flush {} to the disk: {}", temp.display(), one_line(e)),
                )
            })?;
        }
        let entries: Vec<Entry> = self.outputs.iter().map(|o| o.entry.clone()).collect();
        let writer = Writer {
            pid: self.pid,
            start: self.start,
        };
        let journals = journal::write_all(&entries, writer)?;
        let renamed = self.rename_all().and_then(|()| journal::sync_dirs(&entries));
        if let Err(e) = &renamed {
            // Restored and flushed before the journals go; if that fails they
            // stay, and the next run rolls back.
            let restored = journal::roll_back(&entries, self.pid).is_ok() && journal::sync_dirs(&entries).is_ok();
            if !restored {
                log::warn!("{e}; the next run restores the previous outputs");
                return renamed;
            }
        }
        // The first journal is the commit point; the others follow it.
        for j in &journals {
            let _ = durable::remove_file(j);
        }
        let flushed = journal::sync_dirs(&entries);
        renamed?;
        self.committed = true;
        match flushed {
            Ok(()) => {
                for o in &self.outputs {
                    let _ = remove_any(&o.entry.sibling(Sibling::Backup, self.pid));
                }
            }
            // A backup is needed if the journal's removal is lost; the next run removes it.
            Err(e) => log::warn!("{e}; the previous outputs stay as hidden backups until the next run"),
        }
        Ok(())
    }

    fn rename_all(&self) -> Result<()> {
        for o in &self.outputs {
            let (target, backup) = (&o.entry.target, o.entry.sibling(Sibling::Backup, self.pid));
            if o.entry.existed {
                durable::rename(target, &backup)
                    .map_err(|e| Error::output(&o.shown, format!("cannot move the old file aside: {}", one_line(e))))?;
            }
        }
        for o in &self.outputs {
            let temp = o.entry.sibling(o.entry.temp_kind(), self.pid);
            durable::rename(&temp, &o.entry.target)
                .map_err(|e| Error::output(&o.shown, format!("cannot rename into place: {}", one_line(e))))?;
        }
        Ok(())
    }
}

/// Checks that the temporary `temp` of the output `path` (the option
/// `what`) can be created, by creating it and removing it again.
fn probe(temp: &Path, path: &Path, what: &str) -> Result<()> {
    let created = std::fs::OpenOptions::new().write(true).create_new(true).open(temp);
    match created {
        Ok(file) => {
            drop(file);
            let _ = std::fs::remove_file(temp);
            Ok(())
        }
        Err(e) => Err(Error::output(
            path,
            format!(
                "{what}: cannot create a file in {}: {}",
                parent_dir(path).display(),
                one_line(e)
            ),
        )),
    }
}

impl Drop for OutputTransaction {
    fn drop(&mut self) {
        if !self.committed {
            for o in &self.outputs {
                let _ = remove_any(&o.entry.sibling(o.entry.temp_kind(), self.pid));
            }
        }
    }
}

#[cfg(test)]
mod tests;
