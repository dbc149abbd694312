//! Unit tests of the input helpers, and the loaders' error and limit tests
//! (`errors`, `limits`, moved from `tests/` in issue 26).

mod errors;
mod limits;

use super::*;

fn temp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("alpenglow-io-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn special_files_are_rejected_by_name() {
    let dir = temp("special");
    let e = read_input(&dir).unwrap_err().to_string();
    assert!(e.contains("is a directory"), "{e}");
    #[cfg(unix)]
    {
        let e = read_input(Path::new("/dev/zero")).unwrap_err().to_string();
        assert!(
            e.contains("/dev/zero: is a character device, not a regular file"),
            "{e}"
        );
        let fifo = dir.join("fifo");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
        assert!(made.success());
        // A FIFO without a writer: opening it would block forever.
        let e = read_input(&fifo).unwrap_err().to_string();
        assert!(e.contains("is a FIFO, not a regular file"), "{e}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn reads_are_capped() {
    let dir = temp("cap");
    let file = dir.join("ten.bin");
    std::fs::write(&file, [7u8; 10]).unwrap();
    assert_eq!(read_input_limited(&file, 10).unwrap(), vec![7u8; 10]);
    let e = read_input_limited(&file, 9).unwrap_err().to_string();
    assert!(e.contains("10 bytes, more than the limit of 9"), "{e}");
    let e = read_input(&dir.join("missing")).unwrap_err().to_string();
    assert!(e.contains("file not found"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
