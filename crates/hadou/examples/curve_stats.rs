//! Per-pixel statistics of the curve integrators on one example scene: evaluations (mean and
//! quantiles), error against the f64 reference, and the single-thread time of the integration
//! alone over every pixel, for the default integrator (with optional settings) and Simpson m = 500.
//!
//! `cargo run --release -p hadou --example curve_stats -- SCENE [TIME] [TOLERANCE]`
//!
//! TIME is the scene time in seconds (default 0), TOLERANCE the default integrator's `τ`
//! (default [`DEFAULT_SETTINGS`]). With `ONLY_DEFAULT` set in the environment the Simpson line is
//! skipped. The three worst pixels of each integrator go to stderr.

use hadou_math::curve::{self, integrate::default_energy, CurveWave, Integrator, DEFAULT_SETTINGS};
use hadou_math::energy::{FieldParams, Ray};
use hadou_scene::{Scene, WaveShape};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else {
        eprintln!("usage: curve_stats SCENE [TIME] [TOLERANCE]");
        std::process::exit(2);
    };
    let number = |i: usize, what: &str| -> Option<f64> {
        let s = args.get(i)?;
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() => Some(v),
            _ => {
                eprintln!("{what} {s:?}: not a number");
                std::process::exit(2);
            }
        }
    };
    let time = number(2, "TIME").unwrap_or(0.0) as f32;
    let mut settings = DEFAULT_SETTINGS;
    if let Some(t) = number(3, "TOLERANCE") {
        settings.tolerance = t;
    }
    let scene = match Scene::load(std::path::Path::new(path)) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let frame = scene.at(time);
    let basis = frame.camera.basis(frame.width, frame.height);
    let waves: Vec<(&hadou_scene::Wave, &CurveWave)> = frame
        .waves
        .iter()
        .filter_map(|w| match &w.shape {
            WaveShape::Curve(c) => Some((w, c)),
            _ => None,
        })
        .collect();
    if waves.is_empty() {
        eprintln!("{path}: no curved wave in the scene at t = {time}");
        std::process::exit(2);
    }
    let (w, h) = (frame.width, frame.height);
    let step = 4u32;
    let pixels: Vec<(u32, u32)> = (0..h)
        .step_by(step as usize)
        .flat_map(|y| (0..w).step_by(step as usize).map(move |x| (x, y)))
        .collect();
    let ref_prepared: Vec<_> = waves.iter().map(|(wv, c)| (*wv, curve::prepare(c))).collect();
    let reference: Vec<f64> = pixels
        .iter()
        .map(|&(x, y)| {
            ref_prepared
                .iter()
                .map(|(wv, pc)| {
                    let wr = basis.wave_ray(wv.falloff, frame.camera.far, x as f32, y as f32, w, h, None);
                    let p = FieldParams { falloff: wv.falloff, core_radius: wv.core_radius as f64 };
                    let ray = Ray { origin: wr.ray.origin.as_f64(), dir: wr.ray.dir.as_f64() };
                    curve::curve_energy_reference(
                        pc,
                        &p,
                        &ray,
                        wr.t0 as f64,
                        wr.t1 as f64,
                        wr.t_far as f64,
                        1e-10,
                    )
                })
                .sum()
        })
        .collect();
    let peak = reference.iter().copied().fold(0.0, f64::max);
    let only_default = std::env::var("ONLY_DEFAULT").is_ok();
    for simpson in [false, true] {
        if simpson && only_default {
            break;
        }
        let prepared: Vec<_> = waves
            .iter()
            .map(|(wv, c)| {
                let mut c = (*c).clone();
                c.integrator = if simpson {
                    Integrator::Simpson { m: 500, reduction: None }
                } else {
                    Integrator::Default
                };
                (*wv, curve::prepare(&c))
            })
            .collect();
        let run = |x: u32, y: u32| {
            let (mut e, mut n) = (0.0f32, 0u32);
            for (wv, pc) in &prepared {
                let wr = basis.wave_ray(wv.falloff, frame.camera.far, x as f32, y as f32, w, h, None);
                let p = FieldParams { falloff: wv.falloff, core_radius: wv.core_radius };
                let s = if simpson {
                    curve::curve_energy(pc, &p, &wr.ray, wr.t0, wr.t1, wr.t_far)
                } else {
                    default_energy(pc, &p, &wr.ray, wr.t0, wr.t1, wr.t_far, &settings)
                };
                e += s.energy;
                n += s.evaluations;
            }
            (e, n)
        };
        let mut evals = Vec::new();
        let mut errs = Vec::new();
        let mut worst = Vec::new();
        for (&(x, y), &r) in pixels.iter().zip(&reference) {
            let (e, n) = run(x, y);
            evals.push(n);
            if r > 1e-4 * peak {
                let err = (f64::from(e) - r).abs() / r;
                worst.push((err, x, y, e, r, n));
                errs.push(err);
            }
        }
        worst.sort_by(|a, b| b.0.total_cmp(&a.0));
        for &(err, x, y, e, r, n) in worst.iter().take(3) {
            eprintln!("  worst: pixel ({x}, {y}) energy {e} reference {r:.6e} ({err:.1e}), {n} evaluations");
        }
        let start = Instant::now();
        let mut sink = 0.0f32;
        for y in 0..h {
            for x in 0..w {
                sink += run(x, y).0;
            }
        }
        let ms = start.elapsed().as_secs_f64() * 1e3;
        evals.sort_unstable();
        errs.sort_by(f64::total_cmp);
        let q = |v: &[u32], f: f64| v[((v.len() - 1) as f64 * f).round() as usize];
        let qe =
            |f: f64| if errs.is_empty() { 0.0 } else { errs[((errs.len() - 1) as f64 * f).round() as usize] };
        let mean = evals.iter().map(|&n| f64::from(n)).sum::<f64>() / evals.len() as f64;
        println!(
            "{:<10} evals mean {mean:6.1} p50 {:4} p90 {:4} p99 {:4} max {:5} | err p50 {:.1e} p99 {:.2e} max {:.1e} | {ms:7.1} ms 1 thread ({sink:.0})",
            if simpson { "simpson500" } else { "default" },
            q(&evals, 0.5),
            q(&evals, 0.9),
            q(&evals, 0.99),
            q(&evals, 1.0),
            qe(0.5),
            qe(0.99),
            qe(1.0),
        );
    }
}
