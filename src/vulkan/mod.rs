//! The Vulkan backend: the only layer with `unsafe` code and raw Vulkan
//! handles. Everything above it (graph, passes, scenes) uses these safe types.

mod clock;
mod commands;
mod context;
mod device_memory;
mod device_select;
mod features;
mod frames;
mod heap;
mod image;
mod memory;
mod pipeline;
mod present;
pub(crate) mod renderdoc;
mod shader_overrides;
mod validation;

pub use ash::vk::{
    AccessFlags2, BufferUsageFlags, CompareOp, Format, ImageLayout, ImageUsageFlags, PipelineStageFlags2,
    PrimitiveTopology,
};
pub(crate) use commands::BarrierBatch;
pub use commands::{CommandRecorder, LoadOp};
pub use context::{Context, ContextOptions, DeviceInfo};
pub use device_select::DeviceSelector;
pub(crate) use features::SUBGROUP_COMPUTE;
pub use frames::{CompletedFrame, FrameRing, FRAMES_IN_FLIGHT};
pub use image::{Image, ImageDesc, MemoryBlock};
pub use memory::{AccessState, Barrier, Buffer, BufferDesc, MemoryLocation};
pub use pipeline::{Blend, ComputePipeline, GraphicsPipeline, GraphicsPipelineDesc, SpirV, VertexAttribute};
pub use present::{AcquiredImage, PresentSync, Swapchain};
pub use validation::ValidationReport;
