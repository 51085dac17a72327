//! The curve table (SPEC.md §1.5's second table with evaluation and error columns): the Fig. 4.2
//! curves under every integrator, then the default integrator against faithful Simpson `m = 500`
//! on every example curve scene.

use super::curve_accuracy::{curve_accuracy, curve_reference, with_integrator, ACCURACY_GRID};
use super::table::{rows_json, Cell, Column, Report, Row, Table};
use super::timing::Timer;
use hadou_math::curve::{Integrator, Reduction};
use hadou_scene::{RenderError, Scene};
use std::path::Path;

/// The curve shapes of the curve table and the example scene each is taken from (002 Fig. 4.2).
pub const CURVE_SCENES: [(&str, &str); 4] = [
    ("helix", "fig4-2-helix.toml"),
    ("trig sum", "fig4-2-trig.toml"),
    ("Bézier deg 4", "fig4-2-bezier.toml"),
    ("B-spline", "fig4-2-bspline.toml"),
];

/// The integrators of the curve table: the thesis's Simpson at m = 100, 300, 500 without
/// reduction and with reduction n = 2, 4 (ε = 0.25), then hadou's default, then the nearest-point
/// field (`field = "nearest"`, whose error is against its own reference).
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
    v.push(("nearest field".into(), Integrator::Nearest));
    v
}

/// Measures the curve table on the example curve scenes found in `scenes_dir`. Its JSON `rows` are
/// `{shape, integrator, ms, evals_per_pixel, p99_error}` (`ms` a list of `{size, ms, fps}`), its
/// `acceptance` rows the [`AcceptanceRow`]s.
pub fn curve_table(
    time: &mut Timer<'_>,
    scenes_dir: &Path,
    sizes: &[u32],
    iterations: u32,
    backend: &str,
    method: &str,
    progress: &mut dyn FnMut(&str),
) -> Result<Report, RenderError> {
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
            let nearest_reference;
            let reference = if integrator == Integrator::Nearest {
                nearest_reference = curve_reference(&frame, ACCURACY_GRID);
                &nearest_reference
            } else {
                &reference
            };
            let (evals_per_pixel, p99_error) = curve_accuracy(&frame, reference, ACCURACY_GRID);
            let mut ms = Vec::new();
            for &size in sizes {
                let mut f = frame.clone();
                f.width = size;
                f.height = size;
                ms.push((size, time(&f, iterations)?.ms));
            }
            rows.push(curve_row(shape, &label, &ms, evals_per_pixel, p99_error));
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
    let mut columns = vec![Column::left("shape", 14), Column::left("integrator", 20)];
    columns.extend(sizes.iter().map(|s| Column::right(format!("{s}² ms (fps)"), 18)));
    columns.extend([Column::right("evals/pixel", 12), Column::right("p99 error", 10)]);
    let title = format!(
        "curves — backend {backend}, {method}; evals/pixel and p99 error on a 64×64 pixel grid vs f64 adaptive reference\n"
    );
    let acceptance = Table {
        key: Some("acceptance"),
        title: "\nexample scenes at their own size: default integrator against faithful Simpson m=500\n"
            .into(),
        columns: vec![
            Column::left("scene", 20),
            Column::right("size", 9),
            Column::right("ms Simpson/default", 19),
            Column::right("evals Simp./def.", 19),
            Column::right("evals ×", 8),
            Column::right("time ×", 8),
            Column::right("p99 Simp.", 10),
            Column::right("p99 def.", 10),
            Column::left("bars", 0).after("  "),
        ],
        rows: acceptance.iter().map(AcceptanceRow::cells).collect(),
    };
    Ok(Report {
        fields: vec![("table", "curves".into()), ("backend", backend.into()), ("method", method.into())],
        tables: vec![Table { key: Some("rows"), title, columns, rows }, acceptance],
    })
}

/// One row of the curve table: a shape under one integrator, its median milliseconds per frame
/// per size, its mean evaluations per sampled pixel and its 99th-percentile relative energy
/// error against the converged reference.
fn curve_row(shape: &str, integrator: &str, ms: &[(u32, f64)], evals_per_pixel: f64, p99_error: f64) -> Row {
    let sizes: Vec<Row> = ms
        .iter()
        .map(|&(size, ms)| vec![Cell::json("size", size), Cell::json("ms", ms), Cell::json("fps", 1e3 / ms)])
        .collect();
    let mut row = vec![
        Cell::new("shape", shape, shape),
        Cell::new("integrator", integrator, integrator),
        Cell::json("ms", rows_json(&sizes)),
    ];
    row.extend(ms.iter().map(|&(_, ms)| Cell::text("size", format!("{ms:.1} ({:.2})", 1e3 / ms))));
    row.push(Cell::new("evals_per_pixel", evals_per_pixel, format!("{evals_per_pixel:.1}")));
    row.push(Cell::new("p99_error", p99_error, format!("{p99_error:.2e}")));
    row
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

    /// The row's cells in the curve table's `acceptance` rows.
    fn cells(&self) -> Row {
        let (simpson_ms, default_ms) = (self.simpson_ms, self.default_ms);
        let (simpson_evals, default_evals) = (self.simpson_evals, self.default_evals);
        let (eval_ratio, time_ratio) = (self.eval_ratio(), self.time_ratio());
        let (simpson_p99, default_p99) = (self.simpson_p99, self.default_p99);
        let bars = self.meets_bars();
        vec![
            Cell::new("scene", self.scene.as_str(), self.scene.as_str()),
            Cell::json("width", self.size.0),
            Cell::json("height", self.size.1),
            Cell::text("size", format!("{}×{}", self.size.0, self.size.1)),
            Cell::json("simpson_m500_ms", simpson_ms),
            Cell::json("default_ms", default_ms),
            Cell::text("ms", format!("{simpson_ms:.1}/{default_ms:.1}")),
            Cell::json("simpson_m500_evals_per_pixel", simpson_evals),
            Cell::json("default_evals_per_pixel", default_evals),
            Cell::text("evals", format!("{simpson_evals:.1}/{default_evals:.1}")),
            Cell::new("eval_ratio", eval_ratio, format!("{eval_ratio:.1}")),
            Cell::new("time_ratio", time_ratio, format!("{time_ratio:.1}")),
            Cell::new("simpson_m500_p99_error", simpson_p99, format!("{simpson_p99:.2e}")),
            Cell::new("default_p99_error", default_p99, format!("{default_p99:.2e}")),
            Cell::new("meets_bars", bars, if bars { "met" } else { "NOT met" }),
        ]
    }
}
