//! `lighting.reference`: the Monte Carlo reference on the GPU (§9.2;
//! `glsl/lighting/reference.comp`). Owns the height-field buffer (heights
//! and max-mip pyramid), the sky-light map (RGBA32F) and the sun-visibility
//! map (R32F), one texel per height sample, persistent across frames.
//!
//! The pass recomputes the maps only when the lighting that matters to
//! them changed (or on [`MonteCarloReference::restart`]): call
//! [`MonteCarloReference::prepare`] with the frame's lighting constants
//! before executing the frame; it plans the frame's [`ReferenceWork`],
//! which the pass reads from the frame's prepared data ([`ReferenceFrame`];
//! nothing is shared between preparing and recording). A frame with
//! nothing to do records no dispatch. The work is split into dispatches of
//! `rows_per_dispatch` rows, and with `rows_per_frame` spread over several
//! frames (progressive).

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use super::pyramid::field_buffer_words;
use super::{ray_offset, ReferenceSettings};
use crate::error::Result;
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

/// Where the computation stands across frames (the technique's state).
#[derive(Debug, Default)]
struct Schedule {
    /// The lighting the maps are (being) computed for.
    key: Option<Vec<u32>>,
    next_row: u32,
    /// Analytic test sky (constant, per unit ω.z) instead of the frame's.
    test_sky: Option<(Vec3, Vec3)>,
}

/// What `lighting.reference` dispatches in one frame, planned by
/// [`MonteCarloReference::prepare`] (prepared data, read by the pass).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReferenceWork {
    /// Rows `[first, first + count)`.
    rows: (u32, u32),
    /// Analytic test sky (constant, per unit ω.z) instead of the frame's.
    test_sky: Option<(Vec3, Vec3)>,
}

/// The frame data `lighting.reference` reads its [`ReferenceWork`] from
/// (None: nothing to dispatch).
pub trait ReferenceFrame {
    fn reference_work(&self) -> Option<&ReferenceWork>;
}

impl ReferenceFrame for ReferenceWork {
    fn reference_work(&self) -> Option<&ReferenceWork> {
        Some(self)
    }
}

impl<S: crate::view::Provides<crate::lighting::technique::PreparedLighting>> ReferenceFrame for crate::view::Frame<S> {
    fn reference_work(&self) -> Option<&ReferenceWork> {
        let lighting = self.prepared::<crate::lighting::technique::PreparedLighting>().ok()?;
        lighting.reference.as_ref()
    }
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
    schedule: Schedule,
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
            schedule: Schedule::default(),
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
    pub fn set_test_sky(&mut self, sky: Option<(Vec3, Vec3)>) {
        self.schedule.test_sky = sky;
        self.schedule.key = None;
    }

    /// Computes the maps anew from the next frame on.
    pub fn restart(&mut self) {
        self.schedule.key = None;
    }

    /// Plans this frame's work for the lighting constants `lighting` (the
    /// ones the pass reads): starts over when what the maps depend on
    /// changed, else continues an unfinished computation; nothing once done.
    /// Returns the frame's work (for the pass, through the frame's prepared
    /// data) and the progress.
    pub fn prepare(&mut self, lighting: &LightingFrame) -> (ReferenceWork, ReferenceProgress) {
        let key = lighting_key(lighting);
        let s = &mut self.schedule;
        let restarted = s.key.as_ref() != Some(&key);
        if restarted {
            s.key = Some(key);
            s.next_row = 0;
        }
        let first = s.next_row;
        let count = self.settings.rows_per_frame.unwrap_or(self.rows).min(self.rows - first);
        s.next_row = first + count;
        let work = ReferenceWork {
            rows: (first, count),
            test_sky: s.test_sky,
        };
        let progress = ReferenceProgress {
            rows_done: s.next_row,
            rows: self.rows,
            restarted,
        };
        (work, progress)
    }

    /// Sets the field (`field`) of a view's lighting constants (the maps'
    /// handles, `maps.x` and `maps.z`, are written by the pass that
    /// declares them: [`crate::view::LightingMap::ReferenceSkyLight`]).
    pub fn fill(&self, lighting: &mut LightingFrame) {
        lighting.field = [
            (self.columns - 1) as f32 * self.spacing[0],
            (self.rows - 1) as f32 * self.spacing[1],
            (self.columns - 1) as f32,
            (self.rows - 1) as f32,
        ];
    }

    /// Imports the maps and the field into `graph` and declares
    /// `lighting.reference` (once per graph, not per view): it reads the lighting constants in `lighting`
    /// (any view's: the maps do not depend on the view) and samples
    /// `environment` (the sky model's lookup tables, whatever
    /// `sky_radiance` reads), and writes the maps.
    pub fn declare<P: ReferenceFrame + 'static>(
        &self,
        graph: &mut RenderGraph<P>,
        lighting: UploadRegion,
        environment: &[ImageId],
    ) -> ReferenceImages {
        let field = graph.import_buffer(self.field.clone());
        let sky_light = graph.import_image(self.sky_light.clone());
        let sun_visibility = graph.import_image(self.sun_visibility.clone());
        let compute = Stage::Compute;
        let mut pass = graph.pass("lighting.reference");
        let bindings = [
            pass.upload(lighting, compute),
            pass.storage_buffer(field, BufferAccess::StorageRead(compute)),
            pass.storage_image(sky_light, ImageAccess::StorageReadWrite(compute)),
            pass.storage_image(sun_visibility, ImageAccess::StorageReadWrite(compute)),
        ];
        for &image in environment {
            pass.sample(image, compute);
        }
        let (pipeline, settings) = (self.pipeline.clone(), self.settings);
        let (columns, spacing, offset) = (self.columns, self.spacing, self.offset);
        pass.record(move |ctx, frame| {
            // A frame without `prepare` records nothing.
            let Some(&ReferenceWork {
                rows: (first, count),
                test_sky,
            }) = frame.reference_work()
            else {
                return Ok(());
            };
            if count == 0 {
                return Ok(());
            }
            let flags =
                u32::from(test_sky.is_some()) * FLAG_TEST_SKY + u32::from(settings.sun_bounces) * FLAG_SUN_BOUNCES;
            let (a, b) = test_sky.unwrap_or_default();
            let mut handles = [0; 4];
            for (h, &binding) in handles.iter_mut().zip(&bindings) {
                *h = ctx.handle(binding)?;
            }
            let mut push = ReferencePush {
                handles,
                work: [first, 0, settings.samples, settings.seed],
                options: [settings.bounces, flags, 0, 0],
                surface: [spacing[0], spacing[1], settings.bounce_albedo, offset],
                sky_a: [a.x, a.y, a.z, 0.0],
                sky_b: [b.x, b.y, b.z, 0.0],
            };
            let maps = [ctx.image(sky_light)?, ctx.image(sun_visibility)?];
            let cmd = ctx.cmd();
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
