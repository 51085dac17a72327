//! Glare: a bloom and an anamorphic streak on the linear image, before colour mapping.
//!
//! Not from the theses (SPEC.md has no glare); hadou's own, following the bloom chain of
//! Jimenez, "Next Generation Post Processing in Call of Duty: Advanced Warfare" (SIGGRAPH 2014),
//! written out texel by texel so that both backends compute the same sums from the same texels:
//!
//! 1. **Soft threshold** ([`prefilter`]): with `b = max(r, g, b)`, knee `k = threshold·soft_knee`,
//!    `q = clamp(b − threshold + k, 0, 2k)² / (4k)` (`q = 0` when `k = 0`) and
//!    `w = max(q, b − threshold) / b`, the bright part is `T = min(c·w, BLOOM_CLAMP)` per channel
//!    (`0` where `b ≤ 0`; negative and NaN channels read as 0, infinite ones as `f32::MAX`): zero below `threshold − k`, a quadratic knee up to `threshold + k`, then
//!    `c − threshold` along `c`'s direction.
//! 2. **Downsample** ([`down_row`]): level `k+1` (`⌈w/2⌉ × ⌈h/2⌉`) from level `k` by the 13-tap
//!    filter: thirteen 2×2 box averages `A(dx, dy)` of level `k` around texel `(2i, 2j)` — the box
//!    whose top-left texel is `(2i+dx, 2j+dy)`, `dx, dy ∈ {−2, −1, 0, 1, 2}` as the pattern uses
//!    them — weighted `1/8` for the centre `A(0,0)` and the four inner boxes `A(±1,±1)`
//!    (offsets −1 and +1 in each axis), `1/16` for the edge boxes `A(0,±2)`, `A(±2,0)` and `1/32`
//!    for the corners `A(±2,±2)`: the four overlapping 2×2-sample boxes weighted `1/8` each and the
//!    inner box weighted `1/2`, total 1. Texels outside the level clamp to its edge. Levels
//!    `D₁ … D_N`, `D₁` from `T`.
//! 3. **Upsample** ([`up_row`]): the 3×3 tent of bilinear taps one low texel apart, written out
//!    exactly: per axis, an even high texel `2j` reads low texels `j−2 … j+1` weighted
//!    `(1, 5, 7, 3)/16` and an odd one `2j+1` reads `j−1 … j+2` weighted `(3, 7, 5, 1)/16`; the 2-D
//!    weights are the products. `U_N = D_N`, `U_k = D_k + up(U_{k+1})` down to `U₁`.
//! 4. **Streak** ([`pair_row`], [`streak_row`]): at level 1's height, row `j` the average of the
//!    prefiltered rows `2j` and `2j+1`, then the same chain along `x` only: the 1-D 13-tap
//!    `(1, 3, 4, 4, 3, 1)/16` over texels `2i−2 … 2i+3` ([`down_row_h`]) and the 1-D tent
//!    ([`up_row_h`]) down to `U₁ʰ`, half the image's width.
//! 5. **Glare at level 1** ([`glare_row`]): the tent from `U₁` to full resolution is the
//!    `[1, 2, 1]/4` blur per axis at level 1 followed by a bilinear tap (`(1, 3)/4 ∗ (1, 2, 1)/4 =
//!    (1, 5, 7, 3)/16`), so the last upsample is done at level 1: `G = (intensity/N)·blur(U₁) +
//!    (streak/N_s)·blur_h(U₁ʰ)` (the streak blurred along `x` only), one plane of
//!    `⌈w/2⌉ × ⌈h/2⌉` texels.
//! 6. **Composite** ([`upsample_row`], [`composite`]): `c' = c + bilinear(G)` (per axis `2j` reads
//!    `j−1, j` by `¼, ¾` and `2j+1` reads `j, j+1` by `¾, ¼`, clamped; [`bilinear`]), each
//!    channel saturated at `f32::MAX` (never infinite), then the frame's colour mapping: the one
//!    pass at full resolution after the prefilter and the first downsample. [`glare`] runs the
//!    whole chain over a band of rows.
//!
//! The bloom is the tent of `U₁` as before but for rounding and the clamped edge texels; the
//! streak, made from row pairs and tapped bilinearly, reaches a row either side of its source.
//!
//! `N = clamp(⌈log₂(radius·height)⌉, 1, MAX_LEVELS)` ([`levels`]), `N_s` likewise from
//! `streak_length·height`. [`Plan`] gives, for a band of output rows, the rows of every level the
//! band reads, so a band computed with that halo has the whole image's pixels bit for bit.
//! [`lanes`] is the same chain eight texels at a time, with the same bits.

use std::ops::Range;

pub mod lanes;

/// The most pyramid levels (texels of `2¹⁰ = 1024` pixels at the top).
pub const MAX_LEVELS: u32 = 10;

/// The largest prefiltered channel value (the largest half float), so that weighted sums of the
/// pyramid stay finite whatever the linear colour.
pub const BLOOM_CLAMP: f32 = 65504.0;

/// A bloom's values at one instant (the scene's `[bloom]` table).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BloomParams {
    /// Weight of the bloom `B` added to the colour, `≥ 0`.
    pub intensity: f32,
    /// Brightness (`max(r, g, b)` of the linear colour) where the bloom starts, `≥ 0`.
    pub threshold: f32,
    /// Knee half-width as a fraction of `threshold`, in `[0, 1]`.
    pub soft_knee: f32,
    /// Bloom reach as a fraction of the image height, in `(0, 1]`.
    pub radius: f32,
    /// Weight of the horizontal streak `S`, `≥ 0` (0: no streak).
    pub streak: f32,
    /// Streak reach as a fraction of the image height, in `(0, 4]`.
    pub streak_length: f32,
}

/// Pyramid levels for a reach of `reach_px` pixels: `clamp(⌈log₂ reach_px⌉, 1, MAX_LEVELS)`.
pub fn levels(reach_px: f32) -> u32 {
    if reach_px.is_nan() || reach_px <= 2.0 {
        return 1;
    }
    (reach_px.log2().ceil() as u32).clamp(1, MAX_LEVELS)
}

/// The next level's size along one axis: `⌈n/2⌉`, at least 1.
#[inline]
pub fn half(n: usize) -> usize {
    n.div_ceil(2).max(1)
}

/// Step 1: the soft threshold with a quadratic knee (see the module docs).
#[inline]
pub fn prefilter(c: [f32; 3], threshold: f32, soft_knee: f32) -> [f32; 3] {
    // Negative and NaN channels count as 0, infinite ones as `f32::MAX`.
    let c = c.map(|v| if v.is_nan() { 0.0 } else { v.clamp(0.0, f32::MAX) });
    let b = c[0].max(c[1]).max(c[2]);
    if b <= 0.0 {
        return [0.0; 3];
    }
    let k = threshold * soft_knee;
    let q = if k > 0.0 {
        let s = (b - threshold + k).clamp(0.0, 2.0 * k);
        s * s / (4.0 * k)
    } else {
        0.0
    };
    let w = q.max(b - threshold) / b;
    c.map(|v| (v * w).min(BLOOM_CLAMP))
}

/// Step 6: `c + g` per channel (`g` the full-resolution glare), saturated at `f32::MAX`.
#[inline]
pub fn composite(c: [f32; 3], g: [f32; 3]) -> [f32; 3] {
    std::array::from_fn(|i| (c[i] + g[i]).min(f32::MAX))
}

/// Rows `rows` of one pyramid level `width × height` (row-major, `rows.len()·width` texels).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Plane {
    /// The level's width.
    pub width: usize,
    /// The level's height.
    pub height: usize,
    /// The rows held.
    pub rows: Range<usize>,
    /// The texels of those rows.
    pub data: Vec<[f32; 3]>,
}

impl Plane {
    /// A zeroed window `rows` of a `width × height` level.
    pub fn new(width: usize, height: usize, rows: Range<usize>) -> Self {
        let n = width * rows.len();
        Plane { width, height, rows, data: vec![[0.0; 3]; n] }
    }

    /// [`Plane::new`], its texels reserved fallibly: `Err(bytes)` where that much memory could
    /// not be allocated.
    pub fn try_new(width: usize, height: usize, rows: Range<usize>) -> Result<Self, usize> {
        let n = width.saturating_mul(rows.len());
        let mut data = Vec::new();
        data.try_reserve_exact(n).map_err(|_| n.saturating_mul(12))?;
        data.resize(n, [0.0; 3]);
        Ok(Plane { width, height, rows, data })
    }

    /// A window like [`Plane::try_new`]'s with `pool`'s texels where it has a buffer large
    /// enough (see [`PlanePool`]), without fresh pages to fault in and **not zeroed**: its texels
    /// are what the buffer last held, so the caller writes every one (as [`RowFill`] does).
    pub fn try_new_in(
        pool: &mut PlanePool,
        width: usize,
        height: usize,
        rows: Range<usize>,
    ) -> Result<Self, usize> {
        let n = width.saturating_mul(rows.len());
        let mut data = pool.take(n);
        if data.len() >= n {
            data.truncate(n);
        } else {
            data.try_reserve_exact(n - data.len()).map_err(|_| n.saturating_mul(12))?;
            data.resize(n, [0.0; 3]);
        }
        Ok(Plane { width, height, rows, data })
    }

    /// Texel `(x, y)` of the level, both clamped to its edge; `y` (after clamping) must be held.
    #[inline]
    pub fn at(&self, x: isize, y: isize) -> [f32; 3] {
        let x = x.clamp(0, self.width as isize - 1) as usize;
        let y = y.clamp(0, self.height as isize - 1) as usize;
        debug_assert!(self.rows.contains(&y), "row {y} outside {:?}", self.rows);
        self.data[(y - self.rows.start) * self.width + x]
    }

    /// Row `y` of the level (held).
    pub fn row(&self, y: usize) -> &[[f32; 3]] {
        let s = (y - self.rows.start) * self.width;
        &self.data[s..s + self.width]
    }
}

#[inline]
fn madd(acc: &mut [f32; 3], w: f32, v: [f32; 3]) {
    acc[0] += w * v[0];
    acc[1] += w * v[1];
    acc[2] += w * v[2];
}

/// Step 2: row `y` of the next level from `src` (which holds rows `2y−2 … 2y+3`, clamped), into
/// `out` (`half(src.width)` texels).
pub fn down_row(src: &Plane, y: usize, out: &mut [[f32; 3]]) {
    let y2 = 2 * y as isize;
    // Each row of texels 2y−2 … 2y+3 once, then the 13 box averages from them.
    for (i, o) in out.iter_mut().enumerate() {
        let x2 = 2 * i as isize;
        let t = |dx: isize, dy: isize| src.at(x2 + dx, y2 + dy);
        // A(dx, dy): the 2×2 box with top-left texel (2i+dx, 2j+dy).
        let boxed = |dx: isize, dy: isize| {
            let (a, b, c, d) = (t(dx, dy), t(dx + 1, dy), t(dx, dy + 1), t(dx + 1, dy + 1));
            [0, 1, 2].map(|k| 0.25 * (a[k] + b[k] + c[k] + d[k]))
        };
        let mut acc = [0.0f32; 3];
        madd(&mut acc, 0.125, boxed(0, 0));
        madd(&mut acc, 0.125, boxed(-1, -1));
        madd(&mut acc, 0.125, boxed(1, -1));
        madd(&mut acc, 0.125, boxed(-1, 1));
        madd(&mut acc, 0.125, boxed(1, 1));
        madd(&mut acc, 0.0625, boxed(0, -2));
        madd(&mut acc, 0.0625, boxed(-2, 0));
        madd(&mut acc, 0.0625, boxed(2, 0));
        madd(&mut acc, 0.0625, boxed(0, 2));
        madd(&mut acc, 0.03125, boxed(-2, -2));
        madd(&mut acc, 0.03125, boxed(2, -2));
        madd(&mut acc, 0.03125, boxed(-2, 2));
        madd(&mut acc, 0.03125, boxed(2, 2));
        *o = acc;
    }
}

/// The 1-D tent of step 3 for high texel `i`: the first low texel read and the four weights.
#[inline]
pub fn tent(i: usize) -> (isize, [f32; 4]) {
    let j = (i / 2) as isize;
    if i.is_multiple_of(2) {
        (j - 2, [1.0 / 16.0, 5.0 / 16.0, 7.0 / 16.0, 3.0 / 16.0])
    } else {
        (j - 1, [3.0 / 16.0, 7.0 / 16.0, 5.0 / 16.0, 1.0 / 16.0])
    }
}

/// Step 3: row `y` of the level above `low` (`out.len()` texels wide): `base` (the level's own
/// `D`, if any) plus the tent of `low` (which holds the rows the tent reads).
pub fn up_row(low: &Plane, y: usize, base: Option<&[[f32; 3]]>, out: &mut [[f32; 3]]) {
    let (y0, wy) = tent(y);
    for (i, o) in out.iter_mut().enumerate() {
        let (x0, wx) = tent(i);
        let mut acc = [0.0f32; 3];
        for (dy, &ky) in wy.iter().enumerate() {
            let mut row = [0.0f32; 3];
            for (dx, &kx) in wx.iter().enumerate() {
                madd(&mut row, kx, low.at(x0 + dx as isize, y0 + dy as isize));
            }
            madd(&mut acc, ky, row);
        }
        if let Some(b) = base {
            acc = [0, 1, 2].map(|k| b[i][k] + acc[k]);
        }
        *o = acc;
    }
}

/// Step 4's downsample: one row, `src` (`width`) to `out` (`half(width)`), along `x` only.
pub fn down_row_h(src: &[[f32; 3]], out: &mut [[f32; 3]]) {
    const W: [f32; 6] = [1.0 / 16.0, 3.0 / 16.0, 4.0 / 16.0, 4.0 / 16.0, 3.0 / 16.0, 1.0 / 16.0];
    let last = src.len() as isize - 1;
    for (i, o) in out.iter_mut().enumerate() {
        let mut acc = [0.0f32; 3];
        for (d, &w) in W.iter().enumerate() {
            let x = (2 * i as isize - 2 + d as isize).clamp(0, last) as usize;
            madd(&mut acc, w, src[x]);
        }
        *o = acc;
    }
}

/// Step 4's upsample: one row, `base` (or zero) plus the 1-D tent of `low`, into `out`.
pub fn up_row_h(low: &[[f32; 3]], base: Option<&[[f32; 3]]>, out: &mut [[f32; 3]]) {
    let last = low.len() as isize - 1;
    for (i, o) in out.iter_mut().enumerate() {
        let (x0, wx) = tent(i);
        let mut acc = [0.0f32; 3];
        for (dx, &kx) in wx.iter().enumerate() {
            madd(&mut acc, kx, low[(x0 + dx as isize).clamp(0, last) as usize]);
        }
        if let Some(b) = base {
            acc = [0, 1, 2].map(|k| b[i][k] + acc[k]);
        }
        *o = acc;
    }
}

/// One level of a [`Plan`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlanLevel {
    /// The level's size.
    pub width: usize,
    /// The level's height.
    pub height: usize,
    /// Rows of `D_k` the band needs.
    pub down: Range<usize>,
    /// Rows of `U_k` the band needs (within `down`).
    pub up: Range<usize>,
}

/// Which rows of every level a band of output rows reads (levels `1 … N`), and the rows of the
/// linear image (`source`) the band needs: the band and its halo.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Plan {
    /// Rows of the linear image (level 0) read: the band's rows and the prefilter's halo.
    pub source: Range<usize>,
    /// The output rows.
    pub band: Range<usize>,
    /// Levels `1 … N` (`levels[0]` is level 1).
    pub levels: Vec<PlanLevel>,
}

/// Rows `a ..= b` of a low level an upsample of high rows `r` reads (clamped to `h`).
fn up_source(r: &Range<usize>, h: usize) -> Range<usize> {
    let a = (r.start / 2).saturating_sub(2);
    let b = ((r.end - 1) / 2 + 2).min(h - 1);
    a..b + 1
}

/// Rows of a high level a downsample into rows `r` reads (clamped to `h`).
fn down_source(r: &Range<usize>, h: usize) -> Range<usize> {
    let a = (2 * r.start).saturating_sub(2);
    let b = (2 * (r.end - 1) + 3).min(h - 1);
    a..b + 1
}

fn hull(a: &Range<usize>, b: &Range<usize>) -> Range<usize> {
    a.start.min(b.start)..a.end.max(b.end)
}

impl Plan {
    /// The plan of a `width × height` image with `n` levels for the output rows `band`
    /// (non-empty, within the image).
    pub fn new(width: usize, height: usize, n: u32, band: Range<usize>) -> Plan {
        let n = n.clamp(1, MAX_LEVELS) as usize;
        let mut sizes = vec![(width.max(1), height.max(1))];
        for k in 1..=n {
            let (w, h) = sizes[k - 1];
            sizes.push((half(w), half(h)));
        }
        let mut up = vec![0..0; n + 1];
        up[0] = band.clone();
        for k in 1..=n {
            up[k] = up_source(&up[k - 1], sizes[k].1);
        }
        let mut down = vec![0..0; n + 1];
        down[n] = up[n].clone();
        for k in (1..n).rev() {
            down[k] = hull(&up[k], &down_source(&down[k + 1], sizes[k].1));
        }
        let source = hull(&band, &down_source(&down[1], sizes[0].1));
        let levels = (1..=n)
            .map(|k| PlanLevel {
                width: sizes[k].0,
                height: sizes[k].1,
                down: down[k].clone(),
                up: up[k].clone(),
            })
            .collect();
        Plan { source, band, levels }
    }
}

/// The rows of the linear image a band `band` of a `height`-row image needs for `params`: the
/// band with the bloom's halo (the streak's rows lie within it).
pub fn source_rows(params: &BloomParams, width: usize, height: usize, band: Range<usize>) -> Range<usize> {
    let n = levels(params.radius * height as f32);
    Plan::new(width, height, n, band).source
}

/// The texel buffers of planes a glare no longer needs, kept for the next ones
/// ([`Plane::try_new_in`], [`PlanePool::give`]): a renderer that keeps one from frame to frame
/// allocates its glare's planes once, not every frame (fresh pages cost more than the filters on
/// them). Every texel of a glare's plane is written before it is read, so a pool changes no result
/// (`tests/bloom.rs` runs the chain on a pool of poisoned buffers).
#[derive(Debug, Default)]
pub struct PlanePool {
    free: Vec<Vec<[f32; 3]>>,
}

impl PlanePool {
    /// The free buffer that already holds `n` texels with the least to spare (nothing to fill in),
    /// else the one with room for `n` with the least room (its texels filled in up to `n`, no
    /// fresh pages), else the largest (which grows), else a new one; its texels as they were.
    fn take(&mut self, n: usize) -> Vec<[f32; 3]> {
        let len = |i: &usize| self.free[*i].len();
        let cap = |i: &usize| self.free[*i].capacity();
        let held = (0..self.free.len()).filter(|i| len(i) >= n).min_by_key(len);
        let fits = || (0..self.free.len()).filter(|i| cap(i) >= n).min_by_key(cap);
        let pick = held.or_else(fits).or_else(|| (0..self.free.len()).max_by_key(cap));
        pick.map(|i| self.free.swap_remove(i)).unwrap_or_default()
    }

    /// Keeps `plane`'s texel buffer for a later plane.
    pub fn give(&mut self, plane: Plane) {
        self.free.push(plane.data);
    }

    /// The bytes the kept buffers hold.
    pub fn bytes(&self) -> usize {
        self.free.iter().map(|v| v.capacity() * std::mem::size_of::<[f32; 3]>()).sum()
    }
}

/// How the chain fills a plane's rows: one row at a time here ([`Sequential`]), in parallel in a
/// renderer. `f(y, row)` must be called once for every row `y` of `plane.rows`.
pub trait RowFill {
    /// Calls `f(y, row)` for every row of `plane`.
    fn fill(&self, plane: &mut Plane, f: &(dyn Fn(usize, &mut [[f32; 3]]) + Sync));

    /// Calls `f(rows, a_rows, b_rows)` for the blocks of `block` rows of `a` (the last one
    /// shorter) and the same rows of `b` (which holds `a`'s rows; `None`: no second plane, an
    /// empty slice). One block after the other here; a renderer may run them in parallel.
    fn fill_blocks(&self, a: &mut Plane, b: Option<&mut Plane>, block: usize, f: &BlockFn<'_>) {
        let (y0, block) = (a.rows.start, block.max(1));
        let (wa, wb) = (a.width, b.as_ref().map_or(0, |b| b.width));
        let mut b = b.map(|b| b.data.chunks_mut(wb * block));
        for (i, ca) in a.data.chunks_mut(wa * block).enumerate() {
            let cb = b.as_mut().and_then(|b| b.next()).unwrap_or_default();
            let start = y0 + i * block;
            f(start..start + ca.len() / wa, ca, cb);
        }
    }
}

/// What [`RowFill::fill_blocks`] calls per block.
pub type BlockFn<'a> = dyn Fn(Range<usize>, &mut [[f32; 3]], &mut [[f32; 3]]) + Sync + 'a;

/// Rows one after the other.
#[derive(Clone, Copy, Debug, Default)]
pub struct Sequential;

impl RowFill for Sequential {
    fn fill(&self, plane: &mut Plane, f: &(dyn Fn(usize, &mut [[f32; 3]]) + Sync)) {
        let (w, y0) = (plane.width, plane.rows.start);
        for (r, row) in plane.data.chunks_mut(w).enumerate() {
            f(y0 + r, row);
        }
    }
}

/// The streak's first row at level-1 height: row `j` of the half-height image, the average
/// `(0 + ½·a) + ½·b` of the prefiltered rows `a = T(2j)` and `b = T(min(2j + 1, h − 1))`.
pub fn pair_row(a: &[[f32; 3]], b: &[[f32; 3]], out: &mut [[f32; 3]]) {
    for ((o, a), b) in out.iter_mut().zip(a).zip(b) {
        *o = std::array::from_fn(|k| (0.0 + 0.5 * a[k]) + 0.5 * b[k]);
    }
}

/// The streak's `U₁ʰ` of one half-height row `t` ([`pair_row`]) with `n` levels, into `out`
/// (`half(t.len())` texels): `D₁ʰ = down_h(t)`, …, `U_Nʰ = D_Nʰ`, `U_kʰ = D_kʰ + up_h(U_{k+1}ʰ)`.
pub fn streak_row(t: &[[f32; 3]], n: u32, out: &mut [[f32; 3]]) {
    let n = n.clamp(1, MAX_LEVELS) as usize;
    let mut down: Vec<Vec<[f32; 3]>> = Vec::with_capacity(n);
    for k in 0..n {
        let src: &[[f32; 3]] = if k == 0 { t } else { &down[k - 1] };
        let mut d = vec![[0.0; 3]; half(src.len())];
        down_row_h(src, &mut d);
        down.push(d);
    }
    // U_N = D_N; U_k = D_k + up(U_{k+1}).
    let mut u = down.pop().unwrap_or_default();
    while let Some(d) = down.pop() {
        let mut next = vec![[0.0; 3]; d.len()];
        up_row_h(&u, Some(&d), &mut next);
        u = next;
    }
    out.copy_from_slice(&u);
}

/// The horizontal half of the level-1 blur: `((0 + ¼·r[x−1]) + ½·r[x]) + ¼·r[x+1]` (clamped).
pub fn blur_row_h(row: &[[f32; 3]], out: &mut [[f32; 3]]) {
    let last = row.len() as isize - 1;
    for (x, o) in out.iter_mut().enumerate() {
        let mut acc = [0.0f32; 3];
        for (d, &w) in BLUR.iter().enumerate() {
            madd(&mut acc, w, row[(x as isize - 1 + d as isize).clamp(0, last) as usize]);
        }
        *o = acc;
    }
}

/// The `[1, 2, 1]/4` blur, once per axis, that with the bilinear tap makes the tent.
pub const BLUR: [f32; 3] = [0.25, 0.5, 0.25];

/// Row `y` of the glare `G` at level 1 (step 5): from the horizontal blurs `hb` of `U₁`
/// ([`blur_row_h`]) and `hs` of the streak's `U₁ʰ` (`None`: no streak),
/// `(((0 + kb·¼·hb[y−1]) + kb·½·hb[y]) + kb·¼·hb[y+1]) + ks·hs[y]` (rows clamped, each weight
/// product rounded once).
pub fn glare_row(hb: &Plane, hs: Option<&Plane>, y: usize, kb: f32, ks: f32, out: &mut [[f32; 3]]) {
    let w = glare_weights(kb, ks);
    for (x, o) in out.iter_mut().enumerate() {
        let mut acc = [0.0f32; 3];
        for (d, &wd) in w[..3].iter().enumerate() {
            madd(&mut acc, wd, hb.at(x as isize, y as isize - 1 + d as isize));
        }
        if let Some(hs) = hs {
            madd(&mut acc, w[3], hs.at(x as isize, y as isize));
        }
        *o = acc;
    }
}

/// The weights of [`glare_row`]: `kb·¼, kb·½, kb·¼, ks`.
pub fn glare_weights(kb: f32, ks: f32) -> [f32; 4] {
    [kb * BLUR[0], kb * BLUR[1], kb * BLUR[2], ks]
}

/// The bilinear tap of a full-resolution texel `i` from level 1 (either axis): the first level-1
/// texel read and the two weights (`2j`: `j−1, j` by `¼, ¾`; `2j+1`: `j, j+1` by `¾, ¼`).
#[inline]
pub fn bilinear(i: usize) -> (isize, [f32; 2]) {
    let j = (i / 2) as isize;
    if i.is_multiple_of(2) {
        (j - 1, [0.25, 0.75])
    } else {
        (j, [0.75, 0.25])
    }
}

/// Rows of level 1 (`height` rows) that the bilinear taps of the full-resolution rows `r` read.
pub fn bilinear_rows(r: &Range<usize>, height: usize) -> Range<usize> {
    let a = (r.start / 2).saturating_sub(1);
    let b = ((r.end - 1) / 2 + 1).min(height - 1);
    a..b + 1
}

/// Row `y` of the full-resolution glare from `g` ([`glare_row`]'s plane, which holds the rows
/// [`bilinear_rows`] names): the vertical pair `(0 + wa·g[ya]) + wb·g[yb]` first, then along the
/// row the horizontal pair the same way; `out.len()` texels.
pub fn upsample_row(g: &Plane, y: usize, out: &mut [[f32; 3]]) {
    let (y0, wy) = bilinear(y);
    let (r0, r1) = (g.row(clamp_row(y0, g.height)), g.row(clamp_row(y0 + 1, g.height)));
    let last = g.width as isize - 1;
    let v = |x: isize| {
        let x = x.clamp(0, last) as usize;
        let mut acc = [0.0f32; 3];
        madd(&mut acc, wy[0], r0[x]);
        madd(&mut acc, wy[1], r1[x]);
        acc
    };
    for (x, o) in out.iter_mut().enumerate() {
        let (x0, wx) = bilinear(x);
        let mut acc = [0.0f32; 3];
        madd(&mut acc, wx[0], v(x0));
        madd(&mut acc, wx[1], v(x0 + 1));
        *o = acc;
    }
}

#[inline]
fn clamp_row(y: isize, height: usize) -> usize {
    y.clamp(0, height as isize - 1) as usize
}

/// The glare of steps 1–6 over the rows `band` of a `src.width × src.height` linear image: `src`
/// holds at least the rows `source_rows` names; returns the band's composited colour.
pub fn glare(params: &BloomParams, src: &Plane, band: Range<usize>, fill: &dyn RowFill) -> Plane {
    try_glare(params, src, band, fill).unwrap_or_else(|bytes| panic!("the glare's planes need {bytes} bytes"))
}

/// [`glare`], each plane reserved fallibly: `Err(bytes)`, the size of the plane that could not
/// be allocated, where memory ran out (never an abort). Texel by texel with the kernels above:
/// the definition that the chain in lanes (`lanes::try_glare`, which renderers run) equals bit
/// for bit.
pub fn try_glare(
    params: &BloomParams,
    src: &Plane,
    band: Range<usize>,
    fill: &dyn RowFill,
) -> Result<Plane, usize> {
    let (w, h) = (src.width, src.height);
    let n = levels(params.radius * h as f32);
    let plan = Plan::new(w, h, n, band.clone());
    let (th, kn) = (params.threshold, params.soft_knee);
    // T over the source rows (the streak reads the band's rows of it too).
    let mut t = Plane::try_new(w, h, plan.source.clone())?;
    fill.fill(&mut t, &|y, row| {
        for (o, c) in row.iter_mut().zip(src.row(y)) {
            *o = prefilter(*c, th, kn);
        }
    });
    let mut downs: Vec<Plane> = Vec::with_capacity(plan.levels.len());
    for l in &plan.levels {
        let mut d = Plane::try_new(l.width, l.height, l.down.clone())?;
        let prev = downs.last().unwrap_or(&t);
        fill.fill(&mut d, &|y, row| down_row(prev, y, row));
        downs.push(d);
    }
    let mut u = downs.pop().unwrap_or_default();
    while let Some(d) = downs.pop() {
        let l = &plan.levels[downs.len()];
        let mut next = Plane::try_new(l.width, l.height, l.up.clone())?;
        fill.fill(&mut next, &|y, row| up_row(&u, y, Some(d.row(y)), row));
        u = next;
    }
    let (kb, ks) = weights(params, h);
    let l1 = &plan.levels[0];
    let mut hb = Plane::try_new(l1.width, l1.height, l1.up.clone())?;
    fill.fill(&mut hb, &|y, row| blur_row_h(u.row(y), row));
    drop(u);
    let hs = if ks > 0.0 {
        let ns = levels(params.streak_length * h as f32);
        let mut hs = Plane::try_new(l1.width, l1.height, l1.up.clone())?;
        fill.fill(&mut hs, &|y, row| {
            let mut pair = vec![[0.0f32; 3]; w];
            pair_row(t.row(2 * y), t.row((2 * y + 1).min(h - 1)), &mut pair);
            let mut s = vec![[0.0f32; 3]; l1.width];
            streak_row(&pair, ns, &mut s);
            blur_row_h(&s, row);
        });
        Some(hs)
    } else {
        None
    };
    let mut g = Plane::try_new(l1.width, l1.height, bilinear_rows(&band, l1.height))?;
    fill.fill(&mut g, &|y, row| glare_row(&hb, hs.as_ref(), y, kb, ks, row));
    let mut out = Plane::try_new(w, h, band)?;
    fill.fill(&mut out, &|y, row| {
        upsample_row(&g, y, row);
        for (o, c) in row.iter_mut().zip(src.row(y)) {
            *o = composite(*c, *o);
        }
    });
    Ok(out)
}

/// The glare's two weights for a `height`-row image: `(intensity/N, streak/N_s)`.
pub fn weights(params: &BloomParams, height: usize) -> (f32, f32) {
    let n = levels(params.radius * height as f32);
    let ns = levels(params.streak_length * height as f32);
    (params.intensity / n as f32, params.streak / ns as f32)
}
