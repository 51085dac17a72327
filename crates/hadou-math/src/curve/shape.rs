//! Evaluation of the cross-section curves `(y(s), z(s))` (002 §3.4.7–3.4.10), generic over
//! [`Real`] so the per-ray integrators run in `f32` and the converged reference in `f64` from one
//! source.

use super::wave::{CurveShape, MAX_ORDER};
use crate::Real;

/// A cross-section curve ready for evaluation in precision `R`: the shape's parameters converted
/// once, the B-spline knot vector made explicit.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum ShapeEval<R> {
    /// `y = r sin(θ s + φ)`, `z = r cos(θ s + φ)` (002 eq. 3.25, with a phase).
    Helix { radius: R, rate: R, phase: R },
    /// `y = Σ a_n sin(nθs) + b_n cos(nθs)`, `z = Σ c_n sin(nθs) + d_n cos(nθs)` (002 eq. 3.30).
    Trig { rate: R, y_terms: Vec<[R; 2]>, z_terms: Vec<[R; 2]> },
    /// Bernstein form `Σ B_i^n(s) P_i` (002 eq. 3.31–3.32).
    Bezier { points: Vec<[R; 2]> },
    /// `Σ N_k^i(τ) P_i` with `τ = lo + s (hi − lo)` (002 eq. 3.33–3.34).
    BSpline { points: Vec<[R; 2]>, order: usize, knots: Vec<R>, lo: R, hi: R },
}

/// `s_end`: the curve parameter's upper end (`length` for the periodic shapes, 1 for the
/// control-point curves).
pub(crate) fn s_end(shape: &CurveShape) -> f64 {
    match shape {
        CurveShape::Helix { length, .. } | CurveShape::TrigSum { length, .. } => f64::from(*length),
        CurveShape::Bezier { .. } | CurveShape::BSpline { .. } => 1.0,
    }
}

/// The clamped uniform knot vector of order `k` over `count` control points: `k` zeros, the
/// interior knots `1/(n−k+2), 2/(n−k+2), …`, `k` ones (`n + k + 1` values, `n = count − 1`).
pub fn clamped_uniform_knots(count: usize, order: usize) -> Vec<f64> {
    let n = count.saturating_sub(1);
    let total = n + order + 1;
    let spans = (n + 2).saturating_sub(order).max(1);
    (0..total)
        .map(|i| {
            if i < order {
                0.0
            } else if i > n {
                1.0
            } else {
                (i + 1 - order) as f64 / spans as f64
            }
        })
        .collect()
}

fn conv<R: Real>(v: f32) -> R {
    R::from_f64(f64::from(v))
}

fn conv2<R: Real>(p: &[[f32; 2]]) -> Vec<[R; 2]> {
    p.iter().map(|q| [conv(q[0]), conv(q[1])]).collect()
}

impl<R: Real> ShapeEval<R> {
    /// Converts a (sanitized, valid) shape.
    pub(crate) fn new(shape: &CurveShape) -> Self {
        match shape {
            CurveShape::Helix { radius, rate, phase, .. } => {
                ShapeEval::Helix { radius: conv(*radius), rate: conv(*rate), phase: conv(*phase) }
            }
            CurveShape::TrigSum { rate, y_terms, z_terms, .. } => {
                ShapeEval::Trig { rate: conv(*rate), y_terms: conv2(y_terms), z_terms: conv2(z_terms) }
            }
            CurveShape::Bezier { points } => ShapeEval::Bezier { points: conv2(points) },
            CurveShape::BSpline { points, order, knots } => {
                let order = *order as usize;
                let knots: Vec<R> = match knots {
                    Some(k) => k.iter().map(|&x| conv(x)).collect(),
                    None => clamped_uniform_knots(points.len(), order).into_iter().map(R::from_f64).collect(),
                };
                let n = points.len() - 1;
                let (lo, hi) = (knots[order - 1], knots[n + 1]);
                ShapeEval::BSpline { points: conv2(points), order, knots, lo, hi }
            }
        }
    }

    /// The cross-section point `(y(s), z(s))`; `s` must lie in `[0, s_end]`.
    #[inline]
    pub(crate) fn eval(&self, s: R) -> [R; 2] {
        match self {
            ShapeEval::Helix { radius, rate, phase } => {
                let a = *rate * s + *phase;
                [*radius * a.sin(), *radius * a.cos()]
            }
            ShapeEval::Trig { rate, y_terms, z_terms } => {
                [trig_sum(*rate, s, y_terms), trig_sum(*rate, s, z_terms)]
            }
            ShapeEval::Bezier { points } => bezier(points, s),
            ShapeEval::BSpline { points, order, knots, lo, hi } => {
                let tau = *lo + s.clamp(R::ZERO, R::ONE) * (*hi - *lo);
                bspline(points, *order, knots, tau)
            }
        }
    }
}

/// `Σ_{n≥1} a_n sin(nθs) + b_n cos(nθs)` (002 eq. 3.30).
#[inline]
fn trig_sum<R: Real>(rate: R, s: R, terms: &[[R; 2]]) -> R {
    let mut acc = R::ZERO;
    let mut n = R::ZERO;
    for t in terms {
        n += R::ONE;
        let a = n * rate * s;
        acc += t[0] * a.sin() + t[1] * a.cos();
    }
    acc
}

/// Bernstein form `Σ C(n,i) s^i (1 − s)^{n−i} P_i` (002 eq. 3.31–3.32), evaluated in one pass
/// with running binomials and powers (the nested form `((P₀u + C(n,1)sP₁)u + …)u + sⁿPₙ`,
/// `u = 1 − s`): O(n) per point, no scratch memory, exact at both ends.
#[inline]
pub(crate) fn bezier<R: Real>(points: &[[R; 2]], s: R) -> [R; 2] {
    let n = points.len() - 1;
    let u = R::ONE - s;
    let mut acc = [points[0][0] * u, points[0][1] * u];
    let mut sn = R::ONE;
    let mut binom = R::ONE;
    for (i, p) in points.iter().enumerate().take(n).skip(1) {
        sn *= s;
        binom = binom * R::from_f64((n + 1 - i) as f64) / R::from_f64(i as f64);
        let w = sn * binom;
        acc = [(acc[0] + w * p[0]) * u, (acc[1] + w * p[1]) * u];
    }
    let w = sn * s;
    [acc[0] + w * points[n][0], acc[1] + w * points[n][1]]
}

/// The knot span `μ` with `knots[μ] ≤ τ < knots[μ+1]`, `k − 1 ≤ μ ≤ n`; at the upper end of the
/// valid range the last non-empty span (so the curve is closed at `τ = hi`).
#[inline]
pub(crate) fn find_span<R: Real>(knots: &[R], order: usize, count: usize, tau: R) -> usize {
    let n = count - 1;
    let (mut lo, mut hi) = (order - 1, n);
    if tau >= knots[n + 1] {
        // Last non-empty span ending at knots[n + 1].
        let mut m = n;
        while m > order - 1 && knots[m] >= knots[n + 1] {
            m -= 1;
        }
        return m;
    }
    if tau <= knots[lo] {
        // First non-empty span.
        let mut m = lo;
        while m < n && knots[m + 1] <= knots[lo] {
            m += 1;
        }
        return m;
    }
    // Binary search for knots[μ] ≤ τ < knots[μ+1].
    while hi > lo {
        let mid = (lo + hi).div_ceil(2);
        if knots[mid] <= tau {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    lo
}

/// The `k` B-spline basis functions `N_k^{μ−k+1..=μ}(τ)` that are non-zero on span `μ`, by the
/// Cox–de Boor recursion (002 eq. 3.34) evaluated on its triangle of non-zero terms (the
/// `BasisFuns` arrangement of Piegl & Tiller, *The NURBS Book*, A2.2). On a non-empty span every
/// denominator is at least the span's width, so the recursion's `0/0 := 0` convention never
/// arises.
#[inline]
pub(crate) fn basis_funs<R: Real>(knots: &[R], order: usize, span: usize, tau: R) -> [R; MAX_ORDER] {
    let mut n = [R::ZERO; MAX_ORDER];
    let mut left = [R::ZERO; MAX_ORDER];
    let mut right = [R::ZERO; MAX_ORDER];
    n[0] = R::ONE;
    for d in 1..order {
        left[d] = tau - knots[span + 1 - d];
        right[d] = knots[span + d] - tau;
        let mut saved = R::ZERO;
        for r in 0..d {
            let denom = right[r + 1] + left[d - r];
            let temp = if denom > R::ZERO { n[r] / denom } else { R::ZERO };
            n[r] = saved + right[r + 1] * temp;
            saved = left[d - r] * temp;
        }
        n[d] = saved;
    }
    n
}

/// `Σ N_k^i(τ) P_i` (002 eq. 3.33).
#[inline]
fn bspline<R: Real>(points: &[[R; 2]], order: usize, knots: &[R], tau: R) -> [R; 2] {
    let span = find_span(knots, order, points.len(), tau);
    let n = basis_funs(knots, order, span, tau);
    let mut acc = [R::ZERO; 2];
    for (r, w) in n.iter().enumerate().take(order) {
        let p = points[span + 1 + r - order];
        acc[0] += *w * p[0];
        acc[1] += *w * p[1];
    }
    acc
}

/// The radius of a cylinder around the axis that encloses the whole curve (002 §3.4.4): the
/// amplitude bound of a periodic curve, the farthest control point of a Bézier or B-spline curve
/// (convex-hull property).
pub(crate) fn bound_radius(shape: &CurveShape) -> f64 {
    let hyp = |a: f64, b: f64| (a * a + b * b).sqrt();
    let amp = |terms: &[[f32; 2]]| terms.iter().map(|t| hyp(f64::from(t[0]), f64::from(t[1]))).sum::<f64>();
    match shape {
        CurveShape::Helix { radius, .. } => f64::from(*radius).abs(),
        CurveShape::TrigSum { y_terms, z_terms, .. } => hyp(amp(y_terms), amp(z_terms)),
        CurveShape::Bezier { points } | CurveShape::BSpline { points, .. } => {
            points.iter().map(|p| hyp(f64::from(p[0]), f64::from(p[1]))).fold(0.0, f64::max)
        }
    }
}
