//! Memory aliasing of transient images: images whose uses within a frame do
//! not overlap share one [`MemoryBlock`](crate::vulkan::MemoryBlock).
//!
//! Baking assigns each live transient image the interval of pass indices in
//! which it is used and packs the intervals greedily into slots (first fit, by
//! first use). At execution, a slot remembers which image last occupied its
//! memory and every stage and write that touched it since; the first use of
//! another image waits for all of them and starts from `UNDEFINED` (its
//! contents are gone), which also covers the hand-over from one frame to the
//! next.

use crate::vulkan::{AccessFlags2, AccessState, ImageLayout, PipelineStageFlags2};

/// Packs `[first, last]` pass intervals into slots; returns the slot of each
/// interval. Intervals in one slot never overlap.
pub fn assign_slots(intervals: &[(usize, usize)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..intervals.len()).collect();
    order.sort_by_key(|&i| (intervals[i].0, intervals[i].1, i));
    let mut slot_end: Vec<usize> = Vec::new();
    let mut slot_of = vec![0; intervals.len()];
    for i in order {
        let (first, last) = intervals[i];
        match slot_end.iter().position(|&end| end < first) {
            Some(s) => {
                slot_end[s] = last;
                slot_of[i] = s;
            }
            None => {
                slot_end.push(last);
                slot_of[i] = slot_end.len() - 1;
            }
        }
    }
    slot_of
}

/// What happened to a slot's memory since its current image took it over.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct AliasSlot {
    pub owner: Option<usize>,
    pub stages: PipelineStageFlags2,
    pub writes: AccessFlags2,
}

impl AliasSlot {
    /// The state `resource` starts from when it uses the slot next: the
    /// resource's own state while it still owns the memory, otherwise "written
    /// by everything that touched the memory", with undefined contents.
    pub fn state_for(&self, resource: usize, own: AccessState) -> AccessState {
        if self.owner == Some(resource) {
            own
        } else {
            AccessState::written(self.stages, self.writes, ImageLayout::UNDEFINED)
        }
    }

    /// Records that `resource` accessed the memory at `stages` (writing `writes`).
    pub fn record(&mut self, resource: usize, stages: PipelineStageFlags2, writes: AccessFlags2) {
        if self.owner != Some(resource) {
            *self = AliasSlot {
                owner: Some(resource),
                stages: PipelineStageFlags2::NONE,
                writes: AccessFlags2::NONE,
            };
        }
        self.stages |= stages;
        self.writes |= writes;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::{derive_barrier, Access, Stage};

    #[test]
    fn disjoint_intervals_share_a_slot_and_overlapping_ones_do_not() {
        // hdr [0,4], view depth [0,4], depth [2,2], srgb [3,4]
        let slots = assign_slots(&[(0, 4), (0, 4), (2, 2), (3, 4)]);
        assert_ne!(slots[0], slots[1]);
        assert_eq!(slots[2], slots[3], "depth (pass 2) and srgb (passes 3-4) can alias");
        assert_ne!(slots[0], slots[2]);
        assert_eq!(
            assign_slots(&[(0, 1), (1, 2)]),
            vec![0, 1],
            "touching intervals overlap"
        );
    }

    #[test]
    fn hand_over_waits_for_the_previous_image_and_discards() {
        let mut slot = AliasSlot::default();
        let (stages, access, _) = Access::DepthAttachmentWrite.state();
        slot.record(0, stages, access);
        let mut state = slot.state_for(1, AccessState::UNUSED);
        let b = derive_barrier(&mut state, Access::StorageImageWrite(Stage::Compute), true).expect("WAW on memory");
        assert!(b.src_stages.contains(PipelineStageFlags2::LATE_FRAGMENT_TESTS));
        assert!(b.src_access.contains(AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE));
        assert_eq!(b.old_layout, ImageLayout::UNDEFINED);
        assert_eq!(b.new_layout, ImageLayout::GENERAL);
        slot.record(1, b.dst_stages, b.dst_access);
        assert_eq!(slot.owner, Some(1));
        assert_eq!(slot.stages, PipelineStageFlags2::COMPUTE_SHADER);
    }
}
