//! The kernel-limit table: how far hadou's render of the faithful bulged beam is from the
//! machine's limit, measured on the same machine at the same moment.

use super::analytic::analytic_frame;
use super::table::{Cell, Column, Report, Table};
use super::timing::{median_ms, time_cpu_on};
use hadou_math::energy::{lanes, FieldParams};
use hadou_math::simd::{dispatch, Lane, SimdPath, WithLanes};
use hadou_scene::{Frame, RenderError, WaveShape};

/// The faithful bulged beam of the analytic table at `size`, timed in one run: on each vector
/// path the CPU supports ([`SimdPath::supported`]) the whole render (to the 8-bit sRGB a PNG
/// holds), its wave pass and the eight-lane kernel alone over every pixel's ray; then the scalar
/// kernel alone and a plain scalar loop of the same maths ([`plain_beam_loop`]), so the distance
/// from hadou to the machine's limit is a ratio measured on the same machine at the same moment.
/// Its text gives each line's ratio to the plain loop; its JSON `rows` are `{what, path, ms,
/// mpix_per_s}` (`path` empty for the scalar lines), beside `size`, `iterations` and `paths`.
pub fn limit_table(size: u32, iterations: u32) -> Result<Report, RenderError> {
    use rayon::prelude::*;
    let frame = analytic_frame("bulged beam", "faithful", size, false)?;
    let Some(WaveShape::Beam(beam)) = frame.waves.first().map(|w| w.shape.clone()) else {
        return Err(RenderError::Other("the bench beam scene has no beam".into()));
    };
    let wave = &frame.waves[0];
    let p = FieldParams { falloff: wave.falloff, core_radius: wave.core_radius };
    let basis = frame.camera.basis(frame.width, frame.height);
    let (w, h, far) = (frame.width, frame.height, frame.camera.far);
    let ray = |x: u32, y: u32| basis.wave_ray(wave.falloff, far, x as f32, y as f32, w, h, None);
    let mut lines: Vec<(String, &'static str, f64)> = Vec::new();
    for path in SimdPath::supported() {
        let whole = time_cpu_on(&frame, iterations, path)?;
        let wave_ms = whole.parts.iter().find(|(n, _)| n == "wave").map_or(0.0, |p| p.1);
        let mut kernel = |f: &Frame| -> Result<(), RenderError> {
            let sum: f32 = (0..h)
                .into_par_iter()
                .map(|y| {
                    let rays: Vec<_> = (0..w).map(|x| ray(x, y)).collect();
                    dispatch(path, KernelRow { p: &p, beam: &beam, origin: f.camera.position, rays: &rays })
                })
                .sum();
            std::hint::black_box(sum);
            Ok(())
        };
        let lanes_ms = median_ms(&mut kernel, &frame, iterations)?;
        lines.push((format!("whole render ({path})"), path.name(), whole.ms));
        lines.push((format!("wave pass ({path})"), path.name(), wave_ms));
        lines.push((format!("kernel only, 8 lanes ({path})"), path.name(), lanes_ms));
    }
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
    lines.push(("kernel only, scalar".into(), "", scalar_ms));
    lines.push(("plain scalar loop".into(), "", plain_ms));
    let rows = lines
        .iter()
        .map(|(what, path, ms)| {
            let ms = *ms;
            let mpx = (size as f64).powi(2) / (ms * 1e3);
            let ratio = if ms > 0.0 { plain_ms / ms } else { 0.0 };
            vec![
                Cell::new("what", what.as_str(), what.as_str()),
                Cell::json("path", *path),
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
        Column::left("what", 34),
        Column::right("ms", 10),
        Column::right("Mpx/s", 10),
        Column::right("plain loop ×", 14),
    ];
    let names: Vec<&str> = SimdPath::supported().iter().map(|p| p.name()).collect();
    Ok(Report {
        fields: vec![
            ("size", size.into()),
            ("iterations", iterations.into()),
            ("paths", names.join(",").into()),
        ],
        tables: vec![Table { key: Some("rows"), title, columns, rows }],
    })
}

/// One row of rays through the beam kernel, eight at a time, on a path's lanes: the sum of the
/// energies (so nothing is optimised away).
struct KernelRow<'a> {
    p: &'a FieldParams<f32>,
    beam: &'a hadou_math::energy::BeamField<f32>,
    origin: hadou_math::Vec3f,
    rays: &'a [hadou_scene::WaveRay],
}

impl WithLanes for KernelRow<'_> {
    type Output = f32;
    #[inline(always)]
    fn run<L: Lane>(self) -> f32 {
        let mut acc = L::splat(0.0);
        for chunk in self.rays.chunks(lanes::LANES) {
            let at = |i: usize| chunk[i.min(chunk.len() - 1)];
            let batch = lanes::RayLanes {
                origin: self.origin,
                dir: lanes::V3::<L>::from_vecs(&std::array::from_fn(|i| at(i).ray.dir)),
                t0: L::from_array(std::array::from_fn(|i| at(i).t0)),
                t1: L::from_array(std::array::from_fn(|i| at(i).t1)),
            };
            acc += lanes::beam_energy(self.p, &batch, self.beam);
        }
        acc.reduce_add()
    }
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
