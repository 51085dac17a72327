//! The glare chain of [`super`] (hadou's own; SPEC.md has no glare) over flat rows, eight lanes at
//! a time: the soft threshold ([`prefilter_row`]) and every level from the first downsample on (the
//! 13-tap downsample, the tent upsample, the streak) as weighted sums of whole rows, each texel from the same texels, the same weights and the same additions in the same
//! order as the texel-by-texel kernels ([`super::down_row`], [`super::up_row`],
//! [`super::down_row_h`], [`super::up_row_h`]), with no fused multiply-add: the planes are those
//! kernels' bit for bit, on every vector path (`tests/bloom.rs` holds them together).
//!
//! The rows are read through copies padded by clamping at the edges and split into even and odd
//! texels, so that each of the filters' taps is one contiguous slice:
//! - the downsample's 2×2 box averages `A` are whole rows of boxes (the even-`x` boxes of rows
//!   `2j−2, 2j, 2j+2` and the odd-`x` ones of rows `2j ± 1`), and its thirteen taps are those
//!   rows shifted by a texel;
//! - the tent is separable as written (each low row's four horizontal taps summed first, then the
//!   four rows): the horizontal sums of every low row are made once into a plane of their own
//!   ([`up_plane`]), and each high row sums four of its rows;
//! - the glare at level 1 and its bilinear tap ([`glare_row`], [`upsample_row`]) the same way:
//!   the vertical weights over whole rows, the horizontal ones over a padded row split into the
//!   even and odd texels of the output.
//!
//! [`try_glare_plane`] makes the prefilter, the first downsample and the streak's first level in
//! one pass over the linear image, in blocks of level-1 rows whose prefiltered rows are made and
//! split once (no prefiltered plane: each texel's soft threshold is written straight to its even
//! or odd slot, and eight texels all below the knee, where the threshold gives `+0` exactly, skip
//! its arithmetic); a renderer then reads each output row once for the tap, the composite
//! ([`upsample_composite_row`]) and its colour mapping.

use super::{
    bilinear, composite, half, levels, tent, BloomParams, Plan, Plane, PlanePool, RowFill, BLUR, MAX_LEVELS,
};
use crate::simd::{dispatch, Lane, SimdPath, WithLanes};

/// The downsample's weights in its order of summation (see [`super::down_row`]).
const DOWN_W: [f32; 13] =
    [0.125, 0.125, 0.125, 0.125, 0.125, 0.0625, 0.0625, 0.0625, 0.0625, 0.03125, 0.03125, 0.03125, 0.03125];

/// The streak's 1-D downsample weights (see [`super::down_row_h`]).
const DOWN_H_W: [f32; 6] = [1.0 / 16.0, 3.0 / 16.0, 4.0 / 16.0, 4.0 / 16.0, 3.0 / 16.0, 1.0 / 16.0];

/// `out[k] = base[k] + (((0 + w₀·s₀[k]) + w₁·s₁[k]) + …)` (no `base`: the sum alone), in lanes.
struct WeightedSum<'a, const N: usize> {
    srcs: [&'a [f32]; N],
    w: [f32; N],
    base: Option<&'a [f32]>,
    out: &'a mut [f32],
}

impl<const N: usize> WithLanes for WeightedSum<'_, N> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(self) {
        let n = self.out.len();
        let mut ws = [L::splat(0.0); N];
        for (l, &w) in ws.iter_mut().zip(&self.w) {
            *l = L::splat(w);
        }
        // Every slice cut to `n` and seen as blocks of eight, so the loop's reads need no bounds
        // checks.
        let srcs: [&[f32]; N] = self.srcs.map(|s| &s[..n]);
        let blocks: [&[[f32; 8]]; N] = srcs.map(|s| s.as_chunks::<8>().0);
        let base = self.base.map(|b| &b[..n]);
        let base_blocks = base.map(|b| b.as_chunks::<8>().0);
        let (out, tail) = self.out.as_chunks_mut::<8>();
        let m = out.len();
        for c in 0..m {
            let mut acc = L::splat(0.0);
            for t in 0..N {
                acc += ws[t] * L::from_array(blocks[t][c]);
            }
            if let Some(b) = base_blocks {
                acc += L::from_array(b[c]);
            }
            out[c] = acc.to_array();
        }
        for (i, o) in tail.iter_mut().enumerate() {
            let k = 8 * m + i;
            let mut acc = 0.0f32;
            for (&w, s) in self.w.iter().zip(&srcs) {
                acc += w * s[k];
            }
            if let Some(b) = base {
                acc += b[k];
            }
            *o = acc;
        }
    }
}

/// Floats `k … k+7` of `s` as lanes.
#[inline(always)]
fn load<L: Lane>(s: &[f32], k: usize) -> L {
    L::from_array(s[k..k + 8].try_into().expect("eight floats"))
}

/// `out[k] = ¼·(((a[k] + b[k]) + c[k]) + d[k])`, the 2×2 box average, in lanes.
struct BoxSum<'a> {
    srcs: [&'a [f32]; 4],
    out: &'a mut [f32],
}

impl WithLanes for BoxSum<'_> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(self) {
        let n = self.out.len();
        let [a, b, c, d] = self.srcs;
        let lane = load::<L>;
        let q = L::splat(0.25);
        let mut k = 0;
        while k + 8 <= n {
            let v = q * (((lane(a, k) + lane(b, k)) + lane(c, k)) + lane(d, k));
            self.out[k..k + 8].copy_from_slice(&v.to_array());
            k += 8;
        }
        for k in k..n {
            self.out[k] = 0.25 * (((a[k] + b[k]) + c[k]) + d[k]);
        }
    }
}

/// [`super::prefilter`] of a row of texels, eight at a time: the same comparisons, selects and
/// arithmetic per lane (so the same bits), texels gathered into a lane per channel.
struct PrefilterRow<'a> {
    src: &'a [[f32; 3]],
    out: &'a mut [[f32; 3]],
    threshold: f32,
    soft_knee: f32,
}

/// The soft threshold's constants as lanes: `threshold`, the knee `k = threshold·soft_knee`, `2k`,
/// `4k` (and `k` itself, whose sign picks the knee).
struct Knee<L> {
    k: f32,
    th: L,
    lk: L,
    l2k: L,
    l4k: L,
}

impl<L: Lane> Knee<L> {
    #[inline(always)]
    fn new(threshold: f32, soft_knee: f32) -> Self {
        let k = threshold * soft_knee;
        Knee { k, th: L::splat(threshold), lk: L::splat(k), l2k: L::splat(2.0 * k), l4k: L::splat(4.0 * k) }
    }

    /// [`super::prefilter`] of eight texels (`s`), as three channel arrays: the same comparisons,
    /// selects and arithmetic per lane, so the same bits.
    #[inline(always)]
    fn eight(&self, s: &[[f32; 3]]) -> [[f32; 8]; 3] {
        let (zero, max, clamp) = (L::splat(0.0), L::splat(f32::MAX), L::splat(super::BLOOM_CLAMP));
        let mut ch = [zero; 3];
        for (c, lane) in ch.iter_mut().enumerate() {
            let mut a = [0.0f32; 8];
            for j in 0..8 {
                a[j] = s[j][c];
            }
            // NaN → 0, then clamped to [0, f32::MAX] as `f32::clamp` does.
            let v = L::from_array(a);
            let v = v.simd_lt(zero).select(zero, v);
            let v = v.simd_gt(max).select(max, v);
            *lane = v.is_nan().select(zero, v);
        }
        let b = ch[0].max(ch[1]).max(ch[2]);
        let q = if self.k > 0.0 {
            let x = (b - self.th) + self.lk;
            let x = x.simd_lt(zero).select(zero, x);
            let x = x.simd_gt(self.l2k).select(self.l2k, x);
            x * x / self.l4k
        } else {
            zero
        };
        let w = q.max(b - self.th) / b;
        let dark = b.simd_le(zero);
        let mut r = [[0.0f32; 8]; 3];
        for c in 0..3 {
            r[c] = dark.select(zero, (ch[c] * w).min(clamp)).to_array();
        }
        r
    }
}

impl<L: Lane> Knee<L> {
    /// Whether all eight texels `s` are below the knee, where the soft threshold gives exactly
    /// `+0` in every channel: each channel `v`, negative ones read as 0, has `(v − threshold) + k
    /// ≤ 0` and `v − threshold < 0` (so `q = +0` and `max(q, b − threshold) = +0` whatever the
    /// channel that makes `b`: rounding keeps both monotonic) and no sign bit (a `−0` channel
    /// would give `−0`); NaN and infinite channels fail the tests.
    #[inline(always)]
    fn dark(&self, s: &[[f32; 3]]) -> bool {
        let zero = L::splat(0.0);
        let (flat, _) = s.as_flattened().as_chunks::<8>();
        let mut dark = true;
        for &a in &flat[..3] {
            let v = L::from_array(a);
            let v = v.simd_lt(zero).select(zero, v);
            let below = v - self.th;
            dark &= (below + self.lk).simd_le(zero).bitmask() == 0xff
                && below.simd_lt(zero).bitmask() == 0xff
                && v.is_sign_negative().bitmask() == 0;
        }
        dark
    }
}

impl WithLanes for PrefilterRow<'_> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(self) {
        let (th, kn) = (self.threshold, self.soft_knee);
        let knee = Knee::<L>::new(th, kn);
        let mut src = self.src.chunks_exact(8);
        let mut out = self.out.chunks_exact_mut(8);
        for (s, o) in (&mut src).zip(&mut out) {
            let r = knee.eight(s);
            for j in 0..8 {
                o[j] = [r[0][j], r[1][j], r[2][j]];
            }
        }
        for (s, o) in src.remainder().iter().zip(out.into_remainder()) {
            *o = super::prefilter(*s, th, kn);
        }
    }
}

/// [`split`] of [`super::prefilter`] of a row, without the prefiltered row in between: each
/// texel's eight-lane soft threshold written straight to its even or odd slot.
struct PrefilterSplit<'a> {
    src: &'a [[f32; 3]],
    even: &'a mut [[f32; 3]],
    odd: &'a mut [[f32; 3]],
    threshold: f32,
    soft_knee: f32,
}

impl WithLanes for PrefilterSplit<'_> {
    /// Whether every texel's soft threshold is `+0` (each run of eight below the knee, the
    /// remainder's values `+0`).
    type Output = bool;
    #[inline(always)]
    fn run<L: Lane>(self) -> bool {
        let (th, kn) = (self.threshold, self.soft_knee);
        let knee = Knee::<L>::new(th, kn);
        let (ev, od) = (self.even, self.odd);
        // Texel 2p goes to even[p + 1] and texel 2p + 1 to odd[p + 1] (split's unclamped slots).
        let (ev, od) = (&mut ev[1..], &mut od[1..]);
        let mut src = self.src.chunks_exact(8);
        let mut zero = true;
        for (c, s) in (&mut src).enumerate() {
            let p0 = 4 * c;
            // Most of a picture lies below the knee: nothing to gather, weigh and scatter.
            if knee.dark(s) {
                ev[p0..p0 + 4].fill([0.0; 3]);
                od[p0..p0 + 4].fill([0.0; 3]);
                continue;
            }
            zero = false;
            let r = knee.eight(s);
            // Whole blocks of four pairs fit (the caller sizes the halves to the row).
            for (i, (e, o)) in ev[p0..p0 + 4].iter_mut().zip(&mut od[p0..p0 + 4]).enumerate() {
                *e = [r[0][2 * i], r[1][2 * i], r[2][2 * i]];
                *o = [r[0][2 * i + 1], r[1][2 * i + 1], r[2][2 * i + 1]];
            }
        }
        let x0 = self.src.len() - src.remainder().len();
        for (i, s) in src.remainder().iter().enumerate() {
            let (x, t) = (x0 + i, super::prefilter(*s, th, kn));
            zero &= is_plus_zero(t);
            match x % 2 {
                0 => ev[x / 2] = t,
                _ => od[x / 2] = t,
            }
        }
        zero
    }
}

/// Whether every channel of `t` is `+0` (bit for bit).
#[inline]
fn is_plus_zero(t: [f32; 3]) -> bool {
    t.iter().all(|v| v.to_bits() == 0)
}

/// [`split`] of the prefiltered `row` (`count` texels a half): `even[m] = T(row[clamp(2m − 2)])`,
/// `odd[m] = T(row[clamp(2m − 1)])`, `T` [`super::prefilter`], in lanes; `count` is at least
/// `row.len()/2 + 2` ([`first_level`]'s rows), so every texel of the row has its slot. Returns
/// whether every slot is `+0`: then every sum over the row is `+0` too.
fn prefilter_split(
    path: SimdPath,
    row: &[[f32; 3]],
    count: usize,
    (threshold, soft_knee): (f32, f32),
    even: &mut Vec<f32>,
    odd: &mut Vec<f32>,
) -> bool {
    debug_assert!(count >= row.len() / 2 + 2, "{count} slots for {} texels", row.len());
    even.resize(3 * count, 0.0);
    odd.resize(3 * count, 0.0);
    let (ev, od) = (even.as_chunks_mut::<3>().0, odd.as_chunks_mut::<3>().0);
    let zero =
        dispatch(path, PrefilterSplit { src: row, even: &mut *ev, odd: &mut *od, threshold, soft_knee });
    // The clamped slots: m = 0 reads texel 0, m past the row's end its last texel.
    let (first, last) = (row[0], row[row.len() - 1]);
    let (first, last) =
        (super::prefilter(first, threshold, soft_knee), super::prefilter(last, threshold, soft_knee));
    (ev[0], od[0]) = (first, first);
    let inner = row.len() / 2;
    for m in inner + 1..count {
        (ev[m], od[m]) = (last, last);
    }
    zero && is_plus_zero(first) && is_plus_zero(last)
}

/// [`super::prefilter`] of every texel of `src` into `out`, in lanes.
pub fn prefilter_row(path: SimdPath, src: &[[f32; 3]], threshold: f32, soft_knee: f32, out: &mut [[f32; 3]]) {
    dispatch(path, PrefilterRow { src, out, threshold, soft_knee });
}

/// [`WeightedSum`] of `N` slices of `src`, tap `t` starting `3·offsets[t]` floats (texels) in,
/// into `out`.
fn taps<const N: usize>(
    path: SimdPath,
    src: [&[f32]; N],
    offsets: [usize; N],
    w: [f32; N],
    base: Option<&[f32]>,
    out: &mut [f32],
) {
    let n = out.len();
    let srcs = std::array::from_fn(|t| &src[t][3 * offsets[t]..3 * offsets[t] + n]);
    dispatch(path, WeightedSum { srcs, w, base, out });
}

/// Rows a kernel works in, kept per thread between calls ([`with_scratch`]) so that a row costs
/// no allocation once the buffers have grown.
#[derive(Default)]
struct Scratch {
    /// Flat rows of floats.
    rows: Vec<Vec<f32>>,
    /// The streak's levels.
    levels: Vec<Vec<[f32; 3]>>,
    /// The prefiltered rows of a block of level 1, each split into even and odd padded texels.
    block: Vec<Vec<f32>>,
    /// The 2×2 box rows of a block of level 1 (every box row its rows share, made once).
    boxes: Vec<Vec<f32>>,
    /// Which of the block's source rows are `+0` in every slot once prefiltered.
    zero: Vec<bool>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::default();
}

/// Runs `f` with this thread's [`Scratch`] (at least `rows` rows); `f` must not call it again.
fn with_scratch<R>(rows: usize, f: impl FnOnce(&mut Scratch) -> R) -> R {
    SCRATCH.with(|s| {
        let mut s = s.borrow_mut();
        if s.rows.len() < rows {
            s.rows.resize_with(rows, Vec::new);
        }
        f(&mut s)
    })
}

/// `row`'s texels padded by clamping, split: `even[m] = row[clamp(2m − 2)]`,
/// `odd[m] = row[clamp(2m − 1)]` for `m < count` (flat, three floats a texel). The texels whose
/// index needs no clamping are copied pair by pair, the few at either end one by one.
fn split(row: &[[f32; 3]], count: usize, even: &mut Vec<f32>, odd: &mut Vec<f32>) {
    let last = row.len() as isize - 1;
    even.resize(3 * count, 0.0);
    odd.resize(3 * count, 0.0);
    if count == 0 {
        return;
    }
    let (ev, od) = (even.as_chunks_mut::<3>().0, odd.as_chunks_mut::<3>().0);
    // m in 1..=inner reads the pair row[2m − 2], row[2m − 1] unclamped.
    let inner = (row.len() / 2).min(count.saturating_sub(1));
    let (pairs, _) = row.as_chunks::<2>();
    for ((e, o), p) in ev[1..=inner].iter_mut().zip(od[1..=inner].iter_mut()).zip(&pairs[..inner]) {
        *e = p[0];
        *o = p[1];
    }
    for m in std::iter::once(0).chain(inner + 1..count) {
        let x = 2 * m as isize;
        ev[m] = row[(x - 2).clamp(0, last) as usize];
        od[m] = row[(x - 1).clamp(0, last) as usize];
    }
}

/// `out[2j] = even[j]`, `out[2j + 1] = odd[j]` (`even` holds `⌈n/2⌉` texels, `odd` `⌊n/2⌋`).
fn interleave(even: &[[f32; 3]], odd: &[[f32; 3]], out: &mut [[f32; 3]]) {
    let (pairs, tail) = out.as_chunks_mut::<2>();
    for ((p, e), o) in pairs.iter_mut().zip(even).zip(odd) {
        *p = [*e, *o];
    }
    if let Some(t) = tail.first_mut() {
        *t = even[pairs.len()];
    }
}

/// `b + t` per channel.
#[inline(always)]
fn add3(b: [f32; 3], t: [f32; 3]) -> [f32; 3] {
    [b[0] + t[0], b[1] + t[1], b[2] + t[2]]
}

/// [`interleave`] added to a base: `out[i] = base[i] + t[i]`, `t` the interleaved row (`base`
/// `None`: what `out` holds). The sum the lanes would make with the base as a last tap, `t + b`,
/// is the same float (addition commutes), without the base split into even and odd texels.
fn interleave_add(even: &[[f32; 3]], odd: &[[f32; 3]], base: Option<&[[f32; 3]]>, out: &mut [[f32; 3]]) {
    let (pairs, tail) = out.as_chunks_mut::<2>();
    let n = pairs.len();
    match base {
        None => {
            for ((p, e), o) in pairs.iter_mut().zip(even).zip(odd) {
                *p = [add3(p[0], *e), add3(p[1], *o)];
            }
            if let Some(t) = tail.first_mut() {
                *t = add3(*t, even[n]);
            }
        }
        Some(b) => {
            let (bp, bt) = b.as_chunks::<2>();
            for (((p, e), o), b) in pairs.iter_mut().zip(even).zip(odd).zip(bp) {
                *p = [add3(b[0], *e), add3(b[1], *o)];
            }
            if let Some(t) = tail.first_mut() {
                *t = add3(bt[0], even[n]);
            }
        }
    }
}

/// `row`'s texels padded by clamping: `out[m] = row[clamp(m − 2)]` for `m < count` (flat).
fn pad(row: &[[f32; 3]], count: usize, out: &mut Vec<f32>) {
    let last = row.len() as isize - 1;
    out.resize(3 * count, 0.0);
    let o = out.as_chunks_mut::<3>().0;
    // m in 2..2 + inner reads row[m − 2] unclamped.
    let inner = row.len().min(count.saturating_sub(2));
    if inner > 0 {
        o[2..2 + inner].copy_from_slice(&row[..inner]);
    }
    for m in (0..2.min(count)).chain(2 + inner..count) {
        o[m] = row[(m as isize - 2).clamp(0, last) as usize];
    }
}

/// Row `y` of the next level from `src` (which holds rows `2y−2 … 2y+3`, clamped) into `out`
/// (`half(src.width)` texels): [`super::down_row`] in lanes.
pub fn down_row(path: SimdPath, src: &Plane, y: usize, out: &mut [[f32; 3]]) {
    with_scratch(17, |s| down_row_in(path, src, y, out, &mut s.rows[..17]));
}

fn down_row_in(path: SimdPath, src: &Plane, y: usize, out: &mut [[f32; 3]], s: &mut [Vec<f32>]) {
    let wo = out.len();
    let count = wo + 3;
    let last = src.height as isize - 1;
    let (splits, boxes) = s.split_at_mut(12);
    // The six source rows 2y−2 … 2y+3, each split into even and odd padded texels.
    for r in 0..6 {
        let yy = (2 * y as isize - 2 + r as isize).clamp(0, last) as usize;
        let (e, o) = splits[2 * r..2 * r + 2].split_at_mut(1);
        split(src.row(yy), count, &mut e[0], &mut o[0]);
    }
    // Box rows r = dy + 2: even-x boxes BE[m] = A at x = 2m − 2 for r = 0, 2, 4, odd-x boxes
    // BO[m] = A at x = 2m − 1 for r = 1, 3.
    for (r, bx) in boxes.iter_mut().enumerate() {
        let (e0, o0, e1, o1) = (&splits[2 * r], &splits[2 * r + 1], &splits[2 * r + 2], &splits[2 * r + 3]);
        let n = 3 * (wo + 2);
        bx.resize(n, 0.0);
        let srcs: [&[f32]; 4] = if r % 2 == 0 {
            [&e0[..n], &o0[..n], &e1[..n], &o1[..n]]
        } else {
            [&o0[..n], &e0[3..3 + n], &o1[..n], &e1[3..3 + n]]
        };
        dispatch(path, BoxSum { srcs, out: bx });
    }
    let [be0, bo1, be2, bo3, be4] = [&boxes[0], &boxes[1], &boxes[2], &boxes[3], &boxes[4]].map(|v| &v[..]);
    // The taps in super::down_row's order: A(0,0), A(−1,−1), A(1,−1), A(−1,1), A(1,1), A(0,−2),
    // A(−2,0), A(2,0), A(0,2), A(−2,−2), A(2,−2), A(−2,2), A(2,2); A(2i + dx) is BE[i + 1 + dx/2]
    // for even dx and BO[i + (dx + 1)/2] for odd dx.
    taps(
        path,
        [be2, bo1, bo1, bo3, bo3, be0, be2, be2, be4, be0, be0, be4, be4],
        [1, 0, 1, 0, 1, 1, 0, 2, 1, 0, 2, 0, 2],
        DOWN_W,
        None,
        out.as_flattened_mut(),
    );
}

/// Rows of the streak shorter than this take the texel-by-texel kernels (the same values): their
/// lanes would cost more in padding and splitting than they save.
const SHORT: usize = 16;

/// What [`tent_h`] adds to the tent.
#[derive(Clone, Copy)]
enum BaseIn<'a> {
    /// Nothing.
    None,
    /// The texels `out` holds when it is called.
    Out,
    /// These texels (as many as `out`).
    Row(&'a [[f32; 3]]),
}

/// The horizontal half of the tent: `low` (one row) to `out` (`out.len()` texels, the level
/// above's width), each high texel `i` the sum of the four taps of [`tent`]`(i)`, plus the base
/// ([`BaseIn`]). `s` holds at least three rows.
fn tent_h(path: SimdPath, low: &[[f32; 3]], base: BaseIn, out: &mut [[f32; 3]], s: &mut [Vec<f32>]) {
    let wh = out.len();
    let (ne, no) = (wh.div_ceil(2), wh / 2);
    let [q, he, ho, ..] = s else { unreachable!("three rows") };
    pad(low, ne + 4, q);
    // Even i = 2j reads low j−2 … j+1 = q[j … j+3]; odd i = 2j+1 reads j−1 … j+2 = q[j+1 … j+4].
    let (we, wo) = (tent(0).1, tent(1).1);
    he.resize(3 * ne, 0.0);
    ho.resize(3 * no, 0.0);
    taps(path, [&q[..]; 4], [0, 1, 2, 3], we, None, he);
    taps(path, [&q[..]; 4], [1, 2, 3, 4], wo, None, ho);
    let (he, ho) = (he.as_chunks::<3>().0, ho.as_chunks::<3>().0);
    match base {
        BaseIn::None => interleave(he, ho, out),
        BaseIn::Out => interleave_add(he, ho, None, out),
        BaseIn::Row(b) => interleave_add(he, ho, Some(b), out),
    }
}

/// The horizontal sums of the tent over `low` (every row it holds) at the width `width` of the
/// level above: row `y` of the result is `tent_h` of `low`'s row `y`.
pub fn up_plane(path: SimdPath, low: &Plane, width: usize, fill: &dyn RowFill) -> Result<Plane, usize> {
    up_plane_in(path, low, width, fill, &mut PlanePool::default())
}

/// [`up_plane`] into a plane from `pool`.
fn up_plane_in(
    path: SimdPath,
    low: &Plane,
    width: usize,
    fill: &dyn RowFill,
    pool: &mut PlanePool,
) -> Result<Plane, usize> {
    let mut h = Plane::try_new_in(pool, width, low.height, low.rows.clone())?;
    fill.fill(&mut h, &|y, row| {
        with_scratch(5, |s| tent_h(path, low.row(y), BaseIn::None, row, &mut s.rows[..5]))
    });
    Ok(h)
}

/// Row `y` of the level above from the horizontal sums `h` ([`up_plane`]): the tent's four rows
/// summed, plus `base`: [`super::up_row`] in lanes.
pub fn up_row(path: SimdPath, h: &Plane, y: usize, base: Option<&[[f32; 3]]>, out: &mut [[f32; 3]]) {
    let (y0, wy) = tent(y);
    let last = h.height as isize - 1;
    let rows: [&[f32]; 4] =
        std::array::from_fn(|d| h.row((y0 + d as isize).clamp(0, last) as usize).as_flattened());
    taps(path, rows, [0; 4], wy, base.map(|b| b.as_flattened()), out.as_flattened_mut());
}

/// Step 4's downsample in lanes: [`super::down_row_h`].
pub fn down_row_h(path: SimdPath, src: &[[f32; 3]], out: &mut [[f32; 3]]) {
    with_scratch(2, |s| down_row_h_in(path, src, out, &mut s.rows[..2]));
}

fn down_row_h_in(path: SimdPath, src: &[[f32; 3]], out: &mut [[f32; 3]], s: &mut [Vec<f32>]) {
    let [e, o] = s else { unreachable!("two rows") };
    split(src, out.len() + 3, e, o);
    // Tap d reads texel 2i − 2 + d: even d from e[i + d/2], odd d from o[i + (d − 1)/2].
    taps(path, [&e[..], o, e, o, e, o], [0, 0, 1, 1, 2, 2], DOWN_H_W, None, out.as_flattened_mut());
}

/// The streak's `U₁ʰ` of one half-height row `t` with `n` levels into `out` (`half(t.len())`
/// texels): [`super::streak_row`] in lanes.
pub fn streak_row(path: SimdPath, t: &[[f32; 3]], n: u32, out: &mut [[f32; 3]]) {
    with_scratch(5, |s| {
        streak_row_in(path, t, n, &mut s.rows[..5], &mut s.levels);
        out.copy_from_slice(&s.levels[0][..out.len()]);
    });
}

/// [`streak_row`] in the scratch rows `rows` (five) and `levels`, leaving `U₁ʰ` in `levels[0]`.
fn streak_row_in(
    path: SimdPath,
    t: &[[f32; 3]],
    n: u32,
    rows: &mut [Vec<f32>],
    levels: &mut Vec<Vec<[f32; 3]>>,
) {
    if levels.is_empty() {
        levels.push(Vec::new());
    }
    let mut d1 = std::mem::take(&mut levels[0]);
    d1.resize(half(t.len()), [0.0; 3]);
    if t.len() < SHORT {
        super::down_row_h(t, &mut d1);
    } else {
        down_row_h_in(path, t, &mut d1, &mut rows[..2]);
    }
    levels[0] = d1;
    streak_levels(path, None, n, rows, levels);
}

/// The streak's chain from its first level `d1` (`D₁ʰ`) with `n` levels, leaving `U₁ʰ` in
/// `levels[0]`.
fn streak_from_first(
    path: SimdPath,
    d1: &[[f32; 3]],
    n: u32,
    rows: &mut [Vec<f32>],
    levels: &mut Vec<Vec<[f32; 3]>>,
) {
    streak_levels(path, Some(d1), n, rows, levels);
}

/// Levels `D₂ʰ … D_nʰ` from `D₁ʰ` (`first`, or `None`: what `levels[0]` holds), then `U_kʰ`
/// over them, `U₁ʰ` in `levels[0]`.
fn streak_levels(
    path: SimdPath,
    first: Option<&[[f32; 3]]>,
    n: u32,
    rows: &mut [Vec<f32>],
    levels: &mut Vec<Vec<[f32; 3]>>,
) {
    let n = n.clamp(1, MAX_LEVELS) as usize;
    if levels.len() < n {
        levels.resize_with(n, Vec::new);
    }
    let mut len = first.map_or(levels[0].len(), <[_]>::len);
    for k in 1..n {
        len = half(len);
        let (done, rest) = levels.split_at_mut(k);
        let src: &[[f32; 3]] = match first {
            Some(d1) if k == 1 => d1,
            _ => &done[k - 1],
        };
        rest[0].resize(len, [0.0; 3]);
        if src.len() < SHORT {
            super::down_row_h(src, &mut rest[0]);
        } else {
            down_row_h_in(path, src, &mut rest[0], &mut rows[..2]);
        }
    }
    // U_N = D_N; U_k = D_k + up(U_{k+1}), over D_k in place (U₁ʰ from `first` into levels[0]).
    for k in (0..n - 1).rev() {
        let (lo, hi) = levels.split_at_mut(k + 1);
        let (d, u) = (&mut lo[k], &hi[0]);
        match first {
            Some(d1) if k == 0 => {
                d.resize(d1.len(), [0.0; 3]);
                if d1.len() < SHORT {
                    super::up_row_h(u, Some(d1), d);
                } else {
                    tent_h(path, u, BaseIn::Row(d1), d, rows);
                }
            }
            _ if d.len() < SHORT => {
                let mut base = [[0.0f32; 3]; SHORT];
                base[..d.len()].copy_from_slice(d);
                super::up_row_h(u, Some(&base[..d.len()]), d);
            }
            _ => tent_h(path, u, BaseIn::Out, d, rows),
        }
    }
    if let (Some(d1), 1) = (first, n) {
        levels[0].clear();
        levels[0].extend_from_slice(d1);
    }
}

/// [`super::blur_row_h`] in lanes (`q`: a scratch row).
fn blur_row_h_in(path: SimdPath, row: &[[f32; 3]], out: &mut [[f32; 3]], q: &mut Vec<f32>) {
    // q[m] = row[clamp(m − 2)]: texel x − 1 + d is q[x + 1 + d].
    pad(row, out.len() + 4, q);
    taps(path, [&q[..]; 3], [1, 2, 3], BLUR, None, out.as_flattened_mut());
}

/// [`super::blur_row_h`] in lanes.
pub fn blur_row_h(path: SimdPath, row: &[[f32; 3]], out: &mut [[f32; 3]]) {
    with_scratch(1, |s| blur_row_h_in(path, row, out, &mut s.rows[0]));
}

/// [`super::glare_row`] in lanes.
pub fn glare_row(
    path: SimdPath,
    hb: &Plane,
    hs: Option<&Plane>,
    y: usize,
    kb: f32,
    ks: f32,
    out: &mut [[f32; 3]],
) {
    let w = super::glare_weights(kb, ks);
    let last = hb.height as isize - 1;
    let b: [&[f32]; 3] =
        std::array::from_fn(|d| hb.row((y as isize - 1 + d as isize).clamp(0, last) as usize).as_flattened());
    let out = out.as_flattened_mut();
    match hs {
        Some(hs) => taps(path, [b[0], b[1], b[2], hs.row(y).as_flattened()], [0; 4], w, None, out),
        None => taps(path, b, [0; 3], [w[0], w[1], w[2]], None, out),
    }
}

/// [`super::upsample_row`] in lanes: row `y` of the full-resolution glare from `g`.
pub fn upsample_row(path: SimdPath, g: &Plane, y: usize, out: &mut [[f32; 3]]) {
    with_scratch(4, |s| upsample_row_in(path, g, y, None, out, &mut s.rows[..4]));
}

/// [`upsample_row`] composited over the linear row `linear` ([`super::composite`]): row `y` of the
/// glared linear colour, without the glare's own row in between.
pub fn upsample_composite_row(
    path: SimdPath,
    g: &Plane,
    y: usize,
    linear: &[[f32; 3]],
    out: &mut [[f32; 3]],
) {
    with_scratch(4, |s| upsample_row_in(path, g, y, Some(linear), out, &mut s.rows[..4]));
}

fn upsample_row_in(
    path: SimdPath,
    g: &Plane,
    y: usize,
    linear: Option<&[[f32; 3]]>,
    out: &mut [[f32; 3]],
    s: &mut [Vec<f32>],
) {
    let [v, q, he, ho] = s else { unreachable!("four rows") };
    let (y0, wy) = bilinear(y);
    let last = g.height as isize - 1;
    let rows: [&[f32]; 2] =
        std::array::from_fn(|d| g.row((y0 + d as isize).clamp(0, last) as usize).as_flattened());
    v.resize(3 * g.width, 0.0);
    taps(path, rows, [0; 2], wy, None, v);
    let w = out.len();
    let (ne, no) = (w.div_ceil(2), w / 2);
    // q[m] = v[clamp(m − 2)]: even x = 2j reads v[j − 1], v[j] = q[j + 1], q[j + 2]; odd x = 2j + 1
    // reads v[j], v[j + 1] = q[j + 2], q[j + 3].
    pad(v.as_chunks::<3>().0, ne + 4, q);
    he.resize(3 * ne, 0.0);
    ho.resize(3 * no, 0.0);
    taps(path, [&q[..]; 2], [1, 2], bilinear(0).1, None, he);
    taps(path, [&q[..]; 2], [2, 3], bilinear(1).1, None, ho);
    let (he, ho) = (he.as_chunks::<3>().0, ho.as_chunks::<3>().0);
    match linear {
        None => interleave(he, ho, out),
        Some(c) => {
            // composite(c, g) = min(c + g, f32::MAX) per channel.
            let (pairs, tail) = out.as_chunks_mut::<2>();
            let (cp, ct) = c.as_chunks::<2>();
            for (((p, e), o), c) in pairs.iter_mut().zip(he).zip(ho).zip(cp) {
                *p = [composite(c[0], *e), composite(c[1], *o)];
            }
            if let Some(t) = tail.first_mut() {
                *t = composite(ct[0], he[pairs.len()]);
            }
        }
    }
}

/// Level-1 rows a block of [`first_level`] makes at once: the prefiltered rows it reads (two per
/// row and four more) are made and split once for the block.
const BLOCK: usize = 8;

/// The downsample's rows `rows` of the level below `src` (which holds the rows they read) in a
/// block: the source rows `2·rows.start − 2 … 2·rows.end + 1` (clamped) each split once (with
/// `prefilter = Some((threshold, soft_knee))` prefiltered first, [`prefilter_row`]), every 2×2 box
/// row the block's rows share made once, then for each row `y` the thirteen taps of
/// [`down_row`] into `d1`, and (`s1` not empty) `down_row_h` of the pair `(0 + ½·T(2y)) + ½·T(2y
/// + 1)` into `s1` (the split of the pair is the pair of the splits, texel for texel): with the
/// prefilter `D₁` and the streak's `D₁ʰ` straight from the linear image, without it a level of
/// the pyramid; the planes of the prefilter, [`super::down_row`], [`super::pair_row`] and
/// [`super::down_row_h`], bit for bit.
#[allow(clippy::too_many_arguments)]
fn first_level(
    path: SimdPath,
    src: &Plane,
    prefilter: Option<(f32, f32)>,
    rows: std::ops::Range<usize>,
    d1: &mut [[f32; 3]],
    s1: &mut [[f32; 3]],
    s: &mut Scratch,
) {
    let last = src.height as isize - 1;
    let wo = d1.len() / rows.len();
    let count = wo + 3;
    let clamp = |y: isize| y.clamp(0, last) as usize;
    let ta = clamp(2 * rows.start as isize - 2);
    let tb = clamp(2 * rows.end as isize + 1);
    let Scratch { rows: work, block, boxes, zero, .. } = s;
    let n = tb + 1 - ta;
    if block.len() < 2 * n {
        block.resize_with(2 * n, Vec::new);
    }
    zero.clear();
    for (i, y) in (ta..=tb).enumerate() {
        let (e, o) = block[2 * i..2 * i + 2].split_at_mut(1);
        zero.push(match prefilter {
            Some(knee) => prefilter_split(path, src.row(y), count, knee, &mut e[0], &mut o[0]),
            None => {
                split(src.row(y), count, &mut e[0], &mut o[0]);
                false
            }
        });
    }
    // Where every source row a level-1 row reads is `+0` (a dark stretch of the picture), its
    // `D₁` and `D₁ʰ` are `+0` too: every box, tap and pair sum of `+0` starts from `+0` and adds
    // `+0`. A block of such rows makes no box rows at all.
    if zero.iter().all(|&z| z) {
        d1.fill([0.0; 3]);
        s1.fill([0.0; 3]);
        return;
    }
    // The box rows: row y's five are those at the (unclamped) source rows s = 2y − 2 + k,
    // k = 0 … 4, each the box of the source rows clamp(s) and clamp(s + 1): even-x boxes for even
    // s, odd-x ones for odd s. Neighbouring rows share three of their five, so each is made once
    // for the block, from `s0 = 2·rows.start − 2` on.
    let s0 = 2 * rows.start as isize - 2;
    let nb = 2 * rows.len() + 3;
    if boxes.len() < nb {
        boxes.resize_with(nb, Vec::new);
    }
    let m = 3 * (wo + 2);
    for (b, bx) in boxes[..nb].iter_mut().enumerate() {
        let sy = s0 + b as isize;
        let (i0, i1) = (2 * (clamp(sy) - ta), 2 * (clamp(sy + 1) - ta));
        let (e0, o0, e1, o1) = (&block[i0], &block[i0 + 1], &block[i1], &block[i1 + 1]);
        bx.resize(m, 0.0);
        let srcs: [&[f32]; 4] = if b % 2 == 0 {
            [&e0[..m], &o0[..m], &e1[..m], &o1[..m]]
        } else {
            [&o0[..m], &e0[3..3 + m], &o1[..m], &e1[3..3 + m]]
        };
        dispatch(path, BoxSum { srcs, out: bx });
    }
    let pair = work;
    for (r, y) in rows.clone().enumerate() {
        let at = |dy: isize| 2 * (clamp(2 * y as isize - 2 + dy) - ta);
        if (0..6).all(|dy| zero[at(dy) / 2]) {
            d1[r * wo..(r + 1) * wo].fill([0.0; 3]);
            if !s1.is_empty() {
                s1[r * wo..(r + 1) * wo].fill([0.0; 3]);
            }
            continue;
        }
        let [be0, bo1, be2, bo3, be4] = std::array::from_fn(|k| &boxes[2 * r + k][..]);
        taps(
            path,
            [be2, bo1, bo1, bo3, bo3, be0, be2, be2, be4, be0, be0, be4, be4],
            [1, 0, 1, 0, 1, 1, 0, 2, 1, 0, 2, 0, 2],
            DOWN_W,
            None,
            d1[r * wo..(r + 1) * wo].as_flattened_mut(),
        );
        if s1.is_empty() {
            continue;
        }
        // The pair's even and odd texels, then the 1-D downsample's six taps.
        let (ia, ib) = (at(2), at(3));
        let [pe, po] = &mut pair[..2] else { unreachable!("two rows") };
        let k = 3 * count;
        for (out, (a, b)) in [(&mut *pe, (ia, ib)), (&mut *po, (ia + 1, ib + 1))] {
            out.resize(k, 0.0);
            taps(path, [&block[a][..k], &block[b][..k]], [0; 2], [0.5; 2], None, out);
        }
        let (pe, po) = (&pe[..], &po[..]);
        taps(
            path,
            [pe, po, pe, po, pe, po],
            [0, 0, 1, 1, 2, 2],
            DOWN_H_W,
            None,
            s1[r * wo..(r + 1) * wo].as_flattened_mut(),
        );
    }
}

/// [`super::try_glare`] on the vector path `path`: the same planes, bit for bit.
pub fn try_glare(
    path: SimdPath,
    params: &BloomParams,
    src: &Plane,
    band: std::ops::Range<usize>,
    fill: &dyn RowFill,
) -> Result<Plane, usize> {
    let g = try_glare_plane(path, params, src, band.clone(), fill)?;
    let mut out = Plane::try_new(src.width, src.height, band)?;
    fill.fill(&mut out, &|y, row| upsample_composite_row(path, &g, y, src.row(y), row));
    Ok(out)
}

/// The glare `G` at level 1 of [`super::try_glare`] for the rows `band` of the linear image `src`
/// (which holds at least the rows [`super::source_rows`] names): the plane over the level-1 rows
/// [`super::bilinear_rows`] names, from which [`upsample_row`] and [`super::composite`] give the
/// band's rows. `Err(bytes)` where a plane of that size could not be allocated.
pub fn try_glare_plane(
    path: SimdPath,
    params: &BloomParams,
    src: &Plane,
    band: std::ops::Range<usize>,
    fill: &dyn RowFill,
) -> Result<Plane, usize> {
    try_glare_plane_in(path, params, src, band, fill, &mut PlanePool::default())
}

/// [`try_glare_plane`] with its planes from `pool`, and every plane but the one it returns given
/// back to it (the caller may give that one back too once it is read): the same plane, bit for
/// bit.
pub fn try_glare_plane_in(
    path: SimdPath,
    params: &BloomParams,
    src: &Plane,
    band: std::ops::Range<usize>,
    fill: &dyn RowFill,
    pool: &mut PlanePool,
) -> Result<Plane, usize> {
    let (w, h) = (src.width, src.height);
    let n = levels(params.radius * h as f32);
    let plan = Plan::new(w, h, n, band.clone());
    let (th, kn) = (params.threshold, params.soft_knee);
    let (kb, ks) = super::weights(params, h);
    let l1 = &plan.levels[0];
    // D₁ and the streak's D₁ʰ in one pass over the linear image.
    let mut d1 = Plane::try_new_in(pool, l1.width, l1.height, l1.down.clone())?;
    let mut s1 =
        if ks > 0.0 { Some(Plane::try_new_in(pool, l1.width, l1.height, l1.down.clone())?) } else { None };
    fill.fill_blocks(&mut d1, s1.as_mut(), BLOCK, &|rows, d, s| {
        with_scratch(7, |scratch| first_level(path, src, Some((th, kn)), rows, d, s, scratch))
    });
    let mut downs: Vec<Plane> = Vec::with_capacity(plan.levels.len());
    downs.push(d1);
    for l in &plan.levels[1..] {
        let mut d = Plane::try_new_in(pool, l.width, l.height, l.down.clone())?;
        let prev = downs.last().expect("D₁");
        fill.fill_blocks(&mut d, None, BLOCK, &|rows, d, _| {
            with_scratch(7, |scratch| first_level(path, prev, None, rows, d, &mut [], scratch))
        });
        downs.push(d);
    }
    let mut u = downs.pop().unwrap_or_default();
    while let Some(d) = downs.pop() {
        let l = &plan.levels[downs.len()];
        let hs = up_plane_in(path, &u, l.width, fill, pool)?;
        let mut next = Plane::try_new_in(pool, l.width, l.height, l.up.clone())?;
        fill.fill(&mut next, &|y, row| up_row(path, &hs, y, Some(d.row(y)), row));
        pool.give(hs);
        pool.give(d);
        pool.give(std::mem::replace(&mut u, next));
    }
    let mut hb = Plane::try_new_in(pool, l1.width, l1.height, l1.up.clone())?;
    fill.fill(&mut hb, &|y, row| blur_row_h(path, u.row(y), row));
    pool.give(u);
    let hs = match s1 {
        Some(s1) => {
            let ns = levels(params.streak_length * h as f32);
            let mut hs = Plane::try_new_in(pool, l1.width, l1.height, l1.up.clone())?;
            fill.fill(&mut hs, &|y, row| {
                // A row of `D₁ʰ` that is `+0` throughout (a dark stretch: see `first_level`) has a
                // streak of `+0`: every level's sums and the blur start from `+0` and add `+0`.
                if s1.row(y).iter().all(|t| is_plus_zero(*t)) {
                    row.fill([0.0; 3]);
                    return;
                }
                with_scratch(5, |s| {
                    let Scratch { rows, levels, .. } = s;
                    streak_from_first(path, s1.row(y), ns, &mut rows[..5], levels);
                    blur_row_h_in(path, &levels[0], row, &mut rows[0]);
                })
            });
            pool.give(s1);
            Some(hs)
        }
        None => None,
    };
    let mut g = Plane::try_new_in(pool, l1.width, l1.height, super::bilinear_rows(&band, l1.height))?;
    fill.fill(&mut g, &|y, row| glare_row(path, &hb, hs.as_ref(), y, kb, ks, row));
    pool.give(hb);
    if let Some(hs) = hs {
        pool.give(hs);
    }
    Ok(g)
}
