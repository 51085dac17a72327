//! The traced resolve of the `[area_light]` (hadou's own, issue 43): each pixel's visibility is
//! the share of the lamp ([`LampShape`]) its point sees, from the lamp's samples' rays against the
//! casters' world-space triangles, found through a flattened bounding volume hierarchy
//! ([`Bvh`]). No shadow maps: the hierarchy itself says where a shadow edge can be.
//!
//! 1. **Tiles.** The image is cut into [`TILE`]² tiles. A tile's receivers (each visible point
//!    moved off its surface by [`TRACE_BIAS`] of its distance to `L`) fit in a ball; every ray
//!    from one of them to the lamp (inside the ball of radius `l` around `L`) lies in the tapered
//!    capsule between the two balls ([`hadou_math::soft::capsule_hits`]). The hierarchy is walked once per tile
//!    with that capsule, a triangle whose plane leaves both balls on one side
//!    ([`hadou_math::soft::BvhTri::one_side`]) dropped: no triangle kept, and every pixel of the tile sees the whole
//!    lamp without a single ray (most of the image); up to [`TILE_TRIS`], and each pixel tests
//!    only those; more, and each pixel walks the hierarchy itself (a node counts when it meets the
//!    pixel's capsule and its box's projection meets the lamp, [`LampFrame::box_may_hide`]).
//! 2. **Pixels.** A pixel's own capsule (radius 0 at its point) and [`hadou_math::soft::BvhTri::one_side`] pick the
//!    triangles that can hide part of its lamp; each sets the samples it hides in the pixel's mask
//!    ([`hadou_math::soft::occlude`]: clipped, projected onto the lamp's plane, each row of samples
//!    solved exactly; for the segment [`hadou_math::soft::occlude_segment`], the triangle's chord
//!    across the plane of the receiver and the segment, which needs no side or capsule test
//!    first); the walk stops once every sample is hidden (umbra). The visibility is the mask's
//!    weighted share of clear samples ([`mask_visibility`]).
//! 3. **Determinism.** A pixel's samples depend only on its global coordinates
//!    ([`pixel_offset`]), and the mask's OR does not depend on the order of the triangles, so the
//!    same frame gives the same bits, banded or whole, on any number of threads.
//!
//! A point the lamp adds nothing to (its unshadowed term is zero: facing away) is given 0, as the
//! two-map resolves give it (shadowed in both maps). [`reference()`] is the brute-force check: every
//! sample ray against every caster triangle, no hierarchy.

use crate::opaque::SoftPoint;
use crate::winding::TileCasters;
use hadou_math::soft::{
    lamp_frame, mask_full, mask_visibility, occlude, occlude_segment, pixel_offset, segment_plane_margin,
    segment_triangle_distance, Bvh, Capsule, LampFrame, LampPattern, LampShape, SegmentWedge, Topology,
    MASK_WORDS, TRACE_BIAS, T_MIN,
};
use hadou_math::{Vec3, Vec3f};
use hadou_scene::{AreaLight, Frame};
use rayon::prelude::*;

/// Edge of a tile of pixels that walks the hierarchy once for all its pixels.
pub const TILE: usize = 8;
/// Most triangles a tile keeps for its pixels (more: each pixel walks the hierarchy).
pub const TILE_TRIS: usize = 4096;
/// The same for the segment lamp, whose pixels take the triangles' chords one by one (each
/// three products where it misses the pixel's plane).
pub const SEGMENT_TILE_TRIS: usize = 512;

/// The world-space triangles of the objects `casters` of `frame` (what the two maps draw,
/// [`crate::soft::SpotDepth::render`]): [`hadou_scene::caster_triangles`], which the GPU backend
/// builds the same hierarchy from.
pub use hadou_scene::caster_triangles;

/// The number of triangles of the objects `casters` (what the hierarchy is built over, before
/// the degenerate ones are dropped).
pub fn caster_triangle_count(frame: &Frame, casters: &[u32]) -> u64 {
    casters
        .iter()
        .filter_map(|&c| frame.objects.get(c as usize))
        .map(|o| o.mesh.indices.len() as u64 / 3)
        .sum()
}

/// The receiver point of a visible point: moved along its unit normal by [`TRACE_BIAS`] of its
/// distance to `L` (not at all without a normal).
#[inline]
pub fn receiver(world: Vec3f, normal: Vec3f, l: Vec3f) -> Vec3f {
    world + normal * (TRACE_BIAS * (world - l).length())
}

/// The lamp of `light` as the traced resolve sees it: its shape, centre, axis and size.
#[derive(Clone, Copy, Debug)]
pub struct Lamp {
    /// Shape.
    pub shape: LampShape,
    /// Centre `L`.
    pub centre: Vec3f,
    /// `P = (L − G)/|L − G|`.
    pub axis: Vec3f,
    /// `l`: half-length or radius (also the radius of the ball that holds the lamp).
    pub size: f32,
}

impl Lamp {
    /// The lamp of `light`.
    pub fn of(light: &AreaLight) -> Lamp {
        Lamp { shape: light.shape, centre: light.position, axis: light.axis(), size: light.size }
    }

    /// The lamp seen from the receiver `p` ([`lamp_frame`]).
    #[inline]
    pub fn frame(&self, p: Vec3f) -> Option<LampFrame> {
        lamp_frame(self.shape, self.centre, self.axis, self.size, p)
    }
}

/// The traced visibility of every pixel of an image `width` pixels wide whose visible points are
/// `points` (row-major, `None` for none: a [`crate::soft::SoftInput`]'s) under `light` with
/// `samples` lamp samples a pixel (see the module notes); 0 where no point is.
pub fn traced(
    frame: &Frame,
    light: &AreaLight,
    points: &[Option<SoftPoint>],
    width: usize,
    samples: u32,
) -> Vec<f32> {
    let bvh = Bvh::build(&caster_triangles(frame, &light.casters));
    traced_with(&bvh, light, points, width, samples)
}

/// [`traced`] with the hierarchy already built.
pub fn traced_with(
    bvh: &Bvh,
    light: &AreaLight,
    points: &[Option<SoftPoint>],
    width: usize,
    samples: u32,
) -> Vec<f32> {
    traced_where(bvh, light, points, width, samples, |_| true, |_, _| true)
}

/// [`traced_with`] of the points `points[i]` for which `wanted(i)` holds, as if every other were
/// `None` (0 there), without a copy of the points. `tile(tx, ty)` false says that tile `(tx, ty)`
/// (columns `TILE·tx..`, rows `TILE·ty..`) has no wanted point: it is skipped unread.
fn traced_where(
    bvh: &Bvh,
    light: &AreaLight,
    points: &[Option<SoftPoint>],
    width: usize,
    samples: u32,
    wanted: impl Fn(usize) -> bool + Sync,
    tile: impl Fn(usize, usize) -> bool + Sync,
) -> Vec<f32> {
    let h = points.len().checked_div(width).unwrap_or(0);
    traced_points(bvh, light, width, h, samples, |i| if wanted(i) { points[i] } else { None }, tile)
}

/// [`traced_where`] of the points `point(i)` of a `width × height` image (`None`: no point, 0).
fn traced_points(
    bvh: &Bvh,
    light: &AreaLight,
    width: usize,
    height: usize,
    samples: u32,
    point: impl Fn(usize) -> Option<SoftPoint> + Sync,
    tile: impl Fn(usize, usize) -> bool + Sync,
) -> Vec<f32> {
    let (w, h) = (width, height);
    let lamp = Lamp::of(light);
    let pat = LampPattern::new(lamp.shape, samples);
    let mut out = vec![0.0f32; w * h];
    if w == 0 || h == 0 {
        return out;
    }
    let topo = Topology::of(bvh);
    let extent = bvh_extent(bvh);
    out.par_chunks_mut(w * TILE).enumerate().for_each(|(ty, band)| {
        let y0 = ty * TILE;
        let rows = band.len() / w;
        let mut ids: Vec<u32> = Vec::with_capacity(TILE_TRIS);
        let mut casters = TileCasters::default();
        let mut cands: Vec<[Vec3f; 3]> = Vec::new();
        let mut receivers: Vec<Vec3f> = Vec::with_capacity(TILE * TILE);
        let cap = if lamp.shape == LampShape::Segment { SEGMENT_TILE_TRIS } else { TILE_TRIS };
        for x0 in (0..w).step_by(TILE) {
            if !tile(x0 / TILE, ty) {
                continue;
            }
            let x1 = (x0 + TILE).min(w);
            // The tile's receivers and their ball.
            let (mut lo, mut hi) = (Vec3f::splat(f32::INFINITY), Vec3f::splat(f32::NEG_INFINITY));
            receivers.clear();
            for y in y0..y0 + rows {
                for x in x0..x1 {
                    if let Some(p) = point(y * w + x).filter(|p| lit_at_all(p.term)) {
                        let r = receiver(p.world, p.normal, lamp.centre);
                        lo = lo.min(r);
                        hi = hi.max(r);
                        receivers.push(r);
                    }
                }
            }
            if receivers.is_empty() {
                continue;
            }
            let (tc, tr) = ((lo + hi) * 0.5, (hi - lo).length() * 0.5);
            // The segment's receivers see it only within the wedge of their planes through it.
            let wedge = (lamp.shape == LampShape::Segment)
                .then(|| {
                    let reach =
                        [lo.x, lo.y, lo.z, hi.x, hi.y, hi.z].iter().fold(0.0f32, |m, v| m.max(v.abs()));
                    let margin = segment_plane_margin(Vec3f::splat(reach), extent);
                    SegmentWedge::around(lamp.centre, lamp.axis, &receivers, margin)
                })
                .flatten();
            ids.clear();
            let mut overflow = false;
            let capsule = Capsule::new(tc, tr, lamp.centre, lamp.size);
            bvh.walk(
                |node| {
                    let (c, r) = node.ball();
                    capsule.hits(c, r) && !wedge.is_some_and(|wg| wg.misses_box(node.lo, node.hi))
                },
                |i, t| {
                    // Outside the straight capsule of the larger radius around the axis from the
                    // tile's centre to `L`, which holds the tapered one.
                    if wedge.is_some_and(|wg| wg.misses(&t.corners()))
                        || t.one_side(tc, tr, lamp.centre, lamp.size)
                        || segment_triangle_distance(tc, lamp.centre, &t.corners()) > tr.max(lamp.size)
                    {
                        return true;
                    }
                    if ids.len() == cap {
                        overflow = true;
                        return false;
                    }
                    ids.push(i as u32);
                    true
                },
            );
            if !ids.is_empty() && !overflow {
                if lamp.shape == LampShape::Segment {
                    cands.clear();
                    cands.extend(ids.iter().map(|&i| bvh.tris[i as usize].corners()));
                } else {
                    casters.set(bvh, &topo, &ids, tc, tr);
                }
            }
            for y in y0..y0 + rows {
                for x in x0..x1 {
                    let Some(p) = point(y * w + x) else { continue };
                    let o = &mut band[(y - y0) * w + x];
                    if !lit_at_all(p.term) {
                        *o = 0.0;
                        continue;
                    }
                    if ids.is_empty() && !overflow {
                        *o = 1.0;
                        continue;
                    }
                    let r = receiver(p.world, p.normal, lamp.centre);
                    *o = if overflow {
                        pixel(bvh, &lamp, &pat, r, x as u32, y as u32, extent)
                    } else {
                        let o = pixel_offset(x as u32, y as u32);
                        match lamp.frame(r) {
                            Some(f) if lamp.shape == LampShape::Segment => by_triangles(&cands, &f, &pat, o),
                            Some(f) => casters.visibility(bvh, &f, &pat, o, lamp.centre, lamp.size),
                            None => 1.0,
                        }
                    };
                }
            }
        }
    });
    out
}

/// Where a pixel's traced value settles its samples ([`traced_grid`]): the largest difference
/// from a 4-neighbour's value (each from its pixel's mean point). Past it the visibility changes by
/// more than an eighth across a pixel (a penumbra under about eight pixels wide: a contact
/// shadow's edge), and the pixel's samples are traced one by one.
pub const GRID_SPREAD: f32 = 0.125;

/// Least cosine between two samples' normals for them to show one surface ([`traced_grid`] step 1).
pub const GRID_NORMAL_COS: f32 = 0.98;

/// [`traced_with`] over a sample frame whose image pixels are `k × k` points each (`width` is the
/// sample frame's): one traced value per pixel where its samples agree, each sample traced where
/// they may not. Two passes, each [`traced_with`]:
///
/// 1. **Pixels.** A pixel whose `k²` points all show one surface (every point
///    present, its normal within [`GRID_NORMAL_COS`] of the first's and on the first's tangent
///    plane) is traced once, from its points' mean position and normal, lit or not (the image of
///    the pixels, pixel `(x, y)` with its own [`pixel_offset`]).
/// 2. **Samples.** A pixel is settled when it was traced in step 1 and each 4-neighbour traced
///    there is within [`GRID_SPREAD`] of it: its samples all take its value (the box filter of a
///    visibility that is linear across the pixel is its value at the mean point). Every other
///    pixel's samples are traced one by one, as with one sample a pixel.
///
/// The decisions read only step 1's values, which depend only on the pixels' own points, so the
/// result is deterministic and independent of the order of work, as [`traced_with`]'s. With
/// `k = 1` (or a `width` that is not a multiple of `k`) it is [`traced_with`]. hadou-gpu's
/// soft_traced.wgsl (`cs_traced_pixels`, then `cs_traced`) is the twin.
pub fn traced_grid(
    bvh: &Bvh,
    light: &AreaLight,
    points: &[Option<SoftPoint>],
    width: usize,
    samples: u32,
    k: usize,
) -> Vec<f32> {
    traced_grid_counted(bvh, light, points, width, samples, k).0
}

/// [`traced_grid`] and how many image pixels it settled in step 1 (each traced once), of how
/// many.
pub fn traced_grid_counted(
    bvh: &Bvh,
    light: &AreaLight,
    points: &[Option<SoftPoint>],
    width: usize,
    samples: u32,
    k: usize,
) -> (Vec<f32>, GridCount) {
    let sh = points.len().checked_div(width).unwrap_or(0);
    if k <= 1 || !width.is_multiple_of(k) || !sh.is_multiple_of(k) || width * sh != points.len() {
        let pixels = points.iter().filter(|p| p.is_some()).count();
        return (traced_with(bvh, light, points, width, samples), GridCount { pixels, settled: 0 });
    }
    traced_grid_of(bvh, light, points, None, width, samples, k)
}

/// The pixels of an anti-aliased frame whose samples take their centre's surface (the opaque
/// pass's `ShadedOnce::centred` under a traced area light, a frame without hard shadows): the
/// samples of such a pixel keep no point of their own.
pub(crate) struct Centred<'a> {
    /// Per image pixel: whether it is centred (its samples' entries of the sample points are then
    /// not read) …
    pub marks: &'a [bool],
    /// … and, where it is, the point at its centre.
    pub pixels: &'a [Option<SoftPoint>],
    /// A sample's world position (index into the sample frame), for a centred pixel whose samples
    /// are traced one by one after all: where its ray meets the pixel's surface.
    pub sample_world: &'a (dyn Fn(usize) -> Vec3f + Sync),
}

/// [`traced_grid_counted`] of a sample frame `width` wide (`k × k` samples a pixel, whole
/// pixels), with the pixels `centred` names given by their centre's point: such a pixel is traced
/// once from it (instead of its samples' mean point), and where its value is not settled its
/// samples are traced at their own positions with the centre's normal and term. A centred pixel's
/// samples all get its value where settled; the caller adds it once.
pub(crate) fn traced_grid_of(
    bvh: &Bvh,
    light: &AreaLight,
    points: &[Option<SoftPoint>],
    centred: Option<&Centred<'_>>,
    width: usize,
    samples: u32,
    k: usize,
) -> (Vec<f32>, GridCount) {
    let sh = points.len() / width;
    let (w, h) = (width / k, sh / k);
    let centre = |p: usize| centred.and_then(|c| if c.marks[p] { c.pixels[p] } else { None });
    // Step 1's points, and how many pixels show anything, row by row.
    let mut reps: Vec<Option<SoftPoint>> = vec![None; w * h];
    let drawn: usize = reps
        .par_chunks_mut(w)
        .enumerate()
        .map(|(py, row)| {
            let mut drawn = 0;
            for (px, rep) in row.iter_mut().enumerate() {
                if let Some(c) = centre(py * w + px) {
                    // (Traced whether or not the lamp adds light there, as `grid_point`'s.)
                    *rep = Some(SoftPoint { term: [1.0; 3], ..c });
                    drawn += 1;
                    continue;
                }
                *rep = grid_point(points, width, k, px, py);
                let any = || (0..k * k).any(|s| points[(k * py + s / k) * width + k * px + s % k].is_some());
                drawn += usize::from(rep.is_some() || any());
            }
            drawn
        })
        .sum();
    let once = traced_with(bvh, light, &reps, w, samples);
    let settled: Vec<bool> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % w, i / w);
            reps[i].is_some() && {
                let v = once[i];
                let near = |j: usize| reps[j].is_none() || (once[j] - v).abs() <= GRID_SPREAD;
                (x == 0 || near(i - 1))
                    && (x + 1 == w || near(i + 1))
                    && (y == 0 || near(i - w))
                    && (y + 1 == h || near(i + w))
            }
        })
        .collect();
    // The sample frame's tiles that hold a pixel left to trace sample by sample.
    let (tw, th) = (width.div_ceil(TILE), sh.div_ceil(TILE));
    let mut open = vec![false; tw * th];
    for (i, &s) in settled.iter().enumerate() {
        if !s {
            let (sx, sy) = (k * (i % w), k * (i / w));
            for ty in sy / TILE..=(sy + k - 1) / TILE {
                for tx in sx / TILE..=(sx + k - 1) / TILE {
                    open[ty * tw + tx] = true;
                }
            }
        }
    }
    // A sample's pixel (read only in the open tiles).
    let pixel_of = |j: usize| ((j / width) / k) * w + (j % width) / k;
    let point = |j: usize| {
        let p = pixel_of(j);
        if settled[p] {
            return None;
        }
        match centre(p) {
            Some(c) => centred.map(|cs| SoftPoint { world: (cs.sample_world)(j), ..c }),
            None => points[j],
        }
    };
    let mut out = traced_points(bvh, light, width, sh, samples, point, |tx, ty| open[ty * tw + tx]);
    out.par_chunks_mut(width).zip(points.par_chunks(width)).enumerate().for_each(|(sy, (o, p))| {
        let py = sy / k;
        for (px, (o, p)) in o.chunks_mut(k).zip(p.chunks(k)).enumerate() {
            let i = py * w + px;
            if settled[i] {
                if let Some(c) = centre(i) {
                    o.fill(if lit_at_all(c.term) { once[i] } else { 0.0 });
                    continue;
                }
                for (o, p) in o.iter_mut().zip(p) {
                    // A point the lamp adds nothing to stays 0, as [`traced_with`] gives it.
                    *o = if p.is_some_and(|p| lit_at_all(p.term)) { once[i] } else { 0.0 };
                }
            }
        }
    });
    let count = GridCount { pixels: drawn, settled: settled.iter().filter(|&&s| s).count() };
    (out, count)
}

/// What [`traced_grid_counted`] settled: of `pixels` image pixels with a visible point, `settled`
/// took one traced value for all their samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GridCount {
    /// Image pixels with a visible point (the points, when there is no grid).
    pub pixels: usize,
    /// Pixels traced once for all their samples.
    pub settled: usize,
}

/// Pixel `(x, y)`'s one point when its `k × k` points of the sample frame (`width` wide) show one
/// surface: every point present, each normal within [`GRID_NORMAL_COS`] of the first's (or all
/// without one), each point within a quarter of its distance from the first of the first's
/// tangent plane (no step between two surfaces that face the same way). The point is the mean of
/// their positions and normals (normalised; the first's where the mean has no direction), with a
/// term of 1 so that it is traced whether or not the lamp adds light there (the GPU's twin does
/// not know the term); `None` otherwise.
fn grid_point(points: &[Option<SoftPoint>], width: usize, k: usize, x: usize, y: usize) -> Option<SoftPoint> {
    let first = points[k * y * width + k * x]?;
    let n0 = first.normal;
    let has_normal = n0.length_squared() > 0.0;
    let (mut world, mut normal) = (Vec3f::splat(0.0), Vec3f::splat(0.0));
    for j in 0..k {
        for i in 0..k {
            let p = points[(k * y + j) * width + k * x + i]?;
            if (p.normal.length_squared() > 0.0) != has_normal {
                return None;
            }
            if has_normal {
                let d = p.world - first.world;
                if p.normal.dot(n0) < GRID_NORMAL_COS * p.normal.length() * n0.length()
                    || d.dot(n0).abs() > 0.25 * d.length() * n0.length()
                {
                    return None;
                }
            }
            world += p.world;
            normal += p.normal;
        }
    }
    let inv = 1.0 / (k * k) as f32;
    let normal = if has_normal { normal.normalize_or(n0) } else { normal };
    Some(SoftPoint { world: world * inv, normal, term: [1.0; 3] })
}

/// The largest coordinate magnitude of the hierarchy's triangles (its root box's), for
/// [`segment_plane_margin`]; 0 without triangles.
fn bvh_extent(bvh: &Bvh) -> f32 {
    bvh.nodes.first().map_or(0.0, |n| n.lo.iter().chain(&n.hi).fold(0.0f32, |m, v| m.max(v.abs())))
}

/// Whether an unshadowed term adds anything.
#[inline]
fn lit_at_all(term: [f32; 3]) -> bool {
    term.iter().any(|&t| t > 0.0)
}

/// One pixel's visibility from its lamp frame `f` (a segment's) by the tile's candidates one by
/// one ([`occlude_segment`] each, in the mask), stopping once every sample is hidden: what the
/// segment lamp uses, whose plane runs through the casters its axis points at and whose chords
/// make each triangle cheap. A triangle wholly on one side of the plane through the receiver and
/// the segment costs [`occlude_segment`] three products: most of a tile's candidates are.
fn by_triangles(cands: &[[Vec3f; 3]], f: &LampFrame, pat: &LampPattern, o: f32) -> f32 {
    let mut mask = [0u32; MASK_WORDS];
    for c in cands {
        occlude_segment(f, pat, o, c, &mut mask);
        if mask_full(&mask, pat) {
            return 0.0;
        }
    }
    mask_visibility(&mask, pat)
}

/// One pixel's visibility from the receiver `r` at global pixel `(x, y)` by a walk of the
/// whole hierarchy (a tile with more than [`TILE_TRIS`] candidates), triangle by triangle.
///
/// For the segment lamp, a node wholly on one side of the plane through the receiver and the
/// segment is skipped first ([`LampFrame::box_beside_segment_plane`]), and each triangle's chord
/// taken ([`occlude_segment`]).
fn pixel(bvh: &Bvh, lamp: &Lamp, pat: &LampPattern, r: Vec3f, x: u32, y: u32, extent: f32) -> f32 {
    let Some(f) = lamp.frame(r) else { return 1.0 };
    let o = pixel_offset(x, y);
    let segment = lamp.shape == LampShape::Segment;
    let margin = segment_plane_margin(r, extent);
    let capsule = Capsule::new(r, 0.0, lamp.centre, lamp.size);
    let mut mask = [0u32; MASK_WORDS];
    // `Bvh::walk`, with a node test that reads the mask the leaves write.
    let mut i = 0usize;
    while i < bvh.nodes.len() {
        let node = &bvh.nodes[i];
        let (c, rc) = node.ball();
        if segment && f.box_beside_segment_plane(node.lo, node.hi, margin) {
            i = node.skip as usize;
            continue;
        }
        if !(capsule.hits(c, rc) && f.box_may_hide(node.lo, node.hi, pat, o, &mask)) {
            i = node.skip as usize;
            continue;
        }
        match node.leaf() {
            None => i += 1,
            Some(range) => {
                for t in &bvh.tris[range] {
                    let corners = t.corners();
                    // The segment's chord does in three products what the side test would.
                    if segment {
                        occlude_segment(&f, pat, o, &corners, &mut mask);
                    } else if !t.one_side(r, 0.0, lamp.centre, lamp.size) {
                        occlude(&f, pat, o, &corners, &mut mask);
                    } else {
                        continue;
                    }
                    if mask_full(&mask, pat) {
                        return 0.0;
                    }
                }
                i = node.skip as usize;
            }
        }
    }
    mask_visibility(&mask, pat)
}

/// Point `k` of `n` stratified points of the unit square: stratum `k` of a `⌈√n⌉`-wide grid,
/// jittered by `rand`.
fn stratified(k: u32, side: u32, rand: &mut impl FnMut() -> f64) -> (f64, f64) {
    let (i, j) = (k % side, k / side);
    ((f64::from(i) + rand()) / f64::from(side), (f64::from(j) + rand()) / f64::from(side))
}

/// Shirley and Chiu's concentric map of the unit square onto the unit disc (equal areas).
fn concentric(u: f64, v: f64) -> (f64, f64) {
    let (a, b) = (2.0 * u - 1.0, 2.0 * v - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    let (r, phi) = if a * a > b * b {
        (a, std::f64::consts::FRAC_PI_4 * (b / a))
    } else {
        (b, std::f64::consts::FRAC_PI_2 - std::f64::consts::FRAC_PI_4 * (a / b))
    };
    (r * phi.cos(), r * phi.sin())
}

/// Möller–Trumbore in `f64`, both sides: the ray parameter where `o + t·d` meets the triangle.
fn ray_triangle(o: Vec3<f64>, d: Vec3<f64>, t: &[Vec3<f64>; 3]) -> Option<f64> {
    let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - t[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    Some(e2.dot(q) * inv)
}

/// The brute-force reference of the traced resolve at the pixels `pixels` (row-major indices) of
/// the visible points `points`: for each, `samples` points of the lamp as seen from the pixel's receiver
/// ([`receiver`], [`Lamp::frame`]) — stratified in `⌈√samples⌉²` cells (the segment: `samples`
/// strata along it) and mapped onto the disc by the concentric map, jittered by a generator
/// seeded from the pixel's index — each ray tested against every caster triangle whose box meets
/// the box of the receiver and the lamp's ball (no hierarchy), in `f64`, a blocker counting at
/// `t ∈ [T_MIN, 1]`. The share of clear rays; 0 where no point is or the lamp adds nothing, 1
/// where the lamp has no frame. Slow: for tests and `hadou bench shadows`.
pub fn reference(
    frame: &Frame,
    light: &AreaLight,
    points: &[Option<SoftPoint>],
    samples: u32,
    pixels: &[usize],
) -> Vec<f32> {
    let tris: Vec<[Vec3<f64>; 3]> =
        caster_triangles(frame, &light.casters).iter().map(|t| t.map(|v| v.as_f64())).collect();
    let boxes: Vec<(Vec3<f64>, Vec3<f64>)> =
        tris.iter().map(|t| (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]))).collect();
    let lamp = Lamp::of(light);
    let samples = samples.max(1);
    let side = (f64::from(samples).sqrt().ceil() as u32).max(1);
    pixels
        .par_iter()
        .with_min_len(4)
        .map(|&i| {
            let Some(p) = points.get(i).copied().flatten() else { return 0.0 };
            if !lit_at_all(p.term) {
                return 0.0;
            }
            let r = receiver(p.world, p.normal, lamp.centre);
            let Some(f) = lamp.frame(r) else { return 1.0 };
            let (o, c) = (r.as_f64(), lamp.centre.as_f64());
            let reach = f64::from(lamp.size) * 1.001 + 1e-9;
            let (blo, bhi) = (o.min(c - Vec3::splat(reach)), o.max(c + Vec3::splat(reach)));
            let near: Vec<&[Vec3<f64>; 3]> = tris
                .iter()
                .zip(&boxes)
                .filter(|(_, (lo, hi))| {
                    lo.x <= bhi.x
                        && lo.y <= bhi.y
                        && lo.z <= bhi.z
                        && hi.x >= blo.x
                        && hi.y >= blo.y
                        && hi.z >= blo.z
                })
                .map(|(t, _)| t)
                .collect();
            let mut state = (i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ 0xd1b5_4a32_d192_ed03;
            let mut rand = move || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64
            };
            let (centre, u, v, rad) = (f.centre.as_f64(), f.u.as_f64(), f.v.as_f64(), f64::from(f.radius));
            let mut clear = 0u32;
            for k in 0..samples {
                let (x, y) = if lamp.shape == LampShape::Segment {
                    (-1.0 + 2.0 * (f64::from(k) + rand()) / f64::from(samples), 0.0)
                } else {
                    let (a, b) = stratified(k % (side * side), side, &mut rand);
                    concentric(a, b)
                };
                let target = centre + (u * x + v * y) * rad;
                let d = target - o;
                let blocked = near
                    .iter()
                    .any(|t| ray_triangle(o, d, t).is_some_and(|t| t >= f64::from(T_MIN) && t <= 1.0));
                clear += u32::from(!blocked);
            }
            clear as f32 / samples as f32
        })
        .collect()
}

/// The pixels the reference is computed at for a traced image `traced` (`width` wide, `visible`
/// pixels marked): every visible pixel within 2 pixels (Chebyshev) of one whose value lies in
/// `(0.005, 0.995)`, and every 61st other visible pixel (to check the tiles' and the umbra's
/// verdicts away from any edge), then every `k`-th of those so that at most `cap` remain.
pub fn reference_pixels(traced: &[f32], visible: &[bool], width: usize, cap: usize) -> Vec<usize> {
    let h = traced.len() / width.max(1);
    let soft = |i: usize| traced[i] > 0.005 && traced[i] < 0.995;
    let mut near = vec![false; traced.len()];
    for i in (0..traced.len()).filter(|&i| visible[i] && soft(i)) {
        let (x, y) = ((i % width) as i64, (i / width) as i64);
        for dy in -2..=2 {
            for dx in -2..=2 {
                let (u, v) = (x + dx, y + dy);
                if u >= 0 && v >= 0 && (u as usize) < width && (v as usize) < h {
                    near[v as usize * width + u as usize] = true;
                }
            }
        }
    }
    let all: Vec<usize> = (0..traced.len()).filter(|&i| visible[i] && (near[i] || i % 61 == 0)).collect();
    let step = all.len().div_ceil(cap.max(1)).max(1);
    all.into_iter().step_by(step).collect()
}

/// The truth measure of issue 43 over the pixels `pixels`, `a` and `b` their two values (same
/// order): the pixels where either value lies in `(0.005, 0.995)`, their mean and 99th-percentile
/// `|a − b|`, and how many there were. `(0, 0, 0)` when none.
pub fn truth_errors(a: &[f32], b: &[f32]) -> (f64, f64, usize) {
    let soft = |v: f32| v > 0.005 && v < 0.995;
    let mut e: Vec<f64> = a
        .iter()
        .zip(b)
        .filter(|(&x, &y)| soft(x) || soft(y))
        .map(|(&x, &y)| f64::from((x - y).abs()))
        .collect();
    if e.is_empty() {
        return (0.0, 0.0, 0);
    }
    e.sort_by(f64::total_cmp);
    let mean = e.iter().sum::<f64>() / e.len() as f64;
    let p99 = e[((e.len() - 1) as f64 * 0.99).round() as usize];
    (mean, p99, e.len())
}
