//! Offline GLSL -> SPIR-V compiler for alpenglow, built on `shaderc`.
//!
//! Sources live under `glsl/` (recursively). Files with a stage extension
//! (`.comp`, `.vert`, `.frag`, `.geom`, `.tesc`, `.tese`, `.mesh`, `.task`)
//! are compiled to `spirv/<same relative path>.spv`; `.glsl` files are
//! include-only. Modules target Vulkan 1.3 / SPIR-V 1.6 with performance
//! optimisation, so the checked-in `.spv` files are byte-for-byte
//! reproducible and [`check`] can verify them against the sources.

use anyhow::{anyhow, bail, Context, Result};
use shaderc::{
    CompileOptions, Compiler, EnvVersion, IncludeType, OptimizationLevel, ResolvedInclude, ShaderKind, SpirvVersion,
    TargetEnv,
};
use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

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

/// Shader stage for a file extension, or `None` for non-shader files
/// (including `.glsl` include files).
pub fn stage_for(path: &Path) -> Option<ShaderKind> {
    Some(match path.extension()?.to_str()? {
        "comp" => ShaderKind::Compute,
        "vert" => ShaderKind::Vertex,
        "frag" => ShaderKind::Fragment,
        "geom" => ShaderKind::Geometry,
        "tesc" => ShaderKind::TessControl,
        "tese" => ShaderKind::TessEvaluation,
        "mesh" => ShaderKind::Mesh,
        "task" => ShaderKind::Task,
        _ => return None,
    })
}

/// All files under `root` (recursively, skipping dot-files), sorted.
fn walk(root: &Path, out: &mut Vec<PathBuf>) -> Result<()> {
    let entries = fs::read_dir(root).with_context(|| format!("reading {}", root.display()))?;
    for entry in entries {
        let entry = entry?;
        if entry.file_name().to_string_lossy().starts_with('.') {
            continue;
        }
        let path = entry.path();
        if entry.file_type()?.is_dir() {
            walk(&path, out)?;
        } else {
            out.push(path);
        }
    }
    Ok(())
}

/// Every compilable shader under `glsl_root`, sorted. A missing root yields
/// an empty list.
pub fn shader_sources(glsl_root: &Path) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    if glsl_root.is_dir() {
        walk(glsl_root, &mut files)?;
    }
    files.retain(|p| stage_for(p).is_some());
    files.sort();
    Ok(files)
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

/// Resolves an `#include` against the including file's directory, then
/// against `root`. Names are `base`-relative paths (e.g. `glsl/common.glsl`).
fn resolve_include(base: &Path, root: &Path, name: &str, from: &str) -> Result<ResolvedInclude> {
    let from_dir = base.join(from).parent().map(Path::to_path_buf);
    let candidates = from_dir.iter().map(|d| d.join(name)).chain([root.join(name)]);
    for candidate in candidates {
        if candidate.is_file() {
            let path = candidate.canonicalize()?;
            let content = fs::read_to_string(&path)?;
            let resolved_name = display_name(base, &path);
            return Ok(ResolvedInclude { resolved_name, content });
        }
    }
    bail!(
        "cannot find include \"{name}\" (searched next to {from} and in {})",
        root.display()
    )
}

/// Name used for `path` in diagnostics: relative to `base` when possible.
fn display_name(base: &Path, path: &Path) -> String {
    let rel = path.strip_prefix(base).unwrap_or(path);
    rel.to_string_lossy().replace('\\', "/")
}

/// Compiles one shader to SPIR-V (little-endian bytes). Warnings are printed
/// to stderr; errors carry shaderc's `file:line: error: ...` messages.
pub fn compile(glsl_root: &Path, source: &Path) -> Result<Vec<u8>> {
    let kind = stage_for(source).ok_or_else(|| anyhow!("{}: not a shader stage extension", source.display()))?;
    let root = glsl_root
        .canonicalize()
        .with_context(|| format!("shader root {}", glsl_root.display()))?;
    let path = source
        .canonicalize()
        .with_context(|| format!("shader {}", source.display()))?;
    let base = root.parent().unwrap_or(&root).to_path_buf();
    let name = display_name(&base, &path);
    let text = fs::read_to_string(&path).with_context(|| format!("reading {name}"))?;

    let compiler = Compiler::new().ok_or_else(|| anyhow!("failed to create shaderc compiler"))?;
    let mut options = CompileOptions::new().ok_or_else(|| anyhow!("failed to create shaderc options"))?;
    options.set_target_env(TargetEnv::Vulkan, EnvVersion::Vulkan1_3 as u32);
    options.set_target_spirv(SpirvVersion::V1_6);
    options.set_optimization_level(OptimizationLevel::Performance);
    options.set_include_callback(|requested, _ty: IncludeType, from, _depth| {
        resolve_include(&base, &root, requested, from).map_err(|e| format!("{e:#}"))
    });

    let artifact = compiler
        .compile_into_spirv(&text, kind, &name, "main", Some(&options))
        .map_err(|e| anyhow!("{e}"))
        .with_context(|| format!("compiling {name}"))?;
    if artifact.get_num_warnings() > 0 {
        eprint!("{}", artifact.get_warning_messages());
    }
    Ok(artifact.as_binary().iter().flat_map(|w| w.to_le_bytes()).collect())
}

/// Every `.spv` file under `spirv_root` that no source in `glsl_root` maps to.
fn orphans(glsl_root: &Path, spirv_root: &Path, sources: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let expected: BTreeSet<PathBuf> = sources.iter().map(|s| spirv_path(glsl_root, spirv_root, s)).collect();
    let mut files = Vec::new();
    if spirv_root.is_dir() {
        walk(spirv_root, &mut files)?;
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
    let sources = shader_sources(glsl_root)?;
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
    let sources = shader_sources(glsl_root)?;
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
