//! Eight `f32` lanes at the machine's full vector width, chosen at run time.
//!
//! The lane kernels (`energy::lanes`, the colour mappings of `shade`, and the CPU backend's ray
//! set-up and colour stage) are written once, generic over [`Lane`]: eight `f32`s with the
//! arithmetic, comparisons, selects and the few bit-level steps they need. Two types implement it:
//! - [`Portable`] (`wide::f32x8`): whatever the build targets. On baseline x86-64 that is two SSE2
//!   halves; on aarch64 two NEON halves; on wasm32 scalar code or `simd128`.
//! - `Avx2` (x86-64 only): one 256-bit register per lane set, with fused multiply-adds. Its
//!   functions are only ever inlined into code compiled with AVX2 and FMA enabled, which runs only
//!   after the CPU said it has them.
//!
//! [`SimdPath`] names a path the running CPU supports ([`SimdPath::widest`] is the widest;
//! `HADOU_SIMD` may choose a narrower one and is refused, with a message, for one the CPU lacks),
//! and [`dispatch`] runs a [`WithLanes`] body on it: the body is compiled once per path, the
//! x86-64 ones inside functions carrying `#[target_feature]`, so a single binary uses AVX2 + FMA
//! (and AVX-512's extra registers and encodings, `avx512` path) where the CPU has them and SSE2
//! elsewhere. `tests/simd_paths.rs` holds every path the machine supports to the scalar kernels.
//!
//! A large kernel called from such a body can run in a function of its own compiled for the same
//! path ([`Lane::outlined`], through the [`Outlined`] trait): the attenuated march always does,
//! and in a build at opt-level 0 the closed forms, the capsule's split and the curve packet and
//! its pieces do too ([`Lane::outlined_if_unoptimized`]). Unoptimized, every temporary of an
//! inlined function keeps a stack slot of its own, so a body inlining every kernel would need
//! megabytes of stack; outlined, each kernel's frame is live only while it runs.

mod dispatch;
mod lane;
mod path;
mod portable;
#[cfg(target_arch = "x86_64")]
mod x86;

pub use dispatch::dispatch;
pub use lane::{Lane, Outlined, WithLanes};
pub use path::{SimdPath, SimdPathError, SIMD_ENV};
pub use portable::Portable;
