//! The hard shadows' records: each cast (`GpuShadowCast`) and the frame's (`FrameShadows`).

use bytemuck::{Pod, Zeroable};
use hadou_math::shadow::MapFrame;
use hadou_scene::{Frame, ShadowCast, ShadowMethod};

/// `GpuShadowCast::map_size` of a plane cast. Map casts have a size of at least 1.
pub const CAST_PLANE: u32 = 0;
/// 32-bit words per [`GpuShadowCast`] record in the shading data buffer. Keep in sync with
/// `SHADOW_CAST_WORDS` in common.wgsl.
pub const SHADOW_CAST_WORDS: u32 = (std::mem::size_of::<GpuShadowCast>() / 4) as u32;

/// One shadow cast ([`ShadowCast`]): a plane projection or a shadow map, with what the passes
/// need of its shadow. The plane-shadow and map passes read them from a storage buffer, the wave
/// pass from the shading data buffer (word by word, `load_shadow_cast` in shadow_lookup.wgsl).
/// Keep in sync with `GpuShadowCast` in common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuShadowCast {
    /// Unit projection direction `k` ([`MapFrame::k`] for a map).
    pub k: [f32; 3],
    /// Effective opacity, `> 0`.
    pub opacity: f32,
    /// Plane: a point of the receiver plane.
    pub plane_point: [f32; 3],
    /// Index of the cast's shadow in [`Frame::shadows`] (its bit in `GpuMaterial::shadow_mask`).
    pub shadow: u32,
    /// Plane: the plane's unit normal.
    pub plane_normal: [f32; 3],
    /// Plane: the depth the plane-shadow pass writes (`rank · 2⁻²⁴`, rank 0 for the largest
    /// opacity of the frame's plane casts), so that its `Less` test keeps the most opaque cast
    /// and, among equal opacities, the first.
    pub depth_key: f32,
    /// The shadow's linear RGB colour.
    pub color: [f32; 3],
    /// Map: edge in texels; [`CAST_PLANE`] for a plane cast.
    pub map_size: u32,
    /// Map: [`MapFrame::center`].
    pub map_center: [f32; 3],
    /// Map: `0.5 / radius`, as [`MapFrame::to_map`] computes it.
    pub map_scale: f32,
    /// Map: [`MapFrame::u`].
    pub map_u: [f32; 3],
    /// Map: layer of the shadow-map array texture.
    pub map_layer: u32,
    /// Map: [`MapFrame::v`].
    pub map_v: [f32; 3],
    /// Map: [`MapFrame::bias`] of `map_size`.
    pub map_bias: f32,
}

/// The GPU form of a frame's shadow casts ([`Frame::shadow_casts`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameShadows {
    /// One record per cast, in cast order.
    pub casts: Vec<GpuShadowCast>,
    /// Indices of the map casts, in cast order (map cast `i` is in layer `i`).
    pub map_casts: Vec<u32>,
    /// Edge of the shadow-map texture: the largest map size (0 without map casts).
    pub map_size: u32,
    /// Layers of the shadow-map texture: at least 2 (OpenGL backends mistake a one-layer array
    /// texture for a plain 2D one).
    pub map_layers: u32,
}

impl FrameShadows {
    /// The records of `casts` (from [`Frame::shadow_casts`] of `frame`).
    pub fn new(frame: &Frame, casts: &[ShadowCast]) -> Self {
        let mut opacities: Vec<f32> = casts.iter().filter(|c| c.map.is_none()).map(|c| c.opacity).collect();
        opacities.sort_by(|a, b| b.total_cmp(a));
        opacities.dedup();
        let mut out = FrameShadows { map_layers: 2, ..Default::default() };
        for (j, c) in casts.iter().enumerate() {
            let shadow = &frame.shadows[c.shadow as usize];
            let mut g = GpuShadowCast::zeroed();
            g.k = c.k.to_array();
            g.opacity = c.opacity;
            g.shadow = c.shadow;
            g.color = shadow.color;
            match (c.map, shadow.method) {
                (Some(map), ShadowMethod::Map { size }) => {
                    let size = size.max(1);
                    g.k = map.k.to_array();
                    g.map_size = size;
                    g.map_center = map.center.to_array();
                    g.map_scale = 0.5 / map.radius;
                    g.map_u = map.u.to_array();
                    g.map_v = map.v.to_array();
                    g.map_layer = out.map_casts.len() as u32;
                    g.map_bias = MapFrame::bias(size);
                    out.map_casts.push(j as u32);
                    out.map_size = out.map_size.max(size);
                }
                (_, ShadowMethod::Plane(plane)) => {
                    g.plane_point = plane.point.to_array();
                    g.plane_normal = plane.normal.to_array();
                    let rank = opacities.partition_point(|&o| o > c.opacity);
                    // Exact in f32 below 2²⁴ ranks; more distinct opacities than that cannot occur
                    // (each cast draws at least one mesh).
                    g.depth_key = rank.min((1 << 24) - 1) as f32 / (1u32 << 24) as f32;
                }
                // A map shadow's cast without a map frame (`shadow_casts` makes none): inert, its
                // zero plane normal makes every `t` NaN, so it covers no pixel.
                (None, ShadowMethod::Map { .. }) => {}
            }
            out.casts.push(g);
        }
        out.map_layers = out.map_layers.max(out.map_casts.len() as u32);
        out
    }
}
