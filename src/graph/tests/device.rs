//! The render graph and the descriptor heap on a real device under
//! validation and synchronization validation (moved from
//! `tests/vulkan_renderer.rs` in issue 26): pass culling, a storage buffer
//! written by one pass and copied by the next, heap handle reuse.

use crate::graph::{BufferAccess, BufferInfo, ImageAccess, ImageInfo, RenderGraph, Stage};
use crate::test_support::{assert_validation_clean, transfer_buffer, validated_context};
use crate::vulkan::{Buffer, BufferDesc, BufferUsageFlags, Format, FrameRing, MemoryLocation};

#[test]
fn graph_culls_unused_passes_and_writes_a_storage_buffer_drawn_by_the_next_pass() {
    let (ctx, report) = validated_context();
    {
        let mut graph: RenderGraph<()> = RenderGraph::new();
        let target = transfer_buffer(&ctx, "result", 256, MemoryLocation::GpuToCpu);
        let scratch = graph.create_buffer(
            "scratch",
            BufferInfo {
                size: 256,
                location: MemoryLocation::GpuOnly,
            },
        );
        let unused = graph.create_image("unused", ImageInfo::new(8, 8, Format::R8G8B8A8_UNORM));
        let result = graph.import_buffer(target.clone());
        graph
            .pass("never used")
            .read(scratch, BufferAccess::StorageRead(Stage::Compute))
            .write(unused, ImageAccess::StorageWrite(Stage::Compute))
            .record(|_, _| panic!("a culled pass must not record"));
        graph
            .pass("copy")
            .transfer()
            .read(scratch, BufferAccess::TransferSrc)
            .write(result, BufferAccess::TransferDst)
            .record(move |pass, _| {
                let (src, dst) = (pass.buffer(scratch)?, pass.buffer(result)?);
                pass.cmd().copy_buffer(src, dst, 256);
                Ok(())
            });
        graph.read_back(result);
        let mut baked = graph.bake(&ctx).expect("bake");
        assert_eq!(baked.pass_names(), ["copy"]);
        assert_eq!(baked.culled_passes(), ["never used"]);
        assert!(baked.image(unused).is_none(), "a culled transient is not created");
        let mut frames = FrameRing::new(&ctx).unwrap();
        for _ in 0..3 {
            baked.execute(&mut frames, &(), &[]).unwrap();
        }
        baked.finish(&mut frames).unwrap();
        assert_eq!(baked.take_profiles().len(), 3);
    }
    drop(ctx);
    assert_validation_clean(&report);
}

#[test]
fn heap_handles_are_reused_only_after_the_gpu_is_done() {
    let (ctx, report) = validated_context();
    {
        let storage = |name: &str| {
            Buffer::new(
                &ctx,
                BufferDesc {
                    name: name.into(),
                    size: 64,
                    usage: BufferUsageFlags::STORAGE_BUFFER,
                    location: MemoryLocation::GpuOnly,
                },
            )
            .unwrap()
        };
        let first = storage("first");
        let handle = first.storage_handle().expect("storage buffers get a heap handle");
        drop(first);
        let second = storage("second");
        assert_ne!(
            second.storage_handle(),
            Some(handle),
            "released handle reused before the GPU finished"
        );
        ctx.wait_idle().unwrap();
        let third = storage("third");
        assert_eq!(
            third.storage_handle(),
            Some(handle),
            "released handle recycled once the GPU is done"
        );
    }
    drop(ctx);
    assert_validation_clean(&report);
}

/// A simulator hands the renderer, and with it the baked graph, to its
/// render thread: `BakedGraph<Frame>` is `Send` (a compile-time check; split
/// from `renderer_is_send` in `tests/vulkan_renderer.rs`).
#[test]
fn baked_graph_is_send() {
    fn assert_send<T: Send>() {}
    assert_send::<crate::graph::BakedGraph<crate::renderer::RenderFrame>>();
}
