//! # hadou-math
//!
//! The single source of truth for hadou's formulas: energy fields of the analytic wave shapes and
//! their exact line integrals, curved waves and their integrators, quadrature, and the small vector
//! and matrix types everything else uses. No GPU, no window, no I/O.
//!
//! Every public formula names the thesis equation it implements and any SPEC.md correction.

// Lets the unit tests share `tests/curve_common/mod.rs`, which names the crate `hadou_math`.
#[cfg(test)]
extern crate self as hadou_math;

pub mod bloom;
pub mod curve;
pub mod energy;
pub mod keyframes;
mod mat4;
pub mod mtoon;
pub mod outline;
pub mod quadrature;
mod real;
pub mod rng;
pub mod shade;
pub mod shadow;
pub mod simd;
pub mod soft;
pub mod toon;
mod vec3;

pub use mat4::Mat4;
pub use real::Real;
pub use vec3::{Vec3, Vec3d, Vec3f};
