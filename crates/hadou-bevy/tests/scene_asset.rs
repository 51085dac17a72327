//! A hadou scene file as a Bevy asset: a file hadou-scene rejects fails to load with the
//! reader's `file:line:col: message` and spawns nothing; a valid one spawns its camera, objects
//! and waves, set from its tracks at the root's clock.

use bevy::asset::LoadState;
use bevy::prelude::*;
use hadou_bevy::{
    parse_scene, unsupported, HadouCamera, HadouMaterial, HadouPlugin, HadouScene, HadouSceneRoot, HadouWave,
    SceneClock, SpawnedScene, ViewMapping,
};
use hadou_math::energy::BeamField;
use hadou_scene::WaveShape;
use std::path::{Path, PathBuf};

const BAD: &str = "[image]\nwidth = 64\nheight = 32\n\n[[wave]]\nname = \"w\"\nkind = \"sphere\"\nM = [0.0, 0.0, 0.0]\nalpha_s = -1.0\n";

fn repo_scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// A fresh directory holding `files`.
fn asset_dir(test: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hadou-bevy-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    dir
}

fn app(root: &Path) -> App {
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        AssetPlugin { file_path: root.display().to_string(), ..default() },
        bevy::mesh::MeshPlugin,
    ));
    app.add_plugins(HadouPlugin { asset_root: root.to_path_buf() });
    app
}

/// Updates `app` until `done` or about ten seconds.
fn update_until(app: &mut App, mut done: impl FnMut(&mut App) -> bool) {
    for _ in 0..1000 {
        app.update();
        if done(app) {
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    panic!("timed out");
}

#[test]
fn a_rejected_scene_is_an_error_with_its_location() {
    let error = parse_scene(BAD.as_bytes(), Path::new("bad.toml")).expect_err("alpha_s = -1 is out of range");
    let message = error.to_string();
    assert!(message.starts_with("bad.toml:9:"), "{message}");
    assert!(message.contains("alpha_s"), "{message}");
}

#[test]
fn a_scene_that_fails_to_load_spawns_nothing() {
    let dir = asset_dir("bad", &[("bad.toml", BAD)]);
    let mut app = app(&dir);
    let handle: Handle<HadouScene> = app.world().resource::<AssetServer>().load("bad.toml");
    let root =
        app.world_mut().spawn(HadouSceneRoot { scene: handle.clone(), clock: SceneClock::Running }).id();
    let mut message = String::new();
    update_until(&mut app, |app| match app.world().resource::<AssetServer>().load_state(&handle) {
        LoadState::Failed(e) => {
            message = e.to_string();
            true
        }
        _ => false,
    });
    assert!(message.contains("bad.toml:9:"), "the asset error carries file:line:col: {message}");
    app.update();
    assert!(app.world().get::<SpawnedScene>(root).is_none());
    let waves = app.world_mut().query::<&HadouWave>().iter(app.world()).count();
    assert_eq!(waves, 0);
}

#[test]
fn a_loaded_scene_spawns_its_entities_at_the_frozen_time() {
    let dir = repo_scenes();
    let mut app = app(&dir);
    let handle: Handle<HadouScene> = app.world().resource::<AssetServer>().load("kamehameha.toml");
    let root = app.world_mut().spawn(HadouSceneRoot { scene: handle, clock: SceneClock::Frozen(1.5) }).id();
    update_until(&mut app, |app| app.world().get::<SpawnedScene>(root).is_some());
    app.update();

    let reference = hadou_scene::Scene::load(dir.join("kamehameha.toml")).unwrap().at(1.5);
    let spawned = app.world().get::<SpawnedScene>(root).unwrap();
    assert_eq!(spawned.objects.len(), reference.objects.len());
    assert_eq!(spawned.waves.len(), reference.waves.len());
    let camera = app.world().get::<HadouCamera>(spawned.camera).expect("the camera gets the wave pass");
    assert_eq!(camera.far, reference.camera.far);
    assert_eq!(camera.mapping, ViewMapping::Hadou(reference.color_mapping.mode), "the scene's [color] mode");
    let children = app.world().get::<Children>(spawned.objects[0]).expect("the object's slots");
    let slot = children[0];
    assert!(app.world().get::<Mesh3d>(slot).is_some());
    let material = app.world().get::<MeshMaterial3d<HadouMaterial>>(slot).expect("hadou's shading");
    assert_eq!(material.0, spawned.materials[0][0]);
    let surface = app.world().resource::<Assets<HadouMaterial>>().get(&material.0).unwrap().surface;
    let ground = reference.objects[0].material(0).base_color;
    assert_eq!(surface.base_color.truncate().to_array(), ground);
    let d = reference.light.direction;
    assert_eq!(surface.light_direction.truncate().to_array(), [d.x, d.y, d.z], "the scene's light");
    assert_eq!(surface.ambient.truncate().to_array(), reference.light.ambient);

    let length = |shape: &WaveShape| match shape {
        WaveShape::Beam(BeamField { capsule, .. }) => capsule.length,
        other => panic!("kamehameha's wave is a beam, got {other:?}"),
    };
    let wave = app.world().get::<HadouWave>(spawned.waves[0]).unwrap();
    let expected = length(&reference.waves[0].shape);
    assert!(expected > 1.0, "the track has moved the head by t = 1.5");
    assert_eq!(length(&wave.wave.shape), expected);
}

#[test]
fn what_is_not_drawn_yet_is_named() {
    let scenes = repo_scenes();
    let frame = hadou_scene::Scene::load(scenes.join("glare-kamehameha.toml")).unwrap().at(0.0);
    let missing = unsupported(&frame).join("; ");
    assert!(missing.contains("[bloom]"), "{missing}");
    let frame = hadou_scene::Scene::load(scenes.join("soft-gradient.toml")).unwrap().at(0.0);
    assert!(frame.area_light.is_some());
    assert_eq!(unsupported(&frame), Vec::<String>::new(), "the [area_light] is drawn");
    let frame = hadou_scene::Scene::load(scenes.join("shadow-wave-top.toml")).unwrap().at(1.0);
    assert_eq!(unsupported(&frame), Vec::<String>::new(), "wave shadows are drawn");
    let frame = hadou_scene::Scene::load(scenes.join("light-normal-vs-wave.toml")).unwrap().at(0.75);
    assert_eq!(
        unsupported(&frame),
        Vec::<String>::new(),
        "the wave as a light, textures, material slots and outlines are drawn"
    );
    let frame = hadou_scene::Scene::load(scenes.join("kamehameha.toml")).unwrap().at(1.5);
    assert_eq!(unsupported(&frame), Vec::<String>::new(), "kamehameha (filmic) uses nothing unsupported");
}

const ONE_WAVE: &str = "[image]\nwidth = 64\nheight = 32\n\n[[wave]]\nname = \"a\"\nkind = \"sphere\"\nM = [0.0, 0.0, 0.0]\nalpha_s = 0.1\n";

#[test]
fn a_changed_scene_file_is_spawned_again_and_a_broken_one_keeps_the_last() {
    let dir = asset_dir("reload", &[("live.toml", ONE_WAVE)]);
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        AssetPlugin {
            file_path: dir.display().to_string(),
            watch_for_changes_override: Some(true),
            ..default()
        },
        bevy::mesh::MeshPlugin,
    ));
    app.add_plugins(HadouPlugin { asset_root: dir.clone() });
    let handle: Handle<HadouScene> = app.world().resource::<AssetServer>().load("live.toml");
    let root =
        app.world_mut().spawn(HadouSceneRoot { scene: handle.clone(), clock: SceneClock::Frozen(0.0) }).id();
    update_until(&mut app, |app| app.world().get::<SpawnedScene>(root).is_some());
    let first = app.world().get::<SpawnedScene>(root).unwrap().waves.clone();
    assert_eq!(first.len(), 1);

    let two = format!(
        "{ONE_WAVE}\n[[wave]]\nname = \"b\"\nkind = \"sphere\"\nM = [1.0, 0.0, 0.0]\nalpha_s = 0.1\n"
    );
    std::fs::write(dir.join("live.toml"), two).unwrap();
    update_until(&mut app, |app| app.world().get::<SpawnedScene>(root).is_some_and(|s| s.waves.len() == 2));
    app.update();
    assert!(app.world().get_entity(first[0]).is_err(), "what the old scene spawned is gone");
    let waves = app.world_mut().query::<&HadouWave>().iter(app.world()).count();
    assert_eq!(waves, 2, "no wave of the old scene is left");

    std::fs::write(dir.join("live.toml"), BAD).unwrap();
    update_until(&mut app, |app| {
        matches!(app.world().resource::<AssetServer>().load_state(&handle), LoadState::Failed(_))
    });
    for _ in 0..5 {
        app.update();
    }
    let spawned = app.world().get::<SpawnedScene>(root).expect("the last good scene stays");
    assert_eq!(spawned.waves.len(), 2);
    std::fs::remove_dir_all(&dir).ok();
}
