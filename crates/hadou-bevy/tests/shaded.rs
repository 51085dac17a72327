//! `HadouShaded`: a glTF character loaded by Bevy's own loader (skinned, textured) is switched to
//! hadou's shading by one component on its scene root.

mod common;

use bevy::camera::{Hdr, RenderTarget};
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::gltf::GltfAssetLabel;
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::world_serialization::WorldAssetRoot;
use common::adapter_or_skip;
use hadou_bevy::{HadouMaterial, HadouPlugin, HadouShaded};
use std::path::Path;
use std::sync::{Arc, Mutex};

#[test]
fn a_character_loaded_by_bevy_takes_hadous_shading_with_one_component() {
    let test = "a_character_loaded_by_bevy_takes_hadous_shading_with_one_component";
    if !adapter_or_skip(test) {
        return;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes").canonicalize().unwrap();
    let mut app = App::new();
    app.add_plugins(
        common::windowless().set(AssetPlugin { file_path: root.display().to_string(), ..default() }),
    )
    .add_plugins(HadouPlugin { asset_root: root.clone() });
    let scene = hadou_scene::Scene::load(root.join("light-normal-vs-wave.toml")).unwrap().at(1.5);
    let mut look = scene.objects[0].material(0).clone();
    look.base_color = [0.5, 1.0, 1.0];
    look.wave_blend = 0.75;
    look.model = hadou_scene::ShadingModel::Toon;
    // A colour nothing else in the picture has: the hulls must show around the character.
    look.outline = Some(hadou_scene::Outline { width: 0.01, color: [1.0, 0.0, 1.0] });
    let image = Image::new_target_texture(96, 96, TextureFormat::Rgba8UnormSrgb, None);
    let image = app.world_mut().resource_mut::<Assets<Image>>().add(image);
    app.world_mut().spawn((
        Camera3d::default(),
        Camera { clear_color: ClearColorConfig::Custom(Color::BLACK), ..default() },
        RenderTarget::Image(image.clone().into()),
        Hdr,
        Tonemapping::None,
        Transform::from_xyz(0.0, 1.0, 4.0).looking_at(Vec3::new(0.0, 0.9, 0.0), Vec3::Y),
    ));
    let handle =
        app.world().resource::<AssetServer>().load(GltfAssetLabel::Scene(0).from_asset("assets/hero.glb"));
    let character = app
        .world_mut()
        .spawn((
            WorldAssetRoot(handle),
            HadouShaded { material: look, light: scene.light, shadow_mask: 0b10 },
        ))
        .id();
    app.finish();
    app.cleanup();
    let mut shaded = Vec::new();
    for _ in 0..1000 {
        app.update();
        let world = app.world_mut();
        let standard = world.query::<&MeshMaterial3d<StandardMaterial>>().iter(world).count();
        shaded = world
            .query::<(Entity, &MeshMaterial3d<HadouMaterial>)>()
            .iter(world)
            .map(|(e, m)| (e, m.0.clone()))
            .collect();
        if !shaded.is_empty() && standard == 0 {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert!(!shaded.is_empty(), "the character's meshes are shaded by hadou");
    let world = app.world_mut();
    assert_eq!(world.query::<&MeshMaterial3d<StandardMaterial>>().iter(world).count(), 0);
    let mut parents = world.query::<&ChildOf>();
    for (entity, _) in &shaded {
        let mut e = *entity;
        while e != character {
            e = parents.get(world, e).expect("below the character's root").parent();
        }
    }
    let materials = app.world().resource::<Assets<HadouMaterial>>();
    for (_, handle) in &shaded {
        let m = materials.get(handle).unwrap();
        assert_eq!(m.surface.wave_blend, 0.75);
        assert_eq!(m.surface.shadow_mask, 0b10);
        assert_eq!(m.surface.model, hadou_gpu::layout::MODEL_TOON);
        // The base colour is the look's times the glTF material's.
        assert!(m.surface.base_color.x <= 0.5 + 1e-6, "{:?}", m.surface.base_color);
    }
    let world = app.world_mut();
    let hulls: Vec<bool> = world
        .query_filtered::<Has<bevy::mesh::skinning::SkinnedMesh>, With<MeshMaterial3d<hadou_bevy::HadouOutline>>>()
        .iter(world)
        .collect();
    assert_eq!(hulls.len(), shaded.len(), "every mesh gets its outline hull");
    assert!(hulls.iter().all(|&skinned| skinned), "the hulls of the skinned hero are skinned by its joints");
    // The hulls are drawn (skinned, front faces culled): magenta pixels at the silhouette.
    let shot: Arc<Mutex<Option<Image>>> = Arc::default();
    let sink = shot.clone();
    app.world_mut().spawn(Screenshot::image(image)).observe(move |captured: On<ScreenshotCaptured>| {
        *sink.lock().unwrap() = Some(captured.image.clone());
    });
    for _ in 0..200 {
        app.update();
        if shot.lock().unwrap().is_some() {
            break;
        }
    }
    let picture = shot.lock().unwrap().take().expect("the screenshot came back");
    let data = picture.data.expect("a captured image has its bytes");
    let magenta = data.chunks_exact(4).filter(|p| p[0] > 200 && p[1] < 60 && p[2] > 200).count();
    let lit = data.chunks_exact(4).filter(|p| p[0] > 20 || p[1] > 20 || p[2] > 20).count();
    eprintln!("{magenta} outline pixels of {lit} drawn");
    assert!(magenta > 20, "the outline hulls show ({magenta} magenta pixels)");
    assert!(lit > 2 * magenta, "the character is drawn inside its outline");
    let materials = app.world().resource::<Assets<HadouMaterial>>();
    let textured =
        shaded.iter().filter(|(_, h)| materials.get(h).unwrap().surface.base_texture.x != 0).count();
    eprintln!("{} meshes shaded by hadou, {textured} with the glTF's base-colour texture", shaded.len());
}

/// A model whose `StandardMaterial` names a texture that cannot be loaded: the error is logged
/// (naming the entity and the key), the mesh is switched without the texture, the app keeps
/// running.
#[test]
fn a_missing_texture_is_an_error_and_the_mesh_is_shaded_without_it() {
    let test = "a_missing_texture_is_an_error_and_the_mesh_is_shaded_without_it";
    if !adapter_or_skip(test) {
        return;
    }
    let dir = std::env::temp_dir().join(format!("hadou-bevy-missing-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut app = App::new();
    app.add_plugins(
        common::windowless().set(AssetPlugin { file_path: dir.display().to_string(), ..default() }),
    )
    .add_plugins(HadouPlugin { asset_root: dir.clone() });
    app.finish();
    app.cleanup();
    let texture: Handle<Image> = app.world().resource::<AssetServer>().load("missing.png");
    let standard = app
        .world_mut()
        .resource_mut::<Assets<StandardMaterial>>()
        .add(StandardMaterial { base_color_texture: Some(texture), ..default() });
    let mesh = app.world_mut().resource_mut::<Assets<Mesh>>().add(Cuboid::new(1.0, 1.0, 1.0));
    let look = hadou_scene::Material { wave_blend: 0.5, ..Default::default() };
    let light = hadou_scene::Scene::load(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/light-normal-vs-wave.toml"),
    )
    .unwrap()
    .at(0.0)
    .light;
    let root = app
        .world_mut()
        .spawn((HadouShaded { material: look, light, shadow_mask: 0 }, Transform::default()))
        .id();
    let child = app.world_mut().spawn((Mesh3d(mesh), MeshMaterial3d(standard), ChildOf(root))).id();
    let mut switched = None;
    for _ in 0..500 {
        app.update();
        if let Some(m) = app.world().get::<MeshMaterial3d<HadouMaterial>>(child) {
            switched = Some(m.0.clone());
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let handle = switched.expect("the mesh is switched once the texture has failed");
    let material = app.world().resource::<Assets<HadouMaterial>>().get(&handle).unwrap();
    assert_eq!(material.surface.base_texture.x, 0, "no texture");
    assert_eq!(material.surface.wave_blend, 0.5);
    assert!(app.world().get::<MeshMaterial3d<StandardMaterial>>(child).is_none());
    app.update();
    std::fs::remove_dir_all(&dir).ok();
}
