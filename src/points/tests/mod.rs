//! White-box tests of the point renderer and vegetation, under validation.
//! (Moved from `tests/` in issue 26: integration tests use only the front door.)

mod color_density;
mod hybrid;
mod isocontours;
mod kernel;
mod primitives;
mod render;
mod rock_levels;
mod single_pass;
mod vegetation;
mod view_error;
