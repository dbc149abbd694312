//! The extra input maps of the surface-layer tree (dissertation §8.2,
//! Table 8.1: rainfall, radiation, temperature), registered to the height
//! field: each map's grid spans the terrain rectangle corner to corner at
//! any resolution. Uploaded once as R32F textures; the layer shaders sample
//! them bilinearly (`input_maps` in `glsl/include/surface_layers.glsl`).
//! Also the blurred height fields of `height_blur` layers
//! ([`crate::surface::blurred_height`]), R32F as well, which the shaders
//! sample with the base height's cubic B-spline.

use std::path::Path;
use std::sync::Arc;

use crate::error::{Error, Result};
use crate::graph::{Binding, ImageId, PassBuilder, PassContext, RenderGraph, Stage};
use crate::io::heightmap::HeightField;
use crate::surface::blurred_height::blurred_height;
use crate::surface::layers::{LayerTree, INPUT_NAMES, MAX_BLUR_RADII};
use crate::vulkan::{Context, Format, Image, ImageDesc, ImageUsageFlags};

/// The input maps as graph resources (`None`: absent), and the blurred
/// height fields with their radius.
#[derive(Clone, Copy, Debug, Default)]
pub struct InputMaps {
    pub maps: [Option<ImageId>; 3],
    pub blurred: [Option<(f32, ImageId)>; MAX_BLUR_RADII],
}

/// The input maps and blurred height fields one pass declared it samples
/// ([`InputMaps::sample_in`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct MapBindings {
    maps: [Option<Binding>; 3],
    blurred: [Option<(f32, Binding)>; MAX_BLUR_RADII],
}

/// Uploads `map`'s samples as an R32F texture `name` and imports it.
fn upload<P: 'static>(ctx: &Context, graph: &mut RenderGraph<P>, name: String, map: &HeightField) -> Result<ImageId> {
    let image = Image::with_data(
        ctx,
        ImageDesc {
            name,
            width: map.columns,
            height: map.rows,
            format: Format::R32_SFLOAT,
            usage: ImageUsageFlags::SAMPLED,
        },
        bytemuck::cast_slice(&map.heights),
    )?;
    Ok(graph.import_image(Arc::new(image)))
}

impl InputMaps {
    /// Checks that every input `tree` uses is present and valid, uploads
    /// the present maps and `field` blurred for each of the tree's
    /// `height_blur` radii, and imports them into `graph`.
    pub fn import<P: 'static>(
        ctx: &Context,
        graph: &mut RenderGraph<P>,
        tree: &LayerTree,
        maps: &[Option<HeightField>; 3],
        field: &HeightField,
    ) -> Result<InputMaps> {
        let mut out = InputMaps::default();
        for (k, map) in maps.iter().enumerate() {
            let name = INPUT_NAMES[k];
            let Some(map) = map else {
                if tree.uses_input(k) {
                    return Err(Error::invalid(
                        format!("input_maps.{name}"),
                        format!("a layer constrains input map '{name}' but none was given"),
                    ));
                }
                continue;
            };
            map.validate(Path::new(&format!("input map '{name}'")))?;
            out.maps[k] = Some(upload(ctx, graph, format!("input map {name}"), map)?);
        }
        for (k, radius) in tree.blur_radii().into_iter().enumerate().take(MAX_BLUR_RADII) {
            let layer = (tree.layers.iter()).find(|l| l.layer.height_blur == Some(radius));
            let what = format!("layer '{}': height_blur", layer.map_or("", |l| l.layer.name.as_str()));
            let blurred = blurred_height(field, radius, &what)?;
            let image = upload(ctx, graph, format!("height blurred by {radius} m"), &blurred)?;
            out.blurred[k] = Some((radius, image));
        }
        Ok(out)
    }

    /// Declares that `pass` samples every present map and blurred height
    /// field at `stage`.
    pub fn sample_in<P: 'static>(&self, pass: &mut PassBuilder<'_, P>, stage: Stage) -> MapBindings {
        MapBindings {
            maps: self.maps.map(|map| map.map(|id| pass.sample(id, stage))),
            blurred: self
                .blurred
                .map(|b| b.map(|(radius, id)| (radius, pass.sample(id, stage)))),
        }
    }
}

impl MapBindings {
    /// The sampled handle of the height field blurred by `radius` (0 when
    /// none was declared).
    pub fn blurred_handle(&self, ctx: &PassContext<'_>, radius: f32) -> Result<u32> {
        match self.blurred.iter().flatten().find(|(r, _)| *r == radius) {
            Some(&(_, binding)) => ctx.handle(binding),
            None => Ok(0),
        }
    }

    /// `maps` of the shaders: sampled handles, and in w bit k when map k is
    /// present.
    pub fn handles(&self, ctx: &PassContext<'_>) -> Result<[u32; 4]> {
        let mut handles = [0u32; 4];
        for (k, map) in self.maps.iter().enumerate() {
            if let Some(binding) = map {
                handles[k] = ctx.handle(*binding)?;
                handles[3] |= 1 << k;
            }
        }
        Ok(handles)
    }
}
