//! The glare chain's uniforms (`BloomUniforms`).

use bytemuck::{Pod, Zeroable};

/// One step of the glare chain (bloom.wgsl): its planes, each `[level width, level height, first
/// row held, rows held]`, and the frame's bloom values. Keep in sync with `BloomUniforms` in
/// bloom.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct BloomUniforms {
    /// The first input plane.
    pub a: [u32; 4],
    /// The second input plane (the upsample's base, the composite's bloom).
    pub b: [u32; 4],
    /// The third input plane (the composite's streak).
    pub c: [u32; 4],
    /// The output plane.
    pub o: [u32; 4],
    /// `threshold`, `soft_knee`, `intensity/N`, `streak/N_s`.
    pub params: [f32; 4],
    /// 1 when the upsample adds `b`; the tone mode ([`TONE_FAITHFUL`](crate::layout::TONE_FAITHFUL), [`TONE_FILMIC`](crate::layout::TONE_FILMIC)); unused.
    pub flags: [u32; 4],
}
