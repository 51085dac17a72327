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
    /// World outline direction: the unit direction the outline hull pushes this vertex along
    /// (zero where there is none).
    pub outline: Vec3f,
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
    /// The vertices' outline directions ([`Vert::outline`]).
    pub outline: [Vec3f; 3],
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
            outline: [Vec3f::ZERO; 3],
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
                outline: pv.map(|v| v.outline),
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
            // The crossing computed from the edge's endpoints in one order whichever way the
            // triangle runs along it, so two triangles sharing the edge get the same clipped
            // vertex, bit for bit, and no crack opens between them.
            let (a, b) = if a.view.to_array() <= b.view.to_array() { (a, b) } else { (b, a) };
            let s = (near - a.view.z) / (b.view.z - a.view.z);
            let lerp = |p: Vec3f, q: Vec3f| p + (q - p) * s;
            let mix = |p: f32, q: f32| p + (q - p) * s;
            let mut v = Vert {
                view: lerp(a.view, b.view),
                world: lerp(a.world, b.world),
                normal: lerp(a.normal, b.normal),
                uv: std::array::from_fn(|k| mix(a.uv[k], b.uv[k])),
                color: std::array::from_fn(|k| mix(a.color[k], b.color[k])),
                outline: lerp(a.outline, b.outline),
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

/// One edge of a triangle for the coverage test: its endpoints in a canonical order (by `y`, then
/// `x`) and the factor (±1) that turns [`edge`] of that order into the triangle's inside-positive
/// value. Two triangles sharing the edge evaluate the same products on the same numbers, so their
/// values at any point are exact negatives of each other: a pixel centre near a shared edge is
/// inside exactly one of them however the rounding falls, and one exactly on it goes to the
/// triangle whose side owns it under the top-left rule ([`owns_boundary`]). That is what makes the
/// rasterizer watertight (no pixel between two triangles, none drawn twice).
///
/// Evaluated in f64: a vertex clipped at the near plane can project millions of pixels away, where
/// f32 products of coordinates would misplace the edge by pixels.
#[derive(Clone, Copy)]
struct CanonicalEdge {
    a: [f64; 2],
    b: [f64; 2],
    factor: f64,
    owns: bool,
}

impl CanonicalEdge {
    fn new(a: [f32; 2], b: [f32; 2], sign: f32) -> Self {
        let owns = owns_boundary(a[0], a[1], b[0], b[1], sign);
        let (a64, b64) = (a.map(f64::from), b.map(f64::from));
        if (a[1], a[0]) <= (b[1], b[0]) {
            CanonicalEdge { a: a64, b: b64, factor: f64::from(sign), owns }
        } else {
            CanonicalEdge { a: b64, b: a64, factor: -f64::from(sign), owns }
        }
    }

    /// The edge's inside-positive value at `(px, py)` (twice the area of the edge and the point,
    /// signed by the triangle's orientation).
    #[inline(always)]
    fn at(&self, px: f64, py: f64) -> f64 {
        let [ax, ay] = self.a;
        let [bx, by] = self.b;
        ((bx - ax) * (py - ay) - (by - ay) * (px - ax)) * self.factor
    }

    #[inline(always)]
    fn inside(&self, e: f64) -> bool {
        e > 0.0 || (e == 0.0 && self.owns)
    }
}

/// Pixels whose edge values [`cover`] computes together.
const RUN: usize = 8;

/// Calls `f(i, b)` for every pixel centre of the rows `y_start..y_start + rows` (`i` indexing a
/// `rows × w` buffer) that `t` covers under the top-left rule, with the screen-space barycentric
/// weights `b` of the centre. Degenerate (zero-area or non-finite) triangles cover nothing.
/// Watertight: triangles sharing an edge (the same two screen points) cover every pixel centre
/// near it exactly once ([`CanonicalEdge`]).
#[inline(always)]
pub(crate) fn cover(
    t: &ScreenTri,
    y_start: usize,
    rows: usize,
    w: usize,
    mut f: impl FnMut(usize, [f32; 3]),
) {
    let [ax, bx, cx] = t.sx.map(f64::from);
    let [ay, by, cy] = t.sy.map(f64::from);
    let area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
    if area == 0.0 || !area.is_finite() {
        return;
    }
    let sign = area.signum() as f32;
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
    let v = |k: usize| [t.sx[k], t.sy[k]];
    let edges = [
        CanonicalEdge::new(v(1), v(2), sign),
        CanonicalEdge::new(v(2), v(0), sign),
        CanonicalEdge::new(v(0), v(1), sign),
    ];
    // Edge 0's value at vertex 0 is the triangle's doubled area, inside-positive: each edge's
    // value over it is a barycentric weight.
    let inv_area = 1.0 / edges[0].at(f64::from(t.sx[0]), f64::from(t.sy[0]));
    // How far the rows' spans below may stray from the edge tests, in pixels: a few units of f64
    // rounding of coordinates as large as the triangle's (a vertex far off screen makes them
    // large), so the spans are widened by that much and never miss a pixel the tests accept. An
    // edge function's rounding is about 2⁻⁵² of the coordinates' square, and an edge crossing a
    // row has a height of at least one f32 unit of its coordinates (2⁻²⁴ of them), so its
    // crossing moves by at most some 10⁻⁸ of the coordinates (3·10⁻⁵ pixels on a 2048-sample
    // row): `magnitude·10⁻⁸` plus a sixteenth of a pixel. (Every pixel tested is a pixel whose
    // three edge functions are evaluated, so the margin is paid on every row of every
    // triangle; it was 1.5 pixels a side.)
    let magnitude = [xmin, xmax, ylo, yhi].iter().fold(1.0f64, |m, &c| m.max(f64::from(c).abs()));
    let slack = 1.0 / 16.0 + magnitude * 1e-8;
    // Only the rows whose centres may lie within [ylo, yhi] (the test below still decides).
    let r0 = ((ylo - 0.5).ceil() - y_start as f32 - 1.0).max(0.0) as usize;
    let r1 = ((yhi - 0.5).floor() - y_start as f32 + 2.0).clamp(0.0, rows as f32) as usize;
    for r in r0..r1 {
        let py = (y_start + r) as f32 + 0.5;
        if py < ylo || py > yhi {
            continue;
        }
        // The row's span of the triangle (in f64), widened by `slack`: only its pixels are tested
        // (the edge tests decide), so long thin triangles cost their area, not their bounding box.
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let pyd = f64::from(py);
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            let (ax, ay, bx, by) =
                (f64::from(t.sx[a]), f64::from(t.sy[a]), f64::from(t.sx[b]), f64::from(t.sy[b]));
            if (ay <= pyd && pyd <= by) || (by <= pyd && pyd <= ay) {
                let x = if ay == by {
                    lo = lo.min(ax.min(bx));
                    ax.max(bx)
                } else {
                    ax + (pyd - ay) * ((bx - ax) / (by - ay))
                };
                lo = lo.min(x);
                hi = hi.max(x);
            }
        }
        if lo.is_nan() || hi.is_nan() || lo > hi {
            continue;
        }
        let xs = (lo - slack - 0.5).ceil().max(x0 as f64) as usize;
        let xe = (hi + slack - 0.5).floor().min(x1 as f64);
        if xe < xs as f64 {
            continue;
        }
        // In runs of `RUN` pixels: the three edge values of a run first, the same products on
        // the same numbers (so the same bits) but in lanes, then the tests and the calls.
        let end = xe as usize + 1;
        let mut x = xs;
        while x < end {
            let n = (end - x).min(RUN);
            let px0 = x as f64 + 0.5;
            let mut e = [[0.0f64; RUN]; 3];
            for (edge, e) in edges.iter().zip(&mut e) {
                for (l, v) in e.iter_mut().enumerate() {
                    // (`x + l` and its half are exact in f64: the same `px` as one at a time.)
                    *v = edge.at(px0 + l as f64, pyd);
                }
            }
            for l in 0..n {
                let v = [e[0][l], e[1][l], e[2][l]];
                if edges[0].inside(v[0]) && edges[1].inside(v[1]) && edges[2].inside(v[2]) {
                    f(r * w + x + l, v.map(|e| (e * inv_area) as f32));
                }
            }
            x += RUN;
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

#[cfg(test)]
mod tests {
    use super::*;
    use hadou_math::rng::Rng;

    /// How many times `cover` reaches each pixel of a `w × h` image, over all of `tris`.
    fn coverage(tris: &[ScreenTri], w: usize, h: usize) -> Vec<u32> {
        let mut count = vec![0u32; w * h];
        for t in tris {
            cover(t, 0, h, w, |i, b| {
                assert!(b.iter().all(|x| x.is_finite()), "{b:?}");
                count[i] += 1;
            });
        }
        count
    }

    /// Two triangles per cell of a jittered `n × n` grid over `[x0, x1] × [y0, y1]` (corners and
    /// sides kept on the square's boundary; `jitter` below 0.5 keeps every cell convex), each cell
    /// split along a random diagonal, each
    /// triangle wound at random.
    fn tiled_square(rng: &mut Rng, n: usize, lo: [f32; 2], hi: [f32; 2], jitter: f32) -> Vec<ScreenTri> {
        let mut p = vec![[0.0f32; 2]; (n + 1) * (n + 1)];
        for j in 0..=n {
            for i in 0..=n {
                let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
                let mut x = lo[0] + u * (hi[0] - lo[0]);
                let mut y = lo[1] + v * (hi[1] - lo[1]);
                let cell = [(hi[0] - lo[0]) / n as f32, (hi[1] - lo[1]) / n as f32];
                if i > 0 && i < n {
                    x += (rng.unit() as f32 - 0.5) * jitter * cell[0];
                }
                if j > 0 && j < n {
                    y += (rng.unit() as f32 - 0.5) * jitter * cell[1];
                }
                p[j * (n + 1) + i] = [x, y];
            }
        }
        let mut tris = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let k = |a: usize, b: usize| p[(j + b) * (n + 1) + i + a];
                let (a, b, c, d) = (k(0, 0), k(1, 0), k(1, 1), k(0, 1));
                let halves = if rng.below(2) == 0 { [[a, b, c], [a, c, d]] } else { [[a, b, d], [b, c, d]] };
                for mut t in halves {
                    if rng.below(2) == 0 {
                        t.swap(1, 2);
                    }
                    tris.push(ScreenTri::flat([t[0][0], t[1][0], t[2][0]], [t[0][1], t[1][1], t[2][1]]));
                }
            }
        }
        tris
    }

    /// `cover`'s rows test only a span about the row's crossing of the triangle (widened by a
    /// margin): it must reach exactly the pixels of the whole bounding box whose three edge
    /// tests pass, also for edges nearly parallel to the rows and vertices far off screen.
    #[test]
    fn row_spans_miss_no_pixel_the_edge_tests_accept() {
        let mut rng = Rng(0x7370_616e_7321_2121);
        let (w, h) = (160, 120);
        for case in 0..4000 {
            let far = [1.0e2f32, 1.0e4, 1.0e6, 1.0e7][case % 4];
            let mut p =
                |spread: f32| [(rng.unit() as f32 - 0.3) * spread, (rng.unit() as f32 - 0.3) * spread];
            let (a, mut b, c) = (p(w as f32), p(w as f32), p(far));
            if case % 3 == 0 {
                // An edge within a fraction of a pixel of horizontal.
                b[1] = a[1] + (rng.unit() as f32 - 0.5) * 1e-3;
            }
            let t = ScreenTri::flat([a[0], b[0], c[0]], [a[1], b[1], c[1]]);
            let mut reached = vec![false; w * h];
            cover(&t, 0, h, w, |i, _| reached[i] = true);
            let area = f64::from(edge(a[0], a[1], b[0], b[1], c[0], c[1]));
            if area == 0.0 || !area.is_finite() {
                assert!(!reached.contains(&true), "case {case}: a degenerate triangle covers nothing");
                continue;
            }
            let sign = area.signum() as f32;
            let edges = [
                CanonicalEdge::new(b, c, sign),
                CanonicalEdge::new(c, a, sign),
                CanonicalEdge::new(a, b, sign),
            ];
            let (lo, hi) = ([a, b, c].map(|v| v[0]), [a, b, c].map(|v| v[1]));
            let (xmin, xmax) =
                (lo.iter().copied().fold(f32::MAX, f32::min), lo.iter().copied().fold(f32::MIN, f32::max));
            let (ymin, ymax) =
                (hi.iter().copied().fold(f32::MAX, f32::min), hi.iter().copied().fold(f32::MIN, f32::max));
            for y in 0..h {
                for x in 0..w {
                    let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                    let boxed = px >= xmin - 0.5 && px <= xmax + 0.5 && py >= ymin && py <= ymax;
                    let (pxd, pyd) = (f64::from(px), f64::from(py));
                    let accepted = boxed && edges.iter().all(|e| e.inside(e.at(pxd, pyd)));
                    assert_eq!(
                        reached[y * w + x],
                        accepted,
                        "case {case}: pixel ({x}, {y}) of {a:?} {b:?} {c:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn tiled_squares_cover_every_pixel_exactly_once() {
        let mut rng = Rng(0x7761_7465_7274_6967);
        let (w, h) = (96, 80);
        for case in 0..40 {
            // Small cells, big ones, and squares reaching far past the image (vertices up to
            // 1e5 pixels away, as a ground plane seen from above has).
            let (lo, hi, n) = match case % 4 {
                0 => ([0.0, 0.0], [w as f32, h as f32], 40),
                1 => ([0.0, 0.0], [w as f32, h as f32], 7),
                2 => ([-3000.0, -2000.0], [3100.0, 2500.0], 60),
                _ => ([-1e5, -7e4], [1.2e5, 9e4], 12),
            };
            let tris = tiled_square(&mut rng, n, lo, hi, 0.4);
            let count = coverage(&tris, w, h);
            let bad: Vec<(usize, usize, u32)> =
                (0..w * h).filter(|&i| count[i] != 1).map(|i| (i % w, i / w, count[i])).take(8).collect();
            assert!(bad.is_empty(), "case {case}: {} triangles; (x, y, times covered): {bad:?}", tris.len());
        }
    }

    #[test]
    fn pixel_centres_on_shared_edges_are_covered_once() {
        // Quads split along a diagonal through pixel centres (slopes 1, 2, 1/3, -1), corners far
        // outside the image, as a ground plane seen from straight above has: every centre on the
        // diagonal lies exactly on both triangles' edge, where rounding once dropped it from both.
        let (w, h) = (64, 48);
        for (k, (dx, dy)) in [(1.0f32, 1.0f32), (1.0, 2.0), (3.0, 1.0), (1.0, -1.0)].into_iter().enumerate() {
            for far in [100.0f32, 3000.0, 70_000.0] {
                let c = [20.5f32 + k as f32, 17.5];
                let a = [c[0] - far * dx, c[1] - far * dy];
                let b = [c[0] + far * dx, c[1] + far * dy];
                // The other two corners, far off each side of the diagonal.
                let (nx, ny) = (-dy * far * 3.0, dx * far * 3.0);
                let p = [c[0] + nx, c[1] + ny];
                let q = [c[0] - nx, c[1] - ny];
                let tris = [
                    ScreenTri::flat([a[0], b[0], p[0]], [a[1], b[1], p[1]]),
                    ScreenTri::flat([b[0], a[0], q[0]], [b[1], a[1], q[1]]),
                ];
                let count = coverage(&tris, w, h);
                let bad: Vec<(usize, usize, u32)> =
                    (0..w * h).filter(|&i| count[i] != 1).map(|i| (i % w, i / w, count[i])).take(8).collect();
                assert!(
                    bad.is_empty(),
                    "slope ({dx}, {dy}), corners {far} px away: (x, y, times covered): {bad:?}"
                );
            }
        }
    }

    #[test]
    fn a_ground_reaching_behind_the_camera_has_no_crack() {
        // A huge ground quad under a camera looking ahead, split along a random diagonal that
        // crosses the near plane: both triangles are clipped there, and every pixel below the
        // horizon must be covered exactly once. The clipped ends of the shared diagonal once
        // differed in the last bit between the two triangles, and the crack showed as single
        // background pixels along it (kamehameha.toml at 640×360, t = 1, pixel (516, 282)).
        let mut rng = Rng(0x6772_6f75_6e64);
        let size = 160;
        for case in 0..60 {
            let near = [1e-3f32, 0.05, 0.5][case % 3];
            let height = 0.2 + 3.0 * rng.unit() as f32;
            let yaw = rng.unit() as f32 * std::f32::consts::TAU;
            let extent = [50.0f32, 2000.0, 1e5][(case / 3) % 3];
            let proj = ScreenProjection::square(near, 25f32.to_radians().tan(), size as u32);
            let (c, s) = (yaw.cos(), yaw.sin());
            let corner = |x: f32, z: f32| {
                let view = Vec3f::new(c * x - s * z, -height, s * x + c * z);
                Vert {
                    view,
                    world: view,
                    normal: Vec3f::Y,
                    uv: [0.0; 2],
                    color: [1.0; 4],
                    outline: Vec3f::ZERO,
                }
            };
            let q = [
                corner(-extent, -extent),
                corner(extent, -extent),
                corner(extent, extent),
                corner(-extent, extent),
            ];
            let mut tris = Tris::default();
            proj.push([q[0], q[1], q[2]], 0, 0, false, &mut tris);
            proj.push([q[0], q[2], q[3]], 0, 0, false, &mut tris);
            let tris: Vec<ScreenTri> = tris.iter().copied().collect();
            let count = coverage(&tris, size, size);
            // The horizon is the middle row; below it, the ground fills every row whose ray meets
            // it (at depth `height / slope`, and at most √2 times that from the eye across the
            // view) well within the disc of radius `extent` the quad covers whatever its yaw.
            let tan_half = 25f32.to_radians().tan();
            let on_ground = |row: usize| {
                let slope = ((row as f32 + 0.5) / (size as f32 / 2.0) - 1.0) * tan_half;
                slope > 0.0 && height / slope * 1.5 < extent * 0.9
            };
            let bad: Vec<(usize, usize, u32)> = (0..size * size)
                .filter(|&i| on_ground(i / size) && count[i] != 1)
                .map(|i| (i % size, i / size, count[i]))
                .take(8)
                .collect();
            assert!(
                bad.is_empty(),
                "case {case} (near {near}, extent {extent}): (x, y, times covered): {bad:?}"
            );
        }
    }
}
