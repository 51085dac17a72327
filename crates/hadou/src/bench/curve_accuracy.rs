//! How close a curve integrator comes to the converged reference: evaluations per pixel and the
//! p99 relative error on a grid of pixels (the curve table's accuracy columns and
//! `tests/curve_acceptance.rs`).

use hadou_math::curve::{self, Integrator};
use hadou_scene::{Frame, WaveShape};
use rayon::prelude::*;

/// Replaces the integrator of every curved wave of `frame`.
pub fn with_integrator(frame: &Frame, integrator: Integrator) -> Frame {
    let mut f = frame.clone();
    for w in &mut f.waves {
        if let WaveShape::Curve(c) = &mut w.shape {
            c.integrator = integrator;
        }
    }
    f
}

/// Pixels per side of the grid on which `hadou bench curves` measures evaluations and error.
pub const ACCURACY_GRID: u32 = 64;

/// Evaluations per pixel and p99 relative error of `frame`'s curved waves on a `grid × grid`
/// grid of pixels, against [`curve_reference`] on the same grid. Pixels whose reference energy
/// is below 1e-4 of the grid's largest are left out of the error percentile (their relative
/// error says nothing visible). The example curve scenes have no occluders, so rays run
/// unclipped.
pub fn curve_accuracy(frame: &Frame, reference: &[f64], grid: u32) -> (f64, f64) {
    let samples = sample_curve_energies(frame, None, grid);
    let evals = samples.iter().map(|s| s.1 as f64).sum::<f64>() / samples.len().max(1) as f64;
    let peak = reference.iter().copied().fold(0.0, f64::max);
    let mut errs: Vec<f64> = samples
        .iter()
        .zip(reference)
        .filter(|(_, &r)| r > 1e-4 * peak)
        .map(|((e, _, _), &r)| (*e as f64 - r).abs() / r)
        .collect();
    errs.sort_by(f64::total_cmp);
    let p99 = if errs.is_empty() { 0.0 } else { errs[((errs.len() - 1) as f64 * 0.99).round() as usize] };
    (evals, p99)
}

/// The converged f64 reference energy (adaptive quadrature, relative tolerance 1e-9) of
/// `frame`'s curved waves on a `grid × grid` grid of pixel centres: the cross-section field's, or
/// for a wave with [`Integrator::Nearest`](curve::Integrator::Nearest) the nearest-point field's
/// brute-force reference (relative tolerance 1e-7).
pub fn curve_reference(frame: &Frame, grid: u32) -> Vec<f64> {
    sample_curve_energies(frame, Some(1e-9), grid).into_iter().map(|s| s.2).collect()
}

/// Per sampled pixel: (f32 energy, evaluations, f64 reference energy if `reference_tol`).
fn sample_curve_energies(frame: &Frame, reference_tol: Option<f64>, grid: u32) -> Vec<(f32, u32, f64)> {
    use hadou_math::energy::{FieldParams, Ray};
    let basis = frame.camera.basis(frame.width, frame.height);
    let prepared: Vec<_> = frame
        .waves
        .iter()
        .filter_map(|w| match &w.shape {
            WaveShape::Curve(c) => Some((w, curve::prepare(c))),
            _ => None,
        })
        .collect();
    // Every pixel is independent and the references are slow (adaptive f64 quadrature; the
    // nearest-point field's brute force per node): spread them over the machine's threads, in
    // grid order.
    (0..grid * grid)
        .into_par_iter()
        .map(|i| {
            let (gx, gy) = (i % grid, i / grid);
            let px = ((gx as f32 + 0.5) * frame.width as f32 / grid as f32).floor();
            let py = ((gy as f32 + 0.5) * frame.height as f32 / grid as f32).floor();
            let (mut e, mut n, mut r) = (0.0f32, 0u32, 0.0f64);
            for (w, c) in &prepared {
                let wr = basis.wave_ray(w.falloff, frame.camera.far, px, py, frame.width, frame.height, None);
                let p = FieldParams { falloff: w.falloff, core_radius: w.core_radius };
                if let Some(tol) = reference_tol {
                    let p64 = FieldParams { falloff: w.falloff, core_radius: w.core_radius as f64 };
                    let ray = Ray { origin: wr.ray.origin.as_f64(), dir: wr.ray.dir.as_f64() };
                    let (t0, t1, tf) = (wr.t0 as f64, wr.t1 as f64, wr.t_far as f64);
                    r += if c.wave.integrator == curve::Integrator::Nearest {
                        // Brute force per node: a looser tolerance keeps the grid in minutes.
                        curve::nearest_energy_reference(c, &p64, &ray, t0, t1, tf, tol.max(1e-7))
                    } else {
                        curve::curve_energy_reference(c, &p64, &ray, t0, t1, tf, tol)
                    };
                } else {
                    let s = curve::curve_energy(c, &p, &wr.ray, wr.t0, wr.t1, wr.t_far);
                    e += s.energy;
                    n += s.evaluations;
                }
            }
            (e, n, r)
        })
        .collect()
}
