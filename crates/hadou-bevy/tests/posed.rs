//! Characters posed by hadou-scene in Bevy ([`HadouPose`]): `scenes/showcase.toml`'s VRM character
//! (a VRM Animation clip, spring bones blown by the beam's wind) is drawn by Bevy as `hadou render`
//! draws it at two times of its motion (mean absolute 8-bit difference ≤ [`MAX_MEAN`] each, the
//! pose of one time held apart from the other's by more than [`MIN_MOVED_MEAN`]), and bad input is
//! one clear error: an expression the file lacks or a broken `.vrma` fails the scene's load with
//! `file:line:col`, a pose that does not fit its file is one error naming the entity and `path`,
//! the character at rest, and a pose's values that are not finite leave their node at rest; the
//! pose's morph weights reach the meshes' `MorphWeights`.

mod common;

use bevy::asset::LoadState;
use bevy::gltf::GltfAssetLabel;
use bevy::prelude::*;
use bevy::world_serialization::WorldAssetRoot;
use common::adapter_or_skip;
use common::picture::{difference, pictures_in, scenes};
use hadou_bevy::{HadouPlugin, HadouPose, HadouScene, HadouShaded, PoseRejected};
use std::path::Path;

/// The largest mean absolute difference of the 8-bit RGB values accepted (tests/parity.rs's).
const MAX_MEAN: f64 = 2.0;

/// The smallest mean absolute 8-bit difference of Bevy's picture at the later time from hadou's
/// picture of that time with the character in the earlier time's pose (the character covers a
/// small part of the picture), and the smallest ratio of that difference to the one from hadou's
/// own picture of the time: the pose has moved, and Bevy draws the moved pose.
const MIN_MOVED_MEAN: f64 = 1.0;
const MIN_MOVED_RATIO: f64 = 3.0;

/// Both sides draw the showcase at its `[image]` size divided by this in each direction.
const SHRINK: u32 = 4;

/// The showcase at two times: before the clip starts (clip time 0, no wind) and mid-motion with
/// the wind on the springs (tests/parity.rs's time of the scene, docs/bevy.md's table).
const TIMES: [f32; 2] = [0.3, 0.9];

#[test]
fn the_showcase_character_is_posed_as_hadou_render_poses_it() {
    let test = "the_showcase_character_is_posed_as_hadou_render_poses_it";
    if !adapter_or_skip(test) {
        return;
    }
    let start = std::time::Instant::now();
    let file = "showcase.toml";
    let scene = hadou_scene::Scene::load(scenes().join(file)).unwrap();
    assert!(scene.object_posed_by_hadou(0), "the showcase's character is posed by hadou-scene");
    let mut size = (1, 1);
    let references: Vec<_> = TIMES
        .iter()
        .map(|&time| {
            let mut frame = scene.at(time);
            frame.samples = 1;
            frame.bloom = None;
            (frame.width, frame.height) = (frame.width / SHRINK, frame.height / SHRINK);
            size = (frame.width, frame.height);
            hadou_cpu::render(&frame)
        })
        .collect();
    let (bevy, _) = pictures_in(&scenes(), file, &TIMES, size, None, bevy::render::view::Msaa::Off);
    let mut means = Vec::new();
    for ((time, b), r) in TIMES.iter().zip(&bevy).zip(&references) {
        let (mean, max) = difference(b, r);
        means.push(mean);
        eprintln!("{file} at t = {time}: mean {mean:.3}, largest {max}");
        assert!(mean <= MAX_MEAN, "{file} at t = {time}: mean {mean:.3} > {MAX_MEAN} (largest {max})");
    }
    // The pose moves with time, and Bevy draws the pose of its time: hadou's frame at the later
    // time with the character in the earlier time's pose is far from Bevy's picture.
    let mut swapped = scene.at(TIMES[1]);
    swapped.objects[0].mesh = scene.at(TIMES[0]).objects[0].mesh.clone();
    swapped.samples = 1;
    swapped.bloom = None;
    (swapped.width, swapped.height) = size;
    let (mean, max) = difference(&bevy[1], &hadou_cpu::render(&swapped));
    eprintln!(
        "{file} at t = {} against the pose of t = {}: mean {mean:.3}, largest {max}",
        TIMES[1], TIMES[0]
    );
    assert!(
        mean > MIN_MOVED_MEAN && mean > MIN_MOVED_RATIO * means[1],
        "the pose does not move: mean {mean:.3} against the earlier pose, {:.3} against its own",
        means[1]
    );
    eprintln!("{test}: {:.1} s", start.elapsed().as_secs_f64());
}

/// A folder holding the showcase's character and clip and `scene.toml` with the hero given `keys`.
fn bad_scene(test: &str, keys: &str, vrma: &[u8]) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("hadou-bevy-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(scenes().join("assets/showcase.vrm"), dir.join("hero.vrm")).unwrap();
    std::fs::write(dir.join("hero.vrma"), vrma).unwrap();
    let text = format!(
        "[camera]\nposition = [0, 1, 3]\ntarget = [0, 1, 0]\n\n[[object]]\nname = \"hero\"\nkind = \"gltf\"\n\
         path = \"hero.vrm\"\n{keys}\n"
    );
    std::fs::write(dir.join("scene.toml"), text).unwrap();
    dir
}

/// The error the scene asset `scene.toml` in `dir` fails to load with, the app updated on after.
fn load_error(dir: &Path) -> String {
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        AssetPlugin { file_path: dir.display().to_string(), ..default() },
        bevy::mesh::MeshPlugin,
    ))
    .add_plugins(HadouPlugin { asset_root: dir.to_path_buf() });
    let handle: Handle<HadouScene> = app.world().resource::<AssetServer>().load("scene.toml");
    for _ in 0..1000 {
        app.update();
        if let LoadState::Failed(e) = app.world().resource::<AssetServer>().load_state(&handle) {
            let message = e.to_string();
            for _ in 0..3 {
                app.update(); // the app runs on
            }
            return message;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    panic!("the scene did not fail to load");
}

#[test]
fn a_missing_expression_or_a_broken_vrma_fails_the_scene_with_its_location() {
    let vrma = std::fs::read(scenes().join("assets/showcase.vrma")).unwrap();
    let dir = bad_scene("bad-expression", "expressions = { no_such_face = 1.0 }", &vrma);
    let e = load_error(&dir);
    assert!(e.contains("scene.toml:9:") && e.contains("no expression \"no_such_face\""), "{e}");
    let dir = bad_scene("bad-vrma", "animation_file = \"hero.vrma\"", &vrma[..vrma.len() / 2]);
    let e = load_error(&dir);
    assert!(e.contains("scene.toml:9:") && e.contains("hero.vrma"), "{e}");
}

/// Every named entity's `(name, translation, rotation)` below `root`, by name.
fn nodes(world: &mut World, root: Entity) -> Vec<(String, Vec3, Quat)> {
    let below: Vec<Entity> = world
        .query::<(Entity, &ChildOf)>()
        .iter(world)
        .filter(|(e, _)| {
            let mut at = *e;
            while let Some(parent) = world.get::<ChildOf>(at) {
                at = parent.parent();
                if at == root {
                    return true;
                }
            }
            false
        })
        .map(|(e, _)| e)
        .collect();
    let mut out: Vec<_> = below
        .into_iter()
        .filter_map(|e| {
            let (n, t) = (world.get::<Name>(e)?, world.get::<Transform>(e)?);
            Some((n.to_string(), t.translation, t.rotation))
        })
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

#[test]
fn a_pose_that_does_not_fit_its_file_is_an_error_and_the_character_stays_at_rest() {
    let test = "a_pose_that_does_not_fit_its_file_is_an_error_and_the_character_stays_at_rest";
    if !adapter_or_skip(test) {
        return;
    }
    let start = std::time::Instant::now();
    let root = scenes().canonicalize().unwrap();
    let scene = hadou_scene::Scene::load(root.join("showcase.toml")).unwrap();
    let pose = scene.object_node_pose_at(0, 1.8).expect("the showcase's character has a node pose");
    let frame = scene.at(1.8);
    let mut app = App::new();
    app.add_plugins(
        common::windowless().set(AssetPlugin { file_path: root.display().to_string(), ..default() }),
    )
    .add_plugins(HadouPlugin { asset_root: root.clone() });
    // The `.vrm` loader is registered as the plugins finish.
    app.finish();
    app.cleanup();
    let look = frame.objects[0].material(0).clone();
    let mut spawn = |who: &str, pose: Option<hadou_scene::NodePose>| {
        let handle = app
            .world()
            .resource::<AssetServer>()
            .load(GltfAssetLabel::Scene(0).from_asset("assets/showcase.vrm"));
        let e = app
            .world_mut()
            .spawn((
                Name::new(who.to_string()),
                WorldAssetRoot(handle),
                HadouShaded::new(look.clone(), frame.light, 0),
            ))
            .id();
        if let Some(pose) = pose {
            app.world_mut().entity_mut(e).insert(HadouPose(pose));
        }
        e
    };
    let mut short = pose.clone();
    short.locals.pop();
    let posed = spawn("posed", Some(pose.clone()));
    let wrong = spawn("wrong", Some(short));
    let still = spawn("still", None);
    // A node the pose moves given values that are not finite: that node keeps its rest.
    let (_, rig) = hadou_scene::load_gltf_rig(&root.join("assets/showcase.vrm")).unwrap();
    let rest_pose = rig.unwrap().node_locals(&hadou_scene::PoseInput::default());
    let moved =
        (0..pose.locals.len()).find(|&i| pose.locals[i] != rest_pose.locals[i]).expect("a node moves");
    let mut broken = pose.clone();
    broken.locals[moved] = Some(([f32::NAN; 3], [f32::INFINITY; 4], [f32::NAN; 3]));
    for w in &mut broken.weights {
        w.iter_mut().for_each(|x| *x = f32::NAN);
    }
    let not_finite = spawn("not finite", Some(broken));
    // Morph weights (expressions) reach the meshes' `MorphWeights`.
    let mut weighted = pose.clone();
    for w in &mut weighted.weights {
        w.iter_mut().for_each(|x| *x = 0.25);
    }
    let morphs = weighted.weights.iter().filter(|w| !w.is_empty()).count();
    assert!(morphs > 0, "showcase.vrm has morph targets");
    let weighted = spawn("weighted", Some(weighted));
    let mut rejected = None;
    for _ in 0..1000 {
        app.update();
        rejected = app.world().get::<PoseRejected>(wrong).cloned();
        let rest = nodes(app.world_mut(), still);
        if rejected.is_some() && !rest.is_empty() && nodes(app.world_mut(), posed) != rest {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let line = rejected.expect("a pose that does not fit is rejected").0;
    assert!(
        line.contains(&wrong.to_string()) && line.contains("\"wrong\"") && line.contains("`path`"),
        "{line}"
    );
    assert!(line.contains(&format!("{} glTF nodes", pose.locals.len() - 1)), "{line}");
    assert!(app.world().get::<PoseRejected>(posed).is_none());
    for _ in 0..5 {
        app.update(); // the app runs on
    }
    let rest = nodes(app.world_mut(), still);
    assert!(!rest.is_empty());
    assert_eq!(nodes(app.world_mut(), wrong), rest, "a rejected pose leaves the character at rest");
    let (kept, drawn) = (nodes(app.world_mut(), not_finite), nodes(app.world_mut(), posed));
    assert!(
        kept.iter().all(|(_, t, r)| t.is_finite() && r.is_finite()),
        "no value that is not finite is drawn"
    );
    let differ: Vec<_> = kept.iter().zip(&drawn).zip(&rest).filter(|((k, d), _)| k != d).collect();
    assert!(!differ.is_empty(), "the node given values that are not finite is not posed");
    assert!(differ.iter().all(|((k, _), r)| k == r), "it keeps its rest: {differ:?}");
    let weights = app
        .world_mut()
        .query::<&bevy::mesh::morph::MorphWeights>()
        .iter(app.world())
        .all(|w| w.weights().iter().all(|x| x.is_finite()));
    assert!(weights, "no morph weight that is not finite");
    let below: Vec<Entity> = app.world().get::<Children>(weighted).into_iter().flatten().copied().collect();
    let mut set = 0;
    let mut stack = below;
    while let Some(e) = stack.pop() {
        if let Some(w) = app.world().get::<bevy::mesh::morph::MorphWeights>(e) {
            assert!(w.weights().iter().all(|&x| x == 0.25), "{:?}", w.weights());
            set += 1;
        }
        stack.extend(app.world().get::<Children>(e).into_iter().flatten().copied());
    }
    assert_eq!(set, morphs, "every node with morph targets has the pose's weights");
    let drawn = nodes(app.world_mut(), posed);
    assert_ne!(drawn, rest, "the pose at 1.8 s moves the character");
    // Every node of the pose has hadou's local transform.
    let matched = pose
        .locals
        .iter()
        .flatten()
        .filter(|(t, r, _)| {
            drawn.iter().any(|(_, dt, dr)| {
                dt.abs_diff_eq(Vec3::from_array(*t), 1e-6) && dr.abs_diff_eq(Quat::from_array(*r), 1e-6)
            })
        })
        .count();
    assert_eq!(matched, pose.locals.iter().flatten().count(), "every node has hadou's transform");
    eprintln!("{test}: {:.1} s", start.elapsed().as_secs_f64());
}
