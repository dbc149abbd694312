//! Executing a baked graph: per pass, a debug label, a begin timestamp, the
//! barriers derived from the declared accesses and the tracked state of each
//! resource, the pass's commands, and an end timestamp.

use std::time::{Duration, Instant};

use super::access::{derive_barrier, write_access_bits};
use super::bake::{BakedGraph, PendingFrame, Physical};
use super::binding::{Binding, BindingTarget};
use super::uploads::UploadArena;
use super::{Access, Attachments, BufferId, ImageId, PassKind, ResourceId};
use crate::error::{Error, Result};
use crate::profile::{tracy, FrameProfile, PassTiming, PipelineStats, StageTiming};
use crate::vulkan::{
    AccessFlags2, AccessState, BarrierBatch, Buffer, CommandRecorder, CompletedFrame, ComputePipeline, FrameRing,
    GraphicsPipeline, Image, PipelineStageFlags2,
};

/// What a pass's recording closure gets: the command recorder, the
/// physical resources the pass declared, and the heap handles of its
/// bindings ([`PassContext::handle`]) — nothing it did not declare.
pub struct PassContext<'a> {
    cmd: &'a mut CommandRecorder,
    physical: &'a [Physical],
    uploads: Option<&'a UploadArena>,
    frame: u64,
    /// What the pass declared.
    uses: &'a [(ResourceId, Access)],
    /// The pass's and its graph's numbers (its bindings carry them).
    pass: u32,
    graph: u32,
    name: &'a str,
}

/// A CPU stage of a frame before recording (a technique's `prepare`), for
/// the profile and the trace.
#[derive(Clone, Debug)]
pub struct CpuStage {
    /// Shared, so that timing a stage allocates nothing.
    pub name: std::sync::Arc<str>,
    pub start: Instant,
    pub duration: Duration,
}

impl CpuStage {
    /// Runs `f` as the stage `name`, appending its timing to `stages`.
    pub fn time<T>(stages: &mut Vec<CpuStage>, name: &std::sync::Arc<str>, f: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let value = {
            let _zone = tracy::cpu_zone(name);
            f()
        };
        stages.push(CpuStage {
            name: name.clone(),
            start,
            duration: start.elapsed(),
        });
        value
    }
}

/// The workgroups of a one-dimensional dispatch over `items` with `local`
/// invocations a workgroup, at most the 65535 every device takes
/// (`maxComputeWorkGroupCount`); shaders whose item count may exceed that
/// loop with a stride of the whole dispatch (`gl_NumWorkGroups`).
pub fn stride_groups(items: u32, local: u32) -> u32 {
    items.div_ceil(local).clamp(1, 65535)
}

impl<'a> PassContext<'a> {
    /// The command recorder.
    pub fn cmd(&mut self) -> &mut CommandRecorder {
        &mut *self.cmd
    }

    /// Index of the frame being recorded (0, 1, 2, …).
    pub fn frame(&self) -> u64 {
        self.frame
    }

    fn declared(&self, r: ResourceId, what: &str) -> Result<()> {
        match self.uses.iter().any(|(u, _)| *u == r) {
            true => Ok(()),
            false => Err(Error::Graph(format!(
                "pass '{}' reaches {what} #{} it did not declare",
                self.name, r.0
            ))),
        }
    }

    fn physical_image(&self, r: ResourceId) -> Result<&'a Image> {
        self.physical
            .get(r.0)
            .and_then(|p| p.image(self.frame))
            .map(|i| &**i)
            .ok_or_else(|| Error::Graph(format!("image #{} is not of this graph", r.0)))
    }

    fn physical_buffer(&self, r: ResourceId) -> Result<&'a Buffer> {
        self.physical
            .get(r.0)
            .and_then(|p| p.buffer(self.frame))
            .map(|b| &**b)
            .ok_or_else(|| Error::Graph(format!("buffer #{} is not of this graph", r.0)))
    }

    /// The image behind `id` this frame (attachments, copies); an error
    /// unless the pass declared `id`.
    pub fn image(&self, id: ImageId) -> Result<&'a Image> {
        self.declared(id.0, "the image")?;
        self.physical_image(id.0)
    }

    /// The buffer behind `id` this frame (vertex, index, indirect buffers,
    /// copies); an error unless the pass declared `id`.
    pub fn buffer(&self, id: BufferId) -> Result<&'a Buffer> {
        self.declared(id.0, "the buffer")?;
        self.physical_buffer(id.0)
    }

    /// The bindless heap handle of `binding`, which this pass declared
    /// ([`super::PassBuilder::sample`], `storage_image`, `storage_buffer`,
    /// `upload`): the only way a pass reaches the heap. A binding of
    /// another pass is an error.
    pub fn handle(&self, binding: Binding) -> Result<u32> {
        self.own(binding)?;
        let missing = |what: &str, name: &str| Error::Graph(format!("'{name}' has no {what} heap handle"));
        match binding.target {
            BindingTarget::SampledImage(r) => {
                let image = self.physical_image(r)?;
                (image.sampled_handle()).ok_or_else(|| missing("sampled", &image.desc().name))
            }
            BindingTarget::StorageImage(r) => {
                let image = self.physical_image(r)?;
                (image.storage_handle()).ok_or_else(|| missing("storage", &image.desc().name))
            }
            BindingTarget::StorageBuffer(r) => {
                let buffer = self.physical_buffer(r)?;
                (buffer.storage_handle()).ok_or_else(|| missing("storage", &buffer.desc().name))
            }
            BindingTarget::Upload(region) => self.arena()?.handle(region, self.frame),
        }
    }

    fn own(&self, binding: Binding) -> Result<()> {
        match binding.graph == self.graph && binding.pass == self.pass {
            true => Ok(()),
            false => Err(Error::Graph(format!(
                "pass '{}' was handed a binding another pass declared",
                self.name
            ))),
        }
    }

    fn arena(&self) -> Result<&'a UploadArena> {
        self.uploads
            .ok_or_else(|| Error::Graph("the graph has no upload arena".into()))
    }

    /// Writes `bytes` at the start of this frame's copy of the upload
    /// region of `binding` (declared by this pass with
    /// [`super::PassBuilder::upload`]): constants that embed the pass's
    /// heap handles are written while recording (kajiya's dynamic
    /// constants); the frame slot's previous frame has completed.
    pub fn write_upload(&mut self, binding: Binding, bytes: &[u8]) -> Result<()> {
        self.own(binding)?;
        let BindingTarget::Upload(region) = binding.target else {
            return Err(Error::Graph(format!(
                "pass '{}' writes a binding that is not an upload region",
                self.name
            )));
        };
        self.arena()?.writer(self.frame).write(region, bytes)
    }

    /// Writes `bytes` at byte `offset` of this frame's copy of the upload
    /// region of `binding` ([`PassContext::write_upload`]), e.g. to patch
    /// one handle into constants written whole (no allocation).
    pub fn write_upload_at(&mut self, binding: Binding, offset: u64, bytes: &[u8]) -> Result<()> {
        self.own(binding)?;
        let BindingTarget::Upload(region) = binding.target else {
            return Err(Error::Graph(format!(
                "pass '{}' writes a binding that is not an upload region",
                self.name
            )));
        };
        self.arena()?.writer(self.frame).write_at(region, offset, bytes)
    }

    /// [`PassContext::write_upload`] of one plain value.
    pub fn write_upload_pod<T: bytemuck::Pod>(&mut self, binding: Binding, value: &T) -> Result<()> {
        self.write_upload(binding, bytemuck::bytes_of(value))
    }

    /// Binds `pipeline` and the heap, sets `push` and dispatches `groups`
    /// workgroups: the skeleton of every compute pass.
    pub fn dispatch<T: bytemuck::Pod>(&mut self, pipeline: &ComputePipeline, push: &T, groups: [u32; 3]) -> Result<()> {
        let cmd = self.cmd();
        cmd.bind_compute(pipeline);
        cmd.push_constants(push)?;
        cmd.dispatch(groups[0], groups[1], groups[2]);
        Ok(())
    }

    /// Binds `pipeline` and the heap, sets `push` and draws one
    /// full-screen triangle: the skeleton of every full-screen pass.
    pub fn draw_full_screen<T: bytemuck::Pod>(&mut self, pipeline: &GraphicsPipeline, push: &T) -> Result<()> {
        let cmd = self.cmd();
        cmd.bind_graphics(pipeline);
        cmd.push_constants(push)?;
        cmd.draw(3, 1);
        Ok(())
    }
}

/// Begins rendering into a pass's declared attachments (none: nothing).
fn begin_attachments(
    cmd: &mut CommandRecorder,
    physical: &[Physical],
    attachments: &Attachments,
    frame: u64,
) -> Result<bool> {
    if attachments.is_empty() {
        return Ok(false);
    }
    let image = |r: ResourceId| {
        (physical.get(r.0).and_then(|p| p.image(frame)))
            .map(|i| &**i)
            .ok_or_else(|| Error::Graph(format!("attachment #{} is not an image of this graph", r.0)))
    };
    for (r, _) in &attachments.colors {
        image(*r)?;
    }
    let depth = match attachments.depth {
        Some((r, clear)) => Some((image(r)?, clear)),
        None => None,
    };
    let colors = (attachments.colors.iter()).filter_map(|&(r, load)| image(r).ok().map(|i| (i, load)));
    cmd.begin_rendering_from(colors, depth);
    Ok(true)
}

/// What executing one frame produced.
#[derive(Clone, Copy, Debug)]
pub struct FrameOutcome {
    /// Frame number (0, 1, ...).
    pub frame: u64,
    /// Timeline value that marks the frame's completion. Per-frame imported
    /// resources are used round-robin: copy `frame % copies`.
    pub timeline: u64,
}

fn label_color(kind: PassKind) -> [f32; 4] {
    match kind {
        PassKind::Compute => [0.30, 0.55, 0.95, 1.0],
        PassKind::Graphics => [0.95, 0.55, 0.25, 1.0],
        PassKind::Transfer => [0.50, 0.80, 0.40, 1.0],
    }
}

impl<P> BakedGraph<P> {
    fn state_of(&self, r: ResourceId, frame: u64) -> AccessState {
        let p = &self.physical[r.0];
        if !self.imported[r.0] {
            self.transient_states[r.0]
        } else if let Some(image) = p.image(frame) {
            image.state()
        } else {
            p.buffer(frame).map_or(AccessState::UNUSED, |b| b.state())
        }
    }

    fn set_state_of(&mut self, r: ResourceId, frame: u64, state: AccessState) {
        let p = &self.physical[r.0];
        if !self.imported[r.0] {
            self.transient_states[r.0] = state;
        } else if let Some(image) = p.image(frame) {
            image.set_state(state);
        } else if let Some(buffer) = p.buffer(frame) {
            buffer.set_state(state);
        }
    }

    /// Derives and records the barriers before `uses`, updating tracked
    /// states (gathered on the stack: no allocation).
    fn emit_barriers(&mut self, cmd: &mut CommandRecorder, uses: &[(ResourceId, super::Access)], frame: u64) {
        let mut batch = BarrierBatch::default();
        for &(r, access) in uses {
            let mut state = self.state_of(r, frame);
            if let Some(slot) = self.alias_of[r.0] {
                state = self.alias_slots[slot].state_for(r.0, state);
                let (stages, accesses, _) = access.state();
                self.alias_slots[slot].record(r.0, stages, accesses & write_access_bits());
            }
            let discard = !self.imported[r.0] && !self.touched[r.0];
            self.touched[r.0] = true;
            let barrier = derive_barrier(&mut state, access, discard);
            self.set_state_of(r, frame, state);
            let Some(mut b) = barrier else { continue };
            if access.is_image() && b.old_layout != b.new_layout {
                // A layout transition (e.g. the first use of a transient image
                // this frame, or an atlas texture going from sampled to
                // storage) waits for everything before. A few per frame cost
                // little, and it keeps validation layers before 1.3.268
                // quiet: they count every draw and dispatch as touching every
                // image of the bindless heap (KhronosGroup/Vulkan-ValidationLayers#3450).
                b.src_stages |= PipelineStageFlags2::ALL_COMMANDS;
                b.src_access |= AccessFlags2::MEMORY_WRITE;
            }
            let physical = &self.physical[r.0];
            match (access.is_image(), physical.image(frame), physical.buffer(frame)) {
                (true, Some(image), _) => batch.image(cmd, image, &b),
                (_, _, Some(buffer)) => batch.buffer(cmd, buffer, &b),
                _ => {}
            }
        }
        batch.flush(cmd);
    }

    /// Records and submits one frame from its prepared data `params`;
    /// `prepare` are the CPU stages that prepared it (for the profile).
    /// Returns once the frame is submitted; its GPU timings arrive in
    /// [`BakedGraph::take_profiles`] when the GPU is done.
    pub fn execute(&mut self, frames: &mut FrameRing, params: &P, prepare: &[CpuStage]) -> Result<FrameOutcome> {
        let query_count = 2 * self.passes.len() as u32;
        // Waits for the frame slot (the GPU) first; CPU times start after it,
        // or with the first prepare stage.
        let stats = if self.pipeline_stats {
            self.passes.len() as u32
        } else {
            0
        };
        let ctx = frames.context().clone();
        let (mut recording, completed) = frames.begin(query_count, stats)?;
        if let Some(c) = &completed {
            self.complete(c);
        }
        let record_start = Instant::now();
        let frame_start = prepare
            .iter()
            .map(|s| s.start)
            .min()
            .unwrap_or(record_start)
            .min(record_start);
        let frame = recording.frame;
        let (pool, stats_pool) = (recording.query_pool(), recording.stats_pool());
        self.touched.clear();
        self.touched.resize(self.physical.len(), false);
        let mut cpu_passes = self.spare_cpu_passes.pop().unwrap_or_default();
        cpu_passes.clear();
        let passes = std::mem::take(&mut self.passes);
        let mut result = Ok(());
        for (i, pass) in passes.iter().enumerate() {
            let pass_start = Instant::now();
            let cmd = &mut recording.recorder;
            cmd.begin_label_c(&pass.label, label_color(pass.kind));
            self.tracy.begin_pass(&pass.name, || ctx.gpu_time_ns());
            cmd.write_timestamp(pool, 2 * i as u32, PipelineStageFlags2::TOP_OF_PIPE);
            if stats > 0 {
                cmd.begin_query(stats_pool, i as u32);
            }
            self.emit_barriers(cmd, &pass.uses, frame);
            let recorded = begin_attachments(cmd, &self.physical, &pass.attachments, frame).and_then(|rendering| {
                let mut ctx = PassContext {
                    cmd: &mut *cmd,
                    physical: &self.physical,
                    uploads: self.uploads.as_ref(),
                    frame,
                    uses: &pass.uses,
                    pass: pass.serial,
                    graph: self.serial,
                    name: &pass.name,
                };
                let recorded = (pass.record)(&mut ctx, params);
                if rendering {
                    cmd.end_rendering();
                }
                recorded
            });
            if let Err(e) = recorded {
                result = Err(Error::Graph(format!("pass '{}': {e}", pass.name)));
            }
            let cmd = &mut recording.recorder;
            if stats > 0 {
                cmd.end_query(stats_pool, i as u32);
            }
            cmd.write_timestamp(pool, 2 * i as u32 + 1, PipelineStageFlags2::ALL_COMMANDS);
            cmd.end_label();
            self.tracy.end_pass();
            cpu_passes.push((
                (pass_start - frame_start).as_secs_f64() * 1e3,
                pass_start.elapsed().as_secs_f64() * 1e3,
            ));
            if result.is_err() {
                break;
            }
        }
        self.passes = passes;
        let finals = std::mem::take(&mut self.final_accesses);
        self.emit_barriers(&mut recording.recorder, &finals, frame);
        self.final_accesses = finals;
        // Submit even after a failed pass so the frame slot stays consistent.
        let present = self.present.take();
        let timeline = recording.submit(present.as_ref());
        self.unbind_presented();
        let timeline = timeline?;
        self.tracy.submitted(frame, || ctx.gpu_time_ns());
        tracy::frame_mark();
        if let Some(c) = completed {
            frames.recycle(c);
        }
        result?;
        self.pending.push_back(PendingFrame {
            frame,
            cpu_start_ms: frame_start.saturating_duration_since(self.epoch).as_secs_f64() * 1e3,
            cpu_ms: frame_start.elapsed().as_secs_f64() * 1e3,
            cpu_passes,
            prepare: prepare
                .iter()
                .map(|s| {
                    (
                        s.name.clone(),
                        s.duration,
                        s.start.saturating_duration_since(frame_start),
                    )
                })
                .fold(PrepareTimes::default(), PrepareTimes::with),
        });
        Ok(FrameOutcome { frame, timeline })
    }

    fn complete(&mut self, completed: &CompletedFrame) {
        while let Some(p) = self.pending.front() {
            if p.frame > completed.frame {
                return;
            }
            let p = self.pending.pop_front().expect("front exists");
            if p.frame < completed.frame {
                self.spare_cpu_passes.push(p.cpu_passes);
                continue;
            }
            // Reuse the oldest profile's memory once the history is full.
            let mut profile = match self.profiles.len() >= self.profile_history {
                true => self.profiles.remove(0),
                false => FrameProfile::default(),
            };
            let ts = &completed.timestamps_ns;
            let at = |i: usize| completed.first_ns + ts.get(i).copied().unwrap_or(0.0);
            (self.tracy).completed(p.frame, (0..self.passes.len()).map(|i| (at(2 * i), at(2 * i + 1))));
            profile.passes.truncate(self.passes.len());
            for (i, pass) in self.passes.iter().enumerate() {
                let (begin, end) = (
                    ts.get(2 * i).copied().unwrap_or(0.0),
                    ts.get(2 * i + 1).copied().unwrap_or(0.0),
                );
                let (cpu_start_ms, cpu_ms) = p.cpu_passes.get(i).copied().unwrap_or((0.0, 0.0));
                let timing = PassTiming {
                    name: String::new(),
                    gpu_ms: (end - begin).max(0.0) / 1e6,
                    cpu_ms,
                    gpu_start_ms: begin / 1e6,
                    cpu_start_ms,
                    pipeline_stats: (completed.pipeline_stats.get(i)).map(|c| PipelineStats::from_counters(*c)),
                };
                match profile.passes.get_mut(i) {
                    Some(t) => {
                        let name = std::mem::take(&mut t.name);
                        *t = PassTiming { name, ..timing };
                    }
                    None => profile.passes.push(timing),
                }
                set_name(&mut profile.passes[i].name, &pass.name);
            }
            p.prepare.write_into(&mut profile.prepare);
            let first = ts.iter().copied().fold(f64::INFINITY, f64::min);
            let last = ts.iter().copied().fold(0.0, f64::max);
            profile.frame = p.frame;
            profile.gpu_ms = if first.is_finite() { (last - first) / 1e6 } else { 0.0 };
            profile.cpu_ms = p.cpu_ms;
            profile.cpu_start_ms = p.cpu_start_ms;
            profile.submit_ms = ms_since(self.epoch, completed.submitted);
            profile.fence_ms = ms_since(self.epoch, completed.waited);
            profile.gpu_start_on_cpu_ms = completed.first_gpu.map(|at| ms_since(self.epoch, at));
            self.profiles.push(profile);
            self.spare_cpu_passes.push(p.cpu_passes);
            return;
        }
    }

    /// Waits for every frame in flight and collects its timings.
    pub fn finish(&mut self, frames: &mut FrameRing) -> Result<()> {
        for c in frames.finish()? {
            self.complete(&c);
        }
        Ok(())
    }

    /// Timings of the frames completed so far and not yet taken (oldest first).
    pub fn profiles(&self) -> &[FrameProfile] {
        &self.profiles
    }

    /// Timings of the frames completed so far (oldest first), removing them.
    pub fn take_profiles(&mut self) -> Vec<FrameProfile> {
        std::mem::take(&mut self.profiles)
    }
}

/// Milliseconds from `epoch` to `at` (negative when `at` is earlier).
fn ms_since(epoch: Instant, at: Instant) -> f64 {
    match at.checked_duration_since(epoch) {
        Some(d) => d.as_secs_f64() * 1e3,
        None => -(epoch - at).as_secs_f64() * 1e3,
    }
}

/// Sets `name` to `value`, reusing its memory (no allocation once it has
/// held a name as long).
fn set_name(name: &mut String, value: &str) {
    if name != value {
        name.clear();
        name.push_str(value);
    }
}

/// The CPU stages of a pending frame: (name, duration, start from the
/// frame's start), at most [`PrepareTimes::CAPACITY`] (a frame has one per
/// technique), kept inline so a frame allocates nothing for them.
#[derive(Clone, Default)]
pub(crate) struct PrepareTimes {
    stages: [Option<(std::sync::Arc<str>, Duration, Duration)>; PrepareTimes::CAPACITY],
    len: usize,
}

impl PrepareTimes {
    const CAPACITY: usize = 16;

    fn with(mut self, stage: (std::sync::Arc<str>, Duration, Duration)) -> PrepareTimes {
        if self.len < Self::CAPACITY {
            self.stages[self.len] = Some(stage);
            self.len += 1;
        }
        self
    }

    /// The stages as profile timings, reusing `out`'s memory.
    fn write_into(&self, out: &mut Vec<StageTiming>) {
        out.truncate(self.len);
        for (i, (name, duration, start)) in self.stages.iter().flatten().enumerate() {
            let timing = StageTiming {
                name: String::new(),
                cpu_ms: duration.as_secs_f64() * 1e3,
                cpu_start_ms: start.as_secs_f64() * 1e3,
            };
            match out.get_mut(i) {
                Some(t) => {
                    let n = std::mem::take(&mut t.name);
                    *t = StageTiming { name: n, ..timing };
                }
                None => out.push(timing),
            }
            set_name(&mut out[i].name, name);
        }
    }
}
