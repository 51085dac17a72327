//! Energy fields of the analytic wave shapes and their exact line integrals (thesis 002 §3.3,
//! eq. 3.4–3.11, with the corrections of SPEC.md §1.2).
//!
//! # The two density laws
//! Distances are regularised with the core radius `r_c`: `ρ = sqrt(r² + r_c²)`.
//! - [`Falloff::Faithful`] (the thesis): density `α/ρ`, `I = ∫ F(S + tQ) dt` over the normalized
//!   parameter `t` with `Q = E − S` (002 eq. 3.6–3.11), so `I` scales with `1/|Q|`.
//! - [`Falloff::InverseSquare`] (hadou's default): density `α/ρ²`, `I = ∫ F(S + t·dir) dt` with a
//!   unit `dir`, i.e. over arc length; `t1 = +∞` integrates to infinity.
//!
//! # One reduced integral
//! Along a ray both the sphere's radicand `U(t) = At² + 2Bt + C` (eq. 3.6) and the cylinder's
//! `W(t) = D't² + 2Et + F` (eq. 3.7), plus `r_c²`, are a squared distance `|v + t·u|² + r_c²`
//! (sphere: `u = Q`, `v = S − M`; cylinder: `u = Q × D`, `v = (S − M) × D`). Completing the square
//! with `s = |u|`, `û = u/s`:
//!
//! `|v + t·u|² + r_c² = Y(t)² + H`, `Y = s·t + û·v`, `H = |û × v|² + r_c²`,
//!
//! where `H = (AC − B²)/A` is the squared closest distance plus `r_c²`. Computing it as a cross
//! product (SPEC.md §1.2: `AC − B² = |Q × w|²`) avoids the cancellation of `AC − B²`; `H` is then
//! floored at [`H_FLOOR`] so that a ray exactly through a centre or along an axis with `r_c = 0`
//! (where the true integral diverges) stays finite. Both laws then need one antiderivative:
//!
//! - faithful: `∫ dt/sqrt(Y² + H) = asinh(Y/√H)/s` — SPEC.md's corrected form of eq. 3.8–3.9
//!   (the thesis prints `asinh(2(tA+B)/(4AC − (2B)²))`, lacking the square root);
//! - inverse square: `∫ dt/(Y² + H) = atan(Y/√H)/(s√H)`.
//!
//! # Stable evaluation
//! A difference of two `asinh` (or `atan`) values is never formed. With `P = Y + sqrt(Y² + H)`,
//! `asinh(Y₁/√H) − asinh(Y₀/√H) = ln(P₁/P₀)`: `H` cancels in the ratio, and `P₁/P₀ − 1` is built
//! from positive terms only and passed to one `ln(1 + ·)` (`ln_1p` where it is small) — with
//! `P₀ = H/(sqrt(Y₀²+H) − Y₀)` where `Y₀ < 0`, and the mirrored branch `asinh(x) = −asinh(−x)`
//! (`N = sqrt(Y² + H) − Y`) where the interval lies mostly at negative `Y`. The naive
//! `ln((At₁ + B + sqrt(A·U(t₁)))/(At₀ + B + sqrt(A·U(t₀))))` instead loses the digits of its
//! denominator (infinity once it rounds to zero) in `f32` for rays that pass close to a centre
//! lying ahead: on a 2048-wide view with the far plane at 1e4 it is off by more than 1e-3 on the
//! pixels around a sphere's centre (`tests/analytic_f32_stability.rs`). The `atan` difference is one
//! `atan2(√H·s·Δt, H + Y₀Y₁)`, valid for all signs. Both forms tend to `Δt/sqrt(Y² + H)` resp.
//! `Δt/(Y² + H)` as `s → 0` (a ray parallel to a cylinder's axis) without dividing by `s`.
//! See [`RayQuadratic`] for the details.
//!
//! # Capsule and beam
//! The capsule (eq. 3.10–3.11) splits the ray at the planes through `M` and `M₂` with normal `D`,
//! `t_i = (D·M_i − D·S)/(D·Q)`, and adds sphere / cylinder / sphere pieces in ray order, each its
//! own closed form. `D·Q = 0` puts the whole ray in the region of its offset `D·(S − M)`. On the
//! planes the sphere and cylinder distances coincide, so with `α_s = α_c` the field (and hence the
//! energy) is continuous across them. The bulged beam adds sphere fields at `M₂` and `M`.
//!
//! # Distance attenuation
//! Every shape also has an `*_attenuated` form taking an [`Attenuation`]: the density times
//! `(1 − t/t_far)^j` (002 eq. 3.23, SPEC.md §1.4, which the thesis gives for curves only), 0 from
//! the far point on, in both laws. It is integrated by Gauss–Legendre on graded cells weighted by
//! the closed forms above (see [`RayQuadratic::attenuated`]); `j = 0` is the plain closed form.
//!
//! # Saturation
//! Each closed-form piece is capped at [`ENERGY_MAX`] (`10³⁰`, reached only where the true
//! integral diverges: a ray through a centre or along an axis with `r_c = 0`), and every energy
//! `α·I` and every sum of energies is saturated at `f32::MAX` ([`ENERGY_SATURATION`],
//! [`scaled`], [`saturate`]) instead of overflowing: an energy too large for `f32` is reported
//! as `f32::MAX` (full brightness), never `+∞`, NaN or 0, and `α = 0` gives exactly 0.
//!
//! Every function is generic over [`Real`](crate::Real): `f32` renders, `f64` is what tests compare
//! against. For finite inputs the results are finite, in `[0, f32::MAX]`.

mod attenuated;
mod field;
mod integral;
mod kernel;
pub mod lanes;

pub use attenuated::{
    beam_energy_attenuated, capsule_energy_attenuated, cylinder_energy_attenuated, sphere_energy_attenuated,
    APPROACH_RATIO, FAR_GRADE, FAR_RATIO_MIN, INNER_CELL, LEAVE_GROWTH, MAX_CELLS, PEAK_RANGE,
    REST_TOLERANCE, TAIL_MIN_J, TAIL_REACH, TAIL_REACH_MIN,
};
pub use field::{
    Attenuation, BeamField, CapsuleField, CylinderField, Falloff, FieldParams, Ray, SphereField,
};
pub use integral::{beam_energy, capsule_energy, cylinder_energy, sphere_energy};
pub use kernel::{saturate, scaled, RayAxis, RayQuadratic, ENERGY_MAX, ENERGY_SATURATION, H_FLOOR, T_LIMIT};
