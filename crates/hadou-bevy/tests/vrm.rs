//! Bad input: a `.vrm` whose MToon extension is broken (a key of the wrong type), loaded by Bevy's
//! glTF loader under hadou's `VrmLoader`, gives one error log naming the file, the material and
//! the key; the file still loads, its meshes are switched to hadou's shading without MToon, and
//! the app runs on. Through a scene file, the scene is refused with the object's `file:line:col`
//! and the key (as `hadou render` refuses it) and nothing is spawned.

mod common;

use bevy::asset::LoadState;
use bevy::gltf::GltfAssetLabel;
use bevy::log::tracing_subscriber::{layer::Context, Layer, Registry};
use bevy::log::{BoxedLayer, LogPlugin};
use bevy::prelude::*;
use bevy::world_serialization::WorldAssetRoot;
use common::adapter_or_skip;
use hadou_bevy::{
    HadouMaterial, HadouPlugin, HadouScene, HadouSceneRoot, HadouShaded, SceneClock, SpawnedScene,
};
use std::path::Path;
use std::sync::Mutex;

/// The error events logged while the test runs.
static ERRORS: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// Records every error event's message.
struct Errors;

impl<S: bevy::log::tracing::Subscriber> Layer<S> for Errors {
    fn on_event(&self, event: &bevy::log::tracing::Event<'_>, _: Context<'_, S>) {
        if *event.metadata().level() != bevy::log::Level::ERROR {
            return;
        }
        struct Message(String);
        impl bevy::log::tracing::field::Visit for Message {
            fn record_debug(
                &mut self,
                field: &bevy::log::tracing::field::Field,
                value: &dyn std::fmt::Debug,
            ) {
                if field.name() == "message" {
                    self.0 = format!("{value:?}");
                }
            }
        }
        let mut message = Message(String::new());
        event.record(&mut message);
        ERRORS.lock().unwrap().push(message.0);
    }
}

fn errors_layer(_: &mut App) -> Option<BoxedLayer> {
    let layer: Box<dyn Layer<Registry> + Send + Sync> = Box::new(Errors);
    Some(layer)
}

/// `glb` (a GLB file) with `from` replaced by `to` in its JSON chunk (padded with spaces to four
/// bytes, as GLB requires).
fn edit_glb(glb: &[u8], from: &str, to: &str) -> Vec<u8> {
    let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let json = std::str::from_utf8(&glb[20..20 + json_len]).unwrap();
    assert!(json.contains(from), "the file has `{from}`");
    let mut json = json.replacen(from, to, 1).into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let rest = &glb[20 + json_len..];
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&((12 + 8 + json.len() + rest.len()) as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(rest);
    out
}

/// mtoon-ball.vrm with material 0's `shadingToonyFactor` a string instead of a number.
fn broken_ball() -> Vec<u8> {
    let ball =
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/assets/mtoon-ball.vrm"))
            .unwrap();
    edit_glb(&ball, "\"shadingToonyFactor\":0.5", "\"shadingToonyFactor\":\"soft\"")
}

#[test]
fn a_scene_with_a_broken_vrm_is_refused_at_the_objects_path() {
    let dir = std::env::temp_dir().join(format!("hadou-bevy-vrm-scene-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("broken.vrm"), broken_ball()).unwrap();
    std::fs::write(
        dir.join("s.toml"),
        "[[object]]\nname = \"avatar\"\nkind = \"gltf\"\npath = \"broken.vrm\"\n",
    )
    .unwrap();
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        AssetPlugin { file_path: dir.display().to_string(), ..default() },
        bevy::mesh::MeshPlugin,
    ))
    .add_plugins(HadouPlugin { asset_root: dir.clone() });
    let handle: Handle<HadouScene> = app.world().resource::<AssetServer>().load("s.toml");
    let root =
        app.world_mut().spawn(HadouSceneRoot { scene: handle.clone(), clock: SceneClock::Running }).id();
    let mut message = None;
    for _ in 0..1000 {
        app.update();
        if let LoadState::Failed(e) = app.world().resource::<AssetServer>().load_state(&handle) {
            message = Some(e.to_string());
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let message = message.expect("the scene fails to load");
    assert!(message.contains("s.toml:4:8:"), "the object's path: {message}");
    assert!(message.contains("material 0 (VRMC_materials_mtoon).shadingToonyFactor"), "the key: {message}");
    app.update();
    assert!(app.world().get::<SpawnedScene>(root).is_none(), "nothing spawned");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_vrm_with_a_broken_mtoon_is_one_error_and_drawn_without_mtoon() {
    let test = "a_vrm_with_a_broken_mtoon_is_one_error_and_drawn_without_mtoon";
    if !adapter_or_skip(test) {
        return;
    }
    let broken = broken_ball();
    let dir = std::env::temp_dir().join(format!("hadou-bevy-vrm-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("broken.vrm"), &broken).unwrap();
    let mut app = App::new();
    app.add_plugins(
        common::windowless()
            .set(AssetPlugin { file_path: dir.display().to_string(), ..default() })
            .set(LogPlugin { custom_layer: errors_layer, ..default() }),
    )
    .add_plugins(HadouPlugin { asset_root: dir.clone() });
    app.finish();
    app.cleanup();
    let handle =
        app.world().resource::<AssetServer>().load(GltfAssetLabel::Scene(0).from_asset("broken.vrm"));
    let look = hadou_scene::Material { model: hadou_scene::ShadingModel::Toon, ..Default::default() };
    let light = hadou_scene::Light {
        direction: hadou_math::Vec3f::new(0.0, -1.0, 0.0),
        color: [1.0; 3],
        ambient: [0.1; 3],
    };
    app.world_mut().spawn((WorldAssetRoot(handle.clone()), HadouShaded::new(look, light, 0)));
    let mut shaded = Vec::new();
    for _ in 0..1000 {
        app.update();
        let world = app.world_mut();
        shaded = world.query::<&MeshMaterial3d<HadouMaterial>>().iter(world).map(|m| m.0.clone()).collect();
        let standard = world.query::<&MeshMaterial3d<StandardMaterial>>().iter(world).count();
        if !shaded.is_empty() && standard == 0 {
            break;
        }
        assert!(
            !matches!(app.world().resource::<AssetServer>().load_state(&handle), LoadState::Failed(_)),
            "the file still loads"
        );
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert!(!shaded.is_empty(), "the ball's meshes are switched to hadou's shading");
    let materials = app.world().resource::<Assets<HadouMaterial>>();
    assert!(shaded.iter().all(|h| materials.get(h).unwrap().surface.mtoon == 0), "drawn without MToon");
    // The app runs on.
    for _ in 0..3 {
        app.update();
    }
    let errors = ERRORS.lock().unwrap().clone();
    let ours: Vec<&String> = errors.iter().filter(|e| e.contains("drawn without MToon")).collect();
    assert_eq!(ours.len(), 1, "one error: {errors:?}");
    let message = ours[0];
    assert!(message.contains("broken.vrm"), "names the file: {message}");
    assert!(
        message.contains("material 0 (VRMC_materials_mtoon).shadingToonyFactor"),
        "names the material and the key: {message}"
    );
    eprintln!("{message}");
    std::fs::remove_dir_all(&dir).ok();
}
