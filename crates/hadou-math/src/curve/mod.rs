//! Curved energy waves (thesis 002 §3.4, SPEC.md §1.4): explicit curves in a local frame, paired
//! with the view ray by cross-section, integrated numerically.
//!
//! The public types re-exported here ([`CurveWave`] and its parts) are the contract the scene and
//! the backends build against.
//!
//! # Model (SPEC.md §1.4)
//! A curve lives in a local frame ([`CurveFrame`]): `c(s) = O + γ s·D + y(s)·ŷ + z(s)·ẑ`
//! (002 eq. 3.14). A ray point `P` with axial coordinate `x = (P − O)·D` is paired with the curve
//! point in the same cross-section, `c(x/γ)` (002 §3.4.2, SPEC.md reading note); with the
//! extension `k` (002 eq. 3.24) only `s ∈ [0, k·s_end]` exists, so with `X = γ k s_end` points
//! with `x > X` pair with the head `c(k·s_end)` and points with `x < 0` with `c(0)`: round ends.
//! The density is `α / sqrt(r² + r_c²)` ([`Falloff::Faithful`], 002 eq. 3.17) or
//! `α / (r² + r_c²)` ([`Falloff::InverseSquare`]), `r = |P − paired point|`, times the attenuation
//! `(1 − u)^j`, `u = t / t_far` (002 eq. 3.23; 0 for `u ≥ 1` when `j > 0`).
//!
//! Inside the slab `0 ≤ x ≤ X` the paired point lies in `P`'s own cross-section, so `r` is the 2-D
//! distance `|P_⊥ − c_⊥(x/γ)|`; outside it is the 3-D distance to an end point. The field is
//! continuous across both end planes.
//!
//! # Integrators
//! - [`Integrator::Simpson`]: the thesis's composite Simpson rule with optional bounding-cylinder
//!   reduction ([`simpson`]); reproduces its banding.
//! - [`Integrator::Default`]: exact integrals over straight pieces chosen adaptively per ray from
//!   a precomputed tree of polylines ([`integrate`], [`PieceTable`]).
//! - [`Integrator::Nearest`]: the nearest-point field — the density taken at the ray point's
//!   true nearest curve point rather than its cross-section partner — by a walk over the ray whose
//!   steps follow the distance, each distance found by branch and bound over the piece table and
//!   refined on the exact curve (`nearest.rs`).
//! - [`curve_energy_lanes`]: the default integrator on up to eight neighbouring rays at once,
//!   walking the piece table as one packet in SIMD lanes (`lanes.rs`; what the CPU backend's
//!   wave pass runs), each ray evaluating the pieces [`curve_energy`] gives it.
//! - [`curve_energy_reference`]: converged `f64` adaptive Gauss–Kronrod on the exact field;
//!   [`nearest_energy_reference`] the same for the nearest-point field, by dense minimisation.
//!
//! # Work per ray
//! The parameters that multiply a ray's work — turns, terms, control points, steepness and
//! Simpson's `m` times the price of a curve point — are bounded by [`CurveWave::validate`] and
//! brought within those bounds by [`prepare`] (`cost.rs`), so that no ray through a valid curve
//! takes more than about 10⁵ evaluations.
//!
//! Every public entry point — [`curve_energy`] / [`curve_energy_f64`] (which dispatch on the
//! wave's [`Integrator`]), [`integrate::default_energy`] and [`curve_energy_reference`] — resolves
//! the ray's span in the curve's local frame once and hands that resolved ray to its integrator;
//! an empty span or input that is not finite gives 0.
//!
//! [`Falloff::Faithful`]: crate::energy::Falloff::Faithful
//! [`Falloff::InverseSquare`]: crate::energy::Falloff::InverseSquare

#![allow(
    clippy::neg_cmp_op_on_partial_ord,
    reason = "`!(a > b)` is deliberate throughout: it is also true when a value is NaN, which must \
              take the empty or fallback path"
)]

mod closed;
mod cost;
pub use cost::DEFAULT_RAY_WORK;
mod dispatch;
pub mod integrate;
mod lanes;
mod local_ray;
mod nearest;
mod prepare;
mod reference;
mod shape;
pub mod simpson;
mod validate;
mod wave;

pub use dispatch::{curve_energy, curve_energy_f64};
pub use integrate::{
    attenuation_split, CurveSample, DefaultSettings, DEFAULT_SETTINGS, MAX_ATTENUATION_PARTS,
};
pub use lanes::{curve_energy_lanes, PACKET};
pub use nearest::{
    MAX_NEAREST_STEPS, MAX_NEAREST_VISITS, NEAREST_PRUNE, NEAREST_RAY_WORK, NEAREST_STEP, TAIL_RADII,
};
pub use prepare::{
    prepare, try_prepare, PieceTable, PreparedCurve, LEAF_TOLERANCE, LIGHT_TOLERANCE, MAX_LIGHT_POINTS,
    MAX_PIECES, MIN_CORE,
};
pub use reference::{curve_energy_reference, nearest_energy_reference};
pub use shape::clamped_uniform_knots;
pub use validate::CurveError;
pub use wave::{
    CurveFrame, CurveShape, CurveWave, Integrator, Reduction, MAX_BEZIER_POINTS, MAX_BSPLINE_POINTS,
    MAX_ORDER, MAX_SIMPSON_M, MAX_SLOPE, MAX_TRIG_TERMS, MAX_TURNS,
};
