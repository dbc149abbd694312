//! Height-field synthesis by non-parametric sampling (dissertation §7.3;
//! `ALGORITHMS.md` §2): Efros–Leung pixel growing on height and its two
//! derivatives, used to fill holes in real DEMs and to grow transitions
//! between terrains of different procedural models.
//!
//! [`search`] is the neighbourhood search, the step that dominates the cost:
//! a CPU twin and GPU compute passes ([`gpu`]) implement the same rule.

pub mod gpu;
pub mod search;
