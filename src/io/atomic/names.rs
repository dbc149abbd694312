//! Names of the temporary siblings of an output: temporary files, backups,
//! staging folders and commit journals, all hidden (leading dot) and
//! carrying the writing process's id, so that a later run can tell those of
//! a dead process (see [`super::clean_stale`]).

use std::ffi::{OsStr, OsString};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Distinguishes the siblings of concurrent writes within one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// A number not used before by this process.
pub(crate) fn next_id() -> u64 {
    COUNTER.fetch_add(1, Ordering::Relaxed)
}

/// What a hidden sibling is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Sibling {
    /// `.{name}.tmp-{pid}-{n}`: a file being written.
    Temp,
    /// `.{name}.bak-{pid}-{n}`: the previous file, moved aside while a
    /// transaction commits.
    Backup,
    /// `.{name}.partial-{pid}-{n}` (or `-{pid}`): a folder being filled.
    Partial,
    /// `.alpenglow-commit-{pid}-{n}.journal`: a transaction's commit journal.
    Journal,
}

impl Sibling {
    fn tag(self) -> &'static str {
        match self {
            Sibling::Temp => "tmp",
            Sibling::Backup => "bak",
            Sibling::Partial => "partial",
            Sibling::Journal => "journal",
        }
    }
}

/// The directory of `path` (`.` for a bare file name).
pub(crate) fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// The sibling of `target` of kind `kind` written by process `pid` as its
/// `n`-th: `.{file name}.{tag}-{pid}-{n}` in the same directory.
pub(crate) fn sibling(target: &Path, file_name: &OsStr, kind: Sibling, pid: u32, n: u64) -> PathBuf {
    let mut name = OsString::from(".");
    name.push(file_name);
    name.push(format!(".{}-{pid}-{n}", kind.tag()));
    parent_dir(target).join(name)
}

/// The commit journal `n` of process `pid` in `dir`.
pub(crate) fn journal(dir: &Path, pid: u32, n: u64) -> PathBuf {
    dir.join(format!(".alpenglow-commit-{pid}-{n}.journal"))
}

/// `digits` or `digits-digits`: the process id (and the counter).
fn pid_and_counter(rest: &str) -> Option<u32> {
    let (pid, n) = rest.split_once('-').unwrap_or((rest, "0"));
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    if !digits(pid) || !digits(n) {
        return None;
    }
    pid.parse().ok()
}

/// The kind and writing process of a hidden sibling named `name`; None for
/// every other name.
pub(crate) fn parse(name: &str) -> Option<(Sibling, u32)> {
    let rest = name.strip_prefix('.')?;
    if let Some(middle) = rest
        .strip_prefix("alpenglow-commit-")
        .and_then(|r| r.strip_suffix(".journal"))
    {
        return pid_and_counter(middle).map(|pid| (Sibling::Journal, pid));
    }
    [Sibling::Temp, Sibling::Backup, Sibling::Partial]
        .into_iter()
        .find_map(|kind| {
            let marker = format!(".{}-", kind.tag());
            let at = rest.rfind(&marker)?;
            // A name of at least one character before the marker.
            (at > 0).then_some(())?;
            pid_and_counter(&rest[at + marker.len()..]).map(|pid| (kind, pid))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        let t = Path::new("/x/out.png");
        let name = |k| {
            sibling(t, OsStr::new("out.png"), k, 42, 7)
                .file_name()
                .unwrap()
                .to_string_lossy()
                .into_owned()
        };
        assert_eq!(name(Sibling::Temp), ".out.png.tmp-42-7");
        for k in [Sibling::Temp, Sibling::Backup, Sibling::Partial] {
            assert_eq!(parse(&name(k)), Some((k, 42)));
        }
        let j = journal(Path::new("/x"), 9, 3);
        assert_eq!(
            parse(&j.file_name().unwrap().to_string_lossy()),
            Some((Sibling::Journal, 9))
        );
        assert_eq!(parse(".frames.partial-123"), Some((Sibling::Partial, 123)));
        for other in [
            "out.png",
            ".tmp-1-2",
            ".a.tmp-x-1",
            ".a.tmp-1-",
            ".a.bak-",
            "a.tmp-1-2",
            ".hidden",
        ] {
            assert_eq!(parse(other), None, "{other}");
        }
    }
}
