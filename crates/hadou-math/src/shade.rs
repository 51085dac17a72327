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
    c.map(|v| one_minus_exp_neg((v + w).min(80.0)))
}

/// `1 − e^{−x}` for `x ∈ [0, 80]` (NaN-free input), within `2·10⁻⁷` of the exact value and without
/// a call into the maths library, so the colour mapping stays a few multiply-adds per channel:
/// below `x = ¼` the Taylor series of `−expm1(−x)` to `x⁸` (relative error under `10⁻⁸`, no
/// cancellation for small `x`); above, `e^{−x} = 2^{n}·2^{f}` with `n = round(−x·log₂e)`, `|f| ≤ ½`
/// and a degree-7 polynomial for `2^f` (relative error under `10⁻⁸`). The GPU's
/// `one_minus_exp_neg` uses its own `exp`; the two agree far inside the backends' colour
/// tolerance.
#[inline(always)]
fn one_minus_exp_neg(x: f32) -> f32 {
    // Taylor: x − x²/2 + x³/6 − … − x⁸/40320, as Horner in x.
    let small = x
        * (1.0
            - x * (1.0 / 2.0
                - x * (1.0 / 6.0
                    - x * (1.0 / 24.0
                        - x * (1.0 / 120.0
                            - x * (1.0 / 720.0 - x * (1.0 / 5040.0 - x * (1.0 / 40320.0))))))));
    let y = -x * std::f32::consts::LOG2_E;
    // Round to the nearest integer without a call: adding and removing 1.5·2²³ leaves no fraction
    // bits (|y| ≤ 116).
    const SHIFT: f32 = 12_582_912.0;
    let n = (y + SHIFT) - SHIFT;
    let f = y - n;
    // 2^f = e^{f·ln 2}, |f| ≤ ½: Taylor in g = f·ln 2 to g⁷ (|g| ≤ 0.347, remainder < 6·10⁻⁹).
    let g = f * std::f32::consts::LN_2;
    let p = 1.0
        + g * (1.0
            + g * (0.5
                + g * (1.0 / 6.0
                    + g * (1.0 / 24.0 + g * (1.0 / 120.0 + g * (1.0 / 720.0 + g * (1.0 / 5040.0)))))));
    // 2^n for n ∈ [−116, 0]: a normal f32 built from its exponent bits.
    let scale = f32::from_bits((((n as i32) + 127).max(1) as u32) << 23);
    let large = 1.0 - p * scale;
    if x < 0.25 {
        small
    } else {
        large
    }
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

    /// The colour mapping's `1 − e^{−x}` against `f64`'s, densely over its whole domain.
    #[test]
    fn one_minus_exp_neg_is_exact_to_2e_7_and_monotone() {
        let mut prev = 0.0f32;
        let mut worst = 0.0f64;
        for i in 0..=800_000 {
            let x = i as f32 * 1e-4;
            let got = one_minus_exp_neg(x);
            let want = -(-f64::from(x)).exp_m1();
            worst = worst.max((f64::from(got) - want).abs());
            assert!(got >= prev, "not monotone at {x}: {got} < {prev}");
            assert!(x == 0.0 || f64::from(got) > 0.0, "{x}: {got}");
            prev = got;
        }
        assert!(worst < 2e-7, "largest error {worst}");
        // Small values keep their relative precision.
        for x in [1e-30f32, 1e-10, 1e-5, 0.01, 0.2499] {
            let want = -(-f64::from(x)).exp_m1();
            assert!(((f64::from(one_minus_exp_neg(x)) - want) / want).abs() < 1e-6, "{x}");
        }
        assert_eq!(one_minus_exp_neg(80.0), 1.0);
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
