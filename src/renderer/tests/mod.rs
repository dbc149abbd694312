//! Renderer-level white-box tests: whole frames checked against the techniques' CPU twins.
//! (Moved from `tests/` in issue 26: integration tests use only the front door.)

mod aovs;
mod detail;
