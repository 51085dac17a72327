//! The two shadow-map positions, the penumbra's brightness, bilinear interpolation of a coarse
//! grid and a pixel's class (003 §4.1–4.4, SPEC.md §4).

use crate::Vec3f;

/// The two shadow-map positions of 003 §4.1: with `P = (L − G)/|L − G|` (unit, from the point of
/// interest `G` towards the light centre `L`), `L₁ = L + l·P` and `L₂ = L − l·P`. `None` when
/// `L = G` (no direction).
pub fn light_pair(light: Vec3f, interest: Vec3f, l: f32) -> Option<(Vec3f, Vec3f)> {
    let p = (light - interest).try_normalize()?;
    Some((light + p * l, light - p * l))
}

/// A penumbra pixel's brightness from its distance `d1` to the nearest umbra pixel and `d2` to the
/// nearest lit pixel (SPEC.md §4.2): `d1 / (d1 + d2)`, 0 at the umbra's edge and 1 at the lit
/// edge. *Correction:* 003 prints `D₂/(D₁+D₂)`, which contradicts its own statement that pixels
/// near the umbra are darker. Both distances 0 (or not finite) give ½, never NaN.
#[inline]
pub fn penumbra_brightness(d1: f32, d2: f32) -> f32 {
    let s = d1 + d2;
    if s > 0.0 && s.is_finite() {
        (d1 / s).clamp(0.0, 1.0)
    } else if d1.is_infinite() && !d2.is_infinite() {
        1.0
    } else if d2.is_infinite() && !d1.is_infinite() {
        0.0
    } else {
        0.5
    }
}

/// hadou's penumbra brightness (SPEC.md §4.2 as corrected, made perspective-correct): the fraction
/// of the segment light `L₁L₂` that a penumbra pixel sees, `k·D₁/(k·D₁ + D₂)` with
/// `k = A₁/A₂` ([`segment_ratio`]).
///
/// The two maps sample a light spread along the axis from `L₁` (axial distance `A₁ = A + l` from
/// an occluder edge) to `L₂` (`A₂ = A − l`). A point light at axial distance `a` throws that edge's
/// shadow `∝ 1/a` beyond the edge on a receiver, so the shadows of the lights between `L₁` and
/// `L₂` are spaced evenly in `1/a`, not in image distance: at the fraction `s = D₁/(D₁ + D₂)` of
/// the band from the umbra's edge (`L₁`'s shadow edge) lies the edge of the light at
/// `1/a = 1/A₁ + s·(1/A₂ − 1/A₁)`, and the pixel sees the lights farther than that, the fraction
/// `(A₁ − a)/(A₁ − A₂) = k·s/(1 + (k − 1)·s) = k·D₁/(k·D₁ + D₂)` of the segment. `k = 1` (a light
/// far from its occluders) is 003's linear ratio [`penumbra_brightness`] bit for bit. 0 at the
/// umbra's edge, 1 at the lit edge, never NaN.
#[inline]
pub fn segment_brightness(d1: f32, d2: f32, k: f32) -> f32 {
    penumbra_brightness(k * d1, d2)
}

/// The ratio `k = A₁/A₂ = (D + l)/(D − l)` of [`segment_brightness`]: the distances of the two map
/// positions `L ± l·P` from an occluder at the point of interest, `D = |L − G|` and `l` the light's
/// size parameter. 1 where `l ≤ 0` or `D` is infinite, at most `10⁶` (`l` near or past `D`),
/// never NaN.
#[inline]
pub fn segment_ratio(l: f32, d: f32) -> f32 {
    if l.is_nan() || l <= 0.0 || !d.is_finite() {
        return 1.0;
    }
    if d <= l {
        return 1e6;
    }
    ((d + l) / (d - l)).clamp(1.0, 1e6)
}

/// Standard bilinear interpolation of the four grid values around a pixel (SPEC.md §4.3), `fx`,
/// `fy ∈ [0, 1]` its offsets from the top-left grid pixel in grid cells:
/// `(1−fx)(1−fy)·v00 + fx(1−fy)·v10 + (1−fx)fy·v01 + fx·fy·v11`. *Correction:* 003's eq. 3.6 gives
/// the first corner the weight `Q·dx` where bilinear interpolation has `1 − Q·dx`.
#[inline]
pub fn bilinear(v00: f32, v10: f32, v01: f32, v11: f32, fx: f32, fy: f32) -> f32 {
    let top = v00 + (v10 - v00) * fx;
    let bottom = v01 + (v11 - v01) * fx;
    top + (bottom - top) * fy
}

/// A pixel's class under 003 §4.1: shadowed in both maps, in one, or in neither.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Class {
    /// No visible surface (background, outline hull): neither classified nor searched for.
    None = 0,
    /// Shadowed in both maps.
    Umbra = 1,
    /// Shadowed in exactly one.
    Penumbra = 2,
    /// Shadowed in neither.
    Lit = 3,
}

impl Class {
    /// The class from the two maps' verdicts.
    #[inline]
    pub fn of(shadowed1: bool, shadowed2: bool) -> Class {
        match (shadowed1, shadowed2) {
            (true, true) => Class::Umbra,
            (false, false) => Class::Lit,
            _ => Class::Penumbra,
        }
    }
}

/// Radius of the disc light whose penumbra has the width of 003's two-map band at an occluder
/// edge: with the maps at `D ∓ l` on the axis and the edge at lateral offset `r` and axial
/// distance `D`, a receiver at `D_r` sees the edge's two shadows `2·l·r·(D_r − D)/(D² − l²)` apart,
/// the width a disc of radius `R` gives is `2·R·(D_r − D)/D`, so `R = l·r·D/(D² − l²)`. The
/// ground truth of `hadou bench shadows` uses it with `r` the point of interest's bounding radius.
pub fn implied_disc_radius(l: f32, r: f32, d: f32) -> f32 {
    let den = d * d - l * l;
    if den > 0.0 {
        l * r * d / den
    } else {
        l
    }
}
