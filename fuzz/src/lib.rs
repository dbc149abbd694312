//! Shared code of the AFL++ targets (one binary per loader, `src/bin/`):
//! each input is written to a temporary file with the loader's extension
//! and loaded; an error must be one non-empty line naming the file. A panic
//! (from the loader or from this check) is a crash for AFL. See
//! `docs/FUZZING.md`.

use std::path::{Path, PathBuf};

/// Where this process writes its case (one file per process, reused).
fn case_path(extension: &str) -> PathBuf {
    std::env::temp_dir().join(format!("alpenglow-afl-{}.{extension}", std::process::id()))
}

/// Writes `bytes` to a file named `*.extension`, runs `load` on it, and
/// panics if it returns an error that is not one line naming the file.
pub fn run<T>(bytes: &[u8], extension: &str, load: impl FnOnce(&Path) -> alpenglow::Result<T>) {
    let path = case_path(extension);
    if std::fs::write(&path, bytes).is_err() {
        return;
    }
    if let Err(e) = load(&path) {
        let message = e.to_string();
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        assert!(
            !message.trim().is_empty() && !message.contains('\n') && message.contains(&name),
            "bad error message: {message:?}"
        );
    }
}
