//! `[[shadow]]` in a frame: hard shadows cast by chosen objects onto chosen receivers, from the sun
//! (001, SPEC.md §3) or from a wave (000 §2.4, SPEC.md §2.4), found on a receiver plane by
//! projection or on any receiver by an orthographic shadow map. The frame's plain values
//! ([`Shadow`], [`ShadowCast`]) and the limits on shadows and maps; `shadow_def.rs` reads the
//! block, `shadow_casts.rs` computes [`Frame::shadow_casts`](crate::Frame::shadow_casts).

use hadou_math::shadow::{MapFrame, Plane};
use hadou_math::Vec3f;

/// Most `[[shadow]]` tables in one scene (receivers carry one bit per shadow).
pub const MAX_SHADOWS: usize = 16;
/// Largest shadow-map edge in texels (WebGPU's guaranteed `maxTextureDimension2D`).
pub const MAX_MAP_SIZE: u32 = 8192;
/// Most shadow-map texels of one frame together (every map of every shadow; 256 MiB of `f32`).
pub const MAX_MAP_TEXELS: u64 = 1 << 26;
/// Most maps of one frame (a sun shadow needs one, a wave shadow one per caster).
pub const MAX_MAPS: usize = 64;
/// Most casters of all `[[shadow]]`s together, each shadow's list counted (so also the most casts
/// of a frame: a wave shadow casts once per caster).
pub const MAX_SHADOW_CASTERS: usize = 1024;
/// Most triangles the shadows cast: each shadow's casters' triangles, summed over the shadows
/// (what the plane casts project and the maps rasterize per frame), the same as the scene's
/// triangle budget [`MAX_TRIANGLES`](crate::MAX_TRIANGLES).
pub const MAX_SHADOW_TRIANGLES: u64 = crate::limits::MAX_TRIANGLES;
/// A visible point counts as on a receiver plane within `ON_PLANE · (1 + eye distance)` of it.
pub const ON_PLANE: f32 = 1e-3;

/// Where a shadow's light comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadowLight {
    /// Parallel rays travelling along this unit direction (001: the sun).
    Sun(Vec3f),
    /// Wave `wave` (index into [`Frame::waves`](crate::Frame::waves)), each caster's direction
    /// clamped to at most `theta` radians from straight down (000 §2.4).
    Wave {
        /// Index into `Frame::waves`.
        wave: u32,
        /// Longest-shadow angle `θ ∈ [0, π/2)`, radians.
        theta: f32,
    },
}

/// How a shadow finds the surface it falls on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadowMethod {
    /// Projection onto a plane (the theses): shows on receiver points within [`ON_PLANE`] of it.
    Plane(Plane),
    /// An orthographic shadow map of `size²` texels per map along each projection direction: any
    /// receiver shape (hadou's answer to the uneven receivers 000 leaves open).
    Map {
        /// Edge in texels, `1..=MAX_MAP_SIZE`.
        size: u32,
    },
}

/// One `[[shadow]]` of a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Shadow {
    /// Name from the scene file.
    pub name: String,
    /// The light.
    pub light: ShadowLight,
    /// Plane projection or shadow map.
    pub method: ShadowMethod,
    /// Unit normal of the receivers' lit side: `−up` is "straight down" for θ, and a light must
    /// travel against it (`k·up < 0`) to cast (the plane's normal for [`ShadowMethod::Plane`]).
    pub up: Vec3f,
    /// Casting objects (indices into [`Frame::objects`](crate::Frame::objects)).
    pub casters: Vec<u32>,
    /// Receiving objects (indices into [`Frame::objects`](crate::Frame::objects)), ascending.
    pub receivers: Vec<u32>,
    /// Linear RGB of the shadow.
    pub color: [f32; 3],
    /// Opacity in `[0, 1]`: a shadowed point becomes `(1 − o)·colour + o·shadow colour`.
    pub opacity: f32,
}

/// One projection of a frame: some casters of one shadow moved along one direction. Computed by
/// [`Frame::shadow_casts`](crate::Frame::shadow_casts); a sun shadow gives one cast for all its
/// casters, a wave shadow one per caster.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadowCast {
    /// Index into [`Frame::shadows`](crate::Frame::shadows).
    pub shadow: u32,
    /// The casting objects.
    pub casters: Vec<u32>,
    /// Unit projection direction `k` (from the light towards the receiver).
    pub k: Vec3f,
    /// Effective opacity: the shadow's opacity times
    /// [`horizon_fade`](hadou_math::shadow::horizon_fade), `> 0`.
    pub opacity: f32,
    /// For [`ShadowMethod::Map`]: the map's frame around the casters' bounding sphere.
    pub map: Option<MapFrame>,
}

impl Shadow {
    /// Whether object `o` receives this shadow (a binary search: the renderers ask per pixel).
    #[inline]
    pub fn receives(&self, o: u32) -> bool {
        self.receivers.binary_search(&o).is_ok()
    }
}
