//! The wave overlay's depth model and viewport corner (`OverlayUniforms`).

use bytemuck::{Pod, Zeroable};

/// How the wave overlay (wave_overlay.wgsl) reads the caller's depth buffer. Keep in sync with
/// `OverlayUniforms` in wave_overlay.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct OverlayUniforms {
    /// [`DEPTH_STANDARD`] or [`DEPTH_REVERSE_INFINITE`].
    pub depth_model: u32,
    /// The camera's near plane.
    pub near: f32,
    /// The camera's far plane (the standard model only).
    pub far: f32,
    /// Padding.
    pub _pad: u32,
    /// The target's pixel where the frame's pixel (0, 0) is (a viewport's corner).
    pub origin: [u32; 2],
    /// Padding to the uniform's 16-byte alignment.
    pub _pad2: [u32; 2],
}

/// Depth 0 at the near plane, 1 at the far plane (hadou's raster pass, most engines).
pub const DEPTH_STANDARD: u32 = 0;
/// Depth `near / z`: 1 at the near plane, 0 at infinity (reverse-Z with an infinite far plane, as
/// Bevy draws).
pub const DEPTH_REVERSE_INFINITE: u32 = 1;
