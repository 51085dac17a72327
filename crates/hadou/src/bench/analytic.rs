//! The analytic table: the thesis's analytic shapes (002 §4) from scene text, each falloff, each
//! size, with and without the occluding cubes, and where the time goes.

use super::table::{rows_json, Cell, Column, Report, Row, Table};
use super::timing::{Timer, Timing};
use hadou_scene::{Frame, RenderError, Scene};
use std::path::Path;

/// The shapes of the analytic table: the thesis's three rows plus the bulged beam, then the
/// sphere and the bulged beam with the distance attenuation `(1 − u)^j`, `j = 8` (002 eq. 3.23;
/// a shape `"<shape>, j = <j>"` gives every wave of `<shape>` that `j`).
pub const ANALYTIC_SHAPES: [&str; 6] =
    ["sphere", "capsule", "sphere+capsule", "bulged beam", "sphere, j = 8", "bulged beam, j = 8"];

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
    let (shape, j) = shape.split_once(", j = ").unwrap_or((shape, "0"));
    let wave = |kind: &str, extra: &str| {
        format!(
            "\n[[wave]]\nname = \"{kind}\"\nkind = \"{kind}\"\nfalloff = \"{falloff}\"\ncore_radius = {core}\n\
             rgba = [0.8, 0.8, 0.2, 1.0]\nj = {j}\n{extra}"
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

/// Measures the analytic table: for each shape and falloff, each size, plus occlusion at the
/// largest size. Its text gives fps and Mpixel/s per cell, then where the time goes (per row,
/// the largest size without occlusion split into its parts, where the timer measured parts); its
/// JSON `rows` are `{shape, falloff, cells}`, each cell `{size, occlusion, ms, fps, mpix_per_s,
/// parts}`.
pub fn analytic_table(
    time: &mut Timer<'_>,
    sizes: &[u32],
    iterations: u32,
    backend: &str,
    method: &str,
) -> Result<Report, RenderError> {
    let mut measured = Vec::new();
    let largest = sizes.iter().copied().max().unwrap_or(512);
    let mut cases: Vec<(u32, bool)> = sizes.iter().map(|&s| (s, false)).collect();
    cases.push((largest, true));
    for falloff in ["faithful", "inverse-square"] {
        for shape in ANALYTIC_SHAPES {
            let mut cells = Vec::new();
            for &(size, occlusion) in &cases {
                let frame = analytic_frame(shape, falloff, size, occlusion)?;
                cells.push(Measured { size, occlusion, timing: time(&frame, iterations)? });
            }
            measured.push((shape, falloff, cells));
        }
    }
    let mut columns = vec![Column::left("shape", 20), Column::left("falloff", 15)];
    for &(size, occlusion) in &cases {
        let label = if occlusion { format!("occl. {size}²") } else { format!("{size}²") };
        columns.push(Column::right(label, 22));
    }
    let rows = measured
        .iter()
        .map(|(shape, falloff, cells)| {
            let mut row = vec![Cell::new("shape", *shape, *shape), Cell::new("falloff", *falloff, *falloff)];
            row.push(Cell::json("cells", rows_json(&cells.iter().map(Measured::cells).collect::<Vec<_>>())));
            for c in cells {
                row.push(Cell::text("cell", format!("{:.1} fps {:.1} Mpx/s", c.fps(), c.mpix_per_s())));
            }
            row
        })
        .collect();
    let title = format!("analytic shapes — backend {backend}, {method} ({iterations} runs, median)\n");
    let mut tables = vec![Table { key: Some("rows"), title, columns, rows }];
    tables.extend(parts_table(&measured));
    Ok(Report {
        fields: vec![
            ("table", "analytic".into()),
            ("backend", backend.into()),
            ("method", method.into()),
            ("iterations", iterations.into()),
        ],
        tables,
    })
}

/// One measured cell of the analytic table.
struct Measured {
    size: u32,
    occlusion: bool,
    timing: Timing,
}

impl Measured {
    fn fps(&self) -> f64 {
        1e3 / self.timing.ms
    }

    fn mpix_per_s(&self) -> f64 {
        (self.size as f64).powi(2) / (self.timing.ms * 1e3)
    }

    /// The cell as a JSON row (its parts as rows of `{name, ms}`).
    fn cells(&self) -> Row {
        vec![
            Cell::json("size", self.size),
            Cell::json("occlusion", self.occlusion),
            Cell::json("ms", self.timing.ms),
            Cell::json("fps", self.fps()),
            Cell::json("mpix_per_s", self.mpix_per_s()),
            Cell::json("parts", self.timing.parts_json()),
        ]
    }
}

/// Where the time goes: per row, the largest size without occlusion split into its parts (text
/// only; none when the timer measured no parts).
fn parts_table(measured: &[(&str, &str, Vec<Measured>)]) -> Option<Table> {
    fn cell(cells: &[Measured]) -> Option<&Measured> {
        cells.iter().filter(|c| !c.occlusion).max_by_key(|c| c.size)
    }
    let first = measured.first().and_then(|(_, _, cells)| cell(cells))?;
    if first.timing.parts.is_empty() {
        return None;
    }
    let title = format!("\nwhere the time goes at {}² (median ms, share of the whole render)\n", first.size);
    let mut columns = vec![Column::left("shape", 20), Column::left("falloff", 15), Column::right("whole", 9)];
    columns.extend(first.timing.parts.iter().map(|(name, _)| Column::right(name.as_str(), 16)));
    let rows = measured
        .iter()
        .filter_map(|(shape, falloff, cells)| {
            let c = &cell(cells)?.timing;
            let mut row = vec![
                Cell::text("shape", *shape),
                Cell::text("falloff", *falloff),
                Cell::text("whole", format!("{:.2}", c.ms)),
            ];
            for (_, ms) in &c.parts {
                let share = if c.ms > 0.0 { 100.0 * ms / c.ms } else { 0.0 };
                row.push(Cell::text("part", format!("{ms:.2} ({share:.0}%)")));
            }
            Some(row)
        })
        .collect();
    Some(Table { key: None, title, columns, rows })
}
