//! Single-pass EWA splatting with a fuzzy depth test (dissertation §10.4;
//! `ALGORITHMS.md` §8) as render-graph passes. Each splat fragment
//! (C_s, A_s, z_s) meets the pixel's stored (C_d, A_d, z_d): nearer than
//! z_d − z_f it replaces them, within ±z_f it blends by weight
//! (C_d = (A_d·C_d + A_s·C_s)/(A_d + A_s), A_d += A_s, z_d kept), farther it
//! is dropped. The kernels, clip lines and ray–plane depth are the
//! three-pass mode's (`glsl/include/splat_setup.glsl`), and pixels are
//! shaded exactly as by `points.normalize` (`glsl/include/splat_resolve.glsl`),
//! so the outputs are the same in kind: radiance, view depth, W,
//! visibility, world normal and ids.
//!
//! z is the distance along the view ray and z_f = ε·r_k with r_k the
//! incoming splat's radius in camera units and ε
//! [`super::SplatSettings::visibility_offset`]: the three-pass visibility
//! pass's push-back (§10.2.3), derived from the splat size, the same for
//! every scene.
//!
//! The operator is not commutative: the result depends on the order in
//! which a pixel's fragments arrive. Both backends fix that order:
//!
//! Passes of a view, compute backend ([`SplatBackend::Compute`], [`tiles`]):
//! the splats set up once and binned into 8×8-pixel screen tiles, the tile
//! entries sorted by (tile, reach) with a GPU radix sort, and each tile's
//! slice merged front to back (the tile order of 3D Gaussian splatting's
//! renderer, with §10.4's operator), deterministic and lock-free, one
//! dispatch chain with no CPU round trip. A splat's reach is a lower bound
//! of the depth of its samples less its z_f: a pixel whose z_d is at most
//! the reach of the next entry keeps its state to the end of the list (the
//! operator drops every later fragment), so the walk stops there.
//! 1. `points.single_pass.triangles` (only with hybrid triangles, §10.1.8):
//!    the triangles opaque and shaded, with depth, so splats test against them;
//! 2. `points.single_pass.clear`: every tile's cut mark, the sort state
//!    and every tile's range 0;
//! 3. `points.single_pass.count`: a dispatch per planned draw, one
//!    invocation per splat: the EWA set-up, kept with its pixels and reach
//!    in the splat's slot for the later passes, the frame's reach range,
//!    each workgroup's entries (the tiles its splats' boxes touch; and the
//!    interval-passed and drawn splats counted);
//! 4. `points.single_pass.prefix`: one workgroup: each binning workgroup's
//!    first entry (an exclusive prefix in draw order), the frame's entries
//!    and the key's layout: the tile index in the high bits, the reach's
//!    float bits less the frame's least below, shifted to fit;
//! 5. `points.single_pass.scatter`: the same dispatches again, each kept
//!    splat's entries (key, slot, the tile's 4×2-pixel blocks its bounding
//!    box touches) written at positions fixed by the draws' order, none
//!    past the entry buffer's capacity (their tiles marked cut, counted);
//! 6. `points.single_pass.radix_serial{k}.{count,scan,starts,scatter}` or
//!    `points.single_pass.radix_runs{k}.{count,scan,scatter}` ([`radix`]):
//!    a stable LSD radix sort of the keys (the tile index and at least 12
//!    bits of reach); on a CPU device digits of up to 12 bits (two passes
//!    at 512²), one invocation per block of entries counting and
//!    scattering its own row, elsewhere 8-bit digits, a workgroup per
//!    block ranking runs of entries in shared counters; the same sorted
//!    entries either way: equal keys keep draw order, so they are the same
//!    on every run and device;
//! 7. `points.single_pass.ranges`: each tile's slice of the sorted entries
//!    (where its tile index starts and ends) into its range words;
//! 8. `points.single_pass.merge`: one workgroup per tile reads its slice of
//!    the sorted entries (a cut list is dropped whole and
//!    counted, [`super::PointFrameStats::tile_entries_dropped`]); each
//!    subgroup (a 4×2-pixel block on a CPU driver's 8-wide rows) walks it
//!    straight from memory, without shared memory or barriers, in runs of
//!    one entry per invocation whose ballots give the entries touching its
//!    blocks, up to the first whose reach is at least every pixel's z_d:
//!    every pixel applies the operator to those splats in order, in
//!    registers, then is normalised, shaded and written once.
//!
//! Interlock backend ([`SplatBackend::Interlock`], [`interlock`]):
//! `points.single_pass.triangles` as above, `points.single_pass.clear`
//! (every pixel's state: z_d = +inf, no sums), `points.single_pass` (the
//! splats as quads whose fragments merge inside a pixel-ordered critical
//! section: primitive order), `points.single_pass.resolve` (compute, per
//! pixel: divide and shade).

mod interlock;
mod radix;
mod tiles;

use bytemuck::{Pod, Zeroable};

#[cfg(test)]
pub(crate) use radix::{with_radix_sort, RadixSort};
#[cfg(test)]
pub(crate) use tiles::with_entry_capacity;
pub(super) use tiles::{entry_capacity, TileCapacity};

use super::passes::{declare_opaque, PointBuffers, PointView, ResolvedTargets, SplatPush};
use super::{PointsFrame, SplatBackend, SplatPrimitive};
use crate::error::{Error, Result};
use crate::graph::{Binding, BufferAccess, BufferId, PassContext, RenderGraph, Stage};
use crate::view::{Frame, Provides, SceneTargets};
use crate::vulkan::{ComputePipeline, Context};

/// Invocations per workgroup of the per-splat compute passes.
const WORKGROUP_SIZE: u32 = 64;
/// Most workgroups per dispatch row (the guaranteed `maxComputeWorkGroupCount`).
const MAX_GROUPS_X: u32 = 65535;

/// Push constants of the per-splat passes (`Push` in glsl/include/splat.glsl
/// with `SPLAT_SINGLE_PASS`): the splat passes' block, then `single`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct SinglePassPush {
    splat: SplatPush,
    /// What the backend's shaders read (their `pc.single`).
    single: [u32; 4],
}

/// The `outputs` and `more` push constants of the passes that resolve
/// splats (`Push` in glsl/include/splat.glsl with `SPLAT_RESOLVE_COMPUTE`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ResolvedPush {
    /// Storage: radiance, view depth, W, lighting AOVs.
    outputs: [u32; 4],
    /// Storage: normal, ids; width, height.
    more: [u32; 4],
}

impl ResolvedPush {
    /// The handles of `targets` in `pass`.
    fn of(targets: &ResolvedTargets, pass: &PassContext<'_>) -> Result<ResolvedPush> {
        let (outputs, more) = targets.push(pass)?;
        Ok(ResolvedPush { outputs, more })
    }
}

/// Runs `f` with this thread's test override `key` set to `value`, then
/// clears it (what the buffers and sorts of the views `f` declares take).
#[cfg(test)]
fn with_override<T: Copy + 'static, R>(
    key: &'static std::thread::LocalKey<std::cell::Cell<Option<T>>>,
    value: T,
    f: impl FnOnce() -> R,
) -> R {
    key.with(|c| c.set(Some(value)));
    let result = f();
    key.with(|c| c.set(None));
    result
}

/// Workgroups for `n` invocations of [`WORKGROUP_SIZE`]: (per row, rows).
fn workgroups(n: u32) -> (u32, u32) {
    let groups = n.div_ceil(WORKGROUP_SIZE);
    let rows = groups.div_ceil(MAX_GROUPS_X).max(1);
    (groups.div_ceil(rows), rows)
}

/// A compute pass `name` that clears `buffers` (their previous contents not
/// needed) with one invocation per item of `items`: its push constants are
/// the buffers' handles, then `items`, padded to four words.
fn declare_clear<S: Provides<PointsFrame> + 'static>(
    graph: &mut RenderGraph<Frame<S>>,
    name: &str,
    (buffers, items): (&[BufferId], u32),
    pipeline: ComputePipeline,
) {
    let mut pass = graph.pass(name);
    let bindings: Vec<Binding> = (buffers.iter())
        .map(|b| pass.storage_buffer(*b, BufferAccess::StorageWrite(Stage::Compute)))
        .collect();
    pass.record(move |ctx, _| {
        let mut push = [0; 4];
        for (word, binding) in push.iter_mut().zip(&bindings) {
            *word = ctx.handle(*binding)?;
        }
        push[bindings.len()] = items;
        let (x, y) = workgroups(items);
        ctx.dispatch(&pipeline, &push, [x, y, 1])
    });
}

/// Fails with a one-line error when the device cannot run `backend`.
pub(super) fn check_backend(ctx: &Context, backend: SplatBackend) -> Result<()> {
    if backend == SplatBackend::Compute {
        let feature = crate::vulkan::SUBGROUP_COMPUTE;
        return match ctx.has_feature(feature) {
            true => Ok(()),
            false => Err(Error::invalid(
                "splat backend compute",
                format!(
                    "the device ({}) lacks {feature} (subgroup vote, arithmetic and ballot operations in compute shaders); use --splat ewa (three passes)",
                    ctx.info().name
                ),
            )),
        };
    }
    let missing: Vec<&str> = [
        (
            "fragmentShaderPixelInterlock (VK_EXT_fragment_shader_interlock)",
            "fragmentShaderPixelInterlock",
        ),
        ("fragmentStoresAndAtomics", "fragmentStoresAndAtomics"),
    ]
    .into_iter()
    .filter(|(_, feature)| !ctx.has_feature(feature))
    .map(|(named, _)| named)
    .collect();
    match missing.is_empty() {
        true => Ok(()),
        false => Err(Error::invalid(
            "splat backend interlock",
            format!(
                "the device ({}) lacks {}; use the compute backend",
                ctx.info().name,
                missing.join(" and ")
            ),
        )),
    }
}

/// What the splat passes of a view test against and keep: whether the
/// depth buffer and W were written before them (terrain, hybrid triangles).
#[derive(Clone, Copy, Debug)]
struct Written {
    depth: bool,
    weight: bool,
}

/// What a backend declares its passes of one view with: `name` gives a
/// pass's name for the view.
#[derive(Clone, Copy)]
struct ViewPasses<'a> {
    name: &'a dyn Fn(&str) -> String,
    buffers: PointBuffers,
    view: PointView,
    targets: &'a SceneTargets,
    written: Written,
}

/// The passes of single-pass splatting of one view (see the module's
/// list); `name` gives a pass's name for the view; `capacity`: what the
/// compute backend's buffers are sized for ([`entry_capacity`] entries).
pub(super) fn declare_single_pass<S: Provides<PointsFrame> + 'static>(
    ctx: &Context,
    graph: &mut RenderGraph<Frame<S>>,
    name: &dyn Fn(&str) -> String,
    (buffers, view): (PointBuffers, PointView),
    targets: &SceneTargets,
    (backend, capacity): (SplatBackend, TileCapacity),
) -> Result<()> {
    check_backend(ctx, backend)?;
    // Hybrid triangles (§10.1.8) as opaque shaded triangles with depth, W = 1,
    // before the splats test against them.
    let written = match buffers.triangles {
        Some(_) => {
            let triangles_only = PointBuffers {
                primitive: SplatPrimitive::Quad,
                ..buffers
            };
            let name = name("points.single_pass.triangles");
            declare_opaque(ctx, graph, &name, (triangles_only, view), targets, false)?;
            Written {
                depth: true,
                weight: true,
            }
        }
        None => Written {
            depth: !view.clear_depth,
            weight: false,
        },
    };
    let at = ViewPasses {
        name,
        buffers,
        view,
        targets,
        written,
    };
    match backend {
        SplatBackend::Compute => tiles::declare(ctx, graph, at, capacity),
        SplatBackend::Interlock => interlock::declare(ctx, graph, at),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn workgroups_cover_every_invocation_within_the_limit() {
        for n in [0, 1, 64, 65, 100_000, 64 * 65535, 64 * 65535 + 1, 50_000_000] {
            let (x, y) = workgroups(n);
            assert!(x <= MAX_GROUPS_X && y >= 1, "{n}: {x}×{y}");
            assert!(u64::from(x) * u64::from(y) * 64 >= u64::from(n), "{n}: {x}×{y}");
        }
    }

    #[test]
    fn push_constants_match_the_shader_block() {
        // handles, mode (SplatPush), single: 48 bytes.
        assert_eq!(std::mem::size_of::<SinglePassPush>(), 48);
    }
}
