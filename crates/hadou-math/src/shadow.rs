//! Hard shadows by projection: planar shadows from a directional light (001, SPEC.md §3), the
//! wave's stylized shadows (000 §2.4, SPEC.md §2.4, with SPEC's corrected direction), and the
//! orthographic shadow-map frame hadou uses for receivers that are not planes.
//!
//! Both kinds are one operation: every point `P` of a caster moves along a unit direction `k`
//! onto the receiver plane, `G = P + t·k` with `t = ((O − P)·n) / (k·n)`. The sun gives `k = L`
//! (001's oblique projection, `p' = p − ((p − o)·n / (L·n)) L`); the wave gives one `k` per caster
//! from [`wave_direction`]. Points with `t < 0` lie beyond the plane as seen from the light and
//! cast nothing (000 §2.4: "fully transparent").

use crate::{Real, Vec3, Vec3f};

/// Below this `−k·n` a light grazes the plane and casts no shadow; between it and
/// [`HORIZON_FULL`] the shadow fades in ([`horizon_fade`]). `−k·n = 10⁻³` is an elevation of
/// 0.057°, where a shadow is 1000× longer than its caster is tall.
pub const HORIZON_NONE: f32 = 1e-3;
/// Above this `−k·n` (an elevation of 1.15°) a shadow has its full opacity.
pub const HORIZON_FULL: f32 = 2e-2;

/// hadou's default longest-shadow angle `θ`, in degrees. 000 §2.4 leaves `θ` to the user and prints
/// no value; at 60° a shadow is at most `tan 60° ≈ 1.73` times as long as its caster is high.
pub const DEFAULT_THETA_DEG: f32 = 60.0;

/// A receiver plane: a point on it and the unit normal of its lit side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane<R: Real = f32> {
    /// A point `O` of the plane.
    pub point: Vec3<R>,
    /// Unit normal `n`, pointing to the side the light comes from.
    pub normal: Vec3<R>,
}

impl<R: Real> Plane<R> {
    /// The plane through `I`, `J`, `K` with 000 §2.4's orientation: `X = J − I`, `x = K − I`,
    /// normal `Y = x × X` (the thesis assumes `X`, `x` unit and orthogonal; any two independent
    /// directions give the same plane, so they are only normalised here). `None` when the points
    /// coincide or are collinear: `|x × X| ≤ 10⁻⁶ |x| |X|` (an angle under 10⁻⁶ rad).
    pub fn from_points(i: Vec3<R>, j: Vec3<R>, k: Vec3<R>) -> Option<Self> {
        let (big_x, small_x) = (j - i, k - i);
        let y = small_x.cross(big_x);
        let scale = big_x.length() * small_x.length();
        // Written so that a NaN anywhere refuses the points too.
        let spans = scale > R::ZERO && y.length() > R::from_f64(1e-6) * scale;
        if !spans {
            return None;
        }
        Some(Plane { point: i, normal: y.try_normalize()? })
    }

    /// The plane through `point` with normal `normal` (any length); `None` for a zero normal.
    pub fn new(point: Vec3<R>, normal: Vec3<R>) -> Option<Self> {
        Some(Plane { point, normal: normal.try_normalize()? })
    }

    /// Signed distance of `p` from the plane, positive on the lit side.
    #[inline]
    pub fn distance(&self, p: Vec3<R>) -> R {
        (p - self.point).dot(self.normal)
    }
}

/// The projection of `p` along unit `k` onto `plane`: `(G, t)` with `G = P + t·k`,
/// `t = ((O − P)·n) / (k·n)` (000 §2.4's `t = ((I − P)·Y) / (k·Y)`; for the sun `k = L` it is
/// 001's `p' = p − ((p − o)·n / (L·n)) L`). `t < 0`: `p` is beyond the plane as seen from the light
/// and casts nothing. Callers only project when `k·n < −`[`HORIZON_NONE`], so `t` is finite.
/// WGSL twin: `vs_plane` in hadou-gpu's `shadow_raster.wgsl`.
#[inline]
pub fn project<R: Real>(p: Vec3<R>, k: Vec3<R>, plane: &Plane<R>) -> (Vec3<R>, R) {
    let t = (plane.point - p).dot(plane.normal) / k.dot(plane.normal);
    (p + k * t, t)
}

/// Opacity factor of a shadow cast along unit `k` onto a surface whose lit side faces unit `n`:
/// 0 when the light is at or below the horizon (`−k·n ≤` [`HORIZON_NONE`], parallel rays included),
/// 1 from [`HORIZON_FULL`] up, a smoothstep between, so a setting sun's shadow fades instead of
/// growing without bound or vanishing in one frame.
#[inline]
pub fn horizon_fade(k: Vec3f, n: Vec3f) -> f32 {
    let c = -k.dot(n);
    let x = ((c - HORIZON_NONE) / (HORIZON_FULL - HORIZON_NONE)).clamp(0.0, 1.0);
    if x.is_nan() {
        return 0.0;
    }
    x * x * (3.0 - 2.0 * x)
}

/// The projection direction of a wave shadow (000 §2.4, SPEC.md §2.4 with its correction).
///
/// `b` is the caster's centre `B`, `w` its light point `W` (the nearest point of the wave's centre
/// line to `B`), `up` the unit normal `Y` of the receiver's lit side, `theta` the longest-shadow angle
/// `θ ∈ [0, π/2)` in radians. With `e = (B − W)/|B − W|` and `λ = arccos(e·(−Y))`: if `λ ≤ θ`,
/// `k = e`; otherwise `k` keeps `e`'s azimuth at exactly `θ` from `−Y`:
/// `i = normalize((e·X)X + (e·Z)Z)` (the part of `e` in the plane), `k = sin θ · i − cos θ · Y`.
/// The printed quaternion turns `i` upwards (to 120° from `−Y` for θ = 60°); SPEC.md's correction,
/// followed here, measures θ from `−Y`.
///
/// Degenerate cases stay finite and continuous where the geometry allows: `B = W` (the wave passes
/// through the centre) and `e = ±Y` with `λ > θ` (no azimuth) cast straight down, `k = −Y`.
pub fn wave_direction(b: Vec3f, w: Vec3f, up: Vec3f, theta: f32) -> Vec3f {
    let down = -up;
    let Some(e) = (b - w).try_normalize() else {
        return down;
    };
    // λ ≤ θ ⇔ e·(−Y) ≥ cos θ (arccos is decreasing), without an arccos.
    let (s, c) = (theta.sin(), theta.cos());
    if e.dot(down) >= c {
        return e;
    }
    let horizontal = e - up * e.dot(up);
    match horizontal.try_normalize() {
        Some(i) if horizontal.length() > 1e-6 => i * s - up * c,
        _ => down,
    }
}

/// An orthographic shadow-map frame along unit `k` around a bounding sphere (hadou's receivers
/// that are not planes): map coordinates `(s, t) ∈ [0, 1]²` across the sphere, depth `∈ [0, 1]`
/// from its near to its far point along `k`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapFrame {
    /// Sphere centre.
    pub center: Vec3f,
    /// Unit projection direction (depth grows along it).
    pub k: Vec3f,
    /// Unit map `s` axis.
    pub u: Vec3f,
    /// Unit map `t` axis.
    pub v: Vec3f,
    /// Sphere radius, `> 0`.
    pub radius: f32,
}

impl MapFrame {
    /// The frame along unit `k` around the sphere `(center, radius)` (radius at least 10⁻⁶).
    pub fn new(k: Vec3f, center: Vec3f, radius: f32) -> Self {
        let (u, v) = k.orthonormal_basis();
        MapFrame { center, k, u, v, radius: radius.max(1e-6) }
    }

    /// `(s, t, depth)` of world point `p`: `s = ((p − c)·u / r + 1) / 2`, likewise `t` with `v`,
    /// `depth = ((p − c)·k / r + 1) / 2`. Not clamped: a receiver beyond the sphere has depth > 1.
    /// WGSL twin: `map_coords` in hadou-gpu's `common.wgsl`.
    #[inline]
    pub fn to_map(&self, p: Vec3f) -> [f32; 3] {
        let d = p - self.center;
        let inv = 0.5 / self.radius;
        [d.dot(self.u) * inv + 0.5, d.dot(self.v) * inv + 0.5, d.dot(self.k) * inv + 0.5]
    }

    /// The depth bias for a map of `size` texels: a receiver point is shadowed only where it lies
    /// more than this beyond the stored caster depth. Two texels' worth of the map's footprint
    /// (`2 · 2r/size` in world units, in depth units `2/size`) keeps a caster that touches the
    /// receiver from shadowing the receiver's own texels at any slope up to 45°.
    #[inline]
    pub fn bias(size: u32) -> f32 {
        2.0 / size.max(1) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f32, y: f32, z: f32) -> Vec3f {
        Vec3::new(x, y, z)
    }

    #[test]
    fn three_points_orientation_matches_the_thesis() {
        // X along +x, x along +z: Y = x × X = +y.
        let p = Plane::from_points(v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 0.0, 1.0)).unwrap();
        assert!((p.normal - Vec3f::Y).length() < 1e-7);
        assert!(Plane::from_points(v(0.0, 0.0, 0.0), v(1.0, 1.0, 1.0), v(2.0, 2.0, 2.0)).is_none());
        assert!(Plane::from_points(v(1.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 0.0, 1.0)).is_none());
        assert!(Plane::new(v(0.0, 0.0, 0.0), Vec3f::ZERO).is_none());
    }

    #[test]
    fn projection_lands_on_the_plane_along_k() {
        let plane = Plane::new(v(0.0, 1.0, 0.0), v(0.0, 2.0, 0.0)).unwrap();
        let k = v(0.6, -0.8, 0.0);
        let (g, t) = project(v(1.0, 5.0, 2.0), k, &plane);
        assert!(plane.distance(g).abs() < 1e-6);
        assert!((t - 5.0).abs() < 1e-6, "t = {t}");
        let (_, t) = project(v(1.0, 0.0, 2.0), k, &plane);
        assert!(t < 0.0);
    }

    #[test]
    fn horizon_fade_is_continuous_and_bounded() {
        let n = Vec3f::Y;
        assert_eq!(horizon_fade(v(1.0, 0.0, 0.0), n), 0.0);
        assert_eq!(horizon_fade(v(0.0, 1.0, 0.0), n), 0.0);
        assert_eq!(horizon_fade(v(0.0, -1.0, 0.0), n), 1.0);
        let mut prev = 0.0;
        for i in 0..=1000 {
            let e = (i as f32 * 0.003f32).to_radians();
            let f = horizon_fade(v(e.cos(), -e.sin(), 0.0), n);
            assert!(f >= prev && (f - prev) < 0.05, "jump at {i}: {prev} → {f}");
            prev = f;
        }
    }
}
