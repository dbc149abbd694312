//! The points part of a scene on the command line: `--points` objects with
//! their `--points-transform`, the default scene's rocks, the plants of the
//! layer tree (`--vegetation`), and the splat settings (§10.1–10.3).

use anyhow::{bail, Context as _, Result};

use alpenglow::files::load_point_object;
use alpenglow::tools::budget::MemoryLimits;
use alpenglow::tools::spt::{sampling_footprint, SamplingMethod};
use alpenglow::{
    PointLoadOptions, PointTransform, Scene, SplatBackend, SplatKernel, SplatMode, SplatPrimitive, SplatSettings,
    SptError, VegetationOptions, ViewSpec,
};

use super::args::{
    PointArgs, SplatArg, SplatBackendArg, SplatKernelArg, SplatPrimitiveArg, SptErrorArg, VegetationArg,
};

/// Adds the plants of the scene's layer tree when `--vegetation` says so
/// (default: on for the built-in terrain); call after the layers and input
/// maps are set.
pub fn add_vegetation(args: &PointArgs, scene: &mut Scene, builtin: bool) -> Result<()> {
    if !(args.vegetation_density.is_finite() && args.vegetation_density >= 0.0) {
        bail!(
            "--vegetation-density {} must be a finite number ≥ 0",
            args.vegetation_density
        );
    }
    let on = match args.vegetation {
        Some(VegetationArg::On) => true,
        Some(VegetationArg::Off) => false,
        None => builtin,
    };
    if !on || args.no_terrain {
        return Ok(());
    }
    if !scene.layers.has_vegetation() {
        if args.vegetation == Some(VegetationArg::On) {
            log::warn!("--vegetation on: no layer of the layer tree has a vegetation table");
        }
        return Ok(());
    }
    let options = VegetationOptions {
        density: args.vegetation_density,
        ..VegetationOptions::default()
    };
    let report = scene.add_vegetation(&options).context("--vegetation")?;
    log::info!(
        "vegetation: {} plants ({}) from {} candidates, {} prototypes",
        report.total(),
        (report.plants.iter())
            .map(|(m, n)| format!("{n} {}", m.name()))
            .collect::<Vec<_>>()
            .join(", "),
        report.candidates,
        report.prototypes
    );
    Ok(())
}

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
    if !args.points.is_empty() {
        MemoryLimits::host_only().check(
            "--points-samples",
            &format!("{} samples", args.samples),
            sampling_footprint(args.samples, SamplingMethod::default()),
        )?;
    }
    if builtin && args.rocks > 0 && !args.no_terrain {
        scene.add_rocks(args.rocks)?;
    }
    let options = PointLoadOptions {
        mesh_samples: args.samples,
        hybrid: args.hybrid,
        hybrid_points_color: args.hybrid_red_points.then_some([230, 20, 20]),
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

/// Splat settings for `views` (seen with `fov_y_deg` where they have no
/// intrinsics): the angular threshold is `--epsilon` pixels of the finest
/// view's pixel footprint.
pub fn splat_settings(args: &PointArgs, views: &[ViewSpec], fov_y_deg: f64) -> Result<SplatSettings> {
    let finest = (views.iter().map(|v| v.pixel_footprint(fov_y_deg))).fold(f64::INFINITY, f64::min);
    let epsilon = args.epsilon * finest as f32;
    if !(args.epsilon.is_finite() && args.epsilon > 0.0 && epsilon.is_finite() && epsilon > 0.0) {
        bail!(
            "invalid --epsilon: {} px is not a positive number of pixels",
            args.epsilon
        );
    }
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
        kernel: match args.splat_kernel {
            SplatKernelArg::Perspective => SplatKernel::Perspective,
            SplatKernelArg::Affine => SplatKernel::Affine,
        },
        error: match args.spt_error {
            SptErrorArg::Isotropic => SptError::Isotropic,
            SptErrorArg::ViewDependent => SptError::ViewDependent,
        },
        shaded: !args.no_shading,
        two_sided: args.two_sided,
        normal_clusters: args.normal_clusters,
        epsilon: Some(epsilon),
        ..SplatSettings::default()
    };
    settings.validate()?;
    Ok(settings)
}
