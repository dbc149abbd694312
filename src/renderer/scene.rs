//! What is drawn: a height field and a sun. The built-in default scene is a
//! procedural ridged-multifractal terrain (§6.1) under a low afternoon sun.

use glam::{DVec2, DVec3, Vec3};

use super::camera::Camera;
use crate::error::Result;
use crate::io::heightmap::HeightField;
use crate::terrain::procedural::ProceduralTerrain;

/// A terrain scene.
#[derive(Clone, Debug)]
pub struct Scene {
    pub heights: HeightField,
    /// Unit direction towards the sun.
    pub sun_direction: Vec3,
}

impl Scene {
    /// The default scene: 513² samples of the default procedural terrain at
    /// 20 m spacing (10.24 km square).
    pub fn default_procedural() -> Result<Scene> {
        let heights = ProceduralTerrain::default().try_generate(513, 513, DVec2::splat(20.0))?;
        Ok(Scene::new(heights))
    }

    /// A scene of `heights` with the default sun.
    pub fn new(heights: HeightField) -> Scene {
        Scene {
            heights,
            sun_direction: Vec3::new(-0.55, 0.45, 0.42).normalize(),
        }
    }

    /// Height range in metres.
    pub fn height_range(&self) -> (f32, f32) {
        self.heights.min_max()
    }

    /// A camera that shows the whole terrain: from beyond its southern edge,
    /// above the highest point, looking at the centre.
    pub fn default_camera(&self) -> Camera {
        let extent = self.heights.extent();
        let (lo, hi) = self.height_range();
        let (lo, hi) = (lo as f64, hi as f64);
        let size = extent.x.max(extent.y);
        let centre = DVec3::new(extent.x * 0.5, extent.y * 0.5, lo + (hi - lo) * 0.3);
        let eye = DVec3::new(extent.x * 0.5, -extent.y * 0.12, hi + (hi - lo) * 0.6 + size * 0.08);
        Camera {
            eye,
            target: centre,
            up: DVec3::Z,
            fov_y_deg: 50.0,
            near: (size * 1e-4).max(0.1),
            far: size * 10.0,
        }
    }
}
