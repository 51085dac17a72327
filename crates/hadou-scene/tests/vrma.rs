//! VRM Animation clips (`scenes/assets/brace.vrma`, written by `make_brace.py`) retargeted onto the
//! VRM avatars `brace.vrm` (1.0) and `brace0.vrm` (0.x) by humanoid bone names (issue 26, point 3).
//! The VRMA skeleton rests with its upper arms 10° lower than the avatars' T-pose, and names a bone
//! the avatars lack. The independent f64 reference (`common/gltf_reference.rs`) poses the VRMA's
//! own skeleton; retargeting as the VRMA specification describes it must give every humanoid bone
//! of the avatar the world rotation *change from rest* that the VRMA bone has, and the hips the
//! VRMA hips' world position scaled by the ratio of hips heights.

#[path = "common/gltf_reference.rs"]
mod gltf_reference;

use gltf_reference::{Gltf, M4};
use hadou_math::keyframes::{quat_conjugate, quat_mul, rotation_of};
use hadou_math::Mat4;
use hadou_scene::{load_gltf_rig, load_vrma_clip, PoseInput, Scene};
use std::path::{Path, PathBuf};

fn asset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/assets").join(name)
}

fn mat(m: &M4) -> Mat4 {
    Mat4 { cols: std::array::from_fn(|c| std::array::from_fn(|r| m[c * 4 + r] as f32)) }
}

/// The rotation taking `a` to `b` in world axes: `b · a⁻¹`.
fn delta(a: &Mat4, b: &Mat4) -> [f32; 4] {
    quat_mul(rotation_of(b), quat_conjugate(rotation_of(a)))
}

fn same_rotation(a: [f32; 4], b: [f32; 4]) -> bool {
    (0..4).map(|i| a[i] * b[i]).sum::<f32>().abs() > 1.0 - 2e-6
}

fn vrma_bones(g: &Gltf) -> Vec<(String, usize)> {
    let bones = g.json["extensions"]["VRMC_vrm_animation"]["humanoid"]["humanBones"].as_object().unwrap();
    bones.iter().map(|(k, v)| (k.clone(), v["node"].as_u64().unwrap() as usize)).collect()
}

#[test]
fn every_bone_turns_as_the_vrma_bone_turns_from_its_rest() {
    for avatar in ["brace.vrm", "brace0.vrm"] {
        let (_, rig) = load_gltf_rig(&asset(avatar)).unwrap_or_else(|e| panic!("{avatar}: {e}"));
        let rig = rig.expect("a VRM has a rig");
        let (clip, warnings) = load_vrma_clip(&asset("brace.vrma"), &rig, Some("brace")).unwrap();
        assert!(
            warnings.iter().any(|w| w.contains("leftThumbProximal") && w.contains("skipped")),
            "{avatar}: {warnings:?}"
        );
        let vrma = Gltf::open(&asset("brace.vrma"));
        let bones = vrma_bones(&vrma);
        let src_rest = vrma.node_globals(None);
        let dst_rest = rig.node_globals(&PoseInput::default());
        let mut checked = 0;
        for t in [0.3f32, 0.9, 1.6] {
            let src = vrma.node_globals(Some(("brace", t as f64)));
            let dst = rig.node_globals(&PoseInput { clip: Some(&clip), time: t, ..Default::default() });
            for (bone, a) in &bones {
                let Some(&(_, b)) = rig.humanoid().iter().find(|h| &h.0 == bone) else { continue };
                let want = delta(&mat(&src_rest[*a]), &mat(&src[*a]));
                let got = delta(&dst_rest[b], &dst[b]);
                assert!(same_rotation(want, got), "{avatar} {bone} at {t}: {got:?}, want {want:?}");
                checked += 1;
            }
            // The hips: the VRMA hips' world position, scaled by the hips heights' ratio.
            let a = bones.iter().find(|b| b.0 == "hips").unwrap().1;
            let b = rig.humanoid().iter().find(|h| h.0 == "hips").unwrap().1;
            let s = dst_rest[b].cols[3][1] as f64 / src_rest[a][13];
            for (c, k) in [(0, 12), (1, 13), (2, 14)] {
                let want = src[a][k] * s;
                // A VRM 0.x avatar is turned to face +z at load, as the VRMA's skeleton faces.
                let got = dst[b].cols[3][c] as f64;
                assert!((got - want).abs() < 1e-4, "{avatar} hips[{c}] at {t}: {got} vs {want}");
            }
        }
        assert!(checked >= 3 * 15, "{avatar}: only {checked} bone checks");
    }
}

#[test]
fn the_vrma_blink_track_drives_the_blink_expression() {
    // The avatar's blink binds morph target `blink` of the head; an expression weight of w moves
    // an eyelid vertex by w·δ in the head bone's frame.
    let (mesh, rig) = load_gltf_rig(&asset("brace.vrm")).unwrap();
    let rig = rig.unwrap();
    let (clip, _) = load_vrma_clip(&asset("brace.vrma"), &rig, None).unwrap();
    let vrma = Gltf::open(&asset("brace.vrma"));
    let ext = &vrma.json["extensions"]["VRMC_vrm_animation"];
    let blink_node = ext["expressions"]["preset"]["blink"]["node"].as_u64().unwrap() as usize;
    let weight = |t: f32| vrma.node_globals(Some(("brace", t as f64)))[blink_node][12] as f32;
    let (t0, t1) =
        (0.0f32, (0..=40).map(|k| k as f32 * 0.05).max_by(|a, b| weight(*a).total_cmp(&weight(*b))).unwrap());
    assert!(weight(t1) - weight(t0) > 0.5, "the blink track barely moves: {} → {}", weight(t0), weight(t1));
    let head = rig.humanoid().iter().find(|h| h.0 == "head").unwrap().1;
    let blink = rig.expressions().iter().position(|e| e.name == "blink").unwrap();
    // Vertex positions in the head bone's frame, posed at `t` with extra expression weights.
    let pose = |t: f32, extra: &[(usize, f32)]| {
        let input = PoseInput { clip: Some(&clip), time: t, expressions: extra, ..Default::default() };
        let g = rig.node_globals(&input)[head];
        let inv = g.normal_matrix().transpose();
        let o = hadou_math::Vec3f::new(g.cols[3][0], g.cols[3][1], g.cols[3][2]);
        rig.pose(&mesh, &input)
            .positions
            .iter()
            .map(|p| inv.transform_vector(hadou_math::Vec3f::from_array(*p) - o).to_array())
            .collect::<Vec<_>>()
    };
    let base = pose(t0, &[]);
    // D1: what the clip does between t0 and t1; D2: the blink weight's change added by hand at t0.
    let d1: Vec<[f32; 3]> =
        pose(t1, &[]).iter().zip(&base).map(|(a, b)| [0, 1, 2].map(|i| a[i] - b[i])).collect();
    let dw = weight(t1) - weight(t0);
    let d2: Vec<[f32; 3]> =
        pose(t0, &[(blink, dw)]).iter().zip(&base).map(|(a, b)| [0, 1, 2].map(|i| a[i] - b[i])).collect();
    let eyelids: Vec<usize> = (0..d2.len()).filter(|&i| d2[i].iter().any(|c| c.abs() > 1e-4)).collect();
    assert!(!eyelids.is_empty(), "the blink expression binds no vertex");
    for &i in &eyelids {
        assert!(
            (0..3).all(|c| (d1[i][c] - d2[i][c]).abs() < 1e-4),
            "vertex {i}: clip moved it {:?}, blink {:?}",
            d1[i],
            d2[i]
        );
    }
}

#[test]
fn a_scene_plays_a_vrma_file_and_reports_its_problems() {
    let d = std::env::temp_dir().join(format!("hadou-vrma-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    for f in ["brace.vrm", "brace.vrma", "brace.glb"] {
        std::fs::copy(asset(f), d.join(f)).unwrap();
    }
    let scene = |keys: &str| {
        let text = format!(
            "[camera]\nposition = [0, 1, 6]\ntarget = [0, 1, 0]\n\n[[object]]\nname = \"who\"\nkind = \"gltf\"\npath = \"brace.vrm\"\n{keys}\n"
        );
        let p = d.join("scene.toml");
        std::fs::write(&p, text).unwrap();
        Scene::load(&p)
    };
    let s = scene("animation_file = \"brace.vrma\"").unwrap();
    assert!(
        s.warnings().iter().any(|w| w.contains("brace.vrma") && w.contains("leftThumbProximal")),
        "{:?}",
        s.warnings()
    );
    let (a, b) = (s.at(0.0), s.at(1.0));
    assert_ne!(
        a.objects[0].mesh.positions, b.objects[0].mesh.positions,
        "the VRMA clip does not move the avatar"
    );
    assert_eq!(s.object_clip_at(0, 1.0).map(|c| c.0), Some("brace".to_string()));
    let e = scene("animation_file = \"brace.vrma\"\nanimation = \"dance\"").unwrap_err().to_string();
    assert!(e.contains("scene.toml:9:18") && e.contains("no clip \"dance\"; its clips are \"brace\""), "{e}");
    let e = scene("animation_file = \"brace.glb\"").unwrap_err().to_string();
    assert!(e.contains("not a VRM Animation"), "{e}");
    let e = scene("animation_file = \"../brace.vrma\"").unwrap_err().to_string();
    assert!(e.contains("scene.toml:9:18") && (e.contains("outside") || e.contains("cannot read")), "{e}");
    let e = scene("animation_file = \"missing.vrma\"").unwrap_err().to_string();
    assert!(e.contains("cannot read the file"), "{e}");
}

/// `data` (a binary glTF) with its JSON chunk replaced by `json` (padded with spaces, as the
/// format pads it).
fn with_json(data: &[u8], json: &str) -> Vec<u8> {
    let le = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize;
    let json_len = le(&data[12..16]);
    let rest = &data[20 + json_len..];
    let mut j = json.as_bytes().to_vec();
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

/// Issue 41, point 3: a VRMA whose bone name holds an escape sequence (`a\x1b[2Jb`) reached the
/// terminal raw in the "names bones … the character lacks" warning. Every warning a scene keeps
/// has its control characters escaped, whichever loader wrote it.
#[test]
fn issue_41_a_warning_never_carries_a_files_control_characters() {
    let d = std::env::temp_dir().join(format!("hadou-vrma-escape-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    std::fs::copy(asset("brace.vrm"), d.join("brace.vrm")).unwrap();
    let data = std::fs::read(asset("brace.vrma")).unwrap();
    let json_len = u32::from_le_bytes([data[12], data[13], data[14], data[15]]) as usize;
    let json = std::str::from_utf8(&data[20..20 + json_len]).unwrap();
    assert!(json.contains("\"leftThumbProximal\""), "the fixture names a bone the avatar lacks");
    let hostile = json.replace("\"leftThumbProximal\"", "\"a\\u001b[2Jb\\u0007\\u202e\"");
    std::fs::write(d.join("hostile.vrma"), with_json(&data, &hostile)).unwrap();
    let p = d.join("scene.toml");
    std::fs::write(
        &p,
        "[camera]\nposition = [0, 1, 6]\ntarget = [0, 1, 0]\n\n[[object]]\nname = \"who\"\nkind = \"gltf\"\n\
         path = \"brace.vrm\"\nanimation_file = \"hostile.vrma\"\n",
    )
    .unwrap();
    let s = Scene::load(&p).unwrap();
    let w = s.warnings().iter().find(|w| w.contains("lacks")).unwrap_or_else(|| panic!("{:?}", s.warnings()));
    assert!(w.contains("a\\u{1b}[2Jb\\u{7}\\u{202e}"), "{w}");
    for w in s.warnings() {
        assert!(
            !w.chars().any(|c| c.is_control() || ('\u{202a}'..='\u{202e}').contains(&c)),
            "a warning carries a control character: {w:?}"
        );
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// `Scene::object_node_pose_at` (what the Bevy plugin sets on the file's own nodes): its node
/// locals, composed parent first (glTF 2.0 §3.5.3, `G(node) = G(parent) · L(node)`), are the
/// node globals hadou skins the VRMA-posed mesh by (`Rig::node_globals` of the same clip and clip
/// time); they move with the scene time, and only an object posed beyond a file clip has them.
#[test]
fn a_scenes_node_pose_composes_to_the_globals_its_mesh_is_posed_by() {
    let d = std::env::temp_dir().join(format!("hadou-vrma-nodes-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    for f in ["brace.vrm", "brace.vrma"] {
        std::fs::copy(asset(f), d.join(f)).unwrap();
    }
    let text = "[camera]\nposition = [0, 1, 6]\ntarget = [0, 1, 0]\n\n[[object]]\nname = \"who\"\nkind = \"gltf\"\n\
                path = \"brace.vrm\"\nanimation_file = \"brace.vrma\"\nspring = false\n\n[[object]]\nname = \"floor\"\n\
                kind = \"plane\"\n";
    std::fs::write(d.join("scene.toml"), text).unwrap();
    let scene = Scene::load(d.join("scene.toml")).unwrap();
    assert!(scene.object_posed_by_hadou(0) && !scene.object_posed_by_hadou(1));
    assert!(scene.object_node_pose_at(1, 0.9).is_none(), "a plane has no nodes");
    let (_, rig) = load_gltf_rig(&asset("brace.vrm")).unwrap();
    let rig = rig.unwrap();
    let (clip, _) = load_vrma_clip(&asset("brace.vrma"), &rig, None).unwrap();
    let json = Gltf::open(&asset("brace.vrm")).json;
    let nodes = json["nodes"].as_array().unwrap();
    let mut parent = vec![None; nodes.len()];
    for (i, n) in nodes.iter().enumerate() {
        for c in n["children"].as_array().into_iter().flatten() {
            parent[c.as_u64().unwrap() as usize] = Some(i);
        }
    }
    let mut poses = Vec::new();
    for t in [0.3f32, 0.9] {
        let pose = scene.object_node_pose_at(0, t).expect("a VRMA-posed character has a node pose");
        assert_eq!((pose.locals.len(), pose.weights.len()), (nodes.len(), nodes.len()));
        let want = rig.node_globals(&PoseInput { clip: Some(&clip), time: t, ..Default::default() });
        let mut got: Vec<Option<Mat4>> = vec![None; nodes.len()];
        // Parents before children: repeat until every node is placed.
        while got.iter().any(Option::is_none) {
            for i in 0..nodes.len() {
                let (t_, r, s) = pose.locals[i].expect("brace.vrm's nodes are TRS");
                let local = hadou_math::keyframes::trs_matrix(t_, r, s);
                got[i] = match parent[i] {
                    None => Some(local),
                    Some(p) => got[p].map(|g| g * local),
                };
            }
        }
        for (i, (g, w)) in got.iter().zip(&want).enumerate() {
            for (a, b) in g.unwrap().cols.iter().flatten().zip(w.cols.iter().flatten()) {
                assert!((a - b).abs() < 1e-5, "node {i} at {t}: {g:?} vs {w:?}");
            }
        }
        poses.push(pose);
    }
    assert_ne!(poses[0], poses[1], "the clip moves the nodes between 0.3 s and 0.9 s");
    // A file clip alone is played by the file's own clip (`object_clip_at`), not posed by hadou.
    let brace =
        Scene::load(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/light-brace.toml")).unwrap();
    assert!(!brace.object_posed_by_hadou(0));
    let showcase =
        Scene::load(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/showcase.toml")).unwrap();
    assert!(showcase.object_posed_by_hadou(0), "a VRMA clip and spring bones");
}
