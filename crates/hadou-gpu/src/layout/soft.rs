//! The `[area_light]`'s records: its maps (`GpuSpotMap`), uniforms (`SoftUniforms`) and casters'
//! boxes (`GpuCasterBox`).

use bytemuck::{Pod, Zeroable};

/// One of the `[area_light]`'s two perspective shadow maps (hadou_math::soft::SpotMap) and its
/// edge in texels. Keep in sync with `GpuSpotMap` in common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuSpotMap {
    /// The map's light position.
    pub eye: [f32; 3],
    /// `tan` of the frustum's half-angle.
    pub tan_half: f32,
    /// Unit axis.
    pub forward: [f32; 3],
    /// Near plane distance.
    pub near: f32,
    /// Unit right.
    pub right: [f32; 3],
    /// Edge in texels.
    pub size: u32,
    /// Unit up.
    pub up: [f32; 3],
    /// Padding.
    pub _pad: u32,
}

impl GpuSpotMap {
    /// The map `m` of edge `size`.
    pub fn new(m: &hadou_math::soft::SpotMap, size: u32) -> Self {
        GpuSpotMap {
            eye: m.eye.to_array(),
            tan_half: m.tan_half,
            forward: m.forward.to_array(),
            near: m.near,
            right: m.right.to_array(),
            size,
            up: m.up.to_array(),
            _pad: 0,
        }
    }
}

/// What the soft-shadow passes (soft.wgsl) know of the frame's `[area_light]`. Keep in sync with
/// `SoftUniforms` in soft.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct SoftUniforms {
    /// The two maps, `[L₁, L₂]`.
    pub maps: [GpuSpotMap; 2],
    /// 1 with the depth-aware search.
    pub depth_aware: u32,
    /// 0 for the exact resolve, else the faithful resolve's grid spacing `n`.
    pub grid: u32,
    /// The faithful grid's size in grid pixels.
    pub grid_size: [u32; 2],
    /// `k` of `hadou_math::soft::segment_brightness` (1: 003's linear ratio).
    pub ratio: f32,
    /// How many caster boxes ([`GpuCasterBox`]) the fit tests.
    pub boxes: u32,
    /// Padding to the uniform's 16-byte alignment.
    pub _pad: [u32; 2],
}

/// A caster's box in the world (`hadou_math::soft::CasterBox`), as soft.wgsl's map fit reads it.
/// Keep in sync with `GpuCasterBox` in soft.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuCasterBox {
    /// The corner (w unused).
    pub origin: [f32; 4],
    /// The dual vectors of its edges (w unused).
    pub dual: [[f32; 4]; 3],
}

impl GpuCasterBox {
    /// The box `b`.
    pub fn new(b: &hadou_math::soft::CasterBox) -> Self {
        let v = |v: hadou_math::Vec3f| [v.x, v.y, v.z, 0.0];
        GpuCasterBox { origin: v(b.origin), dual: b.dual.map(v) }
    }
}
