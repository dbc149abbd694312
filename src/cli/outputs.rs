//! The output files of a command as one [`OutputTransaction`]: every path
//! checked before rendering (formats by extension, no two outputs at one
//! path, nothing but regular files replaced), every file written to its
//! temporary, then all renamed into place together.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};

use alpenglow::files::{ImageFormat, OutputTransaction};

/// The outputs of one command.
#[derive(Default)]
pub struct Outputs {
    tx: OutputTransaction,
}

impl Outputs {
    /// Reserves `path` (if given) for the option `flag`.
    pub fn add(&mut self, path: Option<&Path>, flag: &str) -> Result<()> {
        if let Some(path) = path {
            self.tx.add_file(path, flag)?;
        }
        Ok(())
    }

    /// Reserves the 8-bit image `path` of `flag`: `.png`, `.jpg` or `.jpeg`.
    pub fn add_image(&mut self, path: Option<&Path>, flag: &str) -> Result<()> {
        if let Some(path) = path {
            if let Err(problem) = ImageFormat::from_path(path) {
                bail!("{flag} {}: {problem}", path.display());
            }
        }
        self.add(path, flag)
    }

    /// Reserves the OpenEXR `path` of `flag`: it must end in `.exr`.
    pub fn add_exr(&mut self, path: Option<&Path>, flag: &str) -> Result<()> {
        if let Some(path) = path {
            let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
            if ext.as_deref() != Some("exr") {
                bail!("{flag} {}: an OpenEXR file must end in .exr", path.display());
            }
        }
        self.add(path, flag)
    }

    /// Reserves the folder `path` of `flag` (absent or empty).
    pub fn add_dir(&mut self, path: &Path, flag: &str) -> Result<()> {
        Ok(self.tx.add_dir(path, flag)?)
    }

    /// Writes the bytes of `encode` as the output `path` (if given).
    pub fn stage(&mut self, path: Option<&Path>, encode: impl FnOnce() -> alpenglow::Result<Vec<u8>>) -> Result<()> {
        if let Some(path) = path {
            let bytes = encode()?;
            self.tx.stage_bytes(path, &bytes)?;
        }
        Ok(())
    }

    /// Writes the 8-bit image `path` (if given) in the format of its extension.
    pub fn stage_image(&mut self, path: Option<&Path>, rgba: &[u8], width: u32, height: u32) -> Result<()> {
        let Some(path) = path else { return Ok(()) };
        let format = ImageFormat::from_path(path).map_err(|m| anyhow::anyhow!("{}: {m}", path.display()))?;
        self.stage(Some(path), || format.encode_rgba8(rgba, width, height))
    }

    /// Creates the staging folder of the folder output `path`.
    pub fn stage_dir(&mut self, path: &Path) -> Result<PathBuf> {
        Ok(self.tx.stage_dir(path)?)
    }

    /// Renames every output into place (or restores what was there).
    pub fn commit(self) -> Result<()> {
        Ok(self.tx.commit()?)
    }
}
