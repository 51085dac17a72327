//! What a curve costs per ray, read off its parameters: the turns a periodic curve makes, how
//! steep a curve is against its axis, and the price of one curve point. [`CurveWave::validate`]
//! holds them to [`MAX_TURNS`], [`MAX_SLOPE`] and the Simpson budget, and the sanitizing that
//! [`prepare`](fn@super::prepare) runs brings any wave back within them, so that the work of
//! every ray through a curve is bounded whatever its parameters.
//!
//! # Why these three
//! - **Turns.** The default integrator replaces the curve, per ray, by straight pieces that are
//!   each within tolerance for that ray. A ray that passes a turn closely needs pieces down to
//!   the turn's scale there, so its work grows with the turns it passes: up to about 150
//!   evaluations per helix turn and 650 per turn of a trigonometric sum's fastest harmonic (a
//!   ray along the axis meeting the curve at every turn; `tests/curve_cost.rs`). The piece table
//!   holds [`MAX_PIECES`](super::MAX_PIECES) leaves, so beyond a few hundred turns its leaves
//!   span whole turns and every ray near the curve refines below them on exact curve points:
//!   `rate = −1e6` over 11 units (1.75 million turns) cost half a million evaluations per pixel.
//!   The control-point curves are bounded by their point counts instead: by the
//!   variation-diminishing property a Bézier or B-spline curve crosses any plane no more often
//!   than its control polygon, which has `points − 1` edges.
//! - **Steepness** `M = max |dc_⊥/dx|`: how far the curve moves across its axis per unit of
//!   travel along it. The chord walk forms the squared speed `|q_⊥ − q_x·m|²` of the ray relative
//!   to each piece (`m` the piece's slope, at most `M`); with the faithful ray `|q| < 2e13` (the
//!   scene's far-plane and field-of-view limits) this stays finite only while `M` is below about
//!   `9e5`, and `1e5` leaves a factor 80 in the square. Past it the walk's error model became NaN,
//!   which refined every leaf 16 levels deep (2¹⁷ evaluations each) and saturated the energy.
//! - **Point cost.** Simpson samples the exact curve `m + 1` times per ray, the default
//!   integrator samples it where it refines below the table, and the table is built from about
//!   eleven points per leaf; a point of a trigonometric sum costs a sine and a cosine per term. At
//!   `m = 100000`, 1024 + 1024 terms took 2.6 s per ray, and with the default integrator up to
//!   7 s per ray and 10 s per frame to prepare: hence at most
//!   [`MAX_TRIG_TERMS`](super::MAX_TRIG_TERMS) terms, and `m` times the price of one point, in
//!   helix points ([`CurveWave::point_cost`]), held to [`MAX_SIMPSON_M`], what the largest `m`
//!   costs a helix.
//! - **The nearest-point field** (`nearest.rs`) is bounded by construction: at most
//!   [`MAX_NEAREST_STEPS`](super::MAX_NEAREST_STEPS) intervals of two distance queries, each
//!   visiting at most [`MAX_NEAREST_VISITS`](super::MAX_NEAREST_VISITS) pieces and evaluating 4
//!   exact points, under [`NEAREST_RAY_WORK`](super::NEAREST_RAY_WORK) evaluations. The limits above keep it far below: its work
//!   grows with the turns a ray passes near the axis, where every turn is about as near, and the
//!   costliest corner (a 128-turn helix one unit long) takes about 7.5·10⁵ piece visits on its
//!   worst ray; the example scenes take 2 000–6 000 (`tests/curve_cost.rs`,
//!   `tests/curve_nearest.rs`). A piece visit is a point-to-segment distance, cheaper than a
//!   curve point.
//!
//! The turn limit also keeps the `f32` phase `θs` of a curve point below `2π·128 ≈ 804` rad,
//! where it rounds to `6·10⁻⁵` rad, a relative error a ray passing through the curve with no core
//! radius can see (`tests/curve_near_hit.rs` documents the same for a 5-turn helix): a 128-turn
//! helix seen along its axis with `core_radius = 0` had one pixel in 48 off by 8 %, and none
//! beyond `3·10⁻⁵` with `core_radius = 0.02`.

use super::shape::clamped_uniform_knots;
use super::wave::{CurveShape, CurveWave, Integrator, MAX_SIMPSON_M};
#[cfg(doc)]
use super::wave::{MAX_SLOPE, MAX_TURNS};
use std::f64::consts::TAU;

fn hyp(a: f64, b: f64) -> f64 {
    (a * a + b * b).sqrt()
}

/// `Σ n·|θ|·√(a_n² + b_n²)`: a bound on `|d/ds Σ a_n sin(nθs) + b_n cos(nθs)|`.
fn trig_speed(rate: f64, terms: &[[f32; 2]]) -> f64 {
    terms.iter().enumerate().map(|(i, t)| (i + 1) as f64 * rate * hyp(f64::from(t[0]), f64::from(t[1]))).sum()
}

/// A bound on `|dc_⊥/dτ|` of a B-spline over its valid knot range, from the control points of
/// its derivative, `(k − 1)(P_{i+1} − P_i)/(x_{i+k} − x_{i+1})` (convex hull). A difference over
/// an empty knot interval strictly inside the valid range is a jump (an interior knot repeated
/// `k` times): infinite.
fn bspline_speed(points: &[[f32; 2]], order: usize, knots: &[f64]) -> f64 {
    let n = points.len() - 1;
    let (lo, hi) = (knots[order - 1], knots[n + 1]);
    let mut m: f64 = 0.0;
    for i in 0..n {
        let d = hyp(
            f64::from(points[i + 1][0]) - f64::from(points[i][0]),
            f64::from(points[i + 1][1]) - f64::from(points[i][1]),
        );
        let (a, b) = (knots[i + 1], knots[i + order]);
        if b > a {
            m = m.max((order - 1) as f64 * d / (b - a));
        } else if d > 0.0 && a > lo && a < hi {
            return f64::INFINITY;
        }
    }
    m
}

impl CurveWave {
    /// The turns the curve makes over its whole length `s_end` (the extension `k` only shortens
    /// it): `|θ|·s_end/2π` for a helix (002 eq. 3.25), `H·|θ|·s_end/2π` for a trigonometric sum
    /// whose longer list has `H` terms (its fastest harmonic's turns, 002 eq. 3.30); `None` for
    /// Bézier and B-spline curves, which their point counts bound. At most [`MAX_TURNS`].
    pub fn turns(&self) -> Option<f64> {
        match &self.shape {
            CurveShape::Helix { rate, length, .. } => Some(f64::from(*rate).abs() * f64::from(*length) / TAU),
            CurveShape::TrigSum { rate, y_terms, z_terms, length } => {
                let h = y_terms.len().max(z_terms.len()) as f64;
                Some(h * f64::from(*rate).abs() * f64::from(*length) / TAU)
            }
            CurveShape::Bezier { .. } | CurveShape::BSpline { .. } => None,
        }
    }

    /// A bound on the curve's steepness `max |dc_⊥/dx|` (`x = γs`, 002 eq. 3.14): how far it
    /// moves across its axis per unit of travel along it, from the derivatives of the shapes:
    /// `r·|θ|/γ` for a helix (002 eq. 3.25, exact); `|(Σ nθ|(a_n, b_n)|, Σ nθ|(c_n, d_n)|)|/γ`
    /// for a trigonometric sum (002 eq. 3.30); `n·max|P_{i+1} − P_i|/γ` for a Bézier curve of
    /// degree `n` (002 eq. 3.31–3.32: its derivative is the Bézier curve of the points
    /// `n(P_{i+1} − P_i)`, inside their convex hull); for a B-spline (002 eq. 3.33–3.34) the
    /// largest control point of its derivative, `(k − 1)|P_{i+1} − P_i|/(x_{i+k} − x_{i+1})`,
    /// times the valid knot range (`s` maps onto it linearly) over `γ`, infinite where an
    /// interior knot repeated `k` times makes it jump. At most [`MAX_SLOPE`]. Expects a valid
    /// shape (see [`CurveWave::validate`]).
    pub fn steepness(&self) -> f64 {
        let speed = match &self.shape {
            CurveShape::Helix { radius, rate, .. } => f64::from(*radius).abs() * f64::from(*rate).abs(),
            CurveShape::TrigSum { rate, y_terms, z_terms, .. } => {
                let rate = f64::from(*rate).abs();
                hyp(trig_speed(rate, y_terms), trig_speed(rate, z_terms))
            }
            CurveShape::Bezier { points } => {
                let n = points.len().saturating_sub(1) as f64;
                let d = points
                    .windows(2)
                    .map(|w| {
                        hyp(f64::from(w[1][0]) - f64::from(w[0][0]), f64::from(w[1][1]) - f64::from(w[0][1]))
                    })
                    .fold(0.0, f64::max);
                n * d
            }
            CurveShape::BSpline { points, order, knots } => {
                let k = *order as usize;
                if points.len() < k.max(2) {
                    return 0.0;
                }
                let knots: Vec<f64> = match knots {
                    Some(kn) => kn.iter().map(|&x| f64::from(x)).collect(),
                    None => clamped_uniform_knots(points.len(), k),
                };
                let n = points.len() - 1;
                let (lo, hi) = (knots[k - 1], knots[n + 1]);
                (hi - lo) * bspline_speed(points, k, &knots)
            }
        };
        speed / f64::from(self.gamma)
    }

    /// The work of one exact curve point, in helix points (measured: a helix point with its
    /// density is one sine–cosine pair and a square root): 1 for a helix, half the terms of a
    /// trigonometric sum (`y_terms` and `z_terms` together, a sine and a cosine each), a third
    /// of the control points of a Bézier curve, the order of a B-spline; at least 1. Simpson's
    /// `m` times it is at most [`MAX_SIMPSON_M`].
    pub fn point_cost(&self) -> f64 {
        let cost = match &self.shape {
            CurveShape::Helix { .. } => 1.0,
            CurveShape::TrigSum { y_terms, z_terms, .. } => (y_terms.len() + z_terms.len()) as f64 / 2.0,
            CurveShape::Bezier { points } => points.len() as f64 / 3.0,
            CurveShape::BSpline { order, .. } => f64::from(*order),
        };
        cost.max(1.0)
    }

    /// The largest Simpson `m` this curve allows: `MAX_SIMPSON_M / point_cost`, rounded down to
    /// an even number (at least 2).
    pub fn max_simpson_m(&self) -> u32 {
        let m = (f64::from(MAX_SIMPSON_M) / self.point_cost()).floor() as u32;
        (m & !1).max(2)
    }
}

/// Most evaluations one ray of the default integrator takes through any curve within the limits
/// (turns, terms, control points, steepness; `tests/curve_cost.rs` holds every corner to it: the
/// measured worst is 73 195, a 64-term `trig` sum at 128 turns).
pub const DEFAULT_RAY_WORK: u64 = 100_000;

impl Integrator {
    /// The most evaluations one ray of this integrator may take through any curve within the
    /// limits: [`DEFAULT_RAY_WORK`]; Simpson's `m + 1` samples per region (three regions with
    /// a reduction) plus the default integrator's tail past the far point; the nearest-point
    /// field's [`NEAREST_RAY_WORK`](super::nearest::NEAREST_RAY_WORK).
    pub fn ray_work_bound(&self) -> u64 {
        match self {
            Integrator::Default => DEFAULT_RAY_WORK,
            Integrator::Simpson { m, reduction } => {
                (if reduction.is_some() { 3 } else { 1 }) * (u64::from(*m) + 1) + DEFAULT_RAY_WORK
            }
            Integrator::Nearest => super::nearest::NEAREST_RAY_WORK,
        }
    }
}
