//! What the compute path's deferred shading hands between techniques
//! (issues 28 and 29): the ground's per-pixel visibility keys, which the
//! points' compute passes test their splats against instead of a depth
//! buffer, and the points' per-pixel sums, which the frame's shading pass
//! (`terrain.shade`) normalizes and shades with the ground in one pass over
//! the pixels (§10.2.3 pass 3 fused into the deferred shading). Shared
//! types below the techniques, so neither technique imports the other.

use crate::graph::{BufferId, UploadRegion};

/// A view's ground visibility buffer: one 64-bit key a pixel, the view
/// depth's float bits in the high word (all ones: nothing drawn), as
/// `glsl/include/terrain_visibility.glsl` writes it. Filled by the
/// ground's raster passes before the points' passes read it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GroundKeys(pub BufferId);

/// A view's splat sums on the compute path
/// (`glsl/include/splat_compute_state.glsl`), accumulated and not yet
/// normalized: the frame's shading pass resolves them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SplatSums {
    /// The nearest words (depth bits << 32 | instance record + 1).
    pub nearest: BufferId,
    /// Eight fixed-point sums a pixel.
    pub sums: BufferId,
    /// The last instance record + 1 accumulated a pixel.
    pub last: BufferId,
    /// The view's point frame (splat.glsl's `PointFrame`), its header
    /// written, read as storage.
    pub frame: UploadRegion,
}
