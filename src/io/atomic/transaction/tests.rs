//! Tests of [`OutputTransaction`] and [`crate::io::atomic::clean_stale`].

use std::path::{Path, PathBuf};

use super::super::durable::record::{self, Step};
use super::super::journal;
use super::super::names::Sibling;
use super::super::stale::{clean_stale_where, Seen};
use super::super::tests::{entries, scratch_dir};
use super::*;

/// A process id that no process has (above Linux's largest `pid_max`).
const DEAD: u32 = 4_000_000_000;

fn scratch(name: &str) -> PathBuf {
    scratch_dir(&format!("txn-{name}"))
}

/// What a test's probe says: only [`DEAD`] is dead.
fn dead_only(pid: u32) -> Seen {
    if pid == DEAD {
        Seen::Dead
    } else {
        Seen::Alive(None)
    }
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap()
}

#[test]
fn commit_replaces_every_output_and_leaves_nothing_hidden() {
    let dir = scratch("commit");
    let (a, b, frames) = (dir.join("a.png"), dir.join("b.exr"), dir.join("frames"));
    std::fs::write(&a, "old a").unwrap();
    let mut tx = OutputTransaction::new();
    tx.add_file(&a, "--out").unwrap();
    tx.add_file(&b, "--exr").unwrap();
    tx.add_dir(&frames, "--out-dir").unwrap();
    tx.stage_bytes(&a, b"new a").unwrap();
    tx.stage_bytes(&b, b"new b").unwrap();
    let staged = tx.stage_dir(&frames).unwrap();
    std::fs::write(staged.join("f0"), "frame").unwrap();
    assert_eq!(read(&a), "old a", "nothing is visible before the commit");
    tx.commit().unwrap();
    assert_eq!((read(&a), read(&b)), ("new a".into(), "new b".into()));
    assert_eq!(read(&frames.join("f0")), "frame");
    assert_eq!(entries(&dir), ["a.png", "b.exr", "frames"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn two_outputs_at_one_path_are_refused() {
    let dir = scratch("dup");
    std::fs::create_dir(dir.join("sub")).unwrap();
    let mut tx = OutputTransaction::new();
    tx.add_file(&dir.join("x.png"), "--out").unwrap();
    let e = tx.add_file(&dir.join("sub/../x.png"), "--exr").unwrap_err().to_string();
    assert!(e.contains("--exr names the same file as --out"), "{e}");
    assert_eq!(e.lines().count(), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(unix)]
#[test]
fn non_regular_files_are_never_replaced() {
    let dir = scratch("nonregular");
    let real = dir.join("real.png");
    std::fs::write(&real, "real").unwrap();
    let link = dir.join("link.png");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    let fifo = dir.join("fifo.png");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    let full = dir.join("full");
    std::fs::create_dir(&full).unwrap();
    std::fs::write(full.join("f"), "x").unwrap();
    let cases: [(&Path, &str); 5] = [
        (&link, "a symbolic link"),
        (&fifo, "a FIFO"),
        (Path::new("/dev/null"), "a device node"),
        (&dir, "a directory"),
        (&full, "a directory"),
    ];
    for (path, thing) in cases {
        let mut tx = OutputTransaction::new();
        let e = tx.add_file(path, "--out").unwrap_err().to_string();
        assert!(e.contains(thing) && e.contains(&*path.to_string_lossy()), "{e}");
    }
    let e = OutputTransaction::new()
        .add_dir(&full, "--out-dir")
        .unwrap_err()
        .to_string();
    assert!(e.contains("not empty"), "{e}");
    let e = OutputTransaction::new()
        .add_dir(&link, "--out-dir")
        .unwrap_err()
        .to_string();
    assert!(e.contains("symbolic link"), "{e}");
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert_eq!(read(&real), "real");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A rename that fails at commit time (the last output's) restores the
/// earlier targets' previous contents, and flushes that before the
/// journal goes.
#[test]
fn failed_commit_restores_what_was_there() {
    let dir = scratch("rollback");
    let (a, b, c) = (dir.join("a.png"), dir.join("b.exr"), dir.join("c.json"));
    std::fs::write(&a, "old a").unwrap();
    std::fs::write(&b, "old b").unwrap();
    let mut tx = OutputTransaction::new();
    for (p, what) in [(&a, "--out"), (&c, "--profile"), (&b, "--exr")] {
        tx.add_file(p, what).unwrap();
        tx.stage_bytes(p, b"new").unwrap();
    }
    let temp = tx.outputs[2].entry.sibling(Sibling::Temp, tx.pid);
    record::fail_rename(Some(&temp));
    record::start();
    let e = tx.commit().unwrap_err().to_string();
    record::fail_rename(None);
    let log = record::take();
    let last_rename = log.iter().rposition(|(s, _)| *s == Step::Rename).unwrap();
    let removed = log.iter().position(|(s, _)| *s == Step::Remove).unwrap();
    let synced = (last_rename..removed).any(|i| log[i].0 == Step::SyncDir);
    assert!(synced, "the roll-back is flushed before the journal goes: {log:?}");
    assert!(e.contains("b.exr") && e.contains("rename"), "{e}");
    assert_eq!((read(&a), read(&b)), ("old a".into(), "old b".into()));
    assert_eq!(entries(&dir), ["a.png", "b.exr"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A target that became something else than a regular file after the
/// checks (here a folder) is refused at commit time, before any rename.
#[test]
fn commit_checks_the_targets_again() {
    let dir = scratch("recheck");
    let (a, b) = (dir.join("a.png"), dir.join("b.exr"));
    std::fs::write(&a, "old a").unwrap();
    let mut tx = OutputTransaction::new();
    for (p, what) in [(&a, "--out"), (&b, "--exr")] {
        tx.add_file(p, what).unwrap();
        tx.stage_bytes(p, b"new").unwrap();
    }
    std::fs::create_dir(&b).unwrap();
    std::fs::write(b.join("keep"), "keep").unwrap();
    let e = tx.commit().unwrap_err().to_string();
    assert!(e.contains("b.exr") && e.contains("a directory"), "{e}");
    assert_eq!(read(&a), "old a");
    assert_eq!(read(&b.join("keep")), "keep");
    assert_eq!(entries(&dir), ["a.png", "b.exr"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn dropped_transaction_removes_its_temporaries() {
    let dir = scratch("drop");
    let a = dir.join("a.png");
    let mut tx = OutputTransaction::new();
    tx.add_file(&a, "--out").unwrap();
    tx.add_dir(&dir.join("frames"), "--out-dir").unwrap();
    tx.stage_bytes(&a, b"new").unwrap();
    let frames = tx.stage_dir(&dir.join("frames")).unwrap();
    std::fs::write(frames.join("f"), "x").unwrap();
    let e = tx.stage(&a, |_| Err(Error::output(&a, "simulated"))).unwrap_err();
    assert!(e.to_string().contains("simulated"));
    drop(tx);
    assert!(entries(&dir).is_empty(), "{:?}", entries(&dir));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A transaction of a killed process, interrupted after `renames` of the
/// commit's renames (targets moved aside, then temporaries into place).
fn killed_commit(dir: &Path, renames: usize, commit_point_passed: bool) -> (PathBuf, PathBuf, PathBuf) {
    killed_commit_of(dir, renames, commit_point_passed, Writer { pid: DEAD, start: None })
}

/// [`killed_commit`] of the process `writer`.
fn killed_commit_of(
    dir: &Path,
    renames: usize,
    commit_point_passed: bool,
    writer: Writer,
) -> (PathBuf, PathBuf, PathBuf) {
    let pid = writer.pid;
    let sub = dir.join("sub");
    std::fs::create_dir_all(&sub).unwrap();
    let (a, b, c) = (dir.join("a.png"), sub.join("b.exr"), dir.join("c.json"));
    std::fs::write(&a, "old a").unwrap();
    std::fs::write(&b, "old b").unwrap();
    let mut tx = OutputTransaction::with_pid(pid);
    // All added first: adding cleans up after dead processes, as DEAD is.
    for (p, what) in [(&a, "--out"), (&b, "--exr"), (&c, "--profile")] {
        tx.add_file(p, what).unwrap();
    }
    for p in [&a, &b, &c] {
        tx.stage_bytes(p, b"new").unwrap();
    }
    for o in &mut tx.outputs {
        o.entry.existed = exists(&o.entry.target);
    }
    let list: Vec<Entry> = tx.outputs.iter().map(|o| o.entry.clone()).collect();
    let journals = journal::write_all(&list, writer).unwrap();
    let mut steps: Vec<(PathBuf, PathBuf)> = list
        .iter()
        .filter(|e| e.existed)
        .map(|e| (e.target.clone(), e.sibling(Sibling::Backup, pid)))
        .collect();
    steps.extend(list.iter().map(|e| (e.sibling(Sibling::Temp, pid), e.target.clone())));
    for (from, to) in steps.iter().take(renames) {
        std::fs::rename(from, to).unwrap();
    }
    if commit_point_passed {
        std::fs::remove_file(&journals[0]).unwrap();
    }
    // The process dies: nothing of it runs any more.
    tx.committed = true;
    drop(tx);
    (a, b, c)
}

#[test]
fn next_run_rolls_back_a_commit_killed_at_any_rename() {
    for renames in 0..=5 {
        let dir = scratch(&format!("killed{renames}"));
        let (a, b, c) = killed_commit(&dir, renames, false);
        // A run writing into either directory recovers the whole transaction.
        let from = if renames % 2 == 0 { dir.clone() } else { dir.join("sub") };
        assert!(clean_stale_where(&from, dead_only) > 0);
        clean_stale_where(&dir, dead_only);
        clean_stale_where(&dir.join("sub"), dead_only);
        assert_eq!(
            (read(&a), read(&b)),
            ("old a".into(), "old b".into()),
            "after {renames} renames"
        );
        assert!(!c.exists(), "after {renames} renames");
        assert_eq!(entries(&dir), ["a.png", "sub"], "after {renames} renames");
        assert_eq!(entries(&dir.join("sub")), ["b.exr"], "after {renames} renames");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn next_run_keeps_a_commit_killed_after_its_commit_point() {
    let dir = scratch("committed");
    let (a, b, c) = killed_commit(&dir, 5, true);
    clean_stale_where(&dir.join("sub"), dead_only);
    clean_stale_where(&dir, dead_only);
    assert_eq!(
        (read(&a), read(&b), read(&c)),
        ("new".into(), "new".into(), "new".into())
    );
    assert_eq!(entries(&dir), ["a.png", "c.json", "sub"]);
    assert_eq!(entries(&dir.join("sub")), ["b.exr"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn stale_siblings_of_dead_processes_are_removed_and_live_ones_kept() {
    let dir = scratch("stale");
    let live = std::process::id();
    let names = [
        format!(".out.png.tmp-{DEAD}-3"),
        format!(".out.exr.bak-{DEAD}-4"),
        format!(".frames.partial-{DEAD}"),
        format!(".frames.partial-{DEAD}-9"),
    ];
    for n in &names {
        if n.contains("partial") {
            std::fs::create_dir(dir.join(n)).unwrap();
            std::fs::write(dir.join(n).join("frame_00000.png"), "x").unwrap();
        } else {
            std::fs::write(dir.join(n), "x").unwrap();
        }
    }
    let kept = [
        format!(".out.png.tmp-{live}-1"),
        ".out.png.tmp-x-1".to_string(),
        "out.png".to_string(),
    ];
    for n in &kept {
        std::fs::write(dir.join(n), "x").unwrap();
    }
    assert_eq!(crate::io::atomic::clean_stale(&dir), names.len());
    let mut expected = kept.to_vec();
    expected.sort();
    assert_eq!(entries(&dir), expected);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A commit whose process id belongs to a running process is rolled back
/// unless that process's start time is the journal's: a live process of
/// another start time (the id reused; this very process included), yes;
/// the writer itself, no.
#[cfg(target_os = "linux")]
#[test]
fn a_reused_process_id_does_not_block_the_roll_back() {
    use super::super::stale::start_ticks;
    let mut child = std::process::Command::new("sleep").arg("60").spawn().unwrap();
    let (pid, me) = (child.id(), std::process::id());
    let (start, my_start) = (start_ticks(pid).unwrap(), start_ticks(me).unwrap());
    let cases = [
        (
            "child-wrong",
            Writer {
                pid,
                start: Some(start + 1),
            },
            true,
        ),
        (
            "child-true",
            Writer {
                pid,
                start: Some(start),
            },
            false,
        ),
        (
            "self-wrong",
            Writer {
                pid: me,
                start: Some(my_start.wrapping_sub(1)),
            },
            true,
        ),
        (
            "self-true",
            Writer {
                pid: me,
                start: Some(my_start),
            },
            false,
        ),
    ];
    for (name, writer, rolled_back) in cases {
        let dir = scratch(&format!("reused-{name}"));
        let (a, b, c) = killed_commit_of(&dir, 3, false, writer);
        crate::io::atomic::clean_stale(&dir);
        crate::io::atomic::clean_stale(&dir.join("sub"));
        let journals = |d: &Path| entries(d).iter().filter(|n| n.ends_with(".journal")).count();
        if rolled_back {
            assert_eq!((read(&a), read(&b)), ("old a".into(), "old b".into()), "{name}");
            assert!(!c.exists(), "{name}");
            assert_eq!(entries(&dir), ["a.png", "sub"], "{name}");
            assert_eq!(entries(&dir.join("sub")), ["b.exr"], "{name}");
        } else {
            // Left as the running writer has it: moved aside, partly renamed.
            assert_eq!((journals(&dir), journals(&dir.join("sub"))), (1, 1), "{name}");
            assert_eq!(read(&a), "new", "{name}");
            assert!(!b.exists() && !c.exists(), "{name}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
    child.kill().unwrap();
    child.wait().unwrap();
}

/// A journal of format 1 (no start time) of a running process id: rolled
/// back when that process started after the journal was written, left
/// alone when it may have written it.
#[cfg(target_os = "linux")]
#[test]
fn old_journals_without_a_start_time_are_still_read() {
    let mut child = std::process::Command::new("sleep").arg("60").spawn().unwrap();
    let pid = child.id();
    let hour_ago = std::time::SystemTime::now() - std::time::Duration::from_secs(3600);
    for (name, written, rolled_back) in [
        ("before", hour_ago, true),
        ("after", std::time::SystemTime::now(), false),
    ] {
        let dir = scratch(&format!("v1-{name}"));
        let (a, b, _) = killed_commit_of(&dir, 3, false, Writer { pid, start: None });
        for d in [dir.clone(), dir.join("sub")] {
            for n in entries(&d).iter().filter(|n| n.ends_with(".journal")) {
                let path = d.join(n);
                let text = read(&path)
                    .replace("alpenglow commit journal 2", "alpenglow commit journal 1")
                    .replace("start unknown\n", "");
                std::fs::write(&path, text).unwrap();
                let file = std::fs::OpenOptions::new().write(true).open(&path).unwrap();
                file.set_modified(written).unwrap();
            }
        }
        crate::io::atomic::clean_stale(&dir);
        crate::io::atomic::clean_stale(&dir.join("sub"));
        let restored = read(&a) == "old a" && read(&b) == "old b";
        assert_eq!(restored, rolled_back, "journal written {name} the process started");
        assert_eq!(entries(&dir).len() == 2, rolled_back, "{name}: {:?}", entries(&dir));
        std::fs::remove_dir_all(&dir).unwrap();
    }
    child.kill().unwrap();
    child.wait().unwrap();
}

/// What a recorded path is, for comparing logs: one of `names`, or a
/// journal (or its temporary) in one of them.
fn label(path: &Path, names: &[(&str, &Path)]) -> String {
    if let Some((n, _)) = names.iter().find(|(_, p)| *p == path) {
        return n.to_string();
    }
    let dir = names::parent_dir(path);
    let in_dir = names.iter().find(|(_, p)| *p == dir).map_or("?", |(n, _)| n);
    let file = path.file_name().unwrap().to_string_lossy();
    match (file.contains("alpenglow-commit-"), file.contains(".tmp-")) {
        (true, true) => format!("journal temp in {in_dir}"),
        (true, false) => format!("journal in {in_dir}"),
        _ => format!("{} (unexpected)", path.display()),
    }
}

/// Every step of a commit is flushed before the next one relies on it, in
/// the order of the module documentation: temporaries, journals (each
/// written, flushed, renamed, its directory flushed), the renames and then
/// the directories, the journals' removal and then the directories.
#[test]
fn a_commit_flushes_every_step_in_order() {
    let dir = scratch("fsync-order");
    let sub = dir.join("sub");
    std::fs::create_dir(&sub).unwrap();
    let (a, b, frames) = (dir.join("a.png"), sub.join("b.exr"), dir.join("frames"));
    std::fs::write(&a, "old a").unwrap();
    let mut tx = OutputTransaction::new();
    tx.add_file(&a, "--out").unwrap();
    tx.add_file(&b, "--exr").unwrap();
    tx.add_dir(&frames, "--out-dir").unwrap();
    tx.stage_bytes(&a, b"new a").unwrap();
    tx.stage_bytes(&b, b"new b").unwrap();
    let staged = tx.stage_dir(&frames).unwrap();
    std::fs::write(staged.join("f0"), "frame").unwrap();
    let pid = tx.pid;
    let e: Vec<Entry> = tx.outputs.iter().map(|o| o.entry.clone()).collect();
    let (d1, d2) = (
        names::parent_dir(&e[0].target).to_path_buf(),
        names::parent_dir(&e[1].target).to_path_buf(),
    );
    let (temp_a, temp_b) = (e[0].sibling(Sibling::Temp, pid), e[1].sibling(Sibling::Temp, pid));
    let (partial, backup_a) = (e[2].sibling(Sibling::Partial, pid), e[0].sibling(Sibling::Backup, pid));
    let frame = partial.join("f0");
    let names: [(&str, &Path); 9] = [
        ("d1", &d1),
        ("d2", &d2),
        ("temp a", &temp_a),
        ("temp b", &temp_b),
        ("partial", &partial),
        ("frame", &frame),
        ("a", &e[0].target),
        ("backup a", &backup_a),
        ("b", &e[1].target),
    ];
    record::start();
    tx.commit().unwrap();
    let log: Vec<(Step, String)> = record::take()
        .into_iter()
        .map(|(s, p)| (s, label(&p, &names)))
        .collect();
    use Step::*;
    let expected: Vec<(Step, &str)> = vec![
        (SyncFile, "temp a"),
        (SyncFile, "temp b"),
        (SyncFile, "frame"),
        (SyncDir, "partial"),
        (Write, "journal temp in d1"),
        (SyncFile, "journal temp in d1"),
        (Rename, "journal temp in d1"),
        (SyncDir, "d1"),
        (Write, "journal temp in d2"),
        (SyncFile, "journal temp in d2"),
        (Rename, "journal temp in d2"),
        (SyncDir, "d2"),
        (Rename, "a"),
        (Rename, "temp a"),
        (Rename, "temp b"),
        (Rename, "partial"),
        (SyncDir, "d1"),
        (SyncDir, "d2"),
        (Remove, "journal in d1"),
        (Remove, "journal in d2"),
        (SyncDir, "d1"),
        (SyncDir, "d2"),
    ];
    let expected: Vec<(Step, String)> = expected.into_iter().map(|(s, l)| (s, l.to_string())).collect();
    assert_eq!(log, expected);
    assert_eq!(entries(&dir), ["a.png", "frames", "sub"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Recovering a killed commit flushes the roll-back (backups renamed back)
/// before it removes a journal, and the removal after.
#[test]
fn a_recovery_flushes_its_roll_back_before_removing_the_journal() {
    let dir = scratch("fsync-recover");
    let (a, b, _) = killed_commit(&dir, 4, false);
    let sub = names::parent_dir(&b.canonicalize().unwrap()).to_path_buf();
    record::start();
    assert!(clean_stale_where(&dir, dead_only) > 0);
    let log = record::take();
    let at = |f: &dyn Fn(&(Step, PathBuf)) -> bool| log.iter().position(f);
    let last_rename = log
        .iter()
        .rposition(|(s, _)| *s == Step::Rename)
        .expect("backups renamed back");
    let first_remove = at(&|(s, p)| *s == Step::Remove && p.to_string_lossy().ends_with(".journal")).unwrap();
    let sync_sub = at(&|(s, p)| *s == Step::SyncDir && *p == sub).unwrap();
    assert!(last_rename < sync_sub && sync_sub < first_remove, "{log:?}");
    assert_eq!(log.last().map(|(s, _)| *s), Some(Step::SyncDir), "{log:?}");
    assert_eq!((read(&a), read(&b)), ("old a".into(), "old b".into()));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A single atomic write: written, flushed, renamed, directory flushed.
#[test]
fn an_atomic_write_flushes_the_file_before_renaming_and_the_directory_after() {
    let dir = scratch("fsync-single");
    let target = dir.join("x.json");
    record::start();
    crate::io::atomic::write_bytes_atomically(&target, b"{}").unwrap();
    let steps: Vec<Step> = record::take().into_iter().map(|(s, _)| s).collect();
    assert_eq!(steps, [Step::Write, Step::SyncFile, Step::Rename, Step::SyncDir]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An output whose folder vanished after it was added is that output's
/// error, naming it and the folder (it was "internal error: the output
/// was not added"), for files and folders alike.
#[test]
fn a_vanished_folder_is_the_outputs_error() {
    let dir = scratch("vanished");
    let sub = dir.join("sub");
    std::fs::create_dir(&sub).unwrap();
    let (file, frames) = (sub.join("o.png"), sub.join("frames"));
    let mut tx = OutputTransaction::new();
    tx.add_file(&file, "--out").unwrap();
    tx.add_dir(&frames, "--out-dir").unwrap();
    std::fs::remove_dir(&sub).unwrap();
    for e in [
        tx.stage_bytes(&file, b"x").unwrap_err(),
        tx.stage_dir(&frames).unwrap_err(),
    ] {
        let line = e.to_string();
        assert!(line.contains("sub") && line.contains("no longer exists"), "{line}");
        assert!(!line.contains("internal error"), "{line}");
    }
    drop(tx);
    std::fs::remove_dir_all(&dir).unwrap();
}
