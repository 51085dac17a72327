//! Soft shadows from the `[area_light]` (003, SPEC.md §4): two perspective shadow maps from
//! `L₁ = L + l·P` and `L₂ = L − l·P`, every visible pixel classed umbra / penumbra / lit, and each
//! penumbra pixel's brightness `k·D₁/(k·D₁ + D₂)` ([`segment_brightness`]; `k = 1` is 003's
//! `D₁/(D₁ + D₂)`) from its distances to the nearest umbra and lit pixels, found either by 003's
//! search on every `N`-th pixel with bilinear interpolation ([`SoftResolve::Faithful`]) or by exact
//! Euclidean distance transforms ([`SoftResolve::Exact`], the default). Both count only umbra and lit pixels within [`SEARCH_RADIUS`], and with the
//! depth-aware search only those on the penumbra pixel's own surface ([`same_surface`]), so the
//! exact resolve gives exactly what the faithful one gives at `N = 1`.
//!
//! Also the references `hadou bench shadows` measures against: [`truth`] (a true disc light, many
//! shadow maps, of the radius [`disc_radius`]) and [`pcss`] (percentage-closer soft shadows as
//! commonly shipped), and the error it reports ([`edge_errors`]).
//!
//! The GPU backend mirrors [`visibility`] (`soft.wgsl`).

use crate::opaque::draw_opaque;
use crate::raster::{nearest_depths, ScreenProjection, Tris, Vert};
use crate::setup::FrameSetup;
use hadou_math::soft::{
    bilinear, same_surface, segment_brightness, Class, Envelope, FitTest, FitWindow, SpotMap, FAR,
    SEARCH_RADIUS,
};
use hadou_math::{Vec3, Vec3f};
use hadou_scene::{AreaLight, Frame, SoftResolve};
use rayon::prelude::*;

pub use crate::opaque::SoftPoint;

/// The visible points of a whole frame, as the soft-shadow stage takes them.
#[derive(Clone, Debug)]
pub struct SoftInput {
    /// Image width.
    pub width: usize,
    /// Image height.
    pub height: usize,
    /// Row-major, `None` for the background and outline hulls.
    pub points: Vec<Option<SoftPoint>>,
    /// The anti-aliasing grid's edge `k`: the points are the sample frame's, each image pixel
    /// `k × k` of them ([`hadou_scene::Frame::sample_frame`]); 1 for one point a pixel. Only the
    /// traced resolve reads it ([`crate::traced::traced_grid`]).
    pub grid: usize,
}

/// Runs the opaque pass of `frame` (which must have an `[area_light]`) and returns its visible
/// points: what [`visibility`] and the references work on. `None` without an area light.
pub fn soft_input(frame: &Frame) -> Option<SoftInput> {
    frame.area_light.as_ref()?;
    let opaque = draw_opaque(frame, &FrameSetup::new(frame), 0..frame.height as usize);
    Some(SoftInput {
        width: frame.width as usize,
        height: frame.height as usize,
        points: opaque.soft,
        grid: 1,
    })
}

/// A perspective depth map: the view depth of the nearest surface per texel, `+∞` where none.
#[derive(Clone, Debug)]
pub struct SpotDepth {
    /// The map's frame.
    pub map: SpotMap,
    /// Edge in texels.
    pub size: u32,
    /// `size²` view depths, row 0 at the frustum's top.
    pub depth: Vec<f32>,
}

impl SpotDepth {
    /// Renders the objects `casters` of `frame` (double-sided, top-left rule, perspective-correct
    /// depth, the nearest kept) into a `size²` map of frame `map`, bands of rows in parallel.
    pub fn render(frame: &Frame, casters: &[u32], map: &SpotMap, size: u32) -> SpotDepth {
        let tris = spot_tris(frame, casters, map, size);
        let depth = nearest_depths(&tris, size as usize, f32::INFINITY, |ti, w| tris[ti].depth_at(w));
        SpotDepth { map: *map, size, depth }
    }

    /// The stored depth of texel `(x, y)`, `+∞` outside the map.
    #[inline]
    fn at(&self, x: i64, y: i64) -> f32 {
        let n = i64::from(self.size);
        if x < 0 || y < 0 || x >= n || y >= n {
            return f32::INFINITY;
        }
        self.depth[(y * n + x) as usize]
    }

    /// Whether the point `p` (unit normal `n`) is in this map's shadow: it faces away from the
    /// map's light, or the texel it looks up ([`SpotMap::lookup`]) holds a nearer surface
    /// ([`SpotMap::occludes`]).
    #[inline]
    pub fn shadowed(&self, p: Vec3f, n: Vec3f) -> bool {
        match self.map.lookup(p, n, self.size) {
            None => true,
            Some((x, y, z)) => self.map.occludes(self.at(x, y), z, self.size),
        }
    }
}

/// The triangles of the objects `casters` (not the outline hulls) as seen from one of 003's
/// soft-shadow maps: clipped at the map's near plane and projected to texel coordinates of a
/// `size²` map (texel `(x, y)` covers `[x, x+1) × [y, y+1)`, row 0 at the frustum's top), `1/z`
/// per vertex for the perspective-correct depth ([`ScreenTri::depth_at`]).
fn spot_tris(frame: &Frame, casters: &[u32], map: &SpotMap, size: u32) -> Tris {
    let screen = ScreenProjection::square(map.near, map.tan_half, size);
    let mut out = Tris::default();
    for obj in casters.iter().filter_map(|&c| frame.objects.get(c as usize)) {
        let verts: Vec<Vert> = obj
            .mesh
            .positions
            .iter()
            .map(|p| {
                let world = obj.transform.transform_point(Vec3::from_array(*p));
                Vert {
                    view: map.to_view(world),
                    world,
                    normal: Vec3f::ZERO,
                    uv: [0.0; 2],
                    color: [0.0; 4],
                    outline: Vec3f::ZERO,
                }
            })
            .collect();
        for tri in obj.mesh.indices.chunks_exact(3) {
            let v = [tri[0], tri[1], tri[2]].map(|i| verts.get(i as usize).copied());
            let [Some(a), Some(b), Some(c)] = v else { continue };
            screen.push([a, b, c], 0, 0, false, &mut out);
        }
    }
    out
}

/// Every pixel's class (003 §4.1) from the two maps.
pub fn classify(maps: &[SpotDepth; 2], input: &SoftInput) -> Vec<Class> {
    input
        .points
        .par_iter()
        .with_min_len(4096)
        .map(|p| match p {
            None => Class::None,
            Some(p) => Class::of(maps[0].shadowed(p.world, p.normal), maps[1].shadowed(p.world, p.normal)),
        })
        .collect()
}

/// The soft-shadow visibility of every pixel of `input` under `light` (0 in the umbra, 1 where
/// lit, `k·D₁/(k·D₁ + D₂)` in the penumbra with `k` = [`AreaLight::penumbra_ratio`]; 0 where no
/// point is): the two maps, the classes and the resolve `resolve`, or for
/// [`SoftResolve::Traced`] the share of the lamp each point sees ([`crate::traced`], no maps). What [`crate::render()`]
/// multiplies the area light's term by.
pub fn visibility(frame: &Frame, light: &AreaLight, input: &SoftInput, resolve: SoftResolve) -> Vec<f32> {
    let grid = match resolve {
        SoftResolve::Traced { samples } => {
            let bvh = hadou_math::soft::Bvh::build(&crate::traced::caster_triangles(frame, &light.casters));
            return crate::traced::traced_grid(&bvh, light, &input.points, input.width, samples, input.grid);
        }
        SoftResolve::Exact => None,
        SoftResolve::Faithful { n } => Some(n.max(1) as usize),
    };
    let maps = fitted_maps(light, input).map(|m| (m, light.map_size));
    let [a, b] = maps;
    let (m1, m2) = rayon::join(
        || SpotDepth::render(frame, &light.casters, &a.0, a.1),
        || SpotDepth::render(frame, &light.casters, &b.0, b.1),
    );
    let class = classify(&[m1, m2], input);
    let search =
        Search { input, class: &class, depth_aware: light.depth_aware, ratio: light.penumbra_ratio() };
    match grid {
        None => search.exact(),
        Some(n) => search.faithful(n),
    }
}

/// The light's two maps narrowed to the visible points of `input` that a caster can shadow in
/// each ([`FitWindow::add_point`] by way of [`FitTest`], [`SpotMap::fitted`]): a point no
/// caster's box lies in front of is lit in that map whatever it holds, so the maps spend their
/// texels where shadows can fall (a wall that casts but stands behind everything does not widen
/// them). soft.wgsl's `cs_points` gathers the same windows on the GPU.
///
/// The window of every 4th pixel in x and y comes first: it is part of the whole image's, and
/// [`SpotMap::fitted`]'s half-angle only grows with the window, so when even that window would
/// not narrow a map by [`hadou_math::soft::FIT_GAIN`] the whole one would not either, and that
/// map keeps its frustum without a pass over every pixel (scenes whose casters all stand in
/// view). The result is the whole window's in every case.
pub fn fitted_maps(light: &AreaLight, input: &SoftInput) -> [SpotMap; 2] {
    let tests = light.maps.map(|m| FitTest::new(&m, &light.caster_boxes));
    let windows = |step: usize, which: [bool; 2]| {
        let w = input.width;
        input
            .points
            .par_chunks(w)
            .step_by(step)
            .with_min_len(16)
            .fold(
                || [FitWindow::EMPTY; 2],
                |mut acc, row| {
                    for p in row.iter().step_by(step).flatten() {
                        for k in 0..2 {
                            if which[k] {
                                tests[k].add(&mut acc[k], p.world);
                            }
                        }
                    }
                    acc
                },
            )
            .reduce(|| [FitWindow::EMPTY; 2], |a, b| [a[0].union(b[0]), a[1].union(b[1])])
    };
    let coarse = windows(4, [true; 2]);
    let need = [0, 1].map(|k| light.maps[k].fitted(&coarse[k], light.map_size) != light.maps[k]);
    if !need[0] && !need[1] {
        return light.maps;
    }
    let full = windows(1, need);
    [0, 1].map(|k| if need[k] { light.maps[k].fitted(&full[k], light.map_size) } else { light.maps[k] })
}

/// The classes of a frame and how its penumbra pixels look for umbra and lit pixels.
struct Search<'a> {
    input: &'a SoftInput,
    class: &'a [Class],
    depth_aware: bool,
    /// `k` of [`segment_brightness`] (1: 003's linear ratio).
    ratio: f32,
}

/// The value of a pixel that is not in the penumbra.
#[inline]
fn plain(c: Class) -> f32 {
    match c {
        Class::Umbra | Class::None => 0.0,
        _ => 1.0,
    }
}

const R2: f32 = (SEARCH_RADIUS * SEARCH_RADIUS) as f32;

impl Search<'_> {
    /// Whether pixel `j` counts as a `want` pixel for the penumbra pixel `i`.
    #[inline]
    fn counts(&self, i: usize, j: usize, want: Class) -> bool {
        if self.class[j] != want {
            return false;
        }
        if !self.depth_aware {
            return true;
        }
        match (self.input.points[i], self.input.points[j]) {
            (Some(p), Some(q)) => same_surface(p.world, p.normal, q.world),
            _ => false,
        }
    }

    /// The squared distance from pixel `i` to the nearest pixel that [`Search::counts`] as `want`
    /// within [`SEARCH_RADIUS`] (Euclidean), `FAR` if none: square rings of Chebyshev radius
    /// `r ≥ start`, stopping once `r²` exceeds the best found. Exact when no counting pixel lies
    /// nearer than `start` in Chebyshev distance.
    fn ring_search(&self, i: usize, want: Class, start: u32) -> f32 {
        let (w, h) = (self.input.width as i64, self.input.height as i64);
        let (x, y) = ((i as i64) % w, (i as i64) / w);
        let mut best = FAR;
        let mut r = i64::from(start.max(1));
        while r <= i64::from(SEARCH_RADIUS) && ((r * r) as f32) <= best {
            if x - r < 0 && y - r < 0 && x + r >= w && y + r >= h {
                break;
            }
            let mut visit = |u: i64, v: i64| {
                if u < 0 || v < 0 || u >= w || v >= h {
                    return;
                }
                let d2 = ((u - x) * (u - x) + (v - y) * (v - y)) as f32;
                if d2 < best && d2 <= R2 && self.counts(i, (v * w + u) as usize, want) {
                    best = d2;
                }
            };
            for u in x - r..=x + r {
                visit(u, y - r);
                visit(u, y + r);
            }
            for v in y - r + 1..y + r {
                visit(x - r, v);
                visit(x + r, v);
            }
            r += 1;
        }
        best
    }

    /// The brightness of penumbra pixel `i` by searching (003 §3.2).
    fn searched(&self, i: usize) -> f32 {
        let d1 = self.ring_search(i, Class::Umbra, 1);
        let d2 = self.ring_search(i, Class::Lit, 1);
        segment_brightness(d1.sqrt(), d2.sqrt(), self.ratio)
    }

    /// 003's resolve (SPEC.md §4.2–4.3): the search on every `n`-th pixel in x and y (pixels
    /// `(x, y)` with `x, y ≡ 0 mod n`; umbra grid pixels 0, lit and empty ones 1), every other
    /// penumbra pixel bilinearly interpolated from the four grid pixels around it (the last grid
    /// column or row repeated at the image's edge), standard weights.
    fn faithful(&self, n: usize) -> Vec<f32> {
        let (w, h) = (self.input.width, self.input.height);
        let (gw, gh) = ((w - 1) / n + 1, (h - 1) / n + 1);
        let grid: Vec<f32> = (0..gw * gh)
            .into_par_iter()
            .with_min_len(64)
            .map(|g| {
                let i = (g / gw) * n * w + (g % gw) * n;
                match self.class[i] {
                    Class::Penumbra => self.searched(i),
                    Class::Umbra => 0.0,
                    _ => 1.0,
                }
            })
            .collect();
        let mut out = vec![0.0f32; w * h];
        out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            let (gy0, fy) = (y / n, (y % n) as f32 / n as f32);
            let gy1 = (gy0 + 1).min(gh - 1);
            let fy = if gy1 == gy0 { 0.0 } else { fy };
            for (x, o) in row.iter_mut().enumerate() {
                let c = self.class[y * w + x];
                if c != Class::Penumbra {
                    *o = plain(c);
                    continue;
                }
                let (gx0, fx) = (x / n, (x % n) as f32 / n as f32);
                let gx1 = (gx0 + 1).min(gw - 1);
                let fx = if gx1 == gx0 { 0.0 } else { fx };
                let g = |gx: usize, gy: usize| grid[gy * gw + gx];
                *o = bilinear(g(gx0, gy0), g(gx1, gy0), g(gx0, gy1), g(gx1, gy1), fx, fy);
            }
        });
        out
    }

    /// hadou's resolve: exact squared distance transforms (with nearest-pixel indices) of the umbra
    /// and the lit pixels give every penumbra pixel its nearest of each; with the depth-aware
    /// search a nearest pixel on another surface sends that pixel to [`Search::ring_search`] from
    /// `⌊d/√2⌋` (no counting pixel is nearer), so the answer is the faithful `N = 1` one.
    ///
    /// The transforms cover only the penumbra's bounding box widened by [`MARGIN`] pixels: a
    /// nearest pixel found there at distance `d` is the nearest of the whole image when `d` is at
    /// most the distance `b` to the box's edge (image edges aside); otherwise every pixel nearer
    /// than `b` lies in the box and was not one, so the nearest is farther than `b`: infinite when
    /// `b` exceeds [`SEARCH_RADIUS`], else found by the ring search from `⌊b/√2⌋`. When more than
    /// 1 % of the penumbra pixels would need that search (a penumbra far wider than the margin),
    /// the transforms are redone over the box widened by [`SEARCH_RADIUS`], where none does.
    fn exact(&self) -> Vec<f32> {
        let (w, h) = (self.input.width, self.input.height);
        let mut out: Vec<f32> = self.class.par_iter().with_min_len(4096).map(|&c| plain(c)).collect();
        let Some(mut rect) = penumbra_box(self.class, w, h, MARGIN) else { return out };
        let mut du_fu = edt(self.class, Class::Umbra, w, &rect);
        let mut dl_fl = edt(self.class, Class::Lit, w, &rect);
        let uncertain = |rect: &Rect, du: &[f32], dl: &[f32]| -> (usize, usize) {
            let bw = rect.x1 - rect.x0;
            (rect.y0..rect.y1)
                .into_par_iter()
                .map(|y| {
                    let (mut pen, mut unc) = (0, 0);
                    for x in rect.x0..rect.x1 {
                        if self.class[y * w + x] == Class::Penumbra {
                            pen += 1;
                            let b2 = edge2(rect, w, h, x, y);
                            let k = (y - rect.y0) * bw + (x - rect.x0);
                            unc += usize::from(b2 <= R2 && (du[k] > b2 || dl[k] > b2));
                        }
                    }
                    (pen, unc)
                })
                .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
        };
        let (pen, unc) = uncertain(&rect, &du_fu.0, &dl_fl.0);
        if unc * 100 > pen {
            rect = penumbra_box(self.class, w, h, SEARCH_RADIUS as usize).expect("there is a penumbra");
            du_fu = edt(self.class, Class::Umbra, w, &rect);
            dl_fl = edt(self.class, Class::Lit, w, &rect);
        }
        let ((du, fu), (dl, fl)) = (du_fu, dl_fl);
        let bw = rect.x1 - rect.x0;
        out.par_chunks_mut(w).enumerate().skip(rect.y0).take(rect.y1 - rect.y0).for_each(|(y, row)| {
            for (x, o) in row.iter_mut().enumerate().skip(rect.x0).take(bw) {
                let i = y * w + x;
                if self.class[i] != Class::Penumbra {
                    continue;
                }
                let b = (y - rect.y0) * bw + (x - rect.x0);
                let b2 = edge2(&rect, w, h, x, y);
                let fix = |d2: f32, f: u32, want: Class| -> f32 {
                    let start = if d2 <= b2 {
                        if d2 == FAR {
                            return FAR;
                        }
                        if !self.depth_aware || self.counts(i, f as usize, want) {
                            return if d2 <= R2 { d2 } else { FAR };
                        }
                        d2
                    } else if b2 > R2 {
                        return FAR;
                    } else {
                        b2
                    };
                    let start = (start.sqrt() * std::f32::consts::FRAC_1_SQRT_2).floor() as u32;
                    if start > SEARCH_RADIUS {
                        return FAR;
                    }
                    self.ring_search(i, want, start)
                };
                let d1 = fix(du[b], fu[b], Class::Umbra);
                let d2 = fix(dl[b], fl[b], Class::Lit);
                *o = segment_brightness(d1.sqrt(), d2.sqrt(), self.ratio);
            }
        });
        out
    }
}

/// A rectangle of pixels `[x0, x1) × [y0, y1)`.
struct Rect {
    x0: usize,
    x1: usize,
    y0: usize,
    y1: usize,
}

/// How far the exact resolve's distance transforms reach beyond the penumbra's bounding box at
/// first, in pixels (a speed setting: any value gives the same result).
pub const MARGIN: usize = 128;

/// The squared distance from pixel `(x, y)` of `rect` to the nearest pixel outside it in the
/// `w × h` image (`FAR` where the rectangle is the whole image).
fn edge2(rect: &Rect, w: usize, h: usize, x: usize, y: usize) -> f32 {
    [
        (rect.x0 > 0).then(|| x - rect.x0 + 1),
        (rect.x1 < w).then(|| rect.x1 - x),
        (rect.y0 > 0).then(|| y - rect.y0 + 1),
        (rect.y1 < h).then(|| rect.y1 - y),
    ]
    .into_iter()
    .flatten()
    .min()
    .map_or(FAR, |e| (e * e) as f32)
}

/// The bounding box of the penumbra pixels widened by `r` and clipped to the image; `None`
/// without penumbra pixels.
fn penumbra_box(class: &[Class], w: usize, h: usize, r: usize) -> Option<Rect> {
    let rows = class
        .par_chunks(w)
        .enumerate()
        .filter_map(|(y, row)| {
            let first = row.iter().position(|&c| c == Class::Penumbra)?;
            let last = row.iter().rposition(|&c| c == Class::Penumbra)?;
            Some((y, first, last))
        })
        .collect::<Vec<_>>();
    let (y0, y1) = (rows.first()?.0, rows.last()?.0);
    let x0 = rows.iter().map(|t| t.1).min()?;
    let x1 = rows.iter().map(|t| t.2).max()?;
    Some(Rect {
        x0: x0.saturating_sub(r),
        x1: (x1 + r + 1).min(w),
        y0: y0.saturating_sub(r),
        y1: (y1 + r + 1).min(h),
    })
}

/// The exact squared Euclidean distance transform, within `rect`, of its pixels of class `want`,
/// with the image index of a nearest such pixel (`u32::MAX` where none); both row-major over the
/// rectangle. Felzenszwalb–Huttenlocher's two passes: the columns (for a binary image, the
/// nearest feature pixel of each column: a sweep down and one up over whole rows, in memory order,
/// the upper one on ties), then the rows in parallel (the lower envelope).
fn edt(class: &[Class], want: Class, w: usize, rect: &Rect) -> (Vec<f32>, Vec<u32>) {
    let (bw, bh) = (rect.x1 - rect.x0, rect.y1 - rect.y0);
    // Columns, row-major (`row_of[y·bw + x]`: the nearest feature's row in column x, within the
    // rectangle), sweeping whole rows so the classes are read in memory order.
    let mut row_of = vec![u32::MAX; bw * bh];
    let mut last = vec![u32::MAX; bw];
    for (y, out) in row_of.chunks_exact_mut(bw).enumerate() {
        let row = &class[(rect.y0 + y) * w + rect.x0..][..bw];
        for ((o, l), &c) in out.iter_mut().zip(last.iter_mut()).zip(row) {
            // Downwards: the nearest feature at or above.
            if c == want {
                *l = y as u32;
            }
            *o = *l;
        }
    }
    // Upwards: a nearer feature below replaces it (strictly nearer: ties keep the upper one).
    let mut next = vec![u32::MAX; bw];
    for (y, out) in row_of.chunks_exact_mut(bw).enumerate().rev() {
        let row = &class[(rect.y0 + y) * w + rect.x0..][..bw];
        let y = y as u32;
        for ((o, n), &c) in out.iter_mut().zip(next.iter_mut()).zip(row) {
            if c == want {
                *n = y;
            }
            if *n != u32::MAX && (*o == u32::MAX || *n - y < y - *o) {
                *o = *n;
            }
        }
    }
    let mut d2 = vec![0.0f32; bw * bh];
    let mut feat = vec![u32::MAX; bw * bh];
    d2.par_chunks_mut(bw).zip(feat.par_chunks_mut(bw)).enumerate().for_each_init(
        || (Envelope::new(bw), vec![0.0f32; bw], vec![0u32; bw]),
        |(env, line, arg), (y, (out, f))| {
            let rows = &row_of[y * bw..][..bw];
            for (l, &r) in line.iter_mut().zip(rows) {
                *l = if r == u32::MAX {
                    FAR
                } else {
                    let d = y as f32 - r as f32;
                    d * d
                };
            }
            env.transform(line, out, arg);
            for (x, fo) in f.iter_mut().enumerate() {
                let p = arg[x];
                if p != u32::MAX && out[x] != FAR {
                    let r = rows[p as usize] as usize;
                    *fo = ((rect.y0 + r) * w + rect.x0 + p as usize) as u32;
                }
            }
        },
    );
    (d2, feat)
}

/// The ground truth of a frame's soft shadow: the fraction of `samples` points of a disc of radius
/// `radius` centred at the light's `L` and facing the point of interest (golden-angle spiral,
/// equal areas) from which each pixel's point is visible, each by its own `map_size²` shadow map
/// (the same bias as the two-map method). Slow: for measuring against, not for rendering.
pub fn truth(
    frame: &Frame,
    light: &AreaLight,
    input: &SoftInput,
    radius: f32,
    samples: u32,
    map_size: u32,
) -> Vec<f32> {
    let axis = (light.interest - light.position).normalize_or(-Vec3f::Y);
    let (u, v) = axis.orthonormal_basis();
    let mut lit = vec![0u32; input.points.len()];
    let corners = corners(frame, &light.casters);
    for k in 0..samples {
        let (px, py) = spiral(k, samples);
        let eye = light.position + u * (px * radius) + v * (py * radius);
        let map =
            SpotDepth::render(frame, &light.casters, &SpotMap::look(eye, light.interest, &corners), map_size);
        lit.par_iter_mut().zip(&input.points).with_min_len(4096).for_each(|(l, p)| {
            if let Some(p) = p {
                if !map.shadowed(p.world, p.normal) {
                    *l += 1;
                }
            }
        });
    }
    lit.into_iter().map(|l| l as f32 / samples.max(1) as f32).collect()
}

/// The disc radius the ground truth and PCSS are measured with for `frame`'s area light: 003's two
/// maps at `L ± l·P` give the penumbra of a disc of radius `l·r·D/(D² − l²)` at a silhouette `r` off
/// the axis ([`hadou_math::soft::implied_disc_radius`]), `D = |L − G|` and `r` the bounding radius
/// of the object whose centre is nearest `G` (the point of interest's object). `None` without an
/// area light.
pub fn disc_radius(frame: &Frame) -> Option<f32> {
    let light = frame.area_light.as_ref()?;
    let d = (light.position - light.interest).length();
    let r = frame
        .objects
        .iter()
        .filter_map(hadou_scene::object_bounds)
        .map(|(lo, hi)| (((lo + hi) * 0.5 - light.interest).length(), (hi - lo).length() * 0.5))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map_or(light.size, |(_, r)| r);
    Some(hadou_math::soft::implied_disc_radius(light.size, r, d))
}

/// Mean and 99th percentile of `|v − truth|` over the shadow-edge pixels: those with a visible
/// point where either value lies strictly between 0 and 1 or the two differ. `(0, 0)` when there
/// are none.
pub fn edge_errors(v: &[f32], truth: &[f32], visible: &[bool]) -> (f64, f64) {
    let mut e: Vec<f64> = v
        .iter()
        .zip(truth)
        .zip(visible)
        .filter(|((&a, &b), &vis)| vis && ((a > 0.0 && a < 1.0) || (b > 0.0 && b < 1.0) || a != b))
        .map(|((&a, &b), _)| f64::from((a - b).abs()))
        .collect();
    if e.is_empty() {
        return (0.0, 0.0);
    }
    e.sort_by(f64::total_cmp);
    let mean = e.iter().sum::<f64>() / e.len() as f64;
    let p99 = e[((e.len() - 1) as f64 * 0.99).round() as usize];
    (mean, p99)
}

/// Point `k` of `n` of a golden-angle spiral on the unit disc (equal areas).
fn spiral(k: u32, n: u32) -> (f32, f32) {
    let r = ((k as f32 + 0.5) / n.max(1) as f32).sqrt();
    let a = k as f32 * 2.399_963_2;
    (r * a.cos(), r * a.sin())
}

/// The corners of the bounding boxes of the objects `casters` (what a [`SpotMap`]'s frustum must
/// enclose).
fn corners(frame: &Frame, casters: &[u32]) -> Vec<Vec3f> {
    let mut out = Vec::new();
    for o in casters.iter().filter_map(|&c| frame.objects.get(c as usize)) {
        if let Some((lo, hi)) = hadou_scene::object_bounds(o) {
            for i in 0..8 {
                out.push(Vec3f::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                ));
            }
        }
    }
    out
}

/// Percentage-closer soft shadows as commonly shipped, for comparison: one shadow map from the
/// light centre `L` (`light.map_size²`); for a point at map depth `z_r`, a blocker search with 16
/// samples over the map region through which a disc light of radius `radius` could be hidden
/// (radius `R·(1/z_min − 1/z_r)` in tangent units, `z_min` the map's nearest depth), the average
/// blocker depth `z_b`, then 16 filter samples over the penumbra `R·(1/z_b − 1/z_r)`; the same
/// bias as the two-map method. Samples on a golden-angle spiral.
pub fn pcss(frame: &Frame, light: &AreaLight, input: &SoftInput, radius: f32) -> Vec<f32> {
    let map = SpotDepth::render(
        frame,
        &light.casters,
        &SpotMap::look(light.position, light.interest, &corners(frame, &light.casters)),
        light.map_size,
    );
    let z_min = map.depth.iter().copied().fold(f32::INFINITY, f32::min);
    let m = map.map;
    let size = map.size as f32;
    let taps: Vec<(f32, f32)> = (0..16).map(|k| spiral(k, 16)).collect();
    input
        .points
        .par_iter()
        .with_min_len(1024)
        .map(|p| {
            let Some(p) = p else { return 0.0 };
            let Some((x, y, z)) = m.lookup(p.world, p.normal, map.size) else { return 0.0 };
            let _ = (x, y);
            // The looked-up point in tangent units.
            let q = p.world + p.normal * m.texel(m.to_view(p.world).z.abs(), map.size);
            let v = m.to_view(q);
            let (su, sv) = (v.x / v.z, v.y / v.z);
            let to_texel = |tu: f32, tv: f32| {
                let s = (tu / m.tan_half + 1.0) * 0.5;
                let t = (tv / m.tan_half + 1.0) * 0.5;
                ((s * size).floor() as i64, ((1.0 - t) * size).floor() as i64)
            };
            let search = (radius * (1.0 / z_min - 1.0 / z)).max(0.0);
            let (mut sum, mut count) = (0.0f32, 0u32);
            for &(a, b) in &taps {
                let (tx, ty) = to_texel(su + a * search, sv + b * search);
                let d = map.at(tx, ty);
                if m.occludes(d, z, map.size) {
                    sum += d;
                    count += 1;
                }
            }
            if count == 0 {
                return 1.0;
            }
            let zb = sum / count as f32;
            let pen = (radius * (1.0 / zb - 1.0 / z)).max(0.0);
            let lit = taps
                .iter()
                .filter(|&&(a, b)| {
                    let (tx, ty) = to_texel(su + a * pen, sv + b * pen);
                    !m.occludes(map.at(tx, ty), z, map.size)
                })
                .count();
            lit as f32 / taps.len() as f32
        })
        .collect()
}
