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
use common::picture::{bevy_picture, difference, picture_in, scenes};

use hadou_bevy::ViewMapping;

/// The largest mean absolute difference of the 8-bit RGB values accepted. Measured on Mesa's
/// lavapipe: 0.001 for the toon scene, 0.06 for kamehameha with either mapping, 0.41 for the wave
/// as a light on a character Bevy's glTF loader loaded and skinned, 0.18 for the wave shadows (the
/// same formulas shade and map both sides; the rest is rounding and rasterization at triangle
/// edges).
const MAX_MEAN: f64 = 2.0;

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
