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
