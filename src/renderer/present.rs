//! Frames presented to a window: [`Renderer::present`] acquires a
//! swapchain image, binds it to the graph's `swapchain` image (declared
//! when the settings say [`RenderSettings::present_to`]), renders every
//! view, blits the shown one into it ([`crate::post::present`]) and
//! presents it.

use super::{Camera, RenderSettings, Renderer};
use crate::error::{Error, Result};
use crate::graph::FrameOutcome;
use crate::post::overlay::OverlayFrame;
use crate::post::present::PresentedImage;
use crate::vulkan::Swapchain;

impl RenderSettings {
    /// Frames end in an image of `swapchain` ([`Renderer::present`])
    /// instead of staying headless; readback works as before.
    pub fn present_to(&mut self, swapchain: &Swapchain) {
        self.present = Some(swapchain.format());
    }
}

impl Renderer {
    /// Which image of the shown view the next presented frames show: the
    /// colour (default) or an AOV's debug view.
    pub fn set_presented_image(&mut self, image: PresentedImage) {
        self.presented_image = image;
    }

    /// The image [`Renderer::set_presented_image`] chose.
    pub fn presented_image(&self) -> PresentedImage {
        self.presented_image
    }

    /// What the overlay draws over the next presented frame (over the
    /// shown view, after `present.blit`; never in what is read back).
    pub fn set_overlay(&mut self, overlay: OverlayFrame) -> Result<()> {
        match &mut self.techniques.overlay {
            Some(o) => o.set(overlay),
            None => Err(Error::invalid(
                "overlay",
                "the renderer does not present (Settings::present_to)",
            )),
        }
    }

    /// Renders a frame of every view (view `k` through `cameras[k]`) and
    /// presents view `shown`, letterboxed, to `swapchain`. None (nothing
    /// rendered) while the window is minimised. The renderer must have
    /// been built with [`RenderSettings::present_to`] of this swapchain.
    pub fn present(
        &mut self,
        cameras: &[Camera],
        swapchain: &mut Swapchain,
        shown: usize,
    ) -> Result<Option<FrameOutcome>> {
        let window = (self.presented)
            .ok_or_else(|| Error::invalid("present", "the renderer was built without Settings::present_to"))?;
        if shown >= self.views.len() {
            return Err(Error::invalid(
                "shown view",
                format!("{shown}; the renderer has {} views", self.views.len()),
            ));
        }
        // The slot's previous frame, which waited on the slot's acquisition
        // semaphore, must be done before the semaphore is signalled again.
        let index = self.frames.wait_for_next()?;
        let Some(image) = swapchain.acquire(index)? else {
            return Ok(None);
        };
        self.graph.bind_presented(window, &image)?;
        self.shown = shown;
        let outcome = self.render_views(cameras);
        self.graph.unbind_presented();
        let outcome = outcome?;
        swapchain.present(image)?;
        Ok(Some(outcome))
    }
}
