//! The nearest-point field ([`Integrator::Nearest`](super::Integrator::Nearest)): the density at
//! a ray point `P` is taken at its true nearest point on the curve, `r = min_s |P − c(s)|`,
//! instead of at the point paired with it by cross-section (SPEC.md §1.4's pairing, 002 §3.4.2).
//!
//! # Why
//! The cross-section pairing measures `r` inside `P`'s own cross-section, so where the curve runs
//! steeply across its axis (a helix's crests seen from the side) a point just beside the crest,
//! in a cross-section where the curve has already moved away, is paired with a far point: the
//! energy along a row above a crest has a narrow spike where the row passes the cross-section of
//! the crest — the faint vertical streaks of `spiral-drill` and the Fig. 4.2 scenes. The nearest
//! distance is continuous and 1-Lipschitz in `P`; it has no such spike (`tests/curve_nearest.rs`).
//!
//! # Distance: branch and bound over the piece table
//! [`nearest_point`] searches the [`PieceTable`](super::PieceTable) tree depth first. A piece of
//! any level spans `[x_a, x_b]` and its least-squares line `L` deviates from the curve by at most
//! `δ` in the cross-section at equal `x`, so every curve point of the piece is within `δ` of the
//! 3-D segment `(x, L(x))`, `x ∈ [x_a, x_b]`: `|P − segment| − δ` bounds the distance to that
//! part of the curve from below. A piece whose bound is not below the best distance found
//! (less a relative [`NEAREST_PRUNE`]) is skipped; otherwise its children are visited, the one
//! nearer in `x` first. At a leaf the distance to its chord between two exact curve points is
//! taken (within the leaf tolerance of the curve). The search starts from an exact upper bound,
//! the previous sample's nearest point `c(s)` (its parameter and its point, so that the bound
//! costs no curve evaluation), so along a ray only the pieces near the answer are opened. The
//! winning leaf is refined on the exact curve by one parabolic step on `g(s) = |P − c(s)|²`
//! (nearly quadratic over a leaf: three exact points about the chord's nearest point, then the
//! parabola's vertex), and the smallest exact `g` is returned:
//! the distance is always that of an exact curve point. Every curve point, the two ends included,
//! is a candidate, so the ends are round without a special case.
//!
//! # Integral along the ray
//! `D(t) = sqrt(r(t)² + r_c²)` changes by at most `|q|` per unit of `t`, so over an interval of
//! length `h = NEAREST_STEP·D(a)/|q|` it stays within a factor `1 ± NEAREST_STEP` of `D(a)` and no
//! peak of the density can hide inside: the span is walked in such intervals, each integrated by
//! Simpson's rule on the exact density `w(D)·(1 − u)^j` (002 eq. 3.17 or hadou's `1/r²`, with the
//! attenuation of eq. 3.23; near the far point with `j > 0` the step is also held to
//! `NEAREST_STEP·(t_far − a)`, not below `10⁻³ t_far`, so that `(1 − u)^j` is smooth on it). The
//! number of intervals grows like `log` of the ratio of the span to the closest approach. An
//! inverse-square span that is infinite is walked until the ray is [`TAIL_RADII`] bounding radii
//! from the curve's centre and receding; the rest is the exact integral towards the nearest point
//! found there (a sphere piece, `closed.rs`), which is within `2/TAIL_RADII` of the true distance
//! on a tail that holds a small share of the energy.
//!
//! # Work
//! At most [`MAX_NEAREST_STEPS`] intervals (two distance queries each) and
//! [`MAX_NEAREST_VISITS`] pieces per query: the remaining span, if any, is one last interval, and a
//! query that hits the visit limit returns the best exact point found. The evaluation count
//! ([`CurveSample::evaluations`](super::CurveSample)) is the number of pieces visited plus the
//! exact curve points evaluated.
//!
//! Every function has a WGSL twin in `crates/hadou-gpu/src/shaders/curve.wgsl`
//! (`curve_nearest_point`, `curve_nearest`).

use super::closed::{Quad, Segment};
use super::local_ray::{CurveReal, LocalRay};
use super::prepare::PreparedCurve;
use crate::energy::{scaled, Falloff};
use crate::{Real, Vec3};

/// An interval of the ray walk covers at most this fraction of the distance `D` at its start.
pub const NEAREST_STEP: f64 = 0.25;
/// Most intervals per ray: with [`MAX_NEAREST_VISITS`] it bounds a ray's work by
/// [`NEAREST_RAY_WORK`] (512 allowed 2.1 million pieces visited on one ray; a 512-point order-2
/// B-spline zigzag seen down its axis took 1.87 million).
pub const MAX_NEAREST_STEPS: u32 = 180;
/// Most work one ray of the nearest-point field takes, by construction: the first query and two
/// per interval ([`MAX_NEAREST_STEPS`]), each at most [`MAX_NEAREST_VISITS`] pieces and 8 exact
/// points (a query takes 4, and the walk's start 1: the bound keeps the margin of the two-step
/// refinement it was set for), and the closed tail: 742 217 (below 750 000).
pub const NEAREST_RAY_WORK: u64 = (2 * MAX_NEAREST_STEPS as u64 + 1) * (MAX_NEAREST_VISITS as u64 + 8) + 1;
/// Most pieces one distance query visits.
pub const MAX_NEAREST_VISITS: u32 = 2048;
/// Relative slack of the pruning: a piece is skipped unless its lower bound is below
/// `(1 − NEAREST_PRUNE)` times the best distance found (near-ties change `r` by less).
pub const NEAREST_PRUNE: f64 = 1e-4;
/// An infinite span's closed tail starts this many bounding radii from the curve's centre.
pub const TAIL_RADII: f64 = 64.0;
/// Parabolic steps of the refinement on the exact curve (one is as accurate as two on the
/// random rays of `tests/curve_nearest.rs`: the chord's nearest point is already within a leaf's
/// tolerance).
const REFINE_STEPS: usize = 1;
/// Depth of the search stack (the table has at most 15 levels; a depth-first walk holds at most
/// one pending sibling per level).
const STACK: usize = 32;

/// The nearest exact curve point found for one query: `(squared distance, parameter s, work)`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Nearest<R> {
    /// `|P − c(s)|²`.
    pub d2: R,
    /// Curve parameter of the point.
    pub s: R,
    /// The exact curve point `c(s)` in local coordinates.
    pub foot: Vec3<R>,
    /// Pieces visited plus exact points evaluated.
    pub work: u32,
}

/// Squared distance from `p` to the segment `a..b` and the segment parameter of the nearest
/// point (the search compares squares: no square root per piece).
#[inline]
fn segment<R: Real>(p: Vec3<R>, a: Vec3<R>, b: Vec3<R>) -> (R, R) {
    let d = b - a;
    let dd = d.dot(d);
    let f = if dd > R::ZERO { ((p - a).dot(d) / dd).clamp(R::ZERO, R::ONE) } else { R::ZERO };
    ((p - (a + d * f)).length_squared(), f)
}

/// The vertex of the parabola through three points (`x2` between the others), or `None` when
/// the three are not convex.
#[inline]
fn parabola_vertex<R: Real>(x1: R, g1: R, x2: R, g2: R, x3: R, g3: R) -> Option<R> {
    let (a, b) = (x2 - x1, x2 - x3);
    let num = a * a * (g2 - g3) - b * b * (g2 - g1);
    let den = a * (g2 - g3) - b * (g2 - g1);
    // Convex: the middle value below the chord of the outer two.
    if !(den < R::ZERO) && !(den > R::ZERO) {
        return None;
    }
    let v = x2 - R::HALF * num / den;
    let chord = g1 + (g3 - g1) * (x2 - x1) / (x3 - x1);
    if v.is_finite() && g2 <= chord {
        Some(v)
    } else {
        None
    }
}

/// The nearest point of the curve to the local point `p`, by branch and bound over the piece
/// table, refined on the exact curve (see the module docs). `hint` is an exact curve point
/// `(s, c(s))` whose distance starts the search as an upper bound.
pub(crate) fn nearest_point<R: CurveReal>(c: &PreparedCurve, p: Vec3<R>, hint: (R, Vec3<R>)) -> Nearest<R> {
    let table = &c.table;
    let shape = R::shape(c);
    let gamma = R::from_f64(f64::from(c.wave.gamma));
    let s_head = R::from_f64(c.s_head);
    let n = table.nodes.len() - 1;
    let levels = table.level_offsets.len() - 1;
    let point = |s: R| {
        let cs = shape.eval(s);
        Vec3::new(gamma * s, cs[0], cs[1])
    };
    let node = |i: usize| {
        let v = table.nodes[i];
        Vec3::new(R::from_f64(f64::from(v[0])), R::from_f64(f64::from(v[1])), R::from_f64(f64::from(v[2])))
    };
    let node_s = |i: usize| R::from_f64(f64::from(table.nodes[i][3]));
    let mut out = Nearest { d2: (p - hint.1).length_squared(), s: hint.0, foot: hint.1, work: 0 };
    let mut best2 = out.d2;
    let mut best = best2.sqrt();
    let keep = R::ONE - R::from_f64(NEAREST_PRUNE);
    let mut leaf: Option<(usize, R)> = None;
    let mut stack = [(0u32, 0u32); STACK];
    stack[0] = ((levels - 1) as u32, 0);
    let mut top = 1usize;
    let mut visits = 0u32;
    while top > 0 && visits < MAX_NEAREST_VISITS {
        top -= 1;
        let (l, j) = (stack[top].0 as usize, stack[top].1 as usize);
        visits += 1;
        let a = j << l;
        let b = ((j + 1) << l).min(n);
        let (na, nb) = (node(a), node(b));
        if l == 0 {
            let (d2, f) = segment(p, na, nb);
            if d2 < best2 {
                best2 = d2;
                best = d2.sqrt();
                leaf = Some((a, f));
            }
            continue;
        }
        let k = table.level_offsets[l] as usize + j;
        let [ly, lz, my, mz] = table.lines[k].map(|v| R::from_f64(f64::from(v)));
        let delta = R::from_f64(f64::from(table.errors[k]));
        let xm = R::HALF * (na.x + nb.x);
        let end = |x: R| Vec3::new(x, ly + (x - xm) * my, lz + (x - xm) * mz);
        // |P − segment| − δ < best·keep, squared (both sides of |P − segment| < best·keep + δ
        // are non-negative).
        let (d2, _) = segment(p, end(na.x), end(nb.x));
        let reach = best * keep + delta;
        if !(d2 < reach * reach) {
            continue;
        }
        let left = (l as u32 - 1, 2 * j as u32);
        let right_start = (2 * j + 1) << (l - 1);
        if right_start >= n {
            stack[top] = left;
            top += 1;
            continue;
        }
        let right = (l as u32 - 1, 2 * j as u32 + 1);
        // The child nearer in x is visited first (pushed last).
        let xs = node(right_start).x;
        let (first, second) = if p.x < xs { (left, right) } else { (right, left) };
        if top + 2 <= STACK {
            stack[top] = second;
            stack[top + 1] = first;
            top += 2;
        }
    }
    out.work += visits;
    if let Some((a, f)) = leaf {
        // Two parabolic steps on the exact g over the leaf (and its neighbours' halves).
        let (sa, sb) = (node_s(a), node_s(a + 1));
        let w = sb - sa;
        let (lo, hi) = ((sa - w * R::HALF).max(R::ZERO), (sb + w * R::HALF).min(s_head));
        let mut s0 = sa + w * f;
        let mut h = w * R::from_f64(0.25);
        for _ in 0..REFINE_STEPS {
            let x1 = (s0 - h).max(lo);
            let x3 = (s0 + h).min(hi);
            let (c1, c2, c3) = (point(x1), point(s0), point(x3));
            let (g1, g2, g3) =
                ((p - c1).length_squared(), (p - c2).length_squared(), (p - c3).length_squared());
            out.work += 3;
            for (s, v, f) in [(x1, g1, c1), (s0, g2, c2), (x3, g3, c3)] {
                if v < out.d2 {
                    out.d2 = v;
                    out.s = s;
                    out.foot = f;
                }
            }
            let next = if x1 < s0 && s0 < x3 { parabola_vertex(x1, g1, s0, g2, x3, g3) } else { None };
            let Some(v) = next else { break };
            let v = v.clamp(lo, hi);
            h = ((v - s0).abs() * R::TWO).max(w * R::from_f64(1.0 / 64.0)).min(h);
            s0 = v;
        }
        let cv = point(s0);
        let gv = (p - cv).length_squared();
        out.work += 1;
        if gv < out.d2 {
            out.d2 = gv;
            out.s = s0;
            out.foot = cv;
        }
    }
    out
}

/// The density `w(D)` (without the attenuation) at the squared distance `r²`.
#[inline]
fn weight<R: Real>(falloff: Falloff, d2: R, rc2: R) -> R {
    let q = d2 + rc2;
    match falloff {
        Falloff::Faithful => R::ONE / q.sqrt(),
        Falloff::InverseSquare => R::ONE / q,
    }
}

/// The nearest-point field's integral over the resolved span of `r`: `(α·∫, evaluations)`
/// (see the module docs).
pub(crate) fn nearest_generic<R: CurveReal>(c: &PreparedCurve, r: &LocalRay<R>) -> (R, u32) {
    let qn = r.q.length();
    if !(qn > R::ZERO) || !qn.is_finite() {
        return (R::ZERO, 0);
    }
    let step = R::from_f64(NEAREST_STEP);
    let mut work = 0u32;
    // The end of the walk: the span's end, or where an infinite span's tail starts.
    let mut end = r.t1;
    let open = !r.t1.is_finite();
    if open {
        let centre = Vec3::new(R::HALF * r.x_head, R::ZERO, R::ZERO);
        let rb = R::from_f64(c.tail_radius());
        let big = R::from_f64(TAIL_RADII) * rb;
        let qq = qn * qn;
        let tc = (centre - r.o).dot(r.q) / qq;
        let h2 = (r.at(tc) - centre).length_squared();
        let reach = (big * big - h2).max(R::ZERO).sqrt() / qn;
        end = r.t0.max(tc + reach);
    }
    let mut a = r.t0;
    let start = R::shape(c).eval(R::ZERO);
    let mut na = nearest_point(c, r.at(a), (R::ZERO, Vec3::new(R::ZERO, start[0], start[1])));
    work += 1;
    work += na.work;
    let mut fa = weight(r.falloff, na.d2, r.rc2) * r.attenuation(a);
    let mut sum = R::ZERO;
    let floor = R::from_f64(1e-3) * r.t_far;
    let mut steps = 0u32;
    while a < end {
        steps += 1;
        let d = (na.d2 + r.rc2).sqrt();
        let mut h = step * d / qn;
        if r.j > R::ZERO {
            h = h.min((step * (r.t_far - a)).max(floor));
        }
        let b = if steps >= MAX_NEAREST_STEPS || !(a + h < end) { end } else { a + h };
        let m = R::HALF * (a + b);
        let nm = nearest_point(c, r.at(m), (na.s, na.foot));
        let nb = nearest_point(c, r.at(b), (nm.s, nm.foot));
        work += nm.work + nb.work;
        let fm = weight(r.falloff, nm.d2, r.rc2) * r.attenuation(m);
        let fb = weight(r.falloff, nb.d2, r.rc2) * r.attenuation(b);
        sum += (b - a) / R::from_f64(6.0) * (fa + R::from_f64(4.0) * fm + fb);
        (a, na, fa) = (b, nb, fb);
    }
    if open {
        // The tail: towards the nearest point found at its start (module docs).
        let quad = Quad::new(r.at(end) - na.foot, r.q, r.rc2);
        sum += Segment::from_quad(r.falloff, &quad, R::INFINITY, r.rc2).value;
        work += 1;
    }
    (scaled(sum, r.alpha), work)
}
