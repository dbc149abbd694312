//! White-box tests of the render graph on a validated device (moved from
//! `tests/` in issue 26: integration tests use only the front door).

mod bindings;
mod device;
mod timeline;
