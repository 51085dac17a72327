//! The kernel-limit table: how far hadou's render of the faithful bulged beam is from the
//! machine's limit, measured on the same machine at the same moment.

use super::analytic::analytic_frame;
use super::table::{Cell, Column, Report, Table};
use super::timing::{median_ms, time_cpu};
use hadou_scene::{Frame, RenderError, WaveShape};

/// The faithful bulged beam of the analytic table at `size`, timed five ways in one run: the
/// whole render and its wave pass, the eight-lane kernel alone and the scalar kernel alone over
/// every pixel's ray, and a plain scalar loop of the same maths ([`plain_beam_loop`]), so the
/// distance from hadou to the machine's limit is a ratio measured on the same machine at the same
/// moment. Its text gives each line's ratio to the plain loop; its JSON `rows` are `{what, ms,
/// mpix_per_s}`, beside `size` and `iterations`.
pub fn limit_table(size: u32, iterations: u32) -> Result<Report, RenderError> {
    use hadou_math::energy::{lanes, FieldParams};
    use rayon::prelude::*;
    let frame = analytic_frame("bulged beam", "faithful", size, false)?;
    let Some(WaveShape::Beam(beam)) = frame.waves.first().map(|w| w.shape.clone()) else {
        return Err(RenderError::Other("the bench beam scene has no beam".into()));
    };
    let wave = &frame.waves[0];
    let p = FieldParams { falloff: wave.falloff, core_radius: wave.core_radius };
    let basis = frame.camera.basis(frame.width, frame.height);
    let (w, h, far) = (frame.width, frame.height, frame.camera.far);
    let whole = time_cpu(&frame, iterations)?;
    let wave_ms = whole.parts.iter().find(|(n, _)| n == "wave").map_or(0.0, |p| p.1);
    let ray = |x: u32, y: u32| basis.wave_ray(wave.falloff, far, x as f32, y as f32, w, h, None);
    let mut kernel = |f: &Frame| -> Result<(), RenderError> {
        let sum: f32 = (0..h)
            .into_par_iter()
            .map(|y| {
                let mut acc = lanes::Lanes::ZERO;
                for x0 in (0..w).step_by(lanes::LANES) {
                    let rays: [_; lanes::LANES] = std::array::from_fn(|i| ray(x0 + i as u32, y));
                    let batch = lanes::RayLanes {
                        origin: f.camera.position,
                        dir: lanes::V3::from_vecs(&rays.map(|r| r.ray.dir)),
                        t0: lanes::Lanes::from(rays.map(|r| r.t0)),
                        t1: lanes::Lanes::from(rays.map(|r| r.t1)),
                    };
                    acc += lanes::beam_energy(&p, &batch, &beam);
                }
                acc.reduce_add()
            })
            .sum();
        std::hint::black_box(sum);
        Ok(())
    };
    let lanes_ms = median_ms(&mut kernel, &frame, iterations)?;
    let mut scalar = |_: &Frame| -> Result<(), RenderError> {
        let sum: f32 = (0..h)
            .into_par_iter()
            .map(|y| {
                (0..w)
                    .map(|x| {
                        let r = ray(x, y);
                        hadou_math::energy::beam_energy(&p, &r.ray, r.t0, r.t1, &beam)
                    })
                    .sum::<f32>()
            })
            .sum();
        std::hint::black_box(sum);
        Ok(())
    };
    let scalar_ms = median_ms(&mut scalar, &frame, iterations)?;
    let mut plain = |f: &Frame| -> Result<(), RenderError> {
        std::hint::black_box(plain_beam_loop(f, &beam));
        Ok(())
    };
    let plain_ms = median_ms(&mut plain, &frame, iterations)?;
    let lines = [
        ("whole render (hadou)", whole.ms),
        ("wave pass (hadou)", wave_ms),
        ("kernel only, 8 lanes", lanes_ms),
        ("kernel only, scalar", scalar_ms),
        ("plain scalar loop", plain_ms),
    ];
    let rows = lines
        .iter()
        .map(|&(what, ms)| {
            let mpx = (size as f64).powi(2) / (ms * 1e3);
            let ratio = if ms > 0.0 { plain_ms / ms } else { 0.0 };
            vec![
                Cell::new("what", what, what),
                Cell::new("ms", ms, format!("{ms:.2}")),
                Cell::new("mpix_per_s", mpx, format!("{mpx:.1}")),
                Cell::text("ratio", format!("{ratio:.2}×")),
            ]
        })
        .collect();
    let title = format!(
        "\nbulged beam (faithful) at {size}², kernel at its limit ({iterations} runs, median, one run)\n"
    );
    let columns = vec![
        Column::left("what", 26),
        Column::right("ms", 10),
        Column::right("Mpx/s", 10),
        Column::right("plain loop ×", 14),
    ];
    Ok(Report {
        fields: vec![("size", size.into()), ("iterations", iterations.into())],
        tables: vec![Table { key: Some("rows"), title, columns, rows }],
    })
}

/// A plain, unoptimised scalar `f32` render of a faithful bulged beam, for comparison only: per
/// pixel the ray `Q = E − S` over `[0, 1]`, the capsule split at its two planes plus the head and
/// muzzle spheres over the whole ray, each piece `∫ dt/√(Y² + H) = ln(P₁/P₀)/s` with one
/// logarithm (002 eq. 3.8–3.11 with SPEC.md §1.2's `asinh`; `P = Y + √(Y² + H)`, mirrored where
/// `Y < 0`), rayon over rows, `1 − e^(−x)` colour. Returns the colours.
pub fn plain_beam_loop(frame: &Frame, beam: &hadou_math::energy::BeamField<f32>) -> Vec<[f32; 3]> {
    use hadou_math::Vec3f;
    use rayon::prelude::*;
    let basis = frame.camera.basis(frame.width, frame.height);
    let (w, h, far) = (frame.width, frame.height, frame.camera.far);
    let rc2 = frame.waves.first().map_or(0.0, |w| w.core_radius * w.core_radius);
    let c = &beam.capsule;
    // ∫_{t0}^{t1} dt/√((s·t + β)² + H) for |v + t·u|² + r_c², with one logarithm.
    let piece = |u: Vec3f, v: Vec3f, t0: f32, t1: f32| -> f32 {
        let s = u.length();
        if t1 <= t0 || s < 1e-20 {
            return if t1 > t0 { (t1 - t0) / (v.length_squared() + rc2).max(1e-24).sqrt() } else { 0.0 };
        }
        let un = u / s;
        let beta = un.dot(v);
        let hh = (un.cross(v).length_squared() + rc2).max(1e-24);
        let (y0, y1) = (s * t0 + beta, s * t1 + beta);
        let p = |y: f32| if y >= 0.0 { y + (y * y + hh).sqrt() } else { hh / ((y * y + hh).sqrt() - y) };
        (p(y1) / p(y0)).ln() / s
    };
    let mut out = vec![[0.0f32; 3]; (w * h) as usize];
    out.par_chunks_mut(w as usize).enumerate().for_each(|(y, row)| {
        for (x, px) in row.iter_mut().enumerate() {
            let q = basis.pixel_dir(x as f32, y as f32, w, h) * far;
            let s0 = basis.eye - c.m;
            let s2 = s0 - c.d * c.length;
            let (dq, ds) = (q.dot(c.d), s0.dot(c.d));
            let (mut lo, mut hi) =
                if dq.abs() > 1e-20 { (-ds / dq, (c.length - ds) / dq) } else { (0.0, 1.0) };
            let (first, last) = if dq >= 0.0 { (s0, s2) } else { (s2, s0) };
            if dq < 0.0 {
                std::mem::swap(&mut lo, &mut hi);
            }
            let (lo, hi) = (lo.clamp(0.0, 1.0), hi.clamp(0.0, 1.0).max(lo.clamp(0.0, 1.0)));
            let spheres = piece(q, first, 0.0, lo) + piece(q, last, hi, 1.0);
            let cyl = piece(q.cross(c.d), s0.cross(c.d), lo, hi);
            let e = c.alpha_s * spheres
                + c.alpha_c * cyl
                + beam.head_alpha * piece(q, s2, 0.0, 1.0)
                + beam.muzzle_alpha * piece(q, s0, 0.0, 1.0);
            let [r, g, b, a] = frame.waves[0].color;
            *px = [r, g, b].map(|k| 1.0 - (-(k * a * e)).exp());
        }
    });
    out
}
