//! The `[area_light]`'s lamp as a shape (hadou's own, issue 43): a segment, a disc or a sphere;
//! how much of it a receiver sees ([`LampFrame`], [`LampPattern`], [`occlude`]: the traced
//! resolve's per-pixel work, which the GPU mirrors with the same fixed-size mask) and the light
//! it adds unshadowed ([`lamp_spread`], [`lamp_cosine`], [`lamp_toon_cosine`]).
//!
//! **What a receiver sees.** A receiver at `p` (already moved off its surface, [`TRACE_BIAS`])
//! and the lamp span a shadow volume; a caster triangle hides the lamp points `y` for which it
//! meets the ray `p + t·(y − p)` with `t ∈ [T_MIN, 1]`. The lamp lies in a plane (the segment's:
//! the plane through it facing `p`; the disc's own; the sphere's: the disc of its outline seen
//! from `p`, [`lamp_frame`]), so that set is the triangle clipped to the slab between `p` and the
//! plane and projected from `p` onto it: a convex polygon. The lamp's samples are rows of evenly
//! spaced points (one row of `samples` points along the segment; `⌊√samples⌉` rows of chords
//! across the unit disc, each row weighted by the exact area of its strip), every row shifted by
//! a per-pixel offset from the pixel's global coordinates ([`pixel_offset`]); each row meets the
//! polygon in one interval, solved exactly, and the samples inside it are set in a bit mask
//! ([`MASK_WORDS`] words, whatever the scene). The union over the triangles is the mask's OR, so
//! a pixel's visibility is the weighted share of clear samples: exact to the sample spacing,
//! without noise between frames.

use crate::Vec3f;

/// The lamp's shape.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LampShape {
    /// The segment `L₁L₂` from `L − l·P` to `L + l·P` (003's two map positions; the default).
    #[default]
    Segment,
    /// A disc of radius `l` centred on `L`, facing `G` (emitting towards `G`'s side only).
    Disc,
    /// A sphere of radius `l` centred on `L`.
    Sphere,
}

/// Most lamp samples a pixel of the traced resolve (the `samples` key's limit): 32 words of mask.
pub const MAX_TRACE_SAMPLES: u32 = 1024;
/// Words of a pixel's mask of hidden samples.
pub const MASK_WORDS: usize = (MAX_TRACE_SAMPLES / 32) as usize;
/// Smallest ray parameter a blocker may have (the ray `p + t·(y − p)` from the receiver to the
/// lamp point): a blocker within `T_MIN` of the receiver does not count, which keeps the
/// projection finite (at most `1/T_MIN` times the distance).
pub const T_MIN: f32 = 1e-5;
/// A receiver's point is moved along its normal by this fraction of its distance to `L` before
/// it looks at the lamp (its own surface's facets do not shade it beyond that).
pub const TRACE_BIAS: f32 = 1e-3;

/// Relative margin of [`LampFrame::beside_segment_plane`]: a thousand times what the clip and the
/// projection of [`occlude`] can round by (a few `f32` ulps of the coordinates, `6·10⁻⁸` each).
pub const SEGMENT_PLANE_MARGIN: f32 = 1e-4;

/// The margin [`LampFrame::beside_segment_plane`] takes for a receiver `p` among casters whose
/// coordinates are at most `extent` in magnitude: [`SEGMENT_PLANE_MARGIN`] of the largest
/// coordinate either can have, so that a point it calls beside the plane is beside it after any
/// rounding of [`occlude`] too.
#[inline]
pub fn segment_plane_margin(p: Vec3f, extent: f32) -> f32 {
    SEGMENT_PLANE_MARGIN * (p.x.abs().max(p.y.abs()).max(p.z.abs()) + extent)
}

/// The wedge around a segment lamp's line that holds the planes through it and each receiver of a
/// tile (hadou's own): every sample ray of a receiver lies in the half-plane bounded by the line
/// that holds the receiver, so a triangle or box wholly outside the wedge hides nothing from any
/// of the tile's receivers, and the traced resolve drops it from the tile's candidates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentWedge {
    /// A point of the line (the lamp's centre).
    at: Vec3f,
    /// The two bounding planes' normals through `at`, each towards the wedge.
    lo: Vec3f,
    hi: Vec3f,
    /// [`segment_plane_margin`] of the tile.
    margin: f32,
}

impl SegmentWedge {
    /// The wedge around the line through `centre` along the unit `axis` that holds the receivers
    /// `pts`, with the margin `margin`; `None` where it would be half a turn wide or more, a
    /// receiver lies on the line, or a value is not finite (no wedge: keep every candidate).
    pub fn around(centre: Vec3f, axis: Vec3f, pts: &[Vec3f], margin: f32) -> Option<SegmentWedge> {
        let off = |p: Vec3f| {
            let q = p - centre;
            q - axis * q.dot(axis)
        };
        let d0 = off(*pts.first()?).try_normalize()?;
        let e2 = axis.cross(d0);
        let (mut a0, mut a1) = (0.0f32, 0.0f32);
        for &p in pts {
            let q = off(p);
            if q.length_squared() <= 0.0 {
                return None;
            }
            let a = q.dot(e2).atan2(q.dot(d0));
            a0 = a0.min(a);
            a1 = a1.max(a);
        }
        // Well short of half a turn, so that the planes bound a convex wedge.
        let narrow = a1 - a0 < 0.9 * std::f32::consts::PI;
        if !narrow || !margin.is_finite() {
            return None;
        }
        // The plane at angle `a` holds `d0·cos a + e2·sin a`; its normal towards larger angles.
        let normal = |a: f32| e2 * a.cos() - d0 * a.sin();
        Some(SegmentWedge { at: centre, lo: normal(a0), hi: -normal(a1), margin })
    }

    /// Whether every point of `pts` lies farther than the margin outside one bounding plane.
    #[inline]
    pub fn misses(&self, pts: &[Vec3f]) -> bool {
        let (mut lo, mut hi) = (f32::NEG_INFINITY, f32::NEG_INFINITY);
        for &c in pts {
            let q = c - self.at;
            lo = lo.max(self.lo.dot(q));
            hi = hi.max(self.hi.dot(q));
        }
        lo < -self.margin || hi < -self.margin
    }

    /// [`SegmentWedge::misses`] for the box `lo..hi`.
    #[inline]
    pub fn misses_box(&self, lo: [f32; 3], hi: [f32; 3]) -> bool {
        let c = Vec3f::new(lo[0] + hi[0], lo[1] + hi[1], lo[2] + hi[2]) * 0.5 - self.at;
        let e = Vec3f::new(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) * 0.5;
        let reach = |n: Vec3f| e.x * n.x.abs() + e.y * n.y.abs() + e.z * n.z.abs();
        self.lo.dot(c) + reach(self.lo) < -self.margin || self.hi.dot(c) + reach(self.hi) < -self.margin
    }
}

/// The lamp as seen from one receiver: the plane it is sampled in and the receiver's height
/// above it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LampFrame {
    /// The receiver's (biased) point `p`.
    pub origin: Vec3f,
    /// The centre of the sampled disc or segment.
    pub centre: Vec3f,
    /// In-plane unit axis (the segment's direction).
    pub u: Vec3f,
    /// The other in-plane unit axis.
    pub v: Vec3f,
    /// Unit normal of the plane, towards `p`.
    pub n: Vec3f,
    /// Radius of the disc, half-length of the segment.
    pub radius: f32,
    /// `n·(p − centre) > 0`.
    pub height: f32,
}

/// The lamp of shape `shape`, centre `l`, unit axis `axis = P = (L − G)/|L − G|` and size `size`
/// seen from the (biased) receiver point `p`; `None` where the receiver sees the lamp edge-on or
/// from inside (on the segment's line, in the disc's plane, inside the sphere: the traced
/// resolve counts such a point as seeing all of it).
///
/// - segment: centre `L`, `u = P`, the plane through the segment facing `p`;
/// - disc: centre `L`, the disc's plane (normal `±P` towards `p`), `(u, v)` =
///   `P.orthonormal_basis()` (the same for every pixel);
/// - sphere: the outline disc seen from `p` at distance `d = |p − L|`: centre `L + ŵ·l²/d`,
///   radius `l·√(d² − l²)/d`, normal `ŵ = (p − L)/d`, `(u, v)` = `ŵ.orthonormal_basis()`.
pub fn lamp_frame(shape: LampShape, l: Vec3f, axis: Vec3f, size: f32, p: Vec3f) -> Option<LampFrame> {
    let r = p - l;
    let (centre, u, v, n, radius) = match shape {
        LampShape::Segment => {
            let n = (r - axis * r.dot(axis)).try_normalize()?;
            (l, axis, n.cross(axis), n, size)
        }
        LampShape::Disc => {
            let n = if r.dot(axis) < 0.0 { -axis } else { axis };
            let (u, v) = axis.orthonormal_basis();
            (l, u, v, n, size)
        }
        LampShape::Sphere => {
            let d = r.length();
            if d <= size || !d.is_finite() {
                return None;
            }
            let w = r / d;
            let (u, v) = w.orthonormal_basis();
            (l + w * (size * size / d), u, v, w, size * ((d - size) * (d + size)).sqrt() / d)
        }
    };
    let height = n.dot(p - centre);
    (height > 0.0 && height.is_finite() && radius > 0.0).then_some(LampFrame {
        origin: p,
        centre,
        u,
        v,
        n,
        radius,
        height,
    })
}

impl LampFrame {
    /// For the segment lamp: whether every point of `pts` lies farther than `margin` on one side
    /// of the plane through the receiver and the segment (normal `v`), the plane every sample's
    /// ray lies in. Such a triangle or box hides no sample (its clipped projection misses the
    /// row `y = 0` that [`occlude`] fills), so the traced resolve skips it before clipping
    /// (hadou's own). `margin` covers the rounding of [`occlude`]'s clip and projection
    /// ([`segment_plane_margin`]); `false` where unsure (NaN).
    #[inline]
    pub fn beside_segment_plane(&self, pts: &[Vec3f], margin: f32) -> bool {
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for &c in pts {
            let d = self.v.dot(c - self.origin);
            lo = lo.min(d);
            hi = hi.max(d);
        }
        lo > margin || hi < -margin
    }

    /// [`LampFrame::beside_segment_plane`] for the box `lo..hi`: its centre's distance to the
    /// plane beyond its half-extent's reach along `v` and `margin`.
    #[inline]
    pub fn box_beside_segment_plane(&self, lo: [f32; 3], hi: [f32; 3], margin: f32) -> bool {
        let c = Vec3f::new(lo[0] + hi[0], lo[1] + hi[1], lo[2] + hi[2]) * 0.5;
        let e = Vec3f::new(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) * 0.5;
        let reach = e.x * self.v.x.abs() + e.y * self.v.y.abs() + e.z * self.v.z.abs();
        (self.v.dot(c - self.origin)).abs() > reach + margin
    }

    /// Whether anything inside the box `lo..hi` can hide a sample of the lamp (layout `pat`,
    /// first-row offset `o`) that `mask` does not hide yet: `false` when every corner lies beyond
    /// the lamp's plane, or when every corner lies between the planes and the bounding rectangle
    /// of their projections from the origin (the convex hull of those projections holds the
    /// projection of the whole box: a central projection maps segments to segments there) holds
    /// no sample that is still clear; `true` when unsure (a corner at or behind the origin's
    /// parallel plane, NaN). The traced resolve's node test after [`crate::soft::capsule_hits`]:
    /// it also skips what lies behind samples already hidden (hadou's own).
    #[inline]
    pub fn box_may_hide(
        &self,
        lo: [f32; 3],
        hi: [f32; 3],
        pat: &LampPattern,
        o: f32,
        mask: &[u32; MASK_WORDS],
    ) -> bool {
        let top = self.height * (1.0 - T_MIN);
        let inv_r = 1.0 / self.radius;
        let (mut x0, mut x1, mut y0, mut y1) =
            (f32::INFINITY, f32::NEG_INFINITY, f32::INFINITY, f32::NEG_INFINITY);
        let mut beyond = 0;
        for k in 0..8 {
            let c = Vec3f::new(
                if k & 1 == 0 { lo[0] } else { hi[0] },
                if k & 2 == 0 { lo[1] } else { hi[1] },
                if k & 4 == 0 { lo[2] } else { hi[2] },
            );
            let h = self.n.dot(c - self.centre);
            if h.is_nan() || h >= top {
                return true;
            }
            if h < 0.0 {
                beyond += 1;
            }
            let s = self.height / (self.height - h);
            let y = self.origin + (c - self.origin) * s - self.centre;
            let (px, py) = (self.u.dot(y) * inv_r, self.v.dot(y) * inv_r);
            x0 = x0.min(px);
            x1 = x1.max(px);
            y0 = y0.min(py);
            y1 = y1.max(py);
        }
        if beyond == 8 || x0.is_nan() || y0.is_nan() {
            return beyond < 8;
        }
        let (j0, j1) = pat.rows_within(y0, y1);
        for j in j0..=j1 {
            let (yj, c) = pat.row(j);
            if yj < y0 || yj > y1 {
                continue;
            }
            if let Some((a, b)) = pat.samples_within(o, j, c, x0, x1) {
                if count_bits(mask, a, b) < b - a {
                    return true;
                }
            }
        }
        false
    }
}

/// The sample layout of a lamp: `rows` rows of `per_row` samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LampPattern {
    /// Whether the rows are chords of the unit disc (disc, sphere) or the one row `[−1, 1]`
    /// (segment).
    pub disc: bool,
    /// Rows.
    pub rows: u32,
    /// Samples a row.
    pub per_row: u32,
    /// Each row's share of the lamp ([`LampPattern::row_weight`]), for rows `0..rows` (at most
    /// [`MAX_ROWS`]).
    pub weights: [f32; MAX_ROWS],
}

/// Most rows of a [`LampPattern`]: `round(√MAX_TRACE_SAMPLES)`.
pub const MAX_ROWS: usize = 32;

impl LampPattern {
    /// The layout of `samples` (clamped to `1..=MAX_TRACE_SAMPLES`) for `shape`: one row of
    /// `samples` for the segment; `k = max(1, round(√samples))` rows of `⌊samples/k⌋` for the disc
    /// and the sphere (`k·⌊samples/k⌋ ≤ samples` samples in all: 256 → 16 × 16).
    pub fn new(shape: LampShape, samples: u32) -> LampPattern {
        let s = samples.clamp(1, MAX_TRACE_SAMPLES);
        let mut p = match shape {
            LampShape::Segment => LampPattern { disc: false, rows: 1, per_row: s, weights: [0.0; MAX_ROWS] },
            _ => {
                let rows = ((s as f32).sqrt().round() as u32).clamp(1, MAX_ROWS as u32);
                LampPattern { disc: true, rows, per_row: (s / rows).max(1), weights: [0.0; MAX_ROWS] }
            }
        };
        for j in 0..p.rows {
            p.weights[j as usize] = p.row_weight(j);
        }
        p
    }

    /// Samples in all.
    pub fn samples(&self) -> u32 {
        self.rows * self.per_row
    }

    /// Row `j`'s height `y` in the unit disc (its strip's middle) and the half-length `c` of its
    /// chord: `y = −1 + (2j + 1)/rows`, `c = √(1 − y²)`; the segment's row is `(0, 1)`.
    #[inline]
    pub fn row(&self, j: u32) -> (f32, f32) {
        if !self.disc {
            return (0.0, 1.0);
        }
        let y = -1.0 + (2 * j + 1) as f32 / self.rows as f32;
        (y, (1.0 - y * y).max(0.0).sqrt())
    }

    /// The rows whose height `−1 + (2j + 1)/rows` lies in `[y0, y1]` (the disc's; the segment's
    /// one row always), as `j0..=j1` (empty when `j0 > j1`; a row outside adds nothing since it
    /// meets no edge).
    #[inline]
    pub fn rows_within(&self, y0: f32, y1: f32) -> (u32, u32) {
        if !self.disc {
            return (0, 0);
        }
        let r = self.rows as f32;
        let k = |y: f32| (y.clamp(-1.0, 1.0) + 1.0) * 0.5 * r - 0.5;
        (ceil_small(k(y0)).max(0.0) as u32, floor_small(k(y1)).clamp(0.0, r - 1.0) as u32)
    }

    /// The bits `a..b` of row `j` (chord half-length `c`, first-row offset `o`) whose samples
    /// `x = −c + (i + oⱼ)·2c/per_row` lie in `[lo, hi]`; `None` when none does.
    #[inline]
    pub fn samples_within(&self, o: f32, j: u32, c: f32, lo: f32, hi: f32) -> Option<(u32, u32)> {
        if lo.is_nan() || hi.is_nan() || lo > hi || c <= 0.0 {
            return None;
        }
        let m = self.per_row as f32;
        let oj = row_offset(o, j);
        let scale = m / (2.0 * c);
        let i0 = ceil_small(((lo + c) * scale - oj).clamp(-1.0, m + 1.0)).max(0.0);
        let i1 = floor_small(((hi + c) * scale - oj).clamp(-1.0, m + 1.0)).min(m - 1.0);
        let base = j * self.per_row;
        (i0 <= i1).then(|| (base + i0 as u32, base + i1 as u32 + 1))
    }

    /// Row `j`'s share of the lamp: the area of its strip `[−1 + 2j/rows, −1 + 2(j+1)/rows]` of the
    /// unit disc over `π` (`F(y) = y·√(1 − y²) + asin y`), 1 for the segment.
    pub fn row_weight(&self, j: u32) -> f32 {
        if !self.disc {
            return 1.0;
        }
        let f = |y: f64| y * (1.0 - y * y).max(0.0).sqrt() + y.clamp(-1.0, 1.0).asin();
        let (y0, y1) =
            (-1.0 + 2.0 * j as f64 / self.rows as f64, -1.0 + 2.0 * (j + 1) as f64 / self.rows as f64);
        ((f(y1) - f(y0)) / std::f64::consts::PI) as f32
    }
}

/// Chris Wellons's `lowbias32` integer hash.
#[inline]
fn hash32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// The first row's offset of pixel `(x, y)` (global image coordinates) in `[0, 1)`:
/// `hash32(x·0x9E3779B1 ⊕ hash32(y))·2⁻³²`; row `j` uses `fract(o + j·0.618034)`.
#[inline]
pub fn pixel_offset(x: u32, y: u32) -> f32 {
    (hash32(x.wrapping_mul(0x9e37_79b1) ^ hash32(y)) >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// Row `j`'s offset from the pixel's [`pixel_offset`] `o`: `fract(o + j·0.618034)`.
#[inline]
pub fn row_offset(o: f32, j: u32) -> f32 {
    let x = o + j as f32 * 0.618_034;
    x - floor_small(x)
}

/// `⌊x⌋` of an `x` already clamped to a small range (no libm call).
#[inline]
fn floor_small(x: f32) -> f32 {
    let i = x as i32 as f32;
    if i > x {
        i - 1.0
    } else {
        i
    }
}

/// `⌈x⌉` of an `x` already clamped to a small range.
#[inline]
fn ceil_small(x: f32) -> f32 {
    let i = x as i32 as f32;
    if i < x {
        i + 1.0
    } else {
        i
    }
}

/// Sets the bits `a..b` of `mask`.
#[inline]
fn set_bits(mask: &mut [u32; MASK_WORDS], a: u32, b: u32) {
    let mut i = a;
    while i < b {
        let (w, bit) = ((i / 32) as usize, i % 32);
        let n = (32 - bit).min(b - i);
        let m = if n == 32 { u32::MAX } else { ((1u32 << n) - 1) << bit };
        mask[w] |= m;
        i += n;
    }
}

/// The count of set bits `a..b` of `mask`.
#[inline]
fn count_bits(mask: &[u32; MASK_WORDS], a: u32, b: u32) -> u32 {
    let mut i = a;
    let mut c = 0;
    while i < b {
        let (w, bit) = ((i / 32) as usize, i % 32);
        let n = (32 - bit).min(b - i);
        let m = if n == 32 { u32::MAX } else { ((1u32 << n) - 1) << bit };
        c += (mask[w] & m).count_ones();
        i += n;
    }
    c
}

/// Whether every sample of `pat` is set in `mask`.
#[inline]
pub fn mask_full(mask: &[u32; MASK_WORDS], pat: &LampPattern) -> bool {
    let n = pat.samples();
    let (whole, rest) = ((n / 32) as usize, n % 32);
    mask[..whole].iter().all(|&w| w == u32::MAX)
        && (rest == 0 || mask[whole] | !((1u32 << rest) - 1) == u32::MAX)
}

/// The visible share of the lamp: `Σⱼ weightⱼ·(clear samples of row j)/per_row`, in `[0, 1]`.
pub fn mask_visibility(mask: &[u32; MASK_WORDS], pat: &LampPattern) -> f32 {
    let mut v = 0.0f32;
    for j in 0..pat.rows {
        let hidden = count_bits(mask, j * pat.per_row, (j + 1) * pat.per_row);
        v += pat.weights[j as usize] * (pat.per_row - hidden) as f32 / pat.per_row as f32;
    }
    v.clamp(0.0, 1.0)
}

/// Sets in `mask` the samples of the lamp `f` (layout `pat`, first-row offset `o` from
/// [`pixel_offset`]) that the triangle `tri` hides from `f.origin` (see the module notes): the
/// triangle clipped to `0 ≤ h ≤ (1 − T_MIN)·height` (`h` the height over the lamp's plane),
/// projected from the origin onto the plane in units of the radius, and each row's interval of
/// the polygon turned into the samples `i` with `−c + (i + oⱼ)·2c/per_row` inside it (only the
/// rows within the polygon's height range; every sample at once when the polygon holds the lamp's
/// box).
pub fn occlude(f: &LampFrame, pat: &LampPattern, o: f32, tri: &[Vec3f; 3], mask: &mut [u32; MASK_WORDS]) {
    let hp = f.height;
    let top = hp * (1.0 - T_MIN);
    // Clip against h ≥ 0 then h ≤ top (Sutherland–Hodgman); at most 5 corners.
    let mut a = [Vec3f::ZERO; 5];
    let mut ha = [0.0f32; 5];
    let mut na = 0;
    for &v in tri {
        a[na] = v;
        ha[na] = f.n.dot(v - f.centre);
        na += 1;
    }
    let mut b = [Vec3f::ZERO; 5];
    let mut hb = [0.0f32; 5];
    let mut nb = 0;
    for i in 0..na {
        let (p, q, hp0, hq) = (a[i], a[(i + 1) % na], ha[i], ha[(i + 1) % na]);
        if hp0 >= 0.0 {
            b[nb] = p;
            hb[nb] = hp0;
            nb += 1;
        }
        if (hp0 >= 0.0) != (hq >= 0.0) {
            let t = hp0 / (hp0 - hq);
            b[nb] = p + (q - p) * t;
            hb[nb] = 0.0;
            nb += 1;
        }
    }
    na = 0;
    for i in 0..nb {
        let (p, q, hp0, hq) = (b[i], b[(i + 1) % nb], hb[i], hb[(i + 1) % nb]);
        if hp0 <= top {
            a[na] = p;
            ha[na] = hp0;
            na += 1;
        }
        if (hp0 <= top) != (hq <= top) {
            let t = (hp0 - top) / (hp0 - hq);
            a[na] = p + (q - p) * t;
            ha[na] = top;
            na += 1;
        }
    }
    if na < 3 {
        return;
    }
    // Project from the origin onto the plane, in units of the radius.
    let mut xy = [(0.0f32, 0.0f32); 5];
    let inv_r = 1.0 / f.radius;
    for i in 0..na {
        let s = hp / (hp - ha[i]).max(hp * T_MIN);
        let y = f.origin + (a[i] - f.origin) * s - f.centre;
        xy[i] = (f.u.dot(y) * inv_r, f.v.dot(y) * inv_r);
    }
    // The polygon's extent; nothing to do when it misses the lamp's box.
    let (mut x0, mut x1, mut y0, mut y1) =
        (f32::INFINITY, f32::NEG_INFINITY, f32::INFINITY, f32::NEG_INFINITY);
    for &(x, y) in &xy[..na] {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    let ylim = if pat.disc { 1.0 } else { 0.0 };
    if x0 > 1.0 || x1 < -1.0 || y0 > ylim || y1 < -ylim || x0.is_nan() || y0.is_nan() {
        return;
    }
    // A polygon holding the lamp's box (the square [−1, 1]², the segment [−1, 1] × {0}) hides
    // every sample: the corners on the inner side of every edge (the sign of the polygon's
    // orientation, or on it).
    let area: f32 = (0..na).map(|i| xy[i].0 * xy[(i + 1) % na].1 - xy[(i + 1) % na].0 * xy[i].1).sum();
    let holds = |px: f32, py: f32| {
        (0..na).all(|i| {
            let (a, b) = (xy[i], xy[(i + 1) % na]);
            ((b.0 - a.0) * (py - a.1) - (b.1 - a.1) * (px - a.0)) * area >= 0.0
        })
    };
    if area != 0.0 && holds(-1.0, -ylim) && holds(1.0, -ylim) && holds(-1.0, ylim) && holds(1.0, ylim) {
        set_bits(mask, 0, pat.samples());
        return;
    }
    let (j0, j1) = pat.rows_within(y0, y1);
    for j in j0..=j1 {
        let (yj, c) = pat.row(j);
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for i in 0..na {
            let (p, q) = (xy[i], xy[(i + 1) % na]);
            if (p.1 - yj) * (q.1 - yj) > 0.0 {
                continue;
            }
            if p.1 == q.1 {
                lo = lo.min(p.0.min(q.0));
                hi = hi.max(p.0.max(q.0));
            } else {
                let x = p.0 + (yj - p.1) * (q.0 - p.0) / (q.1 - p.1);
                lo = lo.min(x);
                hi = hi.max(x);
            }
        }
        if let Some((a, b)) = pat.samples_within(o, j, c, lo, hi) {
            set_bits(mask, a, b);
        }
    }
}

/// [`occlude`] for the segment lamp, in the plane that holds the receiver and the segment
/// (hadou's own): every sample ray lies in that plane (normal `v`), so the samples a triangle
/// hides are those its chord across the plane hides, and that chord's projection from the
/// receiver onto the segment's line is one interval. The triangle meets the plane in at most two
/// points (where its edges cross it, or its corners on it); the chord between them, in the
/// plane's coordinates `(u·(X − L), h)`, is clipped to `0 ≤ h ≤ (1 − T_MIN)·height` and its two
/// ends projected from the receiver as [`occlude`] projects a corner. The same set as
/// [`occlude`]'s row `y = 0` of the projected polygon, from a few products instead of two clips
/// of the whole triangle and up to five projections; the two agree but for samples within
/// rounding of an interval's end. A triangle lying in the plane (every corner on it) is handed to
/// [`occlude`]. `f` must be a segment's frame ([`lamp_frame`] with [`LampShape::Segment`]).
pub fn occlude_segment(
    f: &LampFrame,
    pat: &LampPattern,
    o: f32,
    tri: &[Vec3f; 3],
    mask: &mut [u32; MASK_WORDS],
) {
    let d = tri.map(|c| f.v.dot(c - f.origin));
    // Wholly on one side of the plane (most of a pixel's candidates): nothing to do.
    if (d[0] > 0.0 && d[1] > 0.0 && d[2] > 0.0) || (d[0] < 0.0 && d[1] < 0.0 && d[2] < 0.0) {
        return;
    }
    let ah = tri.map(|c| {
        let e = c - f.centre;
        (f.u.dot(e), f.n.dot(e))
    });
    // The triangle's points on the plane: at most two, or three when it lies in it.
    let mut pts = [(0.0f32, 0.0f32); 3];
    let mut np = 0;
    for i in 0..3 {
        let j = (i + 1) % 3;
        if d[i] == 0.0 {
            pts[np] = ah[i];
            np += 1;
        }
        if (d[i] < 0.0 && d[j] > 0.0) || (d[i] > 0.0 && d[j] < 0.0) {
            let t = d[i] / (d[i] - d[j]);
            pts[np] = (ah[i].0 + (ah[j].0 - ah[i].0) * t, ah[i].1 + (ah[j].1 - ah[i].1) * t);
            np += 1;
        }
    }
    match np {
        0 => return,
        3 => return occlude(f, pat, o, tri, mask),
        _ => {}
    }
    let hp = f.height;
    let top = hp * (1.0 - T_MIN);
    let (mut p, mut q) = (pts[0], pts[np - 1]);
    // Clip the chord to h ≥ 0, then to h ≤ top (a crossing point takes the bound's h exactly).
    for (bound, below) in [(0.0f32, false), (top, true)] {
        let out = |h: f32| if below { h > bound } else { h < bound };
        match (out(p.1), out(q.1)) {
            (true, true) => return,
            (false, false) => {}
            (po, _) => {
                let t = (p.1 - bound) / (p.1 - q.1);
                let x = (p.0 + (q.0 - p.0) * t, bound);
                if po {
                    p = x;
                } else {
                    q = x;
                }
            }
        }
    }
    let ar = f.u.dot(f.origin - f.centre);
    let inv_r = 1.0 / f.radius;
    let project = |(a, h): (f32, f32)| {
        let s = hp / (hp - h).max(hp * T_MIN);
        (ar + (a - ar) * s) * inv_r
    };
    let (xp, xq) = (project(p), project(q));
    if let Some((a, b)) = pat.samples_within(o, 0, 1.0, xp.min(xq), xp.max(xq)) {
        set_bits(mask, a, b);
    }
}

/// The world point of sample `i` of row `j` of the lamp `f` (for tests and the GPU's ray-by-ray
/// comparison): `centre + radius·(x·u + y·v)` with `x = −c + (i + oⱼ)·2c/per_row`.
pub fn sample_point(f: &LampFrame, pat: &LampPattern, o: f32, j: u32, i: u32) -> Vec3f {
    let (y, c) = pat.row(j);
    let x = -c + (i as f32 + row_offset(o, j)) * 2.0 * c / pat.per_row as f32;
    f.centre + (f.u * x + f.v * y) * f.radius
}

/// How the lamp spreads around a receiver at `p` for its unshadowed light: `(facing, sin σ)`,
/// `σ` the lamp's angular radius and `facing` its emission towards `p` (hadou's own):
///
/// - segment: `(1, 0)` (003's point-like direction to `L`, unchanged);
/// - disc: `facing = max(0, l̂·P)`, `sin²σ = l²/(l² + d²)` (Lagarde & de Rousiers 2014, "Moving
///   Frostbite to PBR", §4.7.2: the disc as the sphere of the same solid angle seen face-on);
/// - sphere: `(1, min(l/d, 1))`;
///
/// with `l̂ = (L − p)/d`, `d = |L − p|`.
pub fn lamp_spread(shape: LampShape, l: Vec3f, axis: Vec3f, size: f32, p: Vec3f) -> (f32, f32) {
    let r = l - p;
    let d = r.length();
    match shape {
        LampShape::Segment => (1.0, 0.0),
        LampShape::Disc => {
            let facing = (r / d.max(f32::MIN_POSITIVE)).dot(axis).max(0.0);
            let s2 = size * size / (size * size + d * d);
            (if facing.is_finite() { facing } else { 0.0 }, if s2.is_finite() { s2.sqrt() } else { 0.0 })
        }
        LampShape::Sphere => (1.0, if d > size { size / d } else { 1.0 }),
    }
}

/// The diffuse factor of a lamp of angular radius `σ` (`sin_sigma = sin σ`) at `m = N·l̂`:
/// the horizon-clipped irradiance of a sphere (Snyder 1996, in Lagarde & de Rousiers 2014,
/// "Moving Frostbite to PBR", eq. 34 and listing 7) over the `π·sin²σ` of the same lamp straight
/// above, so it is `max(0, m)` wherever the whole lamp is above the horizon or below it
/// (`|m| ≥ sin σ`) and, in between, `[m·acos y − x·sin θ·√(1 − y²)]/π + atan(sin θ·√(1 − y²)/x)/(π·sin²σ)`
/// with `x = √(1/sin²σ − 1)`, `y = −x·m/sin θ`, `sin θ = √(1 − m²)`. `sin σ ≤ 10⁻⁴` gives
/// `max(0, m)`; `sin²σ` is kept below `1 − 10⁻⁶`. Continuous, in `[0, 1]`, never NaN.
pub fn lamp_cosine(m: f32, sin_sigma: f32) -> f32 {
    if m.is_nan() {
        return 0.0;
    }
    let m = m.clamp(-1.0, 1.0);
    if sin_sigma.is_nan() || sin_sigma <= 1e-4 || m * m >= sin_sigma * sin_sigma {
        return m.max(0.0);
    }
    let s2 = (sin_sigma * sin_sigma).min(1.0 - 1e-6);
    let x = (1.0 / s2 - 1.0).sqrt();
    let sin_t = (1.0 - m * m).max(0.0).sqrt().max(1e-6);
    let y = (-x * m / sin_t).clamp(-1.0, 1.0);
    let sy = sin_t * (1.0 - y * y).max(0.0).sqrt();
    let e = (m * y.acos() - x * sy) * s2 + (sy / x).atan();
    (e / (std::f32::consts::PI * s2)).clamp(0.0, 1.0)
}

/// The toon and MToon ramps' input for a lamp of angular radius `σ` (hadou's own): the unclamped
/// `m = N·l̂` plus what the lamp's horizon adds to the diffuse factor, `m + lamp_cosine(m, sin σ) −
/// max(0, m)`: `m` itself wherever the lamp is wholly above or below the horizon (so a toon ramp
/// sees the same negative values as with the segment), continuous across it.
pub fn lamp_toon_cosine(m: f32, sin_sigma: f32) -> f32 {
    if sin_sigma.is_nan() || sin_sigma <= 1e-4 {
        return m;
    }
    m + lamp_cosine(m, sin_sigma) - m.max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tiny ray–triangle test (Möller–Trumbore, double-sided) for the checks below.
    fn hits(o: Vec3f, d: Vec3f, t: &[Vec3f; 3]) -> Option<f32> {
        let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-12 {
            return None;
        }
        let s = o - t[0];
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = d.dot(q) / det;
        let tt = e2.dot(q) / det;
        (u >= 0.0 && v >= 0.0 && u + v <= 1.0).then_some(tt)
    }

    #[test]
    fn the_mask_is_the_rays_that_meet_the_triangle() {
        let mut s = 0x1234_5678u32;
        let mut r = move || {
            s = hash32(s.wrapping_add(0x9e37_79b9));
            (s >> 8) as f32 / 16_777_216.0
        };
        let (mut agree, mut total) = (0usize, 0usize);
        for case in 0..300 {
            let shape = [LampShape::Segment, LampShape::Disc, LampShape::Sphere][case % 3];
            let l = Vec3f::new(0.0, 4.0, 0.0);
            let axis = Vec3f::new(0.1, 1.0, 0.2).normalize_or(Vec3f::Y);
            let p = Vec3f::new(r() * 4.0 - 2.0, 0.0, r() * 4.0 - 2.0);
            let Some(f) = lamp_frame(shape, l, axis, 0.6, p) else { continue };
            let pat = LampPattern::new(shape, 64 + case as u32);
            let c = Vec3f::new(r() * 2.0 - 1.0, 1.0 + r() * 2.5, r() * 2.0 - 1.0);
            let tri = [0, 1, 2].map(|_| c + Vec3f::new(r() - 0.5, r() - 0.5, r() - 0.5) * 1.5);
            let o = pixel_offset(case as u32, 3);
            let mut mask = [0u32; MASK_WORDS];
            occlude(&f, &pat, o, &tri, &mut mask);
            for j in 0..pat.rows {
                for i in 0..pat.per_row {
                    let y = sample_point(&f, &pat, o, j, i);
                    let ray = hits(p, y - p, &tri).is_some_and(|t| (T_MIN..=1.0).contains(&t));
                    let bit = j * pat.per_row + i;
                    let set = mask[(bit / 32) as usize] >> (bit % 32) & 1 == 1;
                    total += 1;
                    agree += usize::from(ray == set);
                }
            }
        }
        // Samples within rounding of a triangle's edge may differ.
        assert!(total > 10_000 && agree as f64 >= 0.999 * total as f64, "{agree} of {total}");
    }

    #[test]
    fn the_segments_chord_hides_what_the_rays_meet() {
        // occlude_segment against the rays and against occlude, on triangles that cross the
        // segment's plane near and far from the receiver, some reaching past the lamp or behind
        // the receiver, some large (whose clipped polygon's edges run nearly along the row).
        let mut s = 0x0bad_5eedu32;
        let mut r = move || {
            s = hash32(s.wrapping_add(0x9e37_79b9));
            (s >> 8) as f32 / 16_777_216.0
        };
        let (mut total, mut chord_off, mut clip_off, mut hidden) = (0u64, 0u64, 0u64, 0u64);
        for case in 0..1500 {
            let l = Vec3f::new(0.3, 4.0, -0.2);
            let axis = Vec3f::new(0.1, 1.0, 0.2).normalize_or(Vec3f::Y);
            let p = Vec3f::new(r() * 4.0 - 2.0, r() * 0.5, r() * 4.0 - 2.0);
            let Some(f) = lamp_frame(LampShape::Segment, l, axis, 0.8, p) else { continue };
            let pat = LampPattern::new(LampShape::Segment, [64, 256, 1000][case % 3]);
            // About a point of the plane through p and the segment, between them or a little
            // beyond either.
            let t = r() * 1.3 - 0.15;
            let on = p + (l + axis * (r() * 2.4 - 1.2) - p) * t;
            let size = [0.05, 0.4, 3.0][(case / 3) % 3];
            let tri = [0, 1, 2].map(|_| on + Vec3f::new(r() - 0.5, r() - 0.5, r() - 0.5) * size);
            let o = pixel_offset(case as u32, 7);
            let (mut clip, mut chord) = ([0u32; MASK_WORDS], [0u32; MASK_WORDS]);
            occlude(&f, &pat, o, &tri, &mut clip);
            occlude_segment(&f, &pat, o, &tri, &mut chord);
            for i in 0..pat.samples() {
                let y = sample_point(&f, &pat, o, 0, i);
                let ray = hits(p, y - p, &tri).is_some_and(|t| (T_MIN..=1.0).contains(&t));
                let bit = |m: &[u32; MASK_WORDS]| m[(i / 32) as usize] >> (i % 32) & 1 == 1;
                total += 1;
                hidden += u64::from(ray);
                chord_off += u64::from(bit(&chord) != ray);
                clip_off += u64::from(bit(&clip) != ray);
            }
        }
        assert!(hidden * 20 > total, "the cases hide samples: {hidden} of {total}");
        // Only samples within rounding of a ray's grazing an edge differ from the rays (the
        // clipped polygon, whose edges may run nearly along the row, misses a few more).
        assert!(chord_off * 100_000 <= total, "{chord_off} of {total} samples differ from the rays");
        assert!(chord_off <= clip_off, "chord {chord_off}, clipped polygon {clip_off}");
    }

    #[test]
    fn a_box_said_not_to_hide_hides_no_clear_sample() {
        let mut s = 0x0bad_5eedu32;
        let mut r = move || {
            s = hash32(s.wrapping_add(0x9e37_79b9));
            (s >> 8) as f32 / 16_777_216.0
        };
        let (mut skipped, mut kept) = (0, 0);
        for case in 0..3000 {
            let shape = [LampShape::Segment, LampShape::Disc, LampShape::Sphere][case % 3];
            let l = Vec3f::new(0.0, 4.0, 0.0);
            let p = Vec3f::new(r() * 4.0 - 2.0, 0.0, r() * 4.0 - 2.0);
            let Some(f) = lamp_frame(shape, l, Vec3f::Y, 0.6, p) else { continue };
            let pat = LampPattern::new(shape, 144);
            let o = pixel_offset(case as u32, 7);
            // Some samples hidden already by one triangle, then a random box.
            let mut mask = [0u32; MASK_WORDS];
            let c0 = Vec3f::new(r() * 2.0 - 1.0, 1.0 + r() * 2.5, r() * 2.0 - 1.0);
            occlude(
                &f,
                &pat,
                o,
                &[0, 1, 2].map(|_| c0 + Vec3f::new(r() - 0.5, r() - 0.5, r() - 0.5) * 2.0),
                &mut mask,
            );
            let c = Vec3f::new(r() * 3.0 - 1.5, r() * 5.0, r() * 3.0 - 1.5);
            let e = Vec3f::new(r(), r(), r()) * 0.6;
            let (lo, hi) = (c - e, c + e);
            if f.box_may_hide(lo.to_array(), hi.to_array(), &pat, o, &mask) {
                kept += 1;
                continue;
            }
            skipped += 1;
            for _ in 0..20 {
                let mut pt = || lo + Vec3f::new(r() * 2.0 * e.x, r() * 2.0 * e.y, r() * 2.0 * e.z);
                let tri = [pt(), pt(), pt()];
                let mut m = mask;
                occlude(&f, &pat, o, &tri, &mut m);
                assert_eq!(m, mask, "case {case}: a triangle in a skipped box hid a clear sample");
            }
        }
        assert!(skipped > 300 && kept > 300, "{skipped} skipped, {kept} kept");
    }

    /// The segment's plane tests drop only what hides nothing: a triangle or box said to lie
    /// beside the plane through the receiver and the segment, or outside a tile's wedge, sets no
    /// sample in [`occlude`], for triangles anywhere and for triangles skimming the plane (within
    /// a few margins of it, far from the world's origin too); and they do drop most triangles.
    #[test]
    fn what_the_segment_planes_drop_hides_nothing() {
        let mut s = 0x5e6_3e47u32;
        let mut r = move || {
            s = hash32(s.wrapping_add(0x9e37_79b9));
            (s >> 8) as f32 / 16_777_216.0
        };
        let (mut dropped, mut kept, mut wedge_dropped, mut box_dropped) = (0, 0, 0, 0);
        for case in 0..6000 {
            // Far from the origin in a third of the cases (coordinates of about 1000).
            let shift = if case % 3 == 0 { Vec3f::new(1000.0, 20.0, -700.0) } else { Vec3f::ZERO };
            let l = Vec3f::new(0.0, 4.0, 0.0) + shift;
            let axis = Vec3f::new(r() - 0.5, 1.0, r() - 0.5).normalize_or(Vec3f::Y);
            // A tile of receivers: a few points close together.
            let base = Vec3f::new(r() * 4.0 - 2.0, r() * 0.5, r() * 4.0 - 2.0) + shift;
            let tile: Vec<Vec3f> =
                (0..4).map(|_| base + Vec3f::new(r() - 0.5, r() - 0.5, r() - 0.5) * 0.1).collect();
            let extent = 1010.0;
            let reach = tile.iter().flat_map(|p| [p.x, p.y, p.z]).fold(0.0f32, |m, v| m.max(v.abs()));
            let margin = segment_plane_margin(Vec3f::splat(reach), extent);
            let wedge = SegmentWedge::around(l, axis, &tile, margin);
            let pat = LampPattern::new(LampShape::Segment, 256);
            let c = Vec3f::new(r() * 2.0 - 1.0, 0.5 + r() * 3.0, r() * 2.0 - 1.0) + shift;
            let mut tri = [0, 1, 2].map(|_| c + Vec3f::new(r() - 0.5, r() - 0.5, r() - 0.5) * 1.2);
            for (k, &p) in tile.iter().enumerate() {
                let Some(f) = lamp_frame(LampShape::Segment, l, axis, 0.6, p) else { continue };
                let m = segment_plane_margin(p, extent);
                if case % 2 == 1 && k == 0 {
                    // Skim the plane: every corner a few margins from it, on one side.
                    for v in &mut tri {
                        let d = f.v.dot(*v - p);
                        *v += f.v * (-d + m * (1.5 + 3.0 * r()));
                    }
                }
                let o = pixel_offset(case as u32, k as u32);
                let mut mask = [0u32; MASK_WORDS];
                occlude(&f, &pat, o, &tri, &mut mask);
                let hides = mask.iter().any(|&w| w != 0);
                if f.beside_segment_plane(&tri, m) {
                    dropped += 1;
                    assert!(!hides, "case {case}: a triangle beside the plane hid a sample");
                } else {
                    kept += 1;
                }
                let (lo, hi) = (tri[0].min(tri[1]).min(tri[2]), tri[0].max(tri[1]).max(tri[2]));
                if f.box_beside_segment_plane(lo.to_array(), hi.to_array(), m) {
                    box_dropped += 1;
                    assert!(!hides, "case {case}: a triangle in a box beside the plane hid a sample");
                }
                if let Some(wg) = wedge {
                    if wg.misses(&tri) {
                        wedge_dropped += 1;
                        assert!(!hides, "case {case}: a triangle outside the wedge hid a sample");
                    }
                    if wg.misses_box(lo.to_array(), hi.to_array()) {
                        assert!(!hides, "case {case}: a triangle in a box outside the wedge hid a sample");
                    }
                }
            }
        }
        eprintln!("{dropped} dropped, {kept} kept, {wedge_dropped} outside wedges, {box_dropped} boxes");
        assert!(dropped > 2 * kept / 3 && kept > 2000, "{dropped} dropped, {kept} kept");
        assert!(
            wedge_dropped > 2000 && box_dropped > 2000,
            "{wedge_dropped} outside wedges, {box_dropped} boxes"
        );
    }

    #[test]
    fn row_weights_sum_to_one_and_visibility_spans_zero_to_one() {
        for s in [1, 2, 16, 100, 256, 1000, 1024] {
            for shape in [LampShape::Segment, LampShape::Disc] {
                let pat = LampPattern::new(shape, s);
                assert!(pat.samples() <= s && pat.samples() as usize <= MASK_WORDS * 32);
                let sum: f32 = (0..pat.rows).map(|j| pat.row_weight(j)).sum();
                assert!((sum - 1.0).abs() < 1e-5, "{s}: {sum}");
                let mut mask = [0u32; MASK_WORDS];
                assert_eq!(mask_visibility(&mask, &pat), 1.0_f32.min(sum));
                set_bits(&mut mask, 0, pat.samples());
                assert!(mask_full(&mask, &pat));
                assert_eq!(mask_visibility(&mask, &pat), 0.0);
            }
        }
    }

    #[test]
    fn lamp_cosine_is_the_cosine_away_from_the_horizon_and_continuous() {
        for s in [0.0f32, 0.05, 0.3, 0.7, 0.99, 1.0] {
            let mut prev = lamp_cosine(-1.0, s);
            for k in 0..=2000 {
                let m = -1.0 + k as f32 / 1000.0;
                let c = lamp_cosine(m, s);
                assert!(c.is_finite() && (0.0..=1.0).contains(&c));
                if m.abs() >= s + 1e-3 {
                    assert!((c - m.max(0.0)).abs() < 1e-4, "{s} {m}: {c}");
                }
                assert!((c - prev).abs() < 0.02, "{s} {m}: {prev} → {c}");
                prev = c;
                let t = lamp_toon_cosine(m, s);
                assert!(t.is_finite() && t >= m - 1e-6);
            }
            // A lamp straddling the horizon still lights a little past it.
            if s > 0.01 && s < 1.0 {
                assert!(lamp_cosine(0.0, s) > 0.0 && lamp_cosine(-0.5 * s, s) > 0.0);
            }
        }
        assert_eq!(lamp_cosine(f32::NAN, 0.5), 0.0);
    }

    #[test]
    fn the_sphere_outline_and_degenerate_frames() {
        let l = Vec3f::new(0.0, 2.0, 0.0);
        assert!(lamp_frame(LampShape::Sphere, l, Vec3f::Y, 0.5, l + Vec3f::X * 0.2).is_none());
        assert!(lamp_frame(LampShape::Segment, l, Vec3f::Y, 0.5, Vec3f::ZERO).is_none());
        assert!(lamp_frame(LampShape::Disc, l, Vec3f::Y, 0.5, l + Vec3f::X).is_none());
        let f = lamp_frame(LampShape::Sphere, l, Vec3f::Y, 0.5, Vec3f::ZERO).unwrap();
        // Tangent rays from the origin touch the outline's rim.
        let rim = f.centre + f.u * f.radius;
        let dir = (rim - f.origin).normalize_or(Vec3f::ZERO);
        let closest = f.origin + dir * (l - f.origin).dot(dir);
        assert!(((closest - l).length() - 0.5).abs() < 1e-5);
    }
}
