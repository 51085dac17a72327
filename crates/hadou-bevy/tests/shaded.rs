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
use hadou_bevy::{HadouMaterial, HadouPlugin, HadouSceneRoot, HadouShaded, SceneClock, SpawnedScene};
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
    let character =
        app.world_mut().spawn((WorldAssetRoot(handle), HadouShaded::new(look, scene.light, 0b10))).id();
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
    assert_eq!(hulls.len(), 2 * shaded.len(), "every mesh gets its outline hull and closing hull");
    assert!(hulls.iter().all(|&skinned| skinned), "the hulls of the skinned hero are skinned by its joints");
    // The hulls are drawn (skinned, front faces culled): magenta pixels at the silhouette. Bevy
    // compiles the pipelines in the background (a cold shader cache on a software adapter can take
    // a while), and a frame taken before they are ready lacks what they draw: screenshots are
    // taken until one shows the outline, for at most three minutes.
    let started = std::time::Instant::now();
    let (magenta, lit) = loop {
        let shot: Arc<Mutex<Option<Image>>> = Arc::default();
        let sink = shot.clone();
        app.world_mut().spawn(Screenshot::image(image.clone())).observe(
            move |captured: On<ScreenshotCaptured>| {
                *sink.lock().unwrap() = Some(captured.image.clone());
            },
        );
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
        if magenta > 20 || started.elapsed() > std::time::Duration::from_secs(180) {
            break (magenta, lit);
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    };
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
    let root = app.world_mut().spawn((HadouShaded::new(look, light, 0), Transform::default())).id();
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

/// A scene file's `kind = "gltf"` object is loaded by Bevy's own glTF loader (skinned by Bevy)
/// and each of its meshes takes its own slot's look from the scene (the glTF material's colour
/// and texture as hadou read them, the scene's `wave_blend`, outline and model); a changed look
/// on the object's `HadouShaded` (what a track or a game system sets) reaches its materials.
#[test]
fn a_scenes_gltf_object_is_loaded_by_bevy_with_each_slots_look() {
    let test = "a_scenes_gltf_object_is_loaded_by_bevy_with_each_slots_look";
    if !adapter_or_skip(test) {
        return;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes").canonicalize().unwrap();
    let mut app = App::new();
    app.add_plugins(
        common::windowless().set(AssetPlugin { file_path: root.display().to_string(), ..default() }),
    )
    .add_plugins(HadouPlugin { asset_root: root.clone() });
    let scene_handle = app.world().resource::<AssetServer>().load("light-normal-vs-wave.toml");
    let scene_root =
        app.world_mut().spawn(HadouSceneRoot { scene: scene_handle, clock: SceneClock::Frozen(0.75) }).id();
    app.finish();
    app.cleanup();
    let ready = |app: &App| app.world().get::<SpawnedScene>(scene_root).is_some_and(|s| s.ready);
    for _ in 0..1000 {
        app.update();
        if ready(&app) {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert!(ready(&app), "the glTF object loads and is switched");
    let scene = hadou_scene::Scene::load(root.join("light-normal-vs-wave.toml")).unwrap();
    let frame = scene.at(0.75);
    let index = scene.object_names().iter().position(|n| *n == "hero").unwrap();
    let expected = &frame.objects[index];
    let hero = app.world().get::<SpawnedScene>(scene_root).unwrap().objects[index];
    assert!(app.world().get::<WorldAssetRoot>(hero).is_some(), "the hero is Bevy's glTF scene");
    let shaded = app.world().get::<HadouShaded>(hero).expect("switched by HadouShaded");
    assert_eq!(shaded.slots, expected.materials, "the frame's looks, slot by slot");
    assert_eq!(shaded.light, frame.light);

    let world = app.world_mut();
    let mut below = Vec::new();
    let mut meshes =
        world.query::<(Entity, &MeshMaterial3d<HadouMaterial>, Has<bevy::mesh::skinning::SkinnedMesh>)>();
    let mut parents = world.query::<&ChildOf>();
    for (entity, material, skinned) in meshes.iter(world) {
        let mut e = entity;
        while let Ok(p) = parents.get(world, e) {
            e = p.parent();
            if e == hero {
                below.push((material.0.clone(), skinned));
                break;
            }
        }
    }
    assert!(!below.is_empty());
    assert!(below.iter().all(|(_, skinned)| *skinned), "hero.glb's meshes are skinned by Bevy");
    let materials = app.world().resource::<Assets<HadouMaterial>>();
    let mut slots_seen = std::collections::BTreeSet::new();
    for (handle, _) in &below {
        let surface = materials.get(handle).unwrap().surface;
        let slot = expected
            .materials
            .iter()
            .position(|m| m.base_color == surface.base_color.truncate().to_array())
            .unwrap_or_else(|| panic!("{:?} is the base colour of one of the slots", surface.base_color));
        slots_seen.insert(slot);
        let look = &expected.materials[slot];
        assert_eq!(surface.wave_blend, look.wave_blend);
        assert_eq!(
            surface.base_texture.x != 0,
            look.base_texture.is_some(),
            "slot {slot}'s texture as hadou read it"
        );
    }
    assert!(slots_seen.len() > 1, "the meshes take different slots: {slots_seen:?}");

    // A game system changes the hero's look: its materials follow.
    let mut shaded = app.world_mut().get_mut::<HadouShaded>(hero).unwrap();
    for slot in &mut shaded.slots {
        slot.wave_blend = 0.25;
    }
    let root_entity = scene_root;
    // The scene's clock sets the look back every frame: stop it from doing so by removing the
    // root's scene link (the spawned entities stay).
    app.world_mut().entity_mut(root_entity).remove::<HadouSceneRoot>();
    app.update();
    app.update();
    let materials = app.world().resource::<Assets<HadouMaterial>>();
    for (handle, _) in &below {
        assert_eq!(materials.get(handle).unwrap().surface.wave_blend, 0.25);
    }
}
