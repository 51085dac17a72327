//! Shading of opaque objects and the mapping from summed wave light to output colour. Mirrored in
//! WGSL by `hadou-gpu` (keep in sync with `crates/hadou-gpu/src/shaders/common.wgsl`).

use crate::Vec3f;

/// Simple diffuse shading of the opaque scene: `albedo · (ambient + light · max(0, N·(−L)))`.
///
/// `normal` need not be unit (it is normalised; a zero normal shades with ambient only);
/// `light_dir` is the unit direction the light travels.
#[inline]
pub fn diffuse(
    albedo: [f32; 3],
    normal: Vec3f,
    light_dir: Vec3f,
    light: [f32; 3],
    ambient: [f32; 3],
) -> [f32; 3] {
    let n = normal.normalize_or(Vec3f::ZERO);
    let lambert = n.dot(-light_dir).max(0.0);
    [
        albedo[0] * (ambient[0] + light[0] * lambert),
        albedo[1] * (ambient[1] + light[1] * lambert),
        albedo[2] * (ambient[2] + light[2] * lambert),
    ]
}

/// The thesis's colour mapping (002 §3.3, SPEC.md §1.1): scene colour plus wave light, clamped to
/// `[0, 1]` per channel. Non-finite input maps to a finite value (NaN → 0, +∞ → 1).
#[inline]
pub fn map_faithful(c: [f32; 3]) -> [f32; 3] {
    c.map(|v| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) })
}

/// hadou's white-core filmic mapping: an exponential shoulder per channel, `1 − exp(−(c + w))`,
/// where `w = ½ · max(0, max(c) − 1)` bleeds the energy that over-saturates the brightest channel
/// into all channels, so dense energy turns white at the core while the glow keeps the wave's hue.
/// Continuous, monotone in every channel, and maps `[0, ∞)` into `[0, 1)`.
#[inline]
pub fn map_filmic(c: [f32; 3]) -> [f32; 3] {
    let c = c.map(|v| if v.is_nan() { 0.0 } else { v.max(0.0) });
    let m = c[0].max(c[1]).max(c[2]);
    let w = 0.5 * (m - 1.0).max(0.0);
    c.map(|v| {
        let x = (v + w).min(80.0);
        -(-x).exp_m1()
    })
}

/// Linear → sRGB transfer (IEC 61966-2-1), for 8-bit output.
#[inline]
pub fn linear_to_srgb(v: f32) -> f32 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn filmic_is_monotone_bounded_and_whitens_the_core() {
        let mut prev = [0.0f32; 3];
        for i in 1..2000 {
            let e = i as f32 * 0.01;
            let out = map_filmic([0.2 * e, 0.3 * e, 1.0 * e]);
            for k in 0..3 {
                assert!(out[k] >= prev[k] && out[k] < 1.0 + 1e-6, "{e} {out:?}");
            }
            prev = out;
        }
        // At high energy the weak channels approach 1: the core is white.
        assert!(prev[0] > 0.99, "{prev:?}");
        assert_eq!(map_filmic([f32::NAN, f32::INFINITY, -1.0]).map(|v| v.is_finite()), [true; 3]);
    }

    /// A saturated energy (`f32::MAX`, summed to `+∞` over several waves, times the exposure)
    /// maps to full white / the saturated colour, never NaN: the colour arithmetic only adds and
    /// multiplies non-negative values, and the mappings take `+∞`.
    #[test]
    fn saturated_light_maps_to_full_brightness() {
        for light in [f32::MAX, f32::MAX + f32::MAX, f32::INFINITY] {
            let c = [0.2 + 0.5 * light, 0.1 + 1.0 * light, 0.0];
            assert_eq!(map_faithful(c), [1.0, 1.0, 0.0]);
            assert_eq!(map_filmic(c), [1.0, 1.0, 1.0]);
        }
        let e = crate::energy::saturate(f32::MAX * 4.0);
        assert_eq!(e, f32::MAX);
        assert_eq!(crate::energy::saturate(f32::NAN), f32::MAX);
        assert_eq!(crate::energy::saturate(-1.0f32), 0.0);
        assert_eq!(crate::energy::scaled(f32::INFINITY, 0.0), 0.0);
        assert_eq!(crate::energy::scaled(1e30f32, 1e9), f32::MAX);
        assert_eq!(crate::energy::scaled(1e30f64, 1e9), f64::from(f32::MAX));
    }

    #[test]
    fn faithful_clamps_and_srgb_endpoints() {
        assert_eq!(map_faithful([-1.0, 0.5, 7.0]), [0.0, 0.5, 1.0]);
        assert_eq!(linear_to_srgb(0.0), 0.0);
        assert!((linear_to_srgb(1.0) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn diffuse_is_ambient_on_the_dark_side() {
        let c = diffuse([1.0, 0.5, 0.25], Vec3f::Y, Vec3f::Y, [1.0; 3], [0.1; 3]);
        assert_eq!(c, [0.1, 0.05, 0.025]);
        let c = diffuse([1.0, 1.0, 1.0], Vec3f::Y, -Vec3f::Y, [1.0; 3], [0.0; 3]);
        assert_eq!(c, [1.0; 3]);
    }
}
