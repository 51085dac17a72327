//! The `[area_light]` in Bevy. `scenes/soft-gradient.toml` and `scenes/soft-plaster.toml`, spawned
//! by `HadouSceneRoot` and drawn by Bevy (the lamp's light by hadou-gpu's `area_term`, its soft
//! shadows by the traced resolve's walk of the casters' hierarchy per fragment, the hierarchy
//! built from the meshes Bevy draws: the plaster figure is the glTF file as Bevy's loader spawns
//! and skins it), against hadou-cpu's render of the same frame at one sample per pixel (as the
//! other tests of `against_cpu.rs`). Both scenes name the exact resolve (the two maps), which
//! Bevy does not draw: Bevy draws the traced resolve whatever the scene names, so the reference is
//! the same frame with its resolve set to traced (`samples` at the traced resolve's default).
//! And bad values of a `HadouAreaLight`: each names its key, the light is not drawn, the app
//! runs on.

mod common;

use bevy::prelude::*;
use bevy::render::storage::ShaderBuffer;
use common::adapter_or_skip;
use common::picture::{bevy_picture, difference, scenes};
use hadou_bevy::{
    area_rejection_message, check_area_light, AreaLightRejected, HadouAreaLight, HadouPlugin, AREA_DATA,
    AREA_NODES, AREA_TRIS,
};
use hadou_math::soft::LampShape;
use hadou_scene::{SoftResolve, DEFAULT_TRACE_SAMPLES};

/// The largest mean absolute difference of the 8-bit RGB values accepted (as in against_cpu.rs).
const MAX_MEAN: f64 = 2.0;

/// Both sides draw the scenes at this size (square, as the scenes' own 512²): on lavapipe every
/// fragment walks the hierarchy alone, and `soft-plaster` at 512² takes 45–50 s a frame in Bevy
/// on the 2-core machine, over a dozen frames a test.
const SIZE: u32 = 112;

/// The scene `file` at `time` in Bevy against hadou-cpu's traced render of the same frame; and,
/// so that the bound tells the shadows apart, against the same frame with the lamp casting no
/// shadow (its light alone).
fn soft_scene_matches(file: &str, time: f32) {
    let mut frame = hadou_scene::Scene::load(scenes().join(file)).unwrap().at(time);
    frame.samples = 1;
    assert_eq!(frame.width, frame.height, "a square scene");
    (frame.width, frame.height) = (SIZE, SIZE);
    let light = frame.area_light.as_mut().expect("the scene has an [area_light]");
    assert_eq!(light.resolve, SoftResolve::Exact, "the scene names the exact resolve");
    light.resolve = SoftResolve::Traced { samples: DEFAULT_TRACE_SAMPLES };
    let start = std::time::Instant::now();
    let reference = hadou_cpu::render(&frame);
    eprintln!("{file}: hadou-cpu's traced frame in {:.1} s", start.elapsed().as_secs_f64());
    let (bevy, _) = bevy_picture(file, time, (frame.width, frame.height), None);
    let (mean, max) = difference(&bevy, &reference);
    eprintln!("{file} at t = {time}, {}×{}: mean {mean:.3}, largest {max}", frame.width, frame.height);
    assert!(mean <= MAX_MEAN, "mean absolute 8-bit difference {mean:.3} > {MAX_MEAN} (largest {max})");
    // How far Bevy's traced shadows are from `hadou render` of the scene as it is (the two maps).
    frame.area_light.as_mut().unwrap().resolve = SoftResolve::Exact;
    let (exact, exact_max) = difference(&bevy, &hadou_cpu::render(&frame));
    eprintln!("against the scene's own resolve (exact): mean {exact:.3}, largest {exact_max}");
    frame.area_light.as_mut().unwrap().casters.clear();
    let (unshadowed, _) = difference(&bevy, &hadou_cpu::render(&frame));
    eprintln!("against the same frame without the lamp's shadows: mean {unshadowed:.3}");
    assert!(unshadowed > MAX_MEAN, "the soft shadows are not drawn ({unshadowed:.3})");
    frame.area_light = None;
    let (unlit, _) = difference(&bevy, &hadou_cpu::render(&frame));
    eprintln!("against the same frame without the [area_light]: mean {unlit:.3}");
    assert!(unlit > MAX_MEAN, "the lamp's light is not drawn ({unlit:.3})");
}

#[test]
fn soft_gradient_in_bevy_is_the_picture_of_hadou_render() {
    if adapter_or_skip("soft_gradient_in_bevy_is_the_picture_of_hadou_render") {
        soft_scene_matches("soft-gradient.toml", 1.0);
    }
}

#[test]
fn soft_plaster_in_bevy_is_the_picture_of_hadou_render() {
    if adapter_or_skip("soft_plaster_in_bevy_is_the_picture_of_hadou_render") {
        soft_scene_matches("soft-plaster.toml", 1.0);
    }
}

fn lamp(casters: Vec<Entity>) -> HadouAreaLight {
    HadouAreaLight {
        shape: LampShape::Disc,
        position: Vec3::new(2.0, 3.0, 1.0),
        target: Vec3::ZERO,
        size: 0.5,
        color: Vec3::ONE,
        samples: 64,
        casters,
        enabled: true,
    }
}

fn key_of(light: &HadouAreaLight) -> &'static str {
    check_area_light(light).expect_err("the light must be rejected").key
}

#[test]
fn each_bad_value_names_its_key() {
    assert_eq!(check_area_light(&lamp(Vec::new())), Ok(()));
    let bad = |f: &dyn Fn(&mut HadouAreaLight)| {
        let mut l = lamp(Vec::new());
        f(&mut l);
        key_of(&l)
    };
    assert_eq!(bad(&|l| l.size = f32::NAN), "size");
    assert_eq!(bad(&|l| l.size = 0.0), "size");
    assert_eq!(bad(&|l| l.size = -0.5), "size");
    // The size reaching the target: |L − G| = √14 ≈ 3.74.
    assert_eq!(bad(&|l| l.size = 3.75), "size");
    assert_eq!(bad(&|l| l.samples = 0), "samples");
    assert_eq!(bad(&|l| l.samples = hadou_scene::MAX_TRACE_SAMPLES + 1), "samples");
    assert_eq!(bad(&|l| l.position.x = f32::NAN), "position");
    assert_eq!(bad(&|l| l.target.y = f32::INFINITY), "target");
    assert_eq!(bad(&|l| l.target = l.position), "target");
    assert_eq!(bad(&|l| l.color.z = -1.0), "color");
    let mut l = lamp(Vec::new());
    l.samples = 0;
    let entity = Entity::from_raw_u32(7).unwrap();
    let line = area_rejection_message(entity, Some(&Name::new("lamp")), &check_area_light(&l).unwrap_err());
    assert!(line.contains(&entity.to_string()) && line.contains("\"lamp\""), "{line}");
    assert!(line.contains("`samples`") && line.contains("1..=1024"), "{line}");
    let mut edge = lamp(Vec::new());
    edge.samples = hadou_scene::MAX_TRACE_SAMPLES;
    edge.size = 3.7;
    assert_eq!(check_area_light(&edge), Ok(()), "the largest sample count and a size short of G pass");
}

/// The `drawn` word and the node count of the plugin's area record.
fn drawn_and_nodes(app: &App) -> (u32, u32) {
    let buffers = app.world().resource::<Assets<ShaderBuffer>>();
    let data = buffers.get(&AREA_DATA).and_then(|b| b.data.clone()).expect("the area record");
    let words: &[u32] = bytemuck::cast_slice(&data);
    // hadou-gpu's TracedUniforms (rows, per_row, disc, node_count) follows 16 words of the lamp.
    (words[0], words[19])
}

fn first_node_bytes(app: &App) -> Vec<u8> {
    let buffers = app.world().resource::<Assets<ShaderBuffer>>();
    let data = buffers.get(&AREA_NODES).and_then(|b| b.data.clone()).expect("the nodes");
    assert!(buffers.get(&AREA_TRIS).is_some_and(|b| b.data.is_some()));
    data[..32].to_vec()
}

#[test]
fn a_bad_area_light_is_not_drawn_the_app_runs_on_and_a_fixed_one_is() {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, AssetPlugin::default(), bevy::transform::TransformPlugin))
        .init_asset::<Mesh>()
        .add_plugins(HadouPlugin::default());
    let cube = app.world_mut().resource_mut::<Assets<Mesh>>().add(Cuboid::new(1.0, 1.0, 1.0));
    let caster = app.world_mut().spawn((Mesh3d(cube), Transform::from_xyz(0.0, 0.5, 0.0))).id();
    let mut bad = lamp(vec![caster]);
    bad.size = f32::NAN;
    let light = app.world_mut().spawn((Name::new("lamp"), bad)).id();
    app.update();
    app.update();
    let rejected = app.world().get::<AreaLightRejected>(light).expect("the NaN size must be rejected");
    assert_eq!(rejected.0.key, "size");
    assert_eq!(drawn_and_nodes(&app).0, 0, "a rejected light is not drawn");

    app.world_mut().get_mut::<HadouAreaLight>(light).unwrap().samples = 0;
    app.world_mut().get_mut::<HadouAreaLight>(light).unwrap().size = 0.5;
    app.update();
    assert_eq!(app.world().get::<AreaLightRejected>(light).unwrap().0.key, "samples");
    assert_eq!(drawn_and_nodes(&app).0, 0);

    app.world_mut().get_mut::<HadouAreaLight>(light).unwrap().samples = 64;
    app.update();
    app.update();
    assert!(app.world().get::<AreaLightRejected>(light).is_none(), "a fixed light is drawn again");
    let (drawn, nodes) = drawn_and_nodes(&app);
    assert_eq!(drawn, 1);
    // The cube's 12 triangles, at most 4 a leaf: more than one node.
    assert!(nodes > 1, "the hierarchy of the caster's mesh ({nodes} nodes)");
    let root = first_node_bytes(&app);
    let lo: [f32; 3] = bytemuck::pod_read_unaligned(&root[..12]);
    assert_eq!(lo, [-0.5, 0.0, -0.5], "the root's box is the cube's, in the world");

    // Moving the caster builds the hierarchy again.
    app.world_mut().get_mut::<Transform>(caster).unwrap().translation.x = 1.0;
    app.update();
    let moved = first_node_bytes(&app);
    let lo: [f32; 3] = bytemuck::pod_read_unaligned(&moved[..12]);
    assert_eq!(lo, [0.5, 0.0, -0.5], "the hierarchy follows the caster");
}
