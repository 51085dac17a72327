//! The MToon look of VRM avatars (`VRMC_materials_mtoon` 1.0, its "Lighting", "Rim Lighting",
//! "MatCap" and "UV Animation" sections), and the energy wave lighting an MToon surface with the
//! same step over 000's unclamped `m = N·L` (000 §2.1, SPEC.md §2.1). `hadou-cpu`'s shading
//! composes these; `hadou-gpu` mirrors them in `shaders/shading.wgsl` (keep in sync).

use crate::Vec3f;

/// `saturate((t − a)/(b − a))` (MToon "Lighting": the toony step); for `b ≤ a` the hard step
/// `t ≥ a` (shadingToonyFactor 1).
#[inline]
pub fn linearstep(a: f32, b: f32, t: f32) -> f32 {
    if b > a {
        ((t - a) / (b - a)).clamp(0.0, 1.0)
    } else if t >= a {
        1.0
    } else {
        0.0
    }
}

/// The MToon shading term (MToon "Lighting"): `linearstep(−1 + toony, 1 − toony, n_dot_l +
/// shift)`, `shift` the shading shift factor plus the shift texture's red channel times its scale.
/// For the scene light `n_dot_l = N·(−L)`; for a wave, 000 §2.1's unclamped `m = N·L_wave`
/// towards the nearest point of its centre line.
#[inline]
pub fn shading(n_dot_l: f32, shift: f32, toony: f32) -> f32 {
    linearstep(-1.0 + toony, 1.0 - toony, n_dot_l + shift)
}

/// The lit colour (MToon "Lighting"): `mix(shade, base, shading) · light`, `shade` the shade
/// colour times its texture, `base` the albedo.
#[inline]
pub fn lit(shade: [f32; 3], base: [f32; 3], shading: f32, light: [f32; 3]) -> [f32; 3] {
    std::array::from_fn(|k| (shade[k] + (base[k] - shade[k]) * shading) * light[k])
}

/// The parametric rim (MToon "Rim Lighting"): `pow(saturate(1 − N·V + lift), power) · colour`,
/// `V` the unit vector towards the eye; `power` below 0 counts as 0, and `0⁰ = 1`.
#[inline]
pub fn parametric_rim(n_dot_v: f32, lift: f32, power: f32, color: [f32; 3]) -> [f32; 3] {
    let x = (1.0 - n_dot_v + lift).clamp(0.0, 1.0);
    let p = power.max(0.0);
    let f = if x > 0.0 {
        x.powf(p)
    } else if p == 0.0 {
        1.0
    } else {
        0.0
    };
    color.map(|c| c * f)
}

/// The rim lighting factor (MToon "Rim Lighting"): `mix(1, lighting, rim_lighting_mix)` per
/// channel, `lighting` the light reaching the surface.
#[inline]
pub fn lighting_mix(lighting: [f32; 3], mix: f32) -> [f32; 3] {
    lighting.map(|l| 1.0 + (l - 1.0) * mix)
}

/// The matcap texture coordinates of unit normal `n` seen along the unit vector `v` towards the
/// eye (MToon "MatCap"): the view-space axes `x = normalize(v.z, 0, −v.x)` (`(1, 0, 0)` looking
/// straight up or down) and `y = v × x`, and `uv = (½ + 0.495·(x·n), ½ − 0.495·(y·n))` (glTF's
/// `v` runs down the image, so the top of the matcap lights normals that point up).
#[inline]
pub fn matcap_uv(n: Vec3f, v: Vec3f) -> [f32; 2] {
    let x = Vec3f::new(v.z, 0.0, -v.x).normalize_or(Vec3f::new(1.0, 0.0, 0.0));
    let y = v.cross(x);
    [0.5 + 0.495 * x.dot(n), 0.5 - 0.495 * y.dot(n)]
}

/// The animated texture coordinates (MToon "UV Animation"): `uv` rotated about (½, ½) by
/// `θ = turn·mask` (`turn` = rotation speed × time, radians; `θ` reduced to [0, 2π), a non-finite
/// `θ` counting as 0) and then
/// moved by `scroll·mask` (`scroll` = scroll speeds × time), `mask` the mask texture's channel.
#[inline]
pub fn uv_animation(uv: [f32; 2], mask: f32, scroll: [f32; 2], turn: f32) -> [f32; 2] {
    let tau = std::f32::consts::TAU;
    let a = turn * mask;
    let a = if a.is_finite() { a - tau * (a / tau).floor() } else { 0.0 };
    let (s, c) = (a.sin(), a.cos());
    let (u, v) = (uv[0] - 0.5, uv[1] - 0.5);
    [c * u - s * v + 0.5 + scroll[0] * mask, s * u + c * v + 0.5 + scroll[1] * mask]
}

/// A texel of one of MToon's data textures (shading shift, outline width, UV animation mask: linear
/// values, not colours, in VRMC_materials_mtoon) from the linear colour hadou's texture decoding
/// gives: the sRGB transfer undone (IEC 61966-2-1), so the texture's stored value comes back. An
/// alpha channel (`channel` 3) is stored linear already.
pub fn data_texel(linear: f32, channel: usize) -> f32 {
    if channel >= 3 {
        return if linear.is_nan() { 0.0 } else { linear.clamp(0.0, 1.0) };
    }
    crate::shade::linear_to_srgb(linear)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &[f32], b: &[f32], tol: f32) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
    }

    #[test]
    fn linearstep_against_hand_values() {
        assert_eq!(linearstep(-0.5, 0.5, 0.0), 0.5);
        assert_eq!(linearstep(-0.5, 0.5, 0.25), 0.75);
        assert_eq!(linearstep(-0.5, 0.5, -2.0), 0.0);
        assert_eq!(linearstep(-0.5, 0.5, 9.0), 1.0);
        // toony 1: a hard step at 0.
        assert_eq!(linearstep(0.0, 0.0, -1e-7), 0.0);
        assert_eq!(linearstep(0.0, 0.0, 0.0), 1.0);

        // toony 0.9, shift −0.05 (VRM 0.x's defaults migrated): N·L = 0.1, the step over
        // [−0.1, 0.1] at 0.05 → (0.05 + 0.1)/0.2.
        assert!((shading(0.1, -0.05, 0.9) - 0.75).abs() < 1e-6);
    }

    #[test]
    fn lit_mixes_shade_and_base() {
        let c = lit([0.2, 0.0, 0.4], [1.0, 0.8, 0.0], 0.25, [2.0, 1.0, 1.0]);
        assert!(close(&c, &[0.8, 0.2, 0.3], 1e-6), "{c:?}");
    }

    #[test]
    fn rim_against_hand_values() {
        // 1 − 0.5 + 0.1 = 0.6, 0.6² = 0.36.
        let r = parametric_rim(0.5, 0.1, 2.0, [1.0, 0.5, 0.0]);
        assert!(close(&r, &[0.36, 0.18, 0.0], 1e-6), "{r:?}");
        // Facing the eye without lift: no rim; 0⁰ = 1; negative powers count as 0.
        assert_eq!(parametric_rim(1.0, 0.0, 5.0, [1.0; 3]), [0.0; 3]);
        assert_eq!(parametric_rim(1.0, 0.0, 0.0, [1.0; 3]), [1.0; 3]);
        assert_eq!(parametric_rim(0.5, 0.0, -3.0, [1.0; 3]), [1.0; 3]);
        assert!(close(&lighting_mix([0.5, 2.0, 1.0], 0.5), &[0.75, 1.5, 1.0], 1e-6));
    }

    #[test]
    fn matcap_centre_and_axes() {
        let v = Vec3f::new(0.0, 0.0, 1.0);
        assert!(close(&matcap_uv(v, v), &[0.5, 0.5], 1e-6));
        assert!(close(&matcap_uv(Vec3f::new(1.0, 0.0, 0.0), v), &[0.995, 0.5], 1e-6));
        assert!(close(&matcap_uv(Vec3f::new(0.0, 1.0, 0.0), v), &[0.5, 0.005], 1e-6));
        // Looking straight down: finite, the fallback axis.
        let uv = matcap_uv(Vec3f::new(1.0, 0.0, 0.0), Vec3f::new(0.0, 1.0, 0.0));
        assert!(uv.iter().all(|x| x.is_finite()) && (uv[0] - 0.995).abs() < 1e-6, "{uv:?}");
    }

    #[test]
    fn uv_animation_against_hand_values() {
        // A quarter turn about (½, ½): (1, ½) → (½, 1); then a scroll of (0.1, −0.2).
        let uv = uv_animation([1.0, 0.5], 1.0, [0.1, -0.2], std::f32::consts::FRAC_PI_2);
        assert!(close(&uv, &[0.6, 0.8], 1e-6), "{uv:?}");
        // Half the mask: half the turn and half the scroll.
        let uv = uv_animation([1.0, 0.5], 0.5, [0.2, 0.0], std::f32::consts::PI);
        assert!(close(&uv, &[0.6, 1.0], 1e-6), "{uv:?}");
        // An overflowing turn is no turn (finite coordinates).
        let uv = uv_animation([0.25, 0.5], 1.0, [0.0, 0.0], f32::MAX * 4.0);
        assert!(close(&uv, &[0.25, 0.5], 1e-6), "{uv:?}");
        // No mask: no animation.
        assert!(close(&uv_animation([0.3, 0.7], 0.0, [5.0, 5.0], 100.0), &[0.3, 0.7], 1e-6));
    }
}
