//! White-box tests of terrain synthesis: hole filling, free growth and the GPU neighbourhood search.
//! (Moved from `tests/` in issue 26: integration tests use only the front door.)

mod channels;
mod fill;
mod free;
mod gpu;
mod lambda;
