//! `Lane::bitmask` on every vector path the machine supports (`SimdPath::supported`): bit `i` is
//! set exactly where lane `i` of a comparison mask is, for every pattern of eight lanes, NaN
//! lanes (which compare false) and `−0` included.

use hadou_math::simd::{dispatch, Lane, SimdPath, WithLanes};

/// The bitmasks of `a > 0`, `a ≤ 0` and `a` NaN for one lane pattern.
struct Masks([f32; 8]);

impl WithLanes for Masks {
    type Output = (u32, u32, u32);
    #[inline(always)]
    fn run<L: Lane>(self) -> Self::Output {
        let a = L::from_array(self.0);
        let zero = L::splat(0.0);
        (a.simd_gt(zero).bitmask(), a.simd_le(zero).bitmask(), a.is_nan().bitmask())
    }
}

#[test]
fn bitmask_sets_the_bits_of_the_set_lanes_on_every_path() {
    let values = [1.0f32, -1.0, 0.0, -0.0, f32::NAN, f32::INFINITY, -f32::INFINITY, 1e-40];
    for path in SimdPath::supported() {
        for pattern in 0u32..256 {
            // Lane i takes values[(pattern >> i & 1) * 4 + i % 4]: every on/off pattern of
            // each kind of value.
            let a: [f32; 8] = std::array::from_fn(|i| values[((pattern >> i) & 1) as usize * 4 + i % 4]);
            let want = |f: &dyn Fn(f32) -> bool| (0..8).filter(|&i| f(a[i])).map(|i| 1u32 << i).sum::<u32>();
            let got = dispatch(path, Masks(a));
            assert_eq!(got.0, want(&|x| x > 0.0), "{path}: {a:?} > 0");
            assert_eq!(got.1, want(&|x| x <= 0.0), "{path}: {a:?} ≤ 0");
            assert_eq!(got.2, want(&|x| x.is_nan()), "{path}: {a:?} NaN");
        }
    }
}
