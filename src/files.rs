//! Reading and writing the files alpenglow knows: height maps, point
//! clouds and meshes, `.spt` point trees, camera key frames, PNG and EXR
//! images, and the atomic output transactions that keep a failed run from
//! leaving a half-written file.
//!
//! Every reader checks its input against [`InputLimits`] before it
//! allocates and answers with a one-line [`Error`](crate::Error) naming the
//! file; every writer either writes the whole file or nothing.
//!
//! ```no_run
//! use alpenglow::files::{load_heightmap, write_png_rgba8};
//! use alpenglow::HeightmapOptions;
//! let field = load_heightmap("dem.png".as_ref(), &HeightmapOptions::default())?;
//! let pixels = vec![255u8; 4 * 2 * 2];
//! write_png_rgba8("out.png".as_ref(), &pixels, 2, 2)?;
//! # Ok::<(), alpenglow::Error>(())
//! ```

pub use crate::io::atomic::{write_bytes_atomically, OutputTransaction};
pub use crate::io::heightmap::{
    check_spacing, load_heightmap, load_heightmap_with_voids, MAX_ABS_HEIGHT, MAX_SPACING, MIN_SPACING,
};
pub use crate::io::image_out::{
    encode_exr_height, encode_exr_samples, encode_png_gray16, write_exr, write_exr_samples, write_image_by_extension,
    write_png_rgba8, ExrChannels, ExrSamples, ImageFormat,
};
/// Reading back the EXR files alpenglow writes, and an RGBA8 PNG encoder (the tests' fixtures).
pub use crate::io::image_out::{encode_png_rgba8, read_exr_channels};
pub use crate::io::limits::InputLimits;
/// GDAL rasters as height rows (feature `gdal`).
#[cfg(feature = "gdal")]
pub use crate::io::pyramid::GdalRows;
pub use crate::io::pyramid::{
    write_pyramid, write_ridge_region, FieldRows, FieldShape, FnRows, HeightPyramid, HeightRows, HgtMosaic,
    PyramidOptions, PyramidSummary, PyramidTile, TileKey, DEFAULT_HEIGHT_STEP, DEFAULT_RESIDENT_SIDE,
    DEFAULT_TILE_SIDE,
};
pub use crate::points::build::input::{load_points_file, PointInput};
pub use crate::points::build::spt_file::{read_spt, write_spt};
pub use crate::points::scene::load_point_object;
pub use crate::terrain::detail::{DEFAULT_DETAIL_WINDOW, MAX_DETAIL_WINDOW};
pub use crate::view::camera_path::load_keyframes;
