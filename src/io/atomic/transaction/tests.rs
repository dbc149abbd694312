//! Tests of [`OutputTransaction`] and [`crate::io::atomic::clean_stale`].

use std::path::{Path, PathBuf};

use super::super::journal;
use super::super::names::Sibling;
use super::super::stale::clean_stale_where;
use super::super::tests::{entries, scratch_dir};
use super::*;

/// A process id that no process has (above Linux's largest `pid_max`).
const DEAD: u32 = 4_000_000_000;

fn scratch(name: &str) -> PathBuf {
    scratch_dir(&format!("txn-{name}"))
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

/// A rename that fails at commit time (the last output's temporary is
/// gone) restores the earlier targets' previous contents.
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
    std::fs::remove_file(tx.outputs[2].entry.sibling(Sibling::Temp, tx.pid)).unwrap();
    let e = tx.commit().unwrap_err().to_string();
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
    let sub = dir.join("sub");
    std::fs::create_dir_all(&sub).unwrap();
    let (a, b, c) = (dir.join("a.png"), sub.join("b.exr"), dir.join("c.json"));
    std::fs::write(&a, "old a").unwrap();
    std::fs::write(&b, "old b").unwrap();
    let mut tx = OutputTransaction::with_pid(DEAD);
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
    let journals = journal::write_all(&list, DEAD).unwrap();
    let mut steps: Vec<(PathBuf, PathBuf)> = list
        .iter()
        .filter(|e| e.existed)
        .map(|e| (e.target.clone(), e.sibling(Sibling::Backup, DEAD)))
        .collect();
    steps.extend(list.iter().map(|e| (e.sibling(Sibling::Temp, DEAD), e.target.clone())));
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
        assert!(clean_stale_where(&from, |p| p == DEAD) > 0);
        clean_stale_where(&dir, |p| p == DEAD);
        clean_stale_where(&dir.join("sub"), |p| p == DEAD);
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
    clean_stale_where(&dir.join("sub"), |p| p == DEAD);
    clean_stale_where(&dir, |p| p == DEAD);
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
