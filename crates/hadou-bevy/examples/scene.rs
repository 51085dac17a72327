//! Opens a hadou scene file in Bevy: its camera, light, objects and waves, its tracks playing.
//!
//! ```text
//! cargo run --release --example scene -- SCENE.toml [--time T] [--screenshot OUT.png]
//!     [--tonemapping none|tony-mc-mapface|agx|aces] [--bloom]
//! ```
//! `--time T` freezes the clock at `T` seconds; `--screenshot OUT.png` saves one frame (once the
//! scene has loaded and been drawn) and exits. The window has the scene's `[image]` size.

use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::post_process::bloom::Bloom;
use bevy::prelude::*;
use bevy::render::view::screenshot::{save_to_disk, Screenshot, ScreenshotCaptured};
use bevy::render::RenderPlugin;
use bevy::window::WindowResolution;
use hadou_bevy::{HadouCamera, HadouPlugin, HadouSceneRoot, SceneClock, SpawnedScene};
use std::path::PathBuf;
use std::process::ExitCode;

/// What the command line asked for.
#[derive(Resource, Clone)]
struct Options {
    scene: PathBuf,
    time: Option<f32>,
    screenshot: Option<PathBuf>,
    tonemapping: Tonemapping,
    bloom: bool,
}

const USAGE: &str = "usage: scene SCENE.toml [--time T] [--screenshot OUT.png] \
                     [--tonemapping none|tony-mc-mapface|agx|aces] [--bloom]";

fn parse_args() -> Result<Options, String> {
    let mut args = std::env::args().skip(1);
    let mut options = Options {
        scene: PathBuf::new(),
        time: None,
        screenshot: None,
        tonemapping: Tonemapping::TonyMcMapface,
        bloom: false,
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
                options.tonemapping = match value("--tonemapping")?.as_str() {
                    "none" => Tonemapping::None,
                    "tony-mc-mapface" => Tonemapping::TonyMcMapface,
                    "agx" => Tonemapping::AgX,
                    "aces" => Tonemapping::AcesFitted,
                    other => return Err(format!("--tonemapping: unknown `{other}`")),
                }
            }
            "--bloom" => options.bloom = true,
            _ if arg.starts_with("--") => return Err(format!("unknown flag `{arg}`")),
            _ if scene.is_none() => scene = Some(PathBuf::from(arg)),
            _ => return Err(format!("unexpected argument `{arg}`")),
        }
    }
    options.scene = scene.ok_or("no scene file given")?;
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
fn style_camera(mut commands: Commands, cameras: Query<Entity, Added<HadouCamera>>, options: Res<Options>) {
    for camera in &cameras {
        let mut camera = commands.entity(camera);
        camera.insert(options.tonemapping);
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
    spawned: Query<(), With<SpawnedScene>>,
    mut frames: Local<u32>,
) {
    let Some(out) = &options.screenshot else { return };
    if spawned.is_empty() {
        return;
    }
    *frames += 1;
    if *frames == SETTLE_FRAMES {
        let mut save = save_to_disk(out.clone());
        commands.spawn(Screenshot::primary_window()).observe(
            move |captured: On<ScreenshotCaptured>, mut exit: MessageWriter<AppExit>| {
                save(captured);
                exit.write(AppExit::Success);
            },
        );
    }
}
