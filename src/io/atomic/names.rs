//! Names of the temporary siblings of an output: temporary files, backups,
//! staging folders and commit journals, all hidden (leading dot) and
//! carrying the writing process's id, so that a later run can tell those of
//! a dead process (see [`super::clean_stale`]).
//!
//! Every sibling name fits in [`NAME_MAX`] bytes whatever the output's name
//! (itself at most [`NAME_MAX`] bytes): a name too long to carry the suffix
//! is cut at a character boundary and followed by `~` and a 64-bit hash of
//! the whole name (`.{prefix}~{hash}.tmp-{pid}-{n}`), so siblings of two
//! long names that share a prefix still differ, and [`parse`] (which reads
//! only the suffix) still recognises them.

use std::ffi::{OsStr, OsString};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;

/// The longest file name (one path component) alpenglow writes, in bytes:
/// Linux's `NAME_MAX` and the limit of the common file systems elsewhere.
pub(crate) const NAME_MAX: usize = 255;

/// Distinguishes the siblings of concurrent writes within one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Where this process's counter starts: the time of its first use in
/// microseconds (modulo 10¹²), so that a later process that reuses this
/// process id does not reuse the names of its siblings either.
fn counter_base() -> u64 {
    static BASE: OnceLock<u64> = OnceLock::new();
    *BASE.get_or_init(|| {
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| (d.as_micros() % 1_000_000_000_000) as u64)
    })
}

/// A number not used before by this process (nor, in practice, by an
/// earlier process of the same id).
pub(crate) fn next_id() -> u64 {
    counter_base() + COUNTER.fetch_add(1, Ordering::Relaxed)
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
/// `n`-th: `.{file name}.{tag}-{pid}-{n}` in the same directory, with the
/// file name shortened (see the module documentation) where that would
/// exceed [`NAME_MAX`] bytes.
pub(crate) fn sibling(target: &Path, file_name: &OsStr, kind: Sibling, pid: u32, n: u64) -> PathBuf {
    let suffix = format!(".{}-{pid}-{n}", kind.tag());
    let mut name = OsString::from(".");
    if 1 + file_name.len() + suffix.len() <= NAME_MAX {
        name.push(file_name);
    } else {
        let hash = format!("~{:016x}", fnv1a(file_name.as_encoded_bytes()));
        let room = NAME_MAX - 1 - hash.len() - suffix.len();
        name.push(prefix(file_name, room));
        name.push(hash);
    }
    name.push(suffix);
    parent_dir(target).join(name)
}

/// The longest prefix of `name` of at most `room` bytes that ends at a
/// character boundary (of its UTF-8, or of its bytes where it is not UTF-8).
fn prefix(name: &OsStr, room: usize) -> OsString {
    match name.to_str() {
        Some(text) => {
            let mut end = room.min(text.len());
            while !text.is_char_boundary(end) {
                end -= 1;
            }
            OsString::from(&text[..end])
        }
        None => {
            #[cfg(unix)]
            {
                let bytes = std::os::unix::ffi::OsStrExt::as_bytes(name);
                let cut = &bytes[..room.min(bytes.len())];
                <OsStr as std::os::unix::ffi::OsStrExt>::from_bytes(cut).to_os_string()
            }
            #[cfg(not(unix))]
            {
                prefix(OsStr::new(&name.to_string_lossy().into_owned()), room)
            }
        }
    }
}

/// 64-bit FNV-1a: a stable hash (the same in every run and version), so a
/// journal's siblings are found again by the next run.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// How many units of the file system's name limit `name` takes: bytes on
/// Unix, UTF-16 code units on Windows.
pub(crate) fn name_units(name: &OsStr) -> usize {
    #[cfg(windows)]
    return std::os::windows::ffi::OsStrExt::encode_wide(name).count();
    #[cfg(not(windows))]
    return name.len();
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

    /// Every sibling of every legal name (up to 255 bytes, ASCII or
    /// multi-byte) fits in 255 bytes, keeps the start of the name, differs
    /// between names that differ only at the end, and is recognised.
    #[test]
    fn siblings_of_long_names_fit_and_stay_recognisable() {
        let dir = Path::new("/x");
        let names: Vec<String> = [1, 200, 214, 215, 240, 254, 255]
            .iter()
            .map(|&len| "a".repeat(len))
            .chain(["é".repeat(127) + "b", "€".repeat(85), "😀".repeat(63) + "abc"])
            .collect();
        for name in &names {
            assert!(name.len() <= NAME_MAX, "{}", name.len());
            for kind in [Sibling::Temp, Sibling::Backup, Sibling::Partial] {
                for (pid, n) in [(1, 0), (u32::MAX, u64::MAX)] {
                    let s = sibling(&dir.join(name), OsStr::new(name), kind, pid, n);
                    let s = s.file_name().unwrap().to_str().expect("cut at a character boundary");
                    assert!(s.len() <= NAME_MAX, "{} bytes: {s}", s.len());
                    assert_eq!(parse(s), Some((kind, pid)), "{s}");
                    let start: String = name.chars().take(40).collect();
                    assert!(s.starts_with(&format!(".{start}")), "{s}");
                }
            }
        }
        let long = |last: char| {
            let name = format!("{}{last}", "a".repeat(254));
            sibling(&dir.join(&name), OsStr::new(&name), Sibling::Temp, 7, 1)
        };
        assert_ne!(long('b'), long('c'));
        assert_eq!(long('b'), long('b'), "stable");
    }

    #[cfg(unix)]
    #[test]
    fn siblings_of_long_non_utf8_names_fit() {
        use std::os::unix::ffi::OsStrExt;
        let bytes: Vec<u8> = std::iter::repeat_n(0xff, 255).collect();
        let name = OsStr::from_bytes(&bytes);
        let s = sibling(&Path::new("/x").join(name), name, Sibling::Backup, 3, 4);
        let s = s.file_name().unwrap();
        assert!(s.len() <= NAME_MAX);
        assert_eq!(parse(&s.to_string_lossy()), Some((Sibling::Backup, 3)));
    }

    #[test]
    fn counters_of_two_processes_with_one_id_differ() {
        // The base is the first use's time in microseconds: not 0.
        let (a, b) = (next_id(), next_id());
        assert!(b > a && a >= counter_base() && counter_base() > 0);
    }
}
