//! `lighting.reference`: the Monte Carlo reference on the GPU (§9.2;
//! `glsl/lighting/reference.comp`). Owns the height-field buffer (heights
//! and max-mip pyramid), the sky-light map (RGBA32F) and the sun-visibility
//! map (R32F), one texel per height sample, persistent across frames.
//!
//! The pass recomputes the maps only when the lighting that matters to
//! them changed (or on [`MonteCarloReference::restart`]): call
//! [`MonteCarloReference::prepare`] with the frame's lighting constants
//! before executing the frame; a frame with nothing to do records no
//! dispatch. The work is split into dispatches of `rows_per_dispatch` rows,
//! and with `rows_per_frame` spread over several frames (progressive).

use std::sync::{Arc, Mutex};

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use super::pyramid::field_buffer_words;
use super::{ray_offset, ReferenceSettings};
use crate::error::{Error, Result};
use crate::graph::{BufferAccess, ImageAccess, ImageId, RenderGraph, Stage, UploadRegion};
use crate::io::heightmap::HeightField;
use crate::lighting::constants::LightingFrame;
use crate::shaders;
use crate::vulkan::{
    AccessFlags2, Barrier, Buffer, BufferUsageFlags, ComputePipeline, Context, Format, Image, ImageDesc, ImageLayout,
    ImageUsageFlags, PipelineStageFlags2,
};

/// Flag of the push constants: the analytic test sky.
const FLAG_TEST_SKY: u32 = 1;
/// Flag of the push constants: bounce the separate sun.
const FLAG_SUN_BOUNCES: u32 = 2;

/// Push constants of `lighting.reference` (`glsl/lighting/reference.comp`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ReferencePush {
    handles: [u32; 4],
    work: [u32; 4],
    options: [u32; 4],
    surface: [f32; 4],
    sky_a: [f32; 4],
    sky_b: [f32; 4],
}

/// The graph images of the maps; consumers declare them as
/// [`ImageAccess::Sampled`] reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ReferenceImages {
    /// rgb: sky light per unit albedo, a: sky visibility.
    pub sky_light: ImageId,
    /// Sun visibility.
    pub sun_visibility: ImageId,
}

/// Where the computation stands after [`MonteCarloReference::prepare`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ReferenceProgress {
    /// Rows complete once this frame's dispatches ran.
    pub rows_done: u32,
    pub rows: u32,
    /// Whether this frame starts over (the lighting changed).
    pub restarted: bool,
}

impl ReferenceProgress {
    /// Whether the maps are complete after this frame.
    pub fn complete(&self) -> bool {
        self.rows_done >= self.rows
    }
}

/// What the recording closure dispatches this frame.
#[derive(Debug, Default)]
struct Schedule {
    /// The lighting the maps are (being) computed for.
    key: Option<Vec<u32>>,
    next_row: u32,
    /// Rows `[first, first + count)` to dispatch this frame.
    pending: (u32, u32),
    /// Analytic test sky (constant, per unit ω.z) instead of the frame's.
    test_sky: Option<(Vec3, Vec3)>,
}

/// The Monte Carlo reference pass and its maps (§9.2).
pub struct MonteCarloReference {
    pipeline: Arc<ComputePipeline>,
    field: Arc<Buffer>,
    sky_light: Arc<Image>,
    sun_visibility: Arc<Image>,
    settings: ReferenceSettings,
    columns: u32,
    rows: u32,
    spacing: [f32; 2],
    offset: f32,
    schedule: Arc<Mutex<Schedule>>,
}

fn lock(schedule: &Mutex<Schedule>) -> Result<std::sync::MutexGuard<'_, Schedule>> {
    schedule
        .lock()
        .map_err(|_| Error::Graph("lighting.reference: schedule lock poisoned".into()))
}

/// Between two chunks' dispatches: storage writes before storage accesses.
fn chunk_barrier() -> Barrier {
    let access = AccessFlags2::SHADER_STORAGE_WRITE | AccessFlags2::SHADER_STORAGE_READ;
    Barrier {
        src_stages: PipelineStageFlags2::COMPUTE_SHADER,
        src_access: AccessFlags2::SHADER_STORAGE_WRITE,
        dst_stages: PipelineStageFlags2::COMPUTE_SHADER,
        dst_access: access,
        old_layout: ImageLayout::GENERAL,
        new_layout: ImageLayout::GENERAL,
    }
}

/// The parts of the lighting constants the maps depend on.
fn lighting_key(l: &LightingFrame) -> Vec<u32> {
    let mut key: Vec<u32> = Vec::with_capacity(64);
    for v in [
        l.sun,
        l.sun_radiance,
        l.sun_irradiance,
        l.zenith,
        l.perez_norm,
        l.rayleigh,
        l.mie,
        l.planet,
    ] {
        key.extend(v.map(f32::to_bits));
    }
    for v in l.perez {
        key.extend(v.map(f32::to_bits));
    }
    key.extend([l.exposure[3].to_bits(), l.models[0], l.models[3]]);
    key.extend(l.atmosphere);
    key
}

impl MonteCarloReference {
    /// Uploads `field` and creates the pipeline and the (zeroed) maps.
    pub fn new(ctx: &Context, field: &HeightField, settings: ReferenceSettings) -> Result<MonteCarloReference> {
        settings.validate()?;
        let words = field_buffer_words(field)?;
        let buffer = Buffer::with_data(
            ctx,
            "lighting.reference height field",
            BufferUsageFlags::STORAGE_BUFFER,
            bytemuck::cast_slice(&words),
        )?;
        let (w, h) = (field.columns, field.rows);
        let map = |name: &str, format: Format, bytes: usize| {
            let desc = ImageDesc {
                name: name.into(),
                width: w,
                height: h,
                format,
                usage: ImageUsageFlags::STORAGE | ImageUsageFlags::SAMPLED | ImageUsageFlags::TRANSFER_SRC,
            };
            Image::with_data(ctx, desc, &vec![0u8; w as usize * h as usize * bytes]).map(Arc::new)
        };
        Ok(MonteCarloReference {
            pipeline: Arc::new(ComputePipeline::new(ctx, shaders::LIGHTING_REFERENCE)?),
            field: Arc::new(buffer),
            sky_light: map("lighting.reference sky light", Format::R32G32B32A32_SFLOAT, 16)?,
            sun_visibility: map("lighting.reference sun visibility", Format::R32_SFLOAT, 4)?,
            settings,
            columns: w,
            rows: h,
            spacing: [field.spacing.x as f32, field.spacing.y as f32],
            offset: ray_offset(field),
            schedule: Arc::new(Mutex::new(Schedule::default())),
        })
    }

    /// The settings.
    pub fn settings(&self) -> &ReferenceSettings {
        &self.settings
    }

    /// The sky-light map (rgb: sky light per unit albedo, a: sky visibility).
    pub fn sky_light_image(&self) -> &Arc<Image> {
        &self.sky_light
    }

    /// The sun-visibility map.
    pub fn sun_visibility_image(&self) -> &Arc<Image> {
        &self.sun_visibility
    }

    /// Tests only: the sky is `constant + per_z · ω.z` instead of the
    /// frame's sky model (`None`: the frame's). Restarts.
    pub fn set_test_sky(&self, sky: Option<(Vec3, Vec3)>) -> Result<()> {
        let mut s = lock(&self.schedule)?;
        s.test_sky = sky;
        s.key = None;
        Ok(())
    }

    /// Computes the maps anew from the next frame on.
    pub fn restart(&self) -> Result<()> {
        lock(&self.schedule)?.key = None;
        Ok(())
    }

    /// Plans this frame's work for the lighting constants `lighting` (the
    /// ones the pass reads): starts over when what the maps depend on
    /// changed, else continues an unfinished computation; nothing once done.
    pub fn prepare(&self, lighting: &LightingFrame) -> Result<ReferenceProgress> {
        let key = lighting_key(lighting);
        let mut s = lock(&self.schedule)?;
        let restarted = s.key.as_ref() != Some(&key);
        if restarted {
            s.key = Some(key);
            s.next_row = 0;
        }
        let first = s.next_row;
        let count = self.settings.rows_per_frame.unwrap_or(self.rows).min(self.rows - first);
        s.pending = (first, count);
        s.next_row = first + count;
        Ok(ReferenceProgress {
            rows_done: s.next_row,
            rows: self.rows,
            restarted,
        })
    }

    /// Sets the maps' sampled handles (`maps.x`, `maps.z`) and the field
    /// (`field`) of a view's lighting constants.
    pub fn fill(&self, lighting: &mut LightingFrame) -> Result<()> {
        let missing = || Error::Graph("lighting.reference: a map has no sampled handle".into());
        lighting.maps[0] = self.sky_light.sampled_handle().ok_or_else(missing)?;
        lighting.maps[2] = self.sun_visibility.sampled_handle().ok_or_else(missing)?;
        lighting.field = [
            (self.columns - 1) as f32 * self.spacing[0],
            (self.rows - 1) as f32 * self.spacing[1],
            (self.columns - 1) as f32,
            (self.rows - 1) as f32,
        ];
        Ok(())
    }

    /// Imports the maps and the field into `graph` and declares
    /// `lighting.reference` (once per graph, not per view): it reads the lighting constants in `lighting`
    /// (any view's: the maps do not depend on the view) and samples
    /// `environment` (the sky model's lookup tables, whatever
    /// `sky_radiance` reads), and writes the maps.
    pub fn declare<P: 'static>(
        &self,
        graph: &mut RenderGraph<P>,
        lighting: UploadRegion,
        environment: &[ImageId],
    ) -> ReferenceImages {
        let field = graph.import_buffer(self.field.clone());
        let sky_light = graph.import_image(self.sky_light.clone());
        let sun_visibility = graph.import_image(self.sun_visibility.clone());
        let mut pass = graph
            .pass("lighting.reference")
            .read(lighting, BufferAccess::StorageRead(Stage::Compute))
            .read(field, BufferAccess::StorageRead(Stage::Compute))
            .write(sky_light, ImageAccess::StorageReadWrite(Stage::Compute))
            .write(sun_visibility, ImageAccess::StorageReadWrite(Stage::Compute));
        for &image in environment {
            pass = pass.read(image, ImageAccess::Sampled(Stage::Compute));
        }
        let (pipeline, schedule, settings) = (self.pipeline.clone(), self.schedule.clone(), self.settings);
        let (columns, spacing, offset) = (self.columns, self.spacing, self.offset);
        pass.record(move |pass, _| {
            // Taken: a frame without `prepare` records nothing.
            let ((first, count), test_sky) = {
                let mut s = lock(&schedule)?;
                (std::mem::take(&mut s.pending), s.test_sky)
            };
            if count == 0 {
                return Ok(());
            }
            let flags =
                u32::from(test_sky.is_some()) * FLAG_TEST_SKY + u32::from(settings.sun_bounces) * FLAG_SUN_BOUNCES;
            let (a, b) = test_sky.unwrap_or_default();
            let mut push = ReferencePush {
                handles: [
                    pass.upload(lighting)?,
                    pass.storage_buffer(field)?,
                    pass.storage_image(sky_light)?,
                    pass.storage_image(sun_visibility)?,
                ],
                work: [first, 0, settings.samples, settings.seed],
                options: [settings.bounces, flags, 0, 0],
                surface: [spacing[0], spacing[1], settings.bounce_albedo, offset],
                sky_a: [a.x, a.y, a.z, 0.0],
                sky_b: [b.x, b.y, b.z, 0.0],
            };
            let maps = [pass.image(sky_light)?, pass.image(sun_visibility)?];
            let cmd = pass.cmd();
            cmd.bind_compute(&pipeline);
            let mut row = first;
            while row < first + count {
                if row > first {
                    // Chunks write disjoint rows, but synchronization
                    // validation tracks whole images.
                    cmd.barriers(&[], &[(maps[0], chunk_barrier()), (maps[1], chunk_barrier())]);
                }
                let rows = settings.rows_per_dispatch.min(first + count - row);
                push.work[0] = row;
                push.work[1] = rows;
                cmd.push_constants(&push)?;
                cmd.dispatch(columns.div_ceil(8), rows.div_ceil(8), 1);
                row += rows;
            }
            Ok(())
        });
        ReferenceImages {
            sky_light,
            sun_visibility,
        }
    }
}
