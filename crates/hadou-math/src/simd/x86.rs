//! The x86-64 paths: [`Avx2`] lanes, and the `#[target_feature]` functions [`super::dispatch`]
//! runs a body in.
//!
//! Each [`Avx2`] method is an `#[inline(always)]` call of one or two AVX intrinsics. Compiled on
//! its own (without AVX) such a call could not inline, so the type is only ever used inside
//! [`run_avx2`] and [`run_avx512`], where everything inlines into code compiled for the path. It
//! has no public constructor: outside a dispatched body no value of it exists.
//!
//! This file and the two calls in `dispatch.rs` are the workspace's only `unsafe` code.
#![allow(unsafe_code)]

use super::{Lane, WithLanes};
use std::arch::x86_64::*;
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Eight `f32` lanes in one 256-bit AVX register.
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct Avx2(__m256);

/// Runs `body` on [`Avx2`] lanes, compiled for AVX2 and FMA.
///
/// # Safety
/// The CPU must have AVX2 and FMA.
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn run_avx2<W: WithLanes>(body: W) -> W::Output {
    body.run::<Avx2>()
}

/// Runs `body` on [`Avx2`] lanes, compiled for AVX2, FMA, AVX-512F and AVX-512VL (the same
/// 256-bit lanes with 32 registers and EVEX encodings).
///
/// # Safety
/// The CPU must have AVX2, FMA, AVX-512F and AVX-512VL.
#[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
pub(super) unsafe fn run_avx512<W: WithLanes>(body: W) -> W::Output {
    body.run::<Avx2>()
}

// SAFETY (every `unsafe` block below): the intrinsics need AVX, AVX2 or FMA, and an `Avx2` value
// exists only inside `run_avx2` / `run_avx512`, which the CPU runs only with those features.

macro_rules! binary {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl $trait for Avx2 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Self(unsafe { $intrinsic(self.0, rhs.0) })
            }
        }
    };
}

binary!(Add, add, _mm256_add_ps);
binary!(Sub, sub, _mm256_sub_ps);
binary!(Mul, mul, _mm256_mul_ps);
binary!(Div, div, _mm256_div_ps);
binary!(BitAnd, bitand, _mm256_and_ps);
binary!(BitOr, bitor, _mm256_or_ps);

impl Neg for Avx2 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self(unsafe { _mm256_xor_ps(self.0, _mm256_set1_ps(-0.0)) })
    }
}

impl Not for Avx2 {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        Self(unsafe { _mm256_xor_ps(self.0, _mm256_castsi256_ps(_mm256_set1_epi32(-1))) })
    }
}

impl AddAssign for Avx2 {
    #[inline(always)]
    fn add_assign(&mut self, rhs: Self) {
        *self = *self + rhs;
    }
}

impl Avx2 {
    #[inline(always)]
    fn cmp<const OP: i32>(self, rhs: Self) -> Self {
        Self(unsafe { _mm256_cmp_ps::<OP>(self.0, rhs.0) })
    }
}

impl Lane for Avx2 {
    #[inline(always)]
    fn splat(v: f32) -> Self {
        Self(unsafe { _mm256_set1_ps(v) })
    }
    #[inline(always)]
    fn from_array(a: [f32; 8]) -> Self {
        Self(unsafe { _mm256_loadu_ps(a.as_ptr()) })
    }
    #[inline(always)]
    fn to_array(self) -> [f32; 8] {
        let mut a = [0.0f32; 8];
        unsafe { _mm256_storeu_ps(a.as_mut_ptr(), self.0) };
        a
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        Self(unsafe { _mm256_fmadd_ps(self.0, a.0, b.0) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self(unsafe { _mm256_sqrt_ps(self.0) })
    }
    #[inline(always)]
    fn min(self, rhs: Self) -> Self {
        // `vminps` returns its second operand where either is NaN: a NaN `rhs` takes `self`.
        rhs.is_nan().select(self, Self(unsafe { _mm256_min_ps(self.0, rhs.0) }))
    }
    #[inline(always)]
    fn max(self, rhs: Self) -> Self {
        rhs.is_nan().select(self, Self(unsafe { _mm256_max_ps(self.0, rhs.0) }))
    }
    #[inline(always)]
    fn simd_ge(self, rhs: Self) -> Self {
        self.cmp::<_CMP_GE_OQ>(rhs)
    }
    #[inline(always)]
    fn simd_gt(self, rhs: Self) -> Self {
        self.cmp::<_CMP_GT_OQ>(rhs)
    }
    #[inline(always)]
    fn simd_le(self, rhs: Self) -> Self {
        self.cmp::<_CMP_LE_OQ>(rhs)
    }
    #[inline(always)]
    fn simd_lt(self, rhs: Self) -> Self {
        self.cmp::<_CMP_LT_OQ>(rhs)
    }
    #[inline(always)]
    fn select(self, if_true: Self, if_false: Self) -> Self {
        Self(unsafe { _mm256_blendv_ps(if_false.0, if_true.0, self.0) })
    }
    #[inline(always)]
    fn is_nan(self) -> Self {
        self.cmp::<_CMP_UNORD_Q>(self)
    }
    #[inline(always)]
    fn is_inf(self) -> Self {
        let abs = Self(unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0) });
        abs.cmp::<_CMP_EQ_OQ>(Self::splat(f32::INFINITY))
    }
    #[inline(always)]
    fn bitmask(self) -> u32 {
        // The eight sign bits; movemask has no failure mode.
        unsafe { _mm256_movemask_ps(self.0) as u32 }
    }
    #[inline(always)]
    fn is_sign_negative(self) -> Self {
        Self(unsafe { _mm256_castsi256_ps(_mm256_srai_epi32::<31>(_mm256_castps_si256(self.0))) })
    }
    #[inline(always)]
    fn frexp(self) -> (Self, Self) {
        unsafe {
            let bits = _mm256_castps_si256(self.0);
            let biased = _mm256_and_si256(_mm256_srli_epi32::<23>(bits), _mm256_set1_epi32(0xff));
            let e = _mm256_sub_epi32(biased, _mm256_set1_epi32(126));
            let f = _mm256_or_si256(
                _mm256_and_si256(bits, _mm256_set1_epi32(0x807f_ffff_u32 as i32)),
                _mm256_set1_epi32(0x3f00_0000),
            );
            (Self(_mm256_castsi256_ps(f)), Self(_mm256_cvtepi32_ps(e)))
        }
    }
    #[inline(always)]
    fn exp2_int(self) -> Self {
        unsafe {
            // Round to nearest, ties to even (the MXCSR default), as `wide`'s `round_int`.
            let n = _mm256_cvtps_epi32(self.0);
            let e = _mm256_max_epi32(_mm256_add_epi32(n, _mm256_set1_epi32(127)), _mm256_set1_epi32(1));
            Self(_mm256_castsi256_ps(_mm256_slli_epi32::<23>(e)))
        }
    }
}
