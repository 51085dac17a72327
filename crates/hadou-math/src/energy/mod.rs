//! Energy fields of the analytic wave shapes and their exact line integrals (thesis 002 §3.3,
//! SPEC.md §1.2).
//!
//! PLACEHOLDER BODIES: the naive formulas below are being replaced by the stable closed forms;
//! the public types and signatures are the contract the backends build against.

use crate::{Real, Vec3};

/// How energy density falls off with distance and what measure the ray integral uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Falloff {
    /// The thesis (002 eq. 3.6–3.11): density `α / r`, integrated over the normalized ray
    /// parameter `t ∈ [0, 1]` from the eye `S` to the far point `E` (so the value scales with
    /// `1/|E − S|`). The ray's `dir` is `Q = E − S`.
    Faithful,
    /// hadou's default: density `α / r²`, integrated over arc length from the eye to the first
    /// occluder or to infinity, so the value never depends on where the far plane is. The ray's
    /// `dir` is a unit vector.
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

/// `∫_{t0}^{t1}` of the sphere field along `ray`.
pub fn sphere_energy<R: Real>(p: &FieldParams<R>, ray: &Ray<R>, t0: R, t1: R, f: &SphereField<R>) -> R {
    let w = ray.origin - f.center;
    let a = ray.dir.length_squared();
    let b = ray.dir.dot(w);
    let c = w.length_squared();
    quad_integral(p, a, b, c, t0, t1) * f.alpha
}

/// `∫_{t0}^{t1}` of the cylinder field along `ray`.
pub fn cylinder_energy<R: Real>(p: &FieldParams<R>, ray: &Ray<R>, t0: R, t1: R, f: &CylinderField<R>) -> R {
    let w = ray.origin - f.point;
    let qd = ray.dir.dot(f.dir);
    let wd = w.dot(f.dir);
    let a = ray.dir.length_squared() - qd * qd;
    let b = ray.dir.dot(w) - qd * wd;
    let c = w.length_squared() - wd * wd;
    quad_integral(p, a, b, c, t0, t1) * f.alpha
}

/// `∫_{t0}^{t1}` of the capsule field along `ray`.
pub fn capsule_energy<R: Real>(p: &FieldParams<R>, ray: &Ray<R>, t0: R, t1: R, f: &CapsuleField<R>) -> R {
    let dq = ray.dir.dot(f.d);
    let ds = (ray.origin - f.m).dot(f.d);
    let s1 = SphereField { center: f.m, alpha: f.alpha_s };
    let s2 = SphereField { center: f.m2(), alpha: f.alpha_s };
    let cyl = CylinderField { point: f.m, dir: f.d, alpha: f.alpha_c };
    if dq == R::ZERO {
        return if ds < R::ZERO {
            sphere_energy(p, ray, t0, t1, &s1)
        } else if ds > f.length {
            sphere_energy(p, ray, t0, t1, &s2)
        } else {
            cylinder_energy(p, ray, t0, t1, &cyl)
        };
    }
    let ta = -ds / dq;
    let tb = (f.length - ds) / dq;
    let (lo, hi, first, last) = if dq > R::ZERO { (ta, tb, s1, s2) } else { (tb, ta, s2, s1) };
    let c = |x: R| x.clamp(t0, t1);
    sphere_energy(p, ray, t0, c(lo), &first)
        + cylinder_energy(p, ray, c(lo), c(hi), &cyl)
        + sphere_energy(p, ray, c(hi), t1, &last)
}

/// `∫_{t0}^{t1}` of the bulged-beam field along `ray`.
pub fn beam_energy<R: Real>(p: &FieldParams<R>, ray: &Ray<R>, t0: R, t1: R, f: &BeamField<R>) -> R {
    let mut e = capsule_energy(p, ray, t0, t1, &f.capsule);
    if f.head_alpha != R::ZERO {
        e += sphere_energy(p, ray, t0, t1, &SphereField { center: f.capsule.m2(), alpha: f.head_alpha });
    }
    if f.muzzle_alpha != R::ZERO {
        e += sphere_energy(p, ray, t0, t1, &SphereField { center: f.capsule.m, alpha: f.muzzle_alpha });
    }
    e
}

fn quad_integral<R: Real>(p: &FieldParams<R>, a: R, b: R, c: R, t0: R, t1: R) -> R {
    if t1 <= t0 {
        return R::ZERO;
    }
    let rc2 = p.core_radius * p.core_radius;
    let c = c + rc2;
    let h = (a * c - b * b).max(R::MIN_POSITIVE);
    match p.falloff {
        Falloff::Faithful => {
            if a <= R::EPSILON {
                return (t1 - t0) / c.sqrt();
            }
            let sa = a.sqrt();
            let sh = h.sqrt();
            (((a * t1 + b) / sh).asinh() - ((a * t0 + b) / sh).asinh()) / sa
        }
        Falloff::InverseSquare => {
            if a <= R::EPSILON {
                return (t1 - t0) / c;
            }
            let sh = h.sqrt();
            let x1 = if t1.is_finite() { ((a * t1 + b) / sh).atan() } else { R::PI * R::HALF };
            (x1 - ((a * t0 + b) / sh).atan()) / sh
        }
    }
}
