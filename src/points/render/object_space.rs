//! The text's splat primitives for Table 10.3 (dissertation §10.3,
//! "Instancing Techniques for Point Primitives"): a quadrilateral with
//! corners (0,0), (1,0), (1,1), (0,1) placed in object space in the splat's
//! tangent plane, the corners also the texture coordinates of the
//! reconstruction kernel, which is stored in a texture; the GPU's
//! perspective-correct interpolation maps splat and kernel. There is no
//! screen-space EWA set-up, hence no low-pass prefilter: minified splats
//! alias where EWA's resampling kernel (§10.2.2) blurs.
//!
//! * `object-quad` ("quadruplication"): the splat data duplicated into the 4
//!   vertices of each quad in a vertex buffer built once, 2 triangles = 6
//!   indices per splat, in the list's SPT order, so that an instance's prefix
//!   of k splats is 6k consecutive indices (level of detail as for the other
//!   primitives, §10.1.7).
//! * `object-instanced` ("instancing"): one 4-vertex quad (6 indices)
//!   instanced per splat, the splat list itself as the per-instance vertex
//!   buffer.
//!
//! Both draw the same three passes as EWA splats (visibility, accumulation,
//! normalisation; or the opaque pass) with `glsl/points/object_splat.vert` and
//! `object_*.frag`; `points.normalize` is shared.

use std::sync::Arc;

use super::gpu_layout::GpuSplat;
use super::passes::SplatPush;
use super::pipeline_spec::PipelineSpec;
use super::selection::FramePlan;
use super::SplatPrimitive;
use crate::error::{Error, Result};
use crate::graph::{Binding, BufferAccess, BufferId, ImageId, PassBuilder, RenderGraph, Stage};
use crate::shaders;
use crate::view::Frame;
use crate::vulkan::{
    Buffer, BufferUsageFlags, CommandRecorder, Context, Format, GraphicsPipeline, GraphicsPipelineDesc, Image,
    ImageDesc, ImageUsageFlags, PrimitiveTopology, VertexAttribute,
};

/// Side of the kernel texture (texels).
pub const KERNEL_SIDE: u32 = 64;
/// `SplatPush.primitive` (`SPLAT_PRIMITIVE_OBJECT_*` in glsl/include/object_splat.glsl).
const PRIMITIVE_OBJECT_QUAD: u32 = 3;
const PRIMITIVE_OBJECT_INSTANCED: u32 = 4;
/// Indices of one quad: two triangles over corners (0,0), (1,0), (1,1), (0,1).
const QUAD_INDICES: [u32; 6] = [0, 1, 2, 0, 2, 3];
/// Corner (u, v) of vertex k of a quad.
const QUAD_UV: [[u32; 2]; 4] = [[0, 0], [1, 0], [1, 1], [0, 1]];
/// Bytes of a splat record (= of a quadruplicated vertex).
const SPLAT_BYTES: u64 = std::mem::size_of::<GpuSplat>() as u64;

/// Bytes per splat that quadruplication adds to the splat list (which the
/// selection, the shadow pass and the other primitives read anyway): three
/// more copies of the 64-byte splat record and six 32-bit indices.
pub const QUADRUPLICATION_EXTRA_BYTES_PER_SPLAT: u64 = 3 * SPLAT_BYTES + 6 * 4;

/// The reconstruction kernel as an R8 texture of [`KERNEL_SIDE`]² texels,
/// rows from v = 0: at a texel centre (u, v), with r = F_G·|2·(u, v) − 1|,
/// `exp(−r²/2)` inside the disk (r ≤ F_G, the cut-off of §10.2.2) and 0
/// outside it.
pub fn kernel_texels(cutoff: f32) -> Vec<u8> {
    let side = KERNEL_SIDE as usize;
    let centre = |i: usize| 2.0 * (i as f64 + 0.5) / side as f64 - 1.0;
    let cutoff = f64::from(cutoff);
    (0..side * side)
        .map(|k| {
            let (x, y) = (centre(k % side), centre(k / side));
            let d2 = x * x + y * y;
            if d2 > 1.0 {
                0
            } else {
                (255.0 * (-0.5 * cutoff * cutoff * d2).exp()).round() as u8
            }
        })
        .collect()
}

/// Quadruplication: the vertices and indices of `splats` as object-space
/// quads. Splat i owns vertices 4i..4i+3 (its record with the corner's
/// (u, v) ∈ {0, 1}² as u32 in `radius_color` z, w) and indices 6i..6i+5 =
/// 4i + (0, 1, 2, 0, 2, 3), so a prefix of k splats is the first 4k vertices
/// and 6k indices.
pub fn quadruplicate(splats: &[GpuSplat]) -> (Vec<GpuSplat>, Vec<u32>) {
    let vertices = splats
        .iter()
        .flat_map(|s| {
            QUAD_UV.map(|[u, v]| GpuSplat {
                radius_color: [
                    s.radius_color[0],
                    s.radius_color[1],
                    f32::from_bits(u),
                    f32::from_bits(v),
                ],
                ..*s
            })
        })
        .collect();
    let indices = (0..splats.len() as u32)
        .flat_map(|i| QUAD_INDICES.map(|k| 4 * i + k))
        .collect();
    (vertices, indices)
}

/// The object-space primitives' GPU data, uploaded once.
pub(super) struct ObjectSpaceResources {
    /// The kernel texture.
    kernel: Arc<Image>,
    /// Quadruplicated vertices (`object-quad`); None: the splat list is the
    /// per-instance vertex buffer (`object-instanced`).
    vertices: Option<Arc<Buffer>>,
    /// All quads' indices (`object-quad`) or one quad's (`object-instanced`).
    indices: Arc<Buffer>,
}

impl ObjectSpaceResources {
    /// Uploads the kernel texture for `cutoff` and, for `object-quad`, the
    /// quadruplicated `splats`; None for the other primitives.
    pub(super) fn upload(
        ctx: &Context,
        primitive: SplatPrimitive,
        splats: &[GpuSplat],
        cutoff: f32,
    ) -> Result<Option<ObjectSpaceResources>> {
        if !primitive.is_object_space() {
            return Ok(None);
        }
        let kernel = Image::with_data(
            ctx,
            ImageDesc {
                name: "splat kernel".into(),
                width: KERNEL_SIDE,
                height: KERNEL_SIDE,
                format: Format::R8_UNORM,
                usage: ImageUsageFlags::SAMPLED,
            },
            &kernel_texels(cutoff),
        )?;
        let upload = |name: &str, usage, bytes: &[u8]| Buffer::with_data(ctx, name, usage, bytes).map(Arc::new);
        let (vertices, indices) = match primitive {
            SplatPrimitive::ObjectQuad => {
                let (vertices, indices) = quadruplicate(splats);
                let usage = BufferUsageFlags::VERTEX_BUFFER;
                let vertices = upload("quadruplicated splats", usage, bytemuck::cast_slice(&vertices))?;
                (Some(vertices), indices)
            }
            _ => (None, QUAD_INDICES.to_vec()),
        };
        let indices = upload(
            "splat quad indices",
            BufferUsageFlags::INDEX_BUFFER,
            bytemuck::cast_slice(&indices),
        )?;
        Ok(Some(ObjectSpaceResources {
            kernel: Arc::new(kernel),
            vertices,
            indices,
        }))
    }

    /// Imports the resources into `graph`; `splats` is the splat list's id
    /// (the per-instance vertex buffer of `object-instanced`).
    pub(super) fn import<S: 'static>(&self, graph: &mut RenderGraph<Frame<S>>, splats: BufferId) -> ObjectSpaceBuffers {
        ObjectSpaceBuffers {
            kernel: graph.import_image(self.kernel.clone()),
            vertices: self
                .vertices
                .as_ref()
                .map_or(splats, |v| graph.import_buffer(v.clone())),
            indices: graph.import_buffer(self.indices.clone()),
        }
    }
}

/// The object-space primitives' resources in a frame graph.
#[derive(Clone, Copy, Debug)]
pub(super) struct ObjectSpaceBuffers {
    pub kernel: ImageId,
    pub vertices: BufferId,
    pub indices: BufferId,
}

impl ObjectSpaceBuffers {
    /// Declares what a splat pass reads: vertices, indices and the kernel
    /// texture (whose binding it returns).
    pub(super) fn read_by<'g, S: 'static>(
        &self,
        builder: PassBuilder<'g, Frame<S>>,
    ) -> (PassBuilder<'g, Frame<S>>, Binding) {
        let mut builder = builder
            .read(self.vertices, BufferAccess::Vertex)
            .read(self.indices, BufferAccess::Index);
        let kernel = builder.sample(self.kernel, Stage::Fragment);
        (builder, kernel)
    }
}

impl PipelineSpec {
    /// The pass's pipeline for `primitive` (an object-space one) with
    /// `fragment` (`object_*.frag`): the splat record as four vertex
    /// attributes (the third as u32: radius and colour bits, corner),
    /// per vertex (`object-quad`) or per instance (`object-instanced`).
    pub(super) fn build_object_space(
        &self,
        ctx: &Context,
        depth_format: Format,
        primitive: SplatPrimitive,
        fragment: crate::vulkan::SpirV,
    ) -> Result<GraphicsPipeline> {
        let attribute = |location: u32, format| VertexAttribute {
            location,
            format,
            offset: 16 * location,
        };
        let desc = GraphicsPipelineDesc {
            vertex: shaders::OBJECT_SPLAT_VERT,
            fragment,
            vertex_stride: SPLAT_BYTES as u32,
            vertex_attributes: vec![
                attribute(0, Format::R32G32B32A32_SFLOAT),
                attribute(1, Format::R32G32B32A32_SFLOAT),
                attribute(2, Format::R32G32B32A32_UINT),
                attribute(3, Format::R32G32B32A32_SFLOAT),
            ],
            ..self.desc(depth_format, PrimitiveTopology::TRIANGLE_LIST)
        };
        match primitive {
            SplatPrimitive::ObjectInstanced => GraphicsPipeline::new_per_instance(ctx, &desc),
            _ => GraphicsPipeline::new(ctx, &desc),
        }
    }
}

/// Records one draw per planned instance with `pipeline`: 6k indices from
/// 6·first for `object-quad`, k instances of the quad from instance `first`
/// for `object-instanced` (k splats of the prefix from splat `first`).
pub(super) fn draw(
    cmd: &mut CommandRecorder,
    pipeline: &GraphicsPipeline,
    plan: &FramePlan,
    (primitive, mut push): (SplatPrimitive, SplatPush),
    (vertices, indices): (&Buffer, &Buffer),
) -> Result<()> {
    let six = |n: u32| {
        n.checked_mul(6)
            .ok_or_else(|| Error::invalid("splat count", format!("{n} splats exceed one draw")))
    };
    cmd.bind_graphics(pipeline);
    cmd.bind_vertex_buffer(vertices);
    cmd.bind_index_buffer(indices);
    push.primitive = match primitive {
        SplatPrimitive::ObjectQuad => PRIMITIVE_OBJECT_QUAD,
        _ => PRIMITIVE_OBJECT_INSTANCED,
    };
    for d in &plan.draws {
        let record = plan
            .records
            .get(d.record as usize)
            .ok_or_else(|| Error::Graph(format!("points: draw of missing instance record {}", d.record)))?;
        let first = record.params[1].to_bits();
        push.record = d.record;
        cmd.push_constants(&push)?;
        match primitive {
            SplatPrimitive::ObjectQuad => cmd.draw_indexed_range(six(d.count)?, six(first)?, 1, 0),
            _ => cmd.draw_indexed_range(6, 0, d.count, first),
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernel_is_the_cut_gaussian() {
        let texels = kernel_texels(1.5);
        let side = KERNEL_SIDE as usize;
        assert_eq!(texels.len(), side * side);
        // Next to the centre: r ≈ 0, weight ≈ 1.
        assert!(texels[side / 2 * side + side / 2] >= 254);
        // Corners are outside the disk; the middle of an edge is just inside,
        // at r ≈ F_G: exp(−1.125) ≈ 0.325.
        assert_eq!(texels[0], 0);
        assert_eq!(texels[side * side - 1], 0);
        let edge = f64::from(texels[side / 2 * side]) / 255.0;
        assert!((edge - (-1.125f64).exp()).abs() < 0.03, "{edge}");
        // Symmetric in u and v.
        for (k, &t) in texels.iter().enumerate() {
            assert_eq!(t, texels[(k % side) * side + k / side]);
        }
    }

    #[test]
    fn quadruplication_keeps_prefixes_contiguous() {
        let splats: Vec<GpuSplat> = (0..5)
            .map(|i| GpuSplat {
                position_rmin: [i as f32, 0.0, 0.0, 0.0],
                normal_rmax: [0.0, 0.0, 1.0, 1.0],
                radius_color: [0.1, 0.0, 0.0, 0.0],
                clip: [0.0; 4],
            })
            .collect();
        let (vertices, indices) = quadruplicate(&splats);
        assert_eq!((vertices.len(), indices.len()), (20, 30));
        for k in 0..=splats.len() {
            // The first 6k indices reference exactly the first 4k vertices,
            // each of which carries splat ⌊index/4⌋.
            let prefix = &indices[..6 * k];
            assert!(prefix.iter().all(|&i| (i as usize) < 4 * k));
            for &i in prefix {
                let v = &vertices[i as usize];
                assert_eq!(v.position_rmin, splats[i as usize / 4].position_rmin);
            }
        }
        let corners: Vec<[u32; 2]> = vertices[..4]
            .iter()
            .map(|v| [v.radius_color[2].to_bits(), v.radius_color[3].to_bits()])
            .collect();
        assert_eq!(corners, QUAD_UV.to_vec());
        assert_eq!(QUADRUPLICATION_EXTRA_BYTES_PER_SPLAT, 216);
    }
}
