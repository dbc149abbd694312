//! White-box tests of the texturing technique: atlas, streaming and the CPU reference surface.
//! (Moved from `tests/` in issue 26: integration tests use only the front door.)

mod atlas;
mod layers_from_image;
mod legal_views;
mod reference;
mod streaming;
