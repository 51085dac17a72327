//! The exact line integrals of the analytic fields, one ray at a time: each shape reduced to
//! [`RayQuadratic`] pieces (see the [`energy`](crate::energy) module docs for the two laws, the
//! stable forms and the capsule split); `lanes.rs` mirrors them eight rays at a time.

use super::field::{BeamField, CapsuleField, CylinderField, FieldParams, Ray, SphereField};
use super::kernel::{saturate, scaled, RayAxis, RayQuadratic};
use crate::{Real, Vec3};

/// `∫_{t0}^{t1}` of the sphere field `α_s/ρ` (faithful) or `α_s/ρ²` (inverse square) along `ray`,
/// `ρ² = |V(t) − M|² + r_c²` (002 eq. 3.4, 3.6, 3.8–3.9 with SPEC.md §1.2's corrected `asinh`
/// denominator; see the [module docs](crate::energy) for both laws and the stable forms).
#[inline]
pub fn sphere_energy<R: Real>(p: &FieldParams<R>, ray: &Ray<R>, t0: R, t1: R, f: &SphereField<R>) -> R {
    let q = sphere_quadratic(p, ray, f.center);
    scaled(q.integral(p.falloff, t0, t1), f.alpha)
}

/// The sphere's `|V(t) − M|² + r_c²` along `ray` (002 eq. 3.6).
#[inline(always)]
pub(super) fn sphere_quadratic<R: Real>(
    p: &FieldParams<R>,
    ray: &Ray<R>,
    center: Vec3<R>,
) -> RayQuadratic<R> {
    let axis = RayAxis::new(ray.dir);
    RayQuadratic::new(&axis, ray.origin - center, p.core_radius * p.core_radius)
}

/// The cylinder's squared axis distance `+ r_c²` along `ray` (002 eq. 3.7, SPEC.md §1.2).
#[inline(always)]
pub(super) fn cylinder_quadratic<R: Real>(
    p: &FieldParams<R>,
    ray: &Ray<R>,
    f: &CylinderField<R>,
) -> RayQuadratic<R> {
    let axis = RayAxis::new(ray.dir.cross(f.dir));
    let v = (ray.origin - f.point).cross(f.dir);
    RayQuadratic::new(&axis, v, p.core_radius * p.core_radius)
}

/// `∫_{t0}^{t1}` of the infinite cylinder field `α_c/ρ` (faithful) or `α_c/ρ²` (inverse square)
/// along `ray`, `ρ²` = squared distance to the axis `+ r_c²` (002 eq. 3.5, 3.7–3.9, SPEC.md §1.2:
/// `D' = |Q × D|²` and `D'F − E² = ((Q × w)·D)²` from cross products; a ray parallel to the axis,
/// `D' = 0`, integrates the constant density). Inverse square to `t1 = ∞` along the axis diverges
/// and returns [`ENERGY_MAX`](crate::energy::ENERGY_MAX)`·α`.
#[inline]
pub fn cylinder_energy<R: Real>(p: &FieldParams<R>, ray: &Ray<R>, t0: R, t1: R, f: &CylinderField<R>) -> R {
    let q = cylinder_quadratic(p, ray, f);
    scaled(q.integral(p.falloff, t0, t1), f.alpha)
}

/// The capsule's pieces along a ray, kept so the beam can reuse the end spheres' quadratics.
pub(super) struct CapsuleParts<R> {
    /// Sphere around `M`.
    pub(super) at_m: RayQuadratic<R>,
    /// Sphere around `M₂`.
    pub(super) at_m2: RayQuadratic<R>,
    /// The capsule's energy.
    pub(super) energy: R,
}

/// The capsule's split and pieces (002 eq. 3.10–3.11), each piece integrated by `piece(quadratic,
/// from, to)` ([`RayQuadratic::integral`], or its attenuated form); mirrored eight rays at a time
/// by `lanes::capsule_parts` (keep in sync).
#[inline(always)]
pub(super) fn capsule_parts<R: Real>(
    p: &FieldParams<R>,
    ray: &Ray<R>,
    t0: R,
    t1: R,
    f: &CapsuleField<R>,
    piece: impl Fn(&RayQuadratic<R>, R, R) -> R,
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
    let spheres = piece(first, t0, lo) + piece(last, hi, t1);
    let energy = saturate(scaled(spheres, f.alpha_s) + scaled(piece(&cyl, lo, hi), f.alpha_c));
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
    capsule_parts(p, ray, t0, t1, f, |q, a, b| q.integral(p.falloff, a, b)).energy
}

/// `∫_{t0}^{t1}` of the bulged-beam ("端点膨張型") field along `ray`: [`capsule_energy`] plus sphere
/// fields of strength `head_alpha` at `M₂` and `muzzle_alpha` at `M` over the whole interval
/// (002 §3.3.3, eq. 3.4 and 3.11; SPEC.md §1.2), faithful `α/ρ` or inverse square `α/ρ²`.
#[inline]
pub fn beam_energy<R: Real>(p: &FieldParams<R>, ray: &Ray<R>, t0: R, t1: R, f: &BeamField<R>) -> R {
    let parts = capsule_parts(p, ray, t0, t1, &f.capsule, |q, a, b| q.integral(p.falloff, a, b));
    let mut e = parts.energy;
    if f.head_alpha != R::ZERO {
        e = saturate(e + scaled(parts.at_m2.integral(p.falloff, t0, t1), f.head_alpha));
    }
    if f.muzzle_alpha != R::ZERO {
        e = saturate(e + scaled(parts.at_m.integral(p.falloff, t0, t1), f.muzzle_alpha));
    }
    e
}
