//! The glare chain (`hadou_math::bloom`): the soft threshold's pieces, the filters' weights, a
//! uniform area blooming to itself, the streak staying near its row, finite output for any colour,
//! a band computed with its plan's halo equal to the whole image bit for bit, and the chain in
//! lanes (`bloom::lanes`) equal to the texel-by-texel kernels bit for bit on every vector path.

use hadou_math::bloom::{
    down_row, glare, lanes, levels, prefilter, try_glare, up_row, BloomParams, Plan, Plane, PlanePool,
    Sequential, BLOOM_CLAMP,
};
use hadou_math::rng::Rng;
use hadou_math::simd::SimdPath;

fn params() -> BloomParams {
    BloomParams {
        intensity: 0.7,
        threshold: 1.0,
        soft_knee: 0.5,
        radius: 0.1,
        streak: 0.4,
        streak_length: 0.5,
    }
}

fn plane(w: usize, h: usize, f: impl Fn(usize, usize) -> [f32; 3]) -> Plane {
    let mut p = Plane::new(w, h, 0..h);
    for y in 0..h {
        for x in 0..w {
            p.data[y * w + x] = f(x, y);
        }
    }
    p
}

#[test]
fn soft_threshold_has_its_three_pieces() {
    let (th, knee) = (1.0f32, 0.5f32);
    // Below threshold − k: nothing.
    assert_eq!(prefilter([0.49, 0.2, 0.1], th, knee), [0.0; 3]);
    // Above threshold + k: c − threshold along c.
    let c = [3.0, 1.5, 0.0];
    let t = prefilter(c, th, knee);
    let w = (3.0 - 1.0) / 3.0;
    for i in 0..3 {
        assert!((t[i] - c[i] * w).abs() < 1e-6, "{t:?}");
    }
    // In the knee: q = (b − th + k)²/(4k) = 0.5²/2 at b = 1, k = 0.5.
    let t = prefilter([1.0, 0.0, 0.0], th, knee);
    assert!((t[0] - 0.125).abs() < 1e-6, "{t:?}");
    // Continuous at both ends of the knee.
    for b in [0.5f32, 1.5] {
        let lo = prefilter([b - 1e-4, 0.0, 0.0], th, knee)[0];
        let hi = prefilter([b + 1e-4, 0.0, 0.0], th, knee)[0];
        assert!((lo - hi).abs() < 1e-3, "jump at {b}: {lo} {hi}");
    }
    // A hard threshold without a knee.
    assert_eq!(prefilter([0.999, 0.0, 0.0], th, 0.0), [0.0; 3]);
    assert!((prefilter([2.0, 0.0, 0.0], th, 0.0)[0] - 1.0).abs() < 1e-6);
    // Hostile colours stay finite and clamped.
    for c in [[f32::MAX; 3], [f32::INFINITY, 0.0, 0.0], [f32::NAN, 1.0, 2.0], [-5.0, -1.0, 0.0]] {
        let t = prefilter(c, th, knee);
        assert!(t.iter().all(|v| v.is_finite() && (0.0..=BLOOM_CLAMP).contains(v)), "{c:?} -> {t:?}");
    }
}

#[test]
fn filters_keep_a_constant() {
    for (w, h) in [(9usize, 7usize), (16, 16), (1, 1), (3, 1)] {
        let src = plane(w, h, |_, _| [0.5, 2.0, 4.0]);
        let (hw, hh) = (w.div_ceil(2), h.div_ceil(2));
        for y in 0..hh {
            let mut out = vec![[0.0; 3]; hw];
            down_row(&src, y, &mut out);
            for o in &out {
                assert!((o[0] - 0.5).abs() < 1e-6 && (o[1] - 2.0).abs() < 1e-6 && (o[2] - 4.0).abs() < 1e-6);
            }
        }
        let low = plane(hw, hh, |_, _| [0.5, 2.0, 4.0]);
        for y in 0..h {
            let mut out = vec![[0.0; 3]; w];
            up_row(&low, y, Some(&vec![[1.0; 3]; w]), &mut out);
            for o in &out {
                assert!((o[0] - 1.5).abs() < 1e-6 && (o[2] - 5.0).abs() < 1e-6, "{o:?}");
            }
        }
    }
}

#[test]
fn downsample_weights_are_the_13_tap_pattern() {
    // One bright texel at (4, 4) of a 12×12 level: the next level's texel (2, 2) takes it from the
    // centre box A(0,0) (1/8 · 1/4) and the inner box A(−1,−1) (1/8 · 1/4): 1/16.
    let src = plane(12, 12, |x, y| if (x, y) == (4, 4) { [16.0, 0.0, 0.0] } else { [0.0; 3] });
    let mut row = vec![[0.0; 3]; 6];
    down_row(&src, 2, &mut row);
    assert!((row[2][0] - 1.0).abs() < 1e-6, "{row:?}");
    // Texel (1, 2): the boxes holding column 4 are A(+1, ·) and A(+2, ·), those holding row 4
    // A(·, 0) and A(·, −1); of the pattern's, A(+1, −1) (1/8) and A(+2, 0) (1/16): 0.75.
    assert!((row[1][0] - 0.75).abs() < 1e-6, "{row:?}");
    // Every box tiles the level once: the next level sums to a quarter of the texel's value.
    let total: f32 = (0..6)
        .map(|y| {
            let mut r = vec![[0.0; 3]; 6];
            down_row(&src, y, &mut r);
            r.iter().map(|v| v[0]).sum::<f32>()
        })
        .sum();
    assert!((total - 4.0).abs() < 1e-5, "{total}");
}

#[test]
fn uniform_area_blooms_to_its_own_bright_part() {
    let c = [3.0f32, 2.0, 1.5];
    let src = plane(40, 30, |_, _| c);
    let p = params();
    let out = glare(&p, &src, 0..30, &Sequential);
    let t = prefilter(c, p.threshold, p.soft_knee);
    for v in &out.data {
        for i in 0..3 {
            let want = c[i] + (p.intensity + p.streak) * t[i];
            assert!((v[i] - want).abs() < 1e-4 * want, "{v:?} vs {want}");
        }
    }
}

#[test]
fn streak_stays_on_its_row_and_bloom_spreads() {
    let (w, h) = (64, 48);
    let src = plane(w, h, |x, y| if (x, y) == (30, 20) { [50.0; 3] } else { [0.0; 3] });
    let only_streak = BloomParams { intensity: 0.0, streak: 1.0, ..params() };
    let out = glare(&only_streak, &src, 0..h, &Sequential);
    // Made from row pairs at level 1 and tapped bilinearly: a row either side of its source at
    // most (rows 19 … 22 for the pair 20, 21), and nowhere else.
    for y in 0..h {
        for x in 0..w {
            let v = out.data[y * w + x][0];
            if !(19..=22).contains(&y) {
                assert_eq!(v, 0.0, "streak at ({x}, {y})");
            }
        }
    }
    assert!(out.data[20 * w + 30][0] > 4.0 * out.data[19 * w + 30][0], "the source row holds the most");
    // Long: light 20 pixels to either side on the row.
    assert!(out.data[20 * w + 10][0] > 0.0 && out.data[20 * w + 50][0] > 0.0);
    let only_bloom = BloomParams { streak: 0.0, ..params() };
    let out = glare(&only_bloom, &src, 0..h, &Sequential);
    assert!(out.data[14 * w + 30][0] > 0.0 && out.data[26 * w + 36][0] > 0.0, "bloom reaches 6 px");
    assert!(out.data[20 * w + 30][0] > 50.0);
}

#[test]
fn output_is_finite_for_any_colour() {
    let src = plane(33, 17, |x, y| match (x + y) % 4 {
        0 => [f32::MAX; 3],
        1 => [1e30, 0.0, 5.0],
        2 => [0.0; 3],
        _ => [7.0, 1.0, 0.5],
    });
    let p = BloomParams { intensity: 10.0, streak: 10.0, ..params() };
    let out = glare(&p, &src, 0..17, &Sequential);
    assert!(out.data.iter().flatten().all(|v| v.is_finite()));
}

#[test]
fn level_count_follows_the_radius() {
    assert_eq!(levels(0.5), 1);
    assert_eq!(levels(4.0), 2);
    assert_eq!(levels(100.0), 7);
    assert_eq!(levels(1e9), 10);
    assert_eq!(levels(f32::NAN), 1);
}

#[test]
fn band_with_its_halo_equals_the_whole_image() {
    let mut rng = Rng(25);
    for case in 0..12 {
        let w = 5 + rng.below(60);
        let h = 3 + rng.below(90);
        let src = plane(w, h, |x, y| {
            let k = ((x * 31 + y * 17 + case) % 23) as f32;
            if k > 18.0 {
                [k, k * 0.5, 1.0]
            } else {
                [0.1 * k, 0.05, 0.0]
            }
        });
        let p = BloomParams { radius: 0.05 + 0.3 * (case as f32 / 12.0), ..params() };
        let whole = glare(&p, &src, 0..h, &Sequential);
        for _ in 0..4 {
            let a = rng.below(h);
            let b = a + 1 + rng.below(h - a);
            let plan = Plan::new(w, h, levels(p.radius * h as f32), a..b);
            // The band sees only the rows its plan names.
            let mut part = Plane::new(w, h, plan.source.clone());
            part.data.copy_from_slice(&src.data[plan.source.start * w..plan.source.end * w]);
            let band = glare(&p, &part, a..b, &Sequential);
            assert_eq!(band.data, whole.data[a * w..b * w], "case {case}: {w}×{h} rows {a}..{b}");
        }
    }
}

/// Every level of the chain in lanes, on every path the machine has, against the kernels texel by
/// texel: the same bits for images of one to a few dozen texels a side (the clamped edges, the
/// lanes' tails), whole and in bands, with and without a streak, for colours from zero (and
/// negative zero) to beyond the clamp, infinite, negative and NaN.
#[test]
fn lanes_equal_the_texel_kernels_bit_for_bit() {
    let mut rng = Rng(44);
    let sizes =
        [(1, 1), (1, 7), (2, 2), (3, 5), (7, 3), (8, 8), (9, 17), (17, 9), (31, 40), (64, 33), (70, 70)];
    for (case, &(w, h)) in sizes.iter().enumerate() {
        let vals: Vec<[f32; 3]> = (0..w * h)
            .map(|_| match rng.below(6) {
                0 => [0.0, -0.0, 0.0],
                1 => [rng.range_f32(0.0, 1.0), rng.range_f32(0.0, 1.0), rng.range_f32(0.0, 1.0)],
                2 => [1e6, 0.5, 3.0e38],
                3 => [f32::NAN, -1.0, f32::INFINITY],
                _ => [rng.range_f32(0.0, 8.0), rng.range_f32(0.0, 3.0), rng.range_f32(0.0, 20.0)],
            })
            .collect();
        let src = plane(w, h, |x, y| vals[y * w + x]);
        for p in [
            params(),
            BloomParams { radius: 1.0, streak: 0.0, ..params() },
            BloomParams { radius: 0.01, streak: 2.0, streak_length: 4.0, soft_knee: 0.0, ..params() },
        ] {
            let reference = try_glare(&p, &src, 0..h, &Sequential).unwrap();
            for path in SimdPath::supported() {
                let whole = lanes::try_glare(path, &p, &src, 0..h, &Sequential).unwrap();
                let bits = |v: &[[f32; 3]]| v.iter().flatten().map(|f| f.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&whole.data), bits(&reference.data), "case {case} {w}×{h} {p:?} on {path}");
                let a = rng.below(h);
                let b = a + 1 + rng.below(h - a);
                let band = lanes::try_glare(path, &p, &src, a..b, &Sequential).unwrap();
                assert_eq!(
                    bits(&band.data),
                    bits(&reference.data[a * w..b * w]),
                    "case {case} rows {a}..{b} on {path}"
                );
            }
        }
    }
}

/// A picture mostly below the knee (where the lanes skip the soft threshold's arithmetic, eight
/// texels at a time, and the first level's sums over rows dark from end to end): runs of dark
/// texels, some with a negative zero or a negative channel, next to bright, infinite and NaN ones,
/// a stretch of dark rows, for knees from none to the whole threshold, whole and in
/// bands, on every path the machine has: the texel kernels' bits.
#[test]
fn dark_runs_keep_the_texel_kernels_bits() {
    let mut rng = Rng(46);
    let (w, h) = (83, 37);
    let vals: Vec<[f32; 3]> = (0..w * h)
        .map(|i| {
            let dark = [rng.range_f32(0.0, 0.45), rng.range_f32(0.0, 0.45), rng.range_f32(0.0, 0.45)];
            // Rows 9 … 36 dark end to end (whole first-level rows and blocks read only those).
            if (9..37).contains(&(i / w)) {
                return dark;
            }
            match (i / 16 % 5, rng.below(40)) {
                (0, _) => [rng.range_f32(0.0, 4.0), rng.range_f32(0.0, 2.0), rng.range_f32(0.0, 6.0)],
                (_, 0) => [-0.0, dark[1], dark[2]],
                (_, 1) => [dark[0], -2.0, dark[2]],
                (_, 2) => [f32::NAN, dark[1], dark[2]],
                (_, 3) => [dark[0], dark[1], f32::INFINITY],
                (_, 4) => [0.0, -0.0, 0.0],
                (_, 5) => [dark[0], 0.9999, dark[2]],
                _ => dark,
            }
        })
        .collect();
    let src = plane(w, h, |x, y| vals[y * w + x]);
    let bits = |v: &[[f32; 3]]| v.iter().flatten().map(|f| f.to_bits()).collect::<Vec<_>>();
    for (threshold, soft_knee) in [(1.0, 0.5), (1.0, 0.0), (0.5, 1.0), (0.45, 0.1), (0.0, 0.5), (2.0, 0.75)] {
        let p = BloomParams { threshold, soft_knee, ..params() };
        let reference = try_glare(&p, &src, 0..h, &Sequential).unwrap();
        for path in SimdPath::supported() {
            let whole = lanes::try_glare(path, &p, &src, 0..h, &Sequential).unwrap();
            assert_eq!(
                bits(&whole.data),
                bits(&reference.data),
                "threshold {threshold} knee {soft_knee} on {path}"
            );
            let band = lanes::try_glare(path, &p, &src, 5..21, &Sequential).unwrap();
            assert_eq!(
                bits(&band.data),
                bits(&reference.data[5 * w..21 * w]),
                "band, {threshold} {soft_knee} on {path}"
            );
        }
    }
}

/// A pool's buffers are reused without being cleared ([`PlanePool`]): the glare drawn from a pool
/// whose buffers hold NaN, and then from the buffers the earlier glares (of other sizes, bands and
/// parameters) left in it, is the glare drawn from fresh planes, bit for bit.
#[test]
fn a_pool_of_stale_buffers_changes_no_texel() {
    let mut rng = Rng(45);
    let mut pool = PlanePool::default();
    for n in [1usize, 40, 900, 5000] {
        pool.give(Plane { width: n, height: 1, rows: 0..1, data: vec![[f32::NAN; 3]; n] });
    }
    let bits = |v: &[[f32; 3]]| v.iter().flatten().map(|f| f.to_bits()).collect::<Vec<_>>();
    for (case, &(w, h)) in [(70, 70), (9, 17), (64, 33), (31, 40), (70, 70), (3, 5)].iter().enumerate() {
        let vals: Vec<[f32; 3]> = (0..w * h)
            .map(|_| [rng.range_f32(0.0, 8.0), rng.range_f32(0.0, 3.0), rng.range_f32(0.0, 20.0)])
            .collect();
        let src = plane(w, h, |x, y| vals[y * w + x]);
        for p in [params(), BloomParams { radius: 1.0, streak: 0.0, ..params() }] {
            let a = rng.below(h);
            let b = a + 1 + rng.below(h - a);
            for path in SimdPath::supported() {
                let fresh = lanes::try_glare_plane(path, &p, &src, a..b, &Sequential).unwrap();
                let pooled = lanes::try_glare_plane_in(path, &p, &src, a..b, &Sequential, &mut pool).unwrap();
                assert_eq!(
                    bits(&pooled.data),
                    bits(&fresh.data),
                    "case {case} {w}×{h} rows {a}..{b} on {path}"
                );
                // Its own plane back too, stale for the next glare.
                pool.give(pooled);
            }
        }
    }
    assert!(pool.bytes() > 0);
}
