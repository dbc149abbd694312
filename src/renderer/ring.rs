//! Frames read without blocking: [`Renderer::submit`] returns a
//! [`Ticket`]; [`Renderer::try_read`] hands out the frame's outputs once
//! the GPU is done (None before, never blocking) and [`Renderer::wait`]
//! blocks until then. Frame `k` writes readback slot `k %`
//! [`super::RenderSettings::readback_slots`], so a simulator renders frame
//! N+1 (up to `slots - 1` frames ahead) while it consumes frame N; a
//! ticket whose slot a later frame took is an error, never stale data.

use std::sync::atomic::{AtomicU64, Ordering};

use super::frame_data::FrameData;
use super::{Camera, Renderer};
use crate::error::{Error, Result};

/// Identifies renderers, so a ticket is only read from its own.
static NEXT_RENDERER: AtomicU64 = AtomicU64::new(1);

/// A fresh renderer id.
pub(super) fn renderer_id() -> u64 {
    NEXT_RENDERER.fetch_add(1, Ordering::Relaxed)
}

/// A submitted frame: read it with [`Renderer::try_read`] or
/// [`Renderer::wait`] before `readback_slots` more frames are submitted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Ticket {
    renderer: u64,
    frame: u64,
    timeline: u64,
}

impl Ticket {
    /// The frame's number (0, 1, 2, …).
    pub fn frame(&self) -> u64 {
        self.frame
    }
}

impl Renderer {
    /// Prepares, records and submits a frame of every view (view `k`
    /// through `cameras[k]`) and returns its ticket. Blocks only while the
    /// GPU is more than `FRAMES_IN_FLIGHT` frames behind.
    pub fn submit(&mut self, cameras: &[Camera]) -> Result<Ticket> {
        let outcome = self.render_views(cameras)?;
        Ok(Ticket {
            renderer: self.id,
            frame: outcome.frame,
            timeline: outcome.timeline,
        })
    }

    /// The outputs of `ticket`'s frame once the GPU has finished it; None
    /// while it has not (this never blocks). Errors for a ticket of another
    /// renderer, or one whose readback slot a later frame reused.
    pub fn try_read(&mut self, ticket: Ticket) -> Result<Option<FrameData<'_>>> {
        let slot = self.check_ticket(ticket)?;
        if self.ctx.completed()? < ticket.timeline {
            return Ok(None);
        }
        self.frame_data(ticket, slot).map(Some)
    }

    /// The outputs of `ticket`'s frame, waiting for the GPU to finish it;
    /// same errors as [`Renderer::try_read`].
    pub fn wait(&mut self, ticket: Ticket) -> Result<FrameData<'_>> {
        let slot = self.check_ticket(ticket)?;
        self.ctx.wait(ticket.timeline)?;
        self.frame_data(ticket, slot)
    }

    /// The readback slot of `ticket`, if it still holds its frame.
    fn check_ticket(&self, ticket: Ticket) -> Result<usize> {
        let what = || format!("ticket of frame {}", ticket.frame);
        if ticket.renderer != self.id || ticket.frame >= self.frames_rendered {
            return Err(Error::invalid(what(), "it was not submitted to this renderer"));
        }
        let slots = self.readback_slots as u64;
        if self.frames_rendered > ticket.frame + slots {
            return Err(Error::invalid(
                what(),
                format!(
                    "its readback slot was reused by frame {}: read a frame before submitting \
                     {slots} more (readback_slots)",
                    ticket.frame + slots
                ),
            ));
        }
        if self.readback.is_empty() {
            return Err(Error::invalid(
                what(),
                "the renderer reads nothing back (readback is off or outputs is empty)",
            ));
        }
        Ok((ticket.frame % slots) as usize)
    }

    fn frame_data(&self, ticket: Ticket, slot: usize) -> Result<FrameData<'_>> {
        Ok(FrameData {
            frame: ticket.frame,
            views: &self.readback,
            slot,
        })
    }
}
