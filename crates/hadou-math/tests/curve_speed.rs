//! A quick speed and accuracy report for the curve integrators (not a timed test: it is ignored
//! by default and only prints). Run with
//! `cargo test -p hadou-math --test curve_speed -- --ignored --nocapture`.
//! Environment: `CURVE_STEP` (pixel stride, default 4), `CURVE_FALLOFF` (`faithful`/`inverse`),
//! `CURVE_J` (attenuation exponent), `CURVE_TOL` (default-integrator tolerance).

#[allow(dead_code)]
#[path = "curve_common/mod.rs"]
mod support;

use hadou_math::curve::integrate::{default_energy, DefaultSettings, DEFAULT_SETTINGS};
use hadou_math::curve::{curve_energy, curve_energy_reference, prepare, Integrator, Reduction};
use hadou_math::energy::Falloff;
use std::time::Instant;
use support::*;

fn env<T: std::str::FromStr>(k: &str, d: T) -> T {
    std::env::var(k).ok().and_then(|v| v.parse().ok()).unwrap_or(d)
}

#[test]
#[ignore = "prints a measurement table; run explicitly"]
fn curve_speed_report() {
    let step: u32 = env("CURVE_STEP", 4);
    let falloff = match std::env::var("CURVE_FALLOFF").as_deref() {
        Ok("inverse") => Falloff::InverseSquare,
        _ => Falloff::Faithful,
    };
    let j: f32 = env("CURVE_J", 0.0);
    let tol: f64 = env("CURVE_TOL", DEFAULT_SETTINGS.tolerance);
    let only: String = env("CURVE_SHAPE", String::new());
    let settings = DefaultSettings { tolerance: tol };
    let p = params(falloff);
    let p32 = params32(&p);
    let pixels = sample_pixels(step);
    println!("falloff {falloff:?}, j = {j}, {} rays (every {step}th pixel of 512²), tol {tol}", pixels.len());
    println!(
        "{:<10} {:<22} {:>10} {:>10} {:>10} {:>10} {:>10}",
        "shape", "integrator", "evals/ray", "ns/ray", "p50 err", "p99 err", "max err"
    );
    for (name, mut w) in shapes() {
        if !only.is_empty() && !name.starts_with(&only) {
            continue;
        }
        w.attenuation = j;
        let rays: Vec<PixelRay> =
            pixels.iter().map(|&(x, y)| pixel_ray(f64::from(x), f64::from(y), falloff)).collect();
        let c = prepare(&w);
        let t = Instant::now();
        let reference: Vec<f64> =
            rays.iter().map(|r| curve_energy_reference(&c, &p, &r.ray, r.t0, r.t1, r.t_far, 1e-10)).collect();
        let ref_time = t.elapsed();
        let mut configs: Vec<(String, Integrator)> = vec![("default".into(), Integrator::Default)];
        for m in [100u32, 300, 500] {
            configs.push((format!("simpson m={m}"), Integrator::Simpson { m, reduction: None }));
            for n in [2u32, 4] {
                configs.push((
                    format!("simpson m={m} n={n}"),
                    Integrator::Simpson { m, reduction: Some(Reduction { n, epsilon: 0.1 }) },
                ));
            }
        }
        for (label, integ) in configs {
            let mut w2 = w.clone();
            w2.integrator = integ;
            let c = prepare(&w2);
            let run = || {
                let mut evals = 0u64;
                let mut out = Vec::with_capacity(rays.len());
                for r in &rays {
                    let s = if integ == Integrator::Default {
                        default_energy(
                            &c,
                            &p32,
                            &r.ray32(),
                            r.t0 as f32,
                            r.t1 as f32,
                            r.t_far as f32,
                            &settings,
                        )
                    } else {
                        curve_energy(&c, &p32, &r.ray32(), r.t0 as f32, r.t1 as f32, r.t_far as f32)
                    };
                    evals += u64::from(s.evaluations);
                    out.push(s.energy);
                }
                (out, evals)
            };
            let (out, evals) = run();
            let reps = 3;
            let t = Instant::now();
            for _ in 0..reps {
                std::hint::black_box(run());
            }
            let ns = t.elapsed().as_nanos() as f64 / (reps * rays.len()) as f64;
            let errs: Vec<f64> = out
                .iter()
                .zip(&reference)
                .map(|(&e, &r)| if r > 0.0 { (f64::from(e) - r).abs() / r } else { f64::from(e).abs() })
                .collect();
            println!(
                "{:<10} {:<22} {:>10.1} {:>10.0} {:>10.2e} {:>10.2e} {:>10.2e}",
                name,
                label,
                evals as f64 / rays.len() as f64,
                ns,
                quantile(&errs, 0.5),
                quantile(&errs, 0.99),
                quantile(&errs, 1.0)
            );
        }
        println!("{name}: {} leaf pieces, reference {:.2?}", c.table().pieces(), ref_time);
    }
}
