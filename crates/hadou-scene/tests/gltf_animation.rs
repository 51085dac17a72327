//! glTF animation against an independent f64 reference (`common/gltf_reference.rs`, written from
//! the glTF 2.0 specification): the rest pose `load_gltf` reads, and the posed mesh
//! `Scene::at(t)` gives for `animation`, `animation_start`, `animation_speed`, `animation_loop`
//! and `animation_time`, on the characters of `scenes/assets/make_brace.py` and `make_hero.py`.

#[path = "common/gltf_reference.rs"]
mod gltf_reference;

use gltf_reference::{compose, hermite, mul, slerp, transform, Gltf, IDENTITY, V3};
use std::path::{Path, PathBuf};

/// Largest allowed distance between a vertex and its reference (the models are about 1.8 tall).
const TOL: f64 = 1e-4;

fn asset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/assets").join(name)
}

/// The largest distance between corresponding vertices, and where it is.
fn max_dev(got: &[[f32; 3]], want: &[V3]) -> (f64, usize) {
    assert_eq!(got.len(), want.len(), "vertex counts differ");
    got.iter()
        .zip(want)
        .enumerate()
        .map(|(i, (g, w))| {
            let d = (0..3).map(|c| (g[c] as f64 - w[c]).powi(2)).sum::<f64>().sqrt();
            (d, i)
        })
        .fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a })
}

fn assert_close(what: &str, got: &[[f32; 3]], want: &[V3]) {
    let (d, i) = max_dev(got, want);
    assert!(
        d <= TOL,
        "{what}: vertex {i} is {d:.3e} from the reference: got {:?}, want {:?}",
        got[i],
        want[i]
    );
}

/// The largest displacement between two poses (to show a case really moves the mesh).
fn spread(a: &[V3], b: &[V3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (0..3).map(|c| (p[c] - q[c]).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max)
}

// ---------------------------------------------------------------------------------------------
// The reference itself, on hand-computed cases.

#[test]
fn reference_a_joint_turned_90_degrees_moves_a_skinned_vertex_where_expected() {
    // One joint at (1, 0, 0) (bind pose: translation only), turned 90° about z; a vertex at
    // (2, 0, 0) fully bound to it lies one unit along the joint's +x, now +y: at (1, 1, 0).
    let h = std::f64::consts::FRAC_PI_4;
    let joint = compose([1.0, 0.0, 0.0], [0.0, 0.0, h.sin(), h.cos()], [1.0; 3]);
    let mut ibm = IDENTITY;
    ibm[12] = -1.0;
    let p = transform(&mul(&joint, &ibm), [2.0, 0.0, 0.0]);
    for (c, want) in [1.0, 1.0, 0.0].into_iter().enumerate() {
        assert!((p[c] - want).abs() < 1e-12, "{p:?}");
    }
    // The same through a GLB built here: a skin with that joint, the mesh node's own transform
    // (a translation of 5 along x) ignored.
    let glb = one_joint_glb();
    let g = Gltf::from_glb(&glb);
    let rest = g.pose(None);
    let posed = g.pose(Some(("turn", 1.0)));
    assert!((rest[0][0] - 2.0).abs() < 1e-6 && rest[0][1].abs() < 1e-6, "{rest:?}");
    assert!((posed[0][0] - 1.0).abs() < 1e-6 && (posed[0][1] - 1.0).abs() < 1e-6, "{posed:?}");
    // Halfway through the LINEAR key pair: 45°.
    let half = g.pose(Some(("turn", 0.5)));
    let s = std::f64::consts::FRAC_1_SQRT_2;
    assert!((half[0][0] - (1.0 + s)).abs() < 1e-6 && (half[0][1] - s).abs() < 1e-6, "{half:?}");
}

#[test]
fn reference_slerp_takes_the_short_arc_between_q_and_minus_q() {
    let q = [0.0, (0.3f64).sin(), 0.0, (0.3f64).cos()];
    let mq = q.map(|c| -c);
    // q and −q are the same rotation: every point between them is that rotation.
    for u in [0.0, 0.25, 0.5, 0.9] {
        let r = slerp(q, mq, u);
        let dot: f64 = (0..4).map(|i| r[i] * q[i]).sum();
        assert!((dot.abs() - 1.0).abs() < 1e-12, "u = {u}: {r:?}");
    }
    // Identity to a 10° turn stored as its negative (dot < 0): the short way is 10°, so halfway
    // is a 5° turn, not the 175° of the long way round.
    let a = [0.0, 0.0, 0.0, 1.0];
    let h = 10f64.to_radians() / 2.0;
    let b = [0.0, -h.sin(), 0.0, -h.cos()];
    let mid = slerp(a, b, 0.5);
    let angle = 2.0 * mid[3].abs().min(1.0).acos();
    assert!((angle.to_degrees() - 5.0).abs() < 1e-9, "{}", angle.to_degrees());
    assert!(mid[1] * mid[3] > 0.0, "turned the wrong way: {mid:?}");
}

#[test]
fn reference_cubic_spline_with_zero_tangents_is_a_smoothstep() {
    for u in [0.0, 0.1, 0.3, 0.5, 0.77, 1.0] {
        let v = hermite(2.0, 0.0, 5.0, 0.0, u);
        let s = u * u * (3.0 - 2.0 * u);
        assert!((v - (2.0 + 3.0 * s)).abs() < 1e-12, "u = {u}: {v}");
    }
    // Non-zero tangents bend the curve: the slope at u = 0 is the out-tangent (times the
    // interval, already applied here).
    let eps = 1e-6;
    let slope = (hermite(0.0, 0.7, 1.0, 0.0, eps) - hermite(0.0, 0.7, 1.0, 0.0, 0.0)) / eps;
    assert!((slope - 0.7).abs() < 1e-4, "{slope}");
    // And through a file: brace.glb's `cubic` hips translation at the first key's end matches
    // the spec's scaling of the tangents by the key interval.
    let g = Gltf::open(&asset("brace.glb"));
    let a = g.animation("cubic");
    let gltf_reference::Sampled::Translation(t) = g.sample(a, 0, "translation", 0.3) else { panic!() };
    let out = g.accessor(g.json["animations"][a]["samplers"][0]["output"].as_u64().unwrap() as usize);
    let times = g.accessor(g.json["animations"][a]["samplers"][0]["input"].as_u64().unwrap() as usize);
    let td = times[1][0] - times[0][0];
    let (p0, m0, m1, p1) = (&out[1], &out[2], &out[3], &out[4]);
    assert!((0..3).any(|c| m0[c] != 0.0) && (0..3).any(|c| m1[c] != 0.0), "the tangents are zero");
    for c in 0..3 {
        let want = hermite(p0[c], td * m0[c], p1[c], td * m1[c], 0.3 / td);
        assert!((t[c] - want).abs() < 1e-12, "{t:?}");
    }
}

/// A GLB with one joint at (1, 0, 0), a mesh of one triangle skinned to it (node translation
/// (5, 0, 0), to be ignored) and a clip `turn` rotating the joint from 0 to 90° about z in 1 s.
fn one_joint_glb() -> Vec<u8> {
    let mut bin: Vec<u8> = Vec::new();
    let f = |b: &mut Vec<u8>, v: &[f32]| v.iter().for_each(|x| b.extend(x.to_le_bytes()));
    f(&mut bin, &[2.0, 0.0, 0.0, 2.0, 1.0, 0.0, 2.0, 0.0, 1.0]); // 0: positions, 36 bytes
    bin.extend([0u8; 12]); // 36: joints (u8 × 4 × 3)
    bin.extend([255u8, 0, 0, 0].repeat(3)); // 48: normalised u8 weights
    let h = std::f32::consts::FRAC_PI_4;
    f(&mut bin, &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 1.0]); // 60: IBM
    f(&mut bin, &[0.0, 1.0]); // 124: times
    f(&mut bin, &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, h.sin(), h.cos()]); // 132: rotations
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"translation": [1.0, 0.0, 0.0]}, {"mesh": 0, "skin": 0, "translation": [5.0, 0.0, 0.0]}],
        "skins": [{"joints": [0], "inverseBindMatrices": 3}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2}}]}],
        "animations": [{"name": "turn", "channels": [{"sampler": 0, "target": {"node": 0, "path": "rotation"}}],
                        "samplers": [{"input": 4, "output": 5}]}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": bin.len()}],
        "accessors": [
            {"bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
            {"bufferView": 0, "byteOffset": 36, "componentType": 5121, "count": 3, "type": "VEC4"},
            {"bufferView": 0, "byteOffset": 48, "componentType": 5121, "normalized": true, "count": 3, "type": "VEC4"},
            {"bufferView": 0, "byteOffset": 60, "componentType": 5126, "count": 1, "type": "MAT4"},
            {"bufferView": 0, "byteOffset": 124, "componentType": 5126, "count": 2, "type": "SCALAR"},
            {"bufferView": 0, "byteOffset": 132, "componentType": 5126, "count": 2, "type": "VEC4"}
        ]
    });
    let mut js = serde_json::to_vec(&json).unwrap();
    while !js.len().is_multiple_of(4) {
        js.push(b' ');
    }
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + js.len() + 8 + bin.len()) as u32).to_le_bytes());
    out.extend((js.len() as u32).to_le_bytes());
    out.extend(0x4E4F_534Au32.to_le_bytes());
    out.extend(js);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(0x004E_4942u32.to_le_bytes());
    out.extend(bin);
    out
}

// ---------------------------------------------------------------------------------------------
// The assets themselves (what the tests below rely on).

#[test]
fn the_assets_have_the_structure_the_animation_tests_rely_on() {
    let g = Gltf::open(&asset("brace.glb"));
    assert!(g.json["skins"][0]["joints"].as_array().unwrap().len() >= 12);
    let clips: Vec<&str> =
        g.json["animations"].as_array().unwrap().iter().map(|a| a["name"].as_str().unwrap()).collect();
    assert_eq!(clips, ["brace", "step", "cubic", "blink"]);
    assert!((g.duration(g.animation("brace")) - 2.0).abs() < 1e-9);
    // The brace hips rotation holds a key pair with a negative dot product.
    let a = g.animation("brace");
    let s = &g.json["animations"][a]["samplers"][1];
    let keys = g.accessor(s["output"].as_u64().unwrap() as usize);
    assert!(keys.windows(2).any(|k| (0..4).map(|i| k[0][i] * k[1][i]).sum::<f64>() < 0.0));
    // Rest pose: about 1.8 tall on y = 0.
    let rest = g.pose(None);
    let lo = rest.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
    let hi = rest.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max);
    assert!(lo.abs() < 1e-3 && (1.7..1.9).contains(&hi), "{lo} {hi}");
    let d = Gltf::open(&asset("dancer.glb"));
    assert!(d.json["skins"][0]["joints"].as_array().unwrap().len() >= 64);
    let tris: usize = d.json["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|m| m["primitives"].as_array().unwrap())
        .map(|p| {
            d.json["accessors"][p["indices"].as_u64().unwrap() as usize]["count"].as_u64().unwrap() as usize
                / 3
        })
        .sum();
    assert!((48_000..=60_000).contains(&tris), "{tris} triangles");
}

// ---------------------------------------------------------------------------------------------
// The loader's rest pose.

#[test]
fn rest_pose_of_load_gltf_matches_the_reference() {
    for name in ["hero.glb", "dancer.glb", "brace.glb"] {
        let path = asset(name);
        let mesh = hadou_scene::load_gltf(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        // Morph targets left out here: the default weights are held separately below.
        let want = Gltf::open(&path).pose_with(None, false);
        let g = Gltf::open(&path);
        let has_morphs = g.json["meshes"].as_array().unwrap().iter().any(|m| m.get("weights").is_some());
        if !has_morphs {
            assert_close(name, &mesh.positions, &want);
        } else {
            // Every vertex outside the morphed head.
            let full = g.pose(None);
            let moved: Vec<bool> = full.iter().zip(&want).map(|(a, b)| spread(&[*a], &[*b]) > 0.0).collect();
            assert!(moved.iter().any(|&m| m), "{name}: the default morph weights move nothing");
            let (got, ref_): (Vec<[f32; 3]>, Vec<V3>) = mesh
                .positions
                .iter()
                .zip(&want)
                .zip(&moved)
                .filter(|(_, m)| !**m)
                .map(|((g, w), _)| (*g, *w))
                .unzip();
            assert_eq!(mesh.positions.len(), want.len(), "{name}: vertex count");
            assert_close(name, &got, &ref_);
        }
    }
}

#[test]
fn rest_pose_of_load_gltf_applies_the_mesh_default_morph_weights() {
    let path = asset("brace.glb");
    let mesh = hadou_scene::load_gltf(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_close("brace.glb with mesh.weights", &mesh.positions, &Gltf::open(&path).pose(None));
}

// ---------------------------------------------------------------------------------------------
// Posing through scene files.

/// A scene in a fresh temporary directory with `asset` copied next to it and one gltf object
/// `who` carrying `keys`; `extra` is appended (tracks).
struct TempScene {
    dir: PathBuf,
}

impl TempScene {
    fn new(tag: &str, asset_name: &str, keys: &str, extra: &str) -> (TempScene, hadou_scene::Scene) {
        let dir = std::env::temp_dir().join(format!("hadou-gltf-anim-{}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::copy(asset(asset_name), dir.join(asset_name)).unwrap();
        let text = format!(
            "[[object]]\nname = \"who\"\nkind = \"gltf\"\npath = \"{asset_name}\"\nposition = [1.0, 0.0, 0.0]\n{keys}\n{extra}"
        );
        let path = dir.join("scene.toml");
        std::fs::write(&path, text).unwrap();
        let scene = hadou_scene::Scene::load(&path).unwrap_or_else(|e| panic!("{tag}: {e}"));
        (TempScene { dir }, scene)
    }
}

impl Drop for TempScene {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// The clip time the keys give at scene time `t` (f32, as the scene evaluates it).
fn clip_time(t: f32, start: f64, speed: f64, looped: bool, duration: f64) -> f64 {
    let c = (t as f64 - start) * speed;
    if looped {
        c.rem_euclid(duration)
    } else {
        c.clamp(0.0, duration)
    }
}

/// Poses `asset_name` by `keys` at each scene time and compares with the reference at the clip
/// times `want`; returns the reference poses.
fn check(
    tag: &str,
    asset_name: &str,
    clip: &str,
    keys: &str,
    extra: &str,
    cases: &[(f32, f64)],
) -> Vec<Vec<V3>> {
    let (_tmp, scene) = TempScene::new(tag, asset_name, &format!("animation = \"{clip}\"\n{keys}"), extra);
    let g = Gltf::open(&asset(asset_name));
    cases
        .iter()
        .map(|&(t, c)| {
            let want = g.pose(Some((clip, c)));
            let frame = scene.at(t);
            assert_close(
                &format!("{tag}: {clip} at t = {t} (clip time {c})"),
                &frame.objects[0].mesh.positions,
                &want,
            );
            want
        })
        .collect()
}

#[test]
fn brace_clip_matches_the_reference_through_a_scene() {
    let cases: Vec<(f32, f64)> =
        [0.0f32, 0.37, 1.0, 1.99, 2.5].iter().map(|&t| (t, clip_time(t, 0.0, 1.0, true, 2.0))).collect();
    let poses = check("brace", "brace.glb", "brace", "", "", &cases);
    // The clip moves the mesh (the comparison is not between two rest poses).
    assert!(spread(&poses[0], &poses[2]) > 0.1);
}

#[test]
fn step_clip_holds_each_key_until_the_next() {
    let cases: Vec<(f32, f64)> = [0.49f32, 0.5, 0.51, 1.2].iter().map(|&t| (t, t as f64)).collect();
    let poses = check("step", "brace.glb", "step", "", "", &cases);
    assert!(spread(&poses[0], &poses[1]) > 0.01, "the key at 0.5 s changes the pose");
    assert!(spread(&poses[1], &poses[2]) == 0.0, "STEP holds between keys");
}

#[test]
fn cubic_clip_matches_the_reference_between_keys() {
    let cases: Vec<(f32, f64)> = [0.15f32, 0.3, 0.85, 1.1].iter().map(|&t| (t, t as f64)).collect();
    let poses = check("cubic", "brace.glb", "cubic", "", "", &cases);
    assert!(spread(&poses[0], &poses[1]) > 0.001);
}

#[test]
fn blink_clip_animates_the_morph_weights() {
    let cases: Vec<(f32, f64)> = [0.05f32, 0.1, 0.7].iter().map(|&t| (t, t as f64)).collect();
    let poses = check("blink", "brace.glb", "blink", "", "", &cases);
    assert!(spread(&poses[0], &poses[1]) > 0.001);
}

#[test]
fn speed_start_loop_and_hold() {
    let d = 2.0;
    let t = |v: &[f32], start: f64, speed: f64, looped: bool| -> Vec<(f32, f64)> {
        v.iter().map(|&t| (t, clip_time(t, start, speed, looped, d))).collect()
    };
    check("speed", "brace.glb", "brace", "animation_speed = 2.0", "", &t(&[0.3, 0.6], 0.0, 2.0, true));
    check("start", "brace.glb", "brace", "animation_start = 0.5", "", &t(&[0.8, 1.7], 0.5, 1.0, true));
    check("wrap", "brace.glb", "brace", "animation_loop = true", "", &t(&[2.3], 0.0, 1.0, true));
    let held =
        check("hold", "brace.glb", "brace", "animation_loop = false", "", &t(&[2.3, 5.0], 0.0, 1.0, false));
    let wrapped = Gltf::open(&asset("brace.glb")).pose(Some(("brace", 0.3)));
    assert!(spread(&held[0], &wrapped) > 0.01, "holding differs from wrapping");
}

#[test]
fn animation_time_pins_and_a_track_scrubs_the_clip() {
    check("pin", "brace.glb", "brace", "animation_time = 0.8", "", &[(0.0, 0.8), (1.7, 0.8)]);
    let track = "[[track]]\ntarget = \"object.who.animation_time\"\nkeys = [[0.0, 0.0], [2.0, 1.0]]\n";
    check("scrub", "brace.glb", "brace", "animation_time = 0.0", track, &[(1.0, 0.5), (2.0, 1.0)]);
}

#[test]
fn dancer_loops_every_joint_like_the_reference() {
    let cases: Vec<(f32, f64)> =
        [0.45f32, 2.7].iter().map(|&t| (t, clip_time(t, 0.0, 1.0, true, 2.0))).collect();
    check("dance", "dancer.glb", "dance", "", "", &cases);
}

// ---------------------------------------------------------------------------------------------
// The VRM avatars and the VRM animation (inputs of the humanoid tests).

const HUMAN_BONES: [&str; 15] = [
    "hips",
    "spine",
    "chest",
    "neck",
    "head",
    "leftUpperArm",
    "leftLowerArm",
    "leftHand",
    "rightUpperArm",
    "rightLowerArm",
    "rightHand",
    "leftUpperLeg",
    "leftLowerLeg",
    "rightUpperLeg",
    "rightLowerLeg",
];

fn node_count(g: &Gltf) -> u64 {
    g.json["nodes"].as_array().unwrap().len() as u64
}

#[test]
fn vrm_1_avatar_has_humanoid_expressions_and_mtoon_materials() {
    let g = Gltf::open(&asset("brace.vrm"));
    let used: Vec<&str> =
        g.json["extensionsUsed"].as_array().unwrap().iter().map(|v| v.as_str().unwrap()).collect();
    assert!(used.contains(&"VRMC_vrm") && used.contains(&"VRMC_materials_mtoon"), "{used:?}");
    let vrm = &g.json["extensions"]["VRMC_vrm"];
    assert_eq!(vrm["specVersion"], "1.0");
    for k in ["name", "authors", "licenseUrl"] {
        assert!(!vrm["meta"][k].is_null(), "meta.{k}");
    }
    for b in HUMAN_BONES {
        let n = vrm["humanoid"]["humanBones"][b]["node"].as_u64().unwrap_or_else(|| panic!("{b}"));
        assert!(n < node_count(&g), "{b}");
    }
    for e in ["happy", "blink", "aa"] {
        for bind in vrm["expressions"]["preset"][e]["morphTargetBinds"].as_array().unwrap() {
            let node = &g.json["nodes"][bind["node"].as_u64().unwrap() as usize];
            let mesh = &g.json["meshes"][node["mesh"].as_u64().unwrap() as usize];
            let n_targets = mesh["primitives"][0]["targets"].as_array().unwrap().len() as u64;
            assert!(bind["index"].as_u64().unwrap() < n_targets, "{e}");
        }
    }
    let n_tex = g.json["textures"].as_array().unwrap().len() as u64;
    for m in g.json["materials"].as_array().unwrap() {
        let t = &m["extensions"]["VRMC_materials_mtoon"];
        assert_eq!(t["specVersion"], "1.0");
        assert_eq!(t["outlineWidthMode"], "worldCoordinates");
        for k in [
            "shadeColorFactor",
            "shadingShiftFactor",
            "shadingToonyFactor",
            "parametricRimColorFactor",
            "rimLightingMixFactor",
            "parametricRimFresnelPowerFactor",
            "parametricRimLiftFactor",
            "matcapFactor",
            "outlineWidthFactor",
            "outlineColorFactor",
            "outlineLightingMixFactor",
            "uvAnimationScrollXSpeedFactor",
        ] {
            assert!(!t[k].is_null(), "{}: {k}", m["name"]);
        }
        for k in
            ["shadeMultiplyTexture", "shadingShiftTexture", "matcapTexture", "outlineWidthMultiplyTexture"]
        {
            assert!(t[k]["index"].as_u64().unwrap() < n_tex, "{}: {k}", m["name"]);
        }
    }
    // T-pose at rest, facing +z: the hands reach out to ±0.8 at shoulder height, the face
    // morph (aa) moves vertices on the front of the head.
    let rest = g.pose(None);
    let reach = rest.iter().map(|p| p[0].abs()).fold(0.0, f64::max);
    assert!((0.75..0.85).contains(&reach), "{reach}");
    let plain = g.pose_with(None, false);
    let moved: Vec<&V3> =
        rest.iter().zip(&plain).filter(|(a, b)| spread(&[**a], &[**b]) > 1e-5).map(|(a, _)| a).collect();
    assert!(!moved.is_empty() && moved.iter().all(|p| p[2] > 0.0), "the morphs move the back of the head");
    // A valid glTF file for the loader, in the same rest pose.
    let mesh = hadou_scene::load_gltf(&asset("brace.vrm")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(mesh.positions.len(), rest.len());
}

#[test]
fn vrm_0_avatar_is_the_vrm_1_avatar_turned_to_face_minus_z() {
    let g0 = Gltf::open(&asset("brace0.vrm"));
    let g1 = Gltf::open(&asset("brace.vrm"));
    let vrm = &g0.json["extensions"]["VRM"];
    let bones: Vec<(&str, u64)> = vrm["humanoid"]["humanBones"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| (b["bone"].as_str().unwrap(), b["node"].as_u64().unwrap()))
        .collect();
    for b in HUMAN_BONES {
        let n = bones.iter().find(|x| x.0 == b).unwrap_or_else(|| panic!("{b}")).1;
        assert!(n < node_count(&g0));
        // The same bone on the same node as in the VRM 1.0 avatar.
        assert_eq!(
            g1.json["extensions"]["VRMC_vrm"]["humanoid"]["humanBones"][b]["node"].as_u64(),
            Some(n),
            "{b}"
        );
    }
    let presets: Vec<&str> = vrm["blendShapeMaster"]["blendShapeGroups"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| g["presetName"].as_str().unwrap())
        .collect();
    assert_eq!(presets, ["joy", "blink", "a"]);
    for m in vrm["materialProperties"].as_array().unwrap() {
        assert_eq!(m["shader"], "VRM/MToon");
        for k in ["_ShadeShift", "_ShadeToony", "_OutlineWidth", "_OutlineWidthMode", "_RimLightingMix"] {
            assert!(m["floatProperties"][k].is_number(), "{k}");
        }
        for k in ["_Color", "_ShadeColor", "_RimColor", "_OutlineColor"] {
            assert_eq!(m["vectorProperties"][k].as_array().map(Vec::len), Some(4), "{k}");
        }
    }
    // Turned 180° about y: (x, y, z) → (−x, y, −z), morphs included.
    let (p0, p1) = (g0.pose(None), g1.pose(None));
    assert_eq!(p0.len(), p1.len());
    for (a, b) in p0.iter().zip(&p1) {
        assert!(
            (a[0] + b[0]).abs() < 1e-5 && (a[1] - b[1]).abs() < 1e-5 && (a[2] + b[2]).abs() < 1e-5,
            "{a:?} {b:?}"
        );
    }
    // hadou turns a VRM 0.x model half a turn about y at load, so it faces +z like every other
    // model: the loaded VRM 0.x avatar stands where the VRM 1.0 avatar's reference stands.
    let mesh = hadou_scene::load_gltf(&asset("brace0.vrm")).unwrap_or_else(|e| panic!("{e}"));
    assert_close("brace0.vrm", &mesh.positions, &p1);
}

#[test]
fn vrm_animation_has_its_own_rest_pose_an_extra_bone_and_a_blink_track() {
    let g = Gltf::open(&asset("brace.vrma"));
    let ext = &g.json["extensions"]["VRMC_vrm_animation"];
    assert_eq!(ext["specVersion"], "1.0");
    let bones = &ext["humanoid"]["humanBones"];
    for b in HUMAN_BONES {
        assert!(bones[b]["node"].as_u64().unwrap() < node_count(&g), "{b}");
    }
    // A bone the avatars lack.
    assert!(bones["leftThumbProximal"]["node"].is_u64());
    let avatar = Gltf::open(&asset("brace.vrm"));
    assert!(avatar.json["extensions"]["VRMC_vrm"]["humanoid"]["humanBones"]
        .get("leftThumbProximal")
        .is_none());
    // The upper arms rest 10° lower than the avatar's T-pose.
    for (b, sign) in [("leftUpperArm", -1.0), ("rightUpperArm", 1.0)] {
        let n = bones[b]["node"].as_u64().unwrap() as usize;
        let q: Vec<f64> =
            g.json["nodes"][n]["rotation"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
        let deg = 2.0 * q[2].atan2(q[3]).to_degrees();
        assert!((deg - sign * 10.0).abs() < 1e-3, "{b}: {deg}");
        let m = avatar.json["extensions"]["VRMC_vrm"]["humanoid"]["humanBones"][b]["node"].as_u64().unwrap()
            as usize;
        assert!(avatar.json["nodes"][m].get("rotation").is_none(), "{b} of the avatar");
    }
    // The blink expression: its node's translation x is animated, from 0 up to 1.
    let blink = ext["expressions"]["preset"]["blink"]["node"].as_u64().unwrap();
    let a = g.animation("brace");
    let ch = g.json["animations"][a]["channels"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["target"]["node"].as_u64() == Some(blink))
        .expect("no blink track");
    assert_eq!(ch["target"]["path"], "translation");
    let s = ch["sampler"].as_u64().unwrap() as usize;
    let xs: Vec<f64> = (0..=20)
        .map(|k| match g.sample(a, s, "translation", k as f64 * 0.1) {
            gltf_reference::Sampled::Translation(t) => t[0],
            _ => unreachable!(),
        })
        .collect();
    assert!(xs.iter().all(|x| (0.0..=1.0).contains(x)) && xs.iter().any(|&x| x > 0.99), "{xs:?}");
}
