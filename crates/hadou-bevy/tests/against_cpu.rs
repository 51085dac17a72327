//! The same picture as `hadou render`: `scenes/kamehameha.toml` at t = 1.5, spawned by
//! `HadouSceneRoot` (hadou's colour mapping, `HadouMaterial` objects, no bloom, no MSAA) and drawn
//! by Bevy into an image of the scene's size, against hadou-cpu's render of the same frame
//! (what `hadou render` writes on a machine without a GPU); then the same with the camera switched
//! to hadou's faithful mapping, against the faithful render; and a scene of toon materials (banded
//! and gradient ramps, no waves) against hadou-cpu's render of it. Skips with a message when there is no
//! usable adapter; fails instead under `HADOU_REQUIRE_GPU=1`. hadou's frames are taken at one
//! sample per pixel (`samples = 1`): in Bevy anti-aliasing is the camera's own `Msaa`.

mod common;

use common::adapter_or_skip;

use bevy::camera::RenderTarget;
use bevy::image::Image;
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use hadou_bevy::{HadouCamera, HadouPlugin, HadouSceneRoot, SceneClock, SpawnedScene, ViewMapping};
use hadou_math::shade::linear_to_srgb8;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// The largest mean absolute difference of the 8-bit RGB values accepted. Measured on Mesa's
/// lavapipe: 0.001 for the toon scene, 0.06 for kamehameha with either mapping, 0.41 for the wave
/// as a light on a character Bevy's glTF loader loaded and skinned, 0.18 for the wave shadows (the
/// same formulas shade and map both sides; the rest is rounding and rasterization at triangle
/// edges).
const MAX_MEAN: f64 = 2.0;

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// The image every spawned scene camera renders into, and the mapping it is given instead of the
/// scene's, if any.
#[derive(Resource)]
struct Target(Handle<Image>, Option<ViewMapping>, bevy::render::view::Msaa);

fn into_image(
    mut commands: Commands,
    mut cameras: Query<(Entity, &mut HadouCamera), Added<HadouCamera>>,
    target: Res<Target>,
) {
    for (camera, mut settings) in &mut cameras {
        commands.entity(camera).insert((RenderTarget::Image(target.0.clone().into()), target.2));
        if let Some(mapping) = target.1 {
            settings.mapping = mapping;
        }
    }
}

/// The scene `file` at `time` drawn by Bevy into a `width × height` image (with `mapping`
/// instead of the scene's colour mapping, if given): its sRGB bytes, 4 per pixel, and the spawned
/// camera's mapping.
fn bevy_picture(
    file: &str,
    time: f32,
    size: (u32, u32),
    mapping: Option<ViewMapping>,
) -> (Vec<u8>, ViewMapping) {
    picture_in(&scenes(), file, time, size, mapping, bevy::render::view::Msaa::Off)
}

/// [`bevy_picture`] of the scene `file` in the folder `root`.
fn picture_in(
    root: &Path,
    file: &str,
    time: f32,
    (width, height): (u32, u32),
    mapping: Option<ViewMapping>,
    msaa: bevy::render::view::Msaa,
) -> (Vec<u8>, ViewMapping) {
    let root = root.canonicalize().expect("the scenes folder");
    let mut app = App::new();
    app.add_plugins(
        common::windowless().set(AssetPlugin { file_path: root.display().to_string(), ..default() }),
    )
    .add_plugins(HadouPlugin { asset_root: root.clone() });
    let image = Image::new_target_texture(width, height, TextureFormat::Rgba8UnormSrgb, None);
    let image = app.world_mut().resource_mut::<Assets<Image>>().add(image);
    app.insert_resource(Target(image.clone(), mapping, msaa)).add_systems(Update, into_image);
    let scene = app.world().resource::<AssetServer>().load(file.to_string());
    let root = app.world_mut().spawn(HadouSceneRoot { scene, clock: SceneClock::Frozen(time) }).id();
    app.finish();
    app.cleanup();

    let shot: Arc<Mutex<Option<Image>>> = Arc::default();
    let mut drawn = 0;
    for _ in 0..2000 {
        app.update();
        if app.world().get::<SpawnedScene>(root).is_some_and(|s| s.ready) {
            drawn += 1;
        }
        // A few frames after every object has hadou's look (glTF files load asynchronously),
        // once the meshes and pipelines are ready.
        if drawn == 5 {
            let shot = shot.clone();
            app.world_mut().spawn(Screenshot::image(image.clone())).observe(
                move |captured: On<ScreenshotCaptured>| {
                    *shot.lock().unwrap() = Some(captured.image.clone());
                },
            );
        }
        if shot.lock().unwrap().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let image = shot.lock().unwrap().take().expect("the screenshot came back");
    assert_eq!((image.width(), image.height()), (width, height));
    assert_eq!(image.texture_descriptor.format, TextureFormat::Rgba8UnormSrgb);
    let camera = app.world().get::<SpawnedScene>(root).unwrap().camera;
    let mapping = app.world().get::<HadouCamera>(camera).unwrap().mapping;
    (image.data.expect("a captured image has its bytes"), mapping)
}

/// The mean and the largest absolute difference of the RGB bytes of `bevy` (4 per pixel) and
/// hadou-cpu's `image` encoded as `hadou render` encodes it.
fn difference(bevy: &[u8], image: &hadou_scene::Image) -> (f64, u8) {
    assert_eq!(bevy.len(), image.color.len() * 4);
    let (mut sum, mut max) = (0u64, 0u8);
    for (b, c) in bevy.chunks_exact(4).zip(&image.color) {
        for channel in 0..3 {
            let d = b[channel].abs_diff(linear_to_srgb8(c[channel]));
            sum += u64::from(d);
            max = max.max(d);
        }
    }
    (sum as f64 / (image.color.len() * 3) as f64, max)
}

#[test]
fn kamehameha_in_bevy_is_the_picture_of_hadou_render() {
    let test = "kamehameha_in_bevy_is_the_picture_of_hadou_render";
    if !adapter_or_skip(test) {
        return;
    }
    let mut frame = hadou_scene::Scene::load(scenes().join("kamehameha.toml")).unwrap().at(1.5);
    frame.samples = 1;
    assert_eq!(frame.color_mapping.mode, hadou_scene::ToneMode::Filmic);
    let reference = hadou_cpu::render(&frame);
    let (bevy, mapping) = bevy_picture("kamehameha.toml", 1.5, (frame.width, frame.height), None);
    assert_eq!(
        mapping,
        ViewMapping::Hadou(hadou_scene::ToneMode::Filmic),
        "a spawned scene maps as hadou does"
    );
    let (mean, max) = difference(&bevy, &reference);
    eprintln!("kamehameha.toml at t = 1.5, {}×{}: mean {mean:.3}, largest {max}", frame.width, frame.height);
    assert!(mean <= MAX_MEAN, "mean absolute 8-bit difference {mean:.3} > {MAX_MEAN} (largest {max})");
    // Not a picture that matches anything: the beam is there, bright, on both sides.
    let brightest = bevy.chunks_exact(4).map(|p| u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2])).max();
    assert!(brightest.unwrap() > 600, "the beam's white core is drawn");
}

#[test]
fn kamehameha_with_the_faithful_mapping_is_the_picture_of_hadou_render() {
    let test = "kamehameha_with_the_faithful_mapping_is_the_picture_of_hadou_render";
    if !adapter_or_skip(test) {
        return;
    }
    let mut frame = hadou_scene::Scene::load(scenes().join("kamehameha.toml")).unwrap().at(1.5);
    frame.samples = 1;
    frame.color_mapping.mode = hadou_scene::ToneMode::Faithful;
    let reference = hadou_cpu::render(&frame);
    let faithful = ViewMapping::Hadou(hadou_scene::ToneMode::Faithful);
    let (bevy, mapping) = bevy_picture("kamehameha.toml", 1.5, (frame.width, frame.height), Some(faithful));
    assert_eq!(mapping, faithful);
    let (mean, max) = difference(&bevy, &reference);
    eprintln!("kamehameha.toml at t = 1.5, faithful: mean {mean:.3}, largest {max}");
    assert!(mean <= MAX_MEAN, "mean absolute 8-bit difference {mean:.3} > {MAX_MEAN} (largest {max})");
    // And not the filmic picture: the mapping did change.
    frame.color_mapping.mode = hadou_scene::ToneMode::Filmic;
    let (filmic_mean, _) = difference(&bevy, &hadou_cpu::render(&frame));
    assert!(filmic_mean > 2.0 * MAX_MEAN, "the faithful picture is the filmic one ({filmic_mean:.3})");
    eprintln!("against the filmic picture: mean {filmic_mean:.3}");
}

/// Toon materials without waves: a sphere with three smoothed bands, a box with two hard bands, a
/// ground with a gradient ramp, under a slanted light.
const TOON_SCENE: &str = r#"
background = [0.5, 0.6, 0.75]

[image]
width = 320
height = 240

[camera]
position = [0.0, 2.2, 5.0]
target = [0.0, 0.6, 0.0]
fov = 45.0

[light]
direction = [0.6, -0.8, -0.45]
color = [1.0, 0.97, 0.9]
ambient = [0.3, 0.32, 0.38]

[[material]]
name = "ground"
model = "toon"
base_color = [0.45, 0.62, 0.38]
ramp = [[-1.0, 0.3, 0.3, 0.4], [-0.2, 0.6, 0.6, 0.7], [0.5, 1.0, 1.0, 1.0]]
ramp_kind = "gradient"

[[material]]
name = "ball"
model = "toon"
base_color = [0.9, 0.55, 0.3]
ramp = [[-1.0, 0.35, 0.3, 0.45], [-0.1, 0.7, 0.65, 0.75], [0.45, 1.0, 1.0, 1.0]]
ramp_smoothing = 0.08

[[material]]
name = "crate"
model = "toon"
base_color = [0.4, 0.5, 0.9]
ramp = [[-1.0, 0.5, 0.45, 0.55], [0.0, 1.0, 1.0, 1.0]]

[[object]]
name = "ball"
kind = "sphere"
radius = 0.7
segments = 48
position = [-0.7, 0.7, 0.0]
material = "ball"

[[object]]
name = "crate"
kind = "box"
size = [0.8, 0.8, 0.8]
position = [1.1, 0.4, -0.4]
rotation = [0.0, 30.0, 0.0]
material = "crate"

[[object]]
name = "ground"
kind = "plane"
size = [10.0, 8.0]
material = "ground"
"#;

#[test]
fn toon_materials_in_bevy_are_the_picture_of_hadou_render() {
    let test = "toon_materials_in_bevy_are_the_picture_of_hadou_render";
    if !adapter_or_skip(test) {
        return;
    }
    let dir = std::env::temp_dir().join(format!("hadou-bevy-toon-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("toon.toml"), TOON_SCENE).unwrap();
    let mut frame = hadou_scene::Scene::load(dir.join("toon.toml")).unwrap().at(0.0);
    frame.samples = 1;
    assert!(frame.waves.is_empty() && frame.shadows.is_empty());
    assert!(frame
        .objects
        .iter()
        .all(|o| o.materials.iter().all(|m| m.model == hadou_scene::ShadingModel::Toon)));
    let reference = hadou_cpu::render(&frame);
    let (bevy, _) =
        picture_in(&dir, "toon.toml", 0.0, (frame.width, frame.height), None, bevy::render::view::Msaa::Off);
    std::fs::remove_dir_all(&dir).ok();
    let (mean, max) = difference(&bevy, &reference);
    eprintln!("toon scene, {}×{}: mean {mean:.3}, largest {max}", frame.width, frame.height);
    assert!(mean <= MAX_MEAN, "mean absolute 8-bit difference {mean:.3} > {MAX_MEAN} (largest {max})");
    // And not the diffuse picture: the ramps are what shaded it, and the bound above tells them
    // apart (measured on lavapipe: 0.001 against the toon render, 2.74 against the diffuse one).
    for object in &mut frame.objects {
        for material in &mut object.materials {
            material.model = hadou_scene::ShadingModel::Diffuse;
        }
    }
    let (diffuse_mean, _) = difference(&bevy, &hadou_cpu::render(&frame));
    eprintln!("against the same scene shaded as diffuse: mean {diffuse_mean:.3}");
    assert!(diffuse_mean > MAX_MEAN, "the toon picture is the diffuse one ({diffuse_mean:.3})");
}

/// The wave as a light (000 Fig. 4.3–4.4): a textured, outlined glTF character of several
/// material slots whose `wave_blend` a track takes to 1 as a beam fires behind it. Against
/// hadou-cpu's render of the same frame; and not the picture without the wave's light.
#[test]
fn the_wave_as_a_light_in_bevy_is_the_picture_of_hadou_render() {
    let test = "the_wave_as_a_light_in_bevy_is_the_picture_of_hadou_render";
    if !adapter_or_skip(test) {
        return;
    }
    let mut frame = hadou_scene::Scene::load(scenes().join("light-normal-vs-wave.toml")).unwrap().at(0.75);
    frame.samples = 1;
    let materials = || frame.objects.iter().flat_map(|o| &o.materials);
    assert!(materials().any(|m| m.wave_blend > 0.0), "the frame blends towards the wave");
    assert!(materials().any(|m| m.feature_texture.is_some() || m.base_texture.is_some()));
    assert!(materials().any(|m| m.outline.is_some()));
    assert!(frame.objects.iter().any(|o| o.materials.len() > 1));
    let reference = hadou_cpu::render(&frame);
    let (bevy, _) = bevy_picture("light-normal-vs-wave.toml", 0.75, (frame.width, frame.height), None);
    let (mean, max) = difference(&bevy, &reference);
    eprintln!(
        "light-normal-vs-wave.toml at t = 0.75, {}×{}: mean {mean:.3}, largest {max}",
        frame.width, frame.height
    );
    assert!(mean <= MAX_MEAN, "mean absolute 8-bit difference {mean:.3} > {MAX_MEAN} (largest {max})");
    for object in &mut frame.objects {
        for material in &mut object.materials {
            material.wave_blend = 0.0;
        }
    }
    let (unlit_mean, _) = difference(&bevy, &hadou_cpu::render(&frame));
    eprintln!("against the same frame without the wave's light: mean {unlit_mean:.3}");
    assert!(unlit_mean > MAX_MEAN, "the wave's light is not on the character ({unlit_mean:.3})");
}

/// The wave's stylized shadows (000 §2.4): five models around a beam, each shadow leaning away
/// from it along the ground, drawn in Bevy by hadou-gpu's shadow maps. Against hadou-cpu's render
/// of the same frame; and not the picture without the shadows.
#[test]
fn wave_shadows_in_bevy_are_the_picture_of_hadou_render() {
    let test = "wave_shadows_in_bevy_are_the_picture_of_hadou_render";
    if !adapter_or_skip(test) {
        return;
    }
    let mut frame = hadou_scene::Scene::load(scenes().join("shadow-wave-top.toml")).unwrap().at(1.0);
    frame.samples = 1;
    assert!(!frame.shadows.is_empty());
    let reference = hadou_cpu::render(&frame);
    let (bevy, _) = bevy_picture("shadow-wave-top.toml", 1.0, (frame.width, frame.height), None);
    let (mean, max) = difference(&bevy, &reference);
    eprintln!(
        "shadow-wave-top.toml at t = 1.0, {}×{}: mean {mean:.3}, largest {max}",
        frame.width, frame.height
    );
    assert!(mean <= MAX_MEAN, "mean absolute 8-bit difference {mean:.3} > {MAX_MEAN} (largest {max})");
    frame.shadows.clear();
    let (unshadowed, _) = difference(&bevy, &hadou_cpu::render(&frame));
    eprintln!("against the same frame without its shadows: mean {unshadowed:.3}");
    assert!(unshadowed > MAX_MEAN, "the shadows are not drawn ({unshadowed:.3})");
}

/// With Bevy's MSAA (4 samples) the waves are still drawn (against the first sample of the
/// multisampled depth buffer, into the resolved image): the same picture but for the smoothed
/// triangle edges.
#[test]
fn kamehameha_with_msaa_in_bevy_is_the_picture_of_hadou_render() {
    let test = "kamehameha_with_msaa_in_bevy_is_the_picture_of_hadou_render";
    if !adapter_or_skip(test) {
        return;
    }
    let mut frame = hadou_scene::Scene::load(scenes().join("kamehameha.toml")).unwrap().at(1.5);
    frame.samples = 1;
    let reference = hadou_cpu::render(&frame);
    let size = (frame.width, frame.height);
    let (bevy, _) =
        picture_in(&scenes(), "kamehameha.toml", 1.5, size, None, bevy::render::view::Msaa::Sample4);
    let (mean, max) = difference(&bevy, &reference);
    eprintln!("kamehameha.toml at t = 1.5 with MSAA ×4: mean {mean:.3}, largest {max}");
    assert!(mean <= MAX_MEAN, "mean absolute 8-bit difference {mean:.3} > {MAX_MEAN} (largest {max})");
    let brightest = bevy.chunks_exact(4).map(|p| u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2])).max();
    assert!(brightest.unwrap() > 600, "the beam's white core is drawn");
}
