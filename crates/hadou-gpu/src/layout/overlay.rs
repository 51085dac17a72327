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
    /// [`PROJECTION_PERSPECTIVE`] or [`PROJECTION_ORTHOGRAPHIC`].
    pub projection: u32,
    /// The target's pixel where the frame's pixel (0, 0) is (a viewport's corner).
    pub origin: [u32; 2],
    /// Orthographic: the distance from the near plane to the far plane, over which the depth
    /// runs linearly.
    pub depth_span: f32,
    /// Padding to the uniform's 16-byte alignment.
    pub _pad: u32,
    /// Orthographic: the world point on the near plane at the frame's centre (NDC (0, 0)), `w`
    /// unused.
    pub ortho_centre: [f32; 4],
    /// Orthographic: the world vector from that point to NDC x = +1 on the near plane.
    pub ortho_right: [f32; 4],
    /// Orthographic: the world vector from that point to NDC y = +1 on the near plane.
    pub ortho_up: [f32; 4],
}

/// Rays from the frame camera's eye through each pixel (`CameraBasis::pixel_dir`).
pub const PROJECTION_PERSPECTIVE: u32 = 0;
/// Parallel rays along the frame camera's forward axis, each from its pixel's point on the near
/// plane.
pub const PROJECTION_ORTHOGRAPHIC: u32 = 1;

/// Depth 0 at the near plane, 1 at the far plane (hadou's raster pass, most engines).
pub const DEPTH_STANDARD: u32 = 0;
/// Depth `near / z`: 1 at the near plane, 0 at infinity (reverse-Z with an infinite far plane, as
/// Bevy draws).
pub const DEPTH_REVERSE_INFINITE: u32 = 1;
