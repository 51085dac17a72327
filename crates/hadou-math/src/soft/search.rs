//! How far a penumbra pixel searches and which pixels count (003 §4.5, SPEC.md §4.5).

use crate::Vec3f;

/// Farthest a penumbra pixel looks for its nearest umbra and lit pixels, in pixels: beyond it a
/// kind counts as absent (its distance infinite), in every resolve alike, so the faithful search
/// (which costs the square of the distance) stays bounded and the exact resolve gives the same
/// answer. Wider than any penumbra 003 shows at 512².
pub const SEARCH_RADIUS: u32 = 256;

/// Depth-aware search (003 §4.5's proposal, SPEC.md §4.5): an umbra or lit pixel whose visible
/// point `q` lies off the tangent plane of the penumbra pixel's point `p` (unit normal `n`) by more
/// than this fraction of their distance, `|n·(q − p)| > DEPTH_SLOPE·|q − p|` (a slope of 17°), is
/// across a depth discontinuity and does not count.
pub const DEPTH_SLOPE: f32 = 0.3;

/// Whether `q` counts for a penumbra pixel at `p` with unit normal `n` under the depth-aware search
/// ([`DEPTH_SLOPE`]).
#[inline]
pub fn same_surface(p: Vec3f, n: Vec3f, q: Vec3f) -> bool {
    let d = q - p;
    d.dot(n).abs() <= DEPTH_SLOPE * d.length()
}
