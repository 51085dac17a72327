//! Throughput of the `f32` render path (one `beam_energy::<f32>` per pixel of a 1024² view), and
//! of the single-`atan2` inverse-square form against the two-`atan` difference it replaces.
//! Ignored by default and asserts nothing about time; run with
//! `cargo test --release -p hadou-math --test analytic_timing -- --ignored --nocapture`.

use hadou_math::energy::{beam_energy, BeamField, CapsuleField, Falloff, FieldParams, Ray, RayQuadratic};
use hadou_math::Vec3f;
use std::hint::black_box;
use std::time::Instant;

const N: u32 = 1024;

fn rays(falloff: Falloff) -> Vec<Ray<f32>> {
    let half = (30.0f32).to_radians().tan();
    let mut v = Vec::with_capacity((N * N) as usize);
    for py in 0..N {
        for px in 0..N {
            let x = ((px as f32 + 0.5) / N as f32 * 2.0 - 1.0) * half;
            let y = (1.0 - (py as f32 + 0.5) / N as f32 * 2.0) * half;
            let d = Vec3f::new(x, y, -1.0);
            let dir = match falloff {
                Falloff::Faithful => d * 1e4,
                Falloff::InverseSquare => d.normalize_or(Vec3f::Z),
            };
            v.push(Ray { origin: Vec3f::new(0.0, 0.0, 0.0), dir });
        }
    }
    v
}

fn beam() -> BeamField<f32> {
    BeamField {
        capsule: CapsuleField {
            m: Vec3f::new(-3.0, -0.5, -10.0),
            d: Vec3f::new(0.96, 0.0, -0.28),
            length: 6.0,
            alpha_s: 0.5,
            alpha_c: 0.5,
        },
        head_alpha: 1.5,
        muzzle_alpha: 0.7,
    }
}

/// Best of five passes, in Mpixel/s.
fn rate(mut pass: impl FnMut() -> f32) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t = Instant::now();
        black_box(pass());
        best = best.min(t.elapsed().as_secs_f64());
    }
    f64::from(N * N) / best / 1e6
}

#[test]
#[ignore = "timing: prints throughput, run on demand"]
fn beam_energy_f32_throughput() {
    let b = beam();
    for falloff in [Falloff::Faithful, Falloff::InverseSquare] {
        let rs = rays(falloff);
        let t1 = if falloff == Falloff::Faithful { 1.0 } else { f32::INFINITY };
        let p = FieldParams { falloff, core_radius: 0.02f32 };
        let r = rate(|| rs.iter().map(|ray| beam_energy(&p, black_box(ray), 0.0, t1, &b)).sum());
        println!("beam_energy::<f32> {falloff:?}: {r:.1} Mpixel/s on one core");
    }
    // Inverse-square kernel alone: one atan2 against two atans, on the same quadratics.
    let qs: Vec<RayQuadratic<f32>> = (0..N * N)
        .map(|i| RayQuadratic {
            s: 1.0,
            beta: (i % 4096) as f32 * 0.01 - 20.0,
            h: 0.01 + (i % 97) as f32 * 0.01,
        })
        .collect();
    let one = rate(|| qs.iter().map(|q| black_box(q).inverse_square(0.0, 15.0)).sum());
    let two = rate(|| {
        qs.iter()
            .map(|q| {
                let q = black_box(q);
                let sh = q.h.sqrt();
                let y1 = q.s * 15.0 + q.beta;
                ((y1 / sh).atan() - (q.beta / sh).atan()) / (q.s * sh)
            })
            .sum()
    });
    let faithful = rate(|| qs.iter().map(|q| black_box(q).faithful(0.0, 15.0)).sum());
    println!("inverse square kernel: one atan2 {one:.0} M/s, two atans {two:.0} M/s; faithful kernel {faithful:.0} M/s");
}
