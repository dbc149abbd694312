//! Commit journals of [`super::OutputTransaction`]: which targets a
//! transaction is renaming, so that the run after a killed one can roll it
//! back.
//!
//! A journal is a small text file: a header line, `primary HEX` (the path
//! of the transaction's first journal, whose removal is the commit point),
//! `pid PID`, `start TICKS` (the process's start time, clock ticks since
//! boot, or `start unknown`), then one `file|dir existed|new N HEX` line per
//! output (HEX: the canonical target path's bytes). Every directory of the
//! transaction gets a copy, so that whichever of them the next run writes
//! into, it finds the journal.
//!
//! Journals of format 1 (before the start time was recorded) are still
//! read, with no start time (see [`super::clean_stale`] for how their
//! process is told dead).

use std::path::{Path, PathBuf};

use super::durable;
use super::names::{self, next_id, parent_dir, Sibling};
use super::transaction::{exists, remove_any};
use crate::error::{Error, Result};

const HEADER: &str = "alpenglow commit journal 2";
/// The format without the `start` line.
const HEADER_1: &str = "alpenglow commit journal 1";

/// The process that writes a transaction: its id and start time (clock
/// ticks since boot; None where it cannot be told).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Writer {
    pub pid: u32,
    pub start: Option<u64>,
}

/// A parsed journal.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Journal {
    /// The first directory's journal, whose removal is the commit point.
    pub primary: PathBuf,
    pub writer: Writer,
    pub entries: Vec<Entry>,
}

/// A file or a folder output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    File,
    Dir,
}

/// One output of a transaction.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Entry {
    pub kind: Kind,
    /// Number of its hidden siblings.
    pub n: u64,
    /// Whether something was at the target when the commit began.
    pub existed: bool,
    /// Canonical directory joined with the file name.
    pub target: PathBuf,
}

impl Entry {
    /// The hidden sibling `kind` of the target written by `pid`.
    pub fn sibling(&self, kind: Sibling, pid: u32) -> PathBuf {
        let name = self.target.file_name().unwrap_or_default();
        names::sibling(&self.target, name, kind, pid, self.n)
    }

    /// Where the new output is written before the commit.
    pub fn temp_kind(&self) -> Sibling {
        match self.kind {
            Kind::File => Sibling::Temp,
            Kind::Dir => Sibling::Partial,
        }
    }
}

fn hex(path: &Path) -> String {
    #[cfg(unix)]
    let bytes = std::os::unix::ffi::OsStrExt::as_bytes(path.as_os_str()).to_vec();
    #[cfg(not(unix))]
    let bytes = path.to_string_lossy().into_owned().into_bytes();
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn unhex(text: &str) -> Option<PathBuf> {
    if text.len() % 2 != 0 {
        return None;
    }
    let bytes = (0..text.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(text.get(i..i + 2)?, 16).ok())
        .collect::<Option<Vec<u8>>>()?;
    #[cfg(unix)]
    return Some(PathBuf::from(
        <std::ffi::OsStr as std::os::unix::ffi::OsStrExt>::from_bytes(&bytes),
    ));
    #[cfg(not(unix))]
    return String::from_utf8(bytes).ok().map(PathBuf::from);
}

fn encode(primary: &Path, writer: Writer, entries: &[Entry]) -> String {
    let start = writer.start.map_or("unknown".to_string(), |s| s.to_string());
    let mut text = format!(
        "{HEADER}\nprimary {}\npid {}\nstart {start}\n",
        hex(primary),
        writer.pid
    );
    for e in entries {
        let kind = if e.kind == Kind::File { "file" } else { "dir" };
        let existed = if e.existed { "existed" } else { "new" };
        text.push_str(&format!("{kind} {existed} {} {}\n", e.n, hex(&e.target)));
    }
    text
}

fn decode(text: &str) -> Option<Journal> {
    let mut lines = text.lines();
    let version = match lines.next()? {
        HEADER => 2,
        HEADER_1 => 1,
        _ => return None,
    };
    let primary = unhex(lines.next()?.strip_prefix("primary ")?)?;
    let pid = lines.next()?.strip_prefix("pid ")?.parse().ok()?;
    let start = match version {
        1 => None,
        _ => match lines.next()?.strip_prefix("start ")? {
            "unknown" => None,
            ticks => Some(ticks.parse().ok()?),
        },
    };
    let entries = lines
        .map(|line| {
            let mut f = line.split(' ');
            let kind = match f.next()? {
                "file" => Kind::File,
                "dir" => Kind::Dir,
                _ => return None,
            };
            let existed = match f.next()? {
                "existed" => true,
                "new" => false,
                _ => return None,
            };
            let n = f.next()?.parse().ok()?;
            let target = unhex(f.next()?)?;
            f.next().is_none().then_some(Entry {
                kind,
                n,
                existed,
                target,
            })
        })
        .collect::<Option<Vec<_>>>()?;
    Some(Journal {
        primary,
        writer: Writer { pid, start },
        entries,
    })
}

/// Reads and parses the journal `path`. Errors: it cannot be read, or is
/// not a journal.
pub(crate) fn read(path: &Path) -> Result<Journal> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::input(path, crate::io::one_line(e)))?;
    decode(&text).ok_or_else(|| Error::input(path, "not an alpenglow commit journal"))
}

/// The directories of `entries`, each once, in the order of the entries.
pub(crate) fn dirs(entries: &[Entry]) -> Vec<&Path> {
    let mut dirs: Vec<&Path> = Vec::new();
    for e in entries {
        let d = parent_dir(&e.target);
        if !dirs.contains(&d) {
            dirs.push(d);
        }
    }
    dirs
}

/// Flushes the directories of `entries` ([`durable::sync_dirs`]), the
/// error naming the directory.
pub(crate) fn sync_dirs(entries: &[Entry]) -> Result<()> {
    durable::sync_dirs(dirs(entries)).map_err(|(d, e)| {
        Error::output(
            d,
            format!("cannot flush the directory to the disk: {}", crate::io::one_line(e)),
        )
    })
}

/// Writes a journal of `entries` into each of their directories (each
/// atomically, so flushed with its directory), the first directory's
/// first: returns their paths in that order. On failure removes those
/// written.
pub(crate) fn write_all(entries: &[Entry], writer: Writer) -> Result<Vec<PathBuf>> {
    let n = next_id();
    let paths: Vec<PathBuf> = dirs(entries).iter().map(|d| names::journal(d, writer.pid, n)).collect();
    let text = encode(&paths[0], writer, entries);
    for (i, p) in paths.iter().enumerate() {
        if let Err(e) = super::write_bytes_atomically(p, text.as_bytes()) {
            for q in &paths[..i] {
                let _ = std::fs::remove_file(q);
            }
            return Err(e);
        }
    }
    Ok(paths)
}

/// Undoes a transaction of process `pid` that may have been interrupted at
/// any point of its commit: old targets come back from their backups, new
/// ones are removed, temporaries are removed. Safe to repeat.
pub(crate) fn roll_back(entries: &[Entry], pid: u32) -> std::io::Result<()> {
    for e in entries.iter().rev() {
        let (target, temp, backup) = (
            &e.target,
            e.sibling(e.temp_kind(), pid),
            e.sibling(Sibling::Backup, pid),
        );
        if exists(&backup) {
            if exists(target) {
                remove_any(target)?;
            }
            durable::rename(&backup, target)?;
        } else if !e.existed && !exists(&temp) && exists(target) {
            // The new output was renamed into place.
            remove_any(target)?;
        }
        remove_any(&temp)?;
    }
    Ok(())
}

/// Recovers after the dead process of the journal `path` (read as
/// `journal`): rolls its transaction back unless it committed (its primary
/// journal is gone) and flushes the roll-back to the disk, then removes the
/// journals (the primary last) and flushes that. Errors when the roll-back
/// or its flush failed (the journal then stays for a later run).
pub(crate) fn recover(path: &Path, journal: &Journal) -> Result<()> {
    let Journal {
        primary,
        writer,
        entries,
    } = journal;
    let pid = writer.pid;
    if exists(primary) {
        roll_back(entries, pid)
            .map_err(|e| Error::output(path, format!("rolling back failed: {}", crate::io::one_line(e))))?;
        sync_dirs(entries)?;
        // The primary last: while it exists the others roll back too.
        let mut journals: Vec<PathBuf> = entries
            .iter()
            .map(|e| names::journal(parent_dir(&e.target), pid, journal_number(primary)))
            .filter(|j| j != primary)
            .collect();
        journals.dedup();
        for j in journals {
            let _ = durable::remove_file(&j);
        }
        let _ = durable::remove_file(primary);
    }
    if exists(path) {
        let _ = durable::remove_file(path);
    }
    if let Err(e) = sync_dirs(entries) {
        log::warn!("{e}");
    }
    Ok(())
}

/// The counter in a journal's name (`.alpenglow-commit-PID-N.journal`).
fn journal_number(path: &Path) -> u64 {
    path.file_name()
        .and_then(|n| n.to_str())
        .and_then(|n| n.strip_suffix(".journal"))
        .and_then(|n| n.rsplit('-').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or(u64::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn journals_round_trip() {
        let entries = vec![
            Entry {
                kind: Kind::File,
                n: 3,
                existed: true,
                target: PathBuf::from("/a b/ö\nx.png"),
            },
            Entry {
                kind: Kind::Dir,
                n: 4,
                existed: false,
                target: PathBuf::from("/c/frames"),
            },
        ];
        let primary = PathBuf::from("/a b/.alpenglow-commit-7-1.journal");
        for start in [Some(123_456), None] {
            let writer = Writer { pid: 7, start };
            let text = encode(&primary, writer, &entries);
            let back = decode(&text).unwrap();
            assert_eq!(back.primary, primary);
            assert_eq!(journal_number(&back.primary), 1);
            assert_eq!((back.writer, &back.entries), (writer, &entries));
            assert!(decode(&text.replace("file", "fil")).is_none());
            assert!(decode(&text.replace("start ", "begin ")).is_none());
        }
        assert!(decode("something else").is_none());
        // Format 1: no start line, no start time.
        let old = encode(&primary, Writer { pid: 7, start: Some(1) }, &entries)
            .replace(HEADER, HEADER_1)
            .replace("start 1\n", "");
        let back = decode(&old).unwrap();
        assert_eq!((back.writer, back.entries), (Writer { pid: 7, start: None }, entries));
    }
}
