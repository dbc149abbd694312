//! Frames in flight on the timeline semaphore: each slot owns a command pool,
//! a command buffer and a timestamp query pool, reused once the GPU has
//! finished the frame that last used the slot.

use std::time::Instant;

use ash::vk;

use super::clock::Calibration;
use super::commands::CommandRecorder;
use super::context::{vk_err, Context};
use super::memory::Garbage;
use crate::error::Result;

/// How many frames may be recorded while the GPU works on earlier ones.
pub const FRAMES_IN_FLIGHT: usize = 2;

struct FrameSlot {
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    queries: vk::QueryPool,
    query_capacity: u32,
    /// Timeline value of the slot's last submission (0: never submitted).
    submitted: u64,
    /// Timestamps the last submission wrote, and its frame number.
    written_queries: u32,
    frame: u64,
    /// The previous frame's timestamps, read by `wait_for_next`.
    completed: Option<CompletedFrame>,
    /// The last submission's CPU times: right before the submit call, and
    /// when the first wait for its completion returned; the clocks read
    /// together right before submitting (with calibrated timestamps).
    submit_at: Option<Instant>,
    waited_at: Option<Instant>,
    calibration: Option<Calibration>,
}

impl FrameSlot {
    /// Notes that the wait for the last submission returned (the first
    /// time only).
    fn waited(&mut self) {
        if self.submitted > 0 && self.waited_at.is_none() {
            self.waited_at = Some(Instant::now());
        }
    }
}

/// GPU timestamps of a completed frame, in nanoseconds from the first query,
/// and where the frame lies on the CPU clock.
#[derive(Clone, Debug)]
pub struct CompletedFrame {
    pub frame: u64,
    pub timestamps_ns: Vec<f64>,
    /// Right before the frame was submitted.
    pub submitted: Instant,
    /// When the first wait for the frame's completion returned.
    pub waited: Instant,
    /// The CPU instant of the first timestamp, with calibrated timestamps
    /// ([`super::DeviceInfo::calibrated_timestamps`]); None without.
    pub first_gpu: Option<Instant>,
}

/// The ring of frame slots.
pub struct FrameRing {
    ctx: Context,
    slots: Vec<FrameSlot>,
    next_frame: u64,
    /// Reused by every timestamp read (no allocation per frame).
    ticks: Vec<u64>,
    spare_timestamps: Vec<Vec<f64>>,
}

/// A frame being recorded.
pub struct RecordingFrame<'a> {
    ring: &'a mut FrameRing,
    slot: usize,
    pub frame: u64,
    pub recorder: CommandRecorder,
}

impl FrameRing {
    /// Creates [`FRAMES_IN_FLIGHT`] slots.
    pub fn new(ctx: &Context) -> Result<Self> {
        let device = &ctx.shared.device;
        let mut slots = Vec::new();
        for i in 0..FRAMES_IN_FLIGHT {
            let pool_info = vk::CommandPoolCreateInfo::default().queue_family_index(ctx.shared.queue_family);
            // SAFETY: valid create info on a live device.
            let pool =
                unsafe { device.create_command_pool(&pool_info, None) }.map_err(vk_err("vkCreateCommandPool"))?;
            let alloc = vk::CommandBufferAllocateInfo::default()
                .command_pool(pool)
                .level(vk::CommandBufferLevel::PRIMARY)
                .command_buffer_count(1);
            // SAFETY: the pool is live.
            let cmd = match unsafe { device.allocate_command_buffers(&alloc) } {
                Ok(c) => c[0],
                Err(e) => {
                    ctx.defer_destroy(Garbage::CommandPool(pool));
                    return Err(vk_err("vkAllocateCommandBuffers")(e));
                }
            };
            ctx.name_object(cmd, &format!("frame slot {i}"));
            slots.push(FrameSlot {
                pool,
                cmd,
                queries: vk::QueryPool::null(),
                query_capacity: 0,
                submitted: 0,
                written_queries: 0,
                frame: 0,
                completed: None,
                submit_at: None,
                waited_at: None,
                calibration: None,
            });
        }
        Ok(FrameRing {
            ctx: ctx.clone(),
            slots,
            next_frame: 0,
            ticks: Vec::new(),
            spare_timestamps: Vec::new(),
        })
    }

    /// The context the frames run on.
    pub fn context(&self) -> &Context {
        &self.ctx
    }

    /// Gives back a completed frame's memory for the next timestamp read.
    pub fn recycle(&mut self, completed: CompletedFrame) {
        if self.spare_timestamps.len() < FRAMES_IN_FLIGHT {
            self.spare_timestamps.push(completed.timestamps_ns);
        }
    }

    fn read_timestamps(&mut self, slot: usize) -> Result<Option<CompletedFrame>> {
        let s = &self.slots[slot];
        if s.submitted == 0 || s.written_queries == 0 {
            return Ok(None);
        }
        let ticks = &mut self.ticks;
        ticks.clear();
        ticks.resize(s.written_queries as usize, 0);
        // SAFETY: the slot's submission completed (the caller waited), so every
        // query it wrote is available.
        unsafe {
            self.ctx.shared.device.get_query_pool_results(
                s.queries,
                0,
                ticks,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .map_err(vk_err("vkGetQueryPoolResults"))?;
        let period = self.ctx.shared.limits.timestamp_period as f64;
        let first = ticks.iter().copied().min().unwrap_or(0);
        let mut timestamps_ns = self.spare_timestamps.pop().unwrap_or_default();
        timestamps_ns.clear();
        timestamps_ns.extend(ticks.iter().map(|&t| (t.wrapping_sub(first)) as f64 * period));
        let now = Instant::now();
        let submitted = s.submit_at.unwrap_or(now);
        Ok(Some(CompletedFrame {
            frame: s.frame,
            timestamps_ns,
            submitted,
            waited: s.waited_at.unwrap_or(now).max(submitted),
            first_gpu: s.calibration.map(|c| c.instant_of(first)),
        }))
    }

    /// The number of the next frame and, once its slot's previous frame has
    /// completed (this waits for it), leave to write that slot's host-visible
    /// per-frame buffers: call before [`FrameRing::begin`] to prepare a frame.
    ///
    /// It also reads the timestamps of the slot's previous frame, which may
    /// block further (lavapipe reports the timeline value reached before the
    /// queries are available): that wait belongs here, before the frame's
    /// CPU work starts, not inside the frame's CPU time.
    pub fn wait_for_next(&mut self) -> Result<u64> {
        let slot = (self.next_frame % FRAMES_IN_FLIGHT as u64) as usize;
        self.ctx.wait(self.slots[slot].submitted)?;
        self.slots[slot].waited();
        if self.slots[slot].completed.is_none() {
            let completed = self.read_timestamps(slot)?;
            let s = &mut self.slots[slot];
            s.completed = completed;
            s.written_queries = 0;
        }
        Ok(self.next_frame)
    }

    /// Waits for the next slot, returns the timestamps of the frame it held and
    /// starts recording a new frame with room for `queries` timestamps.
    pub fn begin(&mut self, queries: u32) -> Result<(RecordingFrame<'_>, Option<CompletedFrame>)> {
        let slot = (self.next_frame % FRAMES_IN_FLIGHT as u64) as usize;
        self.ctx.wait(self.slots[slot].submitted)?;
        self.slots[slot].waited();
        let completed = match self.slots[slot].completed.take() {
            Some(c) => Some(c),
            None => self.read_timestamps(slot)?,
        };
        let device = &self.ctx.shared.device;
        if queries > self.slots[slot].query_capacity {
            let capacity = queries.next_power_of_two().max(16);
            let info = vk::QueryPoolCreateInfo::default()
                .query_type(vk::QueryType::TIMESTAMP)
                .query_count(capacity);
            // SAFETY: valid create info.
            let pool = unsafe { device.create_query_pool(&info, None) }.map_err(vk_err("vkCreateQueryPool"))?;
            let old = std::mem::replace(&mut self.slots[slot].queries, pool);
            if old != vk::QueryPool::null() {
                self.ctx.defer_destroy(Garbage::QueryPool(old));
            }
            self.slots[slot].query_capacity = capacity;
        }
        let s = &mut self.slots[slot];
        // SAFETY: the slot's last submission completed, so its pool is idle.
        unsafe { device.reset_command_pool(s.pool, vk::CommandPoolResetFlags::empty()) }
            .map_err(vk_err("vkResetCommandPool"))?;
        let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        // SAFETY: the command buffer was reset with its pool.
        unsafe { device.begin_command_buffer(s.cmd, &begin) }.map_err(vk_err("vkBeginCommandBuffer"))?;
        s.written_queries = queries;
        s.frame = self.next_frame;
        let (cmd, pool) = (s.cmd, s.queries);
        let frame = self.next_frame;
        self.next_frame += 1;
        let mut recorder = CommandRecorder::new(&self.ctx, cmd);
        recorder.reset_queries(pool, queries.max(1));
        Ok((
            RecordingFrame {
                ring: self,
                slot,
                frame,
                recorder,
            },
            completed,
        ))
    }

    /// Waits for every frame in flight and returns their timestamps, oldest first.
    pub fn finish(&mut self) -> Result<Vec<CompletedFrame>> {
        self.ctx.wait_idle()?;
        let mut done = Vec::new();
        for slot in 0..self.slots.len() {
            self.slots[slot].waited();
            if let Some(c) = self.slots[slot].completed.take() {
                done.push(c);
            }
            if let Some(c) = self.read_timestamps(slot)? {
                done.push(c);
            }
            self.slots[slot].written_queries = 0;
        }
        done.sort_by_key(|c| c.frame);
        Ok(done)
    }
}

impl RecordingFrame<'_> {
    /// The query pool timestamps of this frame go into.
    pub(crate) fn query_pool(&self) -> vk::QueryPool {
        self.ring.slots[self.slot].queries
    }

    /// Ends recording and submits; returns the timeline value of completion.
    pub fn submit(self) -> Result<u64> {
        let ctx = self.ring.ctx.clone();
        let s = &mut self.ring.slots[self.slot];
        // SAFETY: the command buffer is recording and every label was closed.
        unsafe { ctx.shared.device.end_command_buffer(s.cmd) }.map_err(vk_err("vkEndCommandBuffer"))?;
        s.calibration = ctx.shared.clock.as_ref().and_then(|c| c.calibrate());
        s.waited_at = None;
        s.submit_at = Some(Instant::now());
        let value = ctx.submit(s.cmd)?;
        s.submitted = value;
        ctx.collect_garbage()?;
        Ok(value)
    }
}

impl Drop for FrameRing {
    fn drop(&mut self) {
        let _ = self.ctx.wait_idle();
        for s in self.slots.drain(..) {
            self.ctx.defer_destroy(Garbage::CommandPool(s.pool));
            if s.queries != vk::QueryPool::null() {
                self.ctx.defer_destroy(Garbage::QueryPool(s.queries));
            }
        }
        let _ = self.ctx.collect_garbage();
    }
}
