//! Height-field synthesis by non-parametric sampling (dissertation §7.3;
//! `ALGORITHMS.md` §2): Efros–Leung pixel growing on height and its two
//! derivatives, used to fill holes in real DEMs and to grow transitions
//! between terrains of different procedural models.
//!
//! [`search`] is the neighbourhood search, the step that dominates the cost:
//! a CPU twin and GPU compute passes ([`gpu`]) implement the same rule.
//! [`exemplar`] builds the three channels and the candidate windows,
//! [`fill`] grows the unknown samples in waves, [`free`] grows a new field
//! from an exemplar alone (Fig. 7.1), [`transition`] joins two
//! height fields across a grown band; [`cost`] estimates a growth's time and
//! memory from its sizes before anything is allocated.

pub mod cost;
pub mod exemplar;
pub mod fill;
pub mod free;
pub mod gpu;
pub mod search;
pub mod transition;

#[cfg(test)]
mod tests;
