//! White-box tests of the terrain technique on a validated device and against its CPU twins.
//! (Moved from `tests/` in issue 26: integration tests use only the front door.)

mod compute_raster;
mod detail_panels;
mod ground;
mod pipeline_figure;
mod reversed_depth;
mod swimming;
mod terrain;
mod warp;
