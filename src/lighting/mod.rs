//! Outdoor lighting (§6.3, §9). For now: the analytic sky of the default
//! scene; the Preetham sky, aerial perspective, shadows and PRT follow.

pub mod sky;
