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
//! # Saturation
//! Each closed-form piece is capped at [`ENERGY_MAX`] (`10³⁰`, reached only where the true
//! integral diverges: a ray through a centre or along an axis with `r_c = 0`), and every energy
//! `α·I` and every sum of energies is saturated at `f32::MAX` ([`ENERGY_SATURATION`],
//! [`scaled`], [`saturate`]) instead of overflowing: an energy too large for `f32` is reported
//! as `f32::MAX` (full brightness), never `+∞`, NaN or 0, and `α = 0` gives exactly 0.
//!
//! Every function is generic over [`Real`]: `f32` renders, `f64` is what tests compare against.
//! For finite inputs the results are finite, in `[0, f32::MAX]`.

mod kernel;
pub mod lanes;

pub use kernel::{saturate, scaled, RayAxis, RayQuadratic, ENERGY_MAX, ENERGY_SATURATION, H_FLOOR, T_LIMIT};

use crate::{Real, Vec3};
/// How energy density falls off with distance and what measure the ray integral uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Falloff {
    /// The thesis (002 eq. 3.6–3.11): density `α / r`, integrated over the normalized ray
    /// parameter `t ∈ [0, 1]` from the eye `S` to the far point `E` (so the value scales with
    /// `1/|E − S|`). The ray's `dir` is `Q = E − S`.
    Faithful,
    /// hadou's default: density `α / r²`, integrated over arc length from the eye to the first
    /// occluder or to infinity, so the value does not depend on where the far plane is — with one
    /// exception: a curve's attenuation `(1 − u)^j`, `j > 0` (002 eq. 3.23, SPEC.md §1.4), keeps
    /// the thesis's `u = t/t_far` (`t_far` the far point's distance along the ray) in both
    /// falloffs, so it attenuates the same points equally and ends the integral at the far plane;
    /// `far` is then its length scale. The ray's `dir` is a unit vector.
    #[default]
    InverseSquare,
}

/// Parameters shared by every field of one wave.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldParams<R> {
    /// Density law and ray measure.
    pub falloff: Falloff,
    /// Core radius `r_c ≥ 0`: distances are regularised as `sqrt(r² + r_c²)`, which keeps the
    /// integral finite on rays through a centre or along an axis.
    pub core_radius: R,
}

/// A ray `V(t) = origin + t·dir`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray<R> {
    /// The eye `S`.
    pub origin: Vec3<R>,
    /// `Q = E − S` for [`Falloff::Faithful`], a unit direction for [`Falloff::InverseSquare`].
    pub dir: Vec3<R>,
}

/// Sphere field `α_s / |P − M|` (002 eq. 3.4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereField<R> {
    /// Centre `M`.
    pub center: Vec3<R>,
    /// Strength `α_s`.
    pub alpha: R,
}

/// Infinite cylinder field `α_c / dist(P, line(M, D))` (002 eq. 3.5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CylinderField<R> {
    /// A point `M` on the axis.
    pub point: Vec3<R>,
    /// Unit axis direction `D`.
    pub dir: Vec3<R>,
    /// Strength `α_c`.
    pub alpha: R,
}

/// Capsule ("straight beam") field: sphere around `M` before the plane through `M` with normal
/// `D`, cylinder between the planes, sphere around `M₂ = M + length·D` after (002 eq. 3.11).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CapsuleField<R> {
    /// The end `M` (the muzzle of a beam).
    pub m: Vec3<R>,
    /// Unit direction `D` from `M` to `M₂`.
    pub d: Vec3<R>,
    /// `|M₂ − M| ≥ 0`.
    pub length: R,
    /// Strength of the end spheres `α_s`.
    pub alpha_s: R,
    /// Strength of the cylinder `α_c`.
    pub alpha_c: R,
}

impl<R: Real> CapsuleField<R> {
    /// The far end `M₂ = M + length·D` (the head of a beam).
    pub fn m2(&self) -> Vec3<R> {
        self.m + self.d * self.length
    }
}

/// Bulged beam ("端点膨張型"): a capsule plus extra sphere fields at the head `M₂` and the muzzle
/// `M`; the energies add (SPEC.md §1.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BeamField<R> {
    /// The beam body.
    pub capsule: CapsuleField<R>,
    /// Strength of the bulb at the head `M₂` (0: none).
    pub head_alpha: R,
    /// Strength of the bulb at the muzzle `M` (0: none).
    pub muzzle_alpha: R,
}

/// `∫_{t0}^{t1}` of the sphere field `α_s/ρ` (faithful) or `α_s/ρ²` (inverse square) along `ray`,
/// `ρ² = |V(t) − M|² + r_c²` (002 eq. 3.4, 3.6, 3.8–3.9 with SPEC.md §1.2's corrected `asinh`
/// denominator; see the [module docs](self) for both laws and the stable forms).
#[inline]
pub fn sphere_energy<R: Real>(p: &FieldParams<R>, ray: &Ray<R>, t0: R, t1: R, f: &SphereField<R>) -> R {
    let axis = RayAxis::new(ray.dir);
    let q = RayQuadratic::new(&axis, ray.origin - f.center, p.core_radius * p.core_radius);
    scaled(q.integral(p.falloff, t0, t1), f.alpha)
}

/// `∫_{t0}^{t1}` of the infinite cylinder field `α_c/ρ` (faithful) or `α_c/ρ²` (inverse square)
/// along `ray`, `ρ²` = squared distance to the axis `+ r_c²` (002 eq. 3.5, 3.7–3.9, SPEC.md §1.2:
/// `D' = |Q × D|²` and `D'F − E² = ((Q × w)·D)²` from cross products; a ray parallel to the axis,
/// `D' = 0`, integrates the constant density). Inverse square to `t1 = ∞` along the axis diverges
/// and returns [`ENERGY_MAX`]`·α`.
#[inline]
pub fn cylinder_energy<R: Real>(p: &FieldParams<R>, ray: &Ray<R>, t0: R, t1: R, f: &CylinderField<R>) -> R {
    let axis = RayAxis::new(ray.dir.cross(f.dir));
    let v = (ray.origin - f.point).cross(f.dir);
    let q = RayQuadratic::new(&axis, v, p.core_radius * p.core_radius);
    scaled(q.integral(p.falloff, t0, t1), f.alpha)
}

/// The capsule's pieces along a ray, kept so the beam can reuse the end spheres' quadratics.
struct CapsuleParts<R> {
    /// Sphere around `M`.
    at_m: RayQuadratic<R>,
    /// Sphere around `M₂`.
    at_m2: RayQuadratic<R>,
    /// The capsule's energy.
    energy: R,
}

/// The capsule's split and pieces (002 eq. 3.10–3.11); mirrored eight rays at a time by
/// `lanes::capsule_parts` (keep in sync).
#[inline(always)]
fn capsule_parts<R: Real>(
    p: &FieldParams<R>,
    ray: &Ray<R>,
    t0: R,
    t1: R,
    f: &CapsuleField<R>,
) -> CapsuleParts<R> {
    // An empty or NaN interval: every piece empty (the clamps below would turn a NaN into an end).
    let nonempty = t1 > t0;
    let (t0, t1) = if nonempty { (t0, t1) } else { (R::ZERO, R::ZERO) };
    let rc2 = p.core_radius * p.core_radius;
    let q = ray.dir;
    let w = ray.origin - f.m;
    let sphere_axis = RayAxis::new(q);
    let at_m = RayQuadratic::new(&sphere_axis, w, rc2);
    let at_m2 = RayQuadratic::new(&sphere_axis, w - f.d * f.length, rc2);
    let cyl = RayQuadratic::new(&RayAxis::new(q.cross(f.d)), w.cross(f.d), rc2);
    // Axial coordinate along the ray: z(t) = ds + t·dq; the planes are z = 0 (M) and z = length (M₂).
    let dq = q.dot(f.d);
    let ds = w.dot(f.d);
    let inf = R::INFINITY;
    // (first plane crossed, second plane crossed, sphere before the first, sphere after the second)
    let (lo, hi, first, last) = if dq > R::ZERO {
        (-ds / dq, (f.length - ds) / dq, &at_m, &at_m2)
    } else if dq < R::ZERO {
        ((f.length - ds) / dq, -ds / dq, &at_m2, &at_m)
    } else if ds < R::ZERO {
        (inf, inf, &at_m, &at_m2)
    } else if ds > f.length {
        (-inf, -inf, &at_m, &at_m2)
    } else {
        (-inf, inf, &at_m, &at_m2)
    };
    let lo = lo.clamp(t0, t1);
    let hi = hi.clamp(lo, t1);
    let fo = p.falloff;
    let spheres = first.integral(fo, t0, lo) + last.integral(fo, hi, t1);
    let energy = saturate(scaled(spheres, f.alpha_s) + scaled(cyl.integral(fo, lo, hi), f.alpha_c));
    CapsuleParts { at_m, at_m2, energy }
}

/// `∫_{t0}^{t1}` of the capsule ("straight beam") field along `ray` (002 eq. 3.10–3.11, SPEC.md
/// §1.2): the sphere field around `M` before the plane through `M` with normal `D`, the cylinder
/// field between the planes, the sphere field around `M₂` after, split at
/// `t_i = (D·M_i − D·S)/(D·Q)` and summed in ray order, each piece in the closed form of
/// [`sphere_energy`] / [`cylinder_energy`] (faithful `α/ρ`, or inverse square `α/ρ²`).
/// `D·Q = 0` keeps the whole ray in one region; `length = 0` is the sphere field around `M`.
#[inline]
pub fn capsule_energy<R: Real>(p: &FieldParams<R>, ray: &Ray<R>, t0: R, t1: R, f: &CapsuleField<R>) -> R {
    capsule_parts(p, ray, t0, t1, f).energy
}

/// `∫_{t0}^{t1}` of the bulged-beam ("端点膨張型") field along `ray`: [`capsule_energy`] plus sphere
/// fields of strength `head_alpha` at `M₂` and `muzzle_alpha` at `M` over the whole interval
/// (002 §3.3.3, eq. 3.4 and 3.11; SPEC.md §1.2), faithful `α/ρ` or inverse square `α/ρ²`.
#[inline]
pub fn beam_energy<R: Real>(p: &FieldParams<R>, ray: &Ray<R>, t0: R, t1: R, f: &BeamField<R>) -> R {
    let parts = capsule_parts(p, ray, t0, t1, &f.capsule);
    let mut e = parts.energy;
    if f.head_alpha != R::ZERO {
        e = saturate(e + scaled(parts.at_m2.integral(p.falloff, t0, t1), f.head_alpha));
    }
    if f.muzzle_alpha != R::ZERO {
        e = saturate(e + scaled(parts.at_m.integral(p.falloff, t0, t1), f.muzzle_alpha));
    }
    e
}
