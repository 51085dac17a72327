//! glTF animation on small files built here (issue 26): a two-joint arm with a LINEAR rotation
//! clip, a STEP translation clip, a CUBICSPLINE clip and an animated morph target, posed through
//! the scene keys (`animation`, `animation_start`, `animation_speed`, `animation_loop`,
//! `animation_time`) and checked against positions worked out by hand; and every bad input the
//! issue names, each a located error (or a warning where glTF allows going on).

mod common;

use common::gltf::Builder;
use hadou_scene::{Scene, SceneError};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hadou-anim-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The arm: joint 0 at the origin, joint 1 one unit up (its child); a thin strip of four vertices,
/// the lower two on joint 0, the upper two (at y = 2) on joint 1; a morph target moving vertex 0
/// by +z (default weight 0.5). `edit` may change the JSON before it is written.
fn arm(edit: impl FnOnce(&mut Builder, &mut Value)) -> Vec<u8> {
    let mut b = Builder::default();
    let pos = b.positions(&[[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 2.0, 0.0], [0.1, 2.0, 0.0]]);
    let idx = b.acc(
        &[0u16, 1, 2, 1, 3, 2].iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>(),
        5123,
        6,
        "SCALAR",
        false,
    );
    let joints = b.acc(&[0u8, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0], 5121, 4, "VEC4", false);
    let weights =
        b.f32s(&[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0], 4, "VEC4");
    let morph = b.f32s(&[0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 4, "VEC3");
    let ibm = b.f32s(
        &[
            1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 1., 0., 0., 0., 0., 1., 0., 0.,
            0., 0., 1., 0., 0., -1., 0., 1.,
        ],
        2,
        "MAT4",
    );
    let h = std::f32::consts::FRAC_PI_4;
    let t01 = b.f32s(&[0.0, 1.0], 2, "SCALAR");
    let bend = b.f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, h.sin(), h.cos()], 2, "VEC4");
    let hop = b.f32s(&[0.0, 0.0, 0.0, 0.0, 5.0, 0.0], 2, "VEC3");
    // CUBICSPLINE: (in, value, out) per key; value 0 → 1 in x with out-tangent 3 at the first key.
    let cubic = b.f32s(&[0., 0., 0., 0., 0., 0., 3., 0., 0., 0., 0., 0., 1., 0., 0., 0., 0., 0.], 6, "VEC3");
    let weights_out = b.f32s(&[0.0, 1.0], 2, "SCALAR");
    let mut doc = json!({
        "scene": 0,
        "scenes": [{"nodes": [0, 2]}],
        "nodes": [
            {"name": "root", "children": [1]},
            {"name": "elbow", "translation": [0.0, 1.0, 0.0]},
            {"name": "arm", "mesh": 0, "skin": 0}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos, "JOINTS_0": joints, "WEIGHTS_0": weights},
                                     "indices": idx, "targets": [{"POSITION": morph}]}],
                    "weights": [0.5]}],
        "skins": [{"joints": [0, 1], "inverseBindMatrices": ibm}],
        "animations": [
            {"name": "bend", "samplers": [{"input": t01, "output": bend}],
             "channels": [{"sampler": 0, "target": {"node": 1, "path": "rotation"}}]},
            {"name": "hop", "samplers": [{"input": t01, "output": hop, "interpolation": "STEP"}],
             "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]},
            {"name": "cubic", "samplers": [{"input": t01, "output": cubic, "interpolation": "CUBICSPLINE"}],
             "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]},
            {"name": "morph", "samplers": [{"input": t01, "output": weights_out}],
             "channels": [{"sampler": 0, "target": {"node": 2, "path": "weights"}}]}
        ]
    });
    edit(&mut b, &mut doc);
    b.finish(doc)
}

/// Writes `gltf` and a scene whose one object plays it with the object keys `keys`.
fn scene_with(name: &str, gltf: &[u8], keys: &str, extra: &str) -> Result<Scene, SceneError> {
    let d = dir(name);
    std::fs::write(d.join("arm.gltf"), gltf).unwrap();
    let text = format!(
        "[camera]\nposition = [0, 1, 6]\ntarget = [0, 1, 0]\n\n[[object]]\nname = \"arm\"\nkind = \"gltf\"\npath = \"arm.gltf\"\n{keys}\n{extra}"
    );
    let path = d.join("scene.toml");
    std::fs::write(&path, &text).unwrap();
    Scene::load(&path)
}

fn posed(scene: &Scene, t: f32) -> Vec<[f32; 3]> {
    scene.at(t).objects[0].mesh.positions.clone()
}

fn close(a: [f32; 3], b: [f32; 3]) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() < 1e-5)
}

#[test]
fn a_linear_rotation_clip_bends_the_skin_by_slerp() {
    let s = scene_with("bend", &arm(|_, _| {}), "animation = \"bend\"", "").unwrap();
    // At rest the default morph weight 0.5 moves vertex 0 by z = 0.5.
    let p = posed(&s, 0.0);
    assert!(close(p[0], [0.0, 0.0, 0.5]), "{:?}", p[0]);
    assert!(close(p[2], [0.0, 2.0, 0.0]), "{:?}", p[2]);
    // Half way: 45° about z at the elbow (slerp of identity and 90°).
    let p = posed(&s, 0.5);
    let h = std::f32::consts::FRAC_PI_4;
    assert!(close(p[2], [-h.sin(), 1.0 + h.cos(), 0.0]), "{:?}", p[2]);
    assert!(close(p[1], [0.1, 0.0, 0.0]), "the lower joint does not move: {:?}", p[1]);
    // The end holds 90°, and loops by default: t = 1.25 plays 0.25 s (22.5°).
    let s2 =
        scene_with("bend-hold", &arm(|_, _| {}), "animation = \"bend\"\nanimation_loop = false", "").unwrap();
    assert!(close(posed(&s2, 7.0)[2], [-1.0, 1.0, 0.0]), "{:?}", posed(&s2, 7.0)[2]);
    let q = std::f32::consts::PI / 8.0;
    assert!(close(posed(&s, 1.25)[2], [-q.sin(), 1.0 + q.cos(), 0.0]), "{:?}", posed(&s, 1.25)[2]);
    // The normals turn with the skin: the strip's +z normal stays +z about a z rotation, and the
    // posed mesh keeps the rest mesh's triangles.
    let f = s.at(0.5);
    assert_eq!(f.objects[0].mesh.indices, s.at(0.0).objects[0].mesh.indices);
    assert!(f.objects[0].mesh.normals.iter().all(|n| n[2].abs() > 0.99), "{:?}", f.objects[0].mesh.normals);
}

#[test]
fn start_speed_and_a_pinned_time_choose_the_clip_time() {
    let g = arm(|_, _| {});
    let s = scene_with(
        "speed",
        &g,
        "animation = \"bend\"\nanimation_start = 1.0\nanimation_speed = 2.0\nanimation_loop = false",
        "",
    )
    .unwrap();
    assert!(close(posed(&s, 0.5)[2], [0.0, 2.0, 0.0]), "before the start the first pose holds");
    let h = std::f32::consts::FRAC_PI_4;
    assert!(close(posed(&s, 1.25)[2], [-h.sin(), 1.0 + h.cos(), 0.0]), "{:?}", posed(&s, 1.25)[2]);
    let s = scene_with("pinned", &g, "animation = \"bend\"\nanimation_time = 0.5", "").unwrap();
    for t in [0.0, 0.9, 3.0] {
        assert!(close(posed(&s, t)[2], [-h.sin(), 1.0 + h.cos(), 0.0]), "t = {t}");
    }
    // A track scrubs the clip time: at scene time 2 the track says 1.0 (the end, 90°).
    let s = scene_with(
        "scrub",
        &g,
        "animation = \"bend\"\nanimation_loop = false",
        "[[track]]\ntarget = \"object.arm.animation_time\"\nkeys = [[0, 0.0], [2, 1.0]]\n",
    )
    .unwrap();
    assert!(close(posed(&s, 2.0)[2], [-1.0, 1.0, 0.0]), "{:?}", posed(&s, 2.0)[2]);
    assert!(close(posed(&s, 1.0)[2], [-h.sin(), 1.0 + h.cos(), 0.0]), "{:?}", posed(&s, 1.0)[2]);
}

#[test]
fn step_cubic_and_morph_weight_clips() {
    let g = arm(|_, _| {});
    let s = scene_with("step", &g, "animation = \"hop\"\nanimation_loop = false", "").unwrap();
    assert!(close(posed(&s, 0.999)[2], [0.0, 2.0, 0.0]), "STEP holds the first key until the second");
    assert!(close(posed(&s, 1.0)[2], [0.0, 7.0, 0.0]), "{:?}", posed(&s, 1.0)[2]);
    let s = scene_with("cubic", &g, "animation = \"cubic\"\nanimation_loop = false", "").unwrap();
    for u in [0.25f32, 0.5, 0.8] {
        // Hermite: v0 = 0, b0 = 3, v1 = 1, a1 = 0, t_d = 1.
        let x = 3.0 * (u * u * u - 2.0 * u * u + u) + (-2.0 * u * u * u + 3.0 * u * u);
        assert!(close(posed(&s, u)[2], [x, 2.0, 0.0]), "u = {u}: {:?} vs {x}", posed(&s, u)[2]);
    }
    let s = scene_with("morph", &g, "animation = \"morph\"\nanimation_loop = false", "").unwrap();
    assert!(close(posed(&s, 0.0)[0], [0.0, 0.0, 0.0]), "the clip's weight 0 replaces the default 0.5");
    assert!(close(posed(&s, 0.75)[0], [0.0, 0.0, 0.75]), "{:?}", posed(&s, 0.75)[0]);
}

#[test]
fn an_object_without_animation_keys_is_its_rest_mesh_every_frame() {
    let s = scene_with("rest", &arm(|_, _| {}), "", "").unwrap();
    let a = s.at(0.0);
    let b = s.at(0.7);
    assert!(std::sync::Arc::ptr_eq(&a.objects[0].mesh, &b.objects[0].mesh));
    // The same frame time twice gives the same (cached) posed mesh.
    let s = scene_with("cache", &arm(|_, _| {}), "animation = \"bend\"", "").unwrap();
    assert!(std::sync::Arc::ptr_eq(&s.at(0.3).objects[0].mesh, &s.at(0.3).objects[0].mesh));
}

fn message(r: Result<Scene, SceneError>) -> String {
    match r {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_clip_name_not_in_the_file_lists_the_clips_at_its_place() {
    let e = message(scene_with("noclip", &arm(|_, _| {}), "animation = \"wave\"", ""));
    assert!(e.contains("scene.toml:9:13"), "{e}");
    assert!(e.contains("no clip \"wave\"") && e.contains("\"bend\" (1 s)") && e.contains("\"morph\""), "{e}");
    let e = message(scene_with("nokeys", &arm(|_, _| {}), "animation_speed = 2", ""));
    assert!(e.contains("without `animation`"), "{e}");
    let e = message(scene_with("speed", &arm(|_, _| {}), "animation = \"bend\"\nanimation_speed = 1e9", ""));
    assert!(e.contains("animation_speed"), "{e}");
    let e = message(scene_with("loop", &arm(|_, _| {}), "animation = \"bend\"\nanimation_loop = 1", ""));
    assert!(e.contains("animation_loop"), "{e}");
    let e = message(scene_with("expr", &arm(|_, _| {}), "expressions = { blink = 1 }", ""));
    assert!(e.contains("no VRM expressions"), "{e}");
}

fn load_err(name: &str, edit: impl FnOnce(&mut Builder, &mut Value)) -> String {
    message(scene_with(name, &arm(edit), "animation = \"bend\"", ""))
}

#[test]
fn keyframe_times_must_increase_and_be_finite() {
    let e = load_err("times", |b, d| {
        let t = b.f32s(&[0.0, 0.0], 2, "SCALAR");
        d["animations"][0]["samplers"][0]["input"] = json!(t);
    });
    assert!(e.contains("arm.gltf") && e.contains("key times must increase strictly"), "{e}");
    assert!(e.contains("animation 0 (\"bend\") channel 0"), "{e}");
    let e = load_err("nan-time", |b, d| {
        let t = b.f32s(&[0.0, f32::NAN], 2, "SCALAR");
        d["animations"][0]["samplers"][0]["input"] = json!(t);
    });
    assert!(e.contains("not a finite number"), "{e}");
    let e = load_err("inf-value", |b, d| {
        let v = b.f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, f32::INFINITY, 1.0], 2, "VEC4");
        d["animations"][0]["samplers"][0]["output"] = json!(v);
    });
    assert!(e.contains("output value 6 is not a finite number"), "{e}");
}

#[test]
fn accessors_of_the_wrong_type_or_count_are_errors() {
    let e = load_err("vec3-rotation", |b, d| {
        let v = b.f32s(&[0.0; 6], 2, "VEC3");
        d["animations"][0]["samplers"][0]["output"] = json!(v);
    });
    assert!(e.contains("output: accessor") && e.contains("Vec3"), "{e}");
    let e = load_err("count", |b, d| {
        let v = b.f32s(&[0.0, 0.0, 0.0, 1.0], 1, "VEC4");
        d["animations"][0]["samplers"][0]["output"] = json!(v);
    });
    assert!(e.contains("2 keys need 2"), "{e}");
    let e = load_err("cubic-count", |_, d| {
        d["animations"][0]["samplers"][0]["interpolation"] = json!("CUBICSPLINE");
    });
    assert!(e.contains("× 3 (in-tangent, value, out-tangent)"), "{e}");
    let e = load_err("weights-node", |_, d| {
        d["animations"][3]["channels"][0]["target"]["node"] = json!(1);
    });
    assert!(e.contains("whose mesh has no morph targets"), "{e}");
    let e = load_err("matrix", |_, d| {
        d["nodes"][1] = json!({"matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,1,0,1]});
    });
    assert!(e.contains("has a `matrix`"), "{e}");
}

#[test]
fn joints_must_be_nodes_of_a_tree() {
    let e = load_err("joint-range", |_, d| {
        d["skins"][0]["joints"] = json!([0, 7]);
    });
    assert!(e.contains("skin 0 (joints) refers to node 7"), "{e}");
    let e = load_err("cycle", |_, d| {
        d["nodes"][1]["children"] = json!([0]);
    });
    assert!(e.contains("cycle") || e.contains("trees"), "{e}");
    let e = load_err("channel-node", |_, d| {
        d["animations"][0]["channels"][0]["target"]["node"] = json!(9);
    });
    assert!(e.contains("animation 0 channel 0 refers to node 9"), "{e}");
}

#[test]
fn weights_that_do_not_sum_to_one_are_normalised_with_a_warning() {
    let g = arm(|b, d| {
        let w = b.f32s(
            &[2.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0],
            4,
            "VEC4",
        );
        d["meshes"][0]["primitives"][0]["attributes"]["WEIGHTS_0"] = json!(w);
    });
    let s = scene_with("weights", &g, "animation = \"bend\"", "").unwrap();
    assert!(
        s.warnings().iter().any(|w| w.contains("skin weights of 4 vertices do not sum to 1")),
        "{:?}",
        s.warnings()
    );
    let h = std::f32::consts::FRAC_PI_4;
    assert!(close(posed(&s, 0.5)[2], [-h.sin(), 1.0 + h.cos(), 0.0]), "normalised weights pose as weight 1");
}

#[test]
fn morph_targets_are_checked() {
    let e = load_err("morph-count", |b, d| {
        let m = b.f32s(&[0.0; 6], 2, "VEC3");
        d["meshes"][0]["primitives"][0]["targets"][0]["POSITION"] = json!(m);
    });
    assert!(e.contains("morph target 0 POSITION has 2 entries but POSITION has 4"), "{e}");
    let e = load_err("morph-weights", |_, d| {
        d["meshes"][0]["weights"] = json!([0.5, 0.5]);
    });
    assert!(e.contains("`weights` has 2 entries but the mesh has 1 morph targets"), "{e}");
}

#[test]
fn vrm_expressions_bind_morph_targets() {
    let g = arm(|_, d| {
        d["extensionsUsed"] = json!(["VRMC_vrm"]);
        d["extensions"] = json!({"VRMC_vrm": {"specVersion": "1.0", "expressions": {"preset": {
            "blink": {"morphTargetBinds": [{"node": 2, "index": 0, "weight": 1.0}]}}}}});
        d["meshes"][0]["weights"] = json!([0.0]);
    });
    let s = scene_with("vrm", &g, "expressions = { blink = 0.25 }", "").unwrap();
    assert!(close(posed(&s, 0.0)[0], [0.0, 0.0, 0.25]), "{:?}", posed(&s, 0.0)[0]);
    let s = scene_with(
        "vrm-track",
        &g,
        "expressions = { blink = 0 }",
        "[[track]]\ntarget = \"object.arm.expressions.blink\"\nkeys = [[0, 0.0], [1, 1.0]]\n",
    )
    .unwrap();
    assert!(close(posed(&s, 0.5)[0], [0.0, 0.0, 0.5]), "{:?}", posed(&s, 0.5)[0]);
    let e = message(scene_with("vrm-name", &g, "expressions = { wink = 1 }", ""));
    assert!(
        e.contains("scene.toml:9:17") && e.contains("no expression \"wink\"; its expressions are blink"),
        "{e}"
    );
    let e = message(scene_with("vrm-range", &g, "expressions = { blink = 2 }", ""));
    assert!(e.contains("expression `blink`"), "{e}");
    let broken = arm(|_, d| {
        d["extensions"] = json!({"VRMC_vrm": {"expressions": {"preset": {
            "blink": {"morphTargetBinds": [{"node": 2, "index": 4}]}}}}});
    });
    let e = message(scene_with("vrm-broken", &broken, "", ""));
    assert!(e.contains("VRMC_vrm.expressions.preset.blink.morphTargetBinds[0]: morph target 4"), "{e}");
}

#[test]
fn a_scene_lists_each_objects_clips() {
    let s = scene_with("clips", &arm(|_, _| {}), "", "").unwrap();
    let clips = s.object_clips();
    let names: Vec<&str> = clips[0].iter().map(|c| c.0.as_str()).collect();
    assert_eq!(names, ["bend", "hop", "cubic", "morph"]);
    assert!(clips[0].iter().all(|c| c.1 == 1.0));
    let s = scene_with("clip-at", &arm(|_, _| {}), "animation = \"hop\"\nanimation_speed = 0.5", "").unwrap();
    assert_eq!(s.object_clip_at(0, 1.0), Some(("hop".to_string(), 0.5)));
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/light-normal-vs-wave.toml");
    let s = Scene::load(&path).unwrap();
    assert!(s.object_clips().iter().all(|c| c.is_empty()));
}

#[test]
fn the_scene_lasts_until_its_clips_have_played_once() {
    let g = arm(|_, _| {});
    let s =
        scene_with("duration", &g, "animation = \"bend\"\nanimation_start = 2\nanimation_speed = 0.5", "")
            .unwrap();
    assert_eq!(s.duration(), 4.0);
    let s = scene_with(
        "duration-track",
        &g,
        "animation = \"bend\"",
        "[[track]]\ntarget = \"object.arm.position.x\"\nkeys = [[0, 0.0], [9, 1.0]]\n",
    )
    .unwrap();
    assert_eq!(s.duration(), 9.0);
    let s = scene_with("duration-pinned", &g, "animation = \"bend\"\nanimation_time = 0.5", "").unwrap();
    assert_eq!(s.duration(), 0.0);
}

/// A morph target stored sparse, without a bufferView (zeros but for the listed vertices), as VRM
/// exporters write them.
fn sparse_target(b: &mut Builder, count: usize, indices: &[u16], values: &[f32]) -> usize {
    let iv = b.view(&indices.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>());
    let vv = b.view(&values.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>());
    b.raw_accessor(json!({"componentType": 5126, "count": count, "type": "VEC3",
        "sparse": {"count": indices.len(), "indices": {"bufferView": iv, "componentType": 5123},
                   "values": {"bufferView": vv}}}))
}

#[test]
fn sparse_morph_targets_are_read_and_checked() {
    let g = arm(|b, d| {
        let t = sparse_target(b, 4, &[0, 3], &[0.0, 0.0, 1.0, 0.0, 0.0, 2.0]);
        d["meshes"][0]["primitives"][0]["targets"][0]["POSITION"] = json!(t);
        d["meshes"][0]["weights"] = json!([1.0]);
    });
    let s = scene_with("sparse", &g, "", "").unwrap();
    let p = posed(&s, 0.0);
    assert!(
        close(p[0], [0.0, 0.0, 1.0]) && close(p[3], [0.1, 2.0, 2.0]) && close(p[1], [0.1, 0.0, 0.0]),
        "{p:?}"
    );
    let e = load_err("sparse-count", |b, d| {
        let t = sparse_target(b, 4, &[0, 1, 2, 3, 3], &[0.0; 15]);
        d["meshes"][0]["primitives"][0]["targets"][0]["POSITION"] = json!(t);
    });
    assert!(e.contains("sparse count of 5, which must be 1..=4"), "{e}");
    let e = load_err("sparse-short", |b, d| {
        let t = sparse_target(b, 4, &[0, 3], &[0.0; 3]);
        d["meshes"][0]["primitives"][0]["targets"][0]["POSITION"] = json!(t);
    });
    assert!(e.contains("(sparse values): it reads past the end of bufferView"), "{e}");
}

#[test]
fn morph_targets_and_keyframes_are_bounded() {
    let e = load_err("many-targets", |_, d| {
        let t = d["meshes"][0]["primitives"][0]["targets"][0].clone();
        d["meshes"][0]["primitives"][0]["targets"] = json!(vec![t; hadou_scene::MAX_MORPH_TARGETS + 1]);
        d["meshes"][0]["weights"] = json!(vec![0.0; hadou_scene::MAX_MORPH_TARGETS + 1]);
        d["animations"].as_array_mut().unwrap().pop();
    });
    assert!(e.contains("257 morph targets, more than the limit of 256"), "{e}");
    // One accessor of 2²⁰ keys shared by channels: the keyframe numbers past 2²⁴ are refused
    // before any is copied.
    let e = load_err("many-keys", |b, d| {
        let n = 1 << 20;
        let times: Vec<f32> = (0..n).map(|k| k as f32).collect();
        let t = b.f32s(&times, n, "SCALAR");
        let q: Vec<f32> = (0..n).flat_map(|_| [0.0, 0.0, 0.0, 1.0]).collect();
        let r = b.f32s(&q, n, "VEC4");
        let channels: Vec<Value> =
            (0..4).map(|_| json!({"sampler": 0, "target": {"node": 1, "path": "rotation"}})).collect();
        d["animations"] =
            json!([{"name": "long", "samplers": [{"input": t, "output": r}], "channels": channels}]);
    });
    assert!(e.contains("more than 16777216 keyframe numbers"), "{e}");
}
