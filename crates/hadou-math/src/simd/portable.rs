//! [`Portable`]: `wide::f32x8`, at the vector width the build targets.

use super::{Lane, Outlined};
use wide::{f32x8, i32x8, u32x8};

/// The lanes every build has: `wide::f32x8` (two SSE2 halves on baseline x86-64, two NEON halves
/// on aarch64). Its logarithm and `atan2` are `wide`'s own.
pub type Portable = f32x8;

impl Lane for f32x8 {
    #[inline(always)]
    fn splat(v: f32) -> Self {
        f32x8::splat(v)
    }
    #[inline(always)]
    fn bitmask(self) -> u32 {
        f32x8::to_bitmask(self)
    }
    #[inline(always)]
    fn from_array(a: [f32; 8]) -> Self {
        f32x8::from(a)
    }
    #[inline(always)]
    fn to_array(self) -> [f32; 8] {
        f32x8::to_array(self)
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        f32x8::mul_add(self, a, b)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32x8::sqrt(self)
    }
    #[inline(always)]
    fn min(self, rhs: Self) -> Self {
        f32x8::min(self, rhs)
    }
    #[inline(always)]
    fn max(self, rhs: Self) -> Self {
        f32x8::max(self, rhs)
    }
    #[inline(always)]
    fn simd_ge(self, rhs: Self) -> Self {
        f32x8::simd_ge(self, rhs)
    }
    #[inline(always)]
    fn simd_gt(self, rhs: Self) -> Self {
        f32x8::simd_gt(self, rhs)
    }
    #[inline(always)]
    fn simd_le(self, rhs: Self) -> Self {
        f32x8::simd_le(self, rhs)
    }
    #[inline(always)]
    fn simd_lt(self, rhs: Self) -> Self {
        f32x8::simd_lt(self, rhs)
    }
    #[inline(always)]
    fn select(self, if_true: Self, if_false: Self) -> Self {
        f32x8::select(self, if_true, if_false)
    }
    #[inline(always)]
    fn is_nan(self) -> Self {
        f32x8::is_nan(self)
    }
    #[inline(always)]
    fn is_inf(self) -> Self {
        f32x8::is_inf(self)
    }
    #[inline(always)]
    fn is_sign_negative(self) -> Self {
        f32x8::is_sign_negative(self)
    }
    #[inline(always)]
    fn frexp(self) -> (Self, Self) {
        let bits = wide::bytemuck::cast::<f32x8, u32x8>(self);
        let e = wide::bytemuck::cast::<u32x8, i32x8>((bits >> 23) & u32x8::splat(0xff)) - i32x8::splat(126);
        let f = (bits & u32x8::splat(0x807f_ffff)) | u32x8::splat(0x3f00_0000);
        (wide::bytemuck::cast::<u32x8, f32x8>(f), e.round_float())
    }
    #[inline(always)]
    fn exp2_int(self) -> Self {
        let e = (self.round_int() + i32x8::splat(127)).max(i32x8::splat(1)) << 23;
        f32x8::from_bits(wide::bytemuck::cast::<i32x8, u32x8>(e))
    }
    #[inline(always)]
    fn outlined<B: Outlined<Self>>(body: B) -> B::Output {
        outlined(body)
    }
    #[inline(always)]
    fn ln(self) -> Self {
        f32x8::ln(self)
    }
    #[inline(always)]
    fn atan2(self, x: Self) -> Self {
        f32x8::atan2(self, x)
    }
    #[inline(always)]
    fn reduce_add(self) -> f32 {
        f32x8::reduce_add(self)
    }
}

/// [`Lane::outlined`] for [`Portable`]: the build's own target features are the path's.
#[inline(never)]
fn outlined<B: Outlined<f32x8>>(body: B) -> B::Output {
    body.run()
}
