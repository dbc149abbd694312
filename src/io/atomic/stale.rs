//! Cleaning up after killed runs: [`clean_stale`], and telling whether the
//! process that wrote a hidden sibling or journal still runs.

use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime};

use super::journal::{self, Journal, Writer};
use super::names::{self, Sibling};
use super::transaction::remove_any;

/// What is known now about a process id.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Seen {
    /// No process has this id.
    Dead,
    /// A process has it, started at these clock ticks since boot (None when
    /// that cannot be read).
    Alive(Option<u64>),
    /// This system cannot tell (no `/proc`).
    Unknown,
}

/// The clock ticks per second of `/proc/PID/stat` (Linux's `USER_HZ`, 100
/// on every architecture it runs on today).
const TICKS_PER_SECOND: u64 = 100;

/// A journal of format 1 (no start time) whose process id belongs to a
/// process that started more than this after the journal was last written
/// is of another, dead process (the margin covers the one-second precision
/// of the boot time and small clock adjustments).
const START_MARGIN: Duration = Duration::from_secs(2);

/// The start time of process `pid` in clock ticks since boot: field 22 of
/// `/proc/PID/stat` (after the command name, which is in parentheses and may
/// hold spaces and parentheses itself). None where there is no such file.
pub(crate) fn start_ticks(pid: u32) -> Option<u64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let after_name = &stat[stat.rfind(')')? + 1..];
    // Fields 3, 4, … follow the name: field 22 is the 20th of them.
    after_name.split_whitespace().nth(22 - 3)?.parse().ok()
}

/// This process as it writes into its journals.
pub(crate) fn this_process() -> Writer {
    static START: std::sync::OnceLock<Option<u64>> = std::sync::OnceLock::new();
    Writer {
        pid: std::process::id(),
        start: *START.get_or_init(|| start_ticks(std::process::id())),
    }
}

/// What `/proc` says about `pid` now.
pub(crate) fn probe(pid: u32) -> Seen {
    if !Path::new("/proc/self").exists() {
        return Seen::Unknown;
    }
    if !Path::new(&format!("/proc/{pid}")).exists() {
        return Seen::Dead;
    }
    Seen::Alive(start_ticks(pid))
}

/// When the system booted (`btime` of `/proc/stat`).
fn boot_time() -> Option<SystemTime> {
    let stat = std::fs::read_to_string("/proc/stat").ok()?;
    let line = stat.lines().find_map(|l| l.strip_prefix("btime "))?;
    Some(SystemTime::UNIX_EPOCH + Duration::from_secs(line.trim().parse().ok()?))
}

/// Whether the process that wrote `journal` (last written at `written`)
/// is gone, given what [`probe`] says of its id now:
///
/// * its id is free: gone;
/// * its id belongs to a process of another start time: gone (the id was
///   reused), even when that process is this one;
/// * the journal has no start time (format 1, or written where it could
///   not be read): gone only if the process of its id started more than
///   [`START_MARGIN`] after the journal was written, so cannot have
///   written it; otherwise it is taken as the writer (as before start times
///   were recorded);
/// * anything unknown (no `/proc`, an unreadable start time): not gone.
fn writer_gone(journal: &Journal, written: Option<SystemTime>, seen: Seen) -> bool {
    let Writer { pid, start } = journal.writer;
    let me = this_process();
    let seen = if pid == me.pid { Seen::Alive(me.start) } else { seen };
    match (seen, start) {
        (Seen::Dead, _) => true,
        (Seen::Unknown, _) | (Seen::Alive(None), _) => false,
        (Seen::Alive(Some(now)), Some(then)) => now != then,
        (Seen::Alive(Some(now)), None) => {
            let started =
                boot_time().and_then(|boot| boot.checked_add(Duration::from_millis(now * 1000 / TICKS_PER_SECOND)));
            match (started, written) {
                (Some(started), Some(written)) => started > written + START_MARGIN,
                _ => false,
            }
        }
    }
}

/// Cleans up `dir` after alpenglow processes that were killed while writing
/// into it, and returns how many hidden entries it removed.
///
/// It looks only at hidden entries named as alpenglow names them:
///
/// * commit journals (`.alpenglow-commit-PID-N.journal`) first, of
///   processes that are gone: their id is free, or belongs to a process
///   that started at another time than the journal records (the id was
///   reused; see `writer_gone` for journals without a start time). A
///   transaction killed during its commit is rolled back — every previous
///   file restored from its backup, every new one removed (see
///   [`super::OutputTransaction`]);
/// * then temporary files (`.NAME.tmp-PID-N`), backups (`.NAME.bak-PID-N`)
///   and staging folders (`.NAME.partial-PID[-N]`) whose process id belongs
///   to no running process: removed. (Their names carry no start time; one
///   whose id was reused stays until that process ends. Their counters
///   start at a time-based number, so the new process does not reuse their
///   names.)
///
/// Whether an id is free is read from `/proc/PID`; on systems without
/// `/proc` nothing is touched. Entries of running processes (another
/// alpenglow writing now) are left alone, and so are backups of a journal
/// that could not be rolled back. Best effort: failures are logged, not
/// returned.
pub fn clean_stale(dir: &Path) -> usize {
    clean_stale_where(dir, probe)
}

/// [`clean_stale`] with `probe` telling what is known of a process id.
pub(crate) fn clean_stale_where(dir: &Path, probe: impl Fn(u32) -> Seen) -> usize {
    let Ok(read) = std::fs::read_dir(dir) else { return 0 };
    let mut found: Vec<(Sibling, u32, PathBuf)> = read
        .filter_map(|e| {
            let e = e.ok()?;
            // The suffix that names a sibling is ASCII: lossy is enough.
            let (kind, pid) = names::parse(&e.file_name().to_string_lossy())?;
            Some((kind, pid, e.path()))
        })
        .collect();
    // Journals first: their roll-back needs the backups and temporaries.
    found.sort_by_key(|(kind, ..)| *kind != Sibling::Journal);
    let mut blocked = Vec::new();
    let mut removed = 0;
    for (kind, pid, path) in found {
        if kind == Sibling::Journal {
            match recover_if_gone(&path, pid, &probe) {
                Ok(true) => removed += 1,
                Ok(false) => {}
                Err(e) => {
                    log::warn!("cannot recover after killed process {pid}: {e}");
                    blocked.push(pid);
                }
            }
            continue;
        }
        if pid == std::process::id() || probe(pid) != Seen::Dead {
            continue;
        }
        if kind == Sibling::Backup && blocked.contains(&pid) {
            continue;
        }
        // A journal in another directory may have handled it already.
        if !super::transaction::exists(&path) {
            continue;
        }
        match remove_any(&path) {
            Ok(()) => {
                log::info!("removed {} left by killed process {pid}", path.display());
                removed += 1;
            }
            Err(e) => log::warn!("cannot remove {}: {}", path.display(), crate::io::one_line(e)),
        }
    }
    removed
}

/// Recovers the journal `path` of process id `pid` if its writer is gone:
/// Ok(true) when it did. An unreadable journal of a free process id is an
/// error; of a used one it is left alone (it may be being written).
fn recover_if_gone(path: &Path, pid: u32, probe: &impl Fn(u32) -> Seen) -> crate::error::Result<bool> {
    let seen = probe(pid);
    let journal = match journal::read(path) {
        Ok(j) => j,
        Err(_) if seen != Seen::Dead || !super::transaction::exists(path) => return Ok(false),
        Err(e) => return Err(e),
    };
    let written = std::fs::metadata(path).and_then(|m| m.modified()).ok();
    if !writer_gone(&journal, written, seen) {
        return Ok(false);
    }
    if pid == std::process::id() {
        log::info!("recovering a commit of an earlier process {pid} (its id is this process's now)");
    }
    journal::recover(path, &journal)?;
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn start_ticks_reads_field_22() {
        let me = this_process();
        if Path::new("/proc/self/stat").exists() {
            let start = me.start.expect("this process's start time");
            assert_eq!(start_ticks(std::process::id()), Some(start));
            // A child starts later than its parent.
            let mut child = std::process::Command::new("sleep").arg("5").spawn().unwrap();
            let child_start = start_ticks(child.id());
            child.kill().unwrap();
            child.wait().unwrap();
            assert!(child_start.unwrap() >= start);
            assert!(boot_time().unwrap() < SystemTime::now());
        }
        assert_eq!(start_ticks(4_000_000_000), None);
    }
}
