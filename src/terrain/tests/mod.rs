//! White-box tests of the terrain technique on a validated device and against its CPU twins.
//! (Moved from `tests/` in issue 26: integration tests use only the front door.)

mod ground;
mod terrain;
mod warp;
mod compute_raster;
