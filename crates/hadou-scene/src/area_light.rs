//! `[area_light]` in a frame: a lamp-sized light whose shadows soften with distance (003, SPEC.md
//! §4). The frame's plain value ([`AreaLight`]) carries everything both backends need: the light
//! centre `L`, the point of interest `G`, the two shadow-map positions `L₁ = L + l·P`,
//! `L₂ = L − l·P` and their perspective frames, and how the penumbra is resolved
//! ([`SoftResolve`], [`Penumbra`]), and the lamp's shape ([`LampShape`]). `area_light_def.rs`
//! reads the table and builds this value.

use hadou_math::soft::{CasterBox, SpotMap};
pub use hadou_math::soft::{LampShape, MAX_TRACE_SAMPLES};
use hadou_math::Vec3f;

/// Most pixels of an image with an `[area_light]` (4096²): the penumbra search works on the whole
/// image at once (about 60 bytes a pixel on the CPU).
pub const SOFT_MAX_PIXELS: u64 = 1 << 24;
/// Largest `n` of the faithful resolve.
pub const MAX_GRID: u32 = 64;
/// Lamp samples a pixel of the traced resolve when `samples` is not given.
pub const DEFAULT_TRACE_SAMPLES: u32 = 256;

/// How penumbra pixels find their nearest umbra and lit pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SoftResolve {
    /// Exact Euclidean distance transforms: every penumbra pixel's exact distances (hadou's
    /// default).
    Exact,
    /// 003 §3.3 (SPEC.md §4.2–4.3): a search on every `n`-th pixel in x and y, the others
    /// interpolated bilinearly (standard weights).
    Faithful {
        /// Grid spacing, `1..=MAX_GRID`.
        n: u32,
    },
    /// hadou's (issue 43): the share of the lamp each pixel sees, from its samples' rays against
    /// the casters' triangles through a bounding volume hierarchy
    /// ([`hadou_math::soft::occlude`], [`hadou_math::soft::Bvh`]); models every [`LampShape`].
    Traced {
        /// Lamp samples a pixel, `1..=MAX_TRACE_SAMPLES`.
        samples: u32,
    },
}

/// How a penumbra pixel's brightness follows from its distances `D₁` to the nearest umbra pixel
/// and `D₂` to the nearest lit pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Penumbra {
    /// hadou's: the fraction of the segment light between the two map positions that the pixel
    /// sees, `k·D₁/(k·D₁ + D₂)` ([`hadou_math::soft::segment_brightness`]); the default of the
    /// exact resolve.
    Segment,
    /// 003's `D₁/(D₁ + D₂)` as SPEC.md §4.2 corrects it; the default of the faithful resolve.
    Linear,
}

/// The frame's `[area_light]`.
#[derive(Clone, Debug, PartialEq)]
pub struct AreaLight {
    /// Light centre `L`.
    pub position: Vec3f,
    /// Size parameter `l > 0` (less than `|L − G|`): the segment's half-length, the disc's or
    /// the sphere's radius.
    pub size: f32,
    /// The lamp's shape: what the traced resolve models and whose light is added.
    pub shape: LampShape,
    /// Point of interest `G`.
    pub interest: Vec3f,
    /// Linear RGB times intensity.
    pub color: [f32; 3],
    /// Shadow-map edge in texels.
    pub map_size: u32,
    /// Penumbra resolve.
    pub resolve: SoftResolve,
    /// Depth-aware search ([`hadou_math::soft::same_surface`]).
    pub depth_aware: bool,
    /// The penumbra's brightness from its distances.
    pub penumbra: Penumbra,
    /// The objects drawn into the maps (indices into `Frame::objects`); every object receives.
    pub casters: Vec<u32>,
    /// The two maps: `[L₁ = L + l·P, L₂ = L − l·P]`, each looking at `G`, every caster inside.
    /// The renderers narrow each to the visible points that a caster can shadow
    /// ([`hadou_math::soft::SpotMap::fitted`]) before drawing it.
    pub maps: [SpotMap; 2],
    /// The casters' boxes in the world ([`crate::caster_box`]), in the order of `casters`
    /// less the empty meshes: what the maps are fitted with.
    pub caster_boxes: Vec<CasterBox>,
}

impl AreaLight {
    /// The `k` of [`hadou_math::soft::segment_brightness`] for this frame: `(D + l)/(D − l)` with
    /// `D = |L − G|` for [`Penumbra::Segment`], 1 (003's linear ratio) for [`Penumbra::Linear`].
    pub fn penumbra_ratio(&self) -> f32 {
        match self.penumbra {
            Penumbra::Linear => 1.0,
            Penumbra::Segment => {
                hadou_math::soft::segment_ratio(self.size, (self.position - self.interest).length())
            }
        }
    }

    /// The lamp's axis `P = (L − G)/|L − G|` (the segment's direction, the disc's normal).
    pub fn axis(&self) -> Vec3f {
        (self.position - self.interest).normalize_or(Vec3f::Y)
    }
}
