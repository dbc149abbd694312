//! The alpenglow library builds without the command line's crates: with
//! `--no-default-features` (no `cli` feature) none of them is a normal
//! dependency of the `alpenglow` package.

use std::path::Path;
use std::process::Command;

/// Crates only the `alpenglow` binary may use.
const CLI_ONLY: [&str; 4] = ["clap", "indicatif", "env_logger", "anyhow"];

#[test]
fn library_needs_no_cli_crates() {
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tools/ lies in the workspace root");
    let out = Command::new(env!("CARGO"))
        .current_dir(workspace)
        .args([
            "tree",
            "-p",
            "alpenglow",
            "-e",
            "normal",
            "--no-default-features",
            "--prefix",
            "none",
            "--offline",
        ])
        .output()
        .expect("cannot run cargo tree");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "cargo tree failed ({}):\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.lines().any(|l| l.starts_with("alpenglow ")),
        "cargo tree did not list the alpenglow package:\n{stdout}"
    );
    // Lines are `name vX.Y.Z [(features)] [(*)]`.
    let found: Vec<&str> = stdout
        .lines()
        .filter(|l| CLI_ONLY.contains(&l.split_whitespace().next().unwrap_or("")))
        .collect();
    assert!(
        found.is_empty(),
        "the library without the `cli` feature depends on command-line crates: {found:?}"
    );
}
