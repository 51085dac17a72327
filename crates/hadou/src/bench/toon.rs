//! The toon table: the toon scene full and reduced to plain diffuse, the toon scene at 4 samples
//! per pixel and at 1 (anti-aliasing), the shadow scene with and without its shadows, the
//! glare scene with and without its `[bloom]`, and the MToon scene with its MToon look and with the
//! two-band toon ramps that approximate it, at each size in one run (every other row at one
//! sample per pixel).

use super::table::{Cell, Column, Report, Row, Table};
use super::timing::Timer;
use hadou_scene::{Frame, RenderError, Scene};
use std::path::Path;

/// The scene and time `hadou bench toon` renders: a toon character with textures, a feature
/// texture and outlines, two outlined props and a toon ground, lit by a firing beam.
pub const TOON_SCENE: (&str, f32) = ("light-from-front.toml", 1.2);

/// The scene and time whose shadows `hadou bench toon` times on and off: sun shadows by shadow map
/// (2048²) and by plane projection, and a wave shadow by shadow map, over toon materials.
pub const SHADOW_SCENE: (&str, f32) = ("shadow-uneven.toml", 1.0);

/// The scene and time whose glare `hadou bench toon` times on and off: the kamehameha with a
/// bloom and a streak.
pub const GLARE_SCENE: (&str, f32) = ("glare-kamehameha.toml", 1.5);

/// The animated character `hadou bench toon` poses and renders: `assets/dancer.glb` (written by
/// `scenes/assets/make_brace.py`: about 53 000 triangles, 65 joints, up to four weights per
/// vertex) playing its `dance` clip, outlined, under a firing beam over a toon ground. Read as if it
/// were `scenes/bench-dance.toml`.
pub const ANIMATED_SCENE: &str = r#"
background = [0.05, 0.04, 0.06]
[camera]
position = [0.0, 1.3, 4.2]
target = [0.0, 0.95, 0.0]
fov = 40.0
[light]
direction = [0.4, -1.0, -0.6]
[[material]]
name = "ground"
model = "toon"
base_color = [0.4, 0.38, 0.34]
wave_blend = 0.5
[[object]]
name = "dancer"
kind = "gltf"
path = "assets/dancer.glb"
animation = "dance"
wave_blend = 1.0
outline = true
outline_width = 0.004
[[object]]
name = "ground"
kind = "plane"
size = [14.0, 14.0]
material = "ground"
[[wave]]
name = "beam"
kind = "beam"
rgba = [0.45, 0.8, 1.0, 1.0]
M = [1.0, 1.1, 3.0]
D = [0.0, 0.0, -1.0]
length = 5.0
alpha_s = 0.02
alpha_c = 0.02
head_alpha = 0.05
muzzle_alpha = 0.03
"#;

/// The scene time of the animated row's frame.
pub const ANIMATED_TIME: f32 = 0.7;

/// The scene and time whose MToon materials `hadou bench toon` times against their two-band toon
/// approximation: three MToon spheres (step, rim, matcap, five textures, UV animation) lit by a
/// wave, over a diffuse floor.
pub const MTOON_SCENE: (&str, f32) = ("light-mtoon.toml", 1.5);

/// `frame` with every MToon material drawn by its two-band toon ramp instead (`Material::mtoon`
/// removed).
pub fn without_mtoon(frame: &Frame) -> Frame {
    let mut f = frame.clone();
    for o in &mut f.objects {
        for m in &mut o.materials {
            m.mtoon = None;
        }
    }
    f
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

/// Measures the toon table: [`TOON_SCENE`] at each size, `full` (the scene as written) and
/// `plain` (every material diffuse, no wave light, no outlines, no textures: the opaque pass hadou
/// had before materials) and `4-samples` against `1-sample` (anti-aliasing), then [`SHADOW_SCENE`] at each size, `shadows` (as written) and
/// `no-shadows` (its `[[shadow]]`s removed), then [`GLARE_SCENE`] at each size, `bloom` (as
/// written) and `no-bloom` (its `[bloom]` removed), then [`MTOON_SCENE`] at each size, `mtoon` and
/// `toon-ramp` ([`without_mtoon`]), in one run. Its text pairs the two variants of each
/// size with their ratio; its JSON `rows` are `{scene, size, variant, ms, fps, parts}` (`parts`: `{name, ms}` where the
/// timer measured them, as in the analytic table).
pub fn toon_table(
    time: &mut Timer<'_>,
    scenes: &Path,
    sizes: &[u32],
    iterations: u32,
    backend: &str,
    method: &str,
) -> Result<Report, RenderError> {
    let mut rows = Vec::new();
    // Times both variants of one size: a JSON row each, and the text's line of the pair.
    let mut pair = |scene: &'static str, size: u32, variants: [(&'static str, &Frame); 2]| {
        let mut ms = [0.0; 2];
        for (i, (variant, f)) in variants.into_iter().enumerate() {
            let timing = time(f, iterations)?;
            ms[i] = timing.ms;
            rows.push(vec![
                Cell::json("scene", scene),
                Cell::json("size", size),
                Cell::json("variant", variant),
                Cell::json("ms", ms[i]),
                Cell::json("fps", 1e3 / ms[i]),
                Cell::json("parts", timing.parts_json()),
            ]);
        }
        let [on, off] = ms;
        Ok::<Row, RenderError>(vec![
            Cell::text("size", format!("{size}²")),
            Cell::text("ms", format!("{on:.2}")),
            Cell::text("fps", format!("{:.1}", 1e3 / on)),
            Cell::text("ms", format!("{off:.2}")),
            Cell::text("ratio", format!("{:.2}×", on / off)),
        ])
    };
    let (file, t) = TOON_SCENE;
    let scene = Scene::load(scenes.join(file)).map_err(|e| RenderError::Other(e.to_string()))?;
    let mut toon = Vec::new();
    let mut samples = Vec::new();
    for &size in sizes {
        let mut frame = scene.at(t);
        frame.width = size;
        frame.height = size;
        // The toon, shadow and glare rows at one sample per pixel; the anti-aliasing rows set
        // the scene's 4 samples against 1.
        frame.samples = 1;
        let plain = plain_materials(&frame);
        toon.push(pair(file, size, [("full", &frame), ("plain", &plain)])?);
        let aa = Frame { samples: 4, ..frame.clone() };
        samples.push(pair(file, size, [("4-samples", &aa), ("1-sample", &frame)])?);
    }
    let (shadow_file, st) = SHADOW_SCENE;
    let shadow_scene =
        Scene::load(scenes.join(shadow_file)).map_err(|e| RenderError::Other(e.to_string()))?;
    let mut shadows = Vec::new();
    for &size in sizes {
        let mut frame = shadow_scene.at(st);
        frame.width = size;
        frame.height = size;
        frame.samples = 1;
        let bare = Frame { shadows: Vec::new(), ..frame.clone() };
        shadows.push(pair(shadow_file, size, [("shadows", &frame), ("no-shadows", &bare)])?);
    }
    let (glare_file, gt) = GLARE_SCENE;
    let glare_scene = Scene::load(scenes.join(glare_file)).map_err(|e| RenderError::Other(e.to_string()))?;
    let mut glare = Vec::new();
    for &size in sizes {
        let mut frame = glare_scene.at(gt);
        frame.width = size;
        frame.height = size;
        frame.samples = 1;
        let bare = Frame { bloom: None, ..frame.clone() };
        glare.push(pair(glare_file, size, [("bloom", &frame), ("no-bloom", &bare)])?);
    }
    let (mtoon_file, mt) = MTOON_SCENE;
    let mtoon_scene = Scene::load(scenes.join(mtoon_file)).map_err(|e| RenderError::Other(e.to_string()))?;
    let mut mtoon = Vec::new();
    for &size in sizes {
        let mut frame = mtoon_scene.at(mt);
        frame.width = size;
        frame.height = size;
        frame.samples = 1;
        let ramp = without_mtoon(&frame);
        mtoon.push(pair(mtoon_file, size, [("mtoon", &frame), ("toon-ramp", &ramp)])?);
    }
    // The animated character: the frame at one sample, and the posing (the whole `Scene::at` of
    // a new clip time each iteration, so no pose is reused) against it.
    let dance = Scene::parse(ANIMATED_SCENE, &scenes.join("bench-dance.toml"))
        .map_err(|e| RenderError::Other(e.to_string()))?;
    let mut animated = Vec::new();
    for &size in sizes {
        let mut frame = dance.at(ANIMATED_TIME);
        frame.width = size;
        frame.height = size;
        frame.samples = 1;
        let frame_ms = time(&frame, iterations)?.ms;
        let mut posing = Vec::new();
        for k in 0..iterations.max(1) + 1 {
            let t = ANIMATED_TIME + 0.013 * (k + 1) as f32;
            let start = std::time::Instant::now();
            std::hint::black_box(dance.at(t));
            if k > 0 {
                posing.push(start.elapsed().as_secs_f64() * 1e3);
            }
        }
        let pose_ms = super::timing::median(posing);
        for (variant, ms) in [("frame", frame_ms), ("posing", pose_ms)] {
            rows.push(vec![
                Cell::json("scene", "bench-dance"),
                Cell::json("size", size),
                Cell::json("variant", variant),
                Cell::json("ms", ms),
                Cell::json("fps", 1e3 / ms),
            ]);
        }
        animated.push(vec![
            Cell::text("size", format!("{size}²")),
            Cell::text("ms", format!("{frame_ms:.2}")),
            Cell::text("fps", format!("{:.1}", 1e3 / frame_ms)),
            Cell::text("ms", format!("{pose_ms:.2}")),
            Cell::text("share", format!("{:.1} %", 100.0 * pose_ms / frame_ms)),
        ]);
    }
    let columns = |on: &str, fps: &str, off: &str| {
        vec![
            Column::left("size", 8),
            Column::right(on, 12),
            Column::right(fps, 10),
            Column::right(off, 14),
            Column::right("ratio", 10),
        ]
    };
    let mut tables = vec![
        Table { key: Some("rows"), rows, ..Table::default() },
        Table {
            key: None,
            title: format!("toon scene {file} — backend {backend}, {method} ({iterations} runs, median)\n"),
            columns: columns("full ms", "full fps", "plain ms"),
            rows: toon,
        },
    ];
    if !samples.is_empty() {
        tables.push(Table {
            key: None,
            title: format!("\nanti-aliasing, toon scene {file}\n"),
            columns: columns("4 samples ms", "fps", "1 sample ms"),
            rows: samples,
        });
    }
    if !animated.is_empty() {
        let tris = dance.at(ANIMATED_TIME).objects[0].mesh.indices.len() / 3;
        let mut cols = columns("frame ms", "fps", "posing ms");
        cols[4] = Column::right("share", 10);
        tables.push(Table {
            key: None,
            title: format!("\nanimated character assets/dancer.glb ({tris} triangles), clip `dance`\n"),
            columns: cols,
            rows: animated,
        });
    }
    if !shadows.is_empty() {
        tables.push(Table {
            key: None,
            title: format!("\nshadow scene {shadow_file}\n"),
            columns: columns("shadows ms", "fps", "no-shadows ms"),
            rows: shadows,
        });
    }
    if !glare.is_empty() {
        tables.push(Table {
            key: None,
            title: format!("\nglare scene {glare_file}\n"),
            columns: columns("bloom ms", "fps", "no-bloom ms"),
            rows: glare,
        });
    }
    if !mtoon.is_empty() {
        tables.push(Table {
            key: None,
            title: format!("\nMToon scene {mtoon_file}\n"),
            columns: columns("MToon ms", "fps", "toon ramp ms"),
            rows: mtoon,
        });
    }
    Ok(Report {
        fields: vec![
            ("table", "toon".into()),
            ("scene", file.into()),
            ("backend", backend.into()),
            ("method", method.into()),
            ("iterations", iterations.into()),
        ],
        tables,
    })
}
