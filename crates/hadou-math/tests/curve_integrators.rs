//! The curve integrators against the converged reference on configurations resembling thesis 002
//! Fig. 4.2 (camera from the side at 40 units, 45° field of view, 512² rays, every 8th pixel):
//! Simpson converges as `m` grows; the default integrator meets its acceptance bars (99th-percentile
//! relative error ≤ 0.5 %, ≥ 10× fewer evaluations than Simpson `m = 500`, which is itself
//! further from the reference) and shows no band at the bounding cylinder, where the thesis's
//! reduction does.

#[allow(dead_code)]
#[path = "curve_common/mod.rs"]
mod support;

use hadou_math::curve::{curve_energy, curve_energy_reference, prepare, CurveWave, Integrator, Reduction};
use hadou_math::energy::Falloff;
use support::*;

/// Per-ray `(relative error, evaluations)` of `w`'s integrator over the sampled pixels.
fn errors(w: &CurveWave, falloff: Falloff, reference: &[f64], pixels: &[(u32, u32)]) -> (Vec<f64>, f64) {
    let c = prepare(w);
    let p32 = params32(&params(falloff));
    let mut evals = 0u64;
    let errs = pixels
        .iter()
        .zip(reference)
        .map(|(&(x, y), &rf)| {
            let r = pixel_ray(f64::from(x), f64::from(y), falloff);
            let s = curve_energy(&c, &p32, &r.ray32(), r.t0 as f32, r.t1 as f32, r.t_far as f32);
            evals += u64::from(s.evaluations);
            assert!(s.energy.is_finite());
            (f64::from(s.energy) - rf).abs() / rf
        })
        .collect();
    (errs, evals as f64 / pixels.len() as f64)
}

fn references(w: &CurveWave, falloff: Falloff, pixels: &[(u32, u32)]) -> Vec<f64> {
    let c = prepare(w);
    let p = params(falloff);
    pixels
        .iter()
        .map(|&(x, y)| {
            let r = pixel_ray(f64::from(x), f64::from(y), falloff);
            let v = curve_energy_reference(&c, &p, &r.ray, r.t0, r.t1, r.t_far, 1e-10);
            assert!(v > 0.0 && v.is_finite());
            v
        })
        .collect()
}

#[test]
fn simpson_converges_to_the_reference_as_m_grows() {
    for (name, w) in shapes() {
        for falloff in [Falloff::Faithful, Falloff::InverseSquare] {
            let c = prepare(&w);
            let p = params(falloff);
            let mut r = pixel_ray(300.0, 240.0, falloff);
            // The thesis's domain, eye to far point (beyond it Simpson has no rule).
            r.t1 = r.t1.min(r.t_far);
            let rf = curve_energy_reference(&c, &p, &r.ray, r.t0, r.t1, r.t_far, 1e-11);
            let mut prev = f64::INFINITY;
            for m in [20u32, 200, 2000, 20000] {
                let mut ws = w.clone();
                ws.integrator = Integrator::Simpson { m, reduction: None };
                let cs = prepare(&ws);
                // f64 evaluation isolates the rule's own error from f32 rounding.
                let (e, n) = hadou_math::curve::curve_energy_f64(&cs, &p, &r.ray, r.t0, r.t1, r.t_far);
                let err = (e - rf).abs() / rf;
                assert!(n > m, "{name}: Simpson counts at least m + 1 samples");
                assert!(err < prev.max(1e-9), "{name} {falloff:?} m={m}: {err} ≥ {prev}");
                prev = err;
            }
            assert!(prev < 1e-6, "{name} {falloff:?}: m = 20000 still {prev} off");
        }
    }
}

#[test]
fn default_integrator_meets_the_acceptance_bars() {
    let pixels = sample_pixels(8);
    for (name, w) in shapes() {
        for (falloff, j) in
            [(Falloff::Faithful, 0.0), (Falloff::InverseSquare, 0.0), (Falloff::InverseSquare, 2.0)]
        {
            let mut w = w.clone();
            w.attenuation = j;
            let reference = references(&w, falloff, &pixels);
            let (def, def_evals) = errors(&w, falloff, &reference, &pixels);
            let mut ws = w.clone();
            ws.integrator = Integrator::Simpson { m: 500, reduction: None };
            let (simp, simp_evals) = errors(&ws, falloff, &reference, &pixels);
            let (p99, p99_s) = (quantile(&def, 0.99), quantile(&simp, 0.99));
            println!("{name} {falloff:?} j={j}: default p99 {p99:.2e} ({def_evals:.1} evals), Simpson 500 p99 {p99_s:.2e}");
            assert!(p99 <= 5e-3, "{name} {falloff:?} j={j}: p99 {p99}");
            assert!(
                p99 < p99_s,
                "{name} {falloff:?} j={j}: Simpson m=500 ({p99_s}) should be further off than {p99}"
            );
            let ratio = simp_evals / def_evals;
            assert!(ratio >= 10.0, "{name} {falloff:?} j={j}: only {ratio:.1}× fewer evaluations");
        }
    }
}

/// Energies along a column crossing the bounding cylinder's silhouette, in sub-pixel steps.
fn column(w: &CurveWave, falloff: Falloff, px: f64, rows: (f64, f64), steps: usize) -> Vec<f64> {
    let c = prepare(w);
    let p32 = params32(&params(falloff));
    (0..=steps)
        .map(|i| {
            let py = rows.0 + (rows.1 - rows.0) * i as f64 / steps as f64;
            let r = pixel_ray(px, py, falloff);
            f64::from(curve_energy(&c, &p32, &r.ray32(), r.t0 as f32, r.t1 as f32, r.t_far as f32).energy)
        })
        .collect()
}

/// The largest "jump" along a sampled line: a step `Δ_i` that departs from the mean of its two
/// neighbours by more than `factor` times the larger neighbour step.
fn worst_jump(e: &[f64]) -> f64 {
    let d: Vec<f64> = e.windows(2).map(|w| w[1] - w[0]).collect();
    let mut worst: f64 = 0.0;
    for i in 1..d.len() - 1 {
        let neighbours = d[i - 1].abs().max(d[i + 1].abs()).max(1e-7 * e[i].abs());
        worst = worst.max((d[i] - 0.5 * (d[i - 1] + d[i + 1])).abs() / neighbours);
    }
    worst
}

#[test]
fn no_band_at_the_bounding_cylinder() {
    // The cylinder of radius R + ε around the axis (y = 0 in view) has its silhouette at
    // y = ±(R + ε), rows 256 ∓ (R + ε)/(40 tan 22.5°)·256 for a camera 40 units away.
    let falloff = Falloff::Faithful;
    for (name, w) in shapes() {
        let c = prepare(&w);
        let eps = 0.25f64;
        let rad = f64::from(c.bound_radius()) + eps;
        let row = 256.0 - rad / (40.0 * 22.5f64.to_radians().tan()) * 256.0 - 0.5;
        let rows = (row - 3.0, row + 3.0);
        let px = 330.0;
        let default = column(&w, falloff, px, rows, 240);
        let jump_default = worst_jump(&default);
        let mut ws = w.clone();
        ws.integrator =
            Integrator::Simpson { m: 100, reduction: Some(Reduction { n: 4, epsilon: eps as f32 }) };
        let faithful = column(&ws, falloff, px, rows, 240);
        let jump_simpson = worst_jump(&faithful);
        println!("{name}: worst jump default {jump_default:.2}, Simpson m=100 n=4 {jump_simpson:.2}");
        assert!(jump_default <= 1.0, "{name}: the default integrator bands ({jump_default})");
        assert!(
            jump_simpson > 1.0,
            "{name}: the thesis's reduction should band at the cylinder ({jump_simpson})"
        );
    }
}
