//! Hot reload of `glsl/` in the viewer (feature `hot-reload`): each frame
//! asks the library's [`ShaderWatcher`] (it looks at the files four times
//! a second); when changed shaders compiled, the renderer is rebuilt from
//! the kept setup (same settings and lighting; the camera is the
//! viewer's); when they did not, the old renderer keeps running and the
//! errors (one line each, `glsl/post/tonemap.comp:12: error: ...`) go to
//! the overlay and, once, to the log.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, Result};

use alpenglow::hot_reload::ShaderWatcher;
use alpenglow::Context;

use super::Live;

/// The `glsl/` the viewer watches without `--glsl`: the current
/// directory's, else the one of the tree the binary was built from.
fn default_glsl_dir() -> Result<PathBuf> {
    let built_from = Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl");
    [PathBuf::from("glsl"), built_from.clone()]
        .into_iter()
        .find(|d| d.is_dir())
        .ok_or_else(|| {
            anyhow!(
                "no glsl/ here nor in {} to watch; pass --glsl DIR",
                built_from.display()
            )
        })
}

/// The watcher and what the viewer last showed of it.
pub(super) struct ShaderReload {
    watcher: ShaderWatcher,
}

impl ShaderReload {
    /// Watches `dir` (default: [`default_glsl_dir`]) for `ctx`'s pipelines.
    pub(super) fn new(ctx: &Context, dir: Option<&Path>) -> Result<Self> {
        let dir = match dir {
            Some(dir) => dir.to_path_buf(),
            None => default_glsl_dir()?,
        };
        let watcher = ShaderWatcher::new(ctx, &dir).map_err(|e| anyhow!("--glsl: {e}"))?;
        log::info!("hot reload: watching {}", watcher.root().display());
        Ok(ShaderReload { watcher })
    }

    /// Reloads what changed: rebuilds `state`'s renderer, or sets `error`
    /// (cleared by the next successful reload).
    pub(super) fn frame(&mut self, state: Option<&mut Live>, error: &mut Option<String>) {
        let Some(state) = state else { return };
        let Some(reload) = self.watcher.poll() else { return };
        let outcome = reload.and_then(|names| {
            state
                .rebuild(|_| {})
                .map(|()| names.len())
                .map_err(|e| format!("shaders compiled but the renderer failed: {e:#}"))
        });
        match outcome {
            Ok(n) => {
                eprintln!("shaders reloaded: {n}");
                *error = None;
            }
            Err(text) => {
                log::warn!("shader error (the last good shaders keep running):\n{text}");
                *error = Some(text);
            }
        }
    }
}
