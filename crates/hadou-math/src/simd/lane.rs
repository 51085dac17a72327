//! [`Lane`]: what the lane kernels need of eight `f32`s.

use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Eight `f32` lanes. Comparisons return masks in the same type (every bit of a lane set where
/// true), which `&`, `|`, `!` combine and [`Lane::select`] consumes; NaN compares false.
///
/// Every method must be `#[inline(always)]` in an implementation: a body generic over `Lane` is
/// inlined into one function per path ([`super::dispatch`]), and only there do the target's vector
/// instructions inline. For the same reason a body keeps lane arithmetic out of closures that it
/// calls more than once (`array::map`, a callback): the compiler may keep such a closure as a
/// function of its own, compiled without the path's features, whose every lane operation becomes
/// a call (`hadou-cpu`'s row bodies take a sink trait with `#[inline(always)]` methods instead).
pub trait Lane:
    Copy
    + std::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + BitAnd<Output = Self>
    + BitOr<Output = Self>
    + Not<Output = Self>
    + AddAssign
{
    /// `v` in every lane.
    fn splat(v: f32) -> Self;
    /// Lane `i` from `a[i]`.
    fn from_array(a: [f32; 8]) -> Self;
    /// Lane `i` into `[i]`.
    fn to_array(self) -> [f32; 8];
    /// `self·a + b`: fused (one rounding) on paths with FMA, a multiply and an add elsewhere.
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// Square root per lane.
    fn sqrt(self) -> Self;
    /// The lesser lane; where one is NaN, the other (as `f32::min`).
    fn min(self, rhs: Self) -> Self;
    /// The greater lane; where one is NaN, the other (as `f32::max`).
    fn max(self, rhs: Self) -> Self;
    /// `self ≥ rhs` per lane.
    fn simd_ge(self, rhs: Self) -> Self;
    /// `self > rhs` per lane.
    fn simd_gt(self, rhs: Self) -> Self;
    /// `self ≤ rhs` per lane.
    fn simd_le(self, rhs: Self) -> Self;
    /// `self < rhs` per lane.
    fn simd_lt(self, rhs: Self) -> Self;
    /// With `self` a mask: `if_true` where set, `if_false` elsewhere.
    fn select(self, if_true: Self, if_false: Self) -> Self;
    /// NaN lanes.
    fn is_nan(self) -> Self;
    /// `±∞` lanes.
    fn is_inf(self) -> Self;
    /// Lanes whose sign bit is set (`−0` and `−NaN` included).
    fn is_sign_negative(self) -> Self;
    /// With `self` a mask: bit `i` set where lane `i` is (its sign bit, as `movemask`), so that
    /// scalar control flow can branch on a lane set without going through memory.
    fn bitmask(self) -> u32;
    /// For positive normal finite lanes, `(f, e)` with `self = f·2^e`, `f ∈ [½, 1)`, `e` an
    /// integer held as a float.
    fn frexp(self) -> (Self, Self);
    /// `2^round(self)` for `round(self) ∈ [−126, 127]` (below, `2^−126`), from exponent bits.
    fn exp2_int(self) -> Self;
    /// Runs `body` in a function of its own: never inlined, compiled for this lane type's path
    /// (with its `#[target_feature]`s on x86-64), so that its lane operations inline there.
    ///
    /// For a large piece of lane code called from a dispatched body: inlined (as everything in
    /// such a body is), it would add its temporaries to the body's own frame once per call site,
    /// and an unoptimized build gives every temporary a stack slot of its own. Outlined, it is
    /// one frame, live only while it runs.
    fn outlined<B: Outlined<Self>>(body: B) -> B::Output;

    /// Runs `body` in place (inlined) in an optimized build, and as [`Lane::outlined`] in one
    /// compiled at opt-level 0 (`cfg(hadou_unoptimized)`, from the crate's build script). There
    /// nothing but `#[inline(always)]` inlines, and every temporary of an inlined function keeps
    /// a stack slot of its own for the whole frame: a dispatched body with every kernel inlined
    /// would need megabytes of stack. The lane kernels run through this, so that each takes a
    /// frame of its own only while it runs.
    #[inline(always)]
    fn outlined_if_unoptimized<B: Outlined<Self>>(body: B) -> B::Output {
        #[cfg(hadou_unoptimized)]
        {
            Self::outlined(body)
        }
        #[cfg(not(hadou_unoptimized))]
        {
            body.run()
        }
    }

    /// The natural logarithm of positive normal finite lanes (elsewhere unspecified: callers
    /// select those lanes away). Cephes' `logf` reduction and polynomial (relative error about
    /// `1e-7`): `x = f·2^e`, `f` taken into `[√½, √2)`, `ln(1 + g)` by a degree-9 polynomial in
    /// `g = f − 1`, `e·ln 2` added in two parts.
    #[inline(always)]
    fn ln(self) -> Self {
        let k = Self::splat;
        let (f, e) = self.frexp();
        let low = f.simd_lt(k(std::f32::consts::FRAC_1_SQRT_2));
        let g = low.select(f + f, f) - k(1.0);
        let e = low.select(e - k(1.0), e);
        let z = g * g;
        let mut p = k(7.037_683_6e-2);
        for c in [-1.151_461_e-1, 1.167_699_9e-1, -1.242_014_1e-1, 1.424_932_3e-1, -1.666_805_8e-1] {
            p = p.mul_add(g, k(c));
        }
        for c in [2.000_071_4e-1, -2.499_999_4e-1, 3.333_333e-1] {
            p = p.mul_add(g, k(c));
        }
        let y = p * g * z;
        let y = e.mul_add(k(-2.121_944_4e-4), y);
        let y = y - k(0.5) * z;
        e.mul_add(k(0.693_359_4), g + y)
    }

    /// `atan2(self, x)` per lane, as `f32::atan2` within a few ulp, for every pair of finite or
    /// infinite lanes: both zero give `±0` or `±π` by the signs' rule, both infinite `±π/4` or `±3π/4`. The ratio of the lesser to the greater magnitude, in
    /// `[0, 1]`, goes through cephes' `atanf` (reduced at `tan(π/8)` by `(a − 1)/(a + 1)`, a
    /// degree-4 polynomial in `z²`), then back to the octant.
    #[inline(always)]
    fn atan2(self, x: Self) -> Self {
        use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};
        let k = Self::splat;
        let y = self;
        let (ax, ay) = (x.max(-x), y.max(-y));
        let (lo, hi) = (ax.min(ay), ax.max(ay));
        let both_inf = ax.is_inf() & ay.is_inf();
        let a = hi.simd_gt(k(0.0)).select(lo / hi, k(0.0));
        let a = both_inf.select(k(1.0), a);
        let big = a.simd_gt(k(0.414_213_57));
        let t = big.select((a - k(1.0)) / (a + k(1.0)), a);
        let z = t * t;
        let p = k(8.053_744_5e-2).mul_add(z, k(-1.387_768_6e-1));
        let p = p.mul_add(z, k(1.997_771_1e-1));
        let p = p.mul_add(z, k(-3.333_295e-1));
        let r = (p * z).mul_add(t, t);
        let r = big.select(r + k(FRAC_PI_4), r);
        let r = ay.simd_gt(ax).select(k(FRAC_PI_2) - r, r);
        let r = x.is_sign_negative().select(k(PI) - r, r);
        y.is_sign_negative().select(-r, r)
    }

    /// `e^self` per lane: cephes' `expf` (relative error within 2 ulp on `[−87.3, 88.7]`,
    /// `tests/lane_functions.rs`): `n = round(x·log₂e)` by the `1.5·2²³` shift, `r = x − n·ln 2`
    /// in two parts (exact), `e^r` by a degree-7 polynomial, times `2ⁿ` from exponent bits
    /// ([`Lane::exp2_int`], as `2ⁿ⁻¹·2` above 0 so that `n = 128` does not overflow early). `+∞`
    /// above `88.72` (overflow), 0 below `−87.33` (where `e^x` leaves the normal range), NaN for
    /// NaN.
    #[inline(always)]
    fn exp(self) -> Self {
        let k = Self::splat;
        let x = self.max(k(-87.33)).min(k(88.8));
        let n = x.mul_add(k(std::f32::consts::LOG2_E), k(12_582_912.0)) - k(12_582_912.0);
        // x − n·ln 2 with ln 2 = 0.693359375 − 2.12194440e-4: n·0.693359375 is exact (n has 8
        // bits, the constant 9), and so is the difference.
        let r = x - n * k(0.693_359_4);
        let r = n.mul_add(k(2.121_944_4e-4), r);
        let z = r * r;
        let mut p = k(1.987_569_1e-4);
        for c in [1.398_199_9e-3, 8.333_452e-3, 4.166_579_6e-2, 1.666_666_5e-1, 0.5] {
            p = p.mul_add(r, k(c));
        }
        let y = p.mul_add(z, r) + k(1.0);
        let up = n.simd_gt(k(0.0));
        let scaled = y * up.select(n - k(1.0), n).exp2_int();
        let v = up.select(scaled * k(2.0), scaled);
        let v = self.simd_lt(k(-87.33)).select(k(0.0), v);
        self.is_nan().select(self, v)
    }

    /// `tan(self)` per lane for `|self| < π/2`: cephes' `tanf` (relative error within 3 ulp of
    /// the tangent of the `f32` input, `tests/lane_functions.rs`): on `|x| ≤ π/4` a degree-6
    /// polynomial in `x²`, above it `1/tan(π/2 − |x|)` with `π/2 − |x|` formed exactly in three
    /// parts (so the tangent stays accurate up to `π/2` itself, where it is the `−2.3·10⁷` of
    /// `f32`'s `π/2`).
    #[inline(always)]
    fn tan(self) -> Self {
        let k = Self::splat;
        let a = self.max(-self);
        let big = a.simd_gt(k(std::f32::consts::FRAC_PI_4));
        // π/2 = 1.5703125 + 4.837512969970703e-4 + 7.549789954891882e-8 (cephes' DP1..DP3 ×2).
        let r = big.select(((k(1.570_312_5) - a) + k(4.837_513e-4)) + k(7.549_79e-8), a);
        let z = r * r;
        let mut p = k(9.385_402e-3);
        for c in [3.119_922_3e-3, 2.443_013_6e-2, 5.341_128e-2, 1.333_879_9e-1, 3.333_315_7e-1] {
            p = p.mul_add(z, k(c));
        }
        let t = (p * z).mul_add(r, r);
        let t = big.select(k(1.0) / t, t);
        self.is_sign_negative().select(-t, t)
    }

    /// `asinh(self)` per lane for finite lanes, within 4 ulp relative
    /// (`tests/lane_functions.rs`): `sign(x)·ln(1 + z)`, `z = |x| + x²/(1 + sqrt(1 + x²))`, the
    /// logarithm taken as `z·ln(u)/(u − 1)`, `u = 1 + z` (the rounding of `u` cancels, so small
    /// `|x|` keep their digits: `asinh(x) ≈ x`), and `ln|x| + ln 2` above `|x| = 4096` (where
    /// `sqrt(x² + 1)` is `|x|` in `f32`, and `x²` would overflow further up).
    #[inline(always)]
    fn asinh(self) -> Self {
        let k = Self::splat;
        let a = self.max(-self);
        let big = a.simd_gt(k(4096.0));
        let s = big.select(k(0.0), a);
        let s2 = s * s;
        let z = s + s2 / (k(1.0) + (k(1.0) + s2).sqrt());
        let u = k(1.0) + z;
        let small = u.simd_gt(k(1.0)).select(z * (u.ln() / (u - k(1.0))), z);
        let large = big.select(a, k(1.0)).ln() + k(std::f32::consts::LN_2);
        let r = big.select(large, small);
        self.is_sign_negative().select(-r, r)
    }

    /// `atan(self)` per lane: [`Lane::atan2`]`(self, 1)`, with its accuracy (a few ulp).
    #[inline(always)]
    fn atan(self) -> Self {
        self.atan2(Self::splat(1.0))
    }

    /// The sum of the lanes.
    #[inline(always)]
    fn reduce_add(self) -> f32 {
        self.to_array().iter().sum()
    }
}

/// A body generic over the lane type, run by [`super::dispatch`] on a path's lanes. Implementations mark
/// `run` `#[inline(always)]` (and everything it calls on lanes, down to the [`Lane`] methods), so
/// that it is compiled inside the path's `#[target_feature]` function.
pub trait WithLanes {
    /// What the body returns.
    type Output;
    /// The body on lanes `L`.
    fn run<L: Lane>(self) -> Self::Output;
}

/// A body run on lanes `L` in a function of its own ([`Lane::outlined`]). Implementations mark
/// `run` `#[inline(always)]`, so that it is compiled inside that function.
pub trait Outlined<L> {
    /// What the body returns.
    type Output;
    /// The body.
    fn run(self) -> Self::Output;
}
