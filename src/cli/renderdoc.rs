//! `--renderdoc-capture N` and `--renderdoc [PATH]` of `render`, `bench`
//! and `fly`: RenderDoc captures frame N (0-based) of the headless run,
//! delimited by its in-application API (no present delimits a headless
//! frame). RenderDoc is attached when the process runs under it
//! (`renderdoccmd capture`), or loaded by `--renderdoc` before the Vulkan
//! instance is created.
//!
//! RenderDoc numbers frames by presents and names an application-delimited
//! capture `TEMPLATE_capture.rdc`; the captured frame's template gets
//! `_frameN`, so the file is `TEMPLATE_frameN_capture.rdc`. The other
//! frames are not delimited (that would mean starting and discarding a
//! capture each: RenderDoc snapshots every resource at a start).

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;

use alpenglow::tools::renderdoc::RenderDocCapture;
use alpenglow::{Camera, Renderer};

#[derive(Args, Debug, Clone, Default)]
pub struct RenderDocArgs {
    /// Capture frame FRAME (0-based) with RenderDoc and print the capture
    /// file (TEMPLATE_frameFRAME_capture.rdc); under `renderdoccmd capture`
    /// or with --renderdoc. fly: the path's frame; bench: counted after the
    /// settling frames (warm-up first); render: counted from the first.
    #[arg(long = "renderdoc-capture", value_name = "FRAME", help_heading = "Debug")]
    pub capture: Option<u32>,
    /// Load RenderDoc's library (default: librenderdoc.so from the linker's
    /// path or the usual install places) when not running under RenderDoc.
    #[arg(long, value_name = "PATH", num_args = 0..=1, requires = "capture", help_heading = "Debug")]
    pub renderdoc: Option<Option<PathBuf>>,
}

/// The capture of one frame of a run: RenderDoc, the frame, and the file
/// once written.
pub(crate) struct FrameCapture {
    rdoc: RenderDocCapture,
    frame: u32,
    written: Option<PathBuf>,
}

impl FrameCapture {
    /// RenderDoc for `--renderdoc-capture`, attached or loaded (call before
    /// the Vulkan context); None without the option. `frames`: how many
    /// frames the run renders (at most).
    pub(crate) fn new(args: &RenderDocArgs, frames: u64) -> Result<Option<FrameCapture>> {
        let Some(frame) = args.capture else {
            return Ok(None);
        };
        if u64::from(frame) >= frames {
            bail!(
                "--renderdoc-capture {frame} is out of range: the run renders frames 0 to {}",
                frames - 1
            );
        }
        let rdoc = match (&args.renderdoc, RenderDocCapture::attach()) {
            (_, Some(rdoc)) => rdoc,
            (Some(path), None) => {
                RenderDocCapture::load(path.as_deref()).map_err(|e| anyhow::anyhow!("--renderdoc: {e}"))?
            }
            (None, None) => bail!(
                "--renderdoc-capture: RenderDoc is not loaded in this process (run under `renderdoccmd capture`, \
                 or add --renderdoc [PATH] to load librenderdoc.so)"
            ),
        };
        Ok(Some(FrameCapture {
            rdoc,
            frame,
            written: None,
        }))
    }

    /// Renders frame `index` with `render`, captured when it is the asked frame.
    pub(crate) fn frame<T>(&mut self, index: u64, render: impl FnOnce() -> Result<T>) -> Result<T> {
        if index != u64::from(self.frame) {
            return render();
        }
        let option = format!("--renderdoc-capture {}", self.frame);
        let template = self.rdoc.capture_path_template();
        if let Some(t) = &template {
            let mut framed = t.clone().into_os_string();
            framed.push(format!("_frame{}", self.frame));
            self.rdoc.set_capture_path_template(framed.as_ref())?;
        }
        self.rdoc.start_frame();
        let result = render();
        let written = match &result {
            Ok(_) => Some(self.rdoc.end_frame()),
            Err(_) => {
                self.rdoc.discard_frame();
                None
            }
        };
        if let Some(t) = &template {
            self.rdoc.set_capture_path_template(t)?;
        }
        if let Some(written) = written {
            self.written = Some(written.map_err(|e| anyhow::anyhow!("{option}: {e}"))?);
        }
        result
    }

    /// `render`: renders the still view frame by frame up to the captured
    /// frame (the settling loop then renders until the view settled).
    pub(crate) fn render_until(&mut self, renderer: &mut Renderer, cameras: &[Camera]) -> Result<()> {
        for i in 0..=u64::from(self.frame) {
            self.frame(i, || Ok(renderer.render_views(cameras)?))?;
        }
        Ok(())
    }

    /// The capture written, printed; an error when the run ended before the frame.
    pub(crate) fn finish(self) -> Result<PathBuf> {
        match self.written {
            Some(path) => Ok(path),
            None => bail!("--renderdoc-capture {}: the run ended before that frame", self.frame),
        }
    }
}

/// [`FrameCapture::frame`] when there is a capture, else just `render`.
pub(crate) fn frame<T>(
    capture: &mut Option<FrameCapture>,
    index: u64,
    render: impl FnOnce() -> Result<T>,
) -> Result<T> {
    match capture {
        Some(capture) => capture.frame(index, render),
        None => render(),
    }
}

/// Finishes `capture` and prints the file written.
pub(crate) fn report(capture: Option<FrameCapture>) -> Result<()> {
    if let Some(capture) = capture {
        let frame = capture.frame;
        let path = capture.finish()?;
        println!("RenderDoc capture of frame {frame}: {}", path.display());
    }
    Ok(())
}

/// `error` of the Vulkan context, with why under RenderDoc: it reports
/// Vulkan 1.2 for a device without `bufferDeviceAddressCaptureReplay`
/// (lavapipe among them), and alpenglow needs 1.3.
pub(crate) fn explain_device_error(error: alpenglow::Error) -> anyhow::Error {
    let line = error.to_string();
    match line.split_once(" lacks Vulkan 1.3") {
        Some((device, _)) if RenderDocCapture::attach().is_some() => anyhow::anyhow!(
            "{device} is Vulkan 1.2 under RenderDoc, which reports 1.2 for a device without \
             bufferDeviceAddressCaptureReplay (lavapipe among them); alpenglow needs 1.3: \
             capture on a GPU driver that has it"
        ),
        _ => error.into(),
    }
}
