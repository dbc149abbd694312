//! Bindings come from declarations (issue 27): a pass reaches the heap only
//! through the bindings it declared, the images and buffers it declared,
//! and renders only into the attachments it declared, whose formats must
//! match its pipeline's. On a validated device.

use std::path::Path;
use std::sync::{Arc, Mutex};

use crate::graph::{BufferInfo, ImageAccess, ImageInfo, LoadOp, RenderGraph, Stage};
use crate::shaders;
use crate::test_support::{assert_validation_clean, validated_context};
use crate::vulkan::{Format, FrameRing, GraphicsPipeline, GraphicsPipelineDesc, MemoryLocation};

/// A depth-only pipeline (an empty fragment shader) into `D32_SFLOAT`.
fn depth_only(ctx: &crate::vulkan::Context) -> GraphicsPipeline {
    let mut desc = GraphicsPipelineDesc::full_screen(
        "depth only",
        (shaders::FULL_SCREEN_VERT, shaders::SHADOW_DEPTH_FRAG),
        Vec::new(),
    );
    desc.depth_format = Some(Format::D32_SFLOAT);
    (desc.depth_test, desc.depth_write) = (true, true);
    GraphicsPipeline::new(ctx, &desc).unwrap()
}

/// What each pass's closure saw, for the assertions after the frame.
type Seen = Arc<Mutex<Vec<String>>>;

#[test]
fn a_pass_reaches_only_what_it_declared() {
    let (ctx, report) = validated_context();
    {
        let seen: Seen = Arc::default();
        let mut graph: RenderGraph<()> = RenderGraph::new();
        let declared = graph.create_image("declared", ImageInfo::new(8, 8, Format::R8G8B8A8_UNORM));
        let undeclared = graph.create_buffer(
            "undeclared",
            BufferInfo {
                size: 64,
                location: MemoryLocation::GpuOnly,
            },
        );
        let region = graph.upload_region("constants", 16);
        let mut first = graph.pass("first");
        let image = first.storage_image(declared, ImageAccess::StorageWrite(Stage::Compute));
        let constants = first.upload(region, Stage::Compute);
        let log = seen.clone();
        first.record(move |pass, _| {
            let mut log = log.lock().unwrap();
            log.push(format!("image handle ok: {}", pass.handle(image).is_ok()));
            log.push(format!("upload handle ok: {}", pass.handle(constants).is_ok()));
            log.push(format!(
                "upload written: {}",
                pass.write_upload(constants, &[1; 16]).is_ok()
            ));
            log.push(format!(
                "too much written: {}",
                pass.write_upload(constants, &[1; 17]).is_ok()
            ));
            log.push(format!("undeclared buffer: {}", pass.buffer(undeclared).is_ok()));
            Ok(())
        });
        let out = graph.create_image("out", ImageInfo::new(8, 8, Format::R8G8B8A8_UNORM));
        let mut second = graph.pass("second");
        let own = second.sample(declared, Stage::Compute);
        second.storage_image(out, ImageAccess::StorageWrite(Stage::Compute));
        let log = seen.clone();
        second.record(move |pass, _| {
            let mut log = log.lock().unwrap();
            log.push(format!("own binding: {}", pass.handle(own).is_ok()));
            let foreign = pass.handle(image);
            log.push(format!("first's binding: {}", foreign.is_ok()));
            if let Err(e) = foreign {
                log.push(e.to_string());
            }
            log.push(format!(
                "first's upload: {}",
                pass.write_upload(constants, &[0; 4]).is_ok()
            ));
            Ok(())
        });
        graph.keep(declared);
        graph.keep(out);
        let mut baked = graph.bake(&ctx).expect("bake");
        let mut frames = FrameRing::new(&ctx).unwrap();
        baked.execute(&mut frames, &(), &[]).unwrap();
        baked.finish(&mut frames).unwrap();
        let seen = seen.lock().unwrap().clone();
        assert_eq!(
            seen[..8],
            [
                "image handle ok: true",
                "upload handle ok: true",
                "upload written: true",
                "too much written: false",
                "undeclared buffer: false",
                "own binding: true",
                "first's binding: false",
                "render graph: pass 'second' was handed a binding another pass declared",
            ]
        );
        assert_eq!(seen[8], "first's upload: false");
    }
    drop(ctx);
    assert_validation_clean(&report);
}

#[test]
fn a_binding_of_another_graph_is_refused() {
    let (ctx, report) = validated_context();
    {
        let mut other: RenderGraph<()> = RenderGraph::new();
        let image = other.create_image("other", ImageInfo::new(4, 4, Format::R8G8B8A8_UNORM));
        let mut pass = other.pass("other");
        let foreign = pass.sample(image, Stage::Compute);
        pass.record(|_, _| Ok(()));
        let mut graph: RenderGraph<()> = RenderGraph::new();
        let target = graph.create_image("target", ImageInfo::new(4, 4, Format::R8G8B8A8_UNORM));
        let mut pass = graph.pass("mine");
        pass.storage_image(target, ImageAccess::StorageWrite(Stage::Compute));
        pass.record(move |pass, _| pass.handle(foreign).map(drop));
        graph.keep(target);
        let mut baked = graph.bake(&ctx).expect("bake");
        let mut frames = FrameRing::new(&ctx).unwrap();
        let error = baked.execute(&mut frames, &(), &[]).unwrap_err().to_string();
        assert!(error.contains("another pass"), "{error}");
        baked.finish(&mut frames).unwrap();
    }
    drop(ctx);
    assert_validation_clean(&report);
}

#[test]
fn attachments_must_match_the_pipeline_formats_at_bake() {
    let (ctx, report) = validated_context();
    {
        let pipeline = depth_only(&ctx);
        let bake = |format: Format, with_pipeline: bool| {
            let mut graph: RenderGraph<()> = RenderGraph::new();
            let target = graph.create_image("target", ImageInfo::new(8, 8, format));
            let mut pass = graph.pass("draw").graphics();
            if with_pipeline {
                pass = pass.pipeline(&pipeline);
            }
            pass.depth(target, Some(1.0)).record(|_, _| Ok(()));
            graph.keep(target);
            graph.bake(&ctx).map(drop).map_err(|e| e.to_string())
        };
        assert_eq!(bake(Format::D32_SFLOAT, true), Ok(()));
        let wrong = bake(Format::D16_UNORM, true).unwrap_err();
        assert!(
            wrong.contains("pipeline 'depth only'") && wrong.contains("D16_UNORM"),
            "{wrong}"
        );
        let unnamed = bake(Format::D32_SFLOAT, false).unwrap_err();
        assert!(unnamed.contains("no pipeline"), "{unnamed}");
        let mut graph: RenderGraph<()> = RenderGraph::new();
        let target = graph.create_image("target", ImageInfo::new(8, 8, Format::R8G8B8A8_UNORM));
        graph
            .pass("compute")
            .pipeline(&pipeline)
            .color(target, LoadOp::DontCare)
            .record(|_, _| Ok(()));
        graph.keep(target);
        let compute = graph.bake(&ctx).map(drop).unwrap_err().to_string();
        assert!(compute.contains("not a graphics pass"), "{compute}");
    }
    drop(ctx);
    assert_validation_clean(&report);
}

#[test]
fn the_graph_begins_and_ends_rendering_into_declared_attachments() {
    let (ctx, report) = validated_context();
    {
        let pipeline = Arc::new(depth_only(&ctx));
        let drawing = pipeline.clone();
        let mut graph: RenderGraph<()> = RenderGraph::new();
        let depth = graph.create_image("depth", ImageInfo::new(8, 8, Format::D32_SFLOAT));
        let drawn = Arc::new(Mutex::new(0));
        let count = drawn.clone();
        // Cleared by the graph's begin_rendering; the closure only draws.
        (graph.pass("draw").graphics().pipeline(&pipeline))
            .depth(depth, Some(0.5))
            .record(move |pass, _| {
                *count.lock().unwrap() += 1;
                pass.draw_full_screen(&drawing, &[0u32; 4])
            });
        graph.keep(depth);
        let mut baked = graph.bake(&ctx).expect("bake");
        let mut frames = FrameRing::new(&ctx).unwrap();
        for _ in 0..2 {
            baked.execute(&mut frames, &(), &[]).unwrap();
        }
        baked.finish(&mut frames).unwrap();
        assert_eq!(baked.pass_names(), ["draw"]);
        assert_eq!(*drawn.lock().unwrap(), 2);
    }
    drop(ctx);
    assert_validation_clean(&report);
}

/// No heap handle is fetched outside `vulkan/` and `graph/`: the raw
/// getters (`sampled_handle`, `storage_handle`, `range_handle`, an upload
/// writer's `handle`) appear nowhere else in the crate's sources.
#[test]
fn no_raw_heap_handle_outside_vulkan_and_graph() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut offenders = Vec::new();
    let mut stack = vec![src.clone()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let relative = path.strip_prefix(&src).unwrap().to_string_lossy().replace('\\', "/");
            if relative.starts_with("vulkan") || relative.starts_with("graph") {
                continue;
            }
            if path.is_dir() {
                stack.push(path);
            } else if relative.ends_with(".rs") {
                let text = std::fs::read_to_string(&path).unwrap();
                for (n, line) in text.lines().enumerate() {
                    let code = line.split("//").next().unwrap_or("");
                    let raw = ["sampled_handle(", "storage_handle(", "range_handle(", "uploads.handle("];
                    if raw.iter().any(|r| code.contains(r)) {
                        offenders.push(format!("src/{relative}:{}: {}", n + 1, line.trim()));
                    }
                }
            }
        }
    }
    assert!(
        offenders.is_empty(),
        "heap handles fetched outside vulkan/ and graph/ (declare a Binding instead):\n{}",
        offenders.join("\n")
    );
}
