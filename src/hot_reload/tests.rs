//! Hot reload on a copy of `glsl/`: the tone mapper changed to write a
//! constant colour reaches the renderers built afterwards; a syntax error
//! is one line naming file and line, and the last good module stays.

use std::fs;
use std::path::{Path, PathBuf};

use glam::DVec2;

use super::ShaderWatcher;
use crate::renderer::{RenderSettings, Renderer, Scene};
use crate::terrain::procedural::ProceduralTerrain;
use crate::test_support::{assert_validation_clean, target_tmp, validated_context};
use crate::vulkan::Context;

const WIDTH: u32 = 64;
const HEIGHT: u32 = 40;
/// What the changed tone mapper writes everywhere.
const MAGENTA: [u8; 3] = [255, 0, 255];
const TONEMAP: &str = "post/tonemap.comp";
/// The tone mapper's store, which the test replaces.
const STORE: &str = "vec4(ldr, clamp(hdr.a, 0.0, 1.0))";

/// Copies the tree `from` into `to`.
fn copy_tree(from: &Path, to: &Path) {
    fs::create_dir_all(to).expect("a scratch glsl/");
    for entry in fs::read_dir(from).expect("glsl/") {
        let entry = entry.expect("an entry");
        let target = to.join(entry.file_name());
        if entry.file_type().expect("a type").is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            fs::copy(entry.path(), target).expect("a copy");
        }
    }
}

/// The rgb of every pixel of a frame of `scene`.
fn render(ctx: &Context, scene: &Scene) -> Vec<[u8; 3]> {
    let mut renderer = Renderer::new(ctx, scene, RenderSettings::new(WIDTH, HEIGHT)).expect("renderer");
    let pixels = render_again(&mut renderer, scene);
    renderer.finish().expect("finish");
    pixels
}

/// The rgb of every pixel of a frame of `renderer`.
fn render_again(renderer: &mut Renderer, scene: &Scene) -> Vec<[u8; 3]> {
    let frame = (renderer.render(&scene.default_camera()))
        .and_then(|f| renderer.read(&f))
        .expect("frame");
    frame.rgba8.chunks_exact(4).map(|p| [p[0], p[1], p[2]]).collect()
}

fn all_magenta(pixels: &[[u8; 3]]) -> bool {
    pixels.iter().all(|&p| p == MAGENTA)
}

#[test]
fn hot_reload_rebuilds_with_the_new_tonemap_and_keeps_it_through_an_error() {
    let dir: PathBuf = target_tmp().join(format!("hot-reload-{}", std::process::id()));
    let glsl = dir.join("glsl");
    let _ = fs::remove_dir_all(&dir);
    copy_tree(&Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl"), &glsl);
    let field = ProceduralTerrain::default()
        .try_generate(33, 33, DVec2::splat(40.0))
        .expect("terrain");
    let scene = Scene::new(field);
    let (ctx, report) = validated_context();
    {
        let mut watcher = ShaderWatcher::new(&ctx, &glsl).expect("watcher");
        assert_eq!(watcher.check(), None, "nothing changed yet");
        let mut before = Renderer::new(&ctx, &scene, RenderSettings::new(WIDTH, HEIGHT)).expect("renderer");
        assert!(
            !all_magenta(&render_again(&mut before, &scene)),
            "the embedded tone mapper"
        );

        let source = fs::read_to_string(glsl.join(TONEMAP)).expect("tonemap.comp");
        assert!(source.contains(STORE), "tonemap.comp stores {STORE}");
        fs::write(glsl.join(TONEMAP), source.replace(STORE, "vec4(1.0, 0.0, 1.0, 1.0)")).expect("write");
        assert_eq!(watcher.check(), Some(Ok(vec![TONEMAP.to_string()])));
        assert!(all_magenta(&render(&ctx, &scene)), "a renderer built after the reload");
        assert!(
            !all_magenta(&render_again(&mut before, &scene)),
            "one built before keeps its pipelines"
        );
        before.finish().expect("finish");

        // A syntax error on line 3: one line naming it; the magenta module stays.
        let broken = source.replacen('\n', "\n\nint broken = ;\n", 1);
        fs::write(glsl.join(TONEMAP), broken).expect("write");
        let errors = watcher.check().expect("a change").expect_err("a syntax error");
        assert_eq!(errors.lines().count(), 1, "{errors}");
        assert!(errors.starts_with("glsl/post/tonemap.comp:3: error:"), "{errors}");
        assert!(all_magenta(&render(&ctx, &scene)), "the last good tone mapper");
        assert_eq!(watcher.check(), None, "no new change");

        // An include's change recompiles the shaders that include it.
        fs::write(glsl.join(TONEMAP), source).expect("write");
        let heap = glsl.join("include/heap.glsl");
        fs::write(&heap, fs::read_to_string(&heap).expect("heap.glsl") + "\n").expect("write");
        let names = watcher.check().expect("a change").expect("compiles");
        assert!(names.len() > 10 && names.contains(&TONEMAP.to_string()), "{names:?}");
        assert!(!all_magenta(&render(&ctx, &scene)), "the tone mapper as it was");
    }
    drop(ctx);
    let _ = fs::remove_dir_all(&dir);
    assert_validation_clean(&report);
}
