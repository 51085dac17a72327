//! A soft shadow map's perspective frame, its depth bias, and its fitting to what can be shadowed
//! in view (`CasterBox`, `FitTest`, `FitWindow`).

use crate::Vec3f;

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
