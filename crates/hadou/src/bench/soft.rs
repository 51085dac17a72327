//! The soft-shadow table (003): every resolve's soft-shadow stage on the CPU against the ground
//! truth of a true disc light, and the whole frame with and without the area light.

use super::table::{Cell, Column, Report, Row, Table};
use super::timing::{median_ms, Timer};
use hadou_scene::{AreaLight, Frame, RenderError, Scene};
use std::path::Path;

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

/// Lamp rays a pixel of the traced rows' brute-force reference
/// ([`hadou_cpu::traced::reference`]).
pub const REFERENCE_SAMPLES: u32 = 4096;
/// Most pixels the reference is computed at for each shape (every `k`-th of the traced image's
/// soft pixels and their 2-pixel neighbourhood, and every 61st other visible pixel:
/// [`hadou_cpu::traced::reference_pixels`]).
pub const REFERENCE_PIXELS: usize = 3000;

/// The lamp shapes of the traced rows, with their names.
pub const TRACED_SHAPES: [(&str, hadou_math::soft::LampShape); 3] = [
    ("segment", hadou_math::soft::LampShape::Segment),
    ("disc", hadou_math::soft::LampShape::Disc),
    ("sphere", hadou_math::soft::LampShape::Sphere),
];

/// The methods of the soft-shadow table, in order: 003's faithful resolve at N = 1, 3, 5, 10 (with
/// 003's linear brightness), hadou's exact resolve with 003's linear brightness (`exact-linear`:
/// faithful N = 1's picture) and with its default segment brightness (`exact`), and PCSS.
pub const SOFT_METHODS: [&str; 7] =
    ["faithful-n1", "faithful-n3", "faithful-n5", "faithful-n10", "exact-linear", "exact", "pcss"];

/// One row of the soft-shadow table.
pub use hadou_cpu::soft::{disc_radius as soft_disc_radius, edge_errors as soft_errors};

/// What `hadou bench shadows` measures besides the sizes: the scene, whether only the traced rows,
/// and the ground truth's disc radius.
#[derive(Clone, Copy, Debug, Default)]
pub struct SoftOptions<'a> {
    /// The scene file in the scenes folder (`None`: [`SOFT_SCENE`]), taken at t = 0.
    pub scene: Option<&'a str>,
    /// Only the traced rows, their references and the whole frames.
    pub traced_only: bool,
    /// The ground truth's disc radius (`None`: [`soft_disc_radius`]).
    pub disc_radius: Option<f32>,
}

/// Measures the soft-shadow table: `options.scene` (by default [`SOFT_SCENE`]; at t = 0) at each
/// size, every method's soft-shadow stage on the CPU against the ground truth
/// ([`hadou_cpu::soft::truth`], a disc of radius `disc_radius`, by default [`soft_disc_radius`];
/// skipped with `traced_only`), then for each lamp shape ([`TRACED_SHAPES`]) the traced resolve
/// (its hierarchy and resolve on the CPU, at the scene's `samples` or the default) against its
/// brute-force reference ([`REFERENCE_SAMPLES`] rays a pixel at up to [`REFERENCE_PIXELS`]
/// pixels), then the whole frame by `time` with and without the area light (and, on the CPU,
/// traced with each shape), all in one run. `progress` hears what is being done.
///
/// A row per method and size: the median milliseconds of the soft-shadow stage (its maps, the
/// classes and the resolve, on the CPU) and the mean and 99th-percentile per-pixel visibility
/// difference from the ground truth over the shadow-edge pixels; then the rows `frame` (the
/// whole render with the scene's own resolve, by the bench's backend) and `frame-unlit` (the same
/// without the area light), without errors. Its JSON `rows` are `{method, size, ms, fps,
/// mean_error, p99_error}` (the traced and reference rows with `pixels`: the pixels measured), the
/// frame rows with their `parts` (`{name, ms}`: on the GPU the
/// soft preparation and the tiles by wall clock, and the output).
pub fn soft_table(
    time: &mut Timer<'_>,
    scenes: &Path,
    sizes: &[u32],
    iterations: u32,
    backend: &str,
    options: SoftOptions<'_>,
    progress: &mut dyn FnMut(&str),
) -> Result<Report, RenderError> {
    use hadou_cpu::soft;
    use hadou_scene::{Penumbra, SoftResolve};
    let SoftOptions { scene: scene_file, traced_only, disc_radius } = options;
    let (file, t) = scene_file.map_or(SOFT_SCENE, |f| (f, 0.0));
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
        let visible: Vec<bool> = input.points.iter().map(Option::is_some).collect();
        let methods: &[&str] = if traced_only { &[] } else { &SOFT_METHODS };
        if !traced_only {
            progress(&format!("{size}²: ground truth ({TRUTH_SAMPLES} shadow maps of {tm}²)"));
        }
        let truth = if traced_only {
            Vec::new()
        } else {
            soft::truth(&frame, &light, &input, radius, TRUTH_SAMPLES, tm)
        };
        for &method in methods {
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
            rows.push(soft_row(method, method.into(), size, ms, Some(mean), Some(p99)));
        }
        let traced_samples = match light.resolve {
            SoftResolve::Traced { samples } => samples,
            _ => hadou_scene::DEFAULT_TRACE_SAMPLES,
        };
        // The scene's two-map picture (exact resolve, segment brightness) against each lamp's
        // reference: how well the maps model each shape.
        let maps = soft::visibility(
            &frame,
            &AreaLight { penumbra: Penumbra::Segment, ..light.clone() },
            &input,
            SoftResolve::Exact,
        );
        let mut traced_frames = Vec::new();
        for (name, shape) in TRACED_SHAPES {
            let lamp = AreaLight {
                shape,
                resolve: SoftResolve::Traced { samples: traced_samples },
                ..light.clone()
            };
            let shaped = Frame { area_light: Some(lamp.clone()), ..frame.clone() };
            progress(&format!("{size}²: traced, {name}"));
            let mut out = Vec::new();
            let mut run = |_: &Frame| -> Result<(), RenderError> {
                out = hadou_cpu::traced::traced(&shaped, &lamp, &input.points, input.width, traced_samples);
                Ok(())
            };
            let ms = median_ms(&mut run, &shaped, iterations)?;
            let px = hadou_cpu::traced::reference_pixels(&out, &visible, input.width, REFERENCE_PIXELS);
            progress(&format!("{size}²: reference, {name} ({} pixels × {REFERENCE_SAMPLES} rays)", px.len()));
            let t0 = std::time::Instant::now();
            let truth = hadou_cpu::traced::reference(&shaped, &lamp, &input.points, REFERENCE_SAMPLES, &px);
            let ref_ms = t0.elapsed().as_secs_f64() * 1e3;
            let mine: Vec<f32> = px.iter().map(|&i| out[i]).collect();
            let (mean, p99, n) = hadou_cpu::traced::truth_errors(&mine, &truth);
            let method = format!("traced-{name}");
            let mut row =
                soft_row(&method, format!("{method} ({traced_samples})"), size, ms, Some(mean), Some(p99));
            row.push(Cell::new("pixels", n as u64, n.to_string()));
            rows.push(row);
            let two: Vec<f32> = px.iter().map(|&i| maps[i]).collect();
            let (mean, p99, n) = hadou_cpu::traced::truth_errors(&two, &truth);
            let method = format!("exact-vs-{name}");
            let mut row = soft_row(&method, method.clone(), size, f64::NAN, Some(mean), Some(p99));
            row.push(Cell::new("pixels", n as u64, n.to_string()));
            rows.push(row);
            let method = format!("reference-{name}");
            let mut row = soft_row(&method, format!("{method} ({} px)", px.len()), size, ref_ms, None, None);
            row.push(Cell::new("pixels", px.len() as u64, px.len().to_string()));
            rows.push(row);
            traced_frames.push((
                format!("frame-traced-{name}"),
                format!("frame traced {name} ({backend})"),
                shaped,
            ));
        }
        progress(&format!("{size}²: whole frames"));
        let unlit = Frame { area_light: None, ..frame.clone() };
        let mut frames = vec![
            ("frame".to_string(), format!("frame ({backend})"), frame.clone()),
            ("frame-unlit".into(), "  no area light".into(), unlit),
        ];
        if backend.starts_with("cpu") {
            frames.extend(traced_frames);
        }
        for (method, label, f) in &frames {
            let timing = time(f, iterations)?;
            let mut row = soft_row(method, label.clone(), size, timing.ms, None, None);
            row.push(Cell::json("parts", timing.parts_json()));
            rows.push(row);
        }
    }
    let title = format!(
        "soft shadows, scene {file} ({iterations} runs, median; stage = maps + classes + resolve on the CPU; error = |visibility − \
         truth| on shadow-edge pixels, truth = disc of radius {used_radius:.4} by {TRUTH_SAMPLES} maps of 4 texels a pixel; traced-* rows: stage = \
         hierarchy + traced resolve, error = |traced − brute-force reference of the same lamp, {REFERENCE_SAMPLES} rays a \
         pixel| where either is in (0.005, 0.995), `pixels` of them; exact-vs-* rows: the exact resolve's error against that reference; reference-* rows: the \
         reference's time at its pixels)\n"
    );
    let columns = vec![
        Column::left("method", 14),
        Column::right("size", 6),
        Column::right("ms", 10),
        Column::right("fps", 9),
        Column::right("mean error", 11),
        Column::right("p99 error", 10),
        Column::right("pixels", 7),
    ];
    Ok(Report {
        fields: vec![
            ("table", "shadows".into()),
            ("scene", file.into()),
            ("iterations", iterations.into()),
            ("disc_radius", used_radius.into()),
            ("truth_samples", TRUTH_SAMPLES.into()),
            ("truth_map_texels_per_pixel", 4.into()),
            ("backend", backend.into()),
        ],
        tables: vec![Table { key: Some("rows"), title, columns, rows }],
    })
}

/// One row of the soft-shadow table: `method` (shown as `label`) at `size`, its median
/// milliseconds (NaN: not timed, `null` in JSON) and its errors (`None` for the `frame` rows).
fn soft_row(method: &str, label: String, size: u32, ms: f64, mean: Option<f64>, p99: Option<f64>) -> Row {
    let err = |e: Option<f64>| e.map_or("—".to_string(), |e| format!("{e:.4}"));
    vec![
        Cell::json("method", method),
        Cell::text("method", label),
        Cell::new("size", size, format!("{size}²")),
        Cell::new(
            "ms",
            ms.is_finite().then_some(ms),
            if ms.is_finite() { format!("{ms:.2}") } else { "—".into() },
        ),
        Cell::new(
            "fps",
            ms.is_finite().then_some(1e3 / ms),
            if ms.is_finite() { format!("{:.1}", 1e3 / ms) } else { "—".into() },
        ),
        Cell::new("mean_error", mean, err(mean)),
        Cell::new("p99_error", p99, err(p99)),
    ]
}
