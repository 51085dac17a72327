//! The density laws, the ray and the analytic fields (sphere, cylinder, capsule, bulged beam) whose
//! energies `integral.rs` integrates: the types the scene builds and both backends read.

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

/// The distance attenuation `(1 − t/t_far)^j` of 002 eq. 3.23 (SPEC.md §1.4) on one ray: the
/// density at ray parameter `t` is multiplied by it, and by 0 from the far point `t_far` on.
///
/// `t_far` is the far point's ray parameter: 1 for [`Falloff::Faithful`] (`t ∈ [0, 1]` from the
/// eye to the far point), the far point's distance for [`Falloff::InverseSquare`] (a unit `dir`).
/// `j = 0` is no attenuation: every `*_attenuated` function then returns exactly what its
/// unattenuated twin returns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attenuation<R> {
    /// Exponent `j ≥ 0` (0: none).
    pub j: R,
    /// The far point's ray parameter (`> 0`).
    pub t_far: R,
}

impl<R: Real> Attenuation<R> {
    /// No attenuation (`j = 0`).
    pub fn none() -> Self {
        Self { j: R::ZERO, t_far: R::ONE }
    }

    /// Whether it changes anything (`j > 0`).
    #[inline(always)]
    pub fn is_active(&self) -> bool {
        self.j > R::ZERO
    }

    /// `(1 − t/t_far)^j`, 0 from the far point on (002 eq. 3.23, SPEC.md §1.4).
    #[inline(always)]
    pub fn factor(&self, t: R) -> R {
        let h = R::ONE - t / self.t_far;
        if h > R::ZERO {
            h.powf(self.j)
        } else {
            R::ZERO
        }
    }
}
