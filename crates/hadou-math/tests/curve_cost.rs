//! The work of a ray through a curve is bounded whatever the curve's parameters: at the corners
//! of every curve kind's parameter box (every value at an extreme the validation allows, both
//! falloffs, no core radius) no ray of a set that sees the curve from the side, along its axis,
//! obliquely and from inside, grazes it along the axis and passes exactly through it takes more
//! evaluations than [`DEFAULT_BOUND`] with the default integrator, and Simpson takes its `m + 1`
//! samples (three regions with a reduction) plus at most [`DEFAULT_BOUND`] for the tail past the
//! far point. A deterministic count, not a timing: see `cost.rs` for why the limits bound it, and
//! `curve_cost_report` (ignored; `--nocapture`) for the counts and times per corner.
//!
//! Before the limits, a helix with `rate = −1e6` over 11 units took 1.5 million evaluations for
//! one pixel.

use hadou_math::curve::{
    curve_energy, prepare, CurveFrame, CurveShape, CurveWave, Integrator, PreparedCurve, Reduction,
    MAX_BEZIER_POINTS, MAX_BSPLINE_POINTS, MAX_NEAREST_STEPS, MAX_NEAREST_VISITS, MAX_ORDER, MAX_SIMPSON_M,
    MAX_SLOPE, MAX_TRIG_TERMS, MAX_TURNS,
};
use hadou_math::energy::{Falloff, FieldParams, Ray};
use hadou_math::rng::Rng;
use hadou_math::{Vec3, Vec3d};
use std::f64::consts::TAU;
use std::time::Instant;

/// Most evaluations any ray of [`rays`] may take with the default integrator at any corner.
/// Measured worst (inverse square): 73 195 for a 64-term sum of ±1e6 coefficients at 128 turns,
/// 57 474 for a 512-point cubic zigzag B-spline, 17 095 for a helix at 128 turns, 4 212 for a
/// Bézier curve (denser ray sets, 1 226 rays a corner, found up to 64 489 for the B-spline).
const DEFAULT_BOUND: u32 = hadou_math::curve::DEFAULT_RAY_WORK as u32;
/// Most evaluations (pieces visited plus exact points) a ray of the nearest-point field takes:
/// its bound by construction, which the scene format documents (below 750 000).
const NEAREST_BOUND: u32 = hadou_math::curve::NEAREST_RAY_WORK as u32;

/// Largest value of a scene number (docs/scene-format.md, Limits).
const COORD_MAX: f32 = 1e6;

/// One ray as a backend integrates it.
#[derive(Clone, Copy, Debug)]
struct TestRay {
    ray: Ray<f32>,
    t0: f32,
    t1: f32,
    t_far: f32,
    params: FieldParams<f32>,
}

/// The wave ray from `eye` towards `target` as `CameraBasis::wave_ray` builds it: faithful rays
/// span the normalised parameter to the far point, inverse-square rays are unit and open.
fn ray_of(eye: Vec3d, target: Vec3d, far: f64, falloff: Falloff) -> Option<TestRay> {
    let dir = (target - eye).try_normalize()?;
    let params = FieldParams { falloff, core_radius: 0.0 };
    Some(match falloff {
        Falloff::Faithful => TestRay {
            ray: Ray { origin: eye.as_f32(), dir: (dir * far).as_f32() },
            t0: 0.0,
            t1: 1.0,
            t_far: 1.0,
            params,
        },
        Falloff::InverseSquare => TestRay {
            ray: Ray { origin: eye.as_f32(), dir: dir.as_f32() },
            t0: 0.0,
            t1: f32::INFINITY,
            t_far: far as f32,
            params,
        },
    })
}

/// Rays that see the curve from the side, along its axis, obliquely and from inside (a `grid²`
/// window each), rays along the axis at a tenth of the bounding radius apart (a helix's every
/// turn passes the ray at the radius) and rays exactly through `2·grid` curve points.
fn rays(c: &PreparedCurve, falloff: Falloff, grid: usize) -> Vec<TestRay> {
    let (o, [d, y, z]) = c.frame_axes();
    let (o, d, y, z) = (o.as_f64(), d.as_f64(), y.as_f64(), z.as_f64());
    let r = f64::from(c.bound_radius());
    let x = f64::from(c.axial_length());
    let l = x.max(r).max(1e-6);
    let center = o + d * (0.5 * x);
    let far = 8.0 * l;
    let mut out = Vec::new();
    let mut push = |eye: Vec3d, target: Vec3d| out.extend(ray_of(eye, target, far, falloff));
    // (eye, look-at, the half-extents of the window seen).
    let across = r * 1.2 + l * 1e-3;
    let views: [(Vec3d, Vec3d, Vec3d, Vec3d); 4] = [
        (center + z * (3.0 * l), center, d * (0.6 * x + r), y * (1.2 * r + 0.1 * l)),
        (o - d * (1.5 * l), center, y * across, z * across),
        (center + (d + y + z) * (1.5 * l), center, (y - z) * (0.5 * l), (d * 2.0 - y - z) * (0.3 * l)),
        (center, o + d * x, y * across, z * across),
    ];
    for (eye, at, a, b) in views {
        for i in 0..grid {
            for j in 0..grid {
                let u = 2.0 * (i as f64 + 0.5) / grid as f64 - 1.0;
                let v = 2.0 * (j as f64 + 0.5) / grid as f64 - 1.0;
                push(eye, at + a * u + b * v);
            }
        }
    }
    for f in [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.999, 1.0] {
        for off in [y * (r * f), z * (r * f)] {
            push(o - d * (0.5 * l) + off, o + d * x + off);
        }
    }
    let mut rng = Rng(0xc057_c057);
    let s_head = x / f64::from(c.wave.gamma);
    for _ in 0..grid * 2 {
        let p = c.point(s_head * rng.unit());
        push(p + rng.unit_vec() * (2.0 * l), p);
    }
    out
}

/// Evaluations (largest and mean) and times of one wave's rays.
struct Stats {
    falloff: Falloff,
    rays: usize,
    max: u32,
    mean: f64,
    ms_per_ray: f64,
    max_ms: f64,
    prep_ms: f64,
}

/// Prepares `w` (timed) and measures its rays in both falloffs.
fn measure(w: &CurveWave, grid: usize) -> [Stats; 2] {
    let t = Instant::now();
    let c = prepare(w);
    let prep_ms = t.elapsed().as_secs_f64() * 1e3;
    [Falloff::Faithful, Falloff::InverseSquare].map(|falloff| {
        let rs = rays(&c, falloff, grid);
        let t = Instant::now();
        let (mut max, mut sum, mut max_ms) = (0u32, 0u64, 0.0f64);
        for r in &rs {
            let tr = Instant::now();
            let s = curve_energy(&c, &r.params, &r.ray, r.t0, r.t1, r.t_far);
            max_ms = max_ms.max(tr.elapsed().as_secs_f64() * 1e3);
            assert!(s.energy.is_finite() && s.energy >= 0.0, "{:?}: energy {}", r, s.energy);
            max = max.max(s.evaluations);
            sum += u64::from(s.evaluations);
        }
        let n = rs.len().max(1) as f64;
        Stats {
            falloff,
            rays: rs.len(),
            max,
            mean: sum as f64 / n,
            ms_per_ray: t.elapsed().as_secs_f64() * 1e3 / n,
            max_ms,
            prep_ms,
        }
    })
}

fn wave(shape: CurveShape, gamma: f32, extension: f32, attenuation: f32) -> CurveWave {
    CurveWave {
        frame: CurveFrame { origin: Vec3::new(-1.0, 0.5, 0.25), axis: Vec3::X, up: Vec3::Y },
        shape,
        gamma,
        extension,
        attenuation,
        alpha: 1.0,
        integrator: Integrator::Default,
    }
}

/// `x` made a little smaller, so that a bound computed in `f64` holds after rounding to `f32`.
fn under(x: f64) -> f32 {
    (x * (1.0 - 1e-5)) as f32
}

/// The largest |rate| a periodic curve may have: `COORD_MAX`, the turn limit and the
/// steepness limit (`speed_per_rate`: the curve's steepness per unit rate at `γ = 1`).
fn max_rate(length: f32, harmonics: usize, speed_per_rate: f64, gamma: f32) -> f32 {
    let by_turns = MAX_TURNS * TAU / (f64::from(length) * harmonics.max(1) as f64);
    let by_slope =
        if speed_per_rate > 0.0 { MAX_SLOPE * f64::from(gamma) / speed_per_rate } else { f64::INFINITY };
    under(by_turns.min(by_slope).min(f64::from(COORD_MAX)))
}

/// The least `γ` at which a curve of steepness `slope_at_1` (at `γ = 1`) is valid, at least
/// `1e-6`.
fn min_gamma(slope_at_1: f64) -> f32 {
    ((slope_at_1 / MAX_SLOPE * (1.0 + 1e-5)).max(1e-6) as f32).min(COORD_MAX)
}

const LENGTHS: [f32; 3] = [1e-6, 1.0, 1e6];
const GAMMAS: [f32; 3] = [1e-6, 1.0, 1e6];
const EXTENSIONS: [f32; 2] = [1e-6, 1.0];
const ATTENUATIONS: [f32; 3] = [0.0, 2.5, 1e6];

/// Every corner of the helix's box: radius, length, rate (both signs, as large as the limits
/// allow), γ, extension and attenuation at their extremes.
fn helix_corners() -> Vec<(String, CurveWave)> {
    let mut v = Vec::new();
    for radius in [0.0f32, 1e-6, 1.0, 1e6] {
        for length in LENGTHS {
            for gamma in GAMMAS {
                let rmax = max_rate(length, 1, f64::from(radius), gamma);
                for rate in [rmax, -rmax] {
                    for extension in EXTENSIONS {
                        for j in ATTENUATIONS {
                            v.push((
                                format!("helix r={radius:e} len={length:e} rate={rate:e} γ={gamma:e} k={extension:e} j={j:e}"),
                                wave(CurveShape::Helix { radius, rate, phase: 0.3, length }, gamma, extension, j),
                            ));
                        }
                    }
                }
            }
        }
    }
    v
}

/// One list of trigonometric coefficients.
type Terms = Vec<[f32; 2]>;

/// Trigonometric sums of 1 and [`MAX_TRIG_TERMS`] terms (flat, decaying, random, alternating
/// and `±1e6` coefficients), the rate as large as the limits allow, at the extremes of length,
/// γ, extension and attenuation.
fn trig_corners() -> Vec<(String, CurveWave)> {
    let mut v = Vec::new();
    let mut rng = Rng(0x7219);
    for h in [1usize, MAX_TRIG_TERMS] {
        let patterns: Vec<(&str, Terms, Terms)> = vec![
            ("flat", vec![[1.0, 1.0]; h], vec![[1.0, 1.0]; h]),
            (
                "decaying",
                (0..h).map(|i| [1.0 / (i + 1) as f32, 0.3]).collect(),
                (0..h).map(|i| [0.5, 1.0 / (i + 1) as f32]).collect(),
            ),
            (
                "random",
                (0..h).map(|_| [rng.range_f32(-1.0, 1.0), rng.range_f32(-1.0, 1.0)]).collect(),
                (0..h).map(|_| [rng.range_f32(-1.0, 1.0), rng.range_f32(-1.0, 1.0)]).collect(),
            ),
            ("alternating", (0..h).map(|i| [if i % 2 == 0 { 1.0 } else { -1.0 }, 0.0]).collect(), vec![]),
            ("huge", vec![[COORD_MAX, -COORD_MAX]; h], vec![[-COORD_MAX, COORD_MAX]; h]),
        ];
        for (name, y, z) in patterns {
            let probe = wave(
                CurveShape::TrigSum { rate: 1.0, y_terms: y.clone(), z_terms: z.clone(), length: 1.0 },
                1.0,
                1.0,
                0.0,
            );
            let speed = probe.steepness();
            for length in LENGTHS {
                for gamma in GAMMAS {
                    let rate = max_rate(length, h, speed, gamma);
                    // Fewer combinations for the long sums, whose tables take longest to build.
                    let kj: &[(f32, f32)] = if h == 1 {
                        &[(1.0, 0.0), (1.0, 1e6), (1e-6, 2.5)]
                    } else {
                        &[(1.0, 0.0), (1e-6, 1e6)]
                    };
                    for &(extension, j) in kj {
                        v.push((
                            format!("trig h={h} {name} len={length:e} rate={rate:e} γ={gamma:e} k={extension:e} j={j:e}"),
                            wave(
                                CurveShape::TrigSum { rate: -rate, y_terms: y.clone(), z_terms: z.clone(), length },
                                gamma,
                                extension,
                                j,
                            ),
                        ));
                    }
                }
            }
        }
    }
    v
}

/// Control points: a zigzag of amplitude `a`, random points within `±a`, and a zigzag with
/// `±COORD_MAX` in both coordinates.
fn point_patterns(n: usize, rng: &mut Rng) -> Vec<(&'static str, Vec<[f32; 2]>)> {
    vec![
        ("zigzag", (0..n).map(|i| [if i % 2 == 0 { 1.0 } else { -1.0 }, 0.0]).collect()),
        ("random", (0..n).map(|_| [rng.range_f32(-1.0, 1.0), rng.range_f32(-1.0, 1.0)]).collect()),
        (
            "wild",
            (0..n)
                .map(|i| {
                    let s = |b: bool| if b { COORD_MAX } else { -COORD_MAX };
                    [s(i % 2 == 0), s(i % 3 == 0)]
                })
                .collect(),
        ),
    ]
}

/// Bézier curves of [`MAX_BEZIER_POINTS`] (and 2) control points, γ the least the steepness
/// limit allows and `1e6`, at the extremes of extension and attenuation.
fn bezier_corners() -> Vec<(String, CurveWave)> {
    let mut v = Vec::new();
    let mut rng = Rng(0xbe21);
    for n in [2usize, MAX_BEZIER_POINTS] {
        for (name, points) in point_patterns(n, &mut rng) {
            let shape = CurveShape::Bezier { points };
            let g0 = min_gamma(wave(shape.clone(), 1.0, 1.0, 0.0).steepness());
            for gamma in [g0, COORD_MAX] {
                for (extension, j) in [(1.0, 0.0), (1.0, 1e6), (1e-6, 2.5)] {
                    v.push((
                        format!("bezier n={n} {name} γ={gamma:e} k={extension:e} j={j:e}"),
                        wave(shape.clone(), gamma, extension, j),
                    ));
                }
            }
        }
    }
    v
}

/// Knot vectors of `count + order` values: clamped uniform (`None`), crowded geometrically
/// towards the start (the first span `crowd` wide), interior knots repeated `order − 1` times,
/// and spread over `[0, 1e6]` with one long span.
fn knot_patterns(count: usize, order: usize, crowd: f64) -> Vec<(&'static str, Option<Vec<f32>>)> {
    let total = count + order;
    let interior = count - order;
    let clamp = |inner: Vec<f32>, hi: f32| {
        let mut k = vec![0.0; order];
        k.extend(inner);
        k.extend(vec![hi; order]);
        assert_eq!(k.len(), total);
        Some(k)
    };
    // Ratio q with q^interior = crowd: every knot distinct.
    let q = (crowd.ln() / interior as f64).exp();
    let geometric: Vec<f32> = (0..interior).map(|i| q.powi((interior - i) as i32) as f32).collect();
    let mut repeated: Vec<f32> = Vec::new();
    let groups = interior.div_ceil((order - 1).max(1));
    for g in 0..groups {
        for _ in 0..order - 1 {
            if repeated.len() < interior {
                repeated.push((g + 1) as f32 / (groups + 1) as f32);
            }
        }
    }
    let long: Vec<f32> = (0..interior).map(|i| (i + 1) as f32 * 1e-3).collect();
    vec![
        ("uniform", None),
        ("crowded", clamp(geometric, 1.0)),
        ("repeated", clamp(repeated, 1.0)),
        ("long-span", clamp(long, 1e6)),
    ]
}

/// B-splines of [`MAX_BSPLINE_POINTS`] control points and order 2, 4 and [`MAX_ORDER`], every
/// point and knot pattern (the crowded knots as crowded as a valid `γ` allows: the first span
/// `1e-12` wide or, where that is too steep, `1e-9`, …; a pattern no `γ ≤ 1e6` makes valid is
/// left out), γ the least the steepness limit allows.
fn bspline_corners() -> Vec<(String, CurveWave)> {
    let mut v = Vec::new();
    let mut rng = Rng(0xb5b1);
    for order in [2usize, 4, MAX_ORDER] {
        for (name, points) in point_patterns(MAX_BSPLINE_POINTS, &mut rng) {
            for which in 0..4 {
                let Some((kname, shape, g0)) = [1e-12, 1e-9, 1e-6, 1e-3]
                    .into_iter()
                    .map(|crowd| {
                        let (kname, knots) =
                            knot_patterns(MAX_BSPLINE_POINTS, order, crowd).swap_remove(which);
                        let shape =
                            CurveShape::BSpline { points: points.clone(), order: order as u32, knots };
                        let slope = wave(shape.clone(), 1.0, 1.0, 0.0).steepness();
                        (kname, shape, slope)
                    })
                    .find(|(_, _, slope)| *slope / MAX_SLOPE <= f64::from(COORD_MAX) * 0.99)
                    .map(|(kname, shape, slope)| (kname, shape, min_gamma(slope)))
                else {
                    // No γ ≤ 1e6 makes it valid (the long span with `wild` points).
                    continue;
                };
                for (extension, j) in [(1.0, 0.0), (1e-6, 1e6)] {
                    v.push((
                        format!("bspline k={order} {name} {kname} γ={g0:e} k={extension:e} j={j:e}"),
                        wave(shape.clone(), g0, extension, j),
                    ));
                }
            }
        }
    }
    v
}

/// The costliest corner of each kind with Simpson at the largest `m` it allows, without and with
/// the reduction `n = 1` (three regions of `m` each).
fn simpson_corners() -> Vec<(String, CurveWave)> {
    let mut picks: Vec<(String, CurveWave)> = Vec::new();
    let pick = |all: Vec<(String, CurveWave)>, key: &str| {
        all.into_iter().find(|(n, _)| n.contains(key) && n.contains("k=1e0 j=0e0")).expect(key)
    };
    picks.push(pick(helix_corners(), "helix r=1e0 len=1e0 rate=8.04"));
    picks.push(pick(trig_corners(), &format!("trig h={MAX_TRIG_TERMS} flat len=1e0")));
    picks.push(pick(bezier_corners(), &format!("bezier n={MAX_BEZIER_POINTS} wild")));
    picks.push(pick(bspline_corners(), &format!("bspline k={MAX_ORDER} random uniform")));
    let mut v = Vec::new();
    for (name, w) in picks {
        let m = w.max_simpson_m();
        for reduction in [None, Some(Reduction { n: 1, epsilon: 0.0 })] {
            let mut w = w.clone();
            w.integrator = Integrator::Simpson { m, reduction };
            v.push((format!("simpson m={m} n={:?} {name}", reduction.map(|r| r.n)), w));
        }
    }
    v
}

fn env<T: std::str::FromStr>(k: &str, d: T) -> T {
    std::env::var(k).ok().and_then(|v| v.parse().ok()).unwrap_or(d)
}

/// Every corner validates, and no ray takes more than `bound(wave)` evaluations; returns the
/// largest count and the corner that took it.
fn check(corners: Vec<(String, CurveWave)>, grid: usize, bound: impl Fn(&CurveWave) -> u32) -> (u32, String) {
    let mut worst = (0u32, String::new());
    for (name, w) in corners {
        if let Err(e) = w.validate() {
            panic!("{name}: not a valid corner: {e}");
        }
        let b = bound(&w);
        for s in measure(&w, grid) {
            assert!(s.max <= b, "{name} {:?}: a ray took {} evaluations (bound {b})", s.falloff, s.max);
            if s.max > worst.0 {
                worst = (s.max, format!("{name} {:?}", s.falloff));
            }
        }
    }
    worst
}

#[test]
fn helix_corners_bound_the_work_per_ray() {
    let worst = check(helix_corners(), 2, |_| DEFAULT_BOUND);
    println!("helix: worst {worst:?}");
}

#[test]
fn trig_corners_bound_the_work_per_ray() {
    let worst = check(trig_corners(), 2, |_| DEFAULT_BOUND);
    println!("trig: worst {worst:?}");
}

#[test]
fn bezier_corners_bound_the_work_per_ray() {
    let worst = check(bezier_corners(), 2, |_| DEFAULT_BOUND);
    println!("bezier: worst {worst:?}");
}

#[test]
fn bspline_corners_bound_the_work_per_ray() {
    let worst = check(bspline_corners(), 2, |_| DEFAULT_BOUND);
    println!("bspline: worst {worst:?}");
}

/// Simpson takes `m + 1` samples per region (at most three) and the default integrator's tail
/// past the far point; `m × point cost` is at most [`MAX_SIMPSON_M`].
#[test]
fn simpson_corners_bound_the_work_per_ray() {
    let worst = check(simpson_corners(), 1, |w| match w.integrator {
        Integrator::Simpson { m, reduction } => {
            assert!(f64::from(m) * w.point_cost() <= f64::from(MAX_SIMPSON_M));
            (if reduction.is_some() { 3 } else { 1 }) * (m + 1) + DEFAULT_BOUND
        }
        Integrator::Default | Integrator::Nearest => DEFAULT_BOUND,
    });
    println!("simpson: worst {worst:?}");
}

/// The same four costliest corners as [`simpson_corners`] (128 helix turns, 64 terms at 128
/// turns, 64 Bézier points, a 512-point B-spline of order 16) with the nearest-point field.
fn nearest_corners() -> Vec<(String, CurveWave)> {
    simpson_corners()
        .into_iter()
        .filter(|(n, _)| n.contains("n=None"))
        .map(|(n, mut w)| {
            w.integrator = Integrator::Nearest;
            (n.replacen("simpson", "nearest", 1), w)
        })
        .collect()
}

/// The nearest-point field's work is bounded by construction (at most [`MAX_NEAREST_STEPS`]
/// intervals of two queries, each at most [`MAX_NEAREST_VISITS`] pieces and 7 exact points, plus
/// the first query and the tail); on the costliest corners it stays far below.
#[test]
fn nearest_corners_bound_the_work_per_ray() {
    let construction = (2 * MAX_NEAREST_STEPS + 1) * (MAX_NEAREST_VISITS + 8) + 1;
    let worst = check(nearest_corners(), 1, |_| NEAREST_BOUND);
    println!("nearest: worst {worst:?} (bound by construction {construction})");
    assert_eq!(NEAREST_BOUND, construction);
    const { assert!(NEAREST_BOUND < 750_000, "the documented bound") };
}

/// Prints evaluations per ray (largest, mean), time per ray (mean, largest) and the preparation
/// time of every corner (`COST_ONLY` filters by name, `COST_GRID` sets the window's grid).
#[test]
#[ignore = "prints a measurement table; run explicitly"]
fn curve_cost_report() {
    let grid: usize = env("COST_GRID", 3);
    let only: String = env("COST_ONLY", String::new());
    let all =
        [helix_corners(), trig_corners(), bezier_corners(), bspline_corners(), simpson_corners()].concat();
    for (name, w) in all {
        if !only.is_empty() && !name.contains(&only) {
            continue;
        }
        for s in measure(&w, grid) {
            println!(
                "{name:<80} {:<5} rays {:>4} max {:>7} mean {:>9.1} | {:>8.3} ms/ray max {:>8.3} ms | prep {:>7.1} ms",
                if s.falloff == Falloff::Faithful { "faith" } else { "inv2" },
                s.rays,
                s.max,
                s.mean,
                s.ms_per_ray,
                s.max_ms,
                s.prep_ms
            );
        }
    }
}
