//! A game's load: many animated characters in hadou's look, waves firing around them, shadows on;
//! the frame time and hadou's share of it, and hadou's passes inside Bevy against the same passes
//! in hadou-gpu alone, in one run: a table (or `--json`).
//!
//! ```text
//! cargo run --manifest-path crates/hadou-bevy/Cargo.toml --example stress -- \
//!     [--json] [--frames N] [--width W --height H] [--characters C] [--waves K]
//! ```
//! The load (defaults: 20 characters, 8 waves, 640×360, 30 frames a measurement, rounded up to
//! whole blocks of five): the character
//! of `scenes/light-brace.toml` (`assets/brace.glb`), loaded C times by Bevy's glTF loader, each
//! playing the file's `brace` clip on repeat with Bevy's `AnimationPlayer`, character `i` at
//! phase `i / C` of the clip, drawn with `HadouShaded` (the file's materials in hadou's look, with
//! outlines) in a grid on the scene's ground; K copies of the scene's beam placed on a circle
//! around the grid, each firing along the circle's tangent and growing from nothing to its full
//! length every [`FIRE_SECONDS`] (at phase `k / K`) while the circle turns; shadows on: the sun's
//! (`[light]`'s direction, every character onto the ground, a map of [`SUN_MAP`]²) and the first
//! wave's stylized shadow (000 §2.4, θ = 60°, every character onto the ground, maps of
//! [`WAVE_MAP`]²), set in `HadouShadows` each frame. Simulated time advances 1/30 s a frame.
//!
//! The camera has Bevy's depth prepass (`DepthPrepass`), as a game drawing many characters in
//! materials with many lights would: each pixel's material is then shaded once, not once for
//! every character drawn over it; `--no-prepass` measures without it.
//!
//! Measured, each frame an `App::update` followed by a wait for Bevy's device to go idle (wall
//! clock), in blocks of five frames (after one that lets the change land) alternating between:
//! - **hadou**: all of the above;
//! - **passes off**: the waves disabled (`HadouWave::enabled`) and `HadouShadows.frame = None`,
//!   the characters and the ground still in hadou's materials;
//! - **Bevy only**: as *passes off*, and every mesh back on its `StandardMaterial` (the glTF
//!   file's own for the characters, the ground's colour for the ground) with the outlines hidden:
//!   the same app drawing the same animated meshes with none of hadou's work.
//!
//! Reported: the frame time with hadou (median and 90th percentile); hadou's share, `(hadou −
//! Bevy only) / hadou` of the medians; hadou's passes in Bevy, `hadou − passes off` of the
//! medians (the wave pass, the shadow-map pass, their preparation on the CPU, and the waves' light
//! and the shadows' lookups in hadou's materials); and the same passes alone: hadou-gpu on its own
//! device (`GpuBackend::new`) drawing each measured frame's shadow maps
//! (`encode_shadow_maps_into`) and wave pass (`encode_wave_overlay`, `Rgba16Float` colour, a
//! cleared reverse-Z depth buffer), one submission waited for a frame (median). The ratio
//! `in Bevy / alone` is what issue 45's bound (≤ 1.2) is about. The passes alone lack what the
//! waves and shadows cost in the shading of the characters and the ground (their light and the
//! shadows' lookups), which the figure in Bevy holds; so the same work is also timed in whole
//! frames: hadou-gpu rendering each measured frame (one sample, characters, ground, waves and
//! shadows; `Backend::render`, read back) against the same frame without its waves and shadows,
//! the difference of the medians (`whole frames`, and `in Bevy / whole frames`).

mod common;

use bevy::animation::graph::{AnimationGraph, AnimationGraphHandle, AnimationNodeIndex};
use bevy::animation::{AnimationClip, AnimationPlayer};
use bevy::asset::AssetPlugin;
use bevy::camera::RenderTarget;
use bevy::gltf::GltfAssetLabel;
use bevy::image::Image;
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use bevy::render::storage::ShaderBuffer;
use bevy::time::TimeUpdateStrategy;
use bevy::world_serialization::WorldAssetRoot;
use common::{camera, json_string, median, quantile, whole_number, windowless_plugins, FrameClock};
use hadou_bevy::{
    shadow_frame, shadow_mask, shadow_records, spawn_object, HadouCamera, HadouMaterial, HadouOutline,
    HadouPlugin, HadouShaded, HadouShadows, HadouWave, ObjectAssets, ViewMapping,
};
use hadou_gpu::{DepthModel, GpuBackend, OverlayBlend, OverlayProjection, OverlayTarget};
use hadou_math::{Mat4, Vec3f};
use hadou_scene::{Backend, Frame, Shadow, ShadowLight, ShadowMethod, Wave, WaveShape};
use std::collections::HashMap;
use std::path::Path;
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// The simulated time of one frame, seconds.
const FRAME_SECONDS: f32 = 1.0 / 30.0;
/// How long a beam takes to grow from nothing to its full length, seconds (then it starts again).
const FIRE_SECONDS: f32 = 1.6;
/// A beam's full length.
const FULL_LENGTH: f32 = 6.0;
/// The radius of the circle the beams' muzzles stand on.
const RING_RADIUS: f32 = 6.0;
/// How fast the circle turns, radians a second.
const RING_TURN: f32 = 0.25;
/// The length of the `brace` clip of `assets/brace.glb`, seconds.
const CLIP_SECONDS: f32 = 2.0;
/// The edge of the sun shadow's map, texels.
const SUN_MAP: u32 = 1024;
/// The edge of each of the wave shadow's maps, texels.
const WAVE_MAP: u32 = 512;
/// The distance between neighbouring characters of the grid.
const SPACING: f32 = 1.5;
/// Characters a grid row holds.
const ROW: u32 = 5;
/// Updates allowed for the characters to load and take hadou's look before giving up.
const LOAD_UPDATES: u32 = 1200;

const USAGE: &str =
    "usage: stress [--json] [--frames N] [--width W --height H] [--characters C] [--waves K] [--no-prepass]";

#[derive(Clone, Debug)]
struct Options {
    json: bool,
    frames: u32,
    size: (u32, u32),
    characters: u32,
    waves: u32,
    /// Bevy's depth prepass on the camera (the default; `--no-prepass` leaves it off).
    prepass: bool,
}

fn parse_args() -> Result<Options, String> {
    let mut o =
        Options { json: false, frames: 30, size: (640, 360), characters: 20, waves: 8, prepass: true };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--json" => o.json = true,
            "--frames" => o.frames = whole_number("--frames", args.next())?,
            "--width" => o.size.0 = whole_number("--width", args.next())?,
            "--height" => o.size.1 = whole_number("--height", args.next())?,
            "--characters" => o.characters = whole_number("--characters", args.next())?,
            "--waves" => o.waves = whole_number("--waves", args.next())?,
            "--no-prepass" => o.prepass = false,
            _ => return Err(format!("unknown argument `{arg}`")),
        }
    }
    if o.characters > 100 {
        return Err(format!("--characters: {} is more than 100", o.characters));
    }
    if o.waves > 32 {
        return Err(format!("--waves: {} is more than 32", o.waves));
    }
    Ok(o)
}

/// `x` eased in and out over `[0, 1]`.
fn smooth(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// Where character `i` of `n` stands: a grid of [`ROW`] a row, centred on the origin.
fn grid_position(i: u32, n: u32) -> Vec3f {
    let (cols, rows) = (ROW.min(n), n.div_ceil(ROW));
    let (c, r) = (i % ROW, i / ROW);
    Vec3f::new(
        (c as f32 - 0.5 * (cols - 1) as f32) * SPACING,
        0.0,
        (r as f32 - 0.5 * (rows - 1) as f32) * SPACING,
    )
}

/// The `count` beams at time `t`: copies of `beam` on a circle around the grid, each firing
/// along the circle's tangent, growing to [`FULL_LENGTH`] every [`FIRE_SECONDS`] at its phase.
fn waves_at(beam: &Wave, count: u32, t: f32) -> Vec<Wave> {
    (0..count)
        .map(|k| {
            let phase = k as f32 / count as f32;
            let angle = std::f32::consts::TAU * phase + RING_TURN * t;
            let mut wave = beam.clone();
            wave.name = format!("beam-{k}");
            if let WaveShape::Beam(b) = &mut wave.shape {
                let height = 0.8 + 0.3 * (k % 3) as f32;
                b.capsule.m = Vec3f::new(RING_RADIUS * angle.cos(), height, RING_RADIUS * angle.sin());
                b.capsule.d = Vec3f::new(-angle.sin(), 0.0, angle.cos());
                b.capsule.length = FULL_LENGTH * smooth((t / FIRE_SECONDS + phase).fract() / 0.8);
            }
            wave
        })
        .collect()
}

/// The load as a hadou frame: the characters (at rest, as hadou reads the file), the ground, the
/// camera, the shadows; its waves are [`waves_at`]'s.
struct Load {
    frame: Frame,
    beam: Wave,
    ground: usize,
}

impl Load {
    fn new(options: &Options) -> Result<Load, String> {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/light-brace.toml");
        let scene = hadou_scene::Scene::load(&path).map_err(|e| e.to_string())?;
        let base = scene.at(0.0);
        let find = |name: &str| {
            base.objects
                .iter()
                .find(|o| o.name == name)
                .cloned()
                .ok_or(format!("{}: no object `{name}`", path.display()))
        };
        let (hero, ground) = (find("hero")?, find("ground")?);
        let beam = base.waves.first().cloned().ok_or(format!("{}: no wave", path.display()))?;
        let mut frame = base.clone();
        (frame.width, frame.height) = options.size;
        frame.objects = (0..options.characters)
            .map(|i| {
                let mut o = hero.clone();
                o.name = format!("hero-{i}");
                let yaw = 360.0 * i as f32 / options.characters as f32;
                o.transform = Mat4::from_trs(
                    grid_position(i, options.characters),
                    Vec3f::new(0.0, yaw, 0.0),
                    Vec3f::new(1.0, 1.0, 1.0),
                );
                o
            })
            .collect();
        frame.objects.push(ground);
        let ground = frame.objects.len() - 1;
        let casters: Vec<u32> = (0..options.characters).collect();
        let shadow = |name: &str, light, size| Shadow {
            name: name.into(),
            light,
            method: ShadowMethod::Map { size },
            up: Vec3f::new(0.0, 1.0, 0.0),
            casters: casters.clone(),
            receivers: vec![ground as u32],
            color: [0.02, 0.02, 0.08],
            opacity: 0.6,
        };
        let sun = frame.light.direction.normalize_or(Vec3f::new(0.0, -1.0, 0.0));
        frame.shadows = vec![
            shadow("sun", ShadowLight::Sun(sun), SUN_MAP),
            shadow("beam-0", ShadowLight::Wave { wave: 0, theta: 60f32.to_radians() }, WAVE_MAP),
        ];
        frame.camera.position = Vec3f::new(0.0, 5.5, 11.0);
        frame.camera.target = Vec3f::new(0.0, 0.7, 0.0);
        frame.camera.fov_y_deg = 45.0;
        frame.waves = waves_at(&beam, options.waves, 0.0);
        Ok(Load { frame, beam, ground })
    }

    /// The frame at time `t`: the waves moved.
    fn at(&self, options: &Options, t: f32) -> Frame {
        let mut frame = self.frame.clone();
        frame.time = t;
        frame.waves = waves_at(&self.beam, options.waves, t);
        frame
    }
}

/// What a measurement switches on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Mode {
    /// Everything of hadou.
    Hadou,
    /// No waves, no shadows; hadou's materials.
    PassesOff,
    /// No waves, no shadows, Bevy's `StandardMaterial`s, no outlines.
    BevyOnly,
}

/// The state the app's systems read.
#[derive(Resource)]
struct Stress {
    options: Options,
    load: Load,
    mode: Mode,
    /// The graph playing the clip, and the clip's node in it.
    clip: Option<(Handle<AnimationGraph>, AnimationNodeIndex)>,
    waves: Vec<Entity>,
    /// Each character mesh's `StandardMaterial` from the glTF loader, by mesh entity.
    standard: HashMap<Entity, Handle<StandardMaterial>>,
    /// Players started (the file has more than one animated root: several a character).
    playing: u32,
}

/// Which character a glTF root is.
#[derive(Component)]
struct Character(u32);

#[allow(clippy::too_many_arguments)] // a Bevy system's parameters
fn setup(
    mut commands: Commands,
    mut stress: ResMut<Stress>,
    asset_server: Res<AssetServer>,
    mut images: ResMut<Assets<Image>>,
    mut graphs: ResMut<Assets<AnimationGraph>>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<HadouMaterial>>,
    mut outlines: ResMut<Assets<HadouOutline>>,
    mut buffers: ResMut<Assets<ShaderBuffer>>,
) {
    let frame = stress.load.frame.clone();
    let image = Image::new_target_texture(frame.width, frame.height, TextureFormat::Rgba8UnormSrgb, None);
    let (transform, projection) = camera(&frame);
    let c = frame.background;
    let view = commands
        .spawn((
            Camera3d::default(),
            Camera {
                clear_color: ClearColorConfig::Custom(Color::linear_rgb(c[0], c[1], c[2])),
                ..default()
            },
            RenderTarget::Image(images.add(image).into()),
            bevy::camera::Hdr,
            bevy::render::view::Msaa::Off,
            HadouCamera {
                exposure: frame.color_mapping.exposure,
                far: frame.camera.far,
                mapping: ViewMapping::Hadou(frame.color_mapping.mode),
            },
            transform,
            projection,
        ))
        .id();
    if stress.options.prepass {
        // Bevy shades each pixel once: the depth of every opaque mesh first, then the materials.
        commands.entity(view).insert(bevy::core_pipeline::prepass::DepthPrepass);
    }
    // Bevy's light, for the `StandardMaterial`s of the "Bevy only" frames.
    let l = frame.light.direction;
    commands.spawn((
        DirectionalLight { illuminance: 8000.0, ..default() },
        Transform::default().looking_to(Vec3::new(l.x, l.y, l.z), Vec3::Y),
    ));
    let clip: Handle<AnimationClip> =
        asset_server.load(GltfAssetLabel::Animation(0).from_asset("assets/brace.glb"));
    let (graph, node) = AnimationGraph::from_clip(clip);
    stress.clip = Some((graphs.add(graph), node));
    let scene = asset_server.load(GltfAssetLabel::Scene(0).from_asset("assets/brace.glb"));
    for (i, object) in frame.objects.iter().enumerate().take(stress.options.characters as usize) {
        let shaded = HadouShaded {
            slots: object.materials.clone(),
            ..HadouShaded::new(object.material(0).clone(), frame.light, shadow_mask(&frame, i as u32))
        };
        commands.spawn((
            Name::new(object.name.clone()),
            Character(i as u32),
            Transform::from_matrix(bevy::math::Mat4::from_cols_array_2d(&object.transform.cols)),
            WorldAssetRoot(scene.clone()),
            shaded,
        ));
    }
    let mut assets = ObjectAssets {
        meshes: &mut meshes,
        materials: &mut materials,
        outlines: &mut outlines,
        buffers: &mut buffers,
    };
    let ground = stress.load.ground;
    spawn_object(
        &mut commands,
        &mut assets,
        &frame.objects[ground],
        &frame.light,
        shadow_mask(&frame, ground as u32),
    );
    stress.waves = frame.waves.iter().map(|w| commands.spawn(HadouWave::new(w.clone())).id()).collect();
}

/// Keeps each glTF mesh's `StandardMaterial` (before `HadouShaded` swaps it) for the "Bevy only"
/// frames.
fn keep_standard(mut stress: ResMut<Stress>, meshes: Query<(Entity, &MeshMaterial3d<StandardMaterial>)>) {
    for (entity, material) in &meshes {
        stress.standard.entry(entity).or_insert_with(|| material.0.clone());
    }
}

/// Starts each character's clip at its phase once its `AnimationPlayer` appears.
fn start_clips(
    mut commands: Commands,
    mut stress: ResMut<Stress>,
    mut players: Query<(Entity, &mut AnimationPlayer), Added<AnimationPlayer>>,
    parents: Query<&ChildOf>,
    characters: Query<&Character>,
) {
    for (entity, mut player) in &mut players {
        let Some(i) = parents.iter_ancestors(entity).find_map(|a| characters.get(a).ok().map(|c| c.0)) else {
            continue;
        };
        let Some((graph, node)) = stress.clip.clone() else { continue };
        let phase = CLIP_SECONDS * i as f32 / stress.options.characters as f32;
        player.play(node).repeat().seek_to(phase);
        commands.entity(entity).insert(AnimationGraphHandle(graph));
        stress.playing += 1;
    }
}

/// Moves the waves and sets the shadows' frame, every frame.
fn fire(
    stress: Res<Stress>,
    time: Res<Time>,
    mut waves: Query<&mut HadouWave>,
    mut shadows: ResMut<HadouShadows>,
) {
    let frame = stress.load.at(&stress.options, time.elapsed_secs());
    let on = stress.mode == Mode::Hadou;
    for (&entity, wave) in stress.waves.iter().zip(&frame.waves) {
        if let Ok(mut w) = waves.get_mut(entity) {
            w.wave = wave.clone();
            w.enabled = on;
        }
    }
    shadows.frame = on.then_some(frame);
}

/// Switches every mesh between hadou's materials and the `StandardMaterial`s, and the outlines
/// on and off, for `mode`.
fn set_materials(
    app: &mut App,
    mode: Mode,
    hadou: &HashMap<Entity, Handle<HadouMaterial>>,
    ground: &Handle<StandardMaterial>,
) {
    let standard = app.world().resource::<Stress>().standard.clone();
    let world = app.world_mut();
    for (&entity, handle) in hadou {
        let mut e = world.entity_mut(entity);
        if mode == Mode::BevyOnly {
            e.remove::<MeshMaterial3d<HadouMaterial>>()
                .insert(MeshMaterial3d(standard.get(&entity).unwrap_or(ground).clone()));
        } else {
            e.remove::<MeshMaterial3d<StandardMaterial>>().insert(MeshMaterial3d(handle.clone()));
        }
    }
    let hulls: Vec<Entity> =
        world.query_filtered::<Entity, With<MeshMaterial3d<HadouOutline>>>().iter(world).collect();
    let visibility = if mode == Mode::BevyOnly { Visibility::Hidden } else { Visibility::Inherited };
    for hull in hulls {
        world.entity_mut(hull).insert(visibility);
    }
    world.resource_mut::<Stress>().mode = mode;
}

/// One run's figures, milliseconds.
struct Report {
    adapter: String,
    frames: usize,
    hadou: Vec<f64>,
    passes_off: Vec<f64>,
    bevy_only: Vec<f64>,
    alone: Vec<f64>,
    alone_waves: Vec<f64>,
    alone_shadows: Vec<f64>,
    /// hadou-gpu's whole frames with the waves and shadows, and without.
    whole: Vec<f64>,
    whole_off: Vec<f64>,
}

impl Report {
    fn in_bevy_ms(&self) -> f64 {
        median(&self.hadou) - median(&self.passes_off)
    }

    fn share(&self) -> f64 {
        (median(&self.hadou) - median(&self.bevy_only)) / median(&self.hadou)
    }

    fn ratio(&self) -> f64 {
        self.in_bevy_ms() / median(&self.alone)
    }

    /// What the waves and shadows add to hadou-gpu's whole frame.
    fn whole_ms(&self) -> f64 {
        median(&self.whole) - median(&self.whole_off)
    }

    fn whole_ratio(&self) -> f64 {
        self.in_bevy_ms() / self.whole_ms()
    }
}

/// Times the load in Bevy: the frames of each [`Mode`], in alternating blocks.
fn time_in_bevy(options: &Options, load: Load) -> Result<[Vec<f64>; 3], String> {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut app = App::new();
    app.add_plugins(
        windowless_plugins()
            .set(AssetPlugin { file_path: scenes.display().to_string(), ..default() })
            .set(bevy::log::LogPlugin { level: bevy::log::Level::WARN, ..default() }),
    )
    .add_plugins(HadouPlugin { asset_root: scenes.clone() })
    .insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f32(FRAME_SECONDS)))
    .insert_resource(Stress {
        options: options.clone(),
        load,
        mode: Mode::Hadou,
        clip: None,
        waves: Vec::new(),
        standard: HashMap::new(),
        playing: 0,
    })
    .add_systems(Startup, setup)
    .add_systems(PreUpdate, keep_standard)
    .add_systems(Update, (start_clips, fire));
    app.finish();
    app.cleanup();
    let clock = FrameClock::new(&app);
    // Loading: every character's clip started and every mesh in hadou's look, for a few frames.
    let mut settled = 0;
    for _ in 0..LOAD_UPDATES {
        clock.frame_ms(&mut app);
        let world = app.world_mut();
        let standard = world.query::<&MeshMaterial3d<StandardMaterial>>().iter(world).count();
        let hadou = world.query::<&MeshMaterial3d<HadouMaterial>>().iter(world).count();
        let playing = world.resource::<Stress>().playing;
        let ready = standard == 0 && playing >= options.characters && hadou > options.characters as usize;
        settled = if ready { settled + 1 } else { 0 };
        if settled == 5 {
            break;
        }
    }
    if settled < 5 {
        return Err(format!("the characters did not load within {LOAD_UPDATES} frames"));
    }
    let world = app.world_mut();
    // The meshes are switched; from here this example switches them itself.
    let roots: Vec<Entity> = world.query_filtered::<Entity, With<HadouShaded>>().iter(world).collect();
    for root in roots {
        world.entity_mut(root).remove::<HadouShaded>();
    }
    let hadou: HashMap<Entity, Handle<HadouMaterial>> = world
        .query::<(Entity, &MeshMaterial3d<HadouMaterial>)>()
        .iter(world)
        .map(|(e, m)| (e, m.0.clone()))
        .collect();
    let g = load_ground_color(&app);
    let ground = app.world_mut().resource_mut::<Assets<StandardMaterial>>().add(StandardMaterial {
        base_color: Color::linear_rgb(g[0], g[1], g[2]),
        perceptual_roughness: 0.9,
        ..default()
    });
    // Warm-up: each mode's pipelines and first uploads.
    for mode in [Mode::BevyOnly, Mode::PassesOff, Mode::Hadou] {
        set_materials(&mut app, mode, &hadou, &ground);
        for _ in 0..5 {
            clock.frame_ms(&mut app);
        }
    }
    let mut times: [Vec<f64>; 3] = Default::default();
    let modes = [Mode::Hadou, Mode::PassesOff, Mode::BevyOnly];
    while times[2].len() < options.frames as usize {
        for (m, &mode) in modes.iter().enumerate() {
            set_materials(&mut app, mode, &hadou, &ground);
            clock.frame_ms(&mut app); // the change lands
            for _ in 0..5 {
                times[m].push(clock.frame_ms(&mut app));
            }
        }
    }
    Ok(times)
}

/// The ground's base colour in the load's frame.
fn load_ground_color(app: &App) -> [f32; 3] {
    let stress = app.world().resource::<Stress>();
    stress.load.frame.objects[stress.load.ground].material(0).base_color
}

/// Times hadou's passes alone: hadou-gpu on its own device drawing each frame's shadow maps and
/// wave pass, `frames` frames after one warm-up. Returns the times of both passes, of the wave
/// pass alone and of the shadow maps alone.
fn time_alone(backend: &mut GpuBackend, options: &Options, load: &Load) -> Result<[Vec<f64>; 3], String> {
    let frames: Vec<Frame> =
        (0..=options.frames).map(|f| load.at(options, (f + 1) as f32 * FRAME_SECONDS)).collect();
    let (mut size, mut layers) = (1, 1);
    for f in &frames {
        let (_, s, l) = shadow_records(&shadow_frame(f));
        (size, layers) = (size.max(s), layers.max(l));
    }
    let device = backend.device().clone();
    let texture = |label, w, h, layers, format, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: layers },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    let attach = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
    let maps = texture("stress shadow maps", size, size, layers, wgpu::TextureFormat::Depth32Float, attach);
    let (w, h) = options.size;
    let color = texture("stress colour", w, h, 1, wgpu::TextureFormat::Rgba16Float, attach);
    let depth = texture("stress depth", w, h, 1, wgpu::TextureFormat::Depth32Float, attach);
    let (color, depth) = (color.create_view(&Default::default()), depth.create_view(&Default::default()));
    // Bevy's depth with nothing drawn: reverse-Z, cleared to 0.
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("stress depth clear"),
        color_attachments: &[],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &depth,
            depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0.0), store: wgpu::StoreOp::Store }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    backend.queue().submit([encoder.finish()]);
    let target = OverlayTarget {
        color: &color,
        color_format: wgpu::TextureFormat::Rgba16Float,
        depth: &depth,
        depth_model: DepthModel::ReverseInfinite,
        depth_samples: 1,
        blend: OverlayBlend::Add,
        origin: [0, 0],
        projection: OverlayProjection::Perspective,
    };
    let mut once = |frame: &Frame, waves: bool, shadows: bool| -> Result<f64, String> {
        let start = Instant::now();
        let mut encoder = backend.device().create_command_encoder(&Default::default());
        if shadows {
            backend
                .encode_shadow_maps_into(&shadow_frame(frame), &mut encoder, &maps)
                .map_err(|e| e.to_string())?;
        }
        if waves {
            backend.encode_wave_overlay(frame, &mut encoder, &target).map_err(|e| e.to_string())?;
        }
        let submission = backend.queue().submit([encoder.finish()]);
        let _ =
            backend.device().poll(wgpu::PollType::Wait { submission_index: Some(submission), timeout: None });
        Ok(start.elapsed().as_secs_f64() * 1e3)
    };
    let mut times: [Vec<f64>; 3] = Default::default();
    for (i, (waves, shadows)) in [(true, true), (true, false), (false, true)].into_iter().enumerate() {
        once(&frames[0], waves, shadows)?; // warm-up
        for frame in &frames[1..] {
            times[i].push(once(frame, waves, shadows)?);
        }
    }
    Ok(times)
}

/// Times hadou-gpu's whole frames of the load (one sample, no glare, read back), with the waves
/// and shadows and without them, alternating frame by frame after one warm-up of each.
fn time_whole(backend: &mut GpuBackend, options: &Options, load: &Load) -> Result<[Vec<f64>; 2], String> {
    let mut times: [Vec<f64>; 2] = Default::default();
    for f in 0..=options.frames {
        let mut frame = load.at(options, (f + 1) as f32 * FRAME_SECONDS);
        frame.samples = 1;
        frame.bloom = None;
        let mut off = frame.clone();
        off.waves.clear();
        off.shadows.clear();
        for (i, frame) in [frame, off].iter().enumerate() {
            let start = Instant::now();
            backend.render(frame).map_err(|e| e.to_string())?;
            if f > 0 {
                times[i].push(start.elapsed().as_secs_f64() * 1e3);
            }
        }
    }
    Ok(times)
}

fn profile() -> &'static str {
    if cfg!(debug_assertions) {
        "dev"
    } else {
        "release"
    }
}

fn print_report(options: &Options, r: &Report) {
    let (w, h) = options.size;
    if options.json {
        let stats =
            |v: &[f64]| format!("{{\"median_ms\":{:.4},\"p90_ms\":{:.4}}}", median(v), quantile(v, 0.9));
        println!(
            "{{\"adapter\":{},\"profile\":{},\"prepass\":{},\"width\":{w},\"height\":{h},\"characters\":{},\"waves\":{},\
             \"frames\":{},\"frame\":{},\"passes_off\":{},\"bevy_only\":{},\"hadou_share\":{:.4},\
             \"passes_in_bevy_ms\":{:.4},\"passes_alone_ms\":{:.4},\"waves_alone_ms\":{:.4},\
             \"shadow_maps_alone_ms\":{:.4},\"ratio\":{:.4},\"whole_frame\":{},\"whole_frame_off\":{},\
             \"passes_whole_ms\":{:.4},\"whole_ratio\":{:.4}}}",
            json_string(&r.adapter),
            json_string(profile()),
            options.prepass,
            options.characters,
            options.waves,
            r.frames,
            stats(&r.hadou),
            stats(&r.passes_off),
            stats(&r.bevy_only),
            r.share(),
            r.in_bevy_ms(),
            median(&r.alone),
            median(&r.alone_waves),
            median(&r.alone_shadows),
            r.ratio(),
            stats(&r.whole),
            stats(&r.whole_off),
            r.whole_ms(),
            r.whole_ratio(),
        );
        return;
    }
    println!(
        "stress: {} characters, {} waves, shadows on, {w}×{h}, depth prepass {}, adapter {}, {} profile, {} frames a row",
        options.characters,
        options.waves,
        if options.prepass { "on" } else { "off" },
        r.adapter,
        profile(),
        r.frames
    );
    println!("{:<34} {:>10} {:>10}", "frame", "median ms", "p90 ms");
    for (name, v) in [("hadou", &r.hadou), ("hadou's passes off", &r.passes_off), ("Bevy only", &r.bevy_only)]
    {
        println!("{:<34} {:>10.2} {:>10.2}", name, median(v), quantile(v, 0.9));
    }
    println!("{:<34} {:>9.1}%", "hadou's share of the frame", 100.0 * r.share());
    println!("{:<34} {:>10.2}", "hadou's passes in Bevy (ms)", r.in_bevy_ms());
    println!(
        "{:<34} {:>10.2}   (wave pass {:.2}, shadow maps {:.2})",
        "hadou's passes alone (ms)",
        median(&r.alone),
        median(&r.alone_waves),
        median(&r.alone_shadows)
    );
    println!("{:<34} {:>10.2}", "in Bevy / alone", r.ratio());
    println!(
        "{:<34} {:>10.2}   (hadou-gpu frame {:.2}, without waves and shadows {:.2})",
        "waves and shadows, whole frames (ms)",
        r.whole_ms(),
        median(&r.whole),
        median(&r.whole_off)
    );
    println!("{:<34} {:>10.2}", "in Bevy / whole frames", r.whole_ratio());
}

fn main() -> ExitCode {
    let options = match parse_args() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("error: {e}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    let run = || -> Result<Report, String> {
        let load = Load::new(&options)?;
        let mut backend = GpuBackend::new().map_err(|e| format!("no GPU adapter for hadou-gpu: {e}"))?;
        if !options.json {
            eprintln!("timing hadou's passes alone…");
        }
        let [alone, alone_waves, alone_shadows] = time_alone(&mut backend, &options, &load)?;
        if !options.json {
            eprintln!("timing hadou-gpu's whole frames…");
        }
        let [whole, whole_off] = time_whole(&mut backend, &options, &load)?;
        let adapter = backend.adapter_name().to_string();
        drop(backend);
        if !options.json {
            eprintln!("timing the load in Bevy…");
        }
        let [hadou, passes_off, bevy_only] = time_in_bevy(&options, load)?;
        let frames = hadou.len();
        Ok(Report {
            adapter,
            frames,
            hadou,
            passes_off,
            bevy_only,
            alone,
            alone_waves,
            alone_shadows,
            whole,
            whole_off,
        })
    };
    let report = match run() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    print_report(&options, &report);
    ExitCode::SUCCESS
}
