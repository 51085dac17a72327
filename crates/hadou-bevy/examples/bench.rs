//! The wave pass inside Bevy against the same pass in hadou-gpu alone, on the same adapter, in one
//! run: a table (or `--json`).
//!
//! ```text
//! cargo run --release --manifest-path crates/hadou-bevy/Cargo.toml --example bench -- \
//!     [--json] [--frames N] [--width W --height H] [SCENE.toml@T ...]
//! ```
//! Per scene (default: kamehameha at t = 1.5 and spiral-drill at t = 2,
//! each at its `[image]` size unless `--width`/`--height` are given):
//! - **alone**: `GpuBackend::time_wave_overlay`, hadou-gpu on its own device drawing the frame's
//!   waves into an `Rgba16Float` target against a cleared depth buffer, each draw encoded,
//!   submitted and waited for (wall clock, median of N);
//! - **in Bevy**: a windowless Bevy app whose camera (the scene's, with `Hdr`, `Msaa::Off` and a
//!   `HadouCamera` with hadou's colour mapping) renders into an image of the same size, the
//!   frame's waves as `HadouWave`s and nothing else drawn; each `App::update` is followed by a wait
//!   for Bevy's device to go idle, and timed. Frames with the waves on and off alternate in blocks
//!   of five; the pass's cost in Bevy is the median frame with them on minus the median frame with
//!   them off (the clear, the tone mapping and Bevy's own work cancel).
//!
//! The ratio `in Bevy / alone` is what the issue's bound (≤ 1.2) is about.

mod common;

use bevy::camera::RenderTarget;
use bevy::image::Image;
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use common::{camera, json_string, median, whole_number, windowless_plugins, FrameClock};
use hadou_bevy::{HadouCamera, HadouPlugin, HadouWave, ViewMapping};
use hadou_gpu::GpuBackend;
use hadou_scene::Frame;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

struct Options {
    json: bool,
    frames: u32,
    size: Option<(u32, u32)>,
    scenes: Vec<(PathBuf, f32)>,
}

const USAGE: &str = "usage: bench [--json] [--frames N] [--width W --height H] [SCENE.toml@T ...]";

fn parse_args() -> Result<Options, String> {
    let mut o = Options { json: false, frames: 20, size: None, scenes: Vec::new() };
    let (mut width, mut height) = (None, None);
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--json" => o.json = true,
            "--frames" => o.frames = whole_number("--frames", args.next())?,
            "--width" => width = Some(whole_number("--width", args.next())?),
            "--height" => height = Some(whole_number("--height", args.next())?),
            _ if arg.starts_with("--") => return Err(format!("unknown flag `{arg}`")),
            _ => {
                let (file, t) = arg.rsplit_once('@').ok_or(format!("`{arg}`: give SCENE.toml@TIME"))?;
                let t: f32 = t.parse().map_err(|_| format!("`{arg}`: `{t}` is not a time"))?;
                if !t.is_finite() {
                    return Err(format!("`{arg}`: the time must be finite"));
                }
                o.scenes.push((PathBuf::from(file), t));
            }
        }
    }
    o.size = match (width, height) {
        (Some(w), Some(h)) => Some((w, h)),
        (None, None) => None,
        _ => return Err("--width and --height go together".into()),
    };
    if o.scenes.is_empty() {
        let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        o.scenes = vec![(scenes.join("kamehameha.toml"), 1.5), (scenes.join("spiral-drill.toml"), 2.0)];
    }
    Ok(o)
}

/// One scene's measurement.
struct Row {
    scene: String,
    time: f32,
    size: (u32, u32),
    waves: usize,
    alone_ms: f64,
    on_ms: f64,
    off_ms: f64,
}

impl Row {
    fn in_bevy_ms(&self) -> f64 {
        (self.on_ms - self.off_ms).max(0.0)
    }

    fn ratio(&self) -> f64 {
        self.in_bevy_ms() / self.alone_ms.max(1e-9)
    }
}

/// Median frame times (ms) of a Bevy app drawing `frame`'s waves, with them on and off.
fn time_in_bevy(frame: &Frame, frames: u32) -> (f64, f64) {
    let mut app = App::new();
    // One app per scene; the first would own the global logger.
    app.add_plugins(windowless_plugins().disable::<bevy::log::LogPlugin>())
        .add_plugins(HadouPlugin::default());
    let image = Image::new_target_texture(frame.width, frame.height, TextureFormat::Rgba8UnormSrgb, None);
    let image = app.world_mut().resource_mut::<Assets<Image>>().add(image);
    let (transform, projection) = camera(frame);
    app.world_mut().spawn((
        Camera3d::default(),
        RenderTarget::Image(image.into()),
        bevy::camera::Hdr,
        bevy::render::view::Msaa::Off,
        HadouCamera {
            exposure: frame.color_mapping.exposure,
            far: frame.camera.far,
            mapping: ViewMapping::Hadou(frame.color_mapping.mode),
        },
        transform,
        projection,
    ));
    let waves: Vec<Entity> =
        frame.waves.iter().map(|w| app.world_mut().spawn(HadouWave::new(w.clone())).id()).collect();
    app.finish();
    app.cleanup();
    let clock = FrameClock::new(&app);
    let frame_ms = |app: &mut App| clock.frame_ms(app);
    let set = |app: &mut App, on: bool| {
        for &w in &waves {
            app.world_mut().get_mut::<HadouWave>(w).unwrap().enabled = on;
        }
    };
    // Warm-up: pipelines, the first uploads.
    for _ in 0..10 {
        frame_ms(&mut app);
    }
    let (mut on, mut off) = (Vec::new(), Vec::new());
    while on.len() < frames as usize {
        set(&mut app, true);
        frame_ms(&mut app); // the change lands
        for _ in 0..5 {
            on.push(frame_ms(&mut app));
        }
        set(&mut app, false);
        frame_ms(&mut app);
        for _ in 0..5 {
            off.push(frame_ms(&mut app));
        }
    }
    (median(&on), median(&off))
}

fn main() -> ExitCode {
    let options = match parse_args() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("error: {e}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    let mut backend = match GpuBackend::new() {
        Ok(b) => b,
        Err(e) => {
            eprintln!("error: no GPU adapter for hadou-gpu: {e}");
            return ExitCode::FAILURE;
        }
    };
    let adapter = backend.adapter_name().to_string();
    let mut rows = Vec::new();
    for (path, time) in &options.scenes {
        let scene = match hadou_scene::Scene::load(path) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::from(2);
            }
        };
        let mut frame = scene.at(*time);
        if let Some((w, h)) = options.size {
            (frame.width, frame.height) = (w, h);
        }
        if !options.json {
            eprintln!("timing {} at t = {time} ({}×{})…", path.display(), frame.width, frame.height);
        }
        let alone = match backend.time_wave_overlay(&frame, options.frames) {
            Ok(t) => t.median_ms,
            Err(e) => {
                eprintln!("error: {}: {e}", path.display());
                return ExitCode::FAILURE;
            }
        };
        let (on_ms, off_ms) = time_in_bevy(&frame, options.frames);
        let name = path.file_name().map_or(String::new(), |n| n.to_string_lossy().into_owned());
        rows.push(Row {
            scene: name,
            time: *time,
            size: (frame.width, frame.height),
            waves: frame.waves.len(),
            alone_ms: alone,
            on_ms,
            off_ms,
        });
    }
    if options.json {
        let rows: Vec<String> = rows
            .iter()
            .map(|r| {
                format!(
                    "{{\"scene\":{},\"time\":{},\"width\":{},\"height\":{},\"waves\":{},\"alone_ms\":{:.4},\
                     \"bevy_frame_on_ms\":{:.4},\"bevy_frame_off_ms\":{:.4},\"in_bevy_ms\":{:.4},\"ratio\":{:.4}}}",
                    json_string(&r.scene),
                    r.time,
                    r.size.0,
                    r.size.1,
                    r.waves,
                    r.alone_ms,
                    r.on_ms,
                    r.off_ms,
                    r.in_bevy_ms(),
                    r.ratio()
                )
            })
            .collect();
        println!(
            "{{\"adapter\":{},\"frames\":{},\"rows\":[{}]}}",
            json_string(&adapter),
            options.frames,
            rows.join(",")
        );
    } else {
        println!(
            "wave pass: hadou-gpu alone vs inside Bevy, adapter {adapter}, median of {} frames",
            options.frames
        );
        println!(
            "{:<26} {:>5} {:>10} {:>5} {:>10} {:>12} {:>12} {:>11} {:>6}",
            "scene", "t", "size", "waves", "alone ms", "Bevy on ms", "Bevy off ms", "in Bevy ms", "ratio"
        );
        for r in &rows {
            println!(
                "{:<26} {:>5} {:>10} {:>5} {:>10.2} {:>12.2} {:>12.2} {:>11.2} {:>6.2}",
                r.scene,
                r.time,
                format!("{}×{}", r.size.0, r.size.1),
                r.waves,
                r.alone_ms,
                r.on_ms,
                r.off_ms,
                r.in_bevy_ms(),
                r.ratio()
            );
        }
    }
    ExitCode::SUCCESS
}
