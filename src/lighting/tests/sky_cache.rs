//! Sky tables kept across frames (issue 28, [`crate::lighting::technique::SkyRefresh`]):
//! a frame that reuses the previous frame's transmittance, multiple
//! scattering, sky-view, environment and sky-light tables is the same, byte
//! for byte, as one that computes them afresh; a moved sun or a climbing
//! eye recomputes what depends on it. Validation is on throughout.

use crate::renderer::{Camera, RenderSettings, Renderer, Scene};
use crate::surface::gpu_layout::TexturingMode;
use crate::test_support::{assert_validation_clean, jacksboro_field, validated_context};
use crate::view::{Lighting, SunPosition};
use crate::vulkan::Context;
use glam::DVec3;

const WIDTH: u32 = 96;
const HEIGHT: u32 = 64;

fn lighting(elevation_deg: f32) -> Lighting {
    Lighting {
        sun: SunPosition::Angles {
            elevation_deg,
            azimuth_deg: 150.0,
        },
        ..Lighting::default()
    }
}

fn renderer(ctx: &Context, scene: &Scene, elevation_deg: f32) -> Renderer {
    let settings = RenderSettings {
        texturing: TexturingMode::Direct,
        lighting: Some(lighting(elevation_deg)),
        ..RenderSettings::new(WIDTH, HEIGHT)
    };
    Renderer::new(ctx, scene, settings).expect("renderer")
}

fn frame(renderer: &mut Renderer, camera: &Camera) -> Vec<u8> {
    let f = renderer.render(camera).expect("frame");
    renderer.read(&f).expect("read").rgba8
}

#[test]
fn frames_with_kept_sky_tables_equal_freshly_computed_ones() {
    let (ctx, report) = validated_context();
    let scene = Scene::new(jacksboro_field());
    let camera = scene.default_camera();
    let up = Camera {
        eye: camera.eye + DVec3::new(0.0, 0.0, 300.0),
        ..camera
    };
    let (moved, kept, climbed) = {
        let mut a = renderer(&ctx, &scene, 30.0);
        let _ = frame(&mut a, &camera);
        a.set_lighting(lighting(12.0)).expect("lighting");
        let moved = frame(&mut a, &camera);
        let kept = frame(&mut a, &camera);
        let climbed = frame(&mut a, &up);
        a.finish().expect("finish");
        (moved, kept, climbed)
    };
    let (fresh, fresh_up) = {
        let mut b = renderer(&ctx, &scene, 12.0);
        let fresh = frame(&mut b, &camera);
        let mut c = renderer(&ctx, &scene, 12.0);
        let fresh_up = frame(&mut c, &up);
        b.finish().expect("finish");
        c.finish().expect("finish");
        (fresh, fresh_up)
    };
    let differ = |a: &[u8], b: &[u8]| a.iter().zip(b).filter(|(x, y)| x != y).count();
    assert_eq!(differ(&kept, &moved), 0, "a frame with kept tables");
    assert_eq!(differ(&moved, &fresh), 0, "a moved sun's tables");
    assert_eq!(differ(&climbed, &fresh_up), 0, "a climbing eye's sky view");
    assert!(differ(&moved, &climbed) > 0, "the views differ");
    drop(ctx);
    assert_validation_clean(&report);
}
