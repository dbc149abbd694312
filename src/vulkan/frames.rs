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

/// The pipeline statistics a pass's query counts, in the order the query
/// writes them (the order of the flags' bits; [`crate::profile::PipelineStats`]).
const PIPELINE_STATISTICS: vk::QueryPipelineStatisticFlags = vk::QueryPipelineStatisticFlags::from_raw(
    vk::QueryPipelineStatisticFlags::INPUT_ASSEMBLY_VERTICES.as_raw()
        | vk::QueryPipelineStatisticFlags::INPUT_ASSEMBLY_PRIMITIVES.as_raw()
        | vk::QueryPipelineStatisticFlags::VERTEX_SHADER_INVOCATIONS.as_raw()
        | vk::QueryPipelineStatisticFlags::CLIPPING_INVOCATIONS.as_raw()
        | vk::QueryPipelineStatisticFlags::CLIPPING_PRIMITIVES.as_raw()
        | vk::QueryPipelineStatisticFlags::FRAGMENT_SHADER_INVOCATIONS.as_raw()
        | vk::QueryPipelineStatisticFlags::COMPUTE_SHADER_INVOCATIONS.as_raw(),
);

/// How many counters a pipeline-statistics query writes.
pub const PIPELINE_STATISTICS_COUNT: usize = 7;

/// A query pool of a frame slot, grown on demand.
#[derive(Default)]
struct Queries {
    pool: vk::QueryPool,
    capacity: u32,
    /// Queries the last submission wrote.
    written: u32,
}

impl Queries {
    /// Makes room for `count` queries of `kind` (a new pool when larger;
    /// the old one is destroyed once the GPU is done with it).
    fn reserve(&mut self, ctx: &Context, count: u32, kind: vk::QueryType) -> Result<()> {
        if count <= self.capacity {
            return Ok(());
        }
        let capacity = count.next_power_of_two().max(16);
        let mut info = vk::QueryPoolCreateInfo::default()
            .query_type(kind)
            .query_count(capacity);
        if kind == vk::QueryType::PIPELINE_STATISTICS {
            info = info.pipeline_statistics(PIPELINE_STATISTICS);
        }
        // SAFETY: valid create info; pipeline-statistics pools are asked for
        // only with `pipelineStatisticsQuery` enabled (checked by the graph).
        let pool = unsafe { ctx.shared.device.create_query_pool(&info, None) }.map_err(vk_err("vkCreateQueryPool"))?;
        let old = std::mem::replace(&mut self.pool, pool);
        if old != vk::QueryPool::null() {
            ctx.defer_destroy(Garbage::QueryPool(old));
        }
        self.capacity = capacity;
        Ok(())
    }

    fn destroy(&self, ctx: &Context) {
        if self.pool != vk::QueryPool::null() {
            ctx.defer_destroy(Garbage::QueryPool(self.pool));
        }
    }
}

struct FrameSlot {
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    /// Timestamps, and pipeline statistics when asked for.
    queries: Queries,
    stats: Queries,
    /// Timeline value of the slot's last submission (0: never submitted).
    submitted: u64,
    /// The last submission's frame number.
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
    /// The first timestamp on the device's clock, in nanoseconds.
    pub first_ns: f64,
    /// Each pass's pipeline statistics, in pass order (empty unless asked for).
    pub pipeline_stats: Vec<[u64; PIPELINE_STATISTICS_COUNT]>,
}

/// The ring of frame slots.
pub struct FrameRing {
    ctx: Context,
    slots: Vec<FrameSlot>,
    next_frame: u64,
    /// Reused by every timestamp read (no allocation per frame).
    ticks: Vec<u64>,
    spare_timestamps: Vec<(Vec<f64>, Vec<[u64; PIPELINE_STATISTICS_COUNT]>)>,
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
                queries: Queries::default(),
                stats: Queries::default(),
                submitted: 0,
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
            (self.spare_timestamps).push((completed.timestamps_ns, completed.pipeline_stats));
        }
    }

    fn read_timestamps(&mut self, slot: usize) -> Result<Option<CompletedFrame>> {
        let s = &self.slots[slot];
        if s.submitted == 0 || s.queries.written == 0 {
            return Ok(None);
        }
        let ticks = &mut self.ticks;
        ticks.clear();
        ticks.resize(s.queries.written as usize, 0);
        let (mut timestamps_ns, mut pipeline_stats) = self.spare_timestamps.pop().unwrap_or_default();
        pipeline_stats.clear();
        pipeline_stats.resize(s.stats.written as usize, [0; PIPELINE_STATISTICS_COUNT]);
        let device = &self.ctx.shared.device;
        let flags = vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT;
        // SAFETY: the slot's submission completed (the caller waited), so every
        // query it wrote is available; each result is the counters of one query.
        unsafe { device.get_query_pool_results(s.queries.pool, 0, ticks, flags) }
            .map_err(vk_err("vkGetQueryPoolResults"))?;
        if !pipeline_stats.is_empty() {
            // SAFETY: as above.
            unsafe { device.get_query_pool_results(s.stats.pool, 0, &mut pipeline_stats, flags) }
                .map_err(vk_err("vkGetQueryPoolResults"))?;
        }
        let period = self.ctx.shared.limits.timestamp_period as f64;
        let first = ticks.iter().copied().min().unwrap_or(0);
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
            first_ns: first as f64 * period,
            pipeline_stats,
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
            s.queries.written = 0;
            s.stats.written = 0;
        }
        Ok(self.next_frame)
    }

    /// Waits for the next slot, returns the timestamps of the frame it held and
    /// starts recording a new frame with room for `queries` timestamps and
    /// `stats` pipeline-statistics queries (0 without: needs the device
    /// feature `pipelineStatisticsQuery`).
    pub fn begin(&mut self, queries: u32, stats: u32) -> Result<(RecordingFrame<'_>, Option<CompletedFrame>)> {
        let slot = (self.next_frame % FRAMES_IN_FLIGHT as u64) as usize;
        self.ctx.wait(self.slots[slot].submitted)?;
        self.slots[slot].waited();
        let completed = match self.slots[slot].completed.take() {
            Some(c) => Some(c),
            None => self.read_timestamps(slot)?,
        };
        let ctx = self.ctx.clone();
        self.slots[slot]
            .queries
            .reserve(&ctx, queries, vk::QueryType::TIMESTAMP)?;
        self.slots[slot]
            .stats
            .reserve(&ctx, stats, vk::QueryType::PIPELINE_STATISTICS)?;
        let device = &ctx.shared.device;
        let s = &mut self.slots[slot];
        // SAFETY: the slot's last submission completed, so its pool is idle.
        unsafe { device.reset_command_pool(s.pool, vk::CommandPoolResetFlags::empty()) }
            .map_err(vk_err("vkResetCommandPool"))?;
        let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        // SAFETY: the command buffer was reset with its pool.
        unsafe { device.begin_command_buffer(s.cmd, &begin) }.map_err(vk_err("vkBeginCommandBuffer"))?;
        s.queries.written = queries;
        s.stats.written = stats;
        s.frame = self.next_frame;
        let (cmd, pool, stats_pool) = (s.cmd, s.queries.pool, s.stats.pool);
        let frame = self.next_frame;
        self.next_frame += 1;
        let mut recorder = CommandRecorder::new(&self.ctx, cmd);
        recorder.reset_queries(pool, queries.max(1));
        if stats > 0 {
            recorder.reset_queries(stats_pool, stats);
        }
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
            self.slots[slot].queries.written = 0;
            self.slots[slot].stats.written = 0;
        }
        done.sort_by_key(|c| c.frame);
        Ok(done)
    }
}

impl RecordingFrame<'_> {
    /// The query pool timestamps of this frame go into.
    pub(crate) fn query_pool(&self) -> vk::QueryPool {
        self.ring.slots[self.slot].queries.pool
    }

    /// The pool of this frame's pipeline-statistics queries (one per pass;
    /// a null handle unless [`FrameRing::begin`] was asked for them).
    pub(crate) fn stats_pool(&self) -> vk::QueryPool {
        self.ring.slots[self.slot].stats.pool
    }

    /// Ends recording and submits (waiting for a swapchain image's
    /// acquisition and signalling its presentation with `present`);
    /// returns the timeline value of completion.
    pub fn submit(self, present: Option<&super::present::PresentSync>) -> Result<u64> {
        let ctx = self.ring.ctx.clone();
        let s = &mut self.ring.slots[self.slot];
        // SAFETY: the command buffer is recording and every label was closed.
        unsafe { ctx.shared.device.end_command_buffer(s.cmd) }.map_err(vk_err("vkEndCommandBuffer"))?;
        s.calibration = ctx.shared.clock.as_ref().and_then(|c| c.calibrate());
        s.waited_at = None;
        s.submit_at = Some(Instant::now());
        let value = ctx.submit_presenting(s.cmd, present)?;
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
            s.queries.destroy(&self.ctx);
            s.stats.destroy(&self.ctx);
        }
        let _ = self.ctx.collect_garbage();
    }
}
