//! A scene's clip played by Bevy (`HadouClip`) and the shadows cast by the pose Bevy draws: the
//! sun's shadow-map silhouette of a character Bevy poses at a clip time is held to `hadou render`'s
//! at the same time (IoU of the shadowed ground pixels ≥ [`MIN_IOU`]), another clip time moves it,
//! and a clip the file lacks is one error naming the entity and `animation`, the character at rest.
//! A mesh's morph targets, blended by Bevy, shape its shadow as they shape `hadou render`'s.

mod common;

use bevy::gltf::GltfAssetLabel;
use bevy::prelude::*;
use bevy::world_serialization::WorldAssetRoot;
use common::adapter_or_skip;
use common::picture::{pictures_in, scenes};
use hadou_bevy::{ClipRejected, HadouClip, HadouPlugin, HadouShaded};
use hadou_math::shade::linear_to_srgb8;

/// The smallest intersection over union of Bevy's and `hadou render`'s shadow silhouettes: the
/// same shadow up to pixels along its edge (the map's texels, rasterization).
const MIN_IOU: f64 = 0.95;

/// The largest intersection over union of the silhouettes of two poses that differ.
const MAX_MOVED_IOU: f64 = 0.85;

/// The character of `scenes/light-brace.toml` playing its `brace` clip on a ground plane, seen
/// from above, with a low sun casting its shadow (a shadow map) on the ground.
const SCENE: &str = r#"
background = [0.0, 0.0, 0.0]
[image]
width = 192
height = 144
[camera]
position = [1.2, 4.5, 3.2]
target = [1.2, 0.0, 0.0]
fov = 50.0
near = 0.1
far = 100.0
[light]
direction = [0.7, -0.55, -0.2]
color = [1.0, 1.0, 1.0]
ambient = [0.2, 0.2, 0.2]
[color]
mode = "faithful"
[[material]]
name = "ground"
model = "diffuse"
base_color = [0.8, 0.8, 0.8]
[[object]]
name = "hero"
kind = "gltf"
path = "assets/brace.glb"
animation = "brace"
animation_loop = false
[[object]]
name = "ground"
kind = "plane"
size = [14.0, 14.0]
material = "ground"
[[shadow]]
name = "sun"
kind = "sun"
method = "map"
map_size = 1024
casters = "hero"
receivers = "ground"
color = [0.0, 0.0, 0.0]
opacity = 1.0
"#;

/// The folder of the test scene (one for each `test`, as tests run in parallel), with the
/// character's file beside it.
fn scene_folder(test: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("hadou-bevy-{test}-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("assets")).unwrap();
    std::fs::copy(scenes().join("assets/brace.glb"), dir.join("assets/brace.glb")).unwrap();
    std::fs::write(dir.join("pose.toml"), SCENE).unwrap();
    dir
}

/// The ground pixels in shadow: those where hadou's picture of the frame without its shadows is
/// the lit ground (its most frequent colour: the ground fills most of the picture, one colour under
/// the sun) and `picture` (sRGB bytes, 4 a pixel) is below half the lit ground's brightness.
fn silhouette(picture: &[u8], unshadowed: &hadou_scene::Image) -> Vec<bool> {
    let mut counts = std::collections::HashMap::new();
    for c in &unshadowed.color {
        *counts.entry(c.map(linear_to_srgb8)).or_insert(0u32) += 1;
    }
    let lit = counts.into_iter().max_by_key(|(c, n)| (*n, *c)).expect("a picture").0;
    let sum = |c: &[u8]| c.iter().take(3).map(|&v| u32::from(v)).sum::<u32>();
    picture
        .chunks_exact(4)
        .zip(&unshadowed.color)
        .map(|(p, c)| {
            let ground = c.map(linear_to_srgb8).iter().zip(&lit).all(|(a, b)| a.abs_diff(*b) <= 2);
            ground && 2 * sum(p) < sum(&lit)
        })
        .collect()
}

fn iou(a: &[bool], b: &[bool]) -> f64 {
    let both = a.iter().zip(b).filter(|(x, y)| **x && **y).count();
    let either = a.iter().zip(b).filter(|(x, y)| **x || **y).count();
    both as f64 / either.max(1) as f64
}

/// hadou's picture of the frame at `time` (one sample), as sRGB bytes, and the frame without
/// its shadows.
fn hadou_pictures(scene: &hadou_scene::Scene, time: f32) -> (Vec<u8>, hadou_scene::Image) {
    let mut frame = scene.at(time);
    frame.samples = 1;
    let shadowed = hadou_cpu::render(&frame);
    frame.shadows.clear();
    let bytes = shadowed.color.iter().flat_map(|c| [c[0], c[1], c[2], 1.0].map(linear_to_srgb8)).collect();
    (bytes, hadou_cpu::render(&frame))
}

#[test]
fn the_shadow_is_cast_by_the_pose_bevy_draws() {
    let test = "the_shadow_is_cast_by_the_pose_bevy_draws";
    if !adapter_or_skip(test) {
        return;
    }
    let dir = scene_folder(test);
    let scene = hadou_scene::Scene::load(dir.join("pose.toml")).unwrap();
    let (braced, rest) = (1.6, 0.0);
    let size = (scene.width(), scene.height());
    let (hadou_braced, unshadowed) = hadou_pictures(&scene, braced);
    let (_, unshadowed_rest) = hadou_pictures(&scene, rest);
    // One app: braced first, then the clock frozen at the rest time (the clip moves the joints).
    let (bevy, _) =
        pictures_in(&dir, "pose.toml", &[braced, rest], size, None, bevy::render::view::Msaa::Off);
    let reference = silhouette(&hadou_braced, &unshadowed);
    let drawn = silhouette(&bevy[0], &unshadowed);
    let count = reference.iter().filter(|s| **s).count();
    assert!(count > 300, "the test's shadow covers {count} pixels: too few to compare");
    let same = iou(&drawn, &reference);
    eprintln!("braced at t = {braced}: {count} shadowed pixels, IoU {same:.3} against hadou render");
    let moved = iou(&silhouette(&bevy[1], &unshadowed_rest), &drawn);
    eprintln!("at rest (t = {rest}) against braced: IoU {moved:.3}");
    let _ = std::fs::remove_dir_all(&dir);
    assert!(same >= MIN_IOU, "Bevy's shadow of the braced pose is not hadou's: IoU {same:.3} < {MIN_IOU}");
    assert!(moved <= MAX_MOVED_IOU, "another pose must move the shadow: IoU {moved:.3} > {MAX_MOVED_IOU}");
}

/// Every joint's `(name, translation, rotation)` below `root`, by name.
fn joints(world: &mut World, root: Entity) -> Vec<(String, Vec3, Quat)> {
    let mut out: Vec<_> = world
        .query::<(Entity, &Name, &Transform)>()
        .iter(world)
        .filter(|(e, _, _)| *e != root)
        .map(|(e, n, t)| (e, n.to_string(), t.translation, t.rotation))
        .collect::<Vec<_>>()
        .into_iter()
        .filter(|(e, ..)| {
            let mut at = *e;
            while let Some(parent) = world.get::<ChildOf>(at) {
                at = parent.parent();
                if at == root {
                    return true;
                }
            }
            false
        })
        .map(|(_, n, t, r)| (n, t, r))
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

#[test]
fn a_clip_the_file_lacks_is_an_error_and_the_character_stays_at_rest() {
    let test = "a_clip_the_file_lacks_is_an_error_and_the_character_stays_at_rest";
    if !adapter_or_skip(test) {
        return;
    }
    let root = scenes().canonicalize().unwrap();
    let mut app = App::new();
    app.add_plugins(
        common::windowless().set(AssetPlugin { file_path: root.display().to_string(), ..default() }),
    )
    .add_plugins(HadouPlugin { asset_root: root.clone() });
    let frame = hadou_scene::Scene::load(root.join("light-brace.toml")).unwrap().at(1.0);
    let look = frame.objects[0].material(0).clone();
    let mut spawn = |clip: &str| {
        let handle = app
            .world()
            .resource::<AssetServer>()
            .load(GltfAssetLabel::Scene(0).from_asset("assets/brace.glb"));
        app.world_mut()
            .spawn((
                Name::new(format!("hero playing {clip}")),
                WorldAssetRoot(handle),
                HadouShaded::new(look.clone(), frame.light, 0),
                HadouClip { name: clip.to_string(), time: 1.2 },
            ))
            .id()
    };
    let (played, wrong) = (spawn("brace"), spawn("no such clip"));
    let still = spawn("brace");
    app.world_mut().entity_mut(still).remove::<HadouClip>();
    app.finish();
    app.cleanup();
    let mut rejected = None;
    for _ in 0..1000 {
        app.update();
        rejected = app.world().get::<ClipRejected>(wrong).cloned();
        let posed = joints(app.world_mut(), played) != joints(app.world_mut(), still);
        if rejected.is_some() && posed {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let line = rejected.expect("a clip the file lacks is rejected").0;
    assert!(line.contains(&wrong.to_string()) && line.contains("`animation`"), "{line}");
    assert!(line.contains("\"no such clip\"") && line.contains("\"brace\""), "{line}");
    assert!(app.world().get::<ClipRejected>(played).is_none());
    // The app runs on; the rejected character stays at rest, the played one is posed.
    for _ in 0..5 {
        app.update();
    }
    let rest = joints(app.world_mut(), still);
    assert!(!rest.is_empty());
    assert_eq!(joints(app.world_mut(), wrong), rest, "a rejected clip leaves the character at rest");
    assert_ne!(joints(app.world_mut(), played), rest, "the `brace` clip at 1.2 s poses the character");
}

/// A glTF binary of one mesh: a plate 0.2 × 1.6 × 0.8 standing on the ground at the origin
/// (24 vertices, flat faces) with one morph target that moves its top face by `(0, 0, 1)` (the
/// plate leans sideways to the sun), blended by the mesh's default weight `weight`.
fn plate_glb(weight: f32) -> Vec<u8> {
    let (x, y, z) = (0.1f32, 1.6f32, 0.4f32);
    let faces: [([f32; 3], [[f32; 3]; 4]); 6] = [
        ([1.0, 0.0, 0.0], [[x, 0.0, -z], [x, y, -z], [x, y, z], [x, 0.0, z]]),
        ([-1.0, 0.0, 0.0], [[-x, 0.0, z], [-x, y, z], [-x, y, -z], [-x, 0.0, -z]]),
        ([0.0, 1.0, 0.0], [[-x, y, -z], [-x, y, z], [x, y, z], [x, y, -z]]),
        ([0.0, -1.0, 0.0], [[-x, 0.0, z], [-x, 0.0, -z], [x, 0.0, -z], [x, 0.0, z]]),
        ([0.0, 0.0, 1.0], [[x, 0.0, z], [x, y, z], [-x, y, z], [-x, 0.0, z]]),
        ([0.0, 0.0, -1.0], [[-x, 0.0, -z], [-x, y, -z], [x, y, -z], [x, 0.0, -z]]),
    ];
    let (mut pos, mut nor, mut lean, mut idx) = (Vec::new(), Vec::new(), Vec::new(), Vec::<u16>::new());
    for (n, quad) in faces {
        let base = pos.len() as u16;
        for p in quad {
            pos.push(p);
            nor.push(n);
            lean.push(if p[1] > 0.0 { [0.0, 0.0, 1.0] } else { [0.0; 3] });
        }
        idx.extend([0, 1, 2, 0, 2, 3].map(|i| base + i));
    }
    let floats = |v: &[[f32; 3]]| v.iter().flatten().flat_map(|f| f.to_le_bytes()).collect::<Vec<u8>>();
    let mut bin = Vec::new();
    let mut views = Vec::new();
    for part in
        [floats(&pos), floats(&nor), floats(&lean), idx.iter().flat_map(|i| i.to_le_bytes()).collect()]
    {
        views.push(format!(r#"{{"buffer":0,"byteOffset":{},"byteLength":{}}}"#, bin.len(), part.len()));
        bin.extend(part);
        bin.resize(bin.len().next_multiple_of(4), 0);
    }
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0,"name":"plate"}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"NORMAL":1}},"indices":3,"targets":[{{"POSITION":2}}]}}],"weights":[{weight}]}}],
"accessors":[
{{"bufferView":0,"componentType":5126,"count":24,"type":"VEC3","min":[{nx},0,{nz}],"max":[{x},{y},{z}]}},
{{"bufferView":1,"componentType":5126,"count":24,"type":"VEC3"}},
{{"bufferView":2,"componentType":5126,"count":24,"type":"VEC3","min":[0,0,0],"max":[0,0,1]}},
{{"bufferView":3,"componentType":5123,"count":36,"type":"SCALAR"}}],
"bufferViews":[{}],"buffers":[{{"byteLength":{}}}]}}"#,
        views.join(","),
        bin.len(),
        nx = -x,
        nz = -z,
    );
    let mut json = json.into_bytes();
    json.resize(json.len().next_multiple_of(4), b' ');
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend(((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(json);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(bin);
    glb
}

#[test]
fn the_shadow_is_cast_by_the_morph_targets_bevy_draws() {
    let test = "the_shadow_is_cast_by_the_morph_targets_bevy_draws";
    if !adapter_or_skip(test) {
        return;
    }
    let dir = scene_folder(test);
    std::fs::write(dir.join("assets/leaning.glb"), plate_glb(1.0)).unwrap();
    std::fs::write(dir.join("assets/upright.glb"), plate_glb(0.0)).unwrap();
    let plate = |file: &str| {
        let text = SCENE
            .replace("assets/brace.glb", &format!("assets/{file}"))
            .replace("animation = \"brace\"\nanimation_loop = false\n", "");
        let name = format!("{file}.toml");
        std::fs::write(dir.join(&name), text).unwrap();
        name
    };
    let (leaning, upright) = (plate("leaning.glb"), plate("upright.glb"));
    let scene = hadou_scene::Scene::load(dir.join(&leaning)).unwrap();
    let size = (scene.width(), scene.height());
    let (hadou_leaning, unshadowed) = hadou_pictures(&scene, 0.0);
    let (hadou_upright, _) = hadou_pictures(&hadou_scene::Scene::load(dir.join(&upright)).unwrap(), 0.0);
    let (bevy, _) = pictures_in(&dir, &leaning, &[0.0], size, None, bevy::render::view::Msaa::Off);
    let _ = std::fs::remove_dir_all(&dir);
    let reference = silhouette(&hadou_leaning, &unshadowed);
    let count = reference.iter().filter(|s| **s).count();
    assert!(count > 300, "the test's shadow covers {count} pixels: too few to compare");
    let drawn = silhouette(&bevy[0], &unshadowed);
    let same = iou(&drawn, &reference);
    // The plate without its morph: what the shadow was before the morph targets were applied.
    let unmorphed = iou(&drawn, &silhouette(&hadou_upright, &unshadowed));
    eprintln!("leaning plate: {count} shadowed pixels, IoU {same:.3} against hadou render, {unmorphed:.3} against the upright plate's");
    assert!(same >= MIN_IOU, "Bevy's shadow of the morphed plate is not hadou's: IoU {same:.3} < {MIN_IOU}");
    assert!(
        unmorphed <= MAX_MOVED_IOU,
        "the morph must move the shadow: IoU {unmorphed:.3} > {MAX_MOVED_IOU}"
    );
}
