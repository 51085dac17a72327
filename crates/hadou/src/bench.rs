//! `hadou bench`: rendering speed in the layout of the thesis's tables (002 §4, SPEC.md §1.5).
//!
//! The scenes are built from scene-file text, so the bench measures exactly what users render.

use hadou_math::curve::{self, Integrator, Reduction};
use hadou_scene::{AreaLight, Frame, RenderError, Scene, WaveShape};
use std::path::Path;

/// One measured cell.
#[derive(Clone, Debug)]
pub struct Cell {
    /// Image side in pixels (square images).
    pub size: u32,
    /// Whether the occluding cubes were in the scene.
    pub occlusion: bool,
    /// Median time per frame in milliseconds.
    pub ms: f64,
    /// The frame's parts (pass name, median milliseconds), see [`Timing::parts`].
    pub parts: Vec<(String, f64)>,
}

impl Cell {
    /// Frames per second.
    pub fn fps(&self) -> f64 {
        1e3 / self.ms
    }
    /// Megapixels per second.
    pub fn mpix_per_s(&self) -> f64 {
        (self.size as f64).powi(2) / (self.ms * 1e3)
    }
}

/// One row: a shape and falloff, its cells.
#[derive(Clone, Debug)]
pub struct Row {
    /// Shape label (`sphere`, `capsule`, …).
    pub shape: String,
    /// Falloff label.
    pub falloff: String,
    /// The cells: each size without occlusion, then the largest size with occlusion.
    pub cells: Vec<Cell>,
}

/// The analytic table.
#[derive(Clone, Debug)]
pub struct Table {
    /// Backend name.
    pub backend: String,
    /// How time was measured.
    pub method: String,
    /// Repetitions per cell.
    pub iterations: u32,
    /// Rows.
    pub rows: Vec<Row>,
}

/// The shapes of the analytic table: the thesis's three rows plus the bulged beam.
pub const ANALYTIC_SHAPES: [&str; 4] = ["sphere", "capsule", "sphere+capsule", "bulged beam"];

/// Scene text for one shape of the analytic table, with or without the two occluding cubes of
/// 002 Fig. 4.14.
pub fn analytic_scene(shape: &str, falloff: &str, size: u32, occlusion: bool) -> String {
    let (alpha, core) = if falloff == "faithful" { (20.0, 0.01) } else { (2.0, 0.05) };
    let mut s = format!(
        r#"[image]
width = {size}
height = {size}

[camera]
position = [0.0, 6.0, 40.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 45.0
near = 0.1
far = 100.0

[color]
mode = "filmic"
"#
    );
    let wave = |kind: &str, extra: &str| {
        format!(
            "\n[[wave]]\nname = \"{kind}\"\nkind = \"{kind}\"\nfalloff = \"{falloff}\"\ncore_radius = {core}\n\
             rgba = [0.8, 0.8, 0.2, 1.0]\n{extra}"
        )
    };
    let capsule =
        format!("M = [-10.0, 0.0, 0.0]\nM2 = [10.0, 0.0, 0.0]\nalpha_s = {alpha}\nalpha_c = {alpha}\n");
    match shape {
        "sphere" => s += &wave("sphere", &format!("M = [0.0, 0.0, 0.0]\nalpha_s = {alpha}\n")),
        "capsule" => s += &wave("capsule", &capsule),
        "sphere+capsule" => {
            s += &wave("capsule", &capsule);
            s += &wave("sphere", &format!("M = [10.0, 0.0, 0.0]\nalpha_s = {}\n", alpha * 2.0));
        }
        _ => {
            s += &wave(
                "beam",
                &format!("{capsule}head_alpha = {}\nmuzzle_alpha = {}\n", alpha * 2.0, alpha * 0.5),
            )
        }
    }
    if occlusion {
        s += r#"
[[object]]
name = "cube-behind"
kind = "box"
size = [8.0, 8.0, 8.0]
position = [0.0, 0.0, -20.0]

[[object]]
name = "cube-front"
kind = "box"
size = [8.0, 8.0, 8.0]
position = [10.0, 0.0, 10.0]
"#;
    }
    s
}

/// Builds the frame for one cell.
pub fn analytic_frame(shape: &str, falloff: &str, size: u32, occlusion: bool) -> Result<Frame, RenderError> {
    let text = analytic_scene(shape, falloff, size, occlusion);
    let scene = Scene::parse(&text, Path::new("<bench>"))
        .map_err(|e| RenderError::Other(format!("bench scene is invalid: {e}")))?;
    Ok(scene.at(0.0))
}

/// What a [`Timer`] measured for one frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Timing {
    /// Median milliseconds per frame: the whole render, without writing the output.
    pub ms: f64,
    /// The parts, in order, as (name, median milliseconds): on the CPU the opaque pass, the wave
    /// pass and the colour mapping (which add up to the whole) and the output (8-bit sRGB and
    /// PNG encoding into memory, after the render); on the GPU each pass's GPU timestamps where
    /// the adapter has them, and the output. Empty where nothing finer was measured.
    pub parts: Vec<(String, f64)>,
}

impl Timing {
    /// A timing with no parts.
    pub fn whole(ms: f64) -> Self {
        Self { ms, parts: Vec::new() }
    }
}

/// A timer: renders `frame` once untimed, then `iterations` timed times, and returns the medians.
pub type Timer<'a> = dyn FnMut(&Frame, u32) -> Result<Timing, RenderError> + 'a;

/// The median of `v` (0 when empty).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(0.0)
}

/// Times the CPU backend: `iterations` frames after a warm-up, drawn as a real-time loop draws
/// them (one [`hadou_cpu::CpuBackend`] and one image reused from frame to frame), each split into
/// its passes ([`hadou_cpu::CpuBackend::render_into`]), then the output of the image (sRGB and
/// PNG encoding into memory) as many times. Medians of each.
pub fn time_cpu(frame: &Frame, iterations: u32) -> Result<Timing, RenderError> {
    let mut cpu = hadou_cpu::CpuBackend::new();
    let mut image = hadou_scene::Image::new(0, 0);
    cpu.render_into(frame, &mut image);
    let (mut whole, mut opaque, mut wave, mut color, mut output) = (vec![], vec![], vec![], vec![], vec![]);
    for _ in 0..iterations.max(1) {
        let t = std::time::Instant::now();
        let p = cpu.render_into(frame, &mut image);
        whole.push(t.elapsed().as_secs_f64() * 1e3);
        opaque.push(p.opaque_ms);
        wave.push(p.wave_ms);
        color.push(p.color_ms);
    }
    for _ in 0..iterations.max(1) {
        output.push(output_ms(&image)?);
    }
    Ok(Timing {
        ms: median(whole),
        parts: vec![
            ("opaque".into(), median(opaque)),
            ("wave".into(), median(wave)),
            ("colour".into(), median(color)),
            ("output".into(), median(output)),
        ],
    })
}

/// Milliseconds to turn `image` into PNG bytes in memory, as `hadou render` does before writing.
pub fn output_ms(image: &hadou_scene::Image) -> Result<f64, RenderError> {
    let t = std::time::Instant::now();
    let bytes = crate::output::encode_png(image).map_err(RenderError::Other)?;
    let ms = t.elapsed().as_secs_f64() * 1e3;
    std::hint::black_box(bytes);
    Ok(ms)
}

/// Measures the analytic table: for each shape and falloff, each size, plus occlusion at the
/// largest size.
pub fn analytic_table(
    time: &mut Timer<'_>,
    sizes: &[u32],
    iterations: u32,
    backend: &str,
    method: &str,
) -> Result<Table, RenderError> {
    let mut rows = Vec::new();
    let largest = sizes.iter().copied().max().unwrap_or(512);
    for falloff in ["faithful", "inverse-square"] {
        for shape in ANALYTIC_SHAPES {
            let mut cells = Vec::new();
            let mut cases: Vec<(u32, bool)> = sizes.iter().map(|&s| (s, false)).collect();
            cases.push((largest, true));
            for (size, occlusion) in cases {
                let frame = analytic_frame(shape, falloff, size, occlusion)?;
                let t = time(&frame, iterations)?;
                cells.push(Cell { size, occlusion, ms: t.ms, parts: t.parts });
            }
            rows.push(Row { shape: shape.into(), falloff: falloff.into(), cells });
        }
    }
    Ok(Table { backend: backend.into(), method: method.into(), iterations, rows })
}

/// Median wall-clock milliseconds of `iterations` calls of `render` after one warm-up.
pub fn median_ms(
    render: &mut dyn FnMut(&Frame) -> Result<(), RenderError>,
    frame: &Frame,
    iterations: u32,
) -> Result<f64, RenderError> {
    render(frame)?;
    let mut v = Vec::with_capacity(iterations as usize);
    for _ in 0..iterations.max(1) {
        let t = std::time::Instant::now();
        render(frame)?;
        v.push(t.elapsed().as_secs_f64() * 1e3);
    }
    Ok(median(v))
}

impl Table {
    /// The table as plain text: fps and Mpixel/s per cell.
    pub fn to_text(&self) -> String {
        let mut out = format!(
            "analytic shapes — backend {}, {} ({} runs, median)\n",
            self.backend, self.method, self.iterations
        );
        if let Some(r) = self.rows.first() {
            out += &format!("{:<16} {:<15}", "shape", "falloff");
            for c in &r.cells {
                let label = if c.occlusion { format!("occl. {}²", c.size) } else { format!("{}²", c.size) };
                out += &format!(" {:>22}", label);
            }
            out += "\n";
        }
        for r in &self.rows {
            out += &format!("{:<16} {:<15}", r.shape, r.falloff);
            for c in &r.cells {
                out += &format!(" {:>22}", format!("{:.1} fps {:.1} Mpx/s", c.fps(), c.mpix_per_s()));
            }
            out += "\n";
        }
        out += &self.parts_text();
        out
    }

    /// Where the time goes: per row, the largest size without occlusion split into its parts.
    fn parts_text(&self) -> String {
        let cell = |r: &Row| r.cells.iter().filter(|c| !c.occlusion).max_by_key(|c| c.size).cloned();
        let Some(first) = self.rows.first().and_then(cell) else { return String::new() };
        if first.parts.is_empty() {
            return String::new();
        }
        let mut out =
            format!("\nwhere the time goes at {}² (median ms, share of the whole render)\n", first.size);
        out += &format!("{:<16} {:<15} {:>9}", "shape", "falloff", "whole");
        for (name, _) in &first.parts {
            out += &format!(" {:>16}", name);
        }
        out += "\n";
        for r in &self.rows {
            let Some(c) = cell(r) else { continue };
            out += &format!("{:<16} {:<15} {:>9.2}", r.shape, r.falloff, c.ms);
            for (_, ms) in &c.parts {
                let share = if c.ms > 0.0 { 100.0 * ms / c.ms } else { 0.0 };
                out += &format!(" {:>16}", format!("{ms:.2} ({share:.0}%)"));
            }
            out += "\n";
        }
        out
    }

    /// The table as JSON.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "table": "analytic",
            "backend": self.backend,
            "method": self.method,
            "iterations": self.iterations,
            "rows": self.rows.iter().map(|r| serde_json::json!({
                "shape": r.shape,
                "falloff": r.falloff,
                "cells": r.cells.iter().map(|c| serde_json::json!({
                    "size": c.size,
                    "occlusion": c.occlusion,
                    "ms": c.ms,
                    "fps": c.fps(),
                    "mpix_per_s": c.mpix_per_s(),
                    "parts": c.parts.iter().map(|(name, ms)| serde_json::json!({"name": name, "ms": ms}))
                        .collect::<Vec<_>>(),
                })).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
        })
    }
}

/// The curve shapes of the curve table and the example scene each is taken from (002 Fig. 4.2).
pub const CURVE_SCENES: [(&str, &str); 4] = [
    ("helix", "fig4-2-helix.toml"),
    ("trig sum", "fig4-2-trig.toml"),
    ("Bézier deg 4", "fig4-2-bezier.toml"),
    ("B-spline", "fig4-2-bspline.toml"),
];

/// The integrators of the curve table: the thesis's Simpson at m = 100, 300, 500 without
/// reduction and with reduction n = 2, 4 (ε = 0.25), then hadou's default.
pub fn curve_integrators() -> Vec<(String, Integrator)> {
    let mut v = Vec::new();
    for m in [100, 300, 500] {
        v.push((format!("simpson m={m}"), Integrator::Simpson { m, reduction: None }));
        for n in [2, 4] {
            let reduction = Some(Reduction { n, epsilon: 0.25 });
            v.push((format!("simpson m={m} n={n}"), Integrator::Simpson { m, reduction }));
        }
    }
    v.push(("default".into(), Integrator::Default));
    v
}

/// One row of the curve table.
#[derive(Clone, Debug)]
pub struct CurveRow {
    /// Shape label.
    pub shape: String,
    /// Integrator label.
    pub integrator: String,
    /// Median milliseconds per frame, per size.
    pub ms: Vec<(u32, f64)>,
    /// Mean integrand evaluations per sampled pixel.
    pub evals_per_pixel: f64,
    /// 99th-percentile relative energy error of sampled pixels against the converged reference.
    pub p99_error: f64,
}

/// The curve table (SPEC.md §1.5's second table with evaluation and error columns).
#[derive(Clone, Debug)]
pub struct CurveTable {
    /// Backend name.
    pub backend: String,
    /// How time was measured.
    pub method: String,
    /// Rows.
    pub rows: Vec<CurveRow>,
    /// Default against Simpson `m = 500` on every example curve scene.
    pub acceptance: Vec<AcceptanceRow>,
}

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
/// `frame`'s curved waves on a `grid × grid` grid of pixel centres.
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
    let mut out = Vec::with_capacity((grid * grid) as usize);
    for gy in 0..grid {
        for gx in 0..grid {
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
                    r += curve::curve_energy_reference(c, &p64, &ray, t0, t1, tf, tol);
                } else {
                    let s = curve::curve_energy(c, &p, &wr.ray, wr.t0, wr.t1, wr.t_far);
                    e += s.energy;
                    n += s.evaluations;
                }
            }
            out.push((e, n, r));
        }
    }
    out
}

/// Measures the curve table on the example curve scenes found in `scenes_dir`.
pub fn curve_table(
    time: &mut Timer<'_>,
    scenes_dir: &Path,
    sizes: &[u32],
    iterations: u32,
    backend: &str,
    method: &str,
    progress: &mut dyn FnMut(&str),
) -> Result<CurveTable, RenderError> {
    let mut rows = Vec::new();
    for (shape, file) in CURVE_SCENES {
        let path = scenes_dir.join(file);
        let scene = Scene::load(&path)
            .map_err(|e| RenderError::Other(format!("curve bench needs the example scenes: {e}")))?;
        let base = scene.at(0.0);
        let reference = curve_reference(&base, ACCURACY_GRID);
        for (label, integrator) in curve_integrators() {
            progress(&format!("{shape}: {label}"));
            let frame = with_integrator(&base, integrator);
            let (evals_per_pixel, p99_error) = curve_accuracy(&frame, &reference, ACCURACY_GRID);
            let mut ms = Vec::new();
            for &size in sizes {
                let mut f = frame.clone();
                f.width = size;
                f.height = size;
                ms.push((size, time(&f, iterations)?.ms));
            }
            rows.push(CurveRow { shape: shape.into(), integrator: label, ms, evals_per_pixel, p99_error });
        }
    }
    let mut acceptance = Vec::new();
    for &(label, file, t) in &ACCEPTANCE_SCENES {
        progress(&format!("acceptance: {label}"));
        let scene = Scene::load(scenes_dir.join(file))
            .map_err(|e| RenderError::Other(format!("curve bench needs the example scenes: {e}")))?;
        let base = scene.at(t);
        let reference = curve_reference(&base, ACCURACY_GRID);
        let simpson = with_integrator(&base, Integrator::Simpson { m: 500, reduction: None });
        let default = with_integrator(&base, Integrator::Default);
        let (simpson_evals, simpson_p99) = curve_accuracy(&simpson, &reference, ACCURACY_GRID);
        let (default_evals, default_p99) = curve_accuracy(&default, &reference, ACCURACY_GRID);
        let simpson_ms = time(&simpson, iterations)?.ms;
        let default_ms = time(&default, iterations)?.ms;
        acceptance.push(AcceptanceRow {
            scene: label.into(),
            size: (base.width, base.height),
            simpson_ms,
            default_ms,
            simpson_evals,
            default_evals,
            simpson_p99,
            default_p99,
        });
    }
    Ok(CurveTable { backend: backend.into(), method: method.into(), rows, acceptance })
}

/// Every example scene with curved waves, at the times its animation shows something new: the
/// scenes on which the default integrator's bars are stated (label, file, time in seconds).
pub const ACCEPTANCE_SCENES: [(&str, &str, f32); 11] = [
    ("Fig. 4.2 helix", "fig4-2-helix.toml", 0.0),
    ("Fig. 4.2 trig sum", "fig4-2-trig.toml", 0.0),
    ("Fig. 4.2 Bézier", "fig4-2-bezier.toml", 0.0),
    ("Fig. 4.2 B-spline", "fig4-2-bspline.toml", 0.0),
    ("Fig. 4.9 two curves", "fig4-9-two-curves.toml", 0.0),
    ("Fig. 4.10 j=0.5", "fig4-10-attenuation.toml", 1.0),
    ("Fig. 4.10 j=2", "fig4-10-attenuation.toml", 3.0),
    ("Fig. 4.10 j=6", "fig4-10-attenuation.toml", 5.0),
    ("Fig. 4.13 k=0.1", "fig4-13-extension.toml", 0.0),
    ("Fig. 4.13 k=0.8", "fig4-13-extension.toml", 2.0),
    ("spiral drill", "spiral-drill.toml", 1.8),
];

/// One example scene: faithful Simpson `m = 500` against the default integrator, both measured
/// in the same run.
#[derive(Clone, Debug)]
pub struct AcceptanceRow {
    /// Scene label.
    pub scene: String,
    /// The scene's own image size.
    pub size: (u32, u32),
    /// Median ms per frame, Simpson `m = 500`.
    pub simpson_ms: f64,
    /// Median ms per frame, default integrator.
    pub default_ms: f64,
    /// Curve evaluations per pixel, Simpson.
    pub simpson_evals: f64,
    /// Curve evaluations per pixel, default.
    pub default_evals: f64,
    /// 99th-percentile relative error, Simpson.
    pub simpson_p99: f64,
    /// 99th-percentile relative error, default.
    pub default_p99: f64,
}

impl AcceptanceRow {
    /// How many times fewer evaluations the default takes.
    pub fn eval_ratio(&self) -> f64 {
        self.simpson_evals / self.default_evals.max(1e-9)
    }
    /// How many times less time the default takes.
    pub fn time_ratio(&self) -> f64 {
        self.simpson_ms / self.default_ms.max(1e-9)
    }
    /// The bars: p99 ≤ 0.5 %, ≥ 10× fewer evaluations, ≥ 5× less time, Simpson further off.
    pub fn meets_bars(&self) -> bool {
        self.default_p99 <= 5e-3
            && self.eval_ratio() >= 10.0
            && self.time_ratio() >= 5.0
            && self.simpson_p99 > self.default_p99
    }
}

impl CurveTable {
    /// The table as plain text.
    pub fn to_text(&self) -> String {
        let mut out = format!(
            "curves — backend {}, {}; evals/pixel and p99 error on a 64×64 pixel grid vs f64 adaptive reference\n",
            self.backend, self.method
        );
        if let Some(r) = self.rows.first() {
            out += &format!("{:<14} {:<20}", "shape", "integrator");
            for (s, _) in &r.ms {
                out += &format!(" {:>18}", format!("{s}² ms (fps)"));
            }
            out += &format!(" {:>12} {:>10}\n", "evals/pixel", "p99 error");
        }
        for r in &self.rows {
            out += &format!("{:<14} {:<20}", r.shape, r.integrator);
            for (_, ms) in &r.ms {
                out += &format!(" {:>18}", format!("{ms:.1} ({:.2})", 1e3 / ms));
            }
            out += &format!(" {:>12.1} {:>10.2e}\n", r.evals_per_pixel, r.p99_error);
        }
        if !self.acceptance.is_empty() {
            out += "\nexample scenes at their own size: default integrator against faithful Simpson m=500\n";
            out += &format!(
                "{:<20} {:>9} {:>19} {:>19} {:>8} {:>8} {:>10} {:>10}  {}\n",
                "scene",
                "size",
                "ms Simpson/default",
                "evals Simp./def.",
                "evals ×",
                "time ×",
                "p99 Simp.",
                "p99 def.",
                "bars"
            );
            for a in &self.acceptance {
                out += &format!(
                    "{:<20} {:>9} {:>19} {:>19} {:>8.1} {:>8.1} {:>10.2e} {:>10.2e}  {}\n",
                    a.scene,
                    format!("{}×{}", a.size.0, a.size.1),
                    format!("{:.1}/{:.1}", a.simpson_ms, a.default_ms),
                    format!("{:.1}/{:.1}", a.simpson_evals, a.default_evals),
                    a.eval_ratio(),
                    a.time_ratio(),
                    a.simpson_p99,
                    a.default_p99,
                    if a.meets_bars() { "met" } else { "NOT met" }
                );
            }
        }
        out
    }

    /// The table as JSON.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "table": "curves",
            "backend": self.backend,
            "method": self.method,
            "rows": self.rows.iter().map(|r| serde_json::json!({
                "shape": r.shape,
                "integrator": r.integrator,
                "ms": r.ms.iter().map(|(s, ms)| serde_json::json!({"size": s, "ms": ms, "fps": 1e3 / ms}))
                    .collect::<Vec<_>>(),
                "evals_per_pixel": r.evals_per_pixel,
                "p99_error": r.p99_error,
            })).collect::<Vec<_>>(),
            "acceptance": self.acceptance.iter().map(|a| serde_json::json!({
                "scene": a.scene,
                "width": a.size.0,
                "height": a.size.1,
                "simpson_m500_ms": a.simpson_ms,
                "default_ms": a.default_ms,
                "simpson_m500_evals_per_pixel": a.simpson_evals,
                "default_evals_per_pixel": a.default_evals,
                "simpson_m500_p99_error": a.simpson_p99,
                "default_p99_error": a.default_p99,
                "eval_ratio": a.eval_ratio(),
                "time_ratio": a.time_ratio(),
                "meets_bars": a.meets_bars(),
            })).collect::<Vec<_>>(),
        })
    }
}

/// The scene and time `hadou bench toon` renders: a toon character with textures, a feature
/// texture and outlines, two outlined props and a toon ground, lit by a firing beam.
pub const TOON_SCENE: (&str, f32) = ("light-from-front.toml", 1.2);

/// The scene and time whose shadows `hadou bench toon` times on and off: sun shadows by shadow map
/// (2048²) and by plane projection, and a wave shadow by shadow map, over toon materials.
pub const SHADOW_SCENE: (&str, f32) = ("shadow-uneven.toml", 1.0);

/// One row of the toon table.
#[derive(Clone, Debug)]
pub struct ToonRow {
    /// Image side in pixels.
    pub size: u32,
    /// For [`TOON_SCENE`]: `full` (the scene as written) or `plain` (every material diffuse, no
    /// wave light, no outlines, no textures: the opaque pass hadou had before materials). For
    /// [`SHADOW_SCENE`]: `shadows` (as written) or `no-shadows` (its `[[shadow]]`s removed).
    pub variant: &'static str,
    /// The scene file.
    pub scene: &'static str,
    /// Median milliseconds per frame.
    pub ms: f64,
}

/// The toon table.
#[derive(Clone, Debug)]
pub struct ToonTable {
    /// Backend name.
    pub backend: String,
    /// How time was measured.
    pub method: String,
    /// Repetitions per cell.
    pub iterations: u32,
    /// The scene file.
    pub scene: String,
    /// Rows, by size then variant.
    pub rows: Vec<ToonRow>,
}

/// `frame` with every material reduced to plain diffuse shading of its base colour.
pub fn plain_materials(frame: &Frame) -> Frame {
    let mut f = frame.clone();
    for o in &mut f.objects {
        for m in &mut o.materials {
            *m = hadou_scene::Material::diffuse(m.base_color);
        }
    }
    for w in &mut f.waves {
        w.light.glow = 0.0;
    }
    f
}

/// Measures the toon table: [`TOON_SCENE`] at each size, full and plain, in one run.
pub fn toon_table(
    time: &mut Timer<'_>,
    scenes: &Path,
    sizes: &[u32],
    iterations: u32,
    backend: &str,
    method: &str,
) -> Result<ToonTable, RenderError> {
    let (file, t) = TOON_SCENE;
    let scene = Scene::load(scenes.join(file)).map_err(|e| RenderError::Other(e.to_string()))?;
    let mut rows = Vec::new();
    for &size in sizes {
        let mut frame = scene.at(t);
        frame.width = size;
        frame.height = size;
        let plain = plain_materials(&frame);
        for (variant, f) in [("full", &frame), ("plain", &plain)] {
            rows.push(ToonRow { size, variant, scene: file, ms: time(f, iterations)?.ms });
        }
    }
    let (shadow_file, st) = SHADOW_SCENE;
    let shadow_scene =
        Scene::load(scenes.join(shadow_file)).map_err(|e| RenderError::Other(e.to_string()))?;
    for &size in sizes {
        let mut frame = shadow_scene.at(st);
        frame.width = size;
        frame.height = size;
        let bare = Frame { shadows: Vec::new(), ..frame.clone() };
        for (variant, f) in [("shadows", &frame), ("no-shadows", &bare)] {
            rows.push(ToonRow { size, variant, scene: shadow_file, ms: time(f, iterations)?.ms });
        }
    }
    Ok(ToonTable { backend: backend.into(), method: method.into(), iterations, scene: file.into(), rows })
}

impl ToonTable {
    /// The table as plain text.
    pub fn to_text(&self) -> String {
        let mut out = format!(
            "toon scene {} — backend {}, {} ({} runs, median)\n{:<8} {:>12} {:>10} {:>14} {:>10}\n",
            self.scene,
            self.backend,
            self.method,
            self.iterations,
            "size",
            "full ms",
            "full fps",
            "plain ms",
            "ratio"
        );
        let (toon, shadows): (Vec<&ToonRow>, Vec<&ToonRow>) =
            self.rows.iter().partition(|r| r.variant == "full" || r.variant == "plain");
        for pair in toon.chunks(2) {
            if let [full, plain] = pair {
                out += &format!(
                    "{:<8} {:>12.2} {:>10.1} {:>14.2} {:>9.2}×\n",
                    format!("{}²", full.size),
                    full.ms,
                    1e3 / full.ms,
                    plain.ms,
                    full.ms / plain.ms
                );
            }
        }
        if !shadows.is_empty() {
            out += &format!(
                "\nshadow scene {}\n{:<8} {:>12} {:>10} {:>14} {:>10}\n",
                SHADOW_SCENE.0, "size", "shadows ms", "fps", "no-shadows ms", "ratio"
            );
            for pair in shadows.chunks(2) {
                if let [on, off] = pair {
                    out += &format!(
                        "{:<8} {:>12.2} {:>10.1} {:>14.2} {:>9.2}×\n",
                        format!("{}²", on.size),
                        on.ms,
                        1e3 / on.ms,
                        off.ms,
                        on.ms / off.ms
                    );
                }
            }
        }
        out
    }

    /// The table as JSON: `rows` of `{scene, size, variant, ms, fps}`.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "table": "toon",
            "scene": self.scene,
            "backend": self.backend,
            "method": self.method,
            "iterations": self.iterations,
            "rows": self.rows.iter().map(|r| serde_json::json!({
                "scene": r.scene,
                "size": r.size,
                "variant": r.variant,
                "ms": r.ms,
                "fps": 1e3 / r.ms,
            })).collect::<Vec<_>>(),
        })
    }
}

/// The scene of the soft-shadow table and the time it is taken at: 003's penumbra close-up (a
/// pillar on a floor under a lamp-sized light).
pub const SOFT_SCENE: (&str, f32) = ("soft-gradient.toml", 0.0);
/// Points of the true disc light in the ground truth (each its own shadow map).
pub const TRUTH_SAMPLES: u32 = 128;
/// Largest shadow-map edge of the ground truth's maps (four map texels per image pixel, at least
/// 256, at most this).
pub const TRUTH_MAP: u32 = 2048;

/// The ground truth's map edge for an image of `size²`.
pub fn truth_map(size: u32) -> u32 {
    (4 * size).clamp(256, TRUTH_MAP)
}

/// The methods of the soft-shadow table, in order: 003's faithful resolve at N = 1, 3, 5, 10 (with
/// 003's linear brightness), hadou's exact resolve with 003's linear brightness (`exact-linear`:
/// faithful N = 1's picture) and with its default segment brightness (`exact`), and PCSS.
pub const SOFT_METHODS: [&str; 7] =
    ["faithful-n1", "faithful-n3", "faithful-n5", "faithful-n10", "exact-linear", "exact", "pcss"];

/// One row of the soft-shadow table.
#[derive(Clone, Debug)]
pub struct SoftRow {
    /// One of [`SOFT_METHODS`], or `frame` (the whole render with the scene's own resolve, by the
    /// bench's backend) and `frame-unlit` (the same without the area light).
    pub method: String,
    /// Image side in pixels.
    pub size: u32,
    /// Median milliseconds: the soft-shadow stage (its maps, the classes and the resolve, on the
    /// CPU) for the methods; the whole frame for the `frame` rows.
    pub ms: f64,
    /// Mean per-pixel visibility difference from the ground truth over the shadow-edge pixels
    /// (`None` for the `frame` rows).
    pub mean_error: Option<f64>,
    /// 99th percentile of the same.
    pub p99_error: Option<f64>,
}

/// The soft-shadow table.
#[derive(Clone, Debug)]
pub struct SoftTable {
    /// The scene file.
    pub scene: String,
    /// Repetitions per timed cell.
    pub iterations: u32,
    /// The true disc light's radius (world units).
    pub disc_radius: f32,
    /// Backend of the `frame` rows.
    pub backend: String,
    /// Rows, by size then method.
    pub rows: Vec<SoftRow>,
}

pub use hadou_cpu::soft::{disc_radius as soft_disc_radius, edge_errors as soft_errors};

/// Measures the soft-shadow table: [`SOFT_SCENE`] at each size, every method's soft-shadow stage
/// on the CPU against the ground truth ([`hadou_cpu::soft::truth`], a disc of radius
/// `disc_radius`, by default [`soft_disc_radius`]), then the whole frame by `time` with and
/// without the area light, all in one run. `progress` hears what is being done.
pub fn soft_table(
    time: &mut Timer<'_>,
    scenes: &Path,
    sizes: &[u32],
    iterations: u32,
    backend: &str,
    disc_radius: Option<f32>,
    progress: &mut dyn FnMut(&str),
) -> Result<SoftTable, RenderError> {
    use hadou_cpu::soft;
    use hadou_scene::{Penumbra, SoftResolve};
    let (file, t) = SOFT_SCENE;
    let scene = Scene::load(scenes.join(file)).map_err(|e| RenderError::Other(e.to_string()))?;
    let mut rows = Vec::new();
    let mut used_radius = 0.0;
    for &size in sizes {
        let mut frame = scene.at(t);
        frame.width = size;
        frame.height = size;
        let light = frame
            .area_light
            .clone()
            .ok_or_else(|| RenderError::Other(format!("{file} has no [area_light]")))?;
        let radius = disc_radius.or_else(|| soft_disc_radius(&frame)).unwrap_or(light.size);
        used_radius = radius;
        progress(&format!("{size}²: visible points"));
        let input = soft::soft_input(&frame).ok_or_else(|| RenderError::Other("no area light".into()))?;
        let tm = truth_map(size);
        progress(&format!("{size}²: ground truth ({TRUTH_SAMPLES} shadow maps of {tm}²)"));
        let truth = soft::truth(&frame, &light, &input, radius, TRUTH_SAMPLES, tm);
        let visible: Vec<bool> = input.points.iter().map(Option::is_some).collect();
        for method in SOFT_METHODS {
            progress(&format!("{size}²: {method}"));
            let resolve = match method {
                "exact" => Some((SoftResolve::Exact, Penumbra::Segment)),
                "exact-linear" => Some((SoftResolve::Exact, Penumbra::Linear)),
                "pcss" => None,
                m => Some((
                    SoftResolve::Faithful { n: m.trim_start_matches("faithful-n").parse().unwrap_or(1) },
                    Penumbra::Linear,
                )),
            }
            .map(|(r, penumbra)| (r, AreaLight { penumbra, ..light.clone() }));
            let mut out = Vec::new();
            let mut run = |_: &Frame| -> Result<(), RenderError> {
                out = match &resolve {
                    Some((r, light)) => soft::visibility(&frame, light, &input, *r),
                    None => soft::pcss(&frame, &light, &input, radius),
                };
                Ok(())
            };
            let ms = median_ms(&mut run, &frame, iterations)?;
            let (mean, p99) = soft_errors(&out, &truth, &visible);
            rows.push(SoftRow {
                method: method.into(),
                size,
                ms,
                mean_error: Some(mean),
                p99_error: Some(p99),
            });
        }
        progress(&format!("{size}²: whole frames"));
        let unlit = Frame { area_light: None, ..frame.clone() };
        for (method, f) in [("frame", &frame), ("frame-unlit", &unlit)] {
            rows.push(SoftRow {
                method: method.into(),
                size,
                ms: time(f, iterations)?.ms,
                mean_error: None,
                p99_error: None,
            });
        }
    }
    Ok(SoftTable { scene: file.into(), iterations, disc_radius: used_radius, backend: backend.into(), rows })
}

impl SoftTable {
    /// The table as plain text.
    pub fn to_text(&self) -> String {
        let mut out = format!(
            "soft shadows, scene {} ({} runs, median; stage = maps + classes + resolve on the CPU; error = |visibility − \
             truth| on shadow-edge pixels, truth = disc of radius {:.4} by {TRUTH_SAMPLES} maps of 4 texels a pixel)\n\
             {:<14} {:>6} {:>10} {:>9} {:>11} {:>10}\n",
            self.scene, self.iterations, self.disc_radius, "method", "size", "ms", "fps", "mean error", "p99 error"
        );
        for r in &self.rows {
            let err = |e: Option<f64>| e.map_or("—".to_string(), |e| format!("{e:.4}"));
            let label = match r.method.as_str() {
                "frame" => format!("frame ({})", self.backend),
                "frame-unlit" => "  no area light".into(),
                m => m.into(),
            };
            out += &format!(
                "{:<14} {:>6} {:>10.2} {:>9.1} {:>11} {:>10}\n",
                label,
                format!("{}²", r.size),
                r.ms,
                1e3 / r.ms,
                err(r.mean_error),
                err(r.p99_error)
            );
        }
        out
    }

    /// The table as JSON: `rows` of `{method, size, ms, fps, mean_error, p99_error}`.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "table": "shadows",
            "scene": self.scene,
            "iterations": self.iterations,
            "disc_radius": self.disc_radius,
            "truth_samples": TRUTH_SAMPLES,
            "truth_map_texels_per_pixel": 4,
            "backend": self.backend,
            "rows": self.rows.iter().map(|r| serde_json::json!({
                "method": r.method,
                "size": r.size,
                "ms": r.ms,
                "fps": 1e3 / r.ms,
                "mean_error": r.mean_error,
                "p99_error": r.p99_error,
            })).collect::<Vec<_>>(),
        })
    }
}

/// One line of the kernel-limit table.
#[derive(Clone, Debug)]
pub struct LimitRow {
    /// What was timed.
    pub what: String,
    /// Median milliseconds per frame.
    pub ms: f64,
}

/// The faithful bulged beam of the analytic table at one size, timed five ways in one run: the
/// whole render and its wave pass, the eight-lane kernel alone and the scalar kernel alone over
/// every pixel's ray, and a plain scalar loop of the same maths ([`plain_beam_loop`]), so the
/// distance from hadou to the machine's limit is a ratio measured on the same machine at the same
/// moment.
#[derive(Clone, Debug)]
pub struct LimitTable {
    /// Image side.
    pub size: u32,
    /// Repetitions per line.
    pub iterations: u32,
    /// The lines, in the order above.
    pub rows: Vec<LimitRow>,
}

/// Measures [`LimitTable`] at `size`.
pub fn limit_table(size: u32, iterations: u32) -> Result<LimitTable, RenderError> {
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
    let row = |what: &str, ms: f64| LimitRow { what: what.into(), ms };
    Ok(LimitTable {
        size,
        iterations,
        rows: vec![
            row("whole render (hadou)", whole.ms),
            row("wave pass (hadou)", wave_ms),
            row("kernel only, 8 lanes", lanes_ms),
            row("kernel only, scalar", scalar_ms),
            row("plain scalar loop", plain_ms),
        ],
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

impl LimitTable {
    /// The table as plain text, with each line's ratio to the plain loop.
    pub fn to_text(&self) -> String {
        let plain = self.rows.last().map_or(0.0, |r| r.ms);
        let mut out = format!(
            "\nbulged beam (faithful) at {}², kernel at its limit ({} runs, median, one run)\n{:<26} {:>10} {:>10} {:>14}\n",
            self.size, self.iterations, "what", "ms", "Mpx/s", "plain loop ×"
        );
        for r in &self.rows {
            let mpx = (self.size as f64).powi(2) / (r.ms * 1e3);
            let ratio = if r.ms > 0.0 { plain / r.ms } else { 0.0 };
            out += &format!("{:<26} {:>10.2} {:>10.1} {:>13.2}×\n", r.what, r.ms, mpx, ratio);
        }
        out
    }

    /// The table as JSON.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "size": self.size,
            "iterations": self.iterations,
            "rows": self.rows.iter().map(|r| serde_json::json!({
                "what": r.what,
                "ms": r.ms,
                "mpix_per_s": (self.size as f64).powi(2) / (r.ms * 1e3),
            })).collect::<Vec<_>>(),
        })
    }
}
