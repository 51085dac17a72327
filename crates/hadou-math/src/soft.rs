//! The maths of 003's soft shadows (SPEC.md §4): the two shadow-map positions, the penumbra's
//! brightness from the distances to the nearest umbra and lit pixels (with SPEC's corrected
//! ratio), standard bilinear interpolation of a coarse grid (SPEC's corrected weights), and the
//! exact Euclidean distance transform that gives every pixel those distances in linear time.

use crate::Vec3f;

/// The two shadow-map positions of 003 §4.1: with `P = (L − G)/|L − G|` (unit, from the point of
/// interest `G` towards the light centre `L`), `L₁ = L + l·P` and `L₂ = L − l·P`. `None` when
/// `L = G` (no direction).
pub fn light_pair(light: Vec3f, interest: Vec3f, l: f32) -> Option<(Vec3f, Vec3f)> {
    let p = (light - interest).try_normalize()?;
    Some((light + p * l, light - p * l))
}

/// A penumbra pixel's brightness from its distance `d1` to the nearest umbra pixel and `d2` to the
/// nearest lit pixel (SPEC.md §4.2): `d1 / (d1 + d2)`, 0 at the umbra's edge and 1 at the lit
/// edge. *Correction:* 003 prints `D₂/(D₁+D₂)`, which contradicts its own statement that pixels
/// near the umbra are darker. Both distances 0 (or not finite) give ½, never NaN.
#[inline]
pub fn penumbra_brightness(d1: f32, d2: f32) -> f32 {
    let s = d1 + d2;
    if s > 0.0 && s.is_finite() {
        (d1 / s).clamp(0.0, 1.0)
    } else if d1.is_infinite() && !d2.is_infinite() {
        1.0
    } else if d2.is_infinite() && !d1.is_infinite() {
        0.0
    } else {
        0.5
    }
}

/// hadou's penumbra brightness (SPEC.md §4.2 as corrected, made perspective-correct): the fraction
/// of the segment light `L₁L₂` that a penumbra pixel sees, `k·D₁/(k·D₁ + D₂)` with
/// `k = A₁/A₂` ([`segment_ratio`]).
///
/// The two maps sample a light spread along the axis from `L₁` (axial distance `A₁ = A + l` from
/// an occluder edge) to `L₂` (`A₂ = A − l`). A point light at axial distance `a` throws that edge's
/// shadow `∝ 1/a` beyond the edge on a receiver, so the shadows of the lights between `L₁` and
/// `L₂` are spaced evenly in `1/a`, not in image distance: at the fraction `s = D₁/(D₁ + D₂)` of
/// the band from the umbra's edge (`L₁`'s shadow edge) lies the edge of the light at
/// `1/a = 1/A₁ + s·(1/A₂ − 1/A₁)`, and the pixel sees the lights farther than that, the fraction
/// `(A₁ − a)/(A₁ − A₂) = k·s/(1 + (k − 1)·s) = k·D₁/(k·D₁ + D₂)` of the segment. `k = 1` (a light
/// far from its occluders) is 003's linear ratio [`penumbra_brightness`] bit for bit. 0 at the
/// umbra's edge, 1 at the lit edge, never NaN.
#[inline]
pub fn segment_brightness(d1: f32, d2: f32, k: f32) -> f32 {
    penumbra_brightness(k * d1, d2)
}

/// The ratio `k = A₁/A₂ = (D + l)/(D − l)` of [`segment_brightness`]: the distances of the two map
/// positions `L ± l·P` from an occluder at the point of interest, `D = |L − G|` and `l` the light's
/// size parameter. 1 where `l ≤ 0` or `D` is infinite, at most `10⁶` (`l` near or past `D`),
/// never NaN.
#[inline]
pub fn segment_ratio(l: f32, d: f32) -> f32 {
    if l.is_nan() || l <= 0.0 || !d.is_finite() {
        return 1.0;
    }
    if d <= l {
        return 1e6;
    }
    ((d + l) / (d - l)).clamp(1.0, 1e6)
}

/// Standard bilinear interpolation of the four grid values around a pixel (SPEC.md §4.3), `fx`,
/// `fy ∈ [0, 1]` its offsets from the top-left grid pixel in grid cells:
/// `(1−fx)(1−fy)·v00 + fx(1−fy)·v10 + (1−fx)fy·v01 + fx·fy·v11`. *Correction:* 003's eq. 3.6 gives
/// the first corner the weight `Q·dx` where bilinear interpolation has `1 − Q·dx`.
#[inline]
pub fn bilinear(v00: f32, v10: f32, v01: f32, v11: f32, fx: f32, fy: f32) -> f32 {
    let top = v00 + (v10 - v00) * fx;
    let bottom = v01 + (v11 - v01) * fx;
    top + (bottom - top) * fy
}

/// Squared distance standing for "no feature pixel at all" in [`distance_transform`].
pub const FAR: f32 = f32::INFINITY;

/// The exact squared Euclidean distance transform of a `width × height` image (row-major): for
/// every pixel, the squared distance in pixels to the nearest pixel where `feature` is true, or
/// [`FAR`] if there is none. Felzenszwalb and Huttenlocher's separable lower-envelope algorithm
/// (2012): one pass over columns, one over rows, `O(width · height)`. The envelope is computed in
/// `f64`; the results are integers, exact in `f32` up to 2²⁴ (a distance of 4096 pixels).
pub fn distance_transform(feature: &[bool], width: usize, height: usize) -> Vec<f32> {
    assert_eq!(feature.len(), width * height, "mask size");
    let mut d: Vec<f32> = feature.iter().map(|&f| if f { 0.0 } else { FAR }).collect();
    let n = width.max(height);
    let mut scratch = Envelope::new(n);
    let mut line = vec![0.0f32; n];
    let mut out = vec![0.0f32; n];
    let mut arg = vec![0u32; n];
    // Columns.
    for x in 0..width {
        for y in 0..height {
            line[y] = d[y * width + x];
        }
        scratch.transform(&line[..height], &mut out[..height], &mut arg[..height]);
        for y in 0..height {
            d[y * width + x] = out[y];
        }
    }
    // Rows.
    for y in 0..height {
        let row = &mut d[y * width..(y + 1) * width];
        line[..width].copy_from_slice(row);
        scratch.transform(&line[..width], &mut out[..width], &mut arg[..width]);
        row.copy_from_slice(&out[..width]);
    }
    d
}

/// Work space of the 1-D squared distance transform (Felzenszwalb–Huttenlocher): the parabolas of
/// the lower envelope and their boundaries. One per thread; [`Envelope::transform`] is the step
/// both passes of [`distance_transform`] make, public so a renderer can run the lines in parallel.
///
/// The boundaries are kept as exact fractions `num/den` (`den > 0`; `den = 0` stands for `±∞` by
/// the sign of `num`) and compared by cross-multiplying in `i64`: no division, no rounding, so the
/// envelope is exact for integer inputs.
#[derive(Clone, Debug)]
pub struct Envelope {
    v: Vec<usize>,
    z: Vec<(i64, i64)>,
}

/// `a/b ≤ c/d` for fractions with `b, d ≥ 0` (`0` denominators are `±∞` by the numerator's sign).
#[inline]
fn frac_le(a: i64, b: i64, c: i64, d: i64) -> bool {
    match (b, d) {
        (0, 0) => a <= c,
        (0, _) => a < 0,
        (_, 0) => c > 0,
        _ => a * d <= c * b,
    }
}

impl Envelope {
    /// Work space for lines of up to `n` samples.
    pub fn new(n: usize) -> Self {
        Envelope { v: vec![0; n.max(1)], z: vec![(0, 1); n.max(1) + 1] }
    }

    /// `out[q] = min_p (q − p)² + f[p]` over `p` with `f[p] ≠` [`FAR`] ([`FAR`] if none), and
    /// `arg[q]` = that `p` (the lowest-index parabola of the envelope at `q`; `u32::MAX` if none).
    /// The finite `f[p]` must be integers (squared distances in pixels), below 2⁴⁰. Lines longer
    /// than [`Envelope::new`]'s `n` grow the work space.
    pub fn transform(&mut self, f: &[f32], out: &mut [f32], arg: &mut [u32]) {
        let n = f.len();
        if self.v.len() < n {
            *self = Envelope::new(n);
        }
        let mut k: usize = 0;
        let mut any = false;
        for q in 0..n {
            if f[q] == FAR {
                continue;
            }
            if !any {
                any = true;
                self.v[0] = q;
                self.z[0] = (-1, 0);
                self.z[1] = (1, 0);
                k = 0;
                continue;
            }
            // Drop the envelope's parabolas the one at q hides (z[0] = −∞ stops the loop at the
            // first). The parabolas from p and q meet at s = (F_q − F_p) / (2(q − p)), F = f + x².
            let fq = f[q] as i64 + (q * q) as i64;
            let (mut sn, mut sd);
            loop {
                let p = self.v[k];
                sn = fq - (f[p] as i64 + (p * p) as i64);
                sd = 2 * (q - p) as i64;
                let (zn, zd) = self.z[k];
                if frac_le(sn, sd, zn, zd) {
                    k -= 1;
                } else {
                    break;
                }
            }
            k += 1;
            self.v[k] = q;
            self.z[k] = (sn, sd);
            self.z[k + 1] = (1, 0);
        }
        if !any {
            out.iter_mut().for_each(|o| *o = FAR);
            arg.iter_mut().for_each(|a| *a = u32::MAX);
            return;
        }
        let mut j = 0;
        for (q, (o, a)) in out.iter_mut().zip(arg.iter_mut()).enumerate() {
            // z[j + 1] < q.
            while {
                let (zn, zd) = self.z[j + 1];
                !frac_le(q as i64, 1, zn, zd)
            } {
                j += 1;
            }
            let p = self.v[j];
            let dq = q as f32 - p as f32;
            *o = dq * dq + f[p];
            *a = p as u32;
        }
    }
}

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

/// Shadow-map bias in texels at the point's depth (see [`SpotMap::texel`]): a stored depth counts
/// as an occluder when it is nearer than the point by more than this many texel widths.
pub const BIAS_TEXELS: f32 = 1.5;

/// The perspective frame of one of 003's shadow maps: from a light position `eye` towards the
/// point of interest, a square frustum of half-angle `atan(tan_half)` wide enough for every
/// object ([`SpotMap::look`]), or narrowed to what can be shadowed in view ([`SpotMap::fitted`]:
/// an off-axis frustum, its centre sheared into `right` and `up`). Map coordinates `s, t ∈ [0, 1]`
/// (right, up) and the view depth `z` (distance along `forward`); texel `(x, y)` of a `size²` map
/// covers `s ∈ [x/size, (x+1)/size)`, `1 − t ∈ [y/size, (y+1)/size)` (row 0 at `t = 1`, as the
/// hard shadows' maps).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotMap {
    /// The map's light position (`L₁` or `L₂`).
    pub eye: Vec3f,
    /// Unit axis towards the point of interest.
    pub forward: Vec3f,
    /// Right: the unit right `r̂` of [`SpotMap::look`], `r̂ − c_x·forward` for a frustum centred
    /// on `x/z = c_x` ([`SpotMap::fitted`]), so that [`SpotMap::to_view`]'s `x` is `0` on the
    /// frustum's centre line.
    pub right: Vec3f,
    /// Up: the unit up `û`, `û − c_y·forward` for a frustum centred on `y/z = c_y`.
    pub up: Vec3f,
    /// `tan` of the frustum's half-angle.
    pub tan_half: f32,
    /// Near plane distance (triangles are clipped there).
    pub near: f32,
}

/// Widest half-angle of a [`SpotMap`]'s frustum (`tan 80°`).
pub const SPOT_MAX_TAN: f32 = 5.671_282;

impl SpotMap {
    /// A map at `eye` looking at `target`, its frustum enclosing `corners` (world points, e.g. the
    /// objects' bounding boxes) up to [`SPOT_MAX_TAN`]; the near plane at `10⁻³·|target − eye|`.
    pub fn look(eye: Vec3f, target: Vec3f, corners: &[Vec3f]) -> Self {
        let dist = (target - eye).length();
        let forward = (target - eye).normalize_or(-Vec3f::Y);
        let helper = if forward.y.abs() < 0.99 { Vec3f::Y } else { Vec3f::X };
        let right = forward.cross(helper).normalize_or(forward.orthonormal_basis().0);
        let up = right.cross(forward);
        let near = (1e-3 * dist).max(1e-5);
        let mut tan_half: f32 = SPOT_MIN_TAN;
        for &c in corners {
            let d = c - eye;
            let z = d.dot(forward);
            let lateral = d.dot(right).abs().max(d.dot(up).abs());
            let t = if z > near { lateral / z } else { SPOT_MAX_TAN };
            if t.is_finite() {
                tan_half = tan_half.max(t);
            } else {
                tan_half = SPOT_MAX_TAN;
            }
        }
        SpotMap { eye, forward, right, up, tan_half: (tan_half * 1.02).min(SPOT_MAX_TAN), near }
    }

    /// View coordinates `(x, y, z)` of `p`: right, up (from the frustum's centre line), along the
    /// axis.
    #[inline]
    pub fn to_view(&self, p: Vec3f) -> Vec3f {
        let d = p - self.eye;
        Vec3f::new(d.dot(self.right), d.dot(self.up), d.dot(self.forward))
    }

    /// World width of one texel of a `size²` map at view depth `z`.
    #[inline]
    pub fn texel(&self, z: f32, size: u32) -> f32 {
        2.0 * self.tan_half * z / size as f32
    }

    /// Where a receiver point `p` with unit normal `n` looks the map up: `None` when `p` faces away
    /// from the map's light (`n·(eye − p) ≤ 0`: it shades itself, as an opaque closed surface
    /// would), else `Some((x, y, z))`, the texel and the depth to compare after moving `p` one
    /// texel along `n` (normal-offset bias); `x` or `y` outside `0..size` when the point is outside
    /// the frustum (no occluder there), and `z ≤ near` likewise.
    #[inline]
    pub fn lookup(&self, p: Vec3f, n: Vec3f, size: u32) -> Option<(i64, i64, f32)> {
        if n.dot(self.eye - p) <= 0.0 {
            return None;
        }
        let v0 = self.to_view(p);
        let off = self.texel(v0.z.abs(), size);
        let v = v0 + Vec3f::new(n.dot(self.right), n.dot(self.up), n.dot(self.forward)) * off;
        if v.z.is_nan() || v.z <= self.near {
            return Some((-1, -1, v.z));
        }
        let sz = size as f32;
        let s = (v.x / (v.z * self.tan_half) + 1.0) * 0.5;
        let t = (v.y / (v.z * self.tan_half) + 1.0) * 0.5;
        let (fx, fy) = (s * sz, (1.0 - t) * sz);
        // `⌊fx⌋ ∈ 0..size` exactly when `0 ≤ fx < size` (false for NaN), and then `⌊fx⌋` is the
        // truncation: no call to `floor`.
        if !(fx >= 0.0 && fx < sz && fy >= 0.0 && fy < sz) {
            return Some((-1, -1, v.z));
        }
        Some((fx as i64, fy as i64, v.z))
    }

    /// Whether a map value `stored` (view depth of the nearest caster in the texel) hides a point
    /// at view depth `z`: nearer by more than [`BIAS_TEXELS`] texels.
    #[inline]
    pub fn occludes(&self, stored: f32, z: f32, size: u32) -> bool {
        stored < z - BIAS_TEXELS * self.texel(z, size)
    }

    /// Where the point `p` lies on the plane of this (unsheared, [`SpotMap::look`]) map's
    /// frustum, `(x/z, y/z)` clamped to `±tan_half`; `None` when `z ≤ near` (the map cannot shadow
    /// it). What [`SpotMap::fitted`]'s window is the bounds of.
    #[inline]
    pub fn fit_coords(&self, p: Vec3f) -> Option<[f32; 2]> {
        let v = self.to_view(p);
        if v.z.is_nan() || v.z <= self.near {
            return None;
        }
        let t = self.tan_half;
        Some([(v.x / v.z).clamp(-t, t), (v.y / v.z).clamp(-t, t)])
    }

    /// This map (from [`SpotMap::look`]) narrowed to the window `lo..=hi` of
    /// [`SpotMap::fit_coords`] (the bounds of the points that need the map, [`FitWindow`]): an
    /// off-axis square frustum centred on the window, `c = (lo + hi)/2`, `right − c_x·forward`
    /// and `up − c_y·forward` as its axes, its half-width the window's larger half-extent `h`
    /// widened to `1.02·h/(1 − 4/size)` so that a point on the window's edge, moved one texel
    /// along its normal by [`SpotMap::lookup`], stays inside. An empty window (nothing in view can
    /// be shadowed) gives the narrowest frustum around the axis, every point outside it lit; a
    /// fitted frustum not narrower than [`FIT_GAIN`] times this map's, or a map of fewer than 16
    /// texels, keeps this map.
    pub fn fitted(&self, window: &FitWindow, size: u32) -> SpotMap {
        if size < 16 {
            return *self;
        }
        let Some((lo, hi)) = window.bounds() else {
            return SpotMap { tan_half: SPOT_MIN_TAN, ..*self };
        };
        let c = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
        let h = (0.5 * (hi[0] - lo[0])).max(0.5 * (hi[1] - lo[1]));
        let half = (1.02 * h / (1.0 - 4.0 / size as f32)).max(SPOT_MIN_TAN);
        if half.is_nan() || half > FIT_GAIN * self.tan_half || !c[0].is_finite() || !c[1].is_finite() {
            return *self;
        }
        SpotMap {
            right: self.right - self.forward * c[0],
            up: self.up - self.forward * c[1],
            tan_half: half,
            ..*self
        }
    }
}

/// Largest ratio of a fitted map's half-angle (`tan`) to the unfitted one's for
/// [`SpotMap::fitted`] to narrow the map: a window that already fills most of 003's frustum
/// (every caster in view, as in most scenes) would buy little resolution for the extra texels the
/// casters then cover, and keeping 003's frustum there leaves those scenes' maps as they were.
pub const FIT_GAIN: f32 = 0.5;

/// How far short of a point a caster's bounding box must begin on the segment from a map's light
/// to the point, as a fraction of the segment, to count as able to shadow it ([`CasterBox::blocks`]):
/// a box that the segment only enters at the point itself (the point lies on the box's face, e.g.
/// the lit face of a wall) cannot shadow it beyond the depth bias.
pub const FIT_MARGIN: f32 = 1e-4;

/// Narrowest half-angle of a [`SpotMap`]'s frustum (`tan`), also the frustum of a map that no
/// point in view needs.
pub const SPOT_MIN_TAN: f32 = 1e-3;

/// A caster's bounding box as it stands in the world (its local box under its transform, a
/// parallelepiped): the corner `origin` and the dual vectors `dual[i]` of its three edges `e_i`
/// (`dual[i]·e_j = δ_ij`), so that a point's box coordinates `dual[i]·(q − origin)` lie in `[0, 1]`
/// inside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CasterBox {
    /// The corner at the local bounds' minimum.
    pub origin: Vec3f,
    /// The edges `e_i` from it.
    pub edges: [Vec3f; 3],
    /// `(e_j × e_k)/(e_i·(e_j × e_k))` for `(i, j, k)` cyclic.
    pub dual: [Vec3f; 3],
}

impl CasterBox {
    /// The box with corner `origin` and edges `edges`; `None` when they span no volume (or are
    /// not finite).
    pub fn from_edges(origin: Vec3f, edges: [Vec3f; 3]) -> Option<Self> {
        let [a, b, c] = edges;
        let det = a.dot(b.cross(c));
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let dual = [b.cross(c) / det, c.cross(a) / det, a.cross(b) / det];
        let ok = dual.iter().all(|d| d.x.is_finite() && d.y.is_finite() && d.z.is_finite());
        (ok && origin.x.is_finite() && origin.y.is_finite() && origin.z.is_finite()).then_some(CasterBox {
            origin,
            edges,
            dual,
        })
    }

    /// The box coordinates of `q` (`[0, 1]³` inside).
    #[inline]
    pub fn local(&self, q: Vec3f) -> [f32; 3] {
        let d = q - self.origin;
        [d.dot(self.dual[0]), d.dot(self.dual[1]), d.dot(self.dual[2])]
    }

    /// Whether the segment from a map's light `eye` to the point `p` meets the box before
    /// `1 − `[`FIT_MARGIN`] of its length: only then can the caster shadow `p` in that map (any
    /// occluder of `p` lies on that segment, 003 §4.1's shadow test, nearer than `p` by the bias).
    /// A slab test in box coordinates; an axis along which the segment moves less than `10⁻⁷` box
    /// widths counts as parallel (met when its coordinate is inside).
    #[inline]
    pub fn blocks(&self, eye: Vec3f, p: Vec3f) -> bool {
        CasterBox::blocks_local(self.local(eye), self.local(p))
    }

    /// [`CasterBox::blocks`] with the box coordinates `a` of the light and `b` of the point.
    #[inline]
    pub fn blocks_local(a: [f32; 3], b: [f32; 3]) -> bool {
        let (mut t0, mut t1) = (0.0f32, 1.0 - FIT_MARGIN);
        for i in 0..3 {
            let d = b[i] - a[i];
            if d.abs() < 1e-7 {
                if !(a[i] >= 0.0 && a[i] <= 1.0) {
                    return false;
                }
            } else {
                let (ta, tb) = (-a[i] / d, (1.0 - a[i]) / d);
                t0 = t0.max(ta.min(tb));
                t1 = t1.min(ta.max(tb));
            }
        }
        t0 <= t1
    }
}

/// [`FitWindow::add_point`] for one map and its casters' boxes, prepared so that most points
/// cost a projection and a comparison: a point inside the window already gathered changes
/// nothing, and a box can only lie in front of a point inside its own projection on the map's
/// plane (the rectangle of its corners' [`SpotMap::fit_coords`], widened by `10⁻⁴·(1 + |c|)`
/// against rounding; unbounded when a corner lies at or behind the near plane). Gives the same
/// window as [`FitWindow::add_point`] (tested).
#[derive(Clone, Debug)]
pub struct FitTest {
    map: SpotMap,
    /// Per box: the box, the light's box coordinates, its rectangle (`None`: unbounded).
    boxes: Vec<(CasterBox, [f32; 3], Option<Rect>)>,
}

/// A rectangle `(lo, hi)` on a map's plane.
type Rect = ([f32; 2], [f32; 2]);

impl FitTest {
    /// The test of `map` (unfitted) against `boxes`.
    pub fn new(map: &SpotMap, boxes: &[CasterBox]) -> Self {
        let boxes = boxes
            .iter()
            .map(|b| {
                let mut rect = Some(([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]));
                for i in 0..8 {
                    let u = |k: usize| if i >> k & 1 == 1 { 1.0 } else { 0.0 };
                    let corner = b.origin + b.edges[0] * u(0) + b.edges[1] * u(1) + b.edges[2] * u(2);
                    let v = map.to_view(corner);
                    match (rect.as_mut(), v.z > map.near && v.z.is_finite()) {
                        (Some((lo, hi)), true) => {
                            for (k, c) in [v.x / v.z, v.y / v.z].into_iter().enumerate() {
                                let pad = 1e-4 * (1.0 + c.abs());
                                lo[k] = lo[k].min(c - pad);
                                hi[k] = hi[k].max(c + pad);
                            }
                        }
                        _ => rect = None,
                    }
                }
                let rect = rect.filter(|(lo, hi)| lo.iter().chain(hi).all(|v| v.is_finite()));
                (*b, b.local(map.eye), rect)
            })
            .collect();
        FitTest { map: *map, boxes }
    }

    /// Adds `p` to `window` as [`FitWindow::add_point`] does.
    #[inline]
    pub fn add(&self, window: &mut FitWindow, p: Vec3f) {
        let v = self.map.to_view(p);
        if v.z.is_nan() || v.z <= self.map.near {
            return;
        }
        // Without a division: well inside the window gathered so far (shrunk by 10⁻⁵·(1 + |b|)
        // against rounding) changes nothing; outside every box's rectangle, no box blocks.
        let within = |lo: [f32; 2], hi: [f32; 2]| {
            lo[0] * v.z <= v.x && v.x <= hi[0] * v.z && lo[1] * v.z <= v.y && v.y <= hi[1] * v.z
        };
        if let Some((lo, hi)) = window.bounds() {
            let shrink = |b: f32| 1e-5 * (1.0 + b.abs());
            let lo = lo.map(|b| b + shrink(b));
            let hi = hi.map(|b| b - shrink(b));
            if within(lo, hi) {
                return;
            }
        }
        if !self.boxes.iter().any(|(_, _, r)| r.is_none_or(|(lo, hi)| within(lo, hi))) {
            return;
        }
        let Some(c) = self.map.fit_coords(p) else { return };
        let k = [FitWindow::key(c[0]), FitWindow::key(c[1])];
        if (0..2).all(|i| window.min[i] <= k[i] && k[i] <= window.max[i]) {
            return;
        }
        let inside = |r: &Option<Rect>| {
            r.is_none_or(|(lo, hi)| lo[0] <= c[0] && c[0] <= hi[0] && lo[1] <= c[1] && c[1] <= hi[1])
        };
        if self.boxes.iter().any(|(b, a, r)| inside(r) && CasterBox::blocks_local(*a, b.local(p))) {
            window.add(c);
        }
    }
}

/// The window of [`SpotMap::fit_coords`] that a map must cover: the bounds of the visible points
/// that some caster's box lies in front of ([`CasterBox::blocks`]). Every other visible point is
/// lit in that map whatever it holds, so a map fitted to the window ([`SpotMap::fitted`]) gives
/// every visible point the verdict the full map would, with its texels spent where shadows fall.
/// Kept as order-preserving integer keys so that the GPU's atomic minima and maxima give the same
/// window ([`FitWindow::key`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FitWindow {
    /// Keys of the least `x/z` and `y/z`.
    pub min: [u32; 2],
    /// Keys of the greatest.
    pub max: [u32; 2],
}

impl Default for FitWindow {
    fn default() -> Self {
        FitWindow::EMPTY
    }
}

impl FitWindow {
    /// No point.
    pub const EMPTY: FitWindow = FitWindow { min: [u32::MAX; 2], max: [0; 2] };

    /// The order-preserving key of a finite `f32` (`a < b ⇔ key(a) < key(b)`): the bits with the
    /// sign bit set for non-negative values, all bits flipped for negative ones.
    #[inline]
    pub fn key(v: f32) -> u32 {
        let b = v.to_bits();
        if b & 0x8000_0000 != 0 {
            !b
        } else {
            b | 0x8000_0000
        }
    }

    /// The `f32` of a [`FitWindow::key`].
    #[inline]
    pub fn value(k: u32) -> f32 {
        if k & 0x8000_0000 != 0 {
            f32::from_bits(k & 0x7fff_ffff)
        } else {
            f32::from_bits(!k)
        }
    }

    /// Adds the point at `c` (from [`SpotMap::fit_coords`]).
    #[inline]
    pub fn add(&mut self, c: [f32; 2]) {
        for (i, &v) in c.iter().enumerate() {
            let k = FitWindow::key(v);
            self.min[i] = self.min[i].min(k);
            self.max[i] = self.max[i].max(k);
        }
    }

    /// Both windows' points.
    #[inline]
    pub fn union(self, o: FitWindow) -> FitWindow {
        FitWindow {
            min: [self.min[0].min(o.min[0]), self.min[1].min(o.min[1])],
            max: [self.max[0].max(o.max[0]), self.max[1].max(o.max[1])],
        }
    }

    /// `(lo, hi)` in `x/z, y/z`, `None` when no point was added.
    pub fn bounds(&self) -> Option<([f32; 2], [f32; 2])> {
        if self.min[0] > self.max[0] || self.min[1] > self.max[1] {
            return None;
        }
        let v = FitWindow::value;
        Some(([v(self.min[0]), v(self.min[1])], [v(self.max[0]), v(self.max[1])]))
    }

    /// Adds `p` when a caster in `boxes` can shadow it in `map` ([`CasterBox::blocks`]) and the
    /// map can see it ([`SpotMap::fit_coords`]).
    #[inline]
    pub fn add_point(&mut self, map: &SpotMap, boxes: &[CasterBox], p: Vec3f) {
        if boxes.iter().any(|b| b.blocks(map.eye, p)) {
            if let Some(c) = map.fit_coords(p) {
                self.add(c);
            }
        }
    }
}

/// A pixel's class under 003 §4.1: shadowed in both maps, in one, or in neither.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Class {
    /// No visible surface (background, outline hull): neither classified nor searched for.
    None = 0,
    /// Shadowed in both maps.
    Umbra = 1,
    /// Shadowed in exactly one.
    Penumbra = 2,
    /// Shadowed in neither.
    Lit = 3,
}

impl Class {
    /// The class from the two maps' verdicts.
    #[inline]
    pub fn of(shadowed1: bool, shadowed2: bool) -> Class {
        match (shadowed1, shadowed2) {
            (true, true) => Class::Umbra,
            (false, false) => Class::Lit,
            _ => Class::Penumbra,
        }
    }
}

/// Radius of the disc light whose penumbra has the width of 003's two-map band at an occluder
/// edge: with the maps at `D ∓ l` on the axis and the edge at lateral offset `r` and axial
/// distance `D`, a receiver at `D_r` sees the edge's two shadows `2·l·r·(D_r − D)/(D² − l²)` apart,
/// the width a disc of radius `R` gives is `2·R·(D_r − D)/D`, so `R = l·r·D/(D² − l²)`. The
/// ground truth of `hadou bench shadows` uses it with `r` the point of interest's bounding radius.
pub fn implied_disc_radius(l: f32, r: f32, d: f32) -> f32 {
    let den = d * d - l * l;
    if den > 0.0 {
        l * r * d / den
    } else {
        l
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: the nearest feature pixel by trying them all.
    fn brute(feature: &[bool], w: usize, h: usize) -> Vec<f32> {
        (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as i64, (i / w) as i64);
                feature
                    .iter()
                    .enumerate()
                    .filter(|(_, &f)| f)
                    .map(|(j, _)| {
                        let (u, v) = ((j % w) as i64, (j / w) as i64);
                        ((x - u).pow(2) + (y - v).pow(2)) as f32
                    })
                    .fold(FAR, f32::min)
            })
            .collect()
    }

    #[test]
    fn distance_transform_is_exact_on_random_masks() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for case in 0..60 {
            let (w, h) = (1 + (next() % 23) as usize, 1 + (next() % 19) as usize);
            let density = [1u64, 5, 30, 90][case % 4];
            let mask: Vec<bool> = (0..w * h).map(|_| next() % 100 < density).collect();
            assert_eq!(distance_transform(&mask, w, h), brute(&mask, w, h), "case {case}: {w}×{h}");
        }
    }

    #[test]
    fn empty_and_full_masks() {
        assert!(distance_transform(&[false; 12], 4, 3).iter().all(|&d| d == FAR));
        assert!(distance_transform(&[true; 12], 4, 3).iter().all(|&d| d == 0.0));
    }

    #[test]
    fn brightness_runs_dark_to_light_and_never_nan() {
        assert_eq!(penumbra_brightness(0.0, 5.0), 0.0);
        assert_eq!(penumbra_brightness(5.0, 0.0), 1.0);
        assert_eq!(penumbra_brightness(1.0, 3.0), 0.25);
        assert_eq!(penumbra_brightness(0.0, 0.0), 0.5);
        assert_eq!(penumbra_brightness(f32::INFINITY, 2.0), 1.0);
        assert_eq!(penumbra_brightness(2.0, f32::INFINITY), 0.0);
        assert_eq!(penumbra_brightness(f32::INFINITY, f32::INFINITY), 0.5);
    }

    #[test]
    fn bilinear_weights_are_the_standard_ones() {
        assert_eq!(bilinear(1.0, 2.0, 3.0, 4.0, 0.0, 0.0), 1.0);
        assert_eq!(bilinear(1.0, 2.0, 3.0, 4.0, 1.0, 0.0), 2.0);
        assert_eq!(bilinear(1.0, 2.0, 3.0, 4.0, 0.0, 1.0), 3.0);
        assert_eq!(bilinear(1.0, 2.0, 3.0, 4.0, 1.0, 1.0), 4.0);
        assert_eq!(bilinear(0.0, 4.0, 0.0, 4.0, 0.25, 0.7), 1.0);
    }

    #[test]
    fn light_pair_straddles_the_light_along_g_to_l() {
        let (l1, l2) = light_pair(Vec3f::new(0.0, 4.0, 0.0), Vec3f::ZERO, 0.5).unwrap();
        assert_eq!(l1, Vec3f::new(0.0, 4.5, 0.0));
        assert_eq!(l2, Vec3f::new(0.0, 3.5, 0.0));
        assert!(light_pair(Vec3f::ZERO, Vec3f::ZERO, 1.0).is_none());
    }

    #[test]
    fn envelope_argmin_is_a_nearest_feature() {
        let f = [FAR, 0.0, FAR, FAR, 4.0, FAR, 0.0, FAR];
        let (mut out, mut arg) = ([0.0f32; 8], [0u32; 8]);
        Envelope::new(8).transform(&f, &mut out, &mut arg);
        for q in 0..8 {
            let best = (0..8)
                .filter(|&p| f[p] != FAR)
                .map(|p| (q as f32 - p as f32).powi(2) + f[p])
                .fold(FAR, f32::min);
            assert_eq!(out[q], best, "q = {q}");
            let p = arg[q] as usize;
            assert_eq!((q as f32 - p as f32).powi(2) + f[p], best, "q = {q}: argmin {p}");
        }
        let mut none = [0u32; 3];
        Envelope::new(1).transform(&[FAR; 3], &mut [0.0; 3], &mut none);
        assert_eq!(none, [u32::MAX; 3]);
    }

    #[test]
    fn spot_map_encloses_the_corners_and_biases_by_texels() {
        let corners = [Vec3f::new(-4.0, 0.0, -4.0), Vec3f::new(4.0, 0.0, 4.0), Vec3f::new(4.0, 2.0, -4.0)];
        let m = SpotMap::look(Vec3f::new(0.0, 6.0, 0.0), Vec3f::ZERO, &corners);
        for c in corners {
            let v = m.to_view(c);
            assert!(v.x.abs() <= v.z * m.tan_half && v.y.abs() <= v.z * m.tan_half, "{v:?}");
        }
        // A floor point facing the light looks up a texel inside the map; the underside does not.
        let (x, y, z) = m.lookup(Vec3f::new(1.0, 0.0, 1.0), Vec3f::Y, 512).unwrap();
        assert!((0..512).contains(&x) && (0..512).contains(&y) && z > 5.9, "{x} {y} {z}");
        assert!(m.lookup(Vec3f::new(1.0, 0.0, 1.0), -Vec3f::Y, 512).is_none());
        // Within the bias a surface does not shadow itself; a caster a metre nearer does.
        assert!(!m.occludes(z - 0.5 * m.texel(z, 512), z, 512));
        assert!(m.occludes(z - 1.0, z, 512));
        // A light inside the objects' bounds takes the widest frustum.
        let wide = SpotMap::look(Vec3f::new(0.0, 1.0, 0.0), Vec3f::ZERO, &corners);
        assert_eq!(wide.tan_half, SPOT_MAX_TAN);
    }

    #[test]
    fn segment_brightness_is_the_visible_fraction_of_the_segment_light() {
        // Lights spread evenly along the axis from A₁ = 5 to A₂ = 3 (D = 4, l = 1): each throws an
        // edge's shadow at 1/a; a receiver point at image fraction s of the band between the
        // shadows of L₁ and L₂ sees exactly the lights whose shadow edge lies short of it.
        let (d, l) = (4.0f64, 1.0f64);
        let k = segment_ratio(l as f32, d as f32);
        assert!((f64::from(k) - 5.0 / 3.0).abs() < 1e-6);
        for j in 0..=20 {
            let s = j as f64 / 20.0;
            let x = 1.0 / (d + l) + s * (1.0 / (d - l) - 1.0 / (d + l));
            let m = 200_000;
            let seen = (0..m)
                .filter(|&i| {
                    let a = (d + l) - (i as f64 + 0.5) / m as f64 * 2.0 * l;
                    1.0 / a < x
                })
                .count() as f64
                / m as f64;
            let got = f64::from(segment_brightness(s as f32, (1.0 - s) as f32, k));
            assert!((got - seen).abs() < 2e-5, "s = {s}: {got} against {seen}");
        }
        // k = 1 is 003's ratio bit for bit; the ends and the degenerate cases stay finite.
        for (d1, d2) in [(0.0, 0.0), (1.0, 3.0), (2.5, 0.5), (FAR, 2.0), (2.0, FAR), (FAR, FAR)] {
            assert_eq!(segment_brightness(d1, d2, 1.0).to_bits(), penumbra_brightness(d1, d2).to_bits());
            for k in [1.0, 1.7, 1e6] {
                let v = segment_brightness(d1, d2, k);
                assert!((0.0..=1.0).contains(&v), "{d1} {d2} {k}: {v}");
            }
        }
        assert_eq!(segment_brightness(0.0, 4.0, 3.0), 0.0);
        assert_eq!(segment_brightness(4.0, 0.0, 3.0), 1.0);
        for (l, d) in [(0.0, 1.0), (-1.0, 1.0), (1.0, 1.0), (2.0, 1.0), (f32::NAN, 1.0), (1.0, f32::INFINITY)]
        {
            let k = segment_ratio(l, d);
            assert!((1.0..=1e6).contains(&k), "l = {l}, d = {d}: {k}");
        }
    }

    #[test]
    fn implied_disc_matches_the_band_width_of_the_two_maps() {
        // Edge at r = 0.5 off the axis at D = 4, receiver at D_r = 6, l = 0.5: the two shadows of
        // the edge are 2·l·r·(D_r − D)/(D² − l²) apart, a disc of radius R gives 2·R·(D_r − D)/D.
        let (l, r, d, dr) = (0.5f32, 0.5f32, 4.0f32, 6.0f32);
        let two_maps = r * ((dr - l) / (d - l) - (dr + l) / (d + l));
        let disc = 2.0 * implied_disc_radius(l, r, d) * (dr - d) / d;
        assert!((two_maps - disc).abs() < 1e-6, "{two_maps} vs {disc}");
        assert_eq!(implied_disc_radius(2.0, 1.0, 1.0), 2.0);
    }

    #[test]
    fn classes_follow_the_two_verdicts() {
        assert_eq!(Class::of(true, true), Class::Umbra);
        assert_eq!(Class::of(true, false), Class::Penumbra);
        assert_eq!(Class::of(false, true), Class::Penumbra);
        assert_eq!(Class::of(false, false), Class::Lit);
        assert!(same_surface(Vec3f::ZERO, Vec3f::Y, Vec3f::new(3.0, 0.5, 0.0)));
        assert!(!same_surface(Vec3f::ZERO, Vec3f::Y, Vec3f::new(1.0, 1.0, 0.0)));
    }

    #[test]
    fn caster_box_blocks_exactly_the_segments_that_enter_it_before_their_end() {
        // A box rotated about y, 2 × 1 × 0.5, corner at (1, 0, −1).
        let (c, sn) = (0.6f32, 0.8f32);
        let edges = [
            Vec3f::new(2.0 * c, 0.0, -2.0 * sn),
            Vec3f::new(0.0, 1.0, 0.0),
            Vec3f::new(0.5 * sn, 0.0, 0.5 * c),
        ];
        let origin = Vec3f::new(1.0, 0.0, -1.0);
        let b = CasterBox::from_edges(origin, edges).unwrap();
        let inside = |q: Vec3f| b.local(q).iter().all(|&u| (0.0..=1.0).contains(&u));
        assert!(inside(origin + (edges[0] + edges[1] + edges[2]) * 0.5));
        assert!(!inside(origin - edges[2] * 0.01));
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 * 8.0 - 4.0
        };
        let (mut hit, mut miss) = (0, 0);
        for _ in 0..3000 {
            let (e, p) = (Vec3f::new(next(), next(), next()), Vec3f::new(next(), next() * 0.3 + 0.5, next()));
            // Samples along the segment up to 1 − FIT_MARGIN with a safety band either side.
            let samples: Vec<bool> =
                (0..=4000).map(|j| inside(e + (p - e) * (j as f32 / 4000.0 * 0.99))).collect();
            let brute_in = samples.iter().any(|&x| x);
            let got = b.blocks(e, p);
            if brute_in {
                assert!(got, "{e:?} → {p:?} passes through the box");
                hit += 1;
            } else if !(0..=200).any(|j| inside(e + (p - e) * (0.99 + j as f32 * 0.0001 / 2.0))) {
                // Clear of the box to the end as well: never counted.
                assert!(!got, "{e:?} → {p:?} misses the box");
                miss += 1;
            }
        }
        assert!(hit > 100 && miss > 100, "{hit} hits, {miss} misses");
        // A point on the box's face, lit from outside: the segment enters it only at the point.
        let face = origin + edges[0] * 0.5 + edges[1] * 0.5;
        assert!(!b.blocks(face - edges[2] * 4.0, face));
        assert!(b.blocks(face - edges[2] * 4.0, face + edges[2] * 0.5));
        // A parallel segment beside a face, and flat or infinite edges.
        assert!(!b.blocks(Vec3f::new(1.0, 2.0, -1.0), Vec3f::new(3.0, 2.0, -1.0)));
        assert!(CasterBox::from_edges(origin, [edges[0], edges[0], edges[2]]).is_none());
        assert!(CasterBox::from_edges(origin, [edges[0] * f32::INFINITY, edges[1], edges[2]]).is_none());
    }

    #[test]
    fn fit_window_keys_keep_the_order_and_the_fitted_map_covers_the_window() {
        let vals = [-5.0f32, -1.5, -1e-30, -0.0, 0.0, 1e-30, 0.25, 3.0, 5.6];
        for w in vals.windows(2) {
            assert!(FitWindow::key(w[0]) <= FitWindow::key(w[1]), "{} {}", w[0], w[1]);
            assert_eq!(FitWindow::value(FitWindow::key(w[1])).to_bits(), w[1].to_bits());
        }
        let corners = [Vec3f::new(-4.0, 0.0, -4.0), Vec3f::new(4.0, 0.0, 4.0), Vec3f::new(4.0, 2.0, -4.0)];
        let map = SpotMap::look(Vec3f::new(0.0, 6.0, 0.0), Vec3f::ZERO, &corners);
        assert_eq!(map.fitted(&FitWindow::EMPTY, 512).tan_half, SPOT_MIN_TAN);
        // Points off the axis: the fitted (off-axis) map looks every one of them up inside, one
        // texel's normal offset included, and is far narrower than the map.
        let pts = [Vec3f::new(1.0, 0.0, 1.2), Vec3f::new(1.6, 0.0, 0.9), Vec3f::new(1.3, 0.4, 1.5)];
        let mut w = FitWindow::default();
        for p in pts {
            w.add(map.fit_coords(p).unwrap());
        }
        let fit = map.fitted(&w, 512);
        assert!(fit.tan_half < 0.2 * map.tan_half, "{} against {}", fit.tan_half, map.tan_half);
        for p in pts {
            for n in
                [Vec3f::Y, Vec3f::new(-0.6, 0.8, 0.0), Vec3f::new(0.0, 0.8, -0.6), Vec3f::new(0.6, 0.8, 0.0)]
            {
                let (x, y, _) = fit.lookup(p, n, 512).unwrap();
                assert!((0..512).contains(&x) && (0..512).contains(&y), "{p:?} {n:?}: {x} {y}");
            }
        }
        // The same depth and texel size as an on-axis map of that width: only the centre moves.
        let v = fit.to_view(pts[0]);
        assert!((v.z - map.to_view(pts[0]).z).abs() < 1e-5);
        // A window as wide as the map keeps the map.
        let mut all = FitWindow::default();
        all.add([-map.tan_half, -map.tan_half]);
        all.add([map.tan_half, map.tan_half]);
        assert_eq!(map.fitted(&all, 512), map);
        // Narrowing by less than FIT_GAIN keeps the map; by more, fits it.
        let window = |f: f32| {
            let mut w = FitWindow::default();
            w.add([-f * map.tan_half, -f * map.tan_half]);
            w.add([f * map.tan_half, f * map.tan_half]);
            w
        };
        assert_eq!(map.fitted(&window(0.6), 512), map);
        let narrow = map.fitted(&window(0.4), 512);
        assert!(narrow.tan_half < FIT_GAIN * map.tan_half && narrow.tan_half > 0.4 * map.tan_half);
        assert_eq!(w.union(FitWindow::EMPTY), w);
    }

    #[test]
    fn the_prepared_fit_test_gathers_the_same_window_as_the_rule() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        // A small box near the point of interest, a long wall past the light (reaching behind it:
        // an unbounded rectangle) and a tilted slab.
        let boxes = [
            CasterBox::from_edges(
                Vec3f::new(-0.3, 0.0, -0.3),
                [Vec3f::X * 0.6, Vec3f::Y * 1.5, Vec3f::Z * 0.6],
            ),
            CasterBox::from_edges(
                Vec3f::new(-4.0, 0.0, -2.0),
                [Vec3f::X * 8.0, Vec3f::Y * 4.0, Vec3f::Z * 0.2],
            ),
            CasterBox::from_edges(
                Vec3f::new(1.0, 0.5, 1.0),
                [Vec3f::new(0.8, 0.3, 0.0), Vec3f::new(0.0, 0.1, 0.9), Vec3f::new(0.05, 0.4, -0.02)],
            ),
        ]
        .map(Option::unwrap);
        let corners: Vec<Vec3f> = boxes
            .iter()
            .flat_map(|b| {
                (0..8).map(move |i| {
                    let u = |k: usize| (i >> k & 1) as f32;
                    b.origin + b.edges[0] * u(0) + b.edges[1] * u(1) + b.edges[2] * u(2)
                })
            })
            .collect();
        for eye in [Vec3f::new(2.5, 1.8, 1.0), Vec3f::new(0.5, 3.0, 2.0)] {
            let map = SpotMap::look(eye, Vec3f::new(0.0, 0.7, 0.0), &corners);
            for set in 0..3 {
                let test = FitTest::new(&map, &boxes[..=set]);
                let (mut rule, mut fast) = (FitWindow::EMPTY, FitWindow::EMPTY);
                for _ in 0..4000 {
                    let p = Vec3f::new(next() * 10.0 - 5.0, next() * 4.0, next() * 6.0 - 3.0);
                    rule.add_point(&map, &boxes[..=set], p);
                    test.add(&mut fast, p);
                }
                assert_ne!(rule, FitWindow::EMPTY);
                assert_eq!(rule, fast, "eye {eye:?}, boxes 0..={set}");
            }
        }
    }
}
