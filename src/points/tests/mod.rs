//! White-box tests of the point renderer and vegetation, under validation.
//! (Moved from `tests/` in issue 26: integration tests use only the front door.)

mod hybrid;
mod kernel;
mod primitives;
mod render;
mod rock_levels;
mod single_pass;
mod vegetation;
