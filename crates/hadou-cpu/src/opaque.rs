//! The opaque pass: the frame's objects and then their inverted-hull outlines (000 §2.3) drawn
//! with [`crate::raster`] into the [`OpaqueBuffers`], each visible point shaded
//! ([`crate::shading`]: the materials and the waves as lights) and darkened by the hard shadows
//! ([`crate::shadows`]); with an `[area_light]`, each visible point is also kept for the soft
//! shadows ([`SoftPoint`]).
//!
//! The depth test is `z < stored z` in submission order, so ties keep the earlier triangle and the
//! result does not depend on the number of threads. Every object's triangles come first, then the
//! outline hulls, of which only the back faces are drawn. The GPU backend's raster pass matches
//! these conventions.

use crate::raster::{cover, edge, perspective, Bands, ScreenProjection, ScreenTri, Tris, Vert, BAND, BATCH};
use crate::setup::FrameSetup;
use crate::shading;
use crate::shadows::NO_SHADOW;
use hadou_math::{outline, Vec3, Vec3f};
use hadou_scene::{CameraBasis, Frame};
use rayon::prelude::*;

/// A visible pixel's point for the soft shadows: with an `[area_light]` the opaque pass keeps one
/// per pixel, and the soft-shadow stage takes them ([`SoftInput`](crate::soft::SoftInput)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftPoint {
    /// World position.
    pub world: Vec3f,
    /// Unit normal (zero if the surface has none).
    pub normal: Vec3f,
    /// What the area light adds there when fully visible (`shading::area_term`).
    pub term: [f32; 3],
}

/// What the opaque pass leaves per pixel.
#[derive(Default)]
pub(crate) struct OpaqueBuffers {
    /// Shaded linear RGB, background where nothing is drawn. Not written for the samples of a
    /// pixel [`ShadedOnce::centred`] marks (their colour is the pixel's [`ShadedOnce::centre`]).
    pub color: Vec<[f32; 3]>,
    /// Eye distance to the visible surface (finite), `+∞` where nothing is drawn (as the wave
    /// pass reads it).
    pub surface: Vec<f32>,
    /// Index into `frame.objects` of the visible object, [`NONE`] where nothing is drawn (four
    /// bytes a sample, not an `Option`'s eight: a frame at 4 samples a pixel writes and reads
    /// these buffers sample by sample).
    pub object: Vec<u32>,
    /// Index into `frame.shadows` of the shadow the pixel takes, [`NONE`] where none (and, not
    /// written, for the samples of a pixel [`ShadedOnce::centred`] marks).
    pub shadow: Vec<u32>,
    /// With an `[area_light]`: each pixel's visible point for the soft shadows (`None` for the
    /// background and outline hulls; not written for the samples of a pixel
    /// [`ShadedOnce::centred`] marks, whose one point is [`ShadedOnce::soft`]'s); empty without
    /// one.
    pub soft: Vec<Option<SoftPoint>>,
    /// The soft-shadow visibility per pixel once resolved (empty before, and without an area
    /// light).
    pub visibility: Vec<f32>,
    /// What the edge pass ([`crate::edges`]) and the anti-aliased resolve read of each drawn
    /// pixel (the GPU's G-buffer holds the same), in three planes so that each reader touches
    /// only the bytes it needs (a frame at 4 samples a pixel scans them sample by sample): the
    /// interpolated world normal (not unit; zero where the surface has none) …
    pub normal: Vec<Vec3f>,
    /// … the material slot of the visible triangle's object, with [`HULL`] set for an outline
    /// hull fragment (0 where nothing is drawn) …
    pub material: Vec<u32>,
    /// … and the hull's reach across the view ray (`hadou_math::outline::reach_code`, at most
    /// `REACH_STEPS` = 255): 0 for hulls, the background and materials without an outline, and
    /// where the edge pass does not read it (wherever the four neighbours show surfaces of the
    /// same object).
    pub reach: Vec<u8>,
    /// A `[bloom]` frame's linear colour, kept from frame to frame (not the opaque pass's).
    pub glare_linear: Vec<[f32; 3]>,
    /// The glare's planes, kept from frame to frame (not the opaque pass's).
    pub glare_planes: hadou_math::bloom::PlanePool,
    /// With `k × k` samples a pixel: what shading once per pixel and surface keeps between the
    /// bands and the refinement ([`ShadedOnce`]); empty otherwise.
    pub once: ShadedOnce,
}

/// Anti-aliasing at the price of multisampling (issue 44): where all `k × k` samples of a pixel
/// show one triangle (not an outline hull), the surface is shaded once, at the pixel's centre,
/// and every sample takes that colour and, with an `[area_light]`, that unshadowed lamp term (its
/// own hard shadow, soft-shadow visibility, depth and edge data stay per sample); coverage and
/// depth stay per sample. In a frame without hard shadows, and with soft shadows only under the
/// traced resolve, whose samples need no visible point of their own, such a pixel's samples also
/// take the centre's surface (its normal, for the edge pass) without an interpolation of their
/// own (the traced resolve traces the pixel once from its centre, and its samples, where they
/// see the lamp differently, from their own eye distances: `traced::Centred`): a sample's eye distance is its view depth
/// from the raster times its ray's length (so the waves' clipping and the outlines' depth tests
/// keep each sample's depth), and the outline's reach stays the sample's own. Where the shading changes across the
/// pixel — a toon band's, a texture's or a wave light's edge — the centre colour differs from a
/// neighbouring pixel's of the same object and material by more than [`ONCE_CONTRAST`], and the
/// pixel is shaded sample by sample after all ([`refine`]), as every pixel was before. The
/// decision reads only pixels whose samples are drawn exactly as in the whole frame, so bands
/// still equal the whole frame bit for bit.
#[derive(Default)]
pub(crate) struct ShadedOnce {
    /// Per pixel of the drawn rows: the shaded colour at its centre where its samples share one
    /// triangle (before the hard shadows), NaN elsewhere.
    pub(crate) centre: Vec<[f32; 3]>,
    /// Per pixel: that triangle (`u32::MAX`: none).
    tri: Vec<u32>,
    /// With an `[area_light]`, per pixel: what the lamp adds at its centre where its samples
    /// share one triangle (`shading::area_term`; every sample takes it, as it takes the centre
    /// colour); empty without one.
    term: Vec<[f32; 3]>,
    /// With a traced `[area_light]` and the pixels centred ([`ShadedOnce::centred`]), per pixel:
    /// the soft-shadow point at its centre where it is centred (its samples' entries of
    /// [`OpaqueBuffers::soft`] are then not written), `None` elsewhere; empty otherwise.
    pub(crate) soft: Vec<Option<SoftPoint>>,
    /// Per sample: the plane shadows' choice (for the samples a refinement shades again); empty
    /// in a frame without plane shadows, where every choice is [`NO_SHADOW`].
    best: Vec<crate::shadows::Choice>,
    /// Per pixel: its samples all take its centre colour and no shadow, and their entries of
    /// [`OpaqueBuffers::color`] and [`OpaqueBuffers::shadow`] are not written (some 16 bytes a
    /// sample that the resolve would read back only to sum four equal values). Set where the
    /// samples of a pixel shaded once take its centre's surface too (a frame without shadows);
    /// cleared, once the samples are written after all, by the refinement and by the edge pass
    /// ([`ShadedOnce::expand`]). Empty where no pixel is shaded once.
    pub(crate) centred: Vec<bool>,
    /// The samples' grid edge `k` of the pixels above (1 where none is shaded once).
    pub(crate) grid: usize,
    /// Per pixel, for the refinement's comparisons: its object and material slot
    /// (`(object << 32) | slot`; `u64::MAX`: not shaded once) …
    keys: Vec<u64>,
    /// … and the square roots of its centre colour's channels and, with an `[area_light]`, of its
    /// area-light term's: [`probe_channels`] planes a pixel row, each a row of pixels (so that
    /// the comparisons run along rows in lanes).
    seen: Vec<f32>,
    /// Per pixel: which of its pairs with its neighbours differ ([`PAIR_E`] and the rest).
    pairs: Vec<u8>,
    /// Shade every sample instead (the tests' reference).
    pub every_sample: bool,
}

/// Writes the centre colour and no shadow into every sample of pixel `px` (column) of a row of
/// pixels marked [`ShadedOnce::centred`], and clears the mark: the samples then hold their own
/// entries, which the caller may change one by one. `color` and `shadow` hold the pixel row's
/// `k` sample rows of width `w`; nothing happens where the pixel is not marked.
pub(crate) fn expand(
    centred: &mut bool,
    centre: [f32; 3],
    k: usize,
    w: usize,
    px: usize,
    color: &mut [[f32; 3]],
    shadow: &mut [u32],
) {
    if !std::mem::take(centred) {
        return;
    }
    for j in 0..k {
        let i = j * w + px * k;
        color[i..i + k].fill(centre);
        shadow[i..i + k].fill(NONE);
    }
}

/// A band's share of [`ShadedOnce`]: its pixels' centre colours, triangles and area-light terms,
/// its samples' plane-shadow choices.
struct OnceBand<'a> {
    centre: &'a mut [[f32; 3]],
    tri: &'a mut [u32],
    term: &'a mut [[f32; 3]],
    soft: &'a mut [Option<SoftPoint>],
    best: &'a mut [crate::shadows::Choice],
    keys: &'a mut [u64],
    seen: &'a mut [f32],
    centred: &'a mut [bool],
}

/// The channels [`ShadedOnce::seen`] holds a pixel: the centre colour's three, and the
/// area-light term's three with an `[area_light]`.
fn probe_channels(frame: &Frame) -> usize {
    if frame.area_light.is_some() {
        6
    } else {
        3
    }
}

/// The largest difference between the centre colours of neighbouring pixels of one object and
/// material (per channel, of the square roots of the linear values: about sRGB's steps) that
/// still counts as smooth shading ([`ShadedOnce`]): below it the pixel keeps its one shade, whose
/// box-filtered mean over the samples it then differs from by at most about half this step.
pub(crate) const ONCE_CONTRAST: f32 = 1.0 / 255.0;

/// No object or shadow ([`OpaqueBuffers::object`], [`OpaqueBuffers::shadow`]).
pub(crate) const NONE: u32 = u32::MAX;

/// The bit of [`OpaqueBuffers::material`] that marks an outline hull fragment (or a pixel the
/// edge pass closed an outline over; material slots are far below it).
pub(crate) const HULL: u32 = 1 << 31;

/// Runs the opaque pass over the frame's rows `rows` (0 = top); the buffers hold those rows only.
/// Every pixel is decided by the triangles covering it alone, so a pixel's result does not depend
/// on which rows are drawn with it.
///
/// Shadows (`[[shadow]]`) darken the shaded colour of receiver pixels here, before the waves:
/// [`ShadowCasts::resolve`](crate::shadows::ShadowCasts::resolve) picks, per pixel, the cast of
/// largest opacity among the plane casts whose projected casters cover the pixel and the map casts
/// whose map shadows it.
pub(crate) fn draw_opaque(frame: &Frame, setup: &FrameSetup, rows: std::ops::Range<usize>) -> OpaqueBuffers {
    let mut out = OpaqueBuffers::default();
    draw_opaque_into(frame, setup, 1, rows, &mut out);
    out
}

/// [`draw_opaque`] into `out`, reusing its buffers' allocations from an earlier frame. Bands of
/// rows that no triangle or shadow touches are filled with the background without further work.
/// `frame` is a sample frame of `grid × grid` samples a pixel (1: none); with 2 or 4, and `rows`
/// on whole pixels, surfaces are shaded once per pixel where they can be ([`ShadedOnce`]).
pub(crate) fn draw_opaque_into(
    frame: &Frame,
    setup: &FrameSetup,
    grid: usize,
    rows: std::ops::Range<usize>,
    out: &mut OpaqueBuffers,
) {
    let FrameSetup { basis, lights, shadows, .. } = setup;
    let (w, h) = (frame.width as usize, rows.len());
    let tris = project_all(frame, basis);
    let shadow_tris = if shadows.any_plane() { shadows.plane_tris(frame, basis) } else { Tris::default() };
    let far = frame.camera.far;
    let bands = Bands::new(&tris, frame.height as usize, &rows);
    // Per triangle: whether its samples carry the outline's reach (an outlined material's
    // surface, not its hull).
    let outlined: Vec<bool> = tris
        .iter()
        .map(|t| {
            !t.hull
                && frame.objects[t.object as usize]
                    .material(t.material)
                    .outline
                    .is_some_and(|o| o.width > 0.0)
        })
        .collect();
    // Per triangle: the object whose surface it is (`u32::MAX` for a hull), as the edge pass's
    // owners name them.
    let owner: Vec<u32> = tris.iter().map(|t| if t.hull { u32::MAX } else { t.object }).collect();
    let shadow_bands = Bands::new(&shadow_tris, frame.height as usize, &rows);
    let k = grid.max(1);
    // `x / k` as a shift where shading once (k is 2 or 4 there): a division a sample costs more
    // than the rest of what a sample of a pixel shaded once does.
    let k_shift = k.trailing_zeros();
    // Whether a sample needs its own visible point (its hard shadows are its own, and the soft
    // shadows' resolves other than the traced one map every sample's point); otherwise a sample
    // of a pixel shaded once takes its pixel's centre geometry too (the traced resolve traces
    // such a pixel once from its centre, or its samples from their own depths).
    let point_per_sample = shadows.any()
        || frame
            .area_light
            .as_ref()
            .is_some_and(|a| !matches!(a.resolve, hadou_scene::SoftResolve::Traced { .. }));
    let once = k > 1
        && k.is_power_of_two()
        && !out.once.every_sample
        && BAND.is_multiple_of(k)
        && rows.start.is_multiple_of(k)
        && rows.len().is_multiple_of(k)
        && (frame.width as usize).is_multiple_of(k);
    let OpaqueBuffers {
        color,
        surface,
        object,
        shadow,
        soft,
        visibility,
        normal,
        material,
        reach,
        once: kept,
        ..
    } = out;
    // Sized only: every band clears its own rows below, the bands in parallel (a frame of waves
    // alone pays for these writes, some 50 bytes a pixel, on every thread rather than one).
    color.resize(w * h, [0.0f32; 3]);
    surface.resize(w * h, f32::INFINITY);
    object.resize(w * h, NONE);
    shadow.resize(w * h, NONE);
    normal.resize(w * h, Vec3f::ZERO);
    material.resize(w * h, 0);
    reach.resize(w * h, 0);
    visibility.clear();
    let area = frame.area_light.as_ref();
    soft.resize(if area.is_some() { w * h } else { 0 }, None);
    if w * h == 0 {
        return;
    }
    // Without shading once every band gets empty slices.
    let (centre, once_tri, once_term, once_soft, once_best, keys, seen, centred) = (
        &mut kept.centre,
        &mut kept.tri,
        &mut kept.term,
        &mut kept.soft,
        &mut kept.best,
        &mut kept.keys,
        &mut kept.seen,
        &mut kept.centred,
    );
    let channels = probe_channels(frame);
    let pixels = if once { w * h / (k * k) } else { 0 };
    centre.resize(pixels, [0.0; 3]);
    once_tri.resize(pixels, u32::MAX);
    once_term.resize(if area.is_some() { pixels } else { 0 }, [0.0; 3]);
    // (Without plane shadows every sample's choice is `NO_SHADOW`: nothing kept.)
    let plane_shadows = shadow_tris.get(0).is_some();
    once_best.resize(if once && plane_shadows { w * h } else { 0 }, NO_SHADOW);
    keys.resize(pixels, u64::MAX);
    seen.resize(pixels * channels, 0.0);
    // Whether a sample of a pixel shaded once takes the centre's surface rather than a point of
    // its own (multisampling's rule: one surface a pixel, coverage and depth order per sample);
    // the outline's reach stays its own.
    let centring = once && !point_per_sample;
    centred.clear();
    centred.resize(if centring { pixels } else { 0 }, false);
    once_soft.resize(if centring && area.is_some() { pixels } else { 0 }, None);
    kept.grid = if once { k } else { 1 };
    let band_pixels = BAND * w / (k * k);
    let mut once_chunks: Vec<OnceBand<'_>> = if once {
        let mut terms = once_term.chunks_mut(band_pixels);
        let mut softs = once_soft.chunks_mut(band_pixels);
        let mut bests = once_best.chunks_mut(BAND * w);
        let mut marks = centred.chunks_mut(band_pixels);
        centre
            .chunks_mut(band_pixels)
            .zip(once_tri.chunks_mut(band_pixels))
            .zip(keys.chunks_mut(band_pixels))
            .zip(seen.chunks_mut(band_pixels * channels))
            .map(|(((centre, tri), keys), seen)| OnceBand {
                centre,
                tri,
                term: terms.next().unwrap_or_default(),
                soft: softs.next().unwrap_or_default(),
                best: bests.next().unwrap_or_default(),
                keys,
                seen,
                centred: marks.next().unwrap_or_default(),
            })
            .collect()
    } else {
        (0..h.div_ceil(BAND))
            .map(|_| OnceBand {
                centre: &mut [],
                tri: &mut [],
                term: &mut [],
                soft: &mut [],
                best: &mut [],
                keys: &mut [],
                seen: &mut [],
                centred: &mut [],
            })
            .collect()
    };
    // Without an area light every band gets an empty slice.
    let mut soft_chunks: Vec<&mut [Option<SoftPoint>]> = if area.is_some() {
        soft.chunks_mut(BAND * w).collect()
    } else {
        (0..h.div_ceil(BAND)).map(|_| Default::default()).collect()
    };
    // Batches of bands, one after the other, each listing the triangles that reach it once; the
    // bands of a batch in parallel, each drawing (in submission order) those that reach it.
    let batch_px = BATCH * BAND * w;
    let batches = color
        .chunks_mut(batch_px)
        .zip(surface.chunks_mut(batch_px))
        .zip(object.chunks_mut(batch_px))
        .zip(shadow.chunks_mut(batch_px))
        .zip(normal.chunks_mut(batch_px))
        .zip(material.chunks_mut(batch_px))
        .zip(reach.chunks_mut(batch_px));
    for (n, ((((((color, surface), object), shadow), normal), material), reach)) in batches.enumerate() {
        let first = n * BATCH;
        let count = color.len().div_ceil(BAND * w);
        let list = bands.batch(first, count);
        let shadow_list = shadow_bands.batch(first, count);
        let soft_batch: Vec<&mut [Option<SoftPoint>]> = soft_chunks.drain(..count).collect();
        let once_batch: Vec<_> = once_chunks.drain(..count).collect();
        color
            .par_chunks_mut(BAND * w)
            .zip(surface.par_chunks_mut(BAND * w))
            .zip(object.par_chunks_mut(BAND * w))
            .zip(shadow.par_chunks_mut(BAND * w))
            .zip(normal.par_chunks_mut(BAND * w))
            .zip(material.par_chunks_mut(BAND * w))
            .zip(reach.par_chunks_mut(BAND * w))
            .zip(soft_batch.into_par_iter())
            .zip(once_batch.into_par_iter())
            .enumerate()
            .for_each(|(j, ((((((((col, surf), obj), shad), nrm), mat), rch), soft), once_band))| {
                let OnceBand {
                    centre,
                    tri: once_tri,
                    term: once_term,
                    soft: once_soft,
                    best: once_best,
                    keys,
                    seen,
                    centred,
                } = once_band;
                let b = first + j;
                let mine = || list.iter().copied().filter(|&ti| bands.reaches(ti, b));
                let mine_shadows = || shadow_list.iter().copied().filter(|&si| shadow_bands.reaches(si, b));
                let y_start = rows.start + b * BAND;
                let rows = col.len() / w;
                if mine().next().is_none() && mine_shadows().next().is_none() {
                    // Nothing drawn here.
                    col.fill(frame.background);
                    surf.fill(f32::INFINITY);
                    obj.fill(NONE);
                    shad.fill(NONE);
                    nrm.fill(Vec3f::ZERO);
                    mat.fill(0);
                    rch.fill(0);
                    soft.fill(None);
                    centre.fill([f32::NAN; 3]);
                    once_tri.fill(u32::MAX);
                    once_soft.fill(None);
                    keys.fill(u64::MAX);
                    seen.fill(0.0);
                    centred.fill(false);
                    return;
                }
                // Otherwise every sample's and pixel's entry is written once below (a frame
                // at 4 samples moves some 200 bytes a sample through these buffers: a clear
                // before the writes would add half as much again).
                // The band's own buffers, kept by the thread from band to band and frame to frame
                // (fresh ones, over a megabyte a band at 1024 wide, cost their pages' faults and
                // clearing each time); taken out while in use, so a band the thread runs meanwhile
                // gets fresh ones.
                let mut scratch = BAND_SCRATCH.take();
                let BandScratch { zbuf, tri_id, world, surfaces, best, centres, columns } = &mut scratch;
                zbuf.clear();
                zbuf.resize(rows * w, f32::INFINITY);
                tri_id.clear();
                tri_id.resize(rows * w, u32::MAX);
                for ti in mine() {
                    raster_tri(&tris[ti as usize], ti, y_start, rows, w, far, zbuf, tri_id);
                }
                // Shading once: the pixels whose samples all show one triangle (not a hull), and
                // their surfaces at their centres.
                let (pw, ph) = (w / k, rows / k);
                centres.resize(if once { pw * ph } else { 0 }, (shading::Surface::default(), [0.0; 4]));
                if once {
                    for py in 0..ph {
                        for px in 0..pw {
                            let i0 = py * k * w + px * k;
                            let t0 = tri_id[i0];
                            let shared = t0 != u32::MAX
                                && !tris[t0 as usize].hull
                                && (0..k)
                                    .all(|j| tri_id[i0 + j * w..i0 + j * w + k].iter().all(|&t| t == t0));
                            once_tri[py * pw + px] = if shared { t0 } else { u32::MAX };
                            if shared {
                                let half = k as f32 / 2.0;
                                let (cx, cy) = ((k * px) as f32 + half, (y_start + k * py) as f32 + half);
                                let (s, _) = interpolate(&tris[t0 as usize], cx, cy);
                                // The triangle's plane in view axes, through the centre's point:
                                // its normal `n` and `n·(C − eye)`.
                                let [a, b, c] = tris[t0 as usize].world;
                                let n = (b - a).cross(c - a);
                                let to = s.world - basis.eye;
                                let plane =
                                    [n.dot(basis.right), n.dot(basis.up), n.dot(basis.forward), n.dot(to)];
                                centres[py * pw + px] = (s, plane);
                            }
                        }
                    }
                }
                // The visible point of every sample: its world position here, its normal in
                // the edge data (every entry written where a triangle is drawn; the rest is
                // never read). Where most samples take their pixel's one shade, only this
                // geometry: the few shaded one by one interpolate again, bit for bit the same
                // (a frame at 4 samples moves some 200 bytes a sample through its buffers,
                // and a whole surface a sample would add a quarter as much again). Where
                // every sample is shaded (one sample a pixel), the whole surface, kept.
                let keep = !once;
                world.resize(rows * w, Vec3f::ZERO);
                surfaces.resize(if keep { rows * w } else { 0 }, shading::Surface::default());
                // A sample's ray direction is `forward + ax·right + ay·up`
                // (`CameraBasis::pixel_dir`), `ax` by column and `ay` by row: it meets the plane
                // `n·(P − eye) = q` at eye distance `q·√(1 + ax² + ay²) / (n·dir)`.
                let (sx, sy) = (basis.tan_half_fov * basis.aspect, basis.tan_half_fov);
                // Per column: `ax` and `1 + ax²` (the sum below adds `ay²` to the latter).
                columns.clear();
                if once && !point_per_sample {
                    columns.extend((0..w).map(|x| {
                        let ax = (2.0 * (x as f32 + 0.5) / w as f32 - 1.0) * sx;
                        (ax, 1.0 + ax * ax)
                    }));
                }
                // The outline's reach of sample `i` (column `x`, band row `r`) of triangle `ti`;
                // the edge pass reads it only where a neighbour shows another object (or none):
                // not where all four show a surface of this one.
                let reach_of = |i: usize, x: usize, r: usize, ti: u32| {
                    if !outlined[ti as usize] {
                        return 0;
                    }
                    // A neighbour of the same surface: the same triangle, or another of the same
                    // object that is not a hull (what the edge pass's owners compare).
                    let o = owner[ti as usize];
                    let same = |j: usize| tri_id[j] == ti || owner.get(tri_id[j] as usize) == Some(&o);
                    let inside = x > 0 && x + 1 < w && r > 0 && r + 1 < rows && {
                        same(i - 1) && same(i + 1) && same(i - w) && same(i + w)
                    };
                    if inside {
                        return 0;
                    }
                    let py = (y_start + r) as f32;
                    let (_, outline_dir) =
                        interpolate_with::<false>(&tris[ti as usize], x as f32 + 0.5, py + 0.5);
                    let dir = basis.pixel_dir(x as f32, py, frame.width, frame.height);
                    // (At most `REACH_STEPS`, 255.)
                    outline::reach_code(outline_dir, dir).min(255) as u8
                };
                for r in 0..rows {
                    let prow = (r / k) * pw;
                    let ay = (1.0 - 2.0 * ((y_start + r) as f32 + 0.5) / frame.height as f32) * sy;
                    let ay2 = ay * ay;
                    let py = (y_start + r) as f32;
                    let mut x = 0;
                    while x < w {
                        let i = r * w + x;
                        if centring && once_tri[prow + (x >> k_shift)] != u32::MAX {
                            // The pixel's `k` samples of this row at once (`x` is on the pixel's
                            // first column: the other columns of a shared pixel never come here).
                            let p = prow + (x >> k_shift);
                            let ti = once_tri[p];
                            let t = &tris[ti as usize];
                            let (ref c, [nx, ny, nz, q]) = centres[p];
                            for (x, &(ax, ax2)) in columns.iter().enumerate().skip(x).take(k) {
                                let i = r * w + x;
                                // Where its ray meets the triangle's plane (its raster depth
                                // times its ray's length where the plane is seen edge-on: less
                                // exact far from a huge triangle's vertices).
                                let len = (ax2 + ay2).sqrt();
                                let d = q * len / (nz + nx * ax + ny * ay);
                                let d = if d.is_finite() && d > 0.0 { d } else { zbuf[i] * len };
                                // (The point itself is read by nothing: such a frame has no
                                // hard shadows, and the traced soft shadows take a sample's
                                // point from its eye distance where they need it.)
                                surf[i] = if d.is_finite() { d } else { 0.0 };
                                obj[i] = t.object;
                                rch[i] = reach_of(i, x, r, ti);
                                nrm[i] = c.normal;
                                // (Never a hull: shared pixels show a surface.)
                                mat[i] = t.material;
                            }
                            x += k;
                            continue;
                        }
                        x += 1;
                        let x = x - 1;
                        let ti = tri_id[i];
                        if ti == u32::MAX {
                            (surf[i], obj[i], nrm[i], mat[i], rch[i]) =
                                (f32::INFINITY, NONE, Vec3f::ZERO, 0, 0);
                            continue;
                        }
                        let t = &tris[ti as usize];
                        let (s, _) = if keep {
                            interpolate(t, x as f32 + 0.5, py + 0.5)
                        } else {
                            interpolate_with::<false>(t, x as f32 + 0.5, py + 0.5)
                        };
                        let d = (s.world - basis.eye).length();
                        surf[i] = if d.is_finite() { d } else { 0.0 };
                        obj[i] = t.object;
                        rch[i] = reach_of(i, x, r, ti);
                        nrm[i] = s.normal;
                        mat[i] = t.material | if t.hull { HULL } else { 0 };
                        world[i] = s.world;
                        if keep {
                            surfaces[i] = s;
                        }
                    }
                }
                // Shadows: the receiver pixels each cast darkens, the largest opacity winning.
                best.clear();
                best.resize(rows * w, NO_SHADOW);
                let receiver = |i: usize| {
                    let t = tris.get(tri_id[i] as usize)?;
                    (!t.hull).then_some(t.object)
                };
                for si in mine_shadows() {
                    let st = &shadow_tris[si as usize];
                    cover(st, y_start, rows, w, |i, bary| {
                        let Some(o) = receiver(i) else { return };
                        let t = perspective(st, bary, |k| st.uv[k][0]);
                        shadows.plane_candidate(frame, st.object, o, t, world[i], surf[i], &mut best[i]);
                    });
                }
                if once {
                    // Each pixel whose samples share one triangle, shaded once at its centre.
                    for py in 0..ph {
                        for px in 0..pw {
                            let t0 = once_tri[py * pw + px];
                            if t0 != u32::MAX {
                                let t = &tris[t0 as usize];
                                let material = frame.objects[t.object as usize].material(t.material);
                                let s = centres[py * pw + px].0;
                                let c = shading::shade(frame, lights, material, &s);
                                centre[py * pw + px] = c;
                                keys[py * pw + px] = (u64::from(t.object) << 32) | u64::from(t.material);
                                let root = |v: f32| v.max(0.0).sqrt();
                                for (ch, v) in c.into_iter().enumerate() {
                                    seen[(py * channels + ch) * pw + px] = root(v);
                                }
                                if let Some(al) = area {
                                    let a = shading::area_term(al, material, &s, frame.time);
                                    once_term[py * pw + px] = a;
                                    if let Some(p) = once_soft.get_mut(py * pw + px) {
                                        let normal = s.normal.normalize_or(Vec3f::ZERO);
                                        *p = Some(SoftPoint { world: s.world, normal, term: a });
                                    }
                                    for (ch, v) in a.into_iter().enumerate() {
                                        seen[(py * channels + 3 + ch) * pw + px] = root(v);
                                    }
                                }
                            } else {
                                centre[py * pw + px] = [f32::NAN; 3];
                                if let Some(p) = once_soft.get_mut(py * pw + px) {
                                    *p = None;
                                }
                                keys[py * pw + px] = u64::MAX;
                                for ch in 0..channels {
                                    seen[(py * channels + ch) * pw + px] = 0.0;
                                }
                            }
                        }
                    }
                    if plane_shadows {
                        once_best.copy_from_slice(best);
                    }
                }
                for r in 0..rows {
                    let prow = (r / k) * pw;
                    let mut x = 0;
                    while x < w {
                        let i = r * w + x;
                        // (Pixels are `k` = 2 or 4 columns wide where shading once.)
                        let p = if once { prow + (x >> k_shift) } else { 0 };
                        let shared = once && once_tri[p] != u32::MAX;
                        if shared && centring {
                            // Its pixel's one shade, and no shadow of its own: marked, its
                            // samples' colour and shadow left unwritten (`ShadedOnce::centred`;
                            // `x` is on the pixel's first column).
                            centred[p] = true;
                            x += k;
                            continue;
                        }
                        if centring {
                            centred[p] = false;
                        }
                        x += 1;
                        let x = x - 1;
                        let Some(t) = tris.get(tri_id[i] as usize) else {
                            (col[i], shad[i]) = (frame.background, NONE);
                            if area.is_some() {
                                soft[i] = None;
                            }
                            continue;
                        };
                        let material = frame.objects[t.object as usize].material(t.material);
                        // The whole surface where something shades it (interpolated once).
                        let mut whole = None;
                        let mut surface = || {
                            *whole.get_or_insert_with(|| {
                                if keep {
                                    surfaces[i]
                                } else {
                                    interpolate(t, x as f32 + 0.5, (y_start + r) as f32 + 0.5).0
                                }
                            })
                        };
                        let c = match (t.hull, material.outline) {
                            _ if shared => centre[p],
                            (true, Some(_)) => material.outline_rgb(&frame.light),
                            _ => shading::shade(frame, lights, material, &surface()),
                        };
                        if t.hull {
                            (col[i], shad[i]) = (c, NONE);
                            if area.is_some() {
                                soft[i] = None;
                            }
                        } else {
                            let (c, si) = shadows.resolve(frame, t.object, world[i], best[i], c);
                            (col[i], shad[i]) = (c, si.unwrap_or(NONE));
                            if let Some(al) = area {
                                soft[i] = Some(SoftPoint {
                                    world: world[i],
                                    normal: nrm[i].normalize_or(Vec3f::ZERO),
                                    term: if shared {
                                        once_term[p]
                                    } else {
                                        shading::area_term(al, material, &surface(), frame.time)
                                    },
                                });
                            }
                        }
                    }
                }
                BAND_SCRATCH.set(scratch);
            });
    }
    if once {
        refine(frame, setup, &tris, k, rows.start, color, shadow, soft, kept);
    }
}

/// Shades sample by sample the pixels of [`ShadedOnce`] whose centre colour differs from a
/// neighbouring pixel's of the same object and material by more than [`ONCE_CONTRAST`] (in
/// either direction, so both sides of a band's edge), exactly as the samples of any other pixel
/// are shaded (with an `[area_light]`, its term too). `color`, `shadow` and `soft` (empty without
/// an area light) hold the drawn sample rows from `y0`.
#[allow(clippy::too_many_arguments)]
fn refine(
    frame: &Frame,
    setup: &FrameSetup,
    tris: &Tris,
    k: usize,
    y0: usize,
    color: &mut [[f32; 3]],
    shadow: &mut [u32],
    soft: &mut [Option<SoftPoint>],
    kept: &mut ShadedOnce,
) {
    let w = frame.width as usize;
    let (pw, ph) = (w / k, color.len() / (w * k));
    let ShadedOnce { tri, best, keys, seen, pairs, centred, .. } = kept;
    let channels = probe_channels(frame);
    // Each neighbouring pair compared once (the step is symmetric): a pixel's bits say which of
    // its pairs to the east, south, south-east and south-west differ.
    pairs.resize(pw * ph, 0);
    pairs.par_chunks_mut(pw).enumerate().for_each(|(py, bits)| {
        let plane = |y: usize, ch: usize| &seen[(y * channels + ch) * pw..(y * channels + ch + 1) * pw];
        let below = py + 1 < ph;
        // Channel by channel along the row (in lanes), whether a pair's step is past the
        // contrast (a NaN channel: no step); then only pairs of the same key kept.
        bits.fill(0);
        let step = |a: f32, b: f32, bit: u8| u8::from((a - b).abs() > ONCE_CONTRAST) * bit;
        for ch in 0..channels {
            let a = plane(py, ch);
            for ((bit, &x), &y) in bits.iter_mut().zip(a).zip(&a[1..]) {
                *bit |= step(x, y, PAIR_E);
            }
            if below {
                let b = plane(py + 1, ch);
                for ((bit, &x), &y) in bits.iter_mut().zip(a).zip(b) {
                    *bit |= step(x, y, PAIR_S);
                }
                for ((bit, &x), &y) in bits.iter_mut().zip(a).zip(&b[1..]) {
                    *bit |= step(x, y, PAIR_SE);
                }
                for ((bit, &x), &y) in bits[1..].iter_mut().zip(&a[1..]).zip(b) {
                    *bit |= step(x, y, PAIR_SW);
                }
            }
        }
        let row = &keys[py * pw..py * pw + pw];
        let next = keys.get((py + 1) * pw..(py + 2) * pw);
        for (px, bit) in bits.iter_mut().enumerate() {
            *bit &= same_keys(row, next, px);
        }
    });
    let pairs = &pairs[..];
    let area = frame.area_light.as_ref();
    // Without an area light every pixel row gets an empty slice.
    let soft_rows: Vec<&mut [Option<SoftPoint>]> = if area.is_some() {
        soft.chunks_mut(k * w).collect()
    } else {
        (0..ph).map(|_| Default::default()).collect()
    };
    // Where no pixel is centred, every pixel row gets an empty slice.
    let centred_rows: Vec<&mut [bool]> = if centred.is_empty() {
        (0..ph).map(|_| Default::default()).collect()
    } else {
        centred.chunks_mut(pw).collect()
    };
    let best = &best[..];
    color
        .par_chunks_mut(k * w)
        .zip(shadow.par_chunks_mut(k * w))
        .zip(soft_rows)
        .zip(centred_rows)
        .enumerate()
        .for_each(|(py, (((col, shad), soft), centred))| {
            let row = &pairs[py * pw..py * pw + pw];
            let above = py.checked_sub(1).map(|a| &pairs[a * pw..a * pw + pw]);
            for px in 0..pw {
                let p = py * pw + px;
                // The pixel's eight neighbours: its own four pairs, its west neighbour's east,
                // and the row above's pairs that reach down to it.
                let mut edge = row[px] != 0 || (px > 0 && row[px - 1] & PAIR_E != 0);
                if let Some(above) = above {
                    edge |= above[px] & PAIR_S != 0
                        || (px > 0 && above[px - 1] & PAIR_SE != 0)
                        || (px + 1 < pw && above[px + 1] & PAIR_SW != 0);
                }
                if !edge {
                    continue;
                }
                let t = &tris[tri[p] as usize];
                let material = frame.objects[t.object as usize].material(t.material);
                // Every sample written below.
                if let Some(c) = centred.get_mut(px) {
                    *c = false;
                }
                for j in 0..k {
                    let sy = y0 + py * k + j;
                    for x in px * k..px * k + k {
                        let i = j * w + x;
                        let (s, _) = interpolate(t, x as f32 + 0.5, sy as f32 + 0.5);
                        let c = shading::shade(frame, &setup.lights, material, &s);
                        let choice = best.get((py * k + j) * w + x).copied().unwrap_or(NO_SHADOW);
                        let (c, si) = setup.shadows.resolve(frame, t.object, s.world, choice, c);
                        (col[i], shad[i]) = (c, si.unwrap_or(NONE));
                        if let (Some(al), Some(p)) = (area, soft.get_mut(i)) {
                            // (The whole point: a centred pixel's samples kept none.)
                            *p = Some(SoftPoint {
                                world: s.world,
                                normal: s.normal.normalize_or(Vec3f::ZERO),
                                term: shading::area_term(al, material, &s, frame.time),
                            });
                        }
                    }
                }
            }
        });
}

/// The bits of [`ShadedOnce::pairs`]: a pixel's pair with its east, south, south-east and
/// south-west neighbour differs.
const PAIR_E: u8 = 1;
const PAIR_S: u8 = 2;
const PAIR_SE: u8 = 4;
const PAIR_SW: u8 = 8;

/// The pair bits of pixel `px` of a row of [`ShadedOnce::keys`] (`next`: the row below, if any)
/// whose two pixels were both shaded once and show the same object and material: only those
/// pairs are compared (a pair differs where a channel of the colour or of the area-light term
/// steps by more than [`ONCE_CONTRAST`]).
#[inline]
fn same_keys(row: &[u64], next: Option<&[u64]>, px: usize) -> u8 {
    let k = row[px];
    if k == u64::MAX {
        return 0;
    }
    let is = |v: Option<&u64>, bit: u8| u8::from(v == Some(&k)) * bit;
    let mut bits = is(row.get(px + 1), PAIR_E);
    if let Some(next) = next {
        bits |= is(next.get(px), PAIR_S) | is(next.get(px + 1), PAIR_SE);
        if px > 0 {
            bits |= is(next.get(px - 1), PAIR_SW);
        }
    }
    bits
}

/// A band's depth, triangle, visible-surface and shadow buffers ([`draw_opaque_into`]).
#[derive(Default)]
struct BandScratch {
    zbuf: Vec<f32>,
    tri_id: Vec<u32>,
    world: Vec<Vec3f>,
    surfaces: Vec<shading::Surface>,
    best: Vec<crate::shadows::Choice>,
    /// Per pixel shaded once: its surface at its centre, and its triangle's plane through that
    /// point in view axes (the normal's right, up and forward components, and `n·(C − eye)`).
    centres: Vec<(shading::Surface, [f32; 4])>,
    /// Per sample column: its ray's `ax` and `1 + ax²`.
    columns: Vec<(f32, f32)>,
}

thread_local! {
    /// Each thread's [`BandScratch`], kept from band to band.
    static BAND_SCRATCH: std::cell::Cell<BandScratch> = std::cell::Cell::new(BandScratch::default());
}

/// The objects' triangles and then their outline hulls, projected by the camera.
fn project_all(frame: &Frame, basis: &CameraBasis) -> Tris {
    let screen = ScreenProjection::new(frame, basis);
    let mut out = Tris::default();
    for (oi, obj) in frame.objects.iter().enumerate() {
        let nm = obj.transform.normal_matrix();
        let mesh = &obj.mesh;
        let outlined = obj.materials.iter().any(|m| m.outline.is_some_and(|o| o.width > 0.0));
        let verts: Vec<Vert> = (0..mesh.positions.len())
            .map(|i| {
                let world = obj.transform.transform_point(Vec3::from_array(mesh.positions[i]));
                let normal =
                    nm.transform_vector(Vec3::from_array(mesh.normals.get(i).copied().unwrap_or([0.0; 3])));
                // The unit outline direction `U` of 000 §2.3, which the hull and the edge pass
                // read.
                let dir = mesh.outline_normals.get(i).or(mesh.normals.get(i)).copied().unwrap_or([0.0; 3]);
                // Its length is the vertex's outline width multiplier (MToon's width texture,
                // `hadou_scene::mesh::outline_scale`), 1 for most meshes.
                let outline = if outlined {
                    let scale = Vec3::from_array(dir).length();
                    let scale = if scale.is_finite() { scale.min(1.0) } else { 0.0 };
                    nm.transform_vector(Vec3::from_array(dir)).normalize_or(Vec3f::ZERO) * scale
                } else {
                    Vec3f::ZERO
                };
                Vert {
                    view: basis.to_view(world),
                    world,
                    normal,
                    uv: mesh.uvs.get(i).copied().unwrap_or([0.0; 2]),
                    color: mesh.colors.get(i).copied().unwrap_or([1.0; 4]),
                    outline,
                }
            })
            .collect();
        // The outline hull (000 §2.3): each vertex pushed along its world-space outline normal
        // by `d·|z|` (`z` its view depth), which is `R' = R + d·|R_z|·U` in view space; an MToon
        // outline by its own width (`Material::hull_push`).
        let hull: Vec<Vert> = if outlined {
            verts
                .iter()
                .enumerate()
                .map(|(i, v)| {
                    let push = obj.material(mesh.material_of(i)).hull_push(v.view.z, basis.tan_half_fov);
                    let world = v.world + v.outline * push;
                    Vert { view: basis.to_view(world), world, ..*v }
                })
                .collect()
        } else {
            Vec::new()
        };
        let passes: &[(&[Vert], bool)] =
            if outlined { &[(&verts, false), (&hull, true)] } else { &[(&verts, false)] };
        for &(verts, is_hull) in passes {
            for tri in mesh.indices.chunks_exact(3) {
                let v = [tri[0], tri[1], tri[2]].map(|i| verts.get(i as usize).copied());
                let [Some(a), Some(b), Some(c)] = v else { continue };
                let material = mesh.material_of(tri[0] as usize);
                if is_hull
                    && obj.material(material).outline.is_none_or(|o| o.width.is_nan() || o.width <= 0.0)
                {
                    continue;
                }
                screen.push([a, b, c], oi as u32, material, is_hull, &mut out);
            }
        }
    }
    out
}

/// Draws triangle `id` into a band's depth buffer `zbuf` and triangle ids `tri_id` (both `rows × w`,
/// the band's first row `y_start`): each covered pixel whose depth is below the stored one and not
/// beyond `far` takes it. An outline hull triangle is drawn only where it shows its back face.
#[allow(clippy::too_many_arguments)] // a hot inner routine: plain slices beat a bundling struct
fn raster_tri(
    t: &ScreenTri,
    id: u32,
    y_start: usize,
    rows: usize,
    w: usize,
    far: f32,
    zbuf: &mut [f32],
    tri_id: &mut [u32],
) {
    // With y down, a triangle counter-clockwise seen from the eye (a front face) has area < 0;
    // a hull shows only its back faces.
    if t.hull && edge(t.sx[0], t.sy[0], t.sx[1], t.sy[1], t.sx[2], t.sy[2]) < 0.0 {
        return;
    }
    cover(t, y_start, rows, w, |i, b| {
        let iz = b[0] * t.inv_z[0] + b[1] * t.inv_z[1] + b[2] * t.inv_z[2];
        let z = 1.0 / iz;
        if z < zbuf[i] && z <= far {
            zbuf[i] = z;
            tri_id[i] = id;
        }
    });
}

/// Perspective-correct surface attributes at screen point `(px, py)`, and the interpolated outline
/// direction there.
fn interpolate(t: &ScreenTri, px: f32, py: f32) -> (shading::Surface, Vec3f) {
    interpolate_with::<true>(t, px, py)
}

/// [`interpolate`], with `FULL` false only the geometry: the texture coordinates and colour are
/// left zero (a sample of a pixel shaded once reads neither); the rest bit for bit the same.
#[inline(always)]
fn interpolate_with<const FULL: bool>(t: &ScreenTri, px: f32, py: f32) -> (shading::Surface, Vec3f) {
    let area = edge(t.sx[0], t.sy[0], t.sx[1], t.sy[1], t.sx[2], t.sy[2]);
    let b = [
        edge(t.sx[1], t.sy[1], t.sx[2], t.sy[2], px, py) / area,
        edge(t.sx[2], t.sy[2], t.sx[0], t.sy[0], px, py) / area,
        edge(t.sx[0], t.sy[0], t.sx[1], t.sy[1], px, py) / area,
    ];
    let wts = [b[0] * t.inv_z[0], b[1] * t.inv_z[1], b[2] * t.inv_z[2]];
    let s = wts[0] + wts[1] + wts[2];
    let wts = wts.map(|v| v / s);
    let world = t.world[0] * wts[0] + t.world[1] * wts[1] + t.world[2] * wts[2];
    let normal = t.normal[0] * wts[0] + t.normal[1] * wts[1] + t.normal[2] * wts[2];
    let (uv, color) = if FULL {
        (
            std::array::from_fn(|k| t.uv[0][k] * wts[0] + t.uv[1][k] * wts[1] + t.uv[2][k] * wts[2]),
            std::array::from_fn(|k| t.color[0][k] * wts[0] + t.color[1][k] * wts[1] + t.color[2][k] * wts[2]),
        )
    } else {
        ([0.0; 2], [0.0; 4])
    };
    let outline = t.outline[0] * wts[0] + t.outline[1] * wts[1] + t.outline[2] * wts[2];
    (shading::Surface { world, normal, uv, color }, outline)
}

/// `scenes/light-from-front.toml` at t = 1.2 s, 160 × 120 pixels of 2 × 2 samples: the image
/// frame, its sample frame, and the sample frame's opaque pass (without the edge pass).
#[cfg(test)]
pub(crate) fn light_from_front_drawn() -> (Frame, Frame, OpaqueBuffers) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/light-from-front.toml");
    let scene = hadou_scene::Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let mut frame = scene.at(1.2);
    (frame.width, frame.height, frame.samples) = (160, 120, 4);
    let sampled = frame.sample_frame();
    let mut out = OpaqueBuffers::default();
    draw_opaque_into(&sampled, &FrameSetup::new(&sampled), 2, 0..sampled.height as usize, &mut out);
    (frame, sampled, out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 44, point 1: the refinement writes every sample of the pixels it shades sample by
    /// sample, so none of them stays marked [`ShadedOnce::centred`] (the resolve would read the
    /// centre colour and drop the band's edge); the rest of the pixels shaded once stay marked.
    #[test]
    fn refined_pixels_are_not_left_centred() {
        let (frame, _, out) = light_from_front_drawn();
        let ShadedOnce { tri, pairs, centred, .. } = &out.once;
        let (pw, ph) = (frame.width as usize, frame.height as usize);
        let (mut refined, mut kept) = (0, 0);
        for py in 0..ph {
            for px in 0..pw {
                let p = py * pw + px;
                let bit = |x: usize, y: usize, b: u8| pairs[y * pw + x] & b != 0;
                let edge = pairs[p] != 0
                    || (px > 0 && bit(px - 1, py, PAIR_E))
                    || (py > 0
                        && (bit(px, py - 1, PAIR_S)
                            || (px > 0 && bit(px - 1, py - 1, PAIR_SE))
                            || (px + 1 < pw && bit(px + 1, py - 1, PAIR_SW))));
                if edge {
                    assert!(!centred[p], "pixel ({px}, {py}) refined but still centred");
                    refined += 1;
                } else if tri[p] != u32::MAX {
                    assert!(centred[p], "pixel ({px}, {py}) shaded once but not centred");
                    kept += 1;
                }
            }
        }
        assert!(refined > 0 && kept > 1000, "{refined} pixels refined, {kept} centred");
    }
}
