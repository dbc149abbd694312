//! The front door's own code: the few constructors and helpers that the
//! crate root re-exports and that no technique owns.

pub(crate) mod scene;
