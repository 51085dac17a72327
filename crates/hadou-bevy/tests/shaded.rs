//! `HadouShaded`: a glTF character loaded by Bevy's own loader (skinned, textured) is switched to
//! hadou's shading by one component on its scene root.

mod common;

use bevy::gltf::GltfAssetLabel;
use bevy::prelude::*;
use bevy::world_serialization::WorldAssetRoot;
use common::adapter_or_skip;
use hadou_bevy::{HadouMaterial, HadouPlugin, HadouShaded};
use std::path::Path;

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
    let textured =
        shaded.iter().filter(|(_, h)| materials.get(h).unwrap().surface.base_texture.x != 0).count();
    eprintln!("{} meshes shaded by hadou, {textured} with the glTF's base-colour texture", shaded.len());
}
