//! The default curve integrator on eight rays at once (`hadou_math::curve::curve_energy_lanes`,
//! what the wave pass runs) against the scalar reference `curve_energy`, on every vector path the
//! machine supports (`SimdPath::supported`): on every example curve scene at the times the curve
//! bench measures, each ray of each row's batches of eight neighbouring pixels gets the scalar
//! evaluation count exactly (the packet walks the same pieces) and its energy within a few ulp of
//! the lane logarithms; on degenerate rays mixed into batches of ordinary ones (NaN and infinite
//! input, empty and reversed spans, open spans, rays across and along the axis, rays through the
//! curve and through its end points, grazing rays that bisect leaves) each lane is finite,
//! non-negative and equal to the scalar value whatever its neighbours.

use hadou_math::curve::{
    self, curve_energy, curve_energy_lanes, CurveSample, Integrator, PreparedCurve, PACKET,
};
use hadou_math::energy::{Falloff, FieldParams, Ray};
use hadou_math::rng::Rng;
use hadou_math::simd::{dispatch, Lane, SimdPath, WithLanes};
use hadou_math::Vec3;
use hadou_scene::{Scene, WaveShape};
use std::path::PathBuf;

/// The example curve scenes and times of `hadou bench curves`' acceptance table.
const SCENES: [(&str, f32); 11] = [
    ("fig4-2-helix.toml", 0.0),
    ("fig4-2-trig.toml", 0.0),
    ("fig4-2-bezier.toml", 0.0),
    ("fig4-2-bspline.toml", 0.0),
    ("fig4-9-two-curves.toml", 0.0),
    ("fig4-10-attenuation.toml", 1.0),
    ("fig4-10-attenuation.toml", 3.0),
    ("fig4-10-attenuation.toml", 5.0),
    ("fig4-13-extension.toml", 0.0),
    ("fig4-13-extension.toml", 2.0),
    ("spiral-drill.toml", 1.8),
];

/// Largest relative energy difference from the scalar code (the lane `ln`, `atan2` and power
/// against libm's, summed over a ray's pieces).
const ENERGY_TOLERANCE: f32 = 1e-4;

/// One ray and its span.
#[derive(Clone, Copy, Debug)]
struct R {
    ray: Ray<f32>,
    t0: f32,
    t1: f32,
    t_far: f32,
}

/// `curve_energy_lanes` on a path's lanes.
struct Packet<'a> {
    c: &'a PreparedCurve,
    p: &'a FieldParams<f32>,
    rays: &'a [R],
}

impl WithLanes for Packet<'_> {
    type Output = [CurveSample; PACKET];
    #[inline(always)]
    fn run<L: Lane>(self) -> Self::Output {
        let rays: Vec<Ray<f32>> = self.rays.iter().map(|r| r.ray).collect();
        let t0: Vec<f32> = self.rays.iter().map(|r| r.t0).collect();
        let t1: Vec<f32> = self.rays.iter().map(|r| r.t1).collect();
        let tf: Vec<f32> = self.rays.iter().map(|r| r.t_far).collect();
        curve_energy_lanes::<L>(self.c, self.p, &rays, &t0, &t1, &tf)
    }
}

/// Checks every lane of one batch against the scalar code; returns how many lanes were checked.
fn check_batch(c: &PreparedCurve, p: &FieldParams<f32>, rays: &[R], path: SimdPath, what: &str) -> usize {
    let got = dispatch(path, Packet { c, p, rays });
    for (i, r) in rays.iter().enumerate() {
        let want = curve_energy(c, p, &r.ray, r.t0, r.t1, r.t_far);
        let g = got[i];
        assert!(
            g.energy.is_finite() && g.energy >= 0.0,
            "{what} on {path}: lane {i} ({r:?}) gives {}",
            g.energy
        );
        assert_eq!(
            g.evaluations, want.evaluations,
            "{what} on {path}: lane {i} ({r:?}): evaluations {} vs scalar {}",
            g.evaluations, want.evaluations
        );
        let tol = ENERGY_TOLERANCE * g.energy.max(want.energy) + 1e-30;
        assert!(
            (g.energy - want.energy).abs() <= tol,
            "{what} on {path}: lane {i} ({r:?}): energy {} vs scalar {}",
            g.energy,
            want.energy
        );
    }
    for (i, g) in got.iter().enumerate().skip(rays.len()) {
        assert_eq!(*g, CurveSample { energy: 0.0, evaluations: 0 }, "{what}: lane {i} beyond the batch");
    }
    rays.len()
}

#[test]
fn packets_match_the_scalar_integrator_on_every_example_curve_scene() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let (w, h) = (48u32, 36u32);
    for path in SimdPath::supported() {
        let mut checked = 0;
        let mut nonzero = 0;
        for (file, t) in SCENES {
            let scene = Scene::load(dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
            let frame = scene.at(t);
            let basis = frame.camera.basis(w, h);
            for wave in &frame.waves {
                let WaveShape::Curve(cw) = &wave.shape else { continue };
                let mut cw = cw.clone();
                cw.integrator = Integrator::Default;
                let c = curve::prepare(&cw);
                let p = FieldParams { falloff: wave.falloff, core_radius: wave.core_radius };
                for py in 0..h {
                    for x0 in (0..w).step_by(PACKET) {
                        let rays: Vec<R> = (x0..(x0 + PACKET as u32).min(w))
                            .map(|px| {
                                let wr = basis.wave_ray(
                                    wave.falloff,
                                    frame.camera.far,
                                    px as f32,
                                    py as f32,
                                    w,
                                    h,
                                    None,
                                );
                                R { ray: wr.ray, t0: wr.t0, t1: wr.t1, t_far: wr.t_far }
                            })
                            .collect();
                        let what = format!("{file} at {t} s, row {py}, pixels {x0}..");
                        checked += check_batch(&c, &p, &rays, path, &what);
                        nonzero += rays
                            .iter()
                            .filter(|r| curve_energy(&c, &p, &r.ray, r.t0, r.t1, r.t_far).energy > 0.0)
                            .count();
                    }
                }
            }
        }
        assert!(checked >= 12 * (w * h) as usize, "{path}: only {checked} rays checked");
        assert!(nonzero > checked / 2, "{path}: only {nonzero} of {checked} rays see a curve");
    }
}

#[test]
fn degenerate_rays_in_packets_match_the_scalar_integrator() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut rng = Rng(0x5eed_c0de);
    for path in SimdPath::supported() {
        for (file, t) in
            [("fig4-2-helix.toml", 0.0), ("fig4-10-attenuation.toml", 5.0), ("spiral-drill.toml", 1.8)]
        {
            let scene = Scene::load(dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
            let frame = scene.at(t);
            for wave in &frame.waves {
                let WaveShape::Curve(cw) = &wave.shape else { continue };
                let mut cw = cw.clone();
                cw.integrator = Integrator::Default;
                let c = curve::prepare(&cw);
                for falloff in [Falloff::Faithful, Falloff::InverseSquare] {
                    let p = FieldParams { falloff, core_radius: wave.core_radius };
                    let t_far = if falloff == Falloff::Faithful { 1.0 } else { 60.0 };
                    let span = if falloff == Falloff::Faithful { 1.0 } else { f32::INFINITY };
                    let scale = if falloff == Falloff::Faithful { 60.0 } else { 1.0 };
                    let (o, [ax, ay, az]) = c.frame_axes();
                    let s_head = f64::from(c.axial_length()) / f64::from(c.wave.gamma);
                    let on = |s: f64| c.point(s).as_f32();
                    let head = on(s_head);
                    let eye = o + ay * 9.0 + az * 3.0 - ax * 2.0;
                    let toward = |q: Vec3<f32>, from: Vec3<f32>| (q - from).normalize_or(ax) * scale;
                    let plain = |s: f64| R {
                        ray: Ray { origin: eye, dir: toward(on(s), eye) },
                        t0: 0.0,
                        t1: span,
                        t_far,
                    };
                    let nan = f32::NAN;
                    let inf = f32::INFINITY;
                    let mid = on(0.5 * s_head);
                    let odd = [
                        R { ray: Ray { origin: Vec3::new(nan, 0.0, 0.0), dir: ax }, t0: 0.0, t1: 1.0, t_far },
                        R {
                            ray: Ray { origin: eye, dir: Vec3::new(inf, 0.0, 0.0) },
                            t0: 0.0,
                            t1: 1.0,
                            t_far,
                        },
                        R { ray: Ray { origin: eye, dir: Vec3::ZERO }, t0: 0.0, t1: span, t_far },
                        R { t0: 0.5, t1: 0.25, ..plain(0.3 * s_head) },
                        R { t0: 0.3, t1: 0.3, ..plain(0.3 * s_head) },
                        R { t1: nan, ..plain(0.3 * s_head) },
                        R { t1: inf, ..plain(0.6 * s_head) },
                        R { t_far: -1.0, ..plain(0.6 * s_head) },
                        // Across the axis (x constant): the one-piece case.
                        R { ray: Ray { origin: mid + ay * 5.0, dir: -ay * scale }, t0: 0.0, t1: span, t_far },
                        // Along the axis, through the whole curve and its round ends.
                        R { ray: Ray { origin: o - ax * 4.0, dir: ax * scale }, t0: 0.0, t1: span, t_far },
                        // Through a curve point and through both end points.
                        R { ray: Ray { origin: eye, dir: toward(mid, eye) }, t0: 0.0, t1: span, t_far },
                        R { ray: Ray { origin: eye, dir: toward(o, eye) }, t0: 0.0, t1: span, t_far },
                        R { ray: Ray { origin: eye, dir: toward(head, eye) }, t0: 0.0, t1: span, t_far },
                        // Starting inside the slab, next to the curve.
                        R {
                            ray: Ray { origin: mid + az * 1e-3, dir: toward(head, mid) },
                            t0: 0.0,
                            t1: span,
                            t_far,
                        },
                    ];
                    // Grazing rays (within 10⁻⁴..10⁻² of a curve point: leaves bisected below the
                    // table) and ordinary ones around them.
                    let mut pool: Vec<R> = odd.to_vec();
                    for _ in 0..48 {
                        let s = rng.unit() * s_head;
                        let off = 10f32.powf(-4.0 + 2.0 * rng.unit() as f32);
                        let target = on(s) + ay * off;
                        pool.push(R { ray: Ray { origin: eye, dir: toward(target, eye) }, ..plain(s) });
                        pool.push(plain(rng.unit() * s_head));
                    }
                    // Every odd ray in every lane position, among ordinary and grazing ones.
                    for shift in 0..PACKET {
                        for start in (0..pool.len()).step_by(PACKET) {
                            let mut batch: Vec<R> =
                                (0..PACKET).map(|k| pool[(start + k * 7 + shift) % pool.len()]).collect();
                            batch.rotate_left(shift);
                            let what = format!("{file} {falloff:?} degenerate batch {start}/{shift}");
                            check_batch(&c, &p, &batch, path, &what);
                        }
                    }
                    // Short batches (the row's last pixels).
                    for len in 0..PACKET {
                        check_batch(
                            &c,
                            &p,
                            &pool[..len],
                            path,
                            &format!("{file} {falloff:?} batch of {len}"),
                        );
                    }
                }
            }
        }
    }
}
