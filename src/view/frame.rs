//! The frame: prepare, then record. Before a frame is recorded, every
//! technique's [`Technique::prepare`] does its CPU work (LOD, tile and point
//! planning) for the frame's views and returns its prepared data, which goes
//! into its typed slot of the [`Frame`]; the passes' recording closures then
//! only read it (`Fn`, no locks), in the manner of Granite's `refresh()`
//! before the graph runs and kajiya's renderers' prepare step.
//!
//! The slots are a plain struct the renderer defines ([`frame_slots!`]), one
//! `Option<T>` per technique's prepared type, with a [`Provides<T>`] impl
//! each: a pass body reads `frame.prepared::<T>()?` and compiles only where
//! its graph's frame provides `T` (no `TypeId`, no boxes). A technique that
//! reads another's prepared data says so in [`Technique::Needs`], and gets
//! it as an argument of its prepare: the renderer hands it the value the
//! other technique returned, so preparing them in the wrong order does not
//! compile.

use std::sync::Arc;

use super::{FrameLighting, View, ViewIndex};
use crate::error::{Error, Result};
use crate::graph::{CpuStage, RenderGraph, UploadWriter};
use crate::vulkan::Context;

/// A frame slot struct holds a `T` (one technique's prepared data): what
/// [`Frame::prepared`] reads. Implemented by [`frame_slots!`].
pub trait Provides<T> {
    /// The slot (None until prepared this frame).
    fn slot(&self) -> &Option<T>;
    fn slot_mut(&mut self) -> &mut Option<T>;
}

/// Defines a frame slot struct: one `Option` field per prepared type, and
/// its [`Provides`] impls. Each type appears once.
///
/// ```ignore
/// frame_slots! {
///     /// What the renderer's techniques prepare.
///     pub(crate) struct Slots { shadows: ShadowFrame, terrain: TerrainFrame }
/// }
/// ```
macro_rules! frame_slots {
    ($(#[$meta:meta])* $vis:vis struct $name:ident { $($field:ident: $ty:ty),* $(,)? }) => {
        $(#[$meta])*
        #[derive(Default)]
        $vis struct $name {
            $($field: Option<$ty>,)*
        }
        $(
            impl $crate::view::Provides<$ty> for $name {
                fn slot(&self) -> &Option<$ty> {
                    &self.$field
                }
                fn slot_mut(&mut self) -> &mut Option<$ty> {
                    &mut self.$field
                }
            }
        )*
    };
}
pub(crate) use frame_slots;

/// Everything a frame's passes read: its views, its lighting and each
/// technique's prepared data, in the slot struct `S`.
pub struct Frame<S> {
    /// Frame number (0, 1, 2, …).
    pub index: u64,
    pub views: Vec<View>,
    pub lighting: FrameLighting,
    /// Each technique's prepared data (None until prepared this frame).
    /// A frame is reused frame after frame ([`Frame::reset`]): each
    /// technique gets its previous frame's data back to reuse
    /// ([`Technique::recycle`]).
    slots: S,
    /// The profile stage name of each technique, made once.
    stage_names: Vec<(&'static str, Arc<str>)>,
}

impl<S: Default> Frame<S> {
    /// A frame of `views` with nothing prepared yet.
    pub fn new(index: u64, views: Vec<View>, lighting: FrameLighting) -> Frame<S> {
        Frame {
            index,
            views,
            lighting,
            slots: S::default(),
            stage_names: Vec::new(),
        }
    }
}

impl<S> Frame<S> {
    /// Starts frame `index` of the same views (update their cameras in
    /// [`Frame::views`]) with `lighting`: what was prepared becomes the
    /// previous frame's, handed back to each technique as it prepares.
    pub fn reset(&mut self, index: u64, lighting: FrameLighting) {
        self.index = index;
        self.lighting = lighting;
    }

    /// The view `index`.
    pub fn view(&self, index: ViewIndex) -> Result<&View> {
        self.views
            .get(index)
            .ok_or_else(|| Error::Graph(format!("view {index} is not in this frame")))
    }

    /// Puts a technique's prepared data into its slot (what
    /// [`Frame::prepare`] returned, once the techniques that need it have
    /// prepared).
    pub fn insert<T>(&mut self, value: T)
    where
        S: Provides<T>,
    {
        *self.slots.slot_mut() = Some(value);
    }

    /// The prepared data of type `T`.
    pub fn prepared<T>(&self) -> Result<&T>
    where
        S: Provides<T>,
    {
        self.slots.slot().as_ref().ok_or_else(|| {
            Error::Graph(format!(
                "{} was not prepared for this frame",
                std::any::type_name::<T>()
            ))
        })
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

    /// Runs `technique`'s prepare step with what it needs of the others
    /// as the profile stage `prepare.<name>` and returns its prepared data
    /// (hand it to the techniques that need it, then [`Frame::insert`] it).
    /// Its slot is emptied first (the previous frame's data goes back to
    /// the technique), so a pass never reads a previous frame's data.
    pub fn prepare<T: Technique>(
        &mut self,
        technique: &mut T,
        needs: T::Needs<'_>,
        uploads: &mut UploadWriter<'_>,
        stages: &mut Vec<CpuStage>,
    ) -> Result<T::Prepared>
    where
        S: Provides<T::Prepared>,
    {
        let name = self.stage_name(technique.name());
        if let Some(previous) = self.slots.slot_mut().take() {
            technique.recycle(previous);
        }
        CpuStage::time(stages, &name, || {
            let mut ctx = FrameContext {
                index: self.index,
                views: &self.views,
                lighting: &self.lighting,
                uploads,
            };
            technique.prepare(&mut ctx, needs)
        })
    }

    /// [`Frame::prepare`] of a technique that no other needs, into its slot.
    pub fn prepare_into<T: Technique>(
        &mut self,
        technique: &mut T,
        needs: T::Needs<'_>,
        uploads: &mut UploadWriter<'_>,
        stages: &mut Vec<CpuStage>,
    ) -> Result<()>
    where
        S: Provides<T::Prepared>,
    {
        let prepared = self.prepare(technique, needs, uploads, stages)?;
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
    pub lighting: &'a FrameLighting,
    pub uploads: &'a mut UploadWriter<'u>,
}

/// The entry of view `index` in a technique's per-view prepared data
/// (`view_of` reads an entry's view): at `items[index]` when the views
/// were declared in order, as the renderer declares them, else searched.
pub fn per_view<T>(items: &[T], index: ViewIndex, view_of: impl Fn(&T) -> ViewIndex) -> Option<&T> {
    match items.get(index) {
        Some(item) if view_of(item) == index => Some(item),
        _ => items.iter().find(|item| view_of(item) == index),
    }
}

/// A technique: persistent GPU state, passes declared once into the frame
/// graph ([`Declare`]), and a per-frame CPU step that prepares what those
/// passes read, from the frame and what it needs of the other techniques'
/// prepared data.
pub trait Technique {
    /// What the technique's passes read this frame.
    type Prepared: Send + Sync + 'static;
    /// What its prepare reads of other techniques' prepared data this
    /// frame (`()`: nothing), e.g. `&'a ShadowFrame`.
    type Needs<'a>;
    /// Short name; the profile stage is `prepare.<name>`.
    fn name(&self) -> &'static str;
    /// The CPU work of a frame, before recording: plans, uploads, statistics.
    fn prepare(&mut self, frame: &mut FrameContext<'_, '_>, needs: Self::Needs<'_>) -> Result<Self::Prepared>;
    /// Takes back the previous frame's prepared data before
    /// [`Technique::prepare`], to reuse its memory (the frame path
    /// allocates nothing in steady state); by default it is dropped.
    fn recycle(&mut self, previous: Self::Prepared) {
        drop(previous);
    }
}

/// Declaring a technique's passes of one view into the frame graph: what
/// they read that other techniques declared comes in (`Inputs`: the view's
/// targets, a shadow atlas), what they write that others read goes out
/// (`Outputs`). `S` is the frame's slot struct; an impl bounds it by the
/// prepared data its passes read (`S: Provides<TerrainFrame>`), so a graph
/// whose frame lacks it does not compile.
pub trait Declare<S> {
    type Inputs<'a>;
    type Outputs;
    /// Declares the passes of one view (`at`).
    fn declare(&mut self, at: ViewGraph<'_, S>, inputs: Self::Inputs<'_>) -> Result<Self::Outputs>;
}

/// Where [`Declare::declare`] declares: the device, the frame graph, and
/// the view (its index in the frame and its reading).
pub struct ViewGraph<'a, S> {
    pub ctx: &'a Context,
    pub graph: &'a mut RenderGraph<Frame<S>>,
    pub index: ViewIndex,
    pub view: &'a View,
}

impl<'a, S> ViewGraph<'a, S> {
    /// Declaring into `graph` for view `index` (`view`).
    pub fn new(ctx: &'a Context, graph: &'a mut RenderGraph<Frame<S>>, (index, view): (ViewIndex, &'a View)) -> Self {
        ViewGraph {
            ctx,
            graph,
            index,
            view,
        }
    }
}

/// Declares `technique`'s passes of every view, view `k` with the `k`-th
/// of `inputs`; returns each view's outputs.
pub fn declare_views<'a, S, T: Declare<S>>(
    technique: &mut T,
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    views: &[View],
    inputs: impl IntoIterator<Item = T::Inputs<'a>>,
) -> Result<Vec<T::Outputs>> {
    let mut inputs = inputs.into_iter();
    let mut outputs = Vec::with_capacity(views.len());
    for (k, view) in views.iter().enumerate() {
        let input = inputs
            .next()
            .ok_or_else(|| Error::Graph(format!("view {k} has no inputs to declare with")))?;
        outputs.push(technique.declare(ViewGraph::new(ctx, graph, (k, view)), input)?);
    }
    Ok(outputs)
}

#[cfg(test)]
mod tests {
    use super::*;

    frame_slots! {
        struct Slots {
            numbers: Vec<u32>,
            name: String,
        }
    }

    #[test]
    fn slots_hold_what_was_inserted_and_nothing_else() {
        let mut frame = Frame::<Slots>::new(0, Vec::new(), FrameLighting::default());
        let missing = frame.prepared::<String>().expect_err("nothing prepared");
        assert!(missing.to_string().contains("String was not prepared"), "{missing}");
        frame.insert(vec![1u32, 2]);
        assert_eq!(frame.prepared::<Vec<u32>>().expect("numbers"), &[1, 2]);
        assert!(frame.prepared::<String>().is_err());
    }

    #[test]
    fn per_view_data_is_found_in_or_out_of_order() {
        let in_order = [(0, 'a'), (1, 'b')];
        assert_eq!(per_view(&in_order, 1, |e| e.0), Some(&(1, 'b')));
        let shuffled = [(1, 'b'), (0, 'a')];
        assert_eq!(per_view(&shuffled, 0, |e| e.0), Some(&(0, 'a')));
        assert_eq!(per_view(&shuffled, 2, |e| e.0), None);
    }
}
