//! The converged `f64` reference for curve energies: adaptive Gauss–Kronrod on the exact field.

use super::integrate::leaf_of;
use super::local_ray::LocalRay;
use super::prepare::PreparedCurve;
use super::simpson::density;
use crate::energy::{FieldParams, Ray};
use crate::quadrature::integrate_adaptive_breaks;
use crate::Vec3;

/// Most break points placed at distance minima along one ray.
const MAX_MINIMA: usize = 4096;

/// The curve energy of one ray by adaptive Gauss–Kronrod 7–15 in `f64` to relative tolerance
/// `rel_tol` on the exact field (002 eq. 3.17, 3.23, 3.24 with the cross-section pairing of
/// SPEC.md §1.4): the curve is evaluated exactly at every node, no table or chord is involved.
///
/// The span (resolved as in [`super::curve_energy`]) is split where the pairing changes — at the
/// end planes `x = 0` and `x = X` — and at every local minimum of the distance to the curve
/// (located on the leaves of the piece table, whose chords are within `10⁻⁵` of the curve), so
/// that every peak of the integrand falls on an interval end; a few evenly spaced leaf boundaries
/// are added so that no long stretch starts unresolved. An infinite end (inverse square) is mapped
/// to a finite one by the quadrature. Returns 0 for an empty span; the value is finite.
pub fn curve_energy_reference(
    c: &PreparedCurve,
    p: &FieldParams<f64>,
    ray: &Ray<f64>,
    t0: f64,
    t1: f64,
    t_far: f64,
    rel_tol: f64,
) -> f64 {
    LocalRay::new(c, p, ray, t0, t1, t_far).map_or(0.0, |r| reference_integral(c, &r, rel_tol))
}

/// [`curve_energy_reference`] over the resolved span of `r`.
fn reference_integral(c: &PreparedCurve, r: &LocalRay<f64>, rel_tol: f64) -> f64 {
    let mut breaks = vec![r.t0];
    let closest = |a: f64, b: f64, pnt: Vec3<f64>| {
        // Closest approach of the ray to a fixed local point, if inside (a, b).
        let qq = r.q.dot(r.q);
        if qq > 0.0 {
            let t = (pnt - r.o).dot(r.q) / qq;
            if t > a && t < b {
                return Some(t);
            }
        }
        None
    };
    let nodes = &c.table.nodes;
    let n = nodes.len() - 1;
    let nd = |i: usize| {
        let v = nodes[i];
        Vec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]))
    };
    let start = Vec3::new(0.0, f64::from(nodes[0][1]), f64::from(nodes[0][2]));
    let head = Vec3::new(r.x_head, f64::from(nodes[n][1]), f64::from(nodes[n][2]));
    let slab_minima = |a: f64, b: f64, breaks: &mut Vec<f64>| {
        if !(b > a) {
            return;
        }
        let qx = r.q.x;
        let xa = (r.o.x + qx * a).clamp(0.0, r.x_head);
        let xb = (r.o.x + qx * b).clamp(0.0, r.x_head);
        let (lo, hi) = if xa <= xb { (xa, xb) } else { (xb, xa) };
        if qx == 0.0 || !(hi > lo) {
            // The paired point is fixed: one minimum at the closest approach to it.
            let i = leaf_of(c, lo);
            let (na, nb) = (nd(i), nd(i + 1));
            let f = ((lo - na.x) / (nb.x - na.x)).clamp(0.0, 1.0);
            let pt = Vec3::new(r.o.x + qx * a, na.y + (nb.y - na.y) * f, na.z + (nb.z - na.z) * f);
            if let Some(t) = closest(a, b, pt) {
                breaks.push(t);
            }
            return;
        }
        let first = leaf_of(c, lo);
        let last = leaf_of(c, hi);
        let count = last + 1 - first;
        let stride = count.div_ceil(32).max(1);
        let mut minima = 0;
        for i in first..=last {
            let (na, nb) = (nd(i), nd(i + 1));
            let x0 = lo.max(na.x);
            let x1 = hi.min(nb.x);
            if !(x1 > x0) {
                continue;
            }
            let tx0 = (x0 - r.o.x) / qx;
            let tx1 = (x1 - r.o.x) / qx;
            let (ts, te) = if tx0 <= tx1 { (tx0, tx1) } else { (tx1, tx0) };
            let (ts, te) = (ts.max(a), te.min(b));
            if (i - first) % stride == 0 && ts > a && ts < b {
                breaks.push(ts);
            }
            // Distance to the leaf chord: minimum of the quadratic over [ts, te].
            let inv = 1.0 / (nb.x - na.x);
            let (my, mz) = ((nb.y - na.y) * inv, (nb.z - na.z) * inv);
            let ps = r.at(ts);
            let xs = ps.x - na.x;
            let pv = Vec3::new(0.0, ps.y - (na.y + xs * my), ps.z - (na.z + xs * mz));
            let v = Vec3::new(0.0, r.q.y - r.q.x * my, r.q.z - r.q.x * mz);
            let vv = v.dot(v);
            if vv > 0.0 && minima < MAX_MINIMA {
                let tau = -pv.dot(v) / vv;
                if tau > 0.0 && ts + tau < te {
                    breaks.push(ts + tau);
                    minima += 1;
                }
            }
        }
    };
    match r.slab() {
        None => {
            if r.o.x < 0.0 {
                breaks.extend(closest(r.t0, r.t1, start));
            } else if r.o.x > r.x_head {
                breaks.extend(closest(r.t0, r.t1, head));
            } else {
                slab_minima(r.t0, r.t1, &mut breaks);
            }
        }
        Some((tin, tout, head_first)) => {
            let (e1, e2) = if head_first { (head, start) } else { (start, head) };
            breaks.extend(closest(r.t0, r.t1.min(tin), e1));
            for t in [tin, tout] {
                if t > r.t0 && t < r.t1 {
                    breaks.push(t);
                }
            }
            slab_minima(r.t0.max(tin), r.t1.min(tout), &mut breaks);
            breaks.extend(closest(r.t0.max(tout), r.t1, e2));
        }
    }
    breaks.push(r.t1);
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    let q = integrate_adaptive_breaks(|t| density(c, r, t), &breaks, rel_tol, 0.0);
    let e = q.value * r.alpha;
    if e.is_finite() {
        e
    } else {
        0.0
    }
}

/// The nearest-point field's energy of one ray ([`Integrator::Nearest`](super::Integrator::Nearest))
/// by brute force in `f64`, independent of the piece table: the distance at every quadrature node
/// is the minimum over a dense uniform sampling of the exact curve (at least 4096 points, 64 per
/// turn), each of the lowest sampled local minima refined by golden-section search on the exact
/// curve to `10⁻¹³` of the parameter range; the integral (002 eq. 3.17 or hadou's `1/r²`, times
/// `(1 − u)^j`, eq. 3.23) is adaptive Gauss–Kronrod to relative tolerance `rel_tol`, with break
/// points at the ray's closest approaches to the curve (the local minima over the dense samples
/// of the distance from the ray's line). The span is resolved as in [`super::curve_energy`].
pub fn nearest_energy_reference(
    c: &PreparedCurve,
    p: &FieldParams<f64>,
    ray: &Ray<f64>,
    t0: f64,
    t1: f64,
    t_far: f64,
    rel_tol: f64,
) -> f64 {
    let Some(r) = LocalRay::new(c, p, ray, t0, t1, t_far) else {
        return 0.0;
    };
    let gamma = f64::from(c.wave.gamma);
    let turns = c.wave.turns().unwrap_or(0.0);
    let m = 4096usize.max((64.0 * turns).ceil() as usize);
    let point = |s: f64| {
        let cs = c.shape64.eval(s.clamp(0.0, c.s_head));
        Vec3::new(gamma * s, cs[0], cs[1])
    };
    let ss: Vec<f64> = (0..=m).map(|i| c.s_head * i as f64 / m as f64).collect();
    let pts: Vec<Vec3<f64>> = ss.iter().map(|&s| point(s)).collect();
    let distance2 = |pnt: Vec3<f64>| {
        let g: Vec<f64> = pts.iter().map(|q| (*q - pnt).length_squared()).collect();
        let mut minima: Vec<(f64, usize)> = (0..=m)
            .filter(|&i| (i == 0 || g[i] <= g[i - 1]) && (i == m || g[i] <= g[i + 1]))
            .map(|i| (g[i], i))
            .collect();
        minima.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut best = minima[0].0;
        for &(_, i) in minima.iter().take(4) {
            let (mut a, mut b) = (ss[i.saturating_sub(1)], ss[(i + 1).min(m)]);
            let f = |s: f64| (point(s) - pnt).length_squared();
            let k = 0.5 * (5f64.sqrt() - 1.0);
            let (mut x1, mut x2) = (b - k * (b - a), a + k * (b - a));
            let (mut f1, mut f2) = (f(x1), f(x2));
            while b - a > 1e-13 * c.s_head.max(1.0) {
                if f1 < f2 {
                    b = x2;
                    (x2, f2) = (x1, f1);
                    x1 = b - k * (b - a);
                    f1 = f(x1);
                } else {
                    a = x1;
                    (x1, f1) = (x2, f2);
                    x2 = a + k * (b - a);
                    f2 = f(x2);
                }
            }
            best = best.min(f1).min(f2).min(f(a)).min(f(b));
        }
        best
    };
    // Closest approaches of the ray's line to the dense samples; local minima become breaks.
    let qq = r.q.dot(r.q);
    let mut breaks = vec![r.t0, r.t1];
    if qq > 0.0 {
        let approach: Vec<(f64, f64)> = pts
            .iter()
            .map(|q| {
                let t = (*q - r.o).dot(r.q) / qq;
                ((r.at(t) - *q).length_squared(), t)
            })
            .collect();
        for i in 0..=m {
            let lower = i == 0 || approach[i].0 <= approach[i - 1].0;
            let upper = i == m || approach[i].0 <= approach[i + 1].0;
            let t = approach[i].1;
            if lower && upper && t > r.t0 && t < r.t1 {
                breaks.push(t);
            }
        }
    }
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    let w = |t: f64| {
        let q = distance2(r.at(t)) + r.rc2;
        let w = match r.falloff {
            crate::energy::Falloff::Faithful => 1.0 / q.sqrt(),
            crate::energy::Falloff::InverseSquare => 1.0 / q,
        };
        w * r.attenuation(t)
    };
    let e = integrate_adaptive_breaks(w, &breaks, rel_tol, 0.0).value * r.alpha;
    if e.is_finite() {
        e
    } else {
        0.0
    }
}
