//! The points part of a scene on the command line: `--points` objects with
//! their `--points-transform`, the default scene's rocks, and the splat
//! settings (§10.1–10.3).

use anyhow::{bail, Context as _, Result};

use alpenglow::points::build::spt::epsilon_from_pixels;
use alpenglow::points::render::{SplatBackend, SplatMode, SplatPrimitive, SplatSettings};
use alpenglow::points::scene::{load_point_object, PointLoadOptions, PointTransform};
use alpenglow::renderer::Scene;

use super::args::{PointArgs, SplatArg, SplatBackendArg, SplatPrimitiveArg};

/// Adds the `--points` objects to `scene` (and, for the built-in terrain,
/// the `--rocks`); `builtin` says whether the scene is the built-in one.
pub fn add_points(args: &PointArgs, scene: &mut Scene, builtin: bool) -> Result<()> {
    if args.transforms.len() > args.points.len() {
        bail!(
            "{} --points-transform given for {} --points objects",
            args.transforms.len(),
            args.points.len()
        );
    }
    if args.samples == 0 {
        bail!("--points-samples must be at least 1");
    }
    if builtin && args.rocks > 0 && !args.no_terrain {
        scene.add_rocks(args.rocks)?;
    }
    let options = PointLoadOptions {
        mesh_samples: args.samples,
        hybrid: args.hybrid,
        ..PointLoadOptions::default()
    };
    for (i, path) in args.points.iter().enumerate() {
        let transform = match args.transforms.get(i) {
            Some(t) => PointTransform::parse(t)?,
            None => PointTransform::default(),
        };
        let object = load_point_object(path, &options).with_context(|| format!("--points {}", path.display()))?;
        scene.points.add(object, transform);
    }
    if args.no_terrain {
        scene.draw_terrain = false;
    }
    Ok(())
}

/// Splat settings for an image of `rows` pixel rows seen with `fov_y_deg`.
pub fn splat_settings(args: &PointArgs, fov_y_deg: f64, rows: u32) -> Result<SplatSettings> {
    let settings = SplatSettings {
        mode: match args.splat {
            SplatArg::Opaque => SplatMode::Opaque,
            SplatArg::Ewa => SplatMode::Ewa,
            SplatArg::SinglePass => SplatMode::SinglePass,
        },
        backend: match args.splat_backend {
            SplatBackendArg::Compute => SplatBackend::Compute,
            SplatBackendArg::Interlock => SplatBackend::Interlock,
        },
        primitive: match args.splat_primitive {
            SplatPrimitiveArg::Point => SplatPrimitive::Point,
            SplatPrimitiveArg::Quad => SplatPrimitive::Quad,
            SplatPrimitiveArg::Instanced => SplatPrimitive::Instanced,
            SplatPrimitiveArg::ObjectQuad => SplatPrimitive::ObjectQuad,
            SplatPrimitiveArg::ObjectInstanced => SplatPrimitive::ObjectInstanced,
        },
        shaded: !args.no_shading,
        two_sided: args.two_sided,
        normal_clusters: args.normal_clusters,
        epsilon: Some(
            epsilon_from_pixels(args.epsilon, fov_y_deg.to_radians() as f32, rows)
                .with_context(|| format!("--epsilon {}", args.epsilon))?,
        ),
        ..SplatSettings::default()
    };
    settings.validate()?;
    Ok(settings)
}
