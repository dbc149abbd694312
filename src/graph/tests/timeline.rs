//! One timeline (issue 30): with calibrated timestamps every GPU pass of a
//! frame lies, on the CPU clock, between the frame's submit and the return
//! of its fence wait, as the Perfetto trace shows it.

use crate::graph::{BufferAccess, BufferInfo, RenderGraph};
use crate::profile::{chrome_trace, gpu_spans_outside_frames};
use crate::test_support::{assert_validation_clean, transfer_buffer, validated_context};
use crate::vulkan::{FrameRing, MemoryLocation};

const SIZE: u64 = 4 << 20;

#[test]
fn calibrated_gpu_passes_lie_between_submit_and_fence_wait() {
    let (ctx, report) = validated_context();
    let calibrated = ctx.info().calibrated_timestamps;
    if cfg!(target_os = "linux") && ctx.info().name.contains("llvmpipe") {
        assert!(
            calibrated,
            "lavapipe offers VK_EXT_calibrated_timestamps with CLOCK_MONOTONIC"
        );
    }
    let trace = {
        let mut graph: RenderGraph<()> = RenderGraph::new();
        let target = transfer_buffer(&ctx, "result", SIZE, MemoryLocation::GpuOnly);
        let info = || BufferInfo {
            size: SIZE,
            location: MemoryLocation::GpuOnly,
        };
        let (a, b) = (graph.create_buffer("a", info()), graph.create_buffer("b", info()));
        let c = graph.create_buffer("c", info());
        let result = graph.import_buffer(target);
        let copy = move |graph: &mut RenderGraph<()>, name: &str, src, dst| {
            graph
                .pass(name)
                .transfer()
                .read(src, BufferAccess::TransferSrc)
                .write(dst, BufferAccess::TransferDst)
                .record(move |pass, _| {
                    let (s, d) = (pass.buffer(src)?, pass.buffer(dst)?);
                    pass.cmd().copy_buffer(s, d, SIZE);
                    Ok(())
                });
        };
        copy(&mut graph, "copy a-b", a, b);
        copy(&mut graph, "copy b-c", b, c);
        copy(&mut graph, "copy c-result", c, result);
        graph.read_back(result);
        let mut baked = graph.bake(&ctx).expect("bake");
        // Pipeline statistics around every pass (copies count nothing).
        let stats = ctx.has_feature("pipelineStatisticsQuery");
        baked.set_pipeline_stats(&ctx, stats).unwrap();
        let mut frames = FrameRing::new(&ctx).unwrap();
        for _ in 0..6 {
            frames.wait_for_next().unwrap();
            baked.execute(&mut frames, &(), &[]).unwrap();
        }
        baked.finish(&mut frames).unwrap();
        let profiles = baked.take_profiles();
        assert_eq!(profiles.len(), 6);
        for p in &profiles {
            assert!(p.submit_ms >= p.cpu_start_ms && p.fence_ms >= p.submit_ms, "{p:?}");
            assert_eq!(p.gpu_start_on_cpu_ms.is_some(), calibrated, "{p:?}");
            let counted = p.passes.iter().filter(|pass| pass.pipeline_stats.is_some()).count();
            assert_eq!(counted, if stats { 3 } else { 0 }, "{p:?}");
        }
        chrome_trace(&ctx.info().name, &profiles).unwrap()
    };
    drop(ctx);
    assert_validation_clean(&report);
    match calibrated {
        true => assert_eq!(gpu_spans_outside_frames(&trace).unwrap(), Vec::<String>::new()),
        false => assert!(
            gpu_spans_outside_frames(&trace).is_err(),
            "an uncalibrated trace is not checked"
        ),
    }
}
