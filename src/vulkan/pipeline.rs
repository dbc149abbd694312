//! Compute and graphics pipelines from SPIR-V, all on the heap's one
//! pipeline layout. Graphics pipelines use dynamic rendering.

use ash::vk;

use super::context::{vk_err, Context};
use super::memory::Garbage;
use crate::error::{Error, Result};

/// A SPIR-V module as compiled into `spirv/` (see `crate::shaders`).
#[derive(Clone, Copy, Debug)]
pub struct SpirV {
    /// Path under `spirv/`, for messages.
    pub name: &'static str,
    pub bytes: &'static [u8],
}

fn create_module(ctx: &Context, spirv: &SpirV) -> Result<vk::ShaderModule> {
    let bytes = ctx.shader_bytes(spirv);
    let words = ash::util::read_spv(&mut std::io::Cursor::new(&bytes[..])).map_err(|e| Error::Shader {
        path: spirv.name.into(),
        message: e.to_string(),
    })?;
    if words.first() != Some(&0x0723_0203) {
        return Err(Error::Shader {
            path: spirv.name.into(),
            message: "not a SPIR-V module (bad magic number)".into(),
        });
    }
    let info = vk::ShaderModuleCreateInfo::default().code(&words);
    // SAFETY: `words` is a SPIR-V module produced by shaderc (the tools
    // crate's, or hot reload's: the same compile function).
    unsafe { ctx.shared.device.create_shader_module(&info, None) }.map_err(vk_err("vkCreateShaderModule"))
}

fn destroy_module(ctx: &Context, module: vk::ShaderModule) {
    // SAFETY: modules are only needed during pipeline creation.
    unsafe { ctx.shared.device.destroy_shader_module(module, None) };
}

/// A compute pipeline.
pub struct ComputePipeline {
    ctx: Context,
    pub(crate) raw: vk::Pipeline,
}

impl ComputePipeline {
    /// Builds a compute pipeline from a module with entry point `main`.
    pub fn new(ctx: &Context, shader: SpirV) -> Result<Self> {
        let module = create_module(ctx, &shader)?;
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(c"main");
        let info = vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(ctx.shared.heap.pipeline_layout);
        // SAFETY: valid create info; the module lives across the call.
        let result = unsafe {
            ctx.shared
                .device
                .create_compute_pipelines(vk::PipelineCache::null(), &[info], None)
        };
        destroy_module(ctx, module);
        let raw = result.map_err(|(_, e)| vk_err("vkCreateComputePipelines")(e))?[0];
        ctx.name_object(raw, shader.name);
        Ok(ComputePipeline { ctx: ctx.clone(), raw })
    }
}

impl Drop for ComputePipeline {
    fn drop(&mut self) {
        self.ctx.defer_destroy(Garbage::Pipeline(self.raw));
    }
}

/// One vertex attribute in buffer binding 0.
#[derive(Clone, Copy, Debug)]
pub struct VertexAttribute {
    pub location: u32,
    pub format: vk::Format,
    pub offset: u32,
}

/// Blending of colour attachments (integer attachments are always replaced).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blend {
    /// Replace.
    None,
    /// `src + dst` (accumulation).
    Additive,
    /// Premultiplied-alpha over.
    PremultipliedOver,
}

/// Whether `format` holds unsigned or signed integers (no blending).
fn is_integer_format(format: vk::Format) -> bool {
    use vk::Format as F;
    matches!(
        format,
        F::R8_UINT
            | F::R8_SINT
            | F::R8G8_UINT
            | F::R8G8_SINT
            | F::R8G8B8A8_UINT
            | F::R8G8B8A8_SINT
            | F::R16_UINT
            | F::R16_SINT
            | F::R16G16_UINT
            | F::R16G16_SINT
            | F::R16G16B16A16_UINT
            | F::R16G16B16A16_SINT
            | F::R32_UINT
            | F::R32_SINT
            | F::R32G32_UINT
            | F::R32G32_SINT
            | F::R32G32B32A32_UINT
            | F::R32G32B32A32_SINT
    )
}

/// Fixed-function state of a graphics pipeline.
#[derive(Clone, Debug)]
pub struct GraphicsPipelineDesc {
    pub name: &'static str,
    pub vertex: SpirV,
    pub fragment: SpirV,
    /// Stride of vertex buffer binding 0 (0: no vertex buffer).
    pub vertex_stride: u32,
    pub vertex_attributes: Vec<VertexAttribute>,
    pub topology: vk::PrimitiveTopology,
    pub cull_back_faces: bool,
    pub wireframe: bool,
    pub color_formats: Vec<vk::Format>,
    pub blend: Blend,
    pub depth_format: Option<vk::Format>,
    pub depth_test: bool,
    pub depth_write: bool,
    pub depth_compare: vk::CompareOp,
}

impl GraphicsPipelineDesc {
    /// A full-screen pass: `vertex` draws one triangle covering the screen
    /// (no vertex buffer), `fragment` writes `color_formats`; no blending, no depth.
    pub fn full_screen(name: &'static str, (vertex, fragment): (SpirV, SpirV), color_formats: Vec<vk::Format>) -> Self {
        GraphicsPipelineDesc {
            name,
            vertex,
            fragment,
            vertex_stride: 0,
            vertex_attributes: Vec::new(),
            topology: vk::PrimitiveTopology::TRIANGLE_LIST,
            cull_back_faces: false,
            wireframe: false,
            color_formats,
            blend: Blend::None,
            depth_format: None,
            depth_test: false,
            depth_write: false,
            depth_compare: vk::CompareOp::ALWAYS,
        }
    }
}

/// A graphics pipeline for dynamic rendering.
pub struct GraphicsPipeline {
    ctx: Context,
    pub(crate) raw: vk::Pipeline,
    name: &'static str,
    color_formats: Vec<vk::Format>,
    depth_format: Option<vk::Format>,
}

impl GraphicsPipeline {
    /// Builds a graphics pipeline.
    pub fn new(ctx: &Context, desc: &GraphicsPipelineDesc) -> Result<Self> {
        Self::with_input_rate(ctx, desc, vk::VertexInputRate::VERTEX)
    }

    /// Builds a graphics pipeline whose vertex buffer binding 0 advances
    /// once per instance (per-instance attributes, e.g. instanced splat quads).
    pub fn new_per_instance(ctx: &Context, desc: &GraphicsPipelineDesc) -> Result<Self> {
        Self::with_input_rate(ctx, desc, vk::VertexInputRate::INSTANCE)
    }

    fn with_input_rate(ctx: &Context, desc: &GraphicsPipelineDesc, input_rate: vk::VertexInputRate) -> Result<Self> {
        let vertex = create_module(ctx, &desc.vertex)?;
        let fragment = match create_module(ctx, &desc.fragment) {
            Ok(m) => m,
            Err(e) => {
                destroy_module(ctx, vertex);
                return Err(e);
            }
        };
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vertex)
                .name(c"main"),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(fragment)
                .name(c"main"),
        ];
        let bindings = [vk::VertexInputBindingDescription {
            binding: 0,
            stride: desc.vertex_stride,
            input_rate,
        }];
        let attributes: Vec<_> = desc
            .vertex_attributes
            .iter()
            .map(|a| vk::VertexInputAttributeDescription {
                location: a.location,
                binding: 0,
                format: a.format,
                offset: a.offset,
            })
            .collect();
        let vertex_input = if desc.vertex_stride > 0 {
            vk::PipelineVertexInputStateCreateInfo::default()
                .vertex_binding_descriptions(&bindings)
                .vertex_attribute_descriptions(&attributes)
        } else {
            vk::PipelineVertexInputStateCreateInfo::default()
        };
        let assembly = vk::PipelineInputAssemblyStateCreateInfo::default().topology(desc.topology);
        let viewport = vk::PipelineViewportStateCreateInfo::default()
            .viewport_count(1)
            .scissor_count(1);
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(if desc.wireframe {
                vk::PolygonMode::LINE
            } else {
                vk::PolygonMode::FILL
            })
            .cull_mode(if desc.cull_back_faces {
                vk::CullModeFlags::BACK
            } else {
                vk::CullModeFlags::NONE
            })
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        let multisample =
            vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(desc.depth_test)
            .depth_write_enable(desc.depth_write)
            .depth_compare_op(desc.depth_compare);
        let attachments = blend_attachments(desc);
        let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&attachments);
        let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(&desc.color_formats)
            .depth_attachment_format(desc.depth_format.unwrap_or(vk::Format::UNDEFINED));
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(ctx.shared.heap.pipeline_layout)
            .push_next(&mut rendering);
        // SAFETY: every pointer in `info` refers to locals that outlive the call.
        let result = unsafe {
            ctx.shared
                .device
                .create_graphics_pipelines(vk::PipelineCache::null(), &[info], None)
        };
        destroy_module(ctx, vertex);
        destroy_module(ctx, fragment);
        let raw = result.map_err(|(_, e)| vk_err("vkCreateGraphicsPipelines")(e))?[0];
        ctx.name_object(raw, desc.name);
        Ok(GraphicsPipeline {
            ctx: ctx.clone(),
            raw,
            name: desc.name,
            color_formats: desc.color_formats.clone(),
            depth_format: desc.depth_format,
        })
    }

    /// The pipeline's name (its debug name).
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// The colour attachment formats the pipeline renders into, in order.
    pub fn color_formats(&self) -> &[vk::Format] {
        &self.color_formats
    }

    /// The depth attachment format, if the pipeline has one.
    pub fn depth_format(&self) -> Option<vk::Format> {
        self.depth_format
    }
}

/// The colour blend state of each of `desc`'s attachments: its blend
/// mode, except on integer attachments (ids), which cannot blend and are
/// always replaced.
fn blend_attachments(desc: &GraphicsPipelineDesc) -> Vec<vk::PipelineColorBlendAttachmentState> {
    let attachment = match desc.blend {
        Blend::None => vk::PipelineColorBlendAttachmentState::default(),
        Blend::Additive => vk::PipelineColorBlendAttachmentState::default()
            .blend_enable(true)
            .src_color_blend_factor(vk::BlendFactor::ONE)
            .dst_color_blend_factor(vk::BlendFactor::ONE)
            .color_blend_op(vk::BlendOp::ADD)
            .src_alpha_blend_factor(vk::BlendFactor::ONE)
            .dst_alpha_blend_factor(vk::BlendFactor::ONE)
            .alpha_blend_op(vk::BlendOp::ADD),
        Blend::PremultipliedOver => vk::PipelineColorBlendAttachmentState::default()
            .blend_enable(true)
            .src_color_blend_factor(vk::BlendFactor::ONE)
            .dst_color_blend_factor(vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
            .color_blend_op(vk::BlendOp::ADD)
            .src_alpha_blend_factor(vk::BlendFactor::ONE)
            .dst_alpha_blend_factor(vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
            .alpha_blend_op(vk::BlendOp::ADD),
    }
    .color_write_mask(vk::ColorComponentFlags::RGBA);
    let replace = vk::PipelineColorBlendAttachmentState::default().color_write_mask(vk::ColorComponentFlags::RGBA);
    (desc.color_formats.iter())
        .map(|&f| if is_integer_format(f) { replace } else { attachment })
        .collect()
}

impl Drop for GraphicsPipeline {
    fn drop(&mut self) {
        self.ctx.defer_destroy(Garbage::Pipeline(self.raw));
    }
}
