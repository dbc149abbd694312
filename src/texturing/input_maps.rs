//! The extra input maps of the surface-layer tree (dissertation §8.2,
//! Table 8.1: rainfall, radiation, temperature), registered to the height
//! field: each map's grid spans the terrain rectangle corner to corner at
//! any resolution. Uploaded once as R32F textures; the layer shaders sample
//! them bilinearly (`input_maps` in `glsl/include/surface_layers.glsl`).

use std::path::Path;
use std::sync::Arc;

use crate::error::{Error, Result};
use crate::graph::{ImageId, RenderGraph};
use crate::io::heightmap::HeightField;
use crate::texturing::layers::{LayerTree, INPUT_NAMES};
use crate::vulkan::{Context, Format, Image, ImageDesc, ImageUsageFlags};

/// The input maps as graph resources with their sampled heap handles
/// (`None`: absent).
#[derive(Clone, Copy, Debug, Default)]
pub struct InputMaps {
    pub maps: [Option<(ImageId, u32)>; 3],
}

impl InputMaps {
    /// Checks that every input `tree` uses is present and valid, uploads
    /// the present maps and imports them into `graph`.
    pub fn import<P: 'static>(
        ctx: &Context,
        graph: &mut RenderGraph<P>,
        tree: &LayerTree,
        maps: &[Option<HeightField>; 3],
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
            let image = Image::with_data(
                ctx,
                ImageDesc {
                    name: format!("input map {name}"),
                    width: map.columns,
                    height: map.rows,
                    format: Format::R32_SFLOAT,
                    usage: ImageUsageFlags::SAMPLED,
                },
                bytemuck::cast_slice(&map.heights),
            )?;
            let handle = image
                .sampled_handle()
                .ok_or_else(|| Error::Graph(format!("input map '{name}' has no sampled handle")))?;
            out.maps[k] = Some((graph.import_image(Arc::new(image)), handle));
        }
        Ok(out)
    }

    /// The present maps.
    pub fn present(&self) -> impl Iterator<Item = ImageId> + '_ {
        self.maps.iter().flatten().map(|(id, _)| *id)
    }

    /// `maps` of the shaders: sampled handles, and in w bit k when map k is
    /// present.
    pub fn handles(&self) -> [u32; 4] {
        let mut handles = [0u32; 4];
        for (k, map) in self.maps.iter().enumerate() {
            if let Some((_, handle)) = map {
                handles[k] = *handle;
                handles[3] |= 1 << k;
            }
        }
        handles
    }
}
