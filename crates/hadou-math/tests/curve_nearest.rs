//! The nearest-point field (`Integrator::Nearest`) against its brute-force `f64` reference
//! (dense minimisation of the distance on the exact curve, adaptive Gauss–Kronrod along the ray)
//! on random rays for every curve kind and both falloffs, with and without attenuation; the
//! streak of the cross-section pairing above a helix's crest, which the nearest field does not
//! have; and the work a ray takes.

#[allow(dead_code)]
#[path = "curve_common/mod.rs"]
mod support;

use hadou_math::curve::{curve_energy, nearest_energy_reference, prepare, CurveWave, Integrator};
use hadou_math::energy::{Falloff, FieldParams, Ray};
use hadou_math::{Vec3, Vec3d};
use support::*;

fn nearest(mut w: CurveWave) -> CurveWave {
    w.integrator = Integrator::Nearest;
    w
}

/// A random ray from 20–40 units away towards a random point within the curve's box
/// (`[-11, 11] × [-4, 4]²`), in the falloff's convention: `(ray, t0, t1, t_far)`.
fn random_ray(rng: &mut Rng, falloff: Falloff) -> (Ray<f64>, f64, f64, f64) {
    let dir = loop {
        let v = Vec3d::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            break v / l;
        }
    };
    let eye = dir * rng.range(20.0, 40.0);
    let target = Vec3d::new(rng.range(-11.0, 11.0), rng.range(-4.0, 4.0), rng.range(-4.0, 4.0));
    let d = (target - eye).normalize_or(Vec3d::X);
    match falloff {
        Falloff::Faithful => (Ray { origin: eye, dir: d * FAR }, 0.0, 1.0, 1.0),
        Falloff::InverseSquare => (Ray { origin: eye, dir: d }, 0.0, f64::INFINITY, FAR),
    }
}

/// Relative errors and mean evaluations of the `f32` nearest field over `count` random rays.
fn errors(w: &CurveWave, falloff: Falloff, count: usize, seed: u64) -> (Vec<f64>, f64) {
    let c = prepare(&nearest(w.clone()));
    let p = params(falloff);
    let p32 = params32(&p);
    let mut rng = Rng(seed);
    let mut evals = 0u64;
    let errs = (0..count)
        .map(|_| {
            let (ray, t0, t1, t_far) = random_ray(&mut rng, falloff);
            let want = nearest_energy_reference(&c, &p, &ray, t0, t1, t_far, 1e-8);
            let r32 = Ray { origin: ray.origin.as_f32(), dir: ray.dir.as_f32() };
            let got = curve_energy(&c, &p32, &r32, t0 as f32, t1 as f32, t_far as f32);
            assert!(got.energy.is_finite() && want.is_finite() && want > 0.0);
            evals += u64::from(got.evaluations);
            (f64::from(got.energy) - want).abs() / want
        })
        .collect();
    (errs, evals as f64 / count as f64)
}

#[test]
fn nearest_field_meets_its_reference_on_random_rays() {
    for (name, w) in shapes() {
        for (k, falloff) in [Falloff::Faithful, Falloff::InverseSquare].into_iter().enumerate() {
            let (errs, evals) = errors(&w, falloff, 120, 0x5eed + k as u64);
            let p99 = quantile(&errs, 0.99);
            let max = quantile(&errs, 1.0);
            println!("{name} {falloff:?}: p99 {p99:.2e} max {max:.2e}, {evals:.0} evaluations per ray");
            assert!(p99 <= 1e-3, "{name} {falloff:?}: p99 relative error {p99:.2e} > 1e-3");
        }
    }
}

#[test]
fn nearest_field_with_attenuation_meets_its_reference() {
    for (name, mut w) in shapes() {
        w.attenuation = 1.5;
        for (k, falloff) in [Falloff::Faithful, Falloff::InverseSquare].into_iter().enumerate() {
            let (errs, _) = errors(&w, falloff, 40, 0xa77e + k as u64);
            let p99 = quantile(&errs, 0.99);
            println!("{name} {falloff:?} j = 1.5: p99 {p99:.2e}");
            assert!(p99 <= 1e-3, "{name} {falloff:?} j = 1.5: p99 relative error {p99:.2e} > 1e-3");
        }
    }
}

/// Energy of the helix fixture (radius 2, pitch 4, axis `x`) along the row `y = 2 + h`, `h` above
/// its crests, seen from `+z` by parallel inverse-square rays, at `x` steps of 0.1 over one pitch
/// around the crest at `x = 0.8`.
fn crest_row(w: &CurveWave, h: f32) -> Vec<f64> {
    let c = prepare(w);
    let p = FieldParams { falloff: Falloff::InverseSquare, core_radius: 0.05f32 };
    (0..=40)
        .map(|i| {
            let x = -1.2 + 0.1 * i as f32;
            let ray = Ray { origin: Vec3::new(x, 2.0 + h, 30.0), dir: Vec3::new(0.0, 0.0, -1.0) };
            f64::from(curve_energy(&c, &p, &ray, 0.0, f32::INFINITY, 100.0).energy)
        })
        .collect()
}

/// Above a helix seen from the side the cross-section pairing measures each ray's distance in
/// its own cross-section only, `|y − y_silhouette(x)|`, so every row above the curve repeats the
/// silhouette's crests at full depth however high it is: bright columns over each crest, the
/// streaks. The true distance spreads them: the row's modulation (largest over smallest energy
/// over one pitch) falls towards 1 with height, and stays well below the pairing's.
#[test]
fn nearest_field_has_no_streak_above_a_crest() {
    let modulation = |v: &[f64]| {
        let max = v.iter().copied().fold(0.0, f64::max);
        let min = v.iter().copied().fold(f64::INFINITY, f64::min);
        max / min
    };
    // The pairing's modulation is (h + 2r)/h at every height (5, 3, 2); the nearest field's excess
    // over 1 is a third of it or less and falls faster.
    for (h, section_min, nearest_max) in [(1.0f32, 4.5, 2.4), (2.0, 2.8, 1.5), (4.0, 1.9, 1.15)] {
        let section = modulation(&crest_row(&helix(), h));
        let near = modulation(&crest_row(&nearest(helix()), h));
        println!("{h} above the crests: modulation {section:.3} (pairing), {near:.3} (nearest)");
        assert!(section > section_min, "h = {h}: the pairing's streaks are missing ({section:.3})");
        assert!(near < nearest_max, "h = {h}: the nearest field has streaks ({near:.3})");
        assert!(near - 1.0 < (section - 1.0) / 3.0, "h = {h}: {near:.3} against {section:.3}");
    }
}
