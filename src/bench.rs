//! What the benchmarks and analysis examples (`examples/*_bench.rs`,
//! `soak`, `quad_area`, `rig_lod`, `fuzz_corpus`) need of the internals.
//! Hidden from the documentation and not part of the API: no stability
//! promise; it exists so that those programs need no public internals.

pub use crate::graph::{Binding, ImageId, ImageInfo, PassContext, RenderGraph, Stage};
pub use crate::lighting::constants::LightingFrame;
pub use crate::lighting::reference::{MonteCarloReference, ReferenceSettings, ReferenceWork};
pub use crate::lighting::sky_light::{BakeSettings, SkyLightBake};
pub use crate::points::build::clip::{ClipLine, ClipLines};
pub use crate::points::build::spt::ROOT_R_MAX;
pub use crate::points::render::object_space::QUADRUPLICATION_EXTRA_BYTES_PER_SPLAT;
pub use crate::points::scene::PointInstance;
pub use crate::points::Surfel;
pub use crate::post::distortion::{source_intrinsics, DistortedCamera, LensDistortion};
pub use crate::post::motion_blur::{MotionBlur, MotionBlurImages};
pub use crate::post::resample::{ImageKind, ResampleImage};
pub use crate::post::resolve::{supersampled_size, Resolve, ResolveDesc, ResolveFilter};
pub use crate::random::SplitMix64;
pub use crate::surface::bspline::sample_bspline;
pub use crate::synthesis::search::{Exemplar, NeighbourhoodSearch, Query, SearchConfig};
pub use crate::terrain::importance::{importance_map, Backface, Frustum, ImportanceParams};
pub use crate::terrain::lod::{Anchor, DebugScalar, LodFrame};
pub use crate::terrain::raycast::{raycast, Raycaster};
pub use crate::terrain::sketch_map::SketchMap;
pub use crate::terrain::swimming::{camera_path, measure as measure_swimming, Mesh, Swimming};
pub use crate::terrain::warp::{warp, warp_into, warp_with, ColumnImportance, WarpOptions};
pub use crate::terrain::zoom::{projected_quad_areas, zoom_positions};
pub use crate::texturing::from_image::{calibrate, classify, distributions, shading, tree, Registration};
pub use crate::view::lens::{Distortion, Intrinsics};
pub use crate::view::lighting::sun_direction;
pub use crate::view::View;
pub use crate::vulkan::{Format, FrameRing, Image, ImageDesc, ImageUsageFlags};
