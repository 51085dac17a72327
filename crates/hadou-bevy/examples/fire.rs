//! A small game: a toon character on a ground; Space fires a Kamehameha past it whose light sweeps
//! the character (its materials blend towards the wave's look, 000 §2.1) and whose shadow leans
//! away from the beam along the ground (the wave's stylized shadow, 000 §2.4, θ = 60°), bloomed
//! by Bevy.
//! Drag with the left mouse button (or the arrow keys) to orbit the camera, the wheel (or +/−)
//! to move in and out. The window's title and the log report the frame time.
//!
//! ```text
//! cargo run --release --manifest-path crates/hadou-bevy/Cargo.toml --example fire
//!     [-- [--time T] [--screenshot OUT.png]]
//! ```
//! `--time T` shows the shot `T` seconds after it was fired, frozen; `--screenshot OUT.png` saves
//! one frame and exits. The character, its materials and the beam come from
//! `scenes/light-normal-vs-wave.toml` (read with hadou-scene, spawned with
//! `hadou_bevy::spawn_object`); the firing is this example's own.

use bevy::diagnostic::{DiagnosticsStore, FrameTimeDiagnosticsPlugin};
use bevy::input::mouse::{AccumulatedMouseMotion, AccumulatedMouseScroll};
use bevy::post_process::bloom::Bloom;
use bevy::prelude::*;
use bevy::render::storage::ShaderBuffer;
use bevy::render::view::screenshot::{save_to_disk, Screenshot, ScreenshotCaptured};
use bevy::render::RenderPlugin;
use bevy::window::{PrimaryWindow, WindowResolution};
use hadou_bevy::{
    shadow_mask, spawn_object, HadouCamera, HadouMaterial, HadouOutline, HadouPlugin, HadouShadows,
    HadouWave, ObjectAssets, ViewMapping,
};
use hadou_scene::{Frame, Shadow, ShadowLight, ShadowMethod, WaveShape};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// How long the beam takes to reach its full length, seconds.
const FIRE_SECONDS: f32 = 1.2;
/// How long it then holds, seconds.
const HOLD_SECONDS: f32 = 1.5;
/// How long it takes to fade, seconds.
const FADE_SECONDS: f32 = 0.6;
/// The beam's full length.
const FULL_LENGTH: f32 = 6.5;
/// The longest-shadow angle θ of the beam's shadow, degrees from straight down.
const SHADOW_THETA_DEG: f32 = 60.0;
/// The shadow's opacity while the beam is at full strength.
const SHADOW_OPACITY: f32 = 0.75;

#[derive(Resource, Clone)]
struct Options {
    time: Option<f32>,
    screenshot: Option<PathBuf>,
}

/// The character's materials (whose `wave_blend` the shot drives) and the scene frame they came
/// from.
#[derive(Resource)]
struct Game {
    frame: Frame,
    /// Object, slot, the blend the shot takes it to, its material.
    materials: Vec<(usize, u32, f32, Handle<HadouMaterial>)>,
    beam: Entity,
    /// Seconds since Space was pressed, if it was.
    shot: Option<f32>,
}

/// The orbiting camera's yaw, pitch (radians) and distance around the target.
#[derive(Component)]
struct Orbit {
    target: Vec3,
    yaw: f32,
    pitch: f32,
    distance: f32,
}

fn parse_args() -> Result<Options, String> {
    let mut options = Options { time: None, screenshot: None };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = |flag: &str| args.next().ok_or(format!("{flag} needs a value"));
        match arg.as_str() {
            "--time" => {
                let v = value("--time")?;
                let t: f32 = v.parse().map_err(|_| format!("--time: `{v}` is not a number"))?;
                if !t.is_finite() || t < 0.0 {
                    return Err(format!("--time: `{v}` must be a finite number ≥ 0"));
                }
                options.time = Some(t);
            }
            "--screenshot" => options.screenshot = Some(PathBuf::from(value("--screenshot")?)),
            other => return Err(format!("unknown argument `{other}`")),
        }
    }
    Ok(options)
}

fn main() -> ExitCode {
    let options = match parse_args() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("error: {e}\nusage: fire [--time T] [--screenshot OUT.png]");
            return ExitCode::from(2);
        }
    };
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/light-normal-vs-wave.toml");
    let (frame, full) = match hadou_scene::Scene::load(&scene) {
        Ok(s) => (s.at(0.0), s.at(s.duration())),
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    let window = Window {
        title: "hadou: fire (Space)".into(),
        resolution: WindowResolution::new(960, 540).with_scale_factor_override(1.0),
        ..default()
    };
    let exit = App::new()
        .add_plugins(
            DefaultPlugins
                .set(WindowPlugin { primary_window: Some(window), ..default() })
                .set(RenderPlugin { synchronous_pipeline_compilation: true, ..default() }),
        )
        .add_plugins((HadouPlugin::default(), FrameTimeDiagnosticsPlugin::default()))
        .insert_resource(options)
        .insert_resource(StartFrame(frame, full))
        .add_systems(Startup, setup)
        .add_systems(Update, (fire, orbit, report_frame_time, screenshot))
        .run();
    match exit {
        AppExit::Success => ExitCode::SUCCESS,
        AppExit::Error(_) => ExitCode::FAILURE,
    }
}

/// The scene at its start, and at its end (whose `wave_blend`s the shot takes each material to).
#[derive(Resource)]
struct StartFrame(Frame, Frame);

fn setup(
    mut commands: Commands,
    start: Res<StartFrame>,
    options: Res<Options>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<HadouMaterial>>,
    mut outlines: ResMut<Assets<HadouOutline>>,
    mut buffers: ResMut<Assets<ShaderBuffer>>,
) {
    let mut frame = start.0.clone();
    let index =
        |name: &str| frame.objects.iter().position(|o| o.name == name).expect("the scene's objects") as u32;
    let (hero, ground) = (index("hero"), index("ground"));
    frame.shadows.push(Shadow {
        name: "beam".into(),
        light: ShadowLight::Wave { wave: 0, theta: SHADOW_THETA_DEG.to_radians() },
        method: ShadowMethod::Map { size: 2048 },
        up: hadou_math::Vec3f::new(0.0, 1.0, 0.0),
        casters: vec![hero],
        receivers: vec![ground],
        color: [0.02, 0.02, 0.08],
        opacity: 0.0,
    });
    let target = Vec3::new(0.0, 0.95, 0.0);
    let c = frame.background;
    commands.spawn((
        Camera3d::default(),
        Camera { clear_color: ClearColorConfig::Custom(Color::linear_rgb(c[0], c[1], c[2])), ..default() },
        bevy::camera::Hdr,
        bevy::render::view::Msaa::Off,
        Bloom::NATURAL,
        HadouCamera { mapping: ViewMapping::Hadou(frame.color_mapping.mode), ..default() },
        Orbit { target, yaw: 0.35, pitch: 0.12, distance: 5.6 },
        Transform::default(),
    ));
    let mut assets = ObjectAssets {
        meshes: &mut meshes,
        materials: &mut materials,
        outlines: &mut outlines,
        buffers: &mut buffers,
    };
    let mut handles = Vec::new();
    for (o, object) in frame.objects.iter().enumerate() {
        let mask = shadow_mask(&frame, o as u32);
        let (_, slots) = spawn_object(&mut commands, &mut assets, object, &frame.light, mask);
        let full = |s: usize| start.1.objects[o].material(s as u32).wave_blend;
        handles.extend(slots.into_iter().enumerate().map(|(s, h)| (o, s as u32, full(s), h)));
    }
    let mut beam = frame.waves[0].clone();
    beam.color[3] = 0.0;
    let beam = commands.spawn((Name::new("beam"), HadouWave::new(beam))).id();
    let shot = options.time;
    commands.insert_resource(Game { frame, materials: handles, beam, shot });
}

/// `x` eased in and out over `[0, 1]`.
fn smooth(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// The shot `t` seconds after Space: the beam's length and strength, the materials' blend.
fn shot_at(t: f32) -> (f32, f32, f32) {
    let grow = smooth(t / FIRE_SECONDS);
    let fade = 1.0 - smooth((t - FIRE_SECONDS - HOLD_SECONDS) / FADE_SECONDS);
    let strength = smooth(t / 0.15) * fade;
    (FULL_LENGTH * grow, strength, smooth(t / 0.5) * fade)
}

fn fire(
    keys: Res<ButtonInput<KeyCode>>,
    time: Res<Time>,
    options: Res<Options>,
    mut game: ResMut<Game>,
    mut waves: Query<&mut HadouWave>,
    mut materials: ResMut<Assets<HadouMaterial>>,
    mut shadows: ResMut<HadouShadows>,
) {
    if options.time.is_none() {
        if keys.just_pressed(KeyCode::Space) {
            game.shot = Some(0.0);
        } else if let Some(t) = &mut game.shot {
            *t += time.delta_secs();
        }
    }
    let t = game.shot.unwrap_or(f32::INFINITY);
    let (length, strength, blend) = shot_at(t);
    if let Ok(mut wave) = waves.get_mut(game.beam) {
        if let WaveShape::Beam(b) = &mut wave.wave.shape {
            b.capsule.length = length;
        }
        wave.wave.color[3] = strength;
        // The shadow follows the beam: its light line and strength.
        let mut frame = game.frame.clone();
        frame.waves[0] = wave.wave.clone();
        frame.shadows[0].opacity = SHADOW_OPACITY * strength;
        shadows.frame = Some(frame);
    }
    let Game { frame, materials: handles, .. } = &*game;
    for (o, s, full, handle) in handles {
        let mut material = frame.objects[*o].material(*s).clone();
        material.wave_blend = blend * full;
        let changed = materials.get(handle).is_some_and(|m| m.clone().update(&material, &frame.light));
        if changed {
            if let Some(mut m) = materials.get_mut(handle) {
                m.update(&material, &frame.light);
            }
        }
    }
}

fn orbit(
    buttons: Res<ButtonInput<MouseButton>>,
    keys: Res<ButtonInput<KeyCode>>,
    motion: Res<AccumulatedMouseMotion>,
    scroll: Res<AccumulatedMouseScroll>,
    time: Res<Time>,
    mut cameras: Query<(&mut Orbit, &mut Transform)>,
) {
    let dt = time.delta_secs();
    for (mut o, mut transform) in &mut cameras {
        if buttons.pressed(MouseButton::Left) {
            o.yaw -= motion.delta.x * 0.005;
            o.pitch += motion.delta.y * 0.005;
        }
        let key = |k: KeyCode| if keys.pressed(k) { 1.0 } else { 0.0 };
        o.yaw += (key(KeyCode::ArrowLeft) - key(KeyCode::ArrowRight)) * 1.5 * dt;
        o.pitch += (key(KeyCode::ArrowUp) - key(KeyCode::ArrowDown)) * 1.0 * dt;
        o.distance *= (1.0 - scroll.delta.y * 0.1) * (1.0 + (key(KeyCode::Minus) - key(KeyCode::Equal)) * dt);
        o.pitch = o.pitch.clamp(-0.2, 1.4);
        o.distance = o.distance.clamp(1.5, 30.0);
        let offset = Vec3::new(o.yaw.sin() * o.pitch.cos(), o.pitch.sin(), o.yaw.cos() * o.pitch.cos());
        *transform =
            Transform::from_translation(o.target + offset * o.distance).looking_at(o.target, Vec3::Y);
    }
}

/// The smoothed frame time in the window's title, and in the log every two seconds.
fn report_frame_time(
    diagnostics: Res<DiagnosticsStore>,
    time: Res<Time>,
    mut window: Query<&mut Window, With<PrimaryWindow>>,
    mut last: Local<f32>,
) {
    let Some(ms) = diagnostics.get(&FrameTimeDiagnosticsPlugin::FRAME_TIME).and_then(|d| d.smoothed()) else {
        return;
    };
    if let Ok(mut window) = window.single_mut() {
        window.title = format!("hadou: fire (Space) — {ms:.1} ms a frame");
    }
    if time.elapsed_secs() - *last >= 2.0 {
        *last = time.elapsed_secs();
        info!("frame time {ms:.2} ms ({:.0} frames/s)", 1000.0 / ms.max(1e-3));
    }
}

/// Frames drawn before the screenshot (the meshes' first frames may still be preparing).
const SETTLE_FRAMES: u32 = 5;

fn screenshot(mut commands: Commands, options: Res<Options>, mut frames: Local<u32>) {
    let Some(out) = &options.screenshot else { return };
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
