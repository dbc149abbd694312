//! GLSL -> SPIR-V for alpenglow, built on `shaderc`: what the offline
//! compiler (`alpenglow-tools`, `compile-shaders`) and the viewer's hot
//! reload (the root crate's `hot-reload` feature) share, so both produce
//! the same bytes from the same sources.
//!
//! Sources live under a root (`glsl/`, recursively). Files with a stage
//! extension (`.comp`, `.vert`, `.frag`, `.geom`, `.tesc`, `.tese`,
//! `.mesh`, `.task`) are shaders; `.glsl` files are include-only. Modules
//! target Vulkan 1.3 / SPIR-V 1.6 with performance optimisation.

use shaderc::{
    CompileOptions, Compiler, EnvVersion, IncludeType, OptimizationLevel, ResolvedInclude, ShaderKind, SpirvVersion,
    TargetEnv,
};
use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

/// Why a shader did not compile: shaderc's messages (`file:line: error:
/// ...` lines) or the I/O error that stopped it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CompileError {
    /// The shader, as diagnostics name it (relative to the root's parent:
    /// `glsl/post/tonemap.comp`).
    pub shader: String,
    /// What went wrong (may span lines).
    pub message: String,
}

impl CompileError {
    fn new(shader: &str, message: impl ToString) -> Self {
        CompileError {
            shader: shader.to_owned(),
            message: message.to_string(),
        }
    }

    /// One line per error: shaderc's `file:line: error: ...` lines, or the
    /// whole message on one line prefixed with the shader when it has none.
    pub fn lines(&self) -> Vec<String> {
        let errors: Vec<String> = self
            .message
            .lines()
            .map(str::trim)
            .filter(|l| l.contains(": error:"))
            .map(str::to_owned)
            .collect();
        if errors.is_empty() {
            let text: Vec<&str> = self.message.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
            vec![format!("{}: {}", self.shader, text.join(" "))]
        } else {
            errors
        }
    }
}

impl std::fmt::Display for CompileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "compiling {}: {}", self.shader, self.message)
    }
}

impl std::error::Error for CompileError {}

/// A compiled module.
#[derive(Clone, Debug)]
pub struct Module {
    /// SPIR-V, little-endian bytes.
    pub spirv: Vec<u8>,
    /// shaderc's warnings (empty when none).
    pub warnings: String,
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

/// All files under `root` (recursively, skipping dot-files), unsorted.
pub fn walk(root: &Path, out: &mut Vec<PathBuf>) -> std::io::Result<()> {
    for entry in fs::read_dir(root)? {
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
pub fn shader_sources(glsl_root: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    if glsl_root.is_dir() {
        walk(glsl_root, &mut files)?;
    }
    files.retain(|p| stage_for(p).is_some());
    files.sort();
    Ok(files)
}

/// The file an `#include "name"` in `from` means: next to `from`, else
/// under `root`.
fn find_include(from: &Path, root: &Path, name: &str) -> Option<PathBuf> {
    let next_to = from.parent().map(|d| d.join(name));
    next_to.into_iter().chain([root.join(name)]).find(|c| c.is_file())
}

/// Resolves an `#include` for shaderc. `from` is the including file as
/// diagnostics name it (relative to `base`, the root's parent).
fn resolve_include(base: &Path, root: &Path, name: &str, from: &str) -> Result<ResolvedInclude, String> {
    let Some(found) = find_include(&base.join(from), root, name) else {
        return Err(format!(
            "cannot find include \"{name}\" (searched next to {from} and in {})",
            root.display()
        ));
    };
    let path = found.canonicalize().map_err(|e| e.to_string())?;
    let content = fs::read_to_string(&path).map_err(|e| e.to_string())?;
    let resolved_name = display_name(base, &path);
    Ok(ResolvedInclude { resolved_name, content })
}

/// Name used for `path` in diagnostics: relative to `base` when possible.
pub fn display_name(base: &Path, path: &Path) -> String {
    let rel = path.strip_prefix(base).unwrap_or(path);
    rel.to_string_lossy().replace('\\', "/")
}

/// Every file `source` includes, directly or not, as far as its
/// `#include "..."` lines tell (a textual scan: an include inside a
/// disabled `#if` counts too). Includes that cannot be found are skipped.
pub fn includes(glsl_root: &Path, source: &Path) -> BTreeSet<PathBuf> {
    let mut found = BTreeSet::new();
    let mut pending = vec![source.to_path_buf()];
    while let Some(file) = pending.pop() {
        let Ok(text) = fs::read_to_string(&file) else { continue };
        for line in text.lines() {
            let Some(rest) = line.trim_start().strip_prefix("#include") else {
                continue;
            };
            let Some(name) = rest.trim().strip_prefix('"').and_then(|r| r.split('"').next()) else {
                continue;
            };
            if let Some(path) = find_include(&file, glsl_root, name) {
                let path = path.canonicalize().unwrap_or(path);
                if found.insert(path.clone()) {
                    pending.push(path);
                }
            }
        }
    }
    found
}

/// Compiles one shader under `glsl_root` to SPIR-V. Errors carry shaderc's
/// `file:line: error: ...` messages, the file named relative to the root's
/// parent (`glsl/post/tonemap.comp`).
pub fn compile_module(glsl_root: &Path, source: &Path) -> Result<Module, CompileError> {
    let shown = source.display().to_string();
    let kind = stage_for(source).ok_or_else(|| CompileError::new(&shown, "not a shader stage extension"))?;
    let root = glsl_root
        .canonicalize()
        .map_err(|e| CompileError::new(&shown, format!("shader root {}: {e}", glsl_root.display())))?;
    let path = source.canonicalize().map_err(|e| CompileError::new(&shown, e))?;
    let base = root.parent().unwrap_or(&root).to_path_buf();
    let name = display_name(&base, &path);
    let text = fs::read_to_string(&path).map_err(|e| CompileError::new(&name, format!("reading: {e}")))?;

    let compiler = Compiler::new().ok_or_else(|| CompileError::new(&name, "failed to create shaderc compiler"))?;
    let mut options =
        CompileOptions::new().ok_or_else(|| CompileError::new(&name, "failed to create shaderc options"))?;
    options.set_target_env(TargetEnv::Vulkan, EnvVersion::Vulkan1_3 as u32);
    options.set_target_spirv(SpirvVersion::V1_6);
    options.set_optimization_level(OptimizationLevel::Performance);
    options.set_include_callback(|requested, _ty: IncludeType, from, _depth| {
        resolve_include(&base, &root, requested, from)
    });

    let artifact = compiler
        .compile_into_spirv(&text, kind, &name, "main", Some(&options))
        .map_err(|e| CompileError::new(&name, e))?;
    Ok(Module {
        spirv: artifact.as_binary().iter().flat_map(|w| w.to_le_bytes()).collect(),
        warnings: artifact.get_warning_messages(),
    })
}
