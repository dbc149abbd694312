//! Offline GLSL -> SPIR-V compiler for alpenglow, built on `shaderc`.
//!
//! Sources live under `glsl/` (recursively). Files with a stage extension
//! (`.comp`, `.vert`, `.frag`, `.geom`, `.tesc`, `.tese`, `.mesh`, `.task`)
//! are compiled to `spirv/<same relative path>.spv`; `.glsl` files are
//! include-only. Modules target Vulkan 1.3 / SPIR-V 1.6 with performance
//! optimisation, so the checked-in `.spv` files are byte-for-byte
//! reproducible and [`check`] can verify them against the sources.

use alpenglow_shader_compiler::{compile_module, display_name, walk};
use anyhow::{bail, Context, Result};
use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

pub use alpenglow_shader_compiler::{shader_sources, stage_for};

/// Command that regenerates every SPIR-V module.
pub const FIX_COMMAND: &str = "cargo run -p alpenglow-tools --bin compile-shaders";

/// Repository root (the parent of this crate's manifest directory).
pub fn repo_root() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    root.canonicalize().unwrap_or(root)
}

/// `<repo>/glsl`, the default shader source root.
pub fn default_glsl_root() -> PathBuf {
    repo_root().join("glsl")
}

/// `<repo>/spirv`, the default output root.
pub fn default_spirv_root() -> PathBuf {
    repo_root().join("spirv")
}

/// `source` relative to `root`, tolerating relative/absolute mismatches.
fn relative(root: &Path, source: &Path) -> Option<PathBuf> {
    if let Ok(rel) = source.strip_prefix(root) {
        return Some(rel.to_path_buf());
    }
    let (root, source) = (root.canonicalize().ok()?, source.canonicalize().ok()?);
    source.strip_prefix(root).ok().map(Path::to_path_buf)
}

/// Output path of `source`: `spirv_root/<path relative to glsl_root>.spv`.
pub fn spirv_path(glsl_root: &Path, spirv_root: &Path, source: &Path) -> PathBuf {
    let rel = relative(glsl_root, source).unwrap_or_else(|| source.file_name().map(PathBuf::from).unwrap_or_default());
    let mut name = rel.into_os_string();
    name.push(".spv");
    spirv_root.join(name)
}

/// Compiles one shader to SPIR-V (little-endian bytes). Warnings are printed
/// to stderr; errors carry shaderc's `file:line: error: ...` messages.
pub fn compile(glsl_root: &Path, source: &Path) -> Result<Vec<u8>> {
    let module = compile_module(glsl_root, source)?;
    eprint!("{}", module.warnings);
    Ok(module.spirv)
}

/// Every `.spv` file under `spirv_root` that no source in `glsl_root` maps to.
fn orphans(glsl_root: &Path, spirv_root: &Path, sources: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let expected: BTreeSet<PathBuf> = sources.iter().map(|s| spirv_path(glsl_root, spirv_root, s)).collect();
    let mut files = Vec::new();
    if spirv_root.is_dir() {
        walk(spirv_root, &mut files).with_context(|| format!("reading {}", spirv_root.display()))?;
    }
    files.retain(|p| p.extension().is_some_and(|e| e == "spv") && !expected.contains(p));
    files.sort();
    Ok(files)
}

/// `path` shown relative to the parent of `root` (e.g. `spirv/a.comp.spv`).
fn short(root: &Path, path: &Path) -> String {
    let base = root.parent().unwrap_or(root);
    display_name(base, path)
}

/// Lists every out-of-date module, one human-readable line each:
/// `stale: ...` (bytes differ from a fresh compile), `missing: ...` or
/// `orphan: ...` (a `.spv` without source). Compile errors are returned as `Err`.
pub fn check(glsl_root: &Path, spirv_root: &Path) -> Result<Vec<String>> {
    let sources = shader_sources(glsl_root).with_context(|| format!("reading {}", glsl_root.display()))?;
    let mut problems = Vec::new();
    for source in &sources {
        let fresh = compile(glsl_root, source)?;
        let out = spirv_path(glsl_root, spirv_root, source);
        match fs::read(&out) {
            Ok(bytes) if bytes == fresh => {}
            Ok(_) => problems.push(format!(
                "stale: {} (out of date with {})",
                short(spirv_root, &out),
                short(glsl_root, source)
            )),
            Err(_) => problems.push(format!(
                "missing: {} (from {})",
                short(spirv_root, &out),
                short(glsl_root, source)
            )),
        }
    }
    for orphan in orphans(glsl_root, spirv_root, &sources)? {
        problems.push(format!("orphan: {} (no source)", short(spirv_root, &orphan)));
    }
    Ok(problems)
}

/// Compiles every shader, writing only modules whose bytes changed, and
/// deletes orphan `.spv` files. Nothing is written if any shader fails to
/// compile (all errors are reported). Returns the number of files written.
pub fn compile_all(glsl_root: &Path, spirv_root: &Path) -> Result<usize> {
    let sources = shader_sources(glsl_root).with_context(|| format!("reading {}", glsl_root.display()))?;
    let mut modules = Vec::new();
    let mut errors = Vec::new();
    for source in &sources {
        match compile(glsl_root, source) {
            Ok(bytes) => modules.push((spirv_path(glsl_root, spirv_root, source), bytes)),
            Err(e) => errors.push(format!("{e:#}")),
        }
    }
    if !errors.is_empty() {
        bail!("{} shader(s) failed:\n{}", errors.len(), errors.join("\n"));
    }
    let mut written = 0;
    for (out, bytes) in modules {
        if fs::read(&out).ok().as_deref() == Some(&bytes[..]) {
            continue;
        }
        if let Some(dir) = out.parent() {
            fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
        fs::write(&out, &bytes).with_context(|| format!("writing {}", out.display()))?;
        written += 1;
    }
    for orphan in orphans(glsl_root, spirv_root, &sources)? {
        fs::remove_file(&orphan).with_context(|| format!("removing {}", orphan.display()))?;
        // Drop directories the orphan leaves empty (never spirv_root itself).
        let mut dir = orphan.parent();
        while let Some(d) = dir.filter(|d| *d != spirv_root && d.starts_with(spirv_root)) {
            if fs::remove_dir(d).is_err() {
                break;
            }
            dir = d.parent();
        }
    }
    Ok(written)
}
