//! Shared parts of the benchmarks and analysis programs in `src/bin/`
//! (`cargo run --release -p alpenglow-bench --bin NAME -- …`). They reach
//! alpenglow's internals through the hidden `alpenglow::bench` module; the
//! crate's own examples use only its front door.

use std::path::{Path, PathBuf};

pub mod points;
pub mod terrain;

/// The repository root (test data lives under `tests/data`).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}
