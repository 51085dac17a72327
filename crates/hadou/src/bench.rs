//! `hadou bench`: rendering speed in the layout of the thesis's tables (002 §4, SPEC.md §1.5).
//!
//! The scenes are built from scene-file text, so the bench measures exactly what users render.

use hadou_scene::{Frame, RenderError, Scene};
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

/// A timer: renders `frame` once untimed, then `iterations` timed times, and returns the median
/// milliseconds per frame.
pub type Timer<'a> = dyn FnMut(&Frame, u32) -> Result<f64, RenderError> + 'a;

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
                let ms = time(&frame, iterations)?;
                cells.push(Cell { size, occlusion, ms });
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
    v.sort_by(|a, b| a.total_cmp(b));
    Ok(v[v.len() / 2])
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
                })).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
        })
    }
}
