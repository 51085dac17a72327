//! hadou's default curve integrator ([`Integrator::Default`](super::Integrator::Default)), run by
//! [`curve_energy`](super::curve_energy) and, with explicit settings, by [`default_energy`].
//!
//! # Method
//! The ray `P(t) = S + t·Q` is split where its axial coordinate `x(t)` crosses the end planes
//! `x = 0` and `x = X` (002 eq. 3.24): before and after the slab the paired point is fixed (`c(0)`
//! or the head), so those parts are exact sphere integrals. Inside the slab the curve is replaced
//! by straight pieces in `x`; on a piece both `P_⊥(t)` and the paired line point are linear in
//! `t`, so `|P − C|² + r_c²` is a quadratic in `t` and the piece's integral is exact in closed
//! form (asinh/log for faithful `1/r`, atan for `1/r²`; see `closed.rs`): the same forms as the
//! analytic fields (002 eq. 3.9, SPEC.md §1.2).
//!
//! Which pieces: the [`PieceTable`](super::PieceTable) is a binary tree of least-squares lines
//! with deviation bounds `δ`. The walk starts at the root and, for each piece overlapping the
//! ray's `x`-range, forms its quadratic, finds the closest approach `d` over the overlap (the
//! quadratic's clamped minimum) and the change `ℓ = |v|Δt` of the relative position along it,
//! and accepts the piece if its estimated relative error (the `ChordModel`:
//! `(δ/D)·(min(1, c₁(ℓ/D)²) + P·(1 − κ)) + c₂(δ/D)²`, `D² = d² + r_c²`, `κ` the part of the
//! piece's `x`-range the ray covers) is at most the tolerance `τ`; otherwise it descends as many
//! levels as the estimate predicts (leaves are always accepted). The first term is the
//! first-order error `∇w·δ`: it cancels to `O((ℓ/D)²)` because a least-squares line leaves a
//! deviation with zero mean and zero first moment over the piece, and does not cancel where the
//! ray passes close to the piece (`ℓ ≳ D`) or covers only part of it; the second is the
//! second-order term. Near the curve the walk reaches fine leaves, far from it a few coarse
//! lines cover whole turns: the bounding-cylinder distinction of the thesis (002 §3.4.4) becomes
//! continuous, and since every accepted piece is within tolerance there is no band where the
//! resolution changes.
//!
//! The walk is stackless (the tree is implicit in the piece indices), iterates in a loop bounded
//! by the table size, and touches only flat arrays: the form the GPU mirrors.
//!
//! Attenuation `(1 − t/t_far)^j` (002 eq. 3.23): each piece's integral is taken to second order
//! about the weight's closed-form centroid, with its closed-form variance (see `closed.rs`): one
//! power per piece, exact for `j ∈ {1, 2}`. The third-order remainder is bounded by keeping
//! `x = Δu/(1 − u_end)` of every part below `x_max(j, τ)` ([`attenuation_split`]): a piece
//! longer than that is cut into parts whose `1 − u` shrinks geometrically, until what the rule
//! could get wrong on the rest falls below `τ/2` (the rest is one last part).
//!
//! # Per-ray algorithm (what the GPU mirrors)
//! 1. Local ray (`LocalRay::new`): `o = ((S−O)·D, (S−O)·ŷ, (S−O)·ẑ)`, `q` likewise; resolve the
//!    span.
//! 2. Slab crossing `t_in`, `t_out` from `x(t) = o.x + q.x·t ∈ [0, X]`.
//! 3. End piece before the slab: `p = local(t_a) − end point`, `v = q` (3-D), exact.
//! 4. Slab: if the `x`-range is below `10⁻⁶X`, one piece against the interpolated leaf point;
//!    else the stackless walk over `(ℓ, j)`: piece range `[nodes[j·2^ℓ].x,
//!    nodes[min((j+1)·2^ℓ, N)].x]` ∩ the ray's range, line `lines[level_offsets[ℓ]+j]`, bound
//!    `errors[…]`; accept, or go to `(ℓ−k, j·2^k)` with `k` from `ChordModel::refinement`; after
//!    a piece, `j += 1` if `j` is even and has a sibling, else climb (`j >>= 1`, `ℓ += 1`) and
//!    retry; stop past the range or after the root.
//! 5. End piece after the slab. Energy `= α·Σ`.
//!
//! # Counting evaluations
//! [`CurveSample::evaluations`] counts, per ray, 1 for every piece refined and 1 for every piece
//! integrated (with attenuation, 1 for every part it is cut into); a part's single evaluation of
//! `(1 − u)^j` at its centroid is within that count, as a Simpson sample evaluates density and
//! attenuation together. Simpson counts one per integrand sample.

use super::closed::{Quad, Segment};
use super::local_ray::{CurveReal, LocalRay};
use super::prepare::PreparedCurve;
use crate::energy::{scaled, Falloff, FieldParams, Ray};
use crate::{Real, Vec3};

/// One ray's curve energy and the work it took.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurveSample {
    /// `α ∫ w(r(t))·(1 − t/t_far)^j dt` over the span.
    pub energy: f32,
    /// Integrand evaluations (see the module docs for the count rule).
    pub evaluations: u32,
}

/// Tuning of the default integrator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DefaultSettings {
    /// Relative error `τ` a piece may have by the chord model (see the module docs); attenuated
    /// parts keep their third-order remainder below `τ/2`.
    pub tolerance: f64,
}

/// The settings [`Integrator::Default`] uses, chosen by measurement (`examples/curve_stats.rs`
/// and the curve tests): `τ = 2·10⁻³` gives a 99th-percentile relative error of 0.3–2.5·10⁻⁴ on
/// the example scenes and the test configurations, 4–20× below faithful Simpson at `m = 500`
/// and 20× below the 0.5 % bar.
///
/// [`Integrator::Default`]: super::Integrator::Default
pub const DEFAULT_SETTINGS: DefaultSettings = DefaultSettings { tolerance: 2e-3 };

/// How attenuated pieces are split: `(q, h_floor)` for exponent `j > 0` and tolerance `τ`.
///
/// The second-order rule of `closed.rs` leaves `g'''μ₃/6 + g''''μ₄/24`; relative to `g` with
/// `x = Δu/(1 − u)`, a skewness bound `|μ₃| ≤ 0.05Δt³` and `μ₄ ≤ Δt⁴/80` this is at most
/// `|j(j−1)(j−2)|·x³/120 + |j(j−1)(j−2)(j−3)|·x⁴/1920`. Each term is held below `τ/2`, which
/// gives `x_max` (at most 4; unbounded for `j ∈ {1, 2}`, where the rule is exact), and parts
/// shrink `1 − u` by `q = 1/(1 + x_max)`. Splitting stops where the last part, up to the far
/// point, cannot be off by more than `τ/2`: that part's rule error is at most
/// `E = |(j+1)·2^{−j}·(1 + j(j−1)/6) − 1| + 0.05` of its share (the exact error for a uniform
/// weight, plus an allowance for skew), and its share at most `(1 − u)^j`, so
/// `h_floor = (τ/(2E))^{1/j}`.
pub fn attenuation_split(j: f64, tolerance: f64) -> (f64, f64) {
    let ta = 0.5 * tolerance.clamp(1e-9, 0.5);
    let c3 = (j * (j - 1.0) * (j - 2.0)).abs() / 120.0;
    let c4 = (j * (j - 1.0) * (j - 2.0) * (j - 3.0)).abs() / 1920.0;
    let x3 = if c3 > 0.0 { (ta / c3).cbrt() } else { f64::INFINITY };
    let x4 = if c4 > 0.0 { (ta / c4).powf(0.25) } else { f64::INFINITY };
    let x_max = x3.min(x4).min(4.0);
    // The last part, [a, t_far], has x = ∞: the rule is then off by the factor
    // (j+1)·2^{−j}·(1 + j(j−1)/6) for a uniform weight, plus an allowance for skew.
    let last = ((j + 1.0) * (-j).exp2() * (1.0 + j * (j - 1.0) / 6.0) - 1.0).abs() + 0.05;
    let h_floor = if j > 0.0 { (ta / last.min(1.0)).min(1.0).powf(1.0 / j) } else { 0.0 };
    (1.0 / (1.0 + x_max), h_floor)
}

/// The default integrator with explicit settings, in `f32` (for measurements and tuning).
pub fn default_energy(
    c: &PreparedCurve,
    p: &FieldParams<f32>,
    ray: &Ray<f32>,
    t0: f32,
    t1: f32,
    t_far: f32,
    settings: &DefaultSettings,
) -> CurveSample {
    let (e, n) =
        LocalRay::new(c, p, ray, t0, t1, t_far).map_or((0.0, 0), |r| default_generic(c, &r, settings));
    CurveSample { energy: e, evaluations: n }
}

/// Accumulates pieces: energy and evaluation count.
pub(super) struct Acc<R> {
    pub(super) sum: R,
    pub(super) evals: u32,
    /// Part ratio `q` of [`attenuation_split`] (`1 − u` shrinks by it per part).
    pub(super) q: R,
    /// Attenuation floor `h_floor` of [`attenuation_split`].
    pub(super) h_floor: R,
}

impl<R: Real> Acc<R> {
    /// Adds the piece `d(τ) = p + vτ`, `τ ∈ [0, dt]`, starting at ray parameter `ts`.
    ///
    /// With attenuation (`j > 0`, so the span and the piece end at the far point at the latest),
    /// the piece is cut into parts `[a, b]` with `1 − u_b = q·(1 − u_a)` (the last part ends at
    /// the piece's end), each integrated by [`Segment::attenuated`]; once `1 − u_a` is below
    /// `h_floor` the rest is one part. Each part counts 1.
    #[inline]
    fn piece(&mut self, r: &LocalRay<R>, ts: R, p: Vec3<R>, v: Vec3<R>, dt: R) {
        self.piece_quad(r, ts, &Quad::new(p, v, r.rc2), dt);
    }

    /// [`piece`](Self::piece) from the piece's [`Quad`].
    #[inline]
    fn piece_quad(&mut self, r: &LocalRay<R>, ts: R, q: &Quad<R>, dt: R) {
        if r.j == R::ZERO {
            self.sum += Segment::from_quad(r.falloff, q, dt, r.rc2).value;
            self.evals += 1;
            return;
        }
        let te = ts + dt;
        let mut a = ts;
        // Parts shrink 1 − u geometrically down to h_floor: at most log(h_floor)/log(q) + 1 of
        // them; the bound ends any other case with one last long part.
        for i in 0..MAX_ATTENUATION_PARTS {
            let ha = R::ONE - a / r.t_far;
            let b = if ha <= self.h_floor || i + 1 == MAX_ATTENUATION_PARTS {
                te
            } else {
                te.min(r.t_far * (R::ONE - ha * self.q))
            };
            let seg = Segment::from_quad(r.falloff, &q.shifted(a - ts), b - a, r.rc2);
            self.sum += seg.attenuated(a, r.t_far, r.j);
            self.evals += 1;
            if !(b < te) {
                break;
            }
            a = b;
        }
    }
}

/// Most parts an attenuated piece is cut into (`CURVE_MAX_PARTS` in curve.wgsl).
pub const MAX_ATTENUATION_PARTS: usize = 64;

/// The chord walk's error model for one density law (see the module docs).
///
/// A piece whose line deviates from the curve by at most `δ` (cross-section distance at equal
/// `x`), passed at closest distance `D` (softened by the core radius) while the relative position
/// moves by `ℓ`, and whose `x`-range the ray covers only in part (fraction `κ`), is estimated to be
/// off by the relative amount
/// `(δ/D)·(min(S, c₁·(ℓ/D)²) + P·(1 − κ)) + c₂·(δ/D)²`:
/// - first order, `∫∇w·e`: the least-squares deviation `e` has zero mean and zero first moment
///   over the piece, so where the ray covers the whole piece only the part of `∇w` beyond linear
///   counts, `½·ℓ²·|∇³w|·λ²`; against `e` (`|e| ≤ δ`) the best linear fit of `λ²` leaves at most
///   `1/16` in the mean. With `|∇³(1/r)| ≤ 6/r⁴` and `|∇³(1/r²)| ≤ 24/r⁵` this gives
///   `c₁ = 3/16` (faithful) and `3/4` (inverse square), relative to `w(D)`;
/// - where the ray sweeps past the piece (`ℓ ≳ D`) there is no cancellation and the first-order
///   term saturates at about `δ/D` (`S = 1`);
/// - where the ray covers only part of the piece's range (its start inside the slab, or a ray
///   nearly across the axis), `e` need not average out: `|∇w|/w` is `1/D` (faithful) or `2/D`
///   (inverse square), and a ray covering only the point of largest deviation meets that bound
///   exactly, so with a 25 % margin `P = 1.25` or `2.5`;
/// - second order, `½·δ²·|∇²w|`: `c₂ = 1` (faithful, `|∇²(1/r)| ≤ 2/r³`), `3` (inverse square).
///
/// `chord_model_is_conservative` (below) checks the estimate against the exact error of single
/// pieces on random rays. The constants are repeated in curve.wgsl `chord_model`, and the
/// walk, [`Acc`] and `line_quad` in `curve_walk`, `curve_piece` and `curve_line_quad` there: keep
/// them in sync (the GPU twin test compares the two on 1704 rays).
#[derive(Clone, Copy, Debug)]
pub(super) struct ChordModel<R> {
    pub(super) first: R,
    pub(super) saturation: R,
    pub(super) partial: R,
    pub(super) second: R,
}

impl<R: Real> ChordModel<R> {
    pub(super) fn new(falloff: Falloff) -> Self {
        let (first, partial, second) = match falloff {
            Falloff::Faithful => (3.0 / 16.0, 1.25, 1.0),
            Falloff::InverseSquare => (0.75, 2.5, 3.0),
        };
        ChordModel {
            first: R::from_f64(first),
            saturation: R::ONE,
            partial: R::from_f64(partial),
            second: R::from_f64(second),
        }
    }

    /// `(x², a)`: the squared relative deviation `x² = δ²/D²` and the first-order factor
    /// `a = min(S, c₁(ℓ/D)²) + P·uncovered` of the piece with quadratic `q` over `τ ∈ [0, dt]`
    /// and deviation bound `err`; `uncovered = 1 − κ`. `D²` is the quadratic's minimum over the
    /// piece ([`Quad::inv_closest`]).
    #[inline]
    fn terms(&self, err: R, q: &Quad<R>, dt: R, rc2: R, uncovered: R) -> (R, R) {
        let inv = q.inv_closest(dt, rc2);
        let x2 = err * err * inv;
        let a = (self.first * q.vv * dt * dt * inv).min(self.saturation) + self.partial * uncovered;
        (x2, a)
    }

    /// The estimate `x·a + c₂x²`.
    #[inline]
    fn estimate(&self, x2: R, a: R) -> R {
        x2.sqrt() * a + self.second * x2
    }

    /// 0 if the estimate meets the tolerance; otherwise how many levels to descend
    /// (1 to `level`).
    ///
    /// The test is free of square roots: with `b = τ − c₂x²`, `x·a + c₂x² ≤ τ` iff `b ≥ 0` and
    /// `x²a² ≤ b²`. A rejected piece descends `max(1, ⌊log₈(estimate/τ)⌋)` levels at once
    /// instead of one: halving a piece that is short against the curve's features divides `δ` by
    /// 4 and `ℓ` by 2, so the estimate falls 16× per level in the `(ℓ/D)²` regime and 4× where
    /// saturated, but a piece spanning whole turns barely improves when halved. 8× per level was
    /// measured best on the example curves (1.2–1.3× fewer evaluations than descending one level
    /// at a time, against 16× or 4×); descending too far costs pieces, never accuracy.
    #[inline]
    fn refinement(&self, x2: R, a: R, tol: R, level: usize) -> usize {
        let b = tol - self.second * x2;
        if b >= R::ZERO && x2 * a * a <= b * b {
            return 0;
        }
        let per_level = R::from_f64(8.0);
        let mut ratio = self.estimate(x2, a) / (tol * per_level);
        let mut k = 1;
        while k < level && ratio > per_level {
            ratio /= per_level;
            k += 1;
        }
        k
    }
}

/// The default integrator over the resolved span of `r`, generic over the precision:
/// `(α·∫, evaluations)`.
pub(crate) fn default_generic<R: CurveReal>(
    c: &PreparedCurve,
    r: &LocalRay<R>,
    settings: &DefaultSettings,
) -> (R, u32) {
    let (q, h_floor) =
        if r.j > R::ZERO { attenuation_split(r.j.to_f64(), settings.tolerance) } else { (0.5, 0.0) };
    let mut acc = Acc { sum: R::ZERO, evals: 0, q: R::from_f64(q), h_floor: R::from_f64(h_floor) };
    integrate_span(c, r, r.t0, r.t1, settings, &mut acc);
    // α·Σ saturated at f32::MAX (energy module docs): an overflow is full brightness, not 0.
    (scaled(acc.sum, r.alpha), acc.evals)
}

/// `∫_{ta}^{tb}` of the (unscaled) density, by end pieces and the chord walk.
fn integrate_span<R: CurveReal>(
    c: &PreparedCurve,
    r: &LocalRay<R>,
    ta: R,
    tb: R,
    settings: &DefaultSettings,
    acc: &mut Acc<R>,
) {
    let table = &c.table;
    let n = table.nodes.len() - 1;
    let end_point = |head: bool| {
        let nd = if head { table.nodes[n] } else { table.nodes[0] };
        let x = if head { r.x_head } else { R::ZERO };
        Vec3::new(x, R::from_f64(f64::from(nd[1])), R::from_f64(f64::from(nd[2])))
    };
    let sphere = |head: bool, a: R, b: R, acc: &mut Acc<R>| {
        if b > a {
            acc.piece(r, a, r.at(a) - end_point(head), r.q, b - a);
        }
    };
    match r.slab() {
        None => {
            if r.o.x < R::ZERO {
                sphere(false, ta, tb, acc);
            } else if r.o.x > r.x_head {
                sphere(true, ta, tb, acc);
            } else {
                walk(c, r, ta, tb, settings, acc);
            }
        }
        Some((tin, tout, head_first)) => {
            sphere(head_first, ta, tb.min(tin), acc);
            let (a, b) = (ta.max(tin), tb.min(tout));
            if b > a {
                walk(c, r, a, b, settings, acc);
            }
            sphere(!head_first, ta.max(tout), tb, acc);
        }
    }
}

/// Node `i` as `(x, y, z)`.
#[inline]
fn node<R: Real>(c: &PreparedCurve, i: usize) -> [R; 3] {
    let nd = c.table.nodes[i];
    [R::from_f64(f64::from(nd[0])), R::from_f64(f64::from(nd[1])), R::from_f64(f64::from(nd[2]))]
}

/// The leaf containing `x` (binary search over the nodes).
#[inline]
pub(crate) fn leaf_of<R: Real>(c: &PreparedCurve, x: R) -> usize {
    let n = c.table.nodes.len() - 1;
    let (mut lo, mut hi) = (0usize, n - 1);
    while hi > lo {
        let mid = (lo + hi).div_ceil(2);
        if node::<R>(c, mid)[0] <= x {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    lo
}

/// The quadratic of piece `j` of level `l` (centred at `x = xm`) along the ray from `t = ts` on,
/// over `τ ∈ [0, dt]`: the relative position `P_⊥(t) − L(x(t))` and its rate, both without an
/// axial component (see [`line_quad`]).
#[inline]
fn slab_quad<R: CurveReal>(
    c: &PreparedCurve,
    r: &LocalRay<R>,
    l: usize,
    j: usize,
    xm: R,
    ts: R,
    dt: R,
) -> Quad<R> {
    let ln = c.table.line(l, j);
    let f = |k: usize| R::from_f64(f64::from(ln[k]));
    line_quad(r, [f(0), f(1), f(2), f(3)], xm, ts, dt)
}

/// `(s, e)` with `s = a + b` rounded and `s + e = a + b` exactly (Knuth's two-sum: additions
/// only, so no contraction into a fused multiply-add can change it).
#[inline]
fn two_sum<R: Real>(a: R, b: R) -> (R, R) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `o + q·t − l` for an anchor `t` with a half-width significand ([`CurveReal::split`]), good to
/// the rounding of the (small) result rather than of `o` or `q·t` (tens of units): `q = q_h + q_l`
/// with half-width parts, so `q_h·t` and `q_l·t` are exact, and the two sums that cancel are
/// two-sums.
#[inline]
fn anchored<R: CurveReal>(o: R, q: R, l: R, t: R) -> R {
    let (h, h_err) = two_sum(o, -l);
    let qh = q.split();
    let (s, s_err) = two_sum(h, qh * t);
    s + (s_err + h_err + (q - qh) * t)
}

/// The quadratic of the line `L(x) = (ȳ, z̄) + (x − xm)·(m_y, m_z)` (`line = [ȳ, z̄, m_y, m_z]`)
/// along the ray from `t = ts` on, over `τ ∈ [0, dt]` (see [`slab_quad`]).
///
/// `p·p` and `p·v` come from the relative position at `ts`, `p = P(ts) − L(x(ts))`; its rounding
/// (that of `o + q·ts`, about `ε·|o|` with the eye tens of units away) only moves the piece along
/// the ray by a relative `ε`. `E = |p × v|²` is formed instead from the relative position at an
/// anchor `t_a` near the piece's point nearest the ray (`ts − p·v/v·v` clamped to the piece, its
/// significand halved), computed by [`anchored`] to the rounding of its own small value: `p × v`
/// is the same at every point of the line, and at `t_a` it is a product of small, locally formed
/// numbers. Formed at `ts` it cancelled: near hits (`d ≈ 10⁻⁴`) came out 1–3 % off in `f32`.
/// Only pieces the ray passes within about `2.4·10⁻³` of their coordinates' size take the anchored
/// form (every piece taking it cost 50 % more time on fig4-2-bezier); elsewhere the cross product at
/// `ts` is good to `2·10⁻⁴`.
#[inline]
fn line_quad<R: CurveReal>(r: &LocalRay<R>, line: [R; 4], xm: R, ts: R, dt: R) -> Quad<R> {
    let [ly, lz, my, mz] = line;
    let xs = r.o.x + r.q.x * ts - xm;
    let py = r.o.y + r.q.y * ts - (ly + xs * my);
    let pz = r.o.z + r.q.z * ts - (lz + xs * mz);
    let vy = r.q.y - r.q.x * my;
    let vz = r.q.z - r.q.x * mz;
    let vv = vy * vy + vz * vz;
    let pv = py * vy + pz * vz;
    // p × v at ts cancels to about ε·S·|v| (S: the size of the numbers p was formed from, the
    // slope's share of x included); where that could reach 2·10⁻⁴ of it (the ray passes within
    // about 2.4·10⁻³·S of the line) it is formed again at the anchor.
    let mut cr = py * vz - pz * vy;
    let ats = ts.abs();
    let size = r.o.y.abs()
        + r.o.z.abs()
        + (r.q.y.abs() + r.q.z.abs()) * ats
        + (r.o.x.abs() + r.q.x.abs() * ats) * (my.abs() + mz.abs());
    let bound = R::EPSILON * R::from_f64(2e4) * size;
    if !(cr * cr > bound * bound * vv) {
        // The piece's point nearest the ray's line (0 where v = 0 or the quotient is not
        // finite).
        let mut tau = -pv / vv;
        if !(tau > R::ZERO) {
            tau = R::ZERO;
        }
        if tau > dt {
            tau = dt;
        }
        let ta = (ts + tau).split();
        let xa = anchored(r.o.x, r.q.x, xm, ta);
        let ay = anchored(r.o.y, r.q.y, ly, ta) - xa * my;
        let az = anchored(r.o.z, r.q.z, lz, ta) - xa * mz;
        cr = ay * vz - az * vy;
    }
    Quad { pp: py * py + pz * pz, vv, pv, big_e: cr * cr + r.rc2 * vv }
}

/// The chord walk over the slab part `[ta, tb]` of the span (see the module docs).
fn walk<R: CurveReal>(
    c: &PreparedCurve,
    r: &LocalRay<R>,
    ta: R,
    tb: R,
    settings: &DefaultSettings,
    acc: &mut Acc<R>,
) {
    let table = &c.table;
    let n = table.nodes.len() - 1;
    let levels = table.levels();
    let xh = r.x_head;
    // A ray perpendicular to the axis keeps x = o.x even on an open span (avoids 0·∞ = NaN).
    let x_at = |t: R| if r.q.x == R::ZERO { r.o.x } else { r.o.x + r.q.x * t };
    let xa = x_at(ta).clamp(R::ZERO, xh);
    let xb = x_at(tb).clamp(R::ZERO, xh);
    let (lo, hi, t_lo, t_hi) = if xa <= xb { (xa, xb, ta, tb) } else { (xb, xa, tb, ta) };
    let tol = R::from_f64(settings.tolerance);
    let model = ChordModel::new(r.falloff);

    // x (nearly) constant along the span (within 8ε of X): one piece against the fixed paired
    // point, evaluated exactly (a ray through the curve there meets it to rounding).
    if !(hi - lo > xh * R::EPSILON * R::from_f64(8.0)) || !(tb - ta).is_finite() {
        let cm = curve_at(c, (lo + hi) * R::HALF);
        let (py, pz) = (r.o.y + r.q.y * ta, r.o.z + r.q.z * ta);
        let p = Vec3::new(R::ZERO, py - cm[0], pz - cm[1]);
        acc.piece(r, ta, p, Vec3::new(R::ZERO, r.q.y, r.q.z), tb - ta);
        return;
    }

    let inv_qx = R::ONE / r.q.x;
    let t_of = |x: R| {
        if x == lo {
            t_lo
        } else if x == hi {
            t_hi
        } else {
            t_lo + (x - lo) * inv_qx
        }
    };
    let (mut l, mut j) = (levels - 1, 0usize);
    // Each piece is visited at most once and refined at most once: a hard bound for the loop.
    let max_steps = 4 * (table.errors.len() + levels);
    for _ in 0..max_steps {
        let a = j << l;
        let b = ((j + 1) << l).min(n);
        let na = node::<R>(c, a);
        let nb = node::<R>(c, b);
        if na[0] >= hi {
            break;
        }
        // Levels to descend (0: the piece was accepted or lies outside the range).
        let mut descend = 0usize;
        if nb[0] > lo {
            let x0 = lo.max(na[0]);
            let x1 = hi.min(nb[0]);
            let (tx0, tx1) = (t_of(x0), t_of(x1));
            let (ts, te) = if tx0 <= tx1 { (tx0, tx1) } else { (tx1, tx0) };
            let dt = te - ts;
            let quad = slab_quad(c, r, l, j, (na[0] + nb[0]) * R::HALF, ts, dt);
            let err = R::from_f64(f64::from(table.error(l, j)));
            // The part of the piece's x-range the ray does not cover (0 but at the ray's ends).
            let uncovered =
                if x0 > na[0] || x1 < nb[0] { R::ONE - (x1 - x0) / (nb[0] - na[0]) } else { R::ZERO };
            let (x2, a) = model.terms(err, &quad, dt, r.rc2, uncovered);
            let refine = model.refinement(x2, a, tol, l);
            if refine == 0 {
                acc.piece_quad(r, ts, &quad, dt);
            } else if l == 0 {
                // A leaf too coarse for this ray (it passes within ~δ/τ of the curve): refine
                // below the table on exact curve points.
                acc.evals += 1;
                leaf_walk(c, r, j, (x0, x1), &t_of, tol, &model, acc);
            } else {
                acc.evals += 1;
                descend = refine;
            }
        }
        if descend > 0 {
            l -= descend;
            j <<= descend;
            continue;
        }
        // Advance to the next piece in x order: the right sibling, or up until there is one.
        if !next_piece(&mut j, &mut l, levels, n) {
            return;
        }
    }
}

/// Moves `(j, l)`, piece `j` at level `l` of a table of `levels` levels over `n` leaves, to the
/// next piece in x order: its right sibling, or the right sibling of the nearest ancestor that has
/// one. False when there is none (the walk is over). Shared by the scalar walk and the packet walk
/// (`lanes.rs`), which must visit pieces in the same order.
pub(super) fn next_piece(j: &mut usize, l: &mut usize, levels: usize, n: usize) -> bool {
    loop {
        if *l + 1 >= levels {
            return false;
        }
        if *j & 1 == 0 && ((*j + 1) << *l) < n {
            *j += 1;
            return true;
        }
        *j >>= 1;
        *l += 1;
    }
}

/// The exact cross-section point `c_⊥(x/γ)` at axial coordinate `x` (`s` clamped to the part
/// that exists).
#[inline]
fn curve_at<R: CurveReal>(c: &PreparedCurve, x: R) -> [R; 2] {
    let s = (x / R::from_f64(f64::from(c.wave.gamma))).clamp(R::ZERO, R::from_f64(c.s_head));
    R::shape(c).eval(s)
}

/// Most levels `leaf_walk` descends below a leaf (`CURVE_SUB_LEVELS` in curve.wgsl): a
/// sub-piece is then `2⁻¹⁶` of its leaf, its deviation about `4⁻¹⁶` of the leaf's.
pub const MAX_SUB_LEVELS: usize = 16;

/// A piece below the table: `x ∈ [xa, xb]` with the exact curve points `a`, `b` at its ends.
#[derive(Clone, Copy)]
struct SubPiece<R> {
    xa: R,
    a: [R; 2],
    xb: R,
    b: [R; 2],
    depth: usize,
}

/// The chord walk below leaf `i`, over the part `[x0, x1]` of its `x`-range the ray covers: for
/// rays passing closer to the curve than the leaves resolve (`δ_leaf/D` above the tolerance,
/// which with `r_c = 0` happens within about `δ_leaf/τ` of the curve, including rays through it).
///
/// Each sub-piece `[x_a, x_b]` is bisected on the exact curve: with the midpoint `c_m` and the
/// chord's midpoint deviation `d = c_m − (c_a + c_b)/2`, its line is the chord shifted by `⅔d`,
/// which for a parabolic arc (what a sub-piece of a leaf is, to higher order) is the
/// least-squares line: its deviation has zero mean and zero first moment and at most `⅔|d|`, so
/// the [`ChordModel`] applies as to the table's pieces, with the bound `δ = |d|` (a 1.5× margin
/// for the cubic part). A piece is accepted by the same test, or split in two (depth-first, the
/// right halves on a fixed stack of [`MAX_SUB_LEVELS`] entries), down to [`MAX_SUB_LEVELS`]
/// levels or to where `|d|` is at the rounding level of the coordinates, `ε/2·(|c_m| + |x_m|)`
/// (`f32` then cannot do better; the curve points themselves are good to about that). The
/// bound was `4ε·(…)`, 8× coarser: in `f32` it stopped pieces `10⁻⁵` off the curve, 10 % of a
/// ray passing `10⁻⁴` from it. Every sub-piece visited costs one curve evaluation (its
/// midpoint) and counts one.
#[allow(clippy::too_many_arguments)]
pub(super) fn leaf_walk<R: CurveReal>(
    c: &PreparedCurve,
    r: &LocalRay<R>,
    i: usize,
    (x0, x1): (R, R),
    t_of: &impl Fn(R) -> R,
    tol: R,
    model: &ChordModel<R>,
    acc: &mut Acc<R>,
) {
    let (na, nb) = (node::<R>(c, i), node::<R>(c, i + 1));
    let mut cur = SubPiece { xa: na[0], a: [na[1], na[2]], xb: nb[0], b: [nb[1], nb[2]], depth: 0 };
    let mut stack = [cur; MAX_SUB_LEVELS];
    let mut top = 0usize;
    let two_thirds = R::from_f64(2.0 / 3.0);
    let noise = R::EPSILON * R::HALF;
    loop {
        if cur.xb > x0 && cur.xa < x1 {
            let w = cur.xb - cur.xa;
            let xm = (cur.xa + cur.xb) * R::HALF;
            let cm = curve_at(c, xm);
            let my = (cur.a[0] + cur.b[0]) * R::HALF;
            let mz = (cur.a[1] + cur.b[1]) * R::HALF;
            let (dy, dz) = (cm[0] - my, cm[1] - mz);
            let err = (dy * dy + dz * dz).sqrt();
            let line = [
                my + dy * two_thirds,
                mz + dz * two_thirds,
                (cur.b[0] - cur.a[0]) / w,
                (cur.b[1] - cur.a[1]) / w,
            ];
            let (px0, px1) = (x0.max(cur.xa), x1.min(cur.xb));
            let (tx0, tx1) = (t_of(px0), t_of(px1));
            let (ts, te) = if tx0 <= tx1 { (tx0, tx1) } else { (tx1, tx0) };
            let dt = te - ts;
            let quad = line_quad(r, line, xm, ts, dt);
            let uncovered = if px0 > cur.xa || px1 < cur.xb { R::ONE - (px1 - px0) / w } else { R::ZERO };
            let split = cur.depth < MAX_SUB_LEVELS
                && xm > cur.xa
                && xm < cur.xb
                && err > noise * (cm[0].abs() + cm[1].abs() + xm.abs())
                && {
                    let (x2, a) = model.terms(err, &quad, dt, r.rc2, uncovered);
                    model.refinement(x2, a, tol, 1) > 0
                };
            if split {
                acc.evals += 1;
                let depth = cur.depth + 1;
                stack[top] = SubPiece { xa: xm, a: cm, xb: cur.xb, b: cur.b, depth };
                top += 1;
                cur = SubPiece { xa: cur.xa, a: cur.a, xb: xm, b: cm, depth };
                continue;
            }
            acc.piece_quad(r, ts, &quad, dt);
        }
        if top == 0 {
            return;
        }
        top -= 1;
        cur = stack[top];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::curve::prepare;

    #[allow(dead_code)]
    mod support {
        include!("../../tests/curve_common/mod.rs");
    }
    use crate::quadrature::integrate_adaptive;

    /// Rays per shape and falloff (300 for a calibration run in release mode).
    const RAYS: usize = 60;

    /// The chord model never underestimates: on random rays past the four test curves, every
    /// piece of every level whose estimate lies near the tolerances in use (1e-4 to 1e-2) is
    /// off by less than its estimate, against the exact (adaptive) integral of the curve it
    /// replaces. Prints the ratio actual/estimate binned by ℓ/D (`--nocapture`); the model is
    /// 3–40× conservative in the median (by ℓ/D bin).
    #[test]
    fn chord_model_is_conservative() {
        let edges = [0.0, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0, f64::INFINITY];
        for (name, w) in support::shapes() {
            for falloff in [Falloff::Faithful, Falloff::InverseSquare] {
                let c = prepare(&w);
                let table = &c.table;
                let n = table.nodes.len() - 1;
                let model = ChordModel::<f64>::new(falloff);
                let rc = if falloff == Falloff::Faithful { 0.0 } else { 0.05 };
                let fp = FieldParams { falloff, core_radius: rc };
                let gamma = f64::from(w.gamma);
                let mut rng = support::Rng(0x1234_5678_9abc_def1);
                let mut bins: Vec<Vec<f64>> = vec![Vec::new(); edges.len() - 1];
                for _ in 0..RAYS {
                    let u = [rng.unit() * 2.0 - 1.0, rng.unit() * 2.0 - 1.0, rng.unit() * 2.0 - 1.0];
                    let dirn = Vec3::new(u[0], u[1], u[2]).normalize_or(Vec3::X);
                    let target = c.point(rng.unit() * c.s_head)
                        + Vec3::new(rng.unit() - 0.5, rng.unit() - 0.5, rng.unit() - 0.5)
                            * (4.0 * rng.unit());
                    let eye = target + dirn * (5.0 + 35.0 * rng.unit());
                    let ray = Ray { origin: eye, dir: (target - eye).normalize_or(Vec3::X) };
                    let Some(r) = LocalRay::new(&c, &fp, &ray, 0.0, 80.0, 100.0) else { continue };
                    if r.q.x.abs() < 1e-6 {
                        continue;
                    }
                    let (xa, xb) = (r.o.x, r.o.x + r.q.x * 80.0);
                    let (lo, hi) = (xa.min(xb), xa.max(xb));
                    let rc2 = r.rc2;
                    for l in 1..table.levels() {
                        for j in 0..n.div_ceil(1 << l) {
                            let a = j << l;
                            let b = ((j + 1) << l).min(n);
                            let (na, nb) = (node::<f64>(&c, a), node::<f64>(&c, b));
                            let x0 = lo.max(na[0]);
                            let x1 = hi.min(nb[0]);
                            if !(x1 > x0) {
                                continue;
                            }
                            let (t0, t1) = ((x0 - r.o.x) / r.q.x, (x1 - r.o.x) / r.q.x);
                            let (ts, te) = (t0.min(t1), t0.max(t1));
                            let dt = te - ts;
                            let quad = slab_quad(&c, &r, l, j, (na[0] + nb[0]) * 0.5, ts, dt);
                            let err = f64::from(table.error(l, j));
                            let ell = (quad.vv * dt * dt * quad.inv_closest(dt, rc2)).sqrt();
                            let uncovered = 1.0 - (x1 - x0) / (nb[0] - na[0]);
                            let (x2m, am) = model.terms(err, &quad, dt, rc2, uncovered);
                            let est = model.estimate(x2m, am);
                            let line = Segment::from_quad(falloff, &quad, dt, rc2).value;
                            let k = if falloff == Falloff::Faithful { 0.5 } else { 1.0 };
                            let exact = integrate_adaptive(
                                |t| {
                                    let x = r.o.x + r.q.x * t;
                                    let cc = c.cross_section(x / gamma);
                                    let dy = r.o.y + r.q.y * t - cc[0];
                                    let dz = r.o.z + r.q.z * t - cc[1];
                                    (dy * dy + dz * dz + rc2).powf(-k)
                                },
                                ts,
                                te,
                                1e-11,
                                0.0,
                            )
                            .value;
                            let actual = (line - exact).abs() / exact;
                            if est > 1e-4 && est < 1e-2 {
                                let bin = edges.windows(2).position(|e| ell >= e[0] && ell < e[1]).unwrap();
                                bins[bin].push(actual / est);
                            }
                        }
                    }
                }
                let worst = bins.iter().flatten().copied().fold(0.0, f64::max);
                println!("{name} {falloff:?}: actual/estimate by ℓ/D (worst {worst:.3})");
                for (i, b) in bins.iter_mut().enumerate() {
                    b.sort_by(f64::total_cmp);
                    if b.is_empty() {
                        continue;
                    }
                    let q = |f: f64| b[((b.len() - 1) as f64 * f) as usize];
                    println!(
                        "  [{:>5}, {:>5}) n={:6} median {:.3} p99 {:.3} max {:.3}",
                        edges[i],
                        edges[i + 1],
                        b.len(),
                        q(0.5),
                        q(0.99),
                        q(1.0)
                    );
                }
                assert!(
                    bins.iter().map(Vec::len).sum::<usize>() > 1000,
                    "{name} {falloff:?}: too few pieces"
                );
                assert!(worst < 1.0, "{name} {falloff:?}: a piece is off by {worst} times its estimate");
            }
        }
    }
}
