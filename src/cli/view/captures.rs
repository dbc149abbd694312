//! The viewer's captures: F12 writes the frame on screen (PNG, EXR,
//! profile JSON and Perfetto trace) into `--capture-dir`; `--screenshot`
//! writes the last frame at exit. Completed frames' profiles are kept for
//! the overlay and the captures.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};

use anyhow::Result;

use alpenglow::tools::profile::{chrome_trace, profile_json};
use alpenglow::{FrameOutcome, FrameProfile, Renderer};

use super::super::outputs::Outputs;

/// Completed frames whose profiles are kept.
pub const PROFILE_HISTORY: usize = 240;

pub struct Captures {
    dir: PathBuf,
    screenshot: Option<PathBuf>,
    /// F12 was pressed: capture the next frame rendered.
    requested: bool,
    /// The last frame presented and the view it showed.
    last: Option<(FrameOutcome, usize)>,
    /// The profiles of the last completed frames, oldest first.
    pub profiles: VecDeque<FrameProfile>,
}

impl Captures {
    pub fn new(dir: PathBuf, screenshot: Option<PathBuf>) -> Captures {
        Captures {
            dir,
            screenshot,
            requested: false,
            last: None,
            profiles: VecDeque::new(),
        }
    }

    /// Captures the next frame.
    pub fn request(&mut self) {
        self.requested = true;
    }

    /// After each frame: collects the completed frames' profiles, and
    /// writes the capture asked for.
    pub fn frame_done(&mut self, renderer: &mut Renderer, frame: FrameOutcome, shown: usize) -> Result<()> {
        self.last = Some((frame, shown));
        if std::mem::take(&mut self.requested) {
            let files = self.capture(renderer, frame, shown)?;
            println!("F12: frame {} written to {}", frame.frame, files.join(", "));
        }
        self.keep(renderer.take_profiles());
        Ok(())
    }

    fn keep(&mut self, profiles: Vec<FrameProfile>) {
        self.profiles.extend(profiles);
        while self.profiles.len() > PROFILE_HISTORY {
            self.profiles.pop_front();
        }
    }

    /// Writes `frame` (view `shown`): waits for it and its profile.
    fn capture(&mut self, renderer: &mut Renderer, frame: FrameOutcome, shown: usize) -> Result<Vec<String>> {
        let images = renderer.read_view(&frame, shown)?;
        // Every frame up to this one is complete: their profiles too.
        let profiles = renderer.finish()?;
        let this: Vec<FrameProfile> = profiles.iter().filter(|p| p.frame == frame.frame).cloned().collect();
        self.keep(profiles);
        let device = renderer.context().info().name.clone();
        let raster = renderer.raster_path();
        let memory = renderer.context().memory_use();
        let path = |ext: &str| self.dir.join(format!("capture_{:05}.{ext}", frame.frame));
        let (png, exr, json, trace) = (path("png"), path("exr"), path("json"), path("trace.json"));
        let mut outputs = Outputs::default();
        for (file, flag) in [
            (&png, "F12 PNG"),
            (&exr, "F12 EXR"),
            (&json, "F12 profile"),
            (&trace, "F12 trace"),
        ] {
            outputs.add(Some(file), flag)?;
        }
        outputs.stage_image(Some(&png), &images.rgba8, images.width, images.height)?;
        outputs.stage(Some(&exr), || super::super::exr::encode_frame_exr(&images))?;
        outputs.stage(Some(&json), || {
            Ok(profile_json(&device, raster.name(), &this, Some(memory))?.into_bytes())
        })?;
        outputs.stage(Some(&trace), || Ok(chrome_trace(&device, &this)?.into_bytes()))?;
        outputs.commit()?;
        Ok([png, exr, json, trace].iter().map(|p| display(p)).collect())
    }

    /// Writes the last frame to `--screenshot` (nothing without it).
    pub fn screenshot(&self, renderer: &mut Renderer, mut outputs: Outputs) -> Result<()> {
        let (Some(path), Some((frame, shown))) = (&self.screenshot, self.last) else {
            return Ok(());
        };
        let images = renderer.read_view(&frame, shown)?;
        outputs.stage_image(Some(path), &images.rgba8, images.width, images.height)?;
        outputs.commit()
    }
}

fn display(path: &Path) -> String {
    path.display().to_string()
}
