//! Shading of opaque objects and the mapping from summed wave light to output colour. Mirrored in
//! WGSL by `hadou-gpu` (keep in sync with `crates/hadou-gpu/src/shaders/common.wgsl`).

use crate::simd::Lane;
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
/// tolerance. Mirrored per lane by [`one_minus_exp_neg_lanes`] (keep in sync: the test
/// `lane_mappings_equal_the_scalar_ones` holds them equal).
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

/// [`map_faithful`] on eight pixels at once (`c[channel]` holds one channel of each), on any
/// [`Lane`] type: lane for lane the same values.
#[inline(always)]
pub fn map_faithful_lanes<L: Lane>(c: [L; 3]) -> [L; 3] {
    // Written out per channel, not with `array::map`: a closure called three times may be
    // compiled apart from the vector path's `#[target_feature]` body (see `simd::Lane`).
    #[inline(always)]
    fn one<L: Lane>(v: L) -> L {
        let v = v.is_nan().select(L::splat(0.0), v);
        v.max(L::splat(0.0)).min(L::splat(1.0))
    }
    [one(c[0]), one(c[1]), one(c[2])]
}

/// [`map_filmic`] on eight pixels at once (`c[channel]` holds one channel of each), with the same
/// arithmetic in the same order, so lane for lane the same values (a zero may lose its sign).
#[inline(always)]
pub fn map_filmic_lanes<L: Lane>(c: [L; 3]) -> [L; 3] {
    // Per channel by hand, as in `map_faithful_lanes`.
    #[inline(always)]
    fn clean<L: Lane>(v: L) -> L {
        v.is_nan().select(L::splat(0.0), v.max(L::splat(0.0)))
    }
    let c = [clean(c[0]), clean(c[1]), clean(c[2])];
    let m = c[0].max(c[1]).max(c[2]);
    let w = L::splat(0.5) * (m - L::splat(1.0)).max(L::splat(0.0));
    let top = L::splat(80.0);
    [
        one_minus_exp_neg_lanes((c[0] + w).min(top)),
        one_minus_exp_neg_lanes((c[1] + w).min(top)),
        one_minus_exp_neg_lanes((c[2] + w).min(top)),
    ]
}

/// [`one_minus_exp_neg`] per lane, the same operations in the same order.
#[inline(always)]
fn one_minus_exp_neg_lanes<L: Lane>(x: L) -> L {
    let k = L::splat;
    let one = L::splat(1.0);
    let small = x
        * (one
            - x * (k(1.0 / 2.0)
                - x * (k(1.0 / 6.0)
                    - x * (k(1.0 / 24.0)
                        - x * (k(1.0 / 120.0)
                            - x * (k(1.0 / 720.0) - x * (k(1.0 / 5040.0) - x * k(1.0 / 40320.0))))))));
    let y = -x * k(std::f32::consts::LOG2_E);
    let shift = k(12_582_912.0);
    let n = (y + shift) - shift;
    let f = y - n;
    let g = f * k(std::f32::consts::LN_2);
    let p = one
        + g * (one
            + g * (k(0.5)
                + g * (k(1.0 / 6.0)
                    + g * (k(1.0 / 24.0)
                        + g * (k(1.0 / 120.0) + g * (k(1.0 / 720.0) + g * k(1.0 / 5040.0)))))));
    // 2^n from its exponent bits, as the scalar form.
    let scale = n.exp2_int();
    let large = one - p * scale;
    x.simd_lt(k(0.25)).select(small, large)
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

/// `linear_to_srgb(v)` as an 8-bit code, `⌊255·srgb(v) + ½⌋`, exactly as that expression
/// computes it but without the power function. Non-negative floats order as their bits, and the
/// code is non-decreasing in `v`: the top 19 bits of `v` pick a bucket whose first code is
/// tabulated, and one comparison with the next code's threshold (the smallest `f32` reaching
/// it, found once by bisection on the exact expression) finishes: no bucket holds two
/// thresholds (asserted when the table is built). NaN and values ≤ 0 give 0, values ≥ 1 give 255.
#[inline]
pub fn linear_to_srgb8(v: f32) -> u8 {
    srgb8_code(srgb8_tables(), v)
}

/// [`linear_to_srgb8`]'s tables, for a loop that encodes many values: [`Srgb8Tables::code`]
/// without looking the tables up each time.
pub fn srgb8_encoder() -> &'static Srgb8Tables {
    srgb8_tables()
}

impl Srgb8Tables {
    /// [`linear_to_srgb8`]`(v)`.
    #[inline(always)]
    pub fn code(&self, v: f32) -> u8 {
        srgb8_code(self, v)
    }

    /// `next[k]`: the smallest `f32` whose code exceeds `k` (`+∞` for `k = 255`), increasing in
    /// `k`. For `v ≥ 0` the code is the number of entries `≤ v` (NaN and `v ≤ 0` give 0): the
    /// table the GPU's 8-bit output bisects to give the same bytes (wave.wgsl `srgb8_code`).
    pub fn next_thresholds(&self) -> &[f32; 256] {
        &self.next
    }
}

/// [`linear_to_srgb8`] with its tables at hand.
#[inline(always)]
fn srgb8_code(tables: &Srgb8Tables, v: f32) -> u8 {
    if v.is_nan() || v <= 0.0 {
        0
    } else if v >= 1.0 {
        255
    } else {
        let k = tables.start[(v.to_bits() >> SRGB8_SHIFT) as usize];
        k + u8::from(v >= tables.next[k as usize])
    }
}

/// [`linear_to_srgb8`] of the red, green and blue of each colour into `out` as RGBA bytes with
/// alpha 255 (`out` holds `4 · colors.len()` bytes; extra bytes are left alone): the viewer's
/// upload format. The tables are looked up once for the whole slice.
pub fn rgba_to_srgba8(colors: &[[f32; 4]], out: &mut [u8]) {
    let tables = srgb8_tables();
    let code = |v: f32| srgb8_code(tables, v);
    for (o, c) in out.chunks_exact_mut(4).zip(colors) {
        o[0] = code(c[0]);
        o[1] = code(c[1]);
        o[2] = code(c[2]);
        o[3] = 255;
    }
}

/// Bits dropped from a float to find its bucket.
const SRGB8_SHIFT: u32 = 13;

/// The number of buckets below 1.0.
const SRGB8_BUCKETS: usize = (0x3F80_0000u32 >> SRGB8_SHIFT) as usize;

/// The tables of [`linear_to_srgb8`] ([`srgb8_encoder`]).
pub struct Srgb8Tables {
    /// Per bucket of floats sharing their top 19 bits, the code of the bucket's first float.
    start: Vec<u8>,
    /// `next[k]`: the smallest `f32` whose code exceeds `k` (`+∞` for 255).
    next: [f32; 256],
}

fn srgb8_tables() -> &'static Srgb8Tables {
    static T: std::sync::OnceLock<Srgb8Tables> = std::sync::OnceLock::new();
    T.get_or_init(|| {
        let t = srgb8_thresholds();
        let mut next = [f32::INFINITY; 256];
        next[..255].copy_from_slice(&t[1..]);
        let mut start = vec![0u8; SRGB8_BUCKETS];
        let mut k = 0usize;
        for (b, s) in start.iter_mut().enumerate() {
            let first = f32::from_bits((b as u32) << SRGB8_SHIFT);
            while k < 255 && first >= t[k + 1] {
                k += 1;
            }
            *s = k as u8;
            // One comparison must suffice: the bucket's last float reaches at most code k + 1.
            let last = f32::from_bits((((b as u32) + 1) << SRGB8_SHIFT) - 1);
            debug_assert!(k >= 254 || last < t[k + 2], "bucket {b} spans two thresholds");
        }
        Srgb8Tables { start, next }
    })
}

/// The code of [`linear_to_srgb8`] by its definition.
#[inline]
fn srgb8_exact(v: f32) -> u8 {
    (linear_to_srgb(v) * 255.0 + 0.5) as u8
}

/// `t[k]` (k ≥ 1): the smallest non-negative `f32` whose exact code is at least `k` (`t[0]` is
/// unused). The code is non-decreasing in `v`, and non-negative floats order as their bits.
fn srgb8_thresholds() -> [f32; 256] {
    let mut t = [0.0f32; 256];
    for (k, tk) in t.iter_mut().enumerate().skip(1) {
        // Invariant: code(lo) < k ≤ code(hi).
        let (mut lo, mut hi) = (0u32, 1.0f32.to_bits());
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            if (srgb8_exact(f32::from_bits(mid)) as usize) < k {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        *tk = f32::from_bits(hi);
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lane_mappings_equal_the_scalar_ones() {
        let mut vals: Vec<f32> =
            (0..4000).map(|i| (i as f32 * 0.37).sin().abs() * 6.0 * (i % 7) as f32 / 3.0).collect();
        vals.extend([
            0.0,
            -0.0,
            -1.0,
            0.2499999,
            0.25,
            1.0,
            79.0,
            80.0,
            1e30,
            f32::MAX,
            f32::INFINITY,
            f32::NAN,
            1e-30,
        ]);
        /// Both mappings of one batch on a path's lanes.
        struct Batch([[f32; 8]; 3]);
        impl crate::simd::WithLanes for Batch {
            type Output = [[[f32; 8]; 3]; 2];
            #[inline(always)]
            fn run<L: Lane>(self) -> Self::Output {
                let c = self.0.map(L::from_array);
                [map_filmic_lanes(c).map(L::to_array), map_faithful_lanes(c).map(L::to_array)]
            }
        }
        // Every vector path this CPU runs, each held to the scalar mappings.
        for path in crate::simd::SimdPath::supported() {
            for chunk in vals.chunks_exact(24) {
                let px: Vec<[f32; 3]> = chunk.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
                let batch = [0, 1, 2].map(|ch| std::array::from_fn::<f32, 8, _>(|i| px[i][ch]));
                let got = crate::simd::dispatch(path, Batch(batch));
                for (m, scalar) in
                    [map_filmic as fn([f32; 3]) -> [f32; 3], map_faithful].into_iter().enumerate()
                {
                    for (i, p) in px.iter().enumerate() {
                        let want = scalar(*p);
                        for ch in 0..3 {
                            // Equal values (a zero's sign may differ: `max(−0, 0)` is either).
                            let g = got[m][ch][i];
                            assert!(g == want[ch], "{path}: {p:?} channel {ch}: {g} vs {}", want[ch]);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn srgb8_codes_equal_the_power_function_everywhere_they_change() {
        // Every code's threshold and 64 floats either side, a dense sweep of [0, 1] and the
        // special values.
        // Every bucket's first float and its neighbours (the bucket table's seams).
        for b in 0..SRGB8_BUCKETS as u32 {
            for v in [(b << SRGB8_SHIFT).saturating_sub(1), b << SRGB8_SHIFT, (b << SRGB8_SHIFT) + 1]
                .map(f32::from_bits)
            {
                assert_eq!(linear_to_srgb8(v), srgb8_exact(v), "{v:e}");
            }
        }
        let t = srgb8_thresholds();
        for &tk in &t[1..] {
            let b = tk.to_bits();
            for v in (b.saturating_sub(64)..=b + 64).map(f32::from_bits) {
                assert_eq!(linear_to_srgb8(v), srgb8_exact(v), "{v:e}");
            }
        }
        for i in 0..=2_000_000u32 {
            let v = i as f32 / 2_000_000.0;
            assert_eq!(linear_to_srgb8(v), srgb8_exact(v), "{v:e}");
        }
        for v in
            [-1.0, -0.0, 0.0, 1.0, 1.5, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, f32::MIN_POSITIVE, 1e-45]
        {
            assert_eq!(linear_to_srgb8(v), srgb8_exact(v), "{v:e}");
        }
        assert_eq!((linear_to_srgb8(0.0), linear_to_srgb8(1.0)), (0, 255));
        let colors: Vec<[f32; 4]> = (0..1000).map(|i| [i as f32 / 900.0, -1.0, f32::NAN, 0.5]).collect();
        let mut out = vec![7u8; 4 * colors.len()];
        rgba_to_srgba8(&colors, &mut out);
        for (c, o) in colors.iter().zip(out.chunks_exact(4)) {
            assert_eq!(o, [linear_to_srgb8(c[0]), 0, 0, 255]);
        }
    }

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

    /// The bisection the GPU's 8-bit output runs over [`Srgb8Tables::next_thresholds`]
    /// (wave.wgsl `srgb8_code`, written the same way here) gives [`linear_to_srgb8`] on every
    /// float of `[0, 1]` near each threshold, on a sweep of the whole range, and at the ends.
    #[test]
    fn bisecting_the_next_thresholds_is_the_code() {
        let next = srgb8_encoder().next_thresholds();
        assert!(next.windows(2).all(|w| w[0] < w[1]) && next[255] == f32::INFINITY);
        let bisect = |v: f32| {
            let mut k = 0usize;
            let mut step = 128;
            while step > 0 {
                if v >= next[k + step - 1] {
                    k += step;
                }
                step >>= 1;
            }
            k as u8
        };
        let mut vals: Vec<f32> = (0..=1_000_000).map(|i| i as f32 * 1e-6).collect();
        for &t in &next[..255] {
            for d in -2i32..=2 {
                vals.push(f32::from_bits((t.to_bits() as i32 + d) as u32));
            }
        }
        vals.extend([-0.0, -1.0, 1.5, f32::MAX, f32::INFINITY, f32::NAN, f32::MIN_POSITIVE, 1e-45]);
        for v in vals {
            assert_eq!(bisect(v), linear_to_srgb8(v), "{v:e}");
        }
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
