//! Curve evaluation (002 §3.4.7–3.4.10): closed forms of the helix and trigonometric sums, Bézier
//! against de Casteljau, B-spline against the literal Cox–de Boor recursion (eq. 3.34), partition
//! of unity, clamped end interpolation, the frame construction and the extension clamp.

#[allow(dead_code)]
#[path = "curve_common/mod.rs"]
mod support;

use hadou_math::curve::{clamped_uniform_knots, prepare, CurveFrame, CurveShape};
use hadou_math::{Vec3, Vec3d};
use support::*;

fn close(a: [f64; 2], b: [f64; 2], tol: f64) -> bool {
    (a[0] - b[0]).abs() <= tol && (a[1] - b[1]).abs() <= tol
}

/// A small deterministic generator for test points.
fn lcg(seed: &mut u64) -> f64 {
    *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    ((*seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

#[test]
fn frame_axes_are_orthonormal_right_handed_gram_schmidt() {
    let f = CurveFrame { origin: Vec3d::ZERO, axis: Vec3::new(2.0, 0.0, 0.0), up: Vec3::new(0.3, 1.0, 0.0) };
    let [d, y, z] = f.axes().unwrap();
    assert!((d - Vec3::X).length() < 1e-15);
    assert!((y - Vec3::Y).length() < 1e-15, "ŷ is the part of up perpendicular to D: {y:?}");
    assert!((z - Vec3::Z).length() < 1e-15, "ẑ = D × ŷ: {z:?}");
    let g = CurveFrame { origin: Vec3d::ZERO, axis: Vec3::new(1.0, 1.0, 1.0), up: Vec3::new(0.0, 0.0, 1.0) };
    let [d, y, z] = g.axes().unwrap();
    for (a, b) in [(d, y), (y, z), (d, z)] {
        assert!(a.dot(b).abs() < 1e-12);
    }
    assert!((d.cross(y) - z).length() < 1e-12);
    let bad =
        CurveFrame { origin: Vec3d::ZERO, axis: Vec3::new(0.0, 3.0, 0.0), up: Vec3::new(0.0, -1.0, 0.0) };
    assert!(bad.axes().is_none());
}

#[test]
fn helix_matches_its_closed_form_in_world_space() {
    let (r, th, ph) = (2.0f64, std::f64::consts::TAU / 4.0, 0.3f64);
    let mut w = helix();
    w.frame.origin = Vec3::new(1.0, 2.0, 3.0);
    w.gamma = 1.5;
    let c = prepare(&w);
    for i in 0..=40 {
        let s = 20.0 * f64::from(i) / 40.0;
        let want = [r * (th * s + ph).sin(), r * (th * s + ph).cos()];
        assert!(close(c.cross_section(s), want, 1e-5), "s={s}");
        let p = c.point(s);
        let want_p = Vec3::new(1.0 + 1.5 * s, 2.0 + want[0], 3.0 + want[1]);
        assert!((p - want_p).length() < 1e-5, "{p:?} vs {want_p:?}");
    }
}

#[test]
fn trig_sum_matches_its_closed_form() {
    let c = prepare(&trig_sum());
    let th = std::f64::consts::TAU / 10.0;
    for i in 0..=50 {
        let s = 20.0 * f64::from(i) / 50.0;
        let y = 2.0 * (th * s).sin() + 0.6 * (2.0 * th * s).cos() + 0.4 * (3.0 * th * s).sin();
        let z = 1.5 * (th * s).cos() + 0.5 * (2.0 * th * s).sin();
        assert!(close(c.cross_section(s), [y, z], 1e-5), "s={s}");
    }
}

fn de_casteljau(points: &[[f64; 2]], s: f64) -> [f64; 2] {
    let mut p = points.to_vec();
    for k in (1..p.len()).rev() {
        for i in 0..k {
            p[i] = [p[i][0] + (p[i + 1][0] - p[i][0]) * s, p[i][1] + (p[i + 1][1] - p[i][1]) * s];
        }
    }
    p[0]
}

#[test]
fn bezier_matches_de_casteljau_for_every_degree() {
    let mut seed = 7;
    for degree in 1..=12 {
        let pts: Vec<[f32; 2]> =
            (0..=degree).map(|_| [lcg(&mut seed) as f32 * 5.0, lcg(&mut seed) as f32 * 5.0]).collect();
        let pts64: Vec<[f64; 2]> = pts.iter().map(|p| [f64::from(p[0]), f64::from(p[1])]).collect();
        let c = prepare(&wave(CurveShape::Bezier { points: pts.clone() }, 10.0));
        for i in 0..=20 {
            let s = f64::from(i) / 20.0;
            assert!(close(c.cross_section(s), de_casteljau(&pts64, s), 1e-9), "degree {degree} s={s}");
        }
        assert!(
            close(c.cross_section(0.0), pts64[0], 0.0) && close(c.cross_section(1.0), pts64[degree], 0.0)
        );
    }
}

#[test]
fn degree_one_bezier_is_a_straight_line() {
    let c = prepare(&wave(CurveShape::Bezier { points: vec![[1.0, -2.0], [3.0, 4.0]] }, 10.0));
    for i in 0..=10 {
        let s = f64::from(i) / 10.0;
        assert!(close(c.cross_section(s), [1.0 + 2.0 * s, -2.0 + 6.0 * s], 1e-12));
    }
    // The straight curve needs a single leaf, and every chord of the tree is exact.
    let worst = c.table().errors.iter().cloned().fold(0.0, f32::max);
    assert!(worst < 1e-5, "{worst}");
}

/// The literal recursion of 002 eq. 3.34 (with 0/0 := 0), right end closed on the last span.
fn cox_de_boor(knots: &[f64], i: usize, k: usize, t: f64, last: usize) -> f64 {
    if k == 1 {
        let inside = knots[i] <= t && t < knots[i + 1];
        let at_end = i == last && t == knots[i + 1];
        return if inside || at_end { 1.0 } else { 0.0 };
    }
    let mut v = 0.0;
    let d1 = knots[i + k - 1] - knots[i];
    if d1 > 0.0 {
        v += (t - knots[i]) / d1 * cox_de_boor(knots, i, k - 1, t, last);
    }
    let d2 = knots[i + k] - knots[i + 1];
    if d2 > 0.0 {
        v += (knots[i + k] - t) / d2 * cox_de_boor(knots, i + 1, k - 1, t, last);
    }
    v
}

#[test]
fn bspline_matches_cox_de_boor_with_explicit_knots_and_interpolates_clamped_ends() {
    let mut seed = 11;
    for (count, order) in [(4usize, 2usize), (6, 3), (8, 4), (9, 5), (5, 5)] {
        let pts: Vec<[f32; 2]> =
            (0..count).map(|_| [lcg(&mut seed) as f32 * 3.0, lcg(&mut seed) as f32 * 3.0]).collect();
        let pts64: Vec<[f64; 2]> = pts.iter().map(|p| [f64::from(p[0]), f64::from(p[1])]).collect();
        // Non-uniform clamped knots with a double interior knot where there is room.
        let mut knots = clamped_uniform_knots(count, order);
        let interior = count - order;
        if interior >= 2 {
            knots[order] = knots[order + 1];
        }
        if interior >= 1 {
            knots[order] *= 0.7;
        }
        let knots32: Vec<f32> = knots.iter().map(|&x| x as f32).collect();
        let knots64: Vec<f64> = knots32.iter().map(|&x| f64::from(x)).collect();
        let c = prepare(&wave(
            CurveShape::BSpline { points: pts, order: order as u32, knots: Some(knots32) },
            10.0,
        ));
        let (lo, hi) = (knots64[order - 1], knots64[count]);
        // The last non-empty span, whose right end is closed.
        let last = (0..count).rev().find(|&i| knots64[i] < knots64[i + 1]).unwrap();
        for i in 0..=40 {
            let s = f64::from(i) / 40.0;
            let t = lo + s * (hi - lo);
            let mut want = [0.0; 2];
            let mut unity = 0.0;
            for (j, p) in pts64.iter().enumerate() {
                let n = cox_de_boor(&knots64, j, order, t, last);
                unity += n;
                want[0] += n * p[0];
                want[1] += n * p[1];
            }
            assert!((unity - 1.0).abs() < 1e-12, "partition of unity: {unity} at t={t}");
            assert!(close(c.cross_section(s), want, 1e-9), "count {count} order {order} s={s}");
        }
        assert!(close(c.cross_section(0.0), pts64[0], 1e-12), "clamped start");
        assert!(close(c.cross_section(1.0), pts64[count - 1], 1e-12), "clamped end");
    }
}

#[test]
fn bspline_default_knots_give_partition_of_unity() {
    // With every control point at (1, 2) the curve is that point wherever Σ N = 1.
    let c = prepare(&wave(CurveShape::BSpline { points: vec![[1.0, 2.0]; 7], order: 4, knots: None }, 10.0));
    for i in 0..=50 {
        assert!(close(c.cross_section(f64::from(i) / 50.0), [1.0, 2.0], 1e-12));
    }
    assert_eq!(clamped_uniform_knots(7, 4), vec![0.0, 0.0, 0.0, 0.0, 0.25, 0.5, 0.75, 1.0, 1.0, 1.0, 1.0]);
}

#[test]
fn extension_clamps_to_the_head_and_bounds_the_table() {
    let mut w = helix();
    w.extension = 0.25;
    let c = prepare(&w);
    assert!((c.axial_length() - 5.0).abs() < 1e-6);
    let head = c.point(5.0);
    assert!((c.point(17.0) - head).length() < 1e-12);
    let t = c.table();
    assert_eq!(t.nodes[0][0], 0.0);
    assert!((t.nodes[t.pieces()][0] - 5.0).abs() < 1e-6);
    assert!(t.nodes.windows(2).all(|w| w[1][0] > w[0][0]), "strictly increasing x");
    assert_eq!(t.level_offsets.len(), t.levels() + 1);
    // Every chord's bound really bounds the curve's distance from its fitted line.
    for l in 0..t.levels() {
        for j in 0..(t.pieces().div_ceil(1 << l)) {
            let (a, b) = (j << l, ((j + 1) << l).min(t.pieces()));
            let (xa, xb) = (f64::from(t.nodes[a][0]), f64::from(t.nodes[b][0]));
            let ln = t.line(l, j).map(f64::from);
            for q in 0..=16 {
                let x = xa + (xb - xa) * f64::from(q) / 16.0;
                let cs = c.cross_section(x / f64::from(w.gamma));
                let xm = 0.5 * (xa + xb);
                let d = ((cs[0] - ln[0] - (x - xm) * ln[2]).powi(2)
                    + (cs[1] - ln[1] - (x - xm) * ln[3]).powi(2))
                .sqrt();
                assert!(
                    d <= f64::from(t.error(l, j)) * 1.001 + 1e-6,
                    "level {l} piece {j}: {d} > {}",
                    t.error(l, j)
                );
            }
        }
    }
}
