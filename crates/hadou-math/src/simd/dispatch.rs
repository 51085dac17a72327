//! [`dispatch`]: one generic body, run on the lanes of a [`SimdPath`].

use super::path::Kind;
use super::{Portable, SimdPath, WithLanes};

/// Runs `body` on `path`'s lanes: [`Portable`] lanes, or on x86-64 the 256-bit lanes inside a
/// function compiled for AVX2 + FMA (`avx2`) or for AVX-512 too (`avx512`).
#[inline]
#[allow(unsafe_code)]
pub fn dispatch<W: WithLanes>(path: SimdPath, body: W) -> W::Output {
    match path.kind() {
        Kind::Portable => body.run::<Portable>(),
        // SAFETY: a `SimdPath` of these kinds is only made where the running CPU has the features
        // the functions are compiled for (`SimdPath::supported`).
        #[cfg(target_arch = "x86_64")]
        Kind::Avx2 => unsafe { super::x86::run_avx2(body) },
        #[cfg(target_arch = "x86_64")]
        Kind::Avx512 => unsafe { super::x86::run_avx512(body) },
    }
}
