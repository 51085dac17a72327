//! The x86-64 paths: [`Avx2`] lanes, and the `#[target_feature]` functions [`super::dispatch`]
//! runs a body in.
//!
//! Each [`Avx2`] method is an `#[inline(always)]` call of one or two AVX intrinsics. Compiled on
//! its own (without AVX) such a call could not inline, so the type is only ever used inside
//! [`run_avx2`] and [`run_avx512`], where everything inlines into code compiled for the path, and
//! inside the functions [`Lane::outlined`] runs a body in, compiled for the same path (the type's
//! parameter, [`OnAvx2`] or [`OnAvx512`], says which). It has no public constructor: outside a
//! dispatched body no value of it exists.
//!
//! This file and the two calls in `dispatch.rs` are the workspace's only `unsafe` code.
#![allow(unsafe_code)]

use super::{Lane, Outlined, WithLanes};
use std::arch::x86_64::*;
use std::marker::PhantomData;
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Eight `f32` lanes in one 256-bit AVX register, on the path `P`: the same instructions on
/// either, `P` choosing what [`Lane::outlined`] compiles a body for.
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct Avx2<P>(__m256, PhantomData<P>);

/// The x86-64 path an [`Avx2`] type runs on: the target features of the functions
/// [`Lane::outlined`] runs its bodies in.
pub trait X86Path: Copy + std::fmt::Debug + 'static {
    /// Runs `body` in a function compiled for the path, never inlined.
    ///
    /// # Safety
    /// The CPU must have the path's features.
    unsafe fn outlined<B: Outlined<Avx2<Self>>>(body: B) -> B::Output;
}

/// The `avx2` path: AVX2 and FMA.
#[derive(Clone, Copy, Debug)]
pub enum OnAvx2 {}

/// The `avx512` path: AVX2, FMA, AVX-512F and AVX-512VL (the same 256-bit lanes with 32
/// registers and EVEX encodings).
#[derive(Clone, Copy, Debug)]
pub enum OnAvx512 {}

impl X86Path for OnAvx2 {
    #[inline(always)]
    unsafe fn outlined<B: Outlined<Avx2<Self>>>(body: B) -> B::Output {
        outlined_avx2(body)
    }
}

impl X86Path for OnAvx512 {
    #[inline(always)]
    unsafe fn outlined<B: Outlined<Avx2<Self>>>(body: B) -> B::Output {
        outlined_avx512(body)
    }
}

/// Runs `body` on [`Avx2`] lanes, compiled for AVX2 and FMA.
///
/// # Safety
/// The CPU must have AVX2 and FMA.
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn run_avx2<W: WithLanes>(body: W) -> W::Output {
    body.run::<Avx2<OnAvx2>>()
}

/// Runs `body` on [`Avx2`] lanes, compiled for AVX2, FMA, AVX-512F and AVX-512VL.
///
/// # Safety
/// The CPU must have AVX2, FMA, AVX-512F and AVX-512VL.
#[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
pub(super) unsafe fn run_avx512<W: WithLanes>(body: W) -> W::Output {
    body.run::<Avx2<OnAvx512>>()
}

/// [`Lane::outlined`] on the `avx2` path: as [`run_avx2`], in a frame of its own.
///
/// # Safety
/// The CPU must have AVX2 and FMA.
#[inline(never)]
#[target_feature(enable = "avx2,fma")]
unsafe fn outlined_avx2<B: Outlined<Avx2<OnAvx2>>>(body: B) -> B::Output {
    body.run()
}

/// [`Lane::outlined`] on the `avx512` path: as [`run_avx512`], in a frame of its own.
///
/// # Safety
/// The CPU must have AVX2, FMA, AVX-512F and AVX-512VL.
#[inline(never)]
#[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
unsafe fn outlined_avx512<B: Outlined<Avx2<OnAvx512>>>(body: B) -> B::Output {
    body.run()
}

// SAFETY (every `unsafe` block below): the intrinsics need AVX, AVX2 or FMA (`Avx2<P>::outlined`:
// `P`'s features), and code on `Avx2` lanes is only ever instantiated by `run_avx2` /
// `run_avx512` (the type is private to this module), which `dispatch` calls only on a path whose
// features `SimdPath` found on the CPU.

macro_rules! binary {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl<P: X86Path> $trait for Avx2<P> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, rhs: Self) -> Self {
                Self::new(unsafe { $intrinsic(self.0, rhs.0) })
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

impl<P: X86Path> Neg for Avx2<P> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self::new(unsafe { _mm256_xor_ps(self.0, _mm256_set1_ps(-0.0)) })
    }
}

impl<P: X86Path> Not for Avx2<P> {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        Self::new(unsafe { _mm256_xor_ps(self.0, _mm256_castsi256_ps(_mm256_set1_epi32(-1))) })
    }
}

impl<P: X86Path> AddAssign for Avx2<P> {
    #[inline(always)]
    fn add_assign(&mut self, rhs: Self) {
        *self = *self + rhs;
    }
}

impl<P: X86Path> Avx2<P> {
    #[inline(always)]
    fn new(v: __m256) -> Self {
        Self(v, PhantomData)
    }

    #[inline(always)]
    fn cmp<const OP: i32>(self, rhs: Self) -> Self {
        Self::new(unsafe { _mm256_cmp_ps::<OP>(self.0, rhs.0) })
    }
}

impl<P: X86Path> Lane for Avx2<P> {
    #[inline(always)]
    fn splat(v: f32) -> Self {
        Self::new(unsafe { _mm256_set1_ps(v) })
    }
    #[inline(always)]
    fn from_array(a: [f32; 8]) -> Self {
        Self::new(unsafe { _mm256_loadu_ps(a.as_ptr()) })
    }
    #[inline(always)]
    fn to_array(self) -> [f32; 8] {
        let mut a = [0.0f32; 8];
        unsafe { _mm256_storeu_ps(a.as_mut_ptr(), self.0) };
        a
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        Self::new(unsafe { _mm256_fmadd_ps(self.0, a.0, b.0) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Self::new(unsafe { _mm256_sqrt_ps(self.0) })
    }
    #[inline(always)]
    fn min(self, rhs: Self) -> Self {
        // `vminps` returns its second operand where either is NaN: a NaN `rhs` takes `self`.
        rhs.is_nan().select(self, Self::new(unsafe { _mm256_min_ps(self.0, rhs.0) }))
    }
    #[inline(always)]
    fn max(self, rhs: Self) -> Self {
        rhs.is_nan().select(self, Self::new(unsafe { _mm256_max_ps(self.0, rhs.0) }))
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
        Self::new(unsafe { _mm256_blendv_ps(if_false.0, if_true.0, self.0) })
    }
    #[inline(always)]
    fn is_nan(self) -> Self {
        self.cmp::<_CMP_UNORD_Q>(self)
    }
    #[inline(always)]
    fn is_inf(self) -> Self {
        let abs = Self::new(unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0) });
        abs.cmp::<_CMP_EQ_OQ>(Self::splat(f32::INFINITY))
    }
    #[inline(always)]
    fn bitmask(self) -> u32 {
        // The eight sign bits; movemask has no failure mode.
        unsafe { _mm256_movemask_ps(self.0) as u32 }
    }
    #[inline(always)]
    fn is_sign_negative(self) -> Self {
        Self::new(unsafe { _mm256_castsi256_ps(_mm256_srai_epi32::<31>(_mm256_castps_si256(self.0))) })
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
            (Self::new(_mm256_castsi256_ps(f)), Self::new(_mm256_cvtepi32_ps(e)))
        }
    }
    #[inline(always)]
    fn exp2_int(self) -> Self {
        unsafe {
            // Round to nearest, ties to even (the MXCSR default), as `wide`'s `round_int`.
            let n = _mm256_cvtps_epi32(self.0);
            let e = _mm256_max_epi32(_mm256_add_epi32(n, _mm256_set1_epi32(127)), _mm256_set1_epi32(1));
            Self::new(_mm256_castsi256_ps(_mm256_slli_epi32::<23>(e)))
        }
    }
    #[inline(always)]
    fn outlined<B: Outlined<Self>>(body: B) -> B::Output {
        unsafe { P::outlined(body) }
    }
}
