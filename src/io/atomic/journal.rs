//! Commit journals of [`super::OutputTransaction`]: which targets a
//! transaction is renaming, so that the run after a killed one can roll it
//! back.
//!
//! A journal is a small text file: a header line, `primary HEX` (the path
//! of the transaction's first journal, whose removal is the commit point),
//! `pid PID`, then one `file|dir existed|new N HEX` line per output
//! (HEX: the canonical target path's bytes). Every directory of the
//! transaction gets a copy, so that whichever of them the next run writes
//! into, it finds the journal.

use std::path::{Path, PathBuf};

use super::names::{self, next_id, parent_dir, Sibling};
use super::transaction::{exists, remove_any};
use crate::error::{Error, Result};

const HEADER: &str = "alpenglow commit journal 1";

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

fn encode(primary: &Path, pid: u32, entries: &[Entry]) -> String {
    let mut text = format!("{HEADER}\nprimary {}\npid {pid}\n", hex(primary));
    for e in entries {
        let kind = if e.kind == Kind::File { "file" } else { "dir" };
        let existed = if e.existed { "existed" } else { "new" };
        text.push_str(&format!("{kind} {existed} {} {}\n", e.n, hex(&e.target)));
    }
    text
}

/// A parsed journal: primary journal, process id, entries.
type Parsed = (PathBuf, u32, Vec<Entry>);

fn decode(text: &str) -> Option<Parsed> {
    let mut lines = text.lines();
    (lines.next()? == HEADER).then_some(())?;
    let primary = unhex(lines.next()?.strip_prefix("primary ")?)?;
    let pid = lines.next()?.strip_prefix("pid ")?.parse().ok()?;
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
    Some((primary, pid, entries))
}

/// Writes a journal of `entries` into each of their directories (each
/// atomically), the first directory's first: returns their paths in that
/// order. On failure removes those written.
pub(crate) fn write_all(entries: &[Entry], pid: u32) -> Result<Vec<PathBuf>> {
    let mut dirs: Vec<&Path> = Vec::new();
    for e in entries {
        let d = parent_dir(&e.target);
        if !dirs.contains(&d) {
            dirs.push(d);
        }
    }
    let n = next_id();
    let paths: Vec<PathBuf> = dirs.iter().map(|d| names::journal(d, pid, n)).collect();
    let text = encode(&paths[0], pid, entries);
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
            std::fs::rename(&backup, target)?;
        } else if !e.existed && !exists(&temp) && exists(target) {
            // The new output was renamed into place.
            remove_any(target)?;
        }
        remove_any(&temp)?;
    }
    Ok(())
}

/// Recovers after the dead process of the journal `path`: rolls its
/// transaction back unless it committed (its primary journal is gone), then
/// removes the journal. Errors when the journal cannot be read or parsed,
/// or the roll-back failed (the journal then stays for a later run).
pub(crate) fn recover(path: &Path) -> Result<()> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::input(path, crate::io::one_line(e)))?;
    let (primary, pid, entries) = decode(&text).ok_or_else(|| Error::input(path, "not an alpenglow commit journal"))?;
    if exists(&primary) {
        roll_back(&entries, pid)
            .map_err(|e| Error::output(path, format!("rolling back failed: {}", crate::io::one_line(e))))?;
        // The primary last: while it exists the others roll back too.
        let mut journals: Vec<PathBuf> = entries
            .iter()
            .map(|e| names::journal(parent_dir(&e.target), pid, journal_number(&primary)))
            .filter(|j| j != &primary)
            .collect();
        journals.dedup();
        for j in journals {
            let _ = std::fs::remove_file(j);
        }
        let _ = std::fs::remove_file(&primary);
    }
    let _ = std::fs::remove_file(path);
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
        let text = encode(Path::new("/a b/.alpenglow-commit-7-1.journal"), 7, &entries);
        let (primary, pid, back) = decode(&text).unwrap();
        assert_eq!(primary, PathBuf::from("/a b/.alpenglow-commit-7-1.journal"));
        assert_eq!(journal_number(&primary), 1);
        assert_eq!((pid, back), (7, entries));
        assert!(decode("something else").is_none());
        assert!(decode(&text.replace("file", "fil")).is_none());
    }
}
