//! The frame: prepare, then record. Before a frame is recorded, every
//! technique's [`Technique::prepare`] does its CPU work (LOD, tile and point
//! planning) for the frame's views and returns its prepared data, which goes
//! into the [`Frame`]; the passes' recording closures then only read it
//! (`Fn`, no locks), in the manner of Granite's `refresh()` before the
//! graph runs and kajiya's renderers' prepare step.

use std::any::{type_name, Any, TypeId};
use std::sync::Arc;

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
    /// Each technique's prepared data (`Option<T>`: None until prepared
    /// this frame). A frame is reused frame after frame
    /// ([`Frame::reset`]): the boxes stay, and each technique gets its
    /// previous frame's data back to reuse ([`Technique::recycle`]).
    prepared: Vec<(TypeId, Box<dyn Any + Send + Sync>)>,
    /// The profile stage name of each technique, made once.
    stage_names: Vec<(&'static str, Arc<str>)>,
}

impl Frame {
    /// A frame of `views` with nothing prepared yet.
    pub fn new(index: u64, views: Vec<View>, lighting: Lighting) -> Frame {
        Frame {
            index,
            views,
            lighting,
            prepared: Vec::new(),
            stage_names: Vec::new(),
        }
    }

    /// Starts frame `index` of the same views (update their cameras in
    /// [`Frame::views`]) with `lighting`: what was prepared becomes the
    /// previous frame's, handed back to each technique as it prepares.
    pub fn reset(&mut self, index: u64, lighting: Lighting) {
        self.index = index;
        self.lighting = lighting;
    }

    /// The view `index`.
    pub fn view(&self, index: ViewIndex) -> Result<&View> {
        self.views
            .get(index)
            .ok_or_else(|| Error::Graph(format!("view {index} is not in this frame")))
    }

    /// Adds a technique's prepared data (replacing any of the same type,
    /// in its box).
    pub fn insert<T: Any + Send + Sync>(&mut self, value: T) {
        match self.slot::<T>() {
            Some(slot) => *slot = Some(value),
            None => self.prepared.push((TypeId::of::<T>(), Box::new(Some(value)))),
        }
    }

    /// The box of `T`'s prepared data, if it has one.
    fn slot<T: Any + Send + Sync>(&mut self) -> Option<&mut Option<T>> {
        let id = TypeId::of::<T>();
        (self.prepared.iter_mut().find(|(t, _)| *t == id)).and_then(|(_, v)| v.downcast_mut::<Option<T>>())
    }

    /// The profile stage name of `technique`.
    fn stage_name(&mut self, technique: &'static str) -> Arc<str> {
        if let Some((_, name)) = self.stage_names.iter().find(|(t, _)| *t == technique) {
            return name.clone();
        }
        let name: Arc<str> = format!("prepare.{technique}").into();
        self.stage_names.push((technique, name.clone()));
        name
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
        let name = self.stage_name(technique.name());
        if let Some(previous) = self.slot::<T::Prepared>().and_then(Option::take) {
            technique.recycle(previous);
        }
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
        .and_then(|(_, v)| v.downcast_ref::<Option<T>>())
        .and_then(Option::as_ref)
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
    /// Takes back the previous frame's prepared data before
    /// [`Technique::prepare`], to reuse its memory (the frame path
    /// allocates nothing in steady state); by default it is dropped.
    fn recycle(&mut self, previous: Self::Prepared) {
        drop(previous);
    }
}
