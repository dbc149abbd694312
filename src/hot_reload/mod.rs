//! Hot reload of the GLSL sources (feature `hot-reload`): a
//! [`ShaderWatcher`] looks at a `glsl/` tree, recompiles with shaderc (the
//! compile function `compile-shaders` uses) the shaders whose source or
//! includes changed, and installs the new SPIR-V in its [`Context`], where
//! it replaces the embedded module of the same name for every pipeline
//! created afterwards. Pipelines already built keep theirs: after a
//! successful reload, build the [`crate::Renderer`] again.
//!
//! ```no_run
//! # fn frame(ctx: &alpenglow::Context, renderer: &mut alpenglow::Renderer) -> alpenglow::Result<()> {
//! let mut watcher = alpenglow::hot_reload::ShaderWatcher::new(ctx, "glsl")?;
//! // once a frame:
//! match watcher.poll() {
//!     Some(Ok(names)) => { /* rebuild the renderer: names were recompiled */ }
//!     Some(Err(errors)) => eprintln!("{errors}"), // file:line: error: ..., one a line
//!     None => {}
//! }
//! # Ok(()) }
//! ```
//!
//! A failed compile installs nothing (not even the shaders that did
//! compile in the same reload): the last good modules stay, and the files
//! of the failed reload are compiled again at the next change.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

use alpenglow_shader_compiler as compiler;

use crate::error::{Error, Result};
use crate::vulkan::Context;

#[cfg(test)]
mod tests;

/// How often [`ShaderWatcher::poll`] looks at the files.
pub const POLL_INTERVAL: Duration = Duration::from_millis(250);

/// What a reload did: the modules recompiled and installed (their names
/// under `glsl/`, as `post/tonemap.comp`), or the compile errors, one line
/// each (`glsl/post/tonemap.comp:12: error: ...`).
pub type Reload = std::result::Result<Vec<String>, String>;

/// A file as last seen: modification time and length.
type Stamp = (Option<SystemTime>, u64);

/// Every file under the root and its stamp.
type Stamps = BTreeMap<PathBuf, Stamp>;

/// Watches a GLSL tree and recompiles what changes; see the module.
pub struct ShaderWatcher {
    ctx: Context,
    /// The tree, canonical.
    root: PathBuf,
    /// The files as the last reload saw them.
    stamps: Stamps,
    /// Files changed since the last successful reload.
    dirty: BTreeSet<PathBuf>,
    /// A change [`Self::poll`] saw, reloaded once the files stay as they
    /// are for one more look (an editor may write a file in pieces).
    settling: Option<Stamps>,
    last_look: Option<Instant>,
}

impl ShaderWatcher {
    /// Watches `glsl_dir` (the repository's `glsl/` or a copy) for the
    /// pipelines `ctx` creates. Nothing is compiled until a file changes:
    /// the embedded modules are taken to match the tree as it is.
    pub fn new(ctx: &Context, glsl_dir: impl AsRef<Path>) -> Result<Self> {
        let dir = glsl_dir.as_ref();
        let root = dir
            .canonicalize()
            .ok()
            .filter(|r| r.is_dir())
            .ok_or_else(|| Error::invalid("glsl directory", format!("{} is not a directory", dir.display())))?;
        let stamps = scan(&root);
        Ok(ShaderWatcher {
            ctx: ctx.clone(),
            root,
            stamps,
            dirty: BTreeSet::new(),
            settling: None,
            last_look: None,
        })
    }

    /// The watched tree.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// Cheap enough to call every frame: looks at the files at most every
    /// [`POLL_INTERVAL`] and reloads once a change has settled (the files
    /// unchanged between two looks). None while nothing (new) changed.
    pub fn poll(&mut self) -> Option<Reload> {
        if self.last_look.is_some_and(|t| t.elapsed() < POLL_INTERVAL) {
            return None;
        }
        self.last_look = Some(Instant::now());
        let now = scan(&self.root);
        if now == self.stamps {
            self.settling = None;
            return None;
        }
        if self.settling.as_ref() != Some(&now) {
            self.settling = Some(now);
            return None;
        }
        self.settling = None;
        self.reload_changes(now)
    }

    /// Looks at the files now and reloads what changed since the last
    /// reload (no waiting: scripts and tests). None when nothing changed
    /// or no shader uses what changed.
    pub fn check(&mut self) -> Option<Reload> {
        let now = scan(&self.root);
        if now == self.stamps {
            return None;
        }
        self.reload_changes(now)
    }

    fn reload_changes(&mut self, now: Stamps) -> Option<Reload> {
        let changed = now
            .iter()
            .filter(|(path, stamp)| self.stamps.get(*path) != Some(stamp))
            .map(|(path, _)| path.clone());
        self.dirty.extend(changed);
        self.stamps = now;
        let shaders = affected(&self.root, &self.dirty);
        if shaders.is_empty() {
            self.dirty.clear();
            return None;
        }
        Some(self.compile(&shaders))
    }

    /// Compiles `shaders`; installs them all if every one compiled.
    fn compile(&mut self, shaders: &[PathBuf]) -> Reload {
        let mut modules = Vec::new();
        let mut errors = Vec::new();
        for shader in shaders {
            match compiler::compile_module(&self.root, shader) {
                Ok(module) => {
                    if !module.warnings.is_empty() {
                        log::warn!("{}", module.warnings.trim_end());
                    }
                    modules.push((compiler::display_name(&self.root, shader), module.spirv));
                }
                Err(e) => errors.extend(e.lines()),
            }
        }
        if !errors.is_empty() {
            return Err(errors.join("\n"));
        }
        let names = modules.iter().map(|(name, _)| name.clone()).collect();
        self.ctx.override_shaders(modules);
        self.dirty.clear();
        Ok(names)
    }
}

/// Every file under `root` with its stamp (files that vanish while being
/// looked at are left out).
fn scan(root: &Path) -> Stamps {
    let mut files = Vec::new();
    if let Err(e) = compiler::walk(root, &mut files) {
        log::debug!("hot reload: reading {}: {e}", root.display());
    }
    files
        .into_iter()
        .filter_map(|path| {
            let meta = std::fs::metadata(&path).ok()?;
            Some((path, (meta.modified().ok(), meta.len())))
        })
        .collect()
}

/// The shaders under `root` that are in `changed` or include one of them.
fn affected(root: &Path, changed: &BTreeSet<PathBuf>) -> Vec<PathBuf> {
    let sources = compiler::shader_sources(root).unwrap_or_default();
    sources
        .into_iter()
        .filter(|s| changed.contains(s) || !compiler::includes(root, s).is_disjoint(changed))
        .collect()
}
