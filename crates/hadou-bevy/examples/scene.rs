//! Opens a hadou scene file in Bevy: its camera, light, objects and waves, its tracks playing.
//!
//! ```text
//! cargo run --release --example scene -- SCENE.toml [--time T] [--screenshot OUT.png]
//!     [--tonemapping none|tony-mc-mapface|agx|aces] [--bloom] [--compare REF.png [--max-diff D]]
//! ```
//! `--time T` freezes the clock at `T` seconds; `--screenshot OUT.png` saves one frame (once the
//! scene has loaded and been drawn) and exits. The window has the scene's `[image]` size. The
//! scene's own colour mapping (`[color] mode`) maps the picture unless `--tonemapping` picks one of
//! Bevy's (`none` is Bevy's clamp).
//! `--compare REF.png` (with `--screenshot`) prints the mean absolute 8-bit difference of the
//! screenshot's RGB against a PNG of the same size (e.g. `hadou render`'s), and `--max-diff D`
//! makes a larger one exit with code 1.

use bevy::asset::RenderAssetUsages;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::image::{CompressedImageFormats, ImageSampler, ImageType};
use bevy::post_process::bloom::Bloom;
use bevy::prelude::*;
use bevy::render::view::screenshot::{save_to_disk, Screenshot, ScreenshotCaptured};
use bevy::render::RenderPlugin;
use bevy::window::WindowResolution;
use hadou_bevy::{HadouCamera, HadouPlugin, HadouSceneRoot, SceneClock, SpawnedScene, ViewMapping};
use std::path::PathBuf;
use std::process::ExitCode;

/// What the command line asked for.
#[derive(Resource, Clone)]
struct Options {
    scene: PathBuf,
    time: Option<f32>,
    screenshot: Option<PathBuf>,
    /// Bevy's tone mapping instead of the scene's colour mapping.
    tonemapping: Option<Tonemapping>,
    bloom: bool,
    compare: Option<PathBuf>,
    max_diff: Option<f64>,
}

const USAGE: &str = "usage: scene SCENE.toml [--time T] [--screenshot OUT.png] \
                     [--tonemapping none|tony-mc-mapface|agx|aces] [--bloom] [--compare REF.png [--max-diff D]]";

fn parse_args() -> Result<Options, String> {
    let mut args = std::env::args().skip(1);
    let mut options = Options {
        scene: PathBuf::new(),
        time: None,
        screenshot: None,
        tonemapping: None,
        bloom: false,
        compare: None,
        max_diff: None,
    };
    let mut scene = None;
    while let Some(arg) = args.next() {
        let mut value = |flag: &str| args.next().ok_or(format!("{flag} needs a value"));
        match arg.as_str() {
            "--time" => {
                let v = value("--time")?;
                let t: f32 = v.parse().map_err(|_| format!("--time: `{v}` is not a number"))?;
                if !t.is_finite() {
                    return Err(format!("--time: `{v}` is not finite"));
                }
                options.time = Some(t);
            }
            "--screenshot" => options.screenshot = Some(PathBuf::from(value("--screenshot")?)),
            "--tonemapping" => {
                options.tonemapping = Some(match value("--tonemapping")?.as_str() {
                    "none" => Tonemapping::None,
                    "tony-mc-mapface" => Tonemapping::TonyMcMapface,
                    "agx" => Tonemapping::AgX,
                    "aces" => Tonemapping::AcesFitted,
                    other => return Err(format!("--tonemapping: unknown `{other}`")),
                })
            }
            "--bloom" => options.bloom = true,
            "--compare" => options.compare = Some(PathBuf::from(value("--compare")?)),
            "--max-diff" => {
                let v = value("--max-diff")?;
                options.max_diff = Some(v.parse().map_err(|_| format!("--max-diff: `{v}` is not a number"))?);
            }
            _ if arg.starts_with("--") => return Err(format!("unknown flag `{arg}`")),
            _ if scene.is_none() => scene = Some(PathBuf::from(arg)),
            _ => return Err(format!("unexpected argument `{arg}`")),
        }
    }
    options.scene = scene.ok_or("no scene file given")?;
    if options.compare.is_some() && options.screenshot.is_none() {
        return Err("--compare needs --screenshot".into());
    }
    Ok(options)
}

fn main() -> ExitCode {
    let options = match parse_args() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("error: {e}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    // Read once here for the window's size (and a plain error message before any window opens).
    let scene = match hadou_scene::Scene::load(&options.scene) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    let path = std::path::absolute(&options.scene).unwrap_or_else(|_| options.scene.clone());
    let root = path.parent().map(PathBuf::from).unwrap_or_default();
    let window = Window {
        title: format!("hadou: {}", options.scene.display()),
        resolution: WindowResolution::new(scene.width(), scene.height()).with_scale_factor_override(1.0),
        resizable: false,
        ..default()
    };
    let exit = App::new()
        .add_plugins(
            DefaultPlugins
                .set(WindowPlugin { primary_window: Some(window), ..default() })
                .set(AssetPlugin { file_path: root.display().to_string(), ..default() })
                .set(RenderPlugin { synchronous_pipeline_compilation: true, ..default() }),
        )
        .add_plugins(HadouPlugin { asset_root: root })
        .insert_resource(options)
        .add_systems(Startup, spawn)
        .add_systems(Update, (style_camera, screenshot))
        .run();
    match exit {
        AppExit::Success => ExitCode::SUCCESS,
        AppExit::Error(_) => ExitCode::FAILURE,
    }
}

fn spawn(mut commands: Commands, assets: Res<AssetServer>, options: Res<Options>) {
    let file = options.scene.file_name().map(PathBuf::from).unwrap_or_default();
    let clock = options.time.map_or(SceneClock::Running, SceneClock::Frozen);
    commands.spawn(HadouSceneRoot { scene: assets.load(file), clock });
}

/// The command line's tone mapping and bloom on the scene's camera.
fn style_camera(
    mut commands: Commands,
    mut cameras: Query<(Entity, &mut HadouCamera), Added<HadouCamera>>,
    options: Res<Options>,
) {
    for (camera, mut settings) in &mut cameras {
        let mut camera = commands.entity(camera);
        if let Some(tonemapping) = options.tonemapping {
            settings.mapping = ViewMapping::Bevy;
            camera.insert(tonemapping);
        }
        if options.bloom {
            camera.insert(Bloom::NATURAL);
        }
    }
}

/// Frames drawn after the scene spawned before the screenshot is taken (the meshes' first
/// frames may still be preparing).
const SETTLE_FRAMES: u32 = 5;

fn screenshot(
    mut commands: Commands,
    options: Res<Options>,
    spawned: Query<&SpawnedScene>,
    mut frames: Local<u32>,
) {
    let Some(out) = &options.screenshot else { return };
    // Every object drawn with hadou's look (a glTF file loads asynchronously).
    if spawned.is_empty() || !spawned.iter().all(|s| s.ready) {
        return;
    }
    *frames += 1;
    if *frames == SETTLE_FRAMES {
        let mut save = save_to_disk(out.clone());
        let (compare, max_diff) = (options.compare.clone(), options.max_diff);
        commands.spawn(Screenshot::primary_window()).observe(
            move |captured: On<ScreenshotCaptured>, mut exit: MessageWriter<AppExit>| {
                let shot = captured.image.clone();
                save(captured);
                let Some(reference) = &compare else {
                    exit.write(AppExit::Success);
                    return;
                };
                match mean_difference(shot, reference) {
                    Ok((mean, max)) => {
                        println!(
                            "mean absolute 8-bit difference against {}: {mean:.3} (largest {max})",
                            reference.display()
                        );
                        let too_large = max_diff.is_some_and(|limit| mean > limit);
                        exit.write(if too_large { AppExit::error() } else { AppExit::Success });
                    }
                    Err(e) => {
                        eprintln!("error: --compare: {e}");
                        exit.write(AppExit::error());
                    }
                }
            },
        );
    }
}

/// The mean and the largest absolute difference of the 8-bit RGB values of `shot` and the PNG
/// at `reference` (alpha ignored), which must have the same size.
fn mean_difference(shot: Image, reference: &std::path::Path) -> Result<(f64, u8), String> {
    let bytes = std::fs::read(reference).map_err(|e| format!("{}: {e}", reference.display()))?;
    let reference = Image::from_buffer(
        &bytes,
        ImageType::Extension("png"),
        CompressedImageFormats::NONE,
        true,
        ImageSampler::Default,
        RenderAssetUsages::default(),
    )
    .map_err(|e| e.to_string())?;
    let a = shot.try_into_dynamic().map_err(|e| e.to_string())?.to_rgb8();
    let b = reference.try_into_dynamic().map_err(|e| e.to_string())?.to_rgb8();
    if a.dimensions() != b.dimensions() {
        return Err(format!("sizes differ: {:?} and {:?}", a.dimensions(), b.dimensions()));
    }
    let (mut sum, mut max) = (0u64, 0u8);
    for (x, y) in a.as_raw().iter().zip(b.as_raw()) {
        let d = x.abs_diff(*y);
        sum += u64::from(d);
        max = max.max(d);
    }
    Ok((sum as f64 / a.as_raw().len().max(1) as f64, max))
}
