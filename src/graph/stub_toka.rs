//! TEMPORARY stub of Contract 1 (helper toka), reverted before merging i27-graph.
#![allow(dead_code, missing_docs)]

use bytemuck::Pod;

use super::execute::PassContext;
use super::typed::{BufferAccess, BufferId, ImageAccess, ImageId};
use super::uploads::UploadRegion;
use super::{PassBuilder, Stage};
use crate::error::Result;
use crate::vulkan::{ComputePipeline, GraphicsPipeline, LoadOp};

#[derive(Clone, Copy, Debug)]
pub enum Binding {
    Sampled(ImageId),
    StorageImage(ImageId),
    StorageBuffer(BufferId),
    Upload(UploadRegion),
}

impl<'g, P: 'static> PassBuilder<'g, P> {
    fn push_use<R: super::Resource>(&mut self, r: R, a: R::Access) {
        self.decl.uses.push((r.id(), a.into()));
    }
    pub fn sample(&mut self, image: ImageId, stage: Stage) -> Binding {
        self.push_use(image, ImageAccess::Sampled(stage));
        Binding::Sampled(image)
    }
    pub fn storage_image(&mut self, image: ImageId, access: ImageAccess) -> Binding {
        self.push_use(image, access);
        Binding::StorageImage(image)
    }
    pub fn storage_buffer(&mut self, buffer: BufferId, access: BufferAccess) -> Binding {
        self.push_use(buffer, access);
        Binding::StorageBuffer(buffer)
    }
    pub fn upload(&mut self, region: UploadRegion, stage: Stage) -> Binding {
        self.push_use(region, BufferAccess::StorageRead(stage));
        Binding::Upload(region)
    }
    pub fn pipeline(self, _p: &GraphicsPipeline) -> GraphicsBuilder<'g, P> {
        GraphicsBuilder {
            inner: self.graphics(),
            colors: Vec::new(),
            depth: None,
        }
    }
}

pub struct GraphicsBuilder<'g, P> {
    inner: PassBuilder<'g, P>,
    colors: Vec<(ImageId, LoadOp)>,
    depth: Option<(ImageId, Option<f32>)>,
}

impl<'g, P: 'static> GraphicsBuilder<'g, P> {
    pub fn color(mut self, id: ImageId, load: LoadOp) -> Self {
        let access = if matches!(load, LoadOp::Load) {
            ImageAccess::ColorAttachmentReadWrite
        } else {
            ImageAccess::ColorAttachmentWrite
        };
        self.inner = self.inner.write(id, access);
        self.colors.push((id, load));
        self
    }
    pub fn depth(mut self, id: ImageId, clear: Option<f32>) -> Self {
        self.inner = self.inner.write(id, ImageAccess::DepthAttachmentWrite);
        self.depth = Some((id, clear));
        self
    }
    pub fn read<R: super::Resource>(mut self, resource: R, access: R::Access) -> Self {
        self.inner = self.inner.read(resource, access);
        self
    }
    pub fn write<R: super::Resource>(mut self, resource: R, access: R::Access) -> Self {
        self.inner = self.inner.write(resource, access);
        self
    }
    pub fn record(self, record: impl Fn(&mut PassContext<'_>, &P) -> Result<()> + Send + Sync + 'static) {
        let (colors, depth) = (self.colors, self.depth);
        self.inner.record(move |ctx, p| {
            let images: Vec<_> = colors.iter().map(|(id, l)| Ok((ctx.image(*id)?, *l))).collect::<Result<_>>()?;
            let depth = match depth {
                Some((id, c)) => Some((ctx.image(id)?, c)),
                None => None,
            };
            ctx.cmd().begin_rendering(&images, depth);
            let r = record(ctx, p);
            ctx.cmd().end_rendering();
            r
        })
    }
}

impl PassContext<'_> {
    pub fn handle(&self, b: Binding) -> Result<u32> {
        match b {
            Binding::Sampled(i) => self.sampled(i),
            Binding::StorageImage(i) => self.storage_image(i),
            Binding::StorageBuffer(b) => self.storage_buffer(b),
            Binding::Upload(r) => self.upload(r),
        }
    }
    pub fn write_upload(&mut self, b: Binding, bytes: &[u8]) -> Result<()> {
        let Binding::Upload(r) = b else {
            return Err(crate::error::Error::Graph("not an upload".into()));
        };
        self.uploads_arena()?.writer(self.frame()).write(r, bytes)
    }
    pub fn write_upload_pod<T: Pod>(&mut self, b: Binding, value: &T) -> Result<()> {
        self.write_upload(b, bytemuck::bytes_of(value))
    }
    pub fn dispatch<T: Pod>(&mut self, pipeline: &ComputePipeline, push: &T, [x, y, z]: [u32; 3]) -> Result<()> {
        let cmd = self.cmd();
        cmd.bind_compute(pipeline);
        cmd.push_constants(push)?;
        cmd.dispatch(x, y, z);
        Ok(())
    }
    pub fn draw_full_screen<T: Pod>(&mut self, pipeline: &GraphicsPipeline, push: &T) -> Result<()> {
        let cmd = self.cmd();
        cmd.bind_graphics(pipeline);
        cmd.push_constants(push)?;
        cmd.draw(3, 1);
        Ok(())
    }
}
