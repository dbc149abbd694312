//! The frame: prepare, then record. Before a frame is recorded, every
//! technique's [`Technique::prepare`] does its CPU work (LOD, tile and point
//! planning) for the frame's views and returns its prepared data, which goes
//! into the [`Frame`]; the passes' recording closures then only read it
//! (`Fn`, no locks), in the manner of Granite's `refresh()` before the
//! graph runs and kajiya's renderers' prepare step.

use std::any::{type_name, Any, TypeId};

use super::{Lighting, View, ViewIndex};
use crate::error::{Error, Result};
use crate::graph::{CpuStage, UploadWriter};

/// Everything a frame's passes read: its views, its lighting and each
/// technique's prepared data.
pub struct Frame {
    /// Frame number (0, 1, 2, …).
    pub index: u64,
    pub views: Vec<View>,
    pub lighting: Lighting,
    prepared: Vec<(TypeId, Box<dyn Any + Send + Sync>)>,
}

impl Frame {
    /// A frame of `views` with nothing prepared yet.
    pub fn new(index: u64, views: Vec<View>, lighting: Lighting) -> Frame {
        Frame {
            index,
            views,
            lighting,
            prepared: Vec::new(),
        }
    }

    /// The view `index`.
    pub fn view(&self, index: ViewIndex) -> Result<&View> {
        self.views
            .get(index)
            .ok_or_else(|| Error::Graph(format!("view {index} is not in this frame")))
    }

    /// Adds a technique's prepared data (replacing any of the same type).
    pub fn insert<T: Any + Send + Sync>(&mut self, value: T) {
        let id = TypeId::of::<T>();
        self.prepared.retain(|(t, _)| *t != id);
        self.prepared.push((id, Box::new(value)));
    }

    /// The prepared data of type `T`.
    pub fn prepared<T: Any>(&self) -> Result<&T> {
        find_prepared(&self.prepared)
    }

    /// Runs `technique`'s prepare step as the profile stage
    /// `prepare.<name>` and adds its result to the frame.
    pub fn prepare<T: Technique>(
        &mut self,
        technique: &mut T,
        uploads: &mut UploadWriter<'_>,
        stages: &mut Vec<CpuStage>,
    ) -> Result<()> {
        let name = format!("prepare.{}", technique.name());
        let prepared = CpuStage::time(stages, &name, || {
            let mut ctx = FrameContext {
                index: self.index,
                views: &self.views,
                lighting: &self.lighting,
                uploads,
                earlier: &self.prepared,
            };
            technique.prepare(&mut ctx)
        })?;
        self.insert(prepared);
        Ok(())
    }
}

/// What a technique's prepare step gets: the frame's number, views and
/// lighting, and the frame slot's upload regions to write (the slot's
/// previous frame has completed).
pub struct FrameContext<'a, 'u> {
    pub index: u64,
    pub views: &'a [View],
    pub lighting: &'a Lighting,
    pub uploads: &'a mut UploadWriter<'u>,
    /// What the techniques prepared before this one.
    earlier: &'a [(TypeId, Box<dyn Any + Send + Sync>)],
}

impl FrameContext<'_, '_> {
    /// The prepared data of type `T` of a technique prepared earlier this
    /// frame (the lighting reads the shadow cascades' plan).
    pub fn prepared<T: Any>(&self) -> Result<&T> {
        find_prepared(self.earlier)
    }
}

fn find_prepared<T: Any>(prepared: &[(TypeId, Box<dyn Any + Send + Sync>)]) -> Result<&T> {
    prepared
        .iter()
        .find(|(t, _)| *t == TypeId::of::<T>())
        .and_then(|(_, v)| v.downcast_ref::<T>())
        .ok_or_else(|| Error::Graph(format!("{} was not prepared for this frame", type_name::<T>())))
}

/// A technique: persistent GPU state, passes declared once into the frame
/// graph, and a per-frame CPU step that prepares what those passes read.
pub trait Technique {
    /// What the technique's passes read this frame.
    type Prepared: Any + Send + Sync;
    /// Short name; the profile stage is `prepare.<name>`.
    fn name(&self) -> &'static str;
    /// The CPU work of a frame, before recording: plans, uploads, statistics.
    fn prepare(&mut self, frame: &mut FrameContext<'_, '_>) -> Result<Self::Prepared>;
}
