//! VRM spring bones in a scene (issue 46): `brace.vrm` and `brace0.vrm` given spring bones on
//! their arms (the JSON chunk rewritten here), posed at a time as a pure function of that time
//! (alone, in a sequence, backwards: the same bits), blown by a wave's `wind`, switched off by
//! `spring = false`, and the keys' located errors.

use hadou_scene::Scene;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn asset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/assets").join(name)
}

/// `data` (a binary glTF) with its JSON chunk replaced by `json`.
fn with_json(data: &[u8], json: &Value) -> Vec<u8> {
    let le = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize;
    let json_len = le(&data[12..16]);
    let rest = &data[20 + json_len..];
    let mut j = serde_json::to_vec(json).unwrap();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut out = data[..12].to_vec();
    out.extend((j.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&j);
    out.extend(rest);
    let total = out.len() as u32;
    out[8..12].copy_from_slice(&total.to_le_bytes());
    out
}

fn json_of(data: &[u8]) -> Value {
    let n = u32::from_le_bytes([data[12], data[13], data[14], data[15]]) as usize;
    serde_json::from_slice(&data[20..20 + n]).unwrap()
}

/// A folder with `arms.vrm` (brace.vrm whose arms are springs, VRM 1.0), `arms0.vrm` (brace0.vrm
/// with the same as VRM 0.x bone groups) and `brace.vrm` as it is.
fn folder(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hadou-springs-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let data = std::fs::read(asset("brace.vrm")).unwrap();
    let mut j = json_of(&data);
    let joint = |n: usize| json!({ "node": n, "stiffness": 0.3, "gravityPower": 1.5, "dragForce": 0.3, "hitRadius": 0.05 });
    j["extensions"]["VRMC_springBone"] = json!({
        "specVersion": "1.0",
        "colliders": [{ "node": 2, "shape": { "capsule": { "offset": [0.0, -0.3, 0.0], "tail": [0.0, 0.2, 0.0], "radius": 0.15 } } }],
        "colliderGroups": [{ "colliders": [0] }],
        "springs": [
            { "name": "left", "joints": [joint(6), joint(7), joint(8)], "colliderGroups": [0] },
            { "name": "right", "joints": [joint(10), joint(11), joint(12)], "colliderGroups": [0] }
        ]
    });
    std::fs::write(d.join("arms.vrm"), with_json(&data, &j)).unwrap();
    let data0 = std::fs::read(asset("brace0.vrm")).unwrap();
    let mut j0 = json_of(&data0);
    j0["extensions"]["VRM"]["secondaryAnimation"] = json!({
        "colliderGroups": [{ "node": 2, "colliders": [{ "offset": { "x": 0.0, "y": 0.0, "z": 0.0 }, "radius": 0.15 }] }],
        "boneGroups": [{ "bones": [6, 10], "stiffiness": 0.3, "gravityPower": 1.5, "dragForce": 0.3,
            "gravityDir": { "x": 0, "y": -1, "z": 0 }, "hitRadius": 0.05, "center": -1, "colliderGroups": [0] }]
    });
    std::fs::write(d.join("arms0.vrm"), with_json(&data0, &j0)).unwrap();
    std::fs::copy(asset("brace.vrm"), d.join("brace.vrm")).unwrap();
    d
}

const BEAM: &str = "[[wave]]\nname = \"beam\"\nkind = \"beam\"\nrgba = [0.45, 0.8, 1.0, 1.0]\n\
    M = [1.2, 1.3, 3.0]\nD = [0.0, 0.0, -1.0]\nlength = 0.0\nalpha_s = 0.02\nalpha_c = 0.02\n\
    head_alpha = 0.05\nmuzzle_alpha = 0.03\ncore_radius = 0.05\n";
const GROW: &str = "[[track]]\ntarget = \"wave.beam.length\"\nkeys = [[0.0, 0.0], [1.5, 6.0]]\n";

fn scene(d: &Path, object: &str, rest: &str) -> Result<Scene, String> {
    let text = format!(
        "[camera]\nposition = [0, 1, 6]\ntarget = [0, 1, 0]\n\n[[object]]\nname = \"who\"\nkind = \"gltf\"\n{object}\n{rest}"
    );
    let p = d.join("scene.toml");
    std::fs::write(&p, text).unwrap();
    Scene::load(&p).map_err(|e| e.to_string())
}

fn bits(s: &Scene, t: f32) -> Vec<u32> {
    s.at(t).objects[0].mesh.positions.iter().flatten().map(|c| c.to_bits()).collect()
}

#[test]
fn past_a_minute_the_start_moves_by_ten_seconds_and_frames_between_continue_one_state() {
    use hadou_scene::{spring_start, SPRING_MAX_STEPS, SPRING_RESTART_STEPS};
    assert_eq!((SPRING_MAX_STEPS, SPRING_RESTART_STEPS), (3_600, 600));
    for (n, start) in [(0, 0), (3_600, 0), (3_601, 600), (4_200, 600), (4_201, 1_200), (10_000, 6_600)] {
        assert_eq!(spring_start(n), start, "step {n}");
    }
    for n in (3_000..20_000).step_by(37).chain([u64::MAX, u64::MAX - 1]) {
        let back = n - spring_start(n);
        assert!(back <= SPRING_MAX_STEPS && (n < SPRING_MAX_STEPS || back > SPRING_MAX_STEPS - 600), "{n}");
    }
    let d = folder("minute");
    let rest = format!("{BEAM}wind = 2.0\n{GROW}");
    let object = "path = \"arms.vrm\"";
    let times = [61.0f32, 61.5, 69.99, 70.02];
    let alone: Vec<Vec<u32>> = times.iter().map(|&t| bits(&scene(&d, object, &rest).unwrap(), t)).collect();
    let s = scene(&d, object, &rest).unwrap();
    for (t, want) in times.iter().zip(&alone) {
        assert!(bits(&s, *t) == *want, "at {t} s the sequence differs");
    }
    assert_eq!(s.spring_state_step("who"), Some(4_201));
}

#[test]
fn a_frame_is_a_function_of_its_time_alone() {
    let d = folder("pure");
    let rest = format!("{BEAM}wind = 2.0\n{GROW}");
    for file in ["arms.vrm", "arms0.vrm"] {
        let object = format!("path = \"{file}\"");
        let times = [0.0f32, 0.3, 0.95, 1.0, 1.7, 2.35, 0.5];
        // Each time from a freshly loaded scene.
        let alone: Vec<Vec<u32>> =
            times.iter().map(|&t| bits(&scene(&d, &object, &rest).unwrap(), t)).collect();
        // One scene in order (the cache continues), then out of order (it restarts).
        let s = scene(&d, &object, &rest).unwrap();
        for (t, want) in times.iter().zip(&alone) {
            assert!(bits(&s, *t) == *want, "{file} at {t} s differs in a sequence");
        }
        for (t, want) in times.iter().zip(&alone).rev() {
            assert!(bits(&s, *t) == *want, "{file} at {t} s differs backwards");
        }
        // A clone shares the cache and gives the same.
        let c = s.clone();
        assert!(bits(&c, 1.7) == alone[4]);
        // The arms swing down under gravity: a later frame differs from the rest pose.
        assert_ne!(alone[0], alone[4], "{file}: the springs do not move");
    }
}

#[test]
fn the_arms_fall_and_the_wind_blows_them_away_from_the_beam() {
    let d = folder("wind");
    // Where the left forearm and hand (x > 0.55 at rest: the beam side) are: the mean of those
    // vertices.
    let rest = scene(&d, "path = \"brace.vrm\"", "").unwrap().at(0.0).objects[0].mesh.clone();
    let picked: Vec<usize> = (0..rest.positions.len()).filter(|&i| rest.positions[i][0] > 0.55).collect();
    assert!(!picked.is_empty());
    let hand = |s: &Scene, t: f32| {
        let f = s.at(t);
        let p = &f.objects[0].mesh.positions;
        let n = picked.len() as f32;
        (
            picked.iter().map(|&i| p[i][0]).sum::<f32>() / n,
            picked.iter().map(|&i| p[i][1]).sum::<f32>() / n,
            n,
        )
    };
    let still = scene(&d, "path = \"arms.vrm\"\nspring = false", "").unwrap();
    let plain = scene(&d, "path = \"brace.vrm\"", "").unwrap();
    assert_eq!(bits(&still, 2.0), bits(&plain, 0.0), "spring = false keeps the rest pose");
    let calm = scene(&d, "path = \"arms.vrm\"", &format!("{BEAM}{GROW}")).unwrap();
    let windless = scene(&d, "path = \"arms.vrm\"", &format!("{BEAM}wind = 0.0\n{GROW}")).unwrap();
    assert_eq!(bits(&calm, 2.0), bits(&windless, 2.0), "wind = 0 is the default");
    let (rx, ry, _) = hand(&plain, 0.0);
    let (cx, cy, _) = hand(&calm, 3.0);
    assert!(cy < ry - 0.05, "the arm falls: rest y {ry}, fallen {cy}");
    let blown = scene(&d, "path = \"arms.vrm\"", &format!("{BEAM}wind = 40.0\n{GROW}")).unwrap();
    let (bx, by, _) = hand(&blown, 3.0);
    // The beam passes at x = 1.2, y = 1.3: the wind pushes the arm that hangs below it away.
    assert!(
        (bx - 1.2).hypot(by - 1.3) > (cx - 1.2).hypot(cy - 1.3) + 0.01,
        "blown ({bx}, {by}) is not further from the beam than calm ({cx}, {cy}); rest x {rx}"
    );
    for p in blown.at(3.0).objects[0].mesh.positions.iter().flatten() {
        assert!(p.is_finite());
    }
    // A gale stays finite.
    let gale = scene(&d, "path = \"arms.vrm\"", &format!("{BEAM}wind = 1e6\n{GROW}")).unwrap();
    for p in gale.at(2.0).objects[0].mesh.positions.iter().flatten() {
        assert!(p.is_finite());
    }
}

#[test]
fn spring_and_wind_keys_report_their_place() {
    let d = folder("keys");
    let e = scene(&d, "path = \"brace.vrm\"\nspring = true", "").unwrap_err();
    assert!(e.contains("scene.toml:9:1") && e.contains("no VRM spring bones"), "{e}");
    let e = scene(&d, "path = \"arms.vrm\"\nspring = 1", "").unwrap_err();
    assert!(e.contains("scene.toml:9:") && e.contains("true or false"), "{e}");
    for bad in ["-1.0", "nan", "inf"] {
        let e = scene(&d, "path = \"arms.vrm\"", &format!("{BEAM}wind = {bad}\n")).unwrap_err();
        assert!(e.contains("scene.toml:") && e.contains("wind"), "{bad}: {e}");
    }
    // A broken spring in the file is an error naming its JSON path.
    let data = std::fs::read(d.join("arms.vrm")).unwrap();
    let mut j = json_of(&data);
    j["extensions"]["VRMC_springBone"]["colliders"][0]["shape"]["capsule"]["radius"] = json!(-1.0);
    std::fs::write(d.join("bad.vrm"), with_json(&data, &j)).unwrap();
    let e = scene(&d, "path = \"bad.vrm\"", "").unwrap_err();
    assert!(e.contains("VRMC_springBone.colliders[0].shape.capsule.radius is -1"), "{e}");
}

#[test]
fn the_generated_blast_character_has_spring_hair_and_skirt_that_fall_and_settle() {
    let (mesh, rig) = hadou_scene::load_gltf_rig(&asset("blast.vrm")).unwrap();
    let rig = rig.expect("a rig");
    let springs = rig.springs().expect("blast.vrm has spring bones");
    // make_brace.py: 12 hair strands of 9 joints and 16 skirt strands of 7, each last joint a tail.
    assert_eq!(springs.joint_count(), 12 * 8 + 16 * 6);
    assert_eq!(springs.collider_count(), 4);
    let d = std::env::temp_dir().join(format!("hadou-springs-blast-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    std::fs::copy(asset("blast.vrm"), d.join("blast.vrm")).unwrap();
    let s = scene(&d, "path = \"blast.vrm\"", "").unwrap();
    let (a, b, c) = (s.at(0.0), s.at(3.0), s.at(3.5));
    let moved = |x: &hadou_scene::Frame, y: &hadou_scene::Frame| {
        x.objects[0]
            .mesh
            .positions
            .iter()
            .zip(&y.objects[0].mesh.positions)
            .map(|(p, q)| (p[0] - q[0]).hypot(p[1] - q[1]).hypot(p[2] - q[2]))
            .fold(0.0f32, f32::max)
    };
    assert_eq!(a.objects[0].mesh.positions, mesh.positions, "at time 0 the springs are at rest");
    assert!(moved(&a, &b) > 0.01, "the strands fall: {}", moved(&a, &b));
    assert!(moved(&b, &c) < 1e-3, "and settle: {}", moved(&b, &c));
    assert!(b.objects[0].mesh.positions.iter().flatten().all(|x| x.is_finite()));
}

/// `brace.vrm` with look-at of type expression: `lookLeft` closes the eyes (the blink morph target),
/// `lookUp` opens the mouth (`aa`), range maps 0–90° → 0–1.
fn look_folder(tag: &str) -> PathBuf {
    let d = folder(tag);
    let data = std::fs::read(asset("brace.vrm")).unwrap();
    let mut j = json_of(&data);
    let head_mesh = j["nodes"].as_array().unwrap().iter().position(|n| n["name"] == "head_mesh").unwrap();
    let vrm = &mut j["extensions"]["VRMC_vrm"];
    let map = json!({ "inputMaxValue": 90.0, "outputScale": 1.0 });
    vrm["lookAt"] = json!({ "type": "expression", "offsetFromHeadBone": [0.0, 0.1, 0.1],
        "rangeMapHorizontalInner": map, "rangeMapHorizontalOuter": map,
        "rangeMapVerticalDown": map, "rangeMapVerticalUp": map });
    vrm["expressions"]["preset"]["lookLeft"] =
        json!({ "morphTargetBinds": [{ "node": head_mesh, "index": 0, "weight": 1.0 }] });
    vrm["expressions"]["preset"]["lookUp"] =
        json!({ "morphTargetBinds": [{ "node": head_mesh, "index": 1, "weight": 1.0 }] });
    std::fs::write(d.join("eyes.vrm"), with_json(&data, &j)).unwrap();
    d
}

#[test]
fn the_eyes_follow_a_point_the_camera_and_a_waves_head() {
    let d = look_folder("look");
    // The head (1.53) plus the offset (0.1) is at y 1.63, z 0.1: a point straight to the character's
    // left, level with it, is 90° of yaw: `lookLeft` at its full weight, as `blink = 1` gives.
    let blink = scene(&d, "path = \"eyes.vrm\"\nexpressions = { blink = 1.0 }", "").unwrap();
    let left = scene(&d, "path = \"eyes.vrm\"\nlook_at = [5.0, 1.63, 0.1]", "").unwrap();
    let pos = |s: &Scene, t: f32| s.at(t).objects[0].mesh.positions.clone();
    let close = |a: &[[f32; 3]], b: &[[f32; 3]]| {
        a.iter()
            .zip(b)
            .map(|(p, q)| (p[0] - q[0]).abs().max((p[1] - q[1]).abs()).max((p[2] - q[2]).abs()))
            .fold(0.0f32, f32::max)
    };
    assert!(close(&pos(&left, 0.0), &pos(&blink, 0.0)) < 1e-5);
    // Straight ahead (the camera at z = 6): no look expression, the rest pose.
    let ahead = scene(&d, "path = \"eyes.vrm\"\nlook_at = \"camera\"", "").unwrap();
    let rest = scene(&d, "path = \"brace.vrm\"", "").unwrap();
    assert!(close(&pos(&ahead, 0.0), &pos(&rest, 0.0)) < 2e-3);
    // A beam's head rising past the character: the eyes follow it up (the mouth opens, `lookUp`).
    let beam = "[[wave]]\nname = \"beam\"\nkind = \"beam\"\nM = [0.0, 1.63, 3.0]\nD = [0.0, 1.0, 0.0]\nlength = 0.0\n\
        alpha_s = 0.02\nalpha_c = 0.02\n[[track]]\ntarget = \"wave.beam.length\"\nkeys = [[0.0, 0.0], [1.0, 3.0]]\n";
    let follow = scene(&d, "path = \"eyes.vrm\"\nlook_at = \"beam\"", beam).unwrap();
    let mouth = scene(&d, "path = \"eyes.vrm\"\nexpressions = { aa = 0.5 }", "").unwrap();
    // At 1 s the head is 3 above and 2.9 in front of the eyes: 45.97° up.
    let want = scene(
        &d,
        &format!("path = \"eyes.vrm\"\nexpressions = {{ aa = {} }}", (3.0f32).atan2(2.9).to_degrees() / 90.0),
        "",
    )
    .unwrap();
    assert!(close(&pos(&follow, 1.0), &pos(&want, 0.0)) < 1e-4);
    assert!(close(&pos(&follow, 0.0), &pos(&mouth, 0.0)) > 1e-3);
    // An animated point.
    let track =
        "[[track]]\ntarget = \"object.who.look_at\"\nkeys = [[0.0, [0.0, 1.63, 5.0]], [1.0, [5.0, 1.63, 0.1]]]\n";
    let moving = scene(&d, "path = \"eyes.vrm\"\nlook_at = [0.0, 1.63, 5.0]", track).unwrap();
    assert!(close(&pos(&moving, 1.0), &pos(&blink, 0.0)) < 1e-5);
    // Bad input, located.
    let e = scene(&d, "path = \"eyes.vrm\"\nlook_at = \"nothing\"", beam).unwrap_err();
    assert!(
        e.contains("scene.toml:9:11") && e.contains("names no wave \"nothing\"") && e.contains("\"beam\""),
        "{e}"
    );
    let e = scene(&d, "path = \"brace.vrm\"\nlook_at = \"camera\"", "").unwrap_err();
    assert!(e.contains("scene.toml:9:1") && e.contains("no VRM look-at"), "{e}");
    // One sentence, without a run of spaces from a line break in its source.
    assert!(e.contains("`lookAt` with eye bones or look expressions") && !e.contains("  "), "{e}");
    let e = scene(&d, "path = \"eyes.vrm\"\nlook_at = [0.0, nan, 1.0]", "").unwrap_err();
    assert!(e.contains("scene.toml:9:") && e.contains("look_at"), "{e}");
}

/// `scenes/showcase.toml` (the README's first picture) loads without a warning, and at its picture's
/// time the beam's wind has blown both the hair and the skirt of `assets/showcase.vrm` away from the
/// beam (which passes at x = 0.95, along z): against the same scene without wind, strands of both
/// materials moved, and on the whole towards −x. The body, the clip and the beam are the same in
/// both, so only the strands can differ.
#[test]
fn the_showcase_blows_its_hair_and_skirt_away_from_the_beam() {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let d = std::env::temp_dir().join(format!("hadou-springs-showcase-{}", std::process::id()));
    std::fs::create_dir_all(d.join("assets")).unwrap();
    for f in ["showcase.vrm", "showcase.vrma"] {
        std::fs::copy(asset(f), d.join("assets").join(f)).unwrap();
    }
    let text = std::fs::read_to_string(scenes.join("showcase.toml")).unwrap();
    let gust = "keys = [[0.0, 0.0], [0.5, 0.0], [0.9, 100.0]]";
    assert!(text.contains(gust), "the showcase's wind track");
    std::fs::write(d.join("showcase.toml"), &text).unwrap();
    std::fs::write(d.join("calm.toml"), text.replace(gust, "keys = [[0.0, 0.0]]")).unwrap();
    let blown = Scene::load(d.join("showcase.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert!(blown.warnings().is_empty(), "the README's first command warns: {:?}", blown.warnings());
    let calm = Scene::load(d.join("calm.toml")).unwrap_or_else(|e| panic!("{e}"));
    let hero = blown.object_names().iter().position(|n| *n == "hero").expect("the character");
    let (a, b) = (blown.at(1.8), calm.at(1.8));
    let (wind, still) = (&a.objects[hero].mesh, &b.objects[hero].mesh);
    assert!(wind.positions.iter().flatten().all(|x| x.is_finite()));
    for material in ["hair", "suit"] {
        let slot = wind.materials.iter().position(|m| m.name == material).expect("the material") as u32;
        let (mut most, mut dx) = (0.0f32, 0.0f32);
        for (v, (p, q)) in wind.positions.iter().zip(&still.positions).enumerate() {
            if wind.material_of(v) == slot {
                most = most.max((p[0] - q[0]).hypot(p[1] - q[1]).hypot(p[2] - q[2]));
                dx += p[0] - q[0];
            }
        }
        assert!(most > 0.05, "the wind moves the {material} strands: at most {most}");
        assert!(dx < 0.0, "away from the beam, towards −x: {dx}");
    }
    std::fs::remove_dir_all(&d).ok();
}
