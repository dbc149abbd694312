//! Presentation to a window (`alpenglow view`): `present.clear` fills the
//! swapchain image with the letterbox colour, `present.blit` scales the
//! shown view's display image (tone-mapped sRGB, `tonemap`) into the
//! largest rectangle of its aspect ratio centred in it. The swapchain image
//! is imported into the graph ([`RenderGraph::import_presented`]), so the
//! graph derives the transitions to and from the presentation layout like
//! any other barrier. Which view is shown is prepared per frame
//! ([`PresentFrame`]), so the graph is baked once for every view.

use crate::error::Error;
use crate::graph::{ImageAccess, ImageId, RenderGraph};
use crate::view::{Frame, Provides};
use crate::vulkan::Format;

/// The colour around a letterboxed view (linear 0..1, the swapchain's
/// UNORM bytes are written as they are).
const LETTERBOX: [f32; 4] = [0.06, 0.06, 0.07, 1.0];

/// What `present.blit` shows this frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct PresentFrame {
    /// The view shown (index into the frame's views).
    pub view: usize,
}

/// The largest rectangle (x, y, width, height) of aspect `source`
/// centred in `target`, at least 1×1.
pub fn letterbox(source: (u32, u32), target: (u32, u32)) -> [u32; 4] {
    let (sw, sh) = (source.0.max(1) as u64, source.1.max(1) as u64);
    let (tw, th) = (target.0.max(1) as u64, target.1.max(1) as u64);
    let (w, h) = match sw * th >= tw * sh {
        true => (tw, (tw * sh / sw).max(1)),
        false => ((th * sw / sh).max(1), th),
    };
    [((tw - w) / 2) as u32, ((th - h) / 2) as u32, w as u32, h as u32]
}

/// Declares `present.clear` and `present.blit` of `displays` (each
/// view's display image) into a swapchain image of `format`; returns it
/// (bind an acquired image to it before each frame).
pub fn declare_present<S>(graph: &mut RenderGraph<Frame<S>>, displays: Vec<ImageId>, format: Format) -> ImageId
where
    S: Provides<PresentFrame> + 'static,
{
    let window = graph.import_presented("swapchain", format);
    graph
        .pass("present.clear")
        .transfer()
        .write(window, ImageAccess::TransferDst)
        .record(move |ctx, _| {
            let image = ctx.image(window)?;
            ctx.cmd().clear_color_image(image, LETTERBOX);
            Ok(())
        });
    let mut blit = graph.pass("present.blit").transfer();
    for &display in &displays {
        blit = blit.read(display, ImageAccess::TransferSrc);
    }
    blit.write(window, ImageAccess::TransferDst)
        .record(move |ctx, frame: &Frame<S>| {
            let shown = frame.prepared::<PresentFrame>()?.view;
            let display = *displays
                .get(shown)
                .ok_or_else(|| Error::invalid("shown view", format!("{shown}; the frame has {}", displays.len())))?;
            let (src, dst) = (ctx.image(display)?, ctx.image(window)?);
            let (s, d) = (src.desc(), dst.desc());
            let rect = letterbox((s.width, s.height), (d.width, d.height));
            ctx.cmd().blit_image(src, dst, rect);
            Ok(())
        });
    window
}

#[cfg(test)]
mod tests {
    use super::letterbox;

    #[test]
    fn letterbox_keeps_the_aspect_ratio_and_centres() {
        assert_eq!(letterbox((320, 200), (320, 200)), [0, 0, 320, 200]);
        // Wider window: bars left and right.
        assert_eq!(letterbox((320, 200), (640, 200)), [160, 0, 320, 200]);
        // Taller window: bars above and below.
        assert_eq!(letterbox((320, 200), (320, 400)), [0, 100, 320, 200]);
        assert_eq!(letterbox((1280, 720), (800, 800)), [0, 175, 800, 450]);
        assert_eq!(letterbox((100, 1), (1, 1)), [0, 0, 1, 1]);
    }
}
