//! Cleaning up after killed runs: [`clean_stale`].

use std::path::Path;

use super::journal;
use super::names::{self, Sibling};
use super::transaction::remove_any;

/// Whether process `pid` is alive: Some on Linux (`/proc/PID` exists), None
/// where that cannot be told.
fn pid_alive(pid: u32) -> Option<bool> {
    if !Path::new("/proc/self").exists() {
        return None;
    }
    Some(Path::new(&format!("/proc/{pid}")).exists())
}

/// Cleans up `dir` after alpenglow processes that were killed while writing
/// into it, and returns how many hidden entries it removed.
///
/// It looks only at hidden entries named as alpenglow names them, whose
/// process id belongs to no running process (checked with `/proc/PID`; on
/// systems without `/proc` nothing is touched):
///
/// * commit journals (`.alpenglow-commit-PID-N.journal`) first: a
///   transaction killed during its commit is rolled back — every previous
///   file restored from its backup, every new one removed (see
///   [`super::OutputTransaction`]);
/// * then temporary files (`.NAME.tmp-PID-N`), backups (`.NAME.bak-PID-N`)
///   and staging folders (`.NAME.partial-PID[-N]`): removed.
///
/// Entries of running processes (another alpenglow writing now) are left
/// alone, and so are backups of a journal that could not be rolled back.
/// Best effort: failures are logged, not returned.
pub fn clean_stale(dir: &Path) -> usize {
    clean_stale_where(dir, |pid| pid_alive(pid) == Some(false))
}

/// [`clean_stale`] with `dead` deciding which process ids are dead.
pub(crate) fn clean_stale_where(dir: &Path, dead: impl Fn(u32) -> bool) -> usize {
    let Ok(read) = std::fs::read_dir(dir) else { return 0 };
    let mut found: Vec<(Sibling, u32, std::path::PathBuf)> = read
        .filter_map(|e| {
            let e = e.ok()?;
            let name = e.file_name().into_string().ok()?;
            let (kind, pid) = names::parse(&name)?;
            (pid != std::process::id() && dead(pid)).then(|| (kind, pid, e.path()))
        })
        .collect();
    // Journals first: their roll-back needs the backups and temporaries.
    found.sort_by_key(|(kind, ..)| *kind != Sibling::Journal);
    let mut blocked = Vec::new();
    let mut removed = 0;
    for (kind, pid, path) in found {
        if kind == Sibling::Journal {
            match journal::recover(&path) {
                Ok(()) => removed += 1,
                Err(e) => {
                    log::warn!("cannot recover after killed process {pid}: {e}");
                    blocked.push(pid);
                }
            }
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
