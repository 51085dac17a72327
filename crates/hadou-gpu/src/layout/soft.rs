//! The `[area_light]`'s records: its maps (`GpuSpotMap`), uniforms (`SoftUniforms`) and casters'
//! boxes (`GpuCasterBox`); the traced resolve's uniforms (`TracedUniforms`) and hierarchy
//! (`GpuBvhNode`, `GpuBvhTri`).

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

/// The traced resolve's uniforms: the lamp's sample layout (`hadou_math::soft::LampPattern`) and
/// the hierarchy's node count. Keep in sync with `TracedUniforms` in soft_traced.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TracedUniforms {
    /// Rows of samples.
    pub rows: u32,
    /// Samples a row.
    pub per_row: u32,
    /// 1 for chords of the unit disc (disc, sphere), 0 for the segment's one row.
    pub disc: u32,
    /// Nodes of the hierarchy (0: no caster triangle).
    pub node_count: u32,
    /// Row `j`'s share of the lamp at `[j / 4][j % 4]`.
    pub weights: [[f32; 4]; 8],
}

impl TracedUniforms {
    /// The uniforms of `pattern` over a hierarchy of `node_count` nodes.
    pub fn new(pattern: &hadou_math::soft::LampPattern, node_count: u32) -> Self {
        let mut weights = [[0.0; 4]; 8];
        for (j, w) in pattern.weights.iter().enumerate() {
            weights[j / 4][j % 4] = *w;
        }
        TracedUniforms {
            rows: pattern.rows,
            per_row: pattern.per_row,
            disc: u32::from(pattern.disc),
            node_count,
            weights,
        }
    }
}

/// The traced resolve's sample grid (soft_traced.wgsl `TracedGrid`): with `k > 1` the soft
/// buffers are the sample frame's, `k × k` points an image pixel, and one value is traced per pixel
/// where its samples agree (hadou-cpu's `traced::traced_grid`). Keep in sync with `TracedGrid`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct TracedGrid {
    /// The sample grid's edge `k` (1: one sample a pixel).
    pub k: u32,
    /// Padding to 16 bytes.
    pub pad: [u32; 3],
}

/// One node of the traced resolve's hierarchy: `hadou_math::soft::BvhNode`'s bytes. Keep in sync
/// with `BvhNode` in soft_traced.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuBvhNode {
    /// Smallest corner.
    pub lo: [f32; 3],
    /// The next node once this subtree is done.
    pub skip: u32,
    /// Largest corner.
    pub hi: [f32; 3],
    /// `first << 4 | count` (0: an inner node).
    pub tris: u32,
}

impl From<&hadou_math::soft::BvhNode> for GpuBvhNode {
    fn from(n: &hadou_math::soft::BvhNode) -> Self {
        GpuBvhNode { lo: n.lo, skip: n.skip, hi: n.hi, tris: n.tris }
    }
}

/// One triangle of the traced resolve's hierarchy: `hadou_math::soft::BvhTri`'s bytes. Keep in
/// sync with `BvhTri` in soft_traced.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuBvhTri {
    /// First corner, `w` the normal's `x`.
    pub a: [f32; 4],
    /// Second corner, `w` the normal's `y`.
    pub b: [f32; 4],
    /// Third corner, `w` the normal's `z`.
    pub c: [f32; 4],
}

impl From<&hadou_math::soft::BvhTri> for GpuBvhTri {
    fn from(t: &hadou_math::soft::BvhTri) -> Self {
        GpuBvhTri { a: t.a, b: t.b, c: t.c }
    }
}
