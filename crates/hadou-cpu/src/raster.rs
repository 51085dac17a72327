//! The triangle rasterizer every pass draws with: view-space vertices clipped at the near plane
//! and projected to screen (or map) coordinates ([`ScreenProjection`]) into a [`Tris`] list,
//! triangles sorted into bands of [`BAND`] rows ([`Bands`]), and the pixel centres a triangle
//! covers under the top-left fill rule with their barycentric weights ([`cover`]).
//!
//! Memory follows the triangle count, not the image: a [`Tris`] list grows in fixed chunks (no
//! doubling and copying), and [`Bands`] keeps one band range per triangle and lists the triangles
//! of [`BATCH`] bands at a time, so a triangle spanning every row of a 16384-row image costs
//! 8 bytes there, not 4 bytes for each of its 1024 bands. It knows nothing of the passes that use it: the
//! opaque pass (`crate::opaque`), the hard shadows' maps and plane casts (`crate::shadows`) and the
//! soft shadows' maps (`crate::soft`) set up their own triangles and decide what a covered pixel
//! does.
//!
//! Conventions (the GPU backend's raster passes match them): pixel `(px, py)` has its centre at
//! `(px + ½, py + ½)`, `py = 0` is the top row; triangles are clipped at the near plane in view
//! space and covered double-sided, with the top-left fill rule; degenerate (zero-area or
//! non-finite) triangles cover nothing.

use hadou_math::Vec3f;
use hadou_scene::{CameraBasis, Frame};
use rayon::prelude::*;

/// Rows per parallel band.
pub(crate) const BAND: usize = 16;
/// Bands drawn together (in parallel) from one list of the triangles that reach them.
pub(crate) const BATCH: usize = 16;
/// Items per chunk of a [`Chunked`] list.
const CHUNK: usize = 1 << 14;

/// A list that grows in chunks of [`CHUNK`] items: pushing never moves what is stored, and at
/// most one chunk is allocated but unused (a `Vec` doubles, holding up to three times its length
/// while it grows).
pub(crate) struct Chunked<T> {
    chunks: Vec<Vec<T>>,
}

impl<T> Default for Chunked<T> {
    fn default() -> Self {
        Chunked { chunks: Vec::new() }
    }
}

impl<T> Chunked<T> {
    /// Appends `x`.
    #[inline]
    pub(crate) fn push(&mut self, x: T) {
        match self.chunks.last_mut() {
            Some(c) if c.len() < CHUNK => c.push(x),
            _ => {
                let mut c = Vec::with_capacity(CHUNK);
                c.push(x);
                self.chunks.push(c);
            }
        }
    }

    /// The items in order.
    pub(crate) fn iter(&self) -> impl Iterator<Item = &T> {
        self.chunks.iter().flatten()
    }

    /// Item `i`, if any.
    #[inline]
    pub(crate) fn get(&self, i: usize) -> Option<&T> {
        self.chunks.get(i / CHUNK)?.get(i % CHUNK)
    }
}

impl<T> std::ops::Index<usize> for Chunked<T> {
    type Output = T;
    #[inline]
    fn index(&self, i: usize) -> &T {
        &self.chunks[i / CHUNK][i % CHUNK]
    }
}

/// Projected triangles, in submission order.
pub(crate) type Tris = Chunked<ScreenTri>;

/// One vertex after transform: view-space position (for clipping/projection) and world-space
/// attributes (for shading).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Vert {
    /// View-space position (`z` the depth along the view axis).
    pub view: Vec3f,
    /// World position.
    pub world: Vec3f,
    /// World normal (not unit).
    pub normal: Vec3f,
    /// Texture coordinates (the plane casts carry their `t` in `uv[0]`).
    pub uv: [f32; 2],
    /// Linear RGBA vertex colour.
    pub color: [f32; 4],
}

/// A projected triangle ready to rasterize.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ScreenTri {
    /// Continuous screen x per vertex (right).
    pub sx: [f32; 3],
    /// Continuous screen y per vertex (down).
    pub sy: [f32; 3],
    /// `1 / view z` per vertex.
    pub inv_z: [f32; 3],
    /// The vertices' world positions.
    pub world: [Vec3f; 3],
    /// The vertices' world normals.
    pub normal: [Vec3f; 3],
    /// The vertices' texture coordinates.
    pub uv: [[f32; 2]; 3],
    /// The vertices' colours.
    pub color: [[f32; 4]; 3],
    /// Index into `frame.objects` (for a plane cast's triangle, the cast's index).
    pub object: u32,
    /// Material slot of the object.
    pub material: u32,
    /// An outline hull triangle: drawn only where it faces away from the eye, in the outline
    /// colour.
    pub hull: bool,
}

impl ScreenTri {
    /// The view depth at screen barycentrics `w`: `1 / Σ wᵢ/zᵢ` (perspective-correct).
    #[inline]
    pub(crate) fn depth_at(&self, w: [f32; 3]) -> f32 {
        1.0 / (w[0] * self.inv_z[0] + w[1] * self.inv_z[1] + w[2] * self.inv_z[2])
    }

    /// A bare triangle in screen coordinates (for the hard shadows' maps, drawn with
    /// [`nearest_depths`]).
    pub(crate) fn flat(sx: [f32; 3], sy: [f32; 3]) -> Self {
        ScreenTri {
            sx,
            sy,
            inv_z: [1.0; 3],
            world: [Vec3f::ZERO; 3],
            normal: [Vec3f::ZERO; 3],
            uv: [[0.0; 2]; 3],
            color: [[0.0; 4]; 3],
            object: 0,
            material: 0,
            hull: false,
        }
    }
}

/// Which bands of [`BAND`] rows of `rows` each triangle may cover: its first and last band
/// (8 bytes per triangle, whatever its height). [`Bands::batch`] lists the triangles reaching a
/// batch of bands, and [`Bands::reaches`] picks a band's own: in submission order, the same
/// triangles a list per band would hold.
pub(crate) struct Bands {
    /// Per triangle: first and last band (relative to `rows.start`), `(1, 0)` for none.
    ranges: Vec<(u32, u32)>,
}

impl Bands {
    /// The bands of `rows` (of an image `height` rows high) each of `tris` may cover.
    pub(crate) fn new(tris: &Tris, height: usize, rows: &std::ops::Range<usize>) -> Self {
        let ranges = tris
            .iter()
            .map(|t| {
                let (y0, y1) = y_range(t, height);
                let (y0, y1) = (y0.max(rows.start), y1.min(rows.end.saturating_sub(1)));
                if y0 > y1 || rows.is_empty() {
                    (1, 0)
                } else {
                    (((y0 - rows.start) / BAND) as u32, ((y1 - rows.start) / BAND) as u32)
                }
            })
            .collect();
        Bands { ranges }
    }

    /// The triangles that may cover any of the bands `first..first + count`, in submission order.
    pub(crate) fn batch(&self, first: usize, count: usize) -> Vec<u32> {
        let (lo, hi) = (first as u32, (first + count) as u32);
        (0..self.ranges.len() as u32)
            .filter(|&i| {
                let (a, b) = self.ranges[i as usize];
                a <= b && a < hi && b >= lo
            })
            .collect()
    }

    /// Whether triangle `i` may cover band `b`.
    #[inline]
    pub(crate) fn reaches(&self, i: u32, b: usize) -> bool {
        let (a, z) = self.ranges[i as usize];
        a as usize <= b && b <= z as usize
    }
}

/// A perspective projection of view-space triangles to [`ScreenTri`]s, clipped at the near plane:
/// view `(x, y, z)` lands at `((x/z·sx_scale + 1)·½·w, (1 − y/z·sy_scale)·½·h)`.
pub(crate) struct ScreenProjection {
    near: f32,
    w: f32,
    h: f32,
    sx_scale: f32,
    sy_scale: f32,
}

impl ScreenProjection {
    /// The camera's projection onto the frame's image (from [`CameraBasis`]).
    pub(crate) fn new(frame: &Frame, basis: &CameraBasis) -> Self {
        ScreenProjection {
            near: frame.camera.near,
            w: frame.width as f32,
            h: frame.height as f32,
            sx_scale: 1.0 / (basis.tan_half_fov * basis.aspect),
            sy_scale: 1.0 / basis.tan_half_fov,
        }
    }

    /// The projection onto a square `size²` map of a frustum with near plane `near` and
    /// `tan(½ field of view)` = `tan_half` (texel `(x, y)` covers `[x, x+1) × [y, y+1)`, row 0 at
    /// the frustum's top).
    pub(crate) fn square(near: f32, tan_half: f32, size: u32) -> Self {
        let (n, scale) = (size as f32, 1.0 / tan_half);
        ScreenProjection { near, w: n, h: n, sx_scale: scale, sy_scale: scale }
    }

    /// Clips `tri` at the near plane and appends the projected pieces (a fan, those with finite
    /// coordinates) to `out`.
    pub(crate) fn push(&self, tri: [Vert; 3], object: u32, material: u32, hull: bool, out: &mut Tris) {
        let mut poly = [tri[0]; 4];
        let n = clip_near(tri, self.near, &mut poly);
        for k in 1..n.saturating_sub(1) {
            let pv = [poly[0], poly[k], poly[k + 1]];
            let mut t = ScreenTri {
                sx: [0.0; 3],
                sy: [0.0; 3],
                inv_z: [0.0; 3],
                world: pv.map(|v| v.world),
                normal: pv.map(|v| v.normal),
                uv: pv.map(|v| v.uv),
                color: pv.map(|v| v.color),
                object,
                material,
                hull,
            };
            let mut ok = true;
            for (j, v) in pv.iter().enumerate() {
                let iz = 1.0 / v.view.z;
                t.inv_z[j] = iz;
                t.sx[j] = (v.view.x * iz * self.sx_scale + 1.0) * 0.5 * self.w;
                t.sy[j] = (1.0 - v.view.y * iz * self.sy_scale) * 0.5 * self.h;
                ok &= t.sx[j].is_finite() && t.sy[j].is_finite() && iz.is_finite();
            }
            if ok {
                out.push(t);
            }
        }
    }
}

/// Sutherland–Hodgman against the plane `z = near` (keeping `z ≥ near`). Returns the vertex count
/// (0, 3 or 4) written to `out`.
fn clip_near(tri: [Vert; 3], near: f32, out: &mut [Vert; 4]) -> usize {
    let mut n = 0;
    for i in 0..3 {
        let a = tri[i];
        let b = tri[(i + 1) % 3];
        let ina = a.view.z >= near;
        let inb = b.view.z >= near;
        if ina {
            out[n] = a;
            n += 1;
        }
        if ina != inb {
            let s = (near - a.view.z) / (b.view.z - a.view.z);
            let lerp = |p: Vec3f, q: Vec3f| p + (q - p) * s;
            let mix = |p: f32, q: f32| p + (q - p) * s;
            let mut v = Vert {
                view: lerp(a.view, b.view),
                world: lerp(a.world, b.world),
                normal: lerp(a.normal, b.normal),
                uv: std::array::from_fn(|k| mix(a.uv[k], b.uv[k])),
                color: std::array::from_fn(|k| mix(a.color[k], b.color[k])),
            };
            v.view.z = near;
            if n < 4 {
                out[n] = v;
                n += 1;
            }
        }
    }
    n
}

/// Rows (inclusive) whose pixel centres the triangle may cover, clamped to the image.
fn y_range(t: &ScreenTri, h: usize) -> (usize, usize) {
    let lo = t.sy[0].min(t.sy[1]).min(t.sy[2]);
    let hi = t.sy[0].max(t.sy[1]).max(t.sy[2]);
    if hi < 0.0 || lo > h as f32 {
        return (1, 0);
    }
    let y0 = (lo - 0.5).ceil().max(0.0) as usize;
    let y1 = ((hi - 0.5).floor().min(h as f32 - 1.0)).max(0.0) as usize;
    (y0, y1)
}

/// Twice the signed area of `(a, b, p)`.
#[inline(always)]
pub(crate) fn edge(ax: f32, ay: f32, bx: f32, by: f32, px: f32, py: f32) -> f32 {
    (bx - ax) * (py - ay) - (by - ay) * (px - ax)
}

/// Whether an edge owns pixel centres lying exactly on it (the top-left rule, for the triangle
/// orientation given by `sign`).
#[inline(always)]
fn owns_boundary(ax: f32, ay: f32, bx: f32, by: f32, sign: f32) -> bool {
    let (dx, dy) = ((bx - ax) * sign, (by - ay) * sign);
    // With y down and positive orientation: a top edge is horizontal going right... expressed
    // for the normalised (positive) orientation.
    (dy == 0.0 && dx > 0.0) || dy < 0.0
}

/// Calls `f(i, b)` for every pixel centre of the rows `y_start..y_start + rows` (`i` indexing a
/// `rows × w` buffer) that `t` covers under the top-left rule, with the screen-space barycentric
/// weights `b` of the centre. Degenerate (zero-area or non-finite) triangles cover nothing.
#[inline(always)]
pub(crate) fn cover(
    t: &ScreenTri,
    y_start: usize,
    rows: usize,
    w: usize,
    mut f: impl FnMut(usize, [f32; 3]),
) {
    let area = edge(t.sx[0], t.sy[0], t.sx[1], t.sy[1], t.sx[2], t.sy[2]);
    if area == 0.0 || !area.is_finite() {
        return;
    }
    let sign = area.signum();
    let inv_area = 1.0 / area;
    let xmin = t.sx[0].min(t.sx[1]).min(t.sx[2]);
    let xmax = t.sx[0].max(t.sx[1]).max(t.sx[2]);
    if xmax < 0.0 || xmin > w as f32 {
        return;
    }
    let x0 = (xmin - 0.5).ceil().max(0.0) as usize;
    let x1 = ((xmax - 0.5).floor()).min(w as f32 - 1.0);
    if x1 < 0.0 {
        return;
    }
    let x1 = x1 as usize;
    let ylo = t.sy[0].min(t.sy[1]).min(t.sy[2]);
    let yhi = t.sy[0].max(t.sy[1]).max(t.sy[2]);
    let own = [
        owns_boundary(t.sx[1], t.sy[1], t.sx[2], t.sy[2], sign),
        owns_boundary(t.sx[2], t.sy[2], t.sx[0], t.sy[0], sign),
        owns_boundary(t.sx[0], t.sy[0], t.sx[1], t.sy[1], sign),
    ];
    // Only the rows whose centres may lie within [ylo, yhi] (the test below still decides).
    let r0 = ((ylo - 0.5).ceil() - y_start as f32 - 1.0).max(0.0) as usize;
    let r1 = ((yhi - 0.5).floor() - y_start as f32 + 2.0).clamp(0.0, rows as f32) as usize;
    for r in r0..r1 {
        let py = (y_start + r) as f32 + 0.5;
        if py < ylo || py > yhi {
            continue;
        }
        // The row's span of the triangle, widened by a pixel against rounding: only its pixels
        // are tested (the exact edge tests below decide), so long thin triangles cost their
        // area, not their bounding box.
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            let (ay, by) = (t.sy[a], t.sy[b]);
            if (ay <= py && py <= by) || (by <= py && py <= ay) {
                let x = if ay == by {
                    lo = lo.min(t.sx[a].min(t.sx[b]));
                    t.sx[a].max(t.sx[b])
                } else {
                    t.sx[a] + (py - ay) * ((t.sx[b] - t.sx[a]) / (by - ay))
                };
                lo = lo.min(x);
                hi = hi.max(x);
            }
        }
        if lo.partial_cmp(&hi) == Some(std::cmp::Ordering::Greater) || lo.is_nan() || hi.is_nan() {
            continue;
        }
        let xs = ((lo - 1.5).ceil().max(x0 as f32)) as usize;
        let xe = ((hi + 0.5).floor().min(x1 as f32)).max(-1.0);
        if xe < xs as f32 {
            continue;
        }
        for x in xs..=xe as usize {
            let px = x as f32 + 0.5;
            let e0 = edge(t.sx[1], t.sy[1], t.sx[2], t.sy[2], px, py) * sign;
            let e1 = edge(t.sx[2], t.sy[2], t.sx[0], t.sy[0], px, py) * sign;
            let e2 = edge(t.sx[0], t.sy[0], t.sx[1], t.sy[1], px, py) * sign;
            let inside = |e: f32, o: bool| e > 0.0 || (e == 0.0 && o);
            if !(inside(e0, own[0]) && inside(e1, own[1]) && inside(e2, own[2])) {
                continue;
            }
            f(r * w + x, [e0 * inv_area * sign, e1 * inv_area * sign, e2 * inv_area * sign]);
        }
    }
}

/// A per-vertex attribute at screen barycentrics `b`, interpolated perspective-correctly.
#[inline]
pub(crate) fn perspective(t: &ScreenTri, b: [f32; 3], attr: impl Fn(usize) -> f32) -> f32 {
    let wts = [b[0] * t.inv_z[0], b[1] * t.inv_z[1], b[2] * t.inv_z[2]];
    let s = wts[0] + wts[1] + wts[2];
    (wts[0] * attr(0) + wts[1] * attr(1) + wts[2] * attr(2)) / s
}

/// The nearest depth per texel of a `size²` map: every triangle of `tris` covered (double-sided,
/// top-left rule), `z(i, b)` the depth of triangle `i` at barycentrics `b`, the smallest kept,
/// `empty` where no triangle covers the texel. Bands of rows in parallel, each drawing the
/// triangles that reach it (the nearest depth wins, so the result does not depend on the banding).
pub(crate) fn nearest_depths(
    tris: &Tris,
    size: usize,
    empty: f32,
    z: impl Fn(usize, [f32; 3]) -> f32 + Sync,
) -> Vec<f32> {
    let n = size;
    let bands = Bands::new(tris, n, &(0..n));
    let mut depth = vec![empty; n * n];
    if n == 0 {
        return depth;
    }
    for (k, batch) in depth.chunks_mut(BATCH * BAND * n).enumerate() {
        let first = k * BATCH;
        let list = bands.batch(first, batch.len().div_ceil(BAND * n));
        batch.par_chunks_mut(BAND * n).enumerate().for_each(|(j, band)| {
            let b = first + j;
            let rows = band.len() / n;
            for &ti in list.iter().filter(|&&ti| bands.reaches(ti, b)) {
                cover(&tris[ti as usize], b * BAND, rows, n, |i, w| {
                    let z = z(ti as usize, w);
                    if z < band[i] {
                        band[i] = z;
                    }
                });
            }
        });
    }
    depth
}
