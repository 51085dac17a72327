//! The scene-wide budgets and the limits on work that multiplies counts from a file: each hostile
//! file is built here by a small generator and must end in a located error naming the limit (or
//! load quickly), never in a panic, an abort or hours of work.

mod common;

use common::gltf::Builder;
use common::{at, err, png_header_only};
use hadou_scene::{
    gltf_from_bytes, gltf_from_bytes_with_warnings, Scene, SceneError, MAX_SCENE_TEXELS, MAX_SKINNED_NODES,
    MAX_SKIN_JOINTS,
};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn tmp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hadou-budgets-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&d).ok();
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn load_err(path: &Path) -> SceneError {
    match Scene::load(path) {
        Ok(_) => panic!("{} loaded but should be refused", path.display()),
        Err(e) => e,
    }
}

// ---------------------------------------------------------------------------------------------
// Small generators: PNG chunks, glTF buffers.

/// A valid black `w × h` greyscale PNG (compresses to almost nothing).
fn png_black(w: u32, h: u32) -> Vec<u8> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Fast);
        let mut wr = enc.write_header().unwrap();
        wr.write_image_data(&vec![0u8; w as usize * h as usize]).unwrap();
    }
    out
}

const TRI: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

// ---------------------------------------------------------------------------------------------
// The scene's texture budget.

#[test]
fn two_halved_8192_textures_cross_the_scene_texel_budget() {
    // The recipe of the GPU's refusal: two 8192² textures, halved to 4096² at load, would take
    // 128 MiB of texels; the loader refuses the second before decoding it.
    let d = tmp_dir("tex8192");
    std::fs::write(d.join("a.png"), png_black(8192, 8192)).unwrap();
    std::fs::write(d.join("b.png"), png_header_only(8192, 8192)).unwrap();
    let scene = "[[material]]\nname = \"first\"\nbase_texture = \"a.png\"\n\n\
                 [[material]]\nname = \"again\"\nfeature_texture = \"a.png\"\n\n\
                 [[material]]\nname = \"second\"\nbase_texture = \"b.png\"\n";
    std::fs::write(d.join("s.toml"), scene).unwrap();
    let e = load_err(&d.join("s.toml"));
    let msg = e.to_string();
    assert_eq!(at(&e), (11, 16), "{msg}");
    assert!(msg.contains("[[material]] \"second\"") && msg.contains("b.png"), "{msg}");
    assert!(
        msg.contains("kept at 4096×4096") && msg.contains(&format!("limit of {MAX_SCENE_TEXELS} texels")),
        "{msg}"
    );
    // The same file named twice is one texture: the first two materials alone load.
    std::fs::write(d.join("s.toml"), &scene[..scene.find("\n\n[[material]]\nname = \"second\"").unwrap()])
        .unwrap();
    let s = Scene::load(d.join("s.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert!(s.warnings().iter().any(|w| w.contains("downscaled")), "{:?}", s.warnings());
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn gltf_textures_count_against_the_scene_texel_budget() {
    // A scene texture of 4096² leaves 31·2²⁰ − 2²⁴ texels; the glTF's 4096² image crosses it, and
    // the message names the glTF material, its image and the limit.
    let d = tmp_dir("texgltf");
    std::fs::write(d.join("big.png"), png_black(4096, 4096)).unwrap();
    std::fs::write(d.join("img.png"), png_header_only(4096, 4096)).unwrap();
    let mut b = Builder::default();
    let pos = b.positions(&TRI);
    let uv = b.f32s(&[0.0; 6], 3, "VEC2");
    let doc = json!({
        "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos, "TEXCOORD_0": uv}, "material": 0}]}],
        "materials": [{"name": "skin", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}], "images": [{"uri": "img.png"}]
    });
    std::fs::write(d.join("m.gltf"), b.finish(doc)).unwrap();
    let scene = "[[material]]\nname = \"wall\"\nbase_texture = \"big.png\"\n\n\
                 [[object]]\nname = \"hero\"\nkind = \"gltf\"\npath = \"m.gltf\"\n";
    std::fs::write(d.join("s.toml"), scene).unwrap();
    let msg = load_err(&d.join("s.toml")).to_string();
    assert!(msg.contains("m.gltf") && msg.contains("material `skin`") && msg.contains("`img.png`"), "{msg}");
    assert!(
        msg.contains("more than the 15728640 left") && msg.contains("texels for all the textures"),
        "{msg}"
    );
    // Alone, the glTF loads (its image then fails to decode, being only a header).
    std::fs::write(d.join("s.toml"), "[[object]]\nname = \"hero\"\nkind = \"gltf\"\npath = \"m.gltf\"\n")
        .unwrap();
    let msg = load_err(&d.join("s.toml")).to_string();
    assert!(msg.contains("not a valid PNG") && !msg.contains("left of"), "{msg}");
    std::fs::remove_dir_all(&d).ok();
}

// ---------------------------------------------------------------------------------------------
// Skins.

/// `nodes` skinned mesh nodes over one skin of `joints` joints (joint nodes in a flat list under
/// one root), each skinned node drawing the same triangle bound to joint 0.
fn skinned_file(nodes: usize, joints: usize, skins: usize) -> Vec<u8> {
    let mut b = Builder::default();
    let pos = b.positions(&TRI);
    let j = b.acc(&[0u8; 12], 5121, 3, "VEC4", false);
    let w = b.f32s(&[1.0, 0.0, 0.0, 0.0].repeat(3), 3, "VEC4");
    let mut node_list: Vec<Value> = Vec::new();
    // Node 0: the root of the joints; nodes 1..=joints: the joints.
    node_list.push(json!({"children": (1..=joints).collect::<Vec<_>>()}));
    for k in 0..joints {
        node_list.push(json!({"translation": [k as f32 * 1e-3, 0.0, 0.0]}));
    }
    let mut roots = vec![0];
    for n in 0..nodes {
        roots.push(node_list.len());
        node_list.push(json!({"mesh": 0, "skin": n % skins}));
    }
    let skin_list: Vec<Value> =
        (0..skins).map(|_| json!({"joints": (1..=joints).collect::<Vec<_>>()})).collect();
    let doc = json!({
        "scenes": [{"nodes": roots}], "nodes": node_list, "skins": skin_list,
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos, "JOINTS_0": j, "WEIGHTS_0": w}}]}]
    });
    b.finish(doc)
}

#[test]
fn skin_matrices_are_computed_once_per_skin() {
    // 16 384 skinned nodes over one 30 000-joint skin: 4.9·10⁸ joint matrices if each node
    // recomputed its skin, 30 000 when each skin is computed once.
    let bytes = skinned_file(MAX_SKINNED_NODES as usize, 30_000, 1);
    let start = std::time::Instant::now();
    let m = gltf_from_bytes(&bytes, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.indices.len(), 3 * MAX_SKINNED_NODES as usize);
    assert!(start.elapsed() < std::time::Duration::from_secs(20), "{:?}", start.elapsed());
}

#[test]
fn skinned_nodes_past_their_limit_are_refused() {
    let e = gltf_from_bytes(&skinned_file(MAX_SKINNED_NODES as usize + 1, 2, 1), Path::new(".")).unwrap_err();
    assert!(e.contains(&format!("limit of {MAX_SKINNED_NODES} skinned mesh nodes")), "{e}");
}

#[test]
fn skin_joints_past_their_limit_are_refused() {
    // One skin too large, and two skins that are too large together.
    let e = gltf_from_bytes(&skinned_file(1, MAX_SKIN_JOINTS as usize + 1, 1), Path::new(".")).unwrap_err();
    assert!(
        e.contains(&format!("limit of {MAX_SKIN_JOINTS} joints per glTF file")) && e.contains("skin 0"),
        "{e}"
    );
    let half = MAX_SKIN_JOINTS as usize / 2 + 1;
    let e = gltf_from_bytes(&skinned_file(2, half, 2), Path::new(".")).unwrap_err();
    assert!(e.contains("brings the joints") && e.contains(&format!("to {}", 2 * half)), "{e}");
    // Two nodes sharing one skin count its joints once.
    assert!(gltf_from_bytes(&skinned_file(2, half, 1), Path::new(".")).is_ok());
}

#[test]
fn overflowing_skin_weights_are_normalised_without_collapsing() {
    // Two joints at x = 0 and x = 1 (translations), weights [3e38, 3e38]: their sum overflows
    // f32, but the vertex must land halfway, not at the origin.
    let mut b = Builder::default();
    let pos = b.positions(&TRI);
    let j = b.acc(&[0, 1, 0, 0].repeat(3), 5121, 3, "VEC4", false);
    let w = b.f32s(&[3e38, 3e38, 0.0, 0.0].repeat(3), 3, "VEC4");
    let doc = json!({
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [{"translation": [0.0, 5.0, 0.0]}, {"translation": [1.0, 5.0, 0.0]}, {"mesh": 0, "skin": 0}],
        "skins": [{"joints": [0, 1]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos, "JOINTS_0": j, "WEIGHTS_0": w}}]}]
    });
    let (m, warn) =
        gltf_from_bytes_with_warnings(&b.finish(doc), Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.positions, [[0.5, 5.0, 0.0], [1.5, 5.0, 0.0], [0.5, 6.0, 0.0]], "{warn:?}");
    // Weights that do not sum to 1 are normalised with a note (issue 26).
    assert_eq!(warn.len(), 1, "{warn:?}");
    assert!(warn[0].contains("the skin weights of 3 vertices do not sum to 1"), "{warn:?}");
}

// ---------------------------------------------------------------------------------------------
// Messages: shortest digits, escaped control characters.

#[test]
fn messages_print_numbers_with_their_shortest_digits() {
    let cases = [
        (
            "[area_light]\nposition = [0, 0, 0]\nsize = 1e-5\ntarget = [0, 0, 3e-6]\n",
            "`size` (1e-5) must be less than the distance from `position` to `target` (3e-6)",
        ),
        ("[camera]\nup = [1e-30, 0, 0]\n", "length 1e-30, at least 1e-6"),
        ("[camera]\nposition = [0, 0, 0]\ntarget = [0, 0, 1e-7]\n", "`target` is only 1e-7 from `position`"),
        (
            "[[material]]\nname = \"m\"\nmodel = \"toon\"\nramp = [[1.0000001, 1, 1, 1]]\n",
            "must be in [-1, 1] (m = N·L), got 1.0000001",
        ),
        (
            "[[material]]\nname = \"m\"\nmodel = \"toon\"\nramp = [[0.5, 1, 1, 1], [1e-7, 1, 1, 1]]\n",
            "row 2 has 1e-7 after 0.5",
        ),
        ("[[material]]\nname = \"m\"\nmodel = \"toon\"\nramp = [[0, 3e38, 1, 1]]\n", "must be in [0, 1e6], got 3e38"),
        (
            "[[material]]\nname = \"m\"\nmodel = \"toon\"\nramp = [[0, 1, 1, 1]]\nramp_smoothing = 2.0000002\n",
            "must be in [0, 2], got 2.0000002",
        ),
    ];
    for (text, want) in cases {
        let msg = err(text).to_string();
        assert!(msg.contains(want), "want `{want}` in: {msg}");
        assert!(!msg.contains("0.0000") && !msg.contains("00000000"), "{msg}");
    }
}

#[test]
fn control_bytes_in_paths_are_escaped_in_messages() {
    let d = tmp_dir("ctl");
    // A texture path with a NUL, a newline and an escape sequence (TOML escapes them).
    let scene = "[[material]]\nname = \"m\"\nbase_texture = \"a\\u0000b\\nc\\u001b[31m.png\"\n";
    std::fs::write(d.join("s.toml"), scene).unwrap();
    let msg = load_err(&d.join("s.toml")).to_string();
    assert!(msg.contains("a\\0b\\nc\\u{1b}[31m.png"), "{msg}");
    assert!(!msg.contains('\0') && !msg.contains('\n') && !msg.contains('\u{1b}'), "{msg:?}");
    // A scene file whose own name holds a newline and an escape; and a glTF buffer URI with them.
    let odd = d.join("odd\nname\u{1b}.toml");
    std::fs::write(&odd, "[camera]\nfov = 500\n").unwrap();
    let msg = load_err(&odd).to_string();
    assert!(msg.contains("odd\\nname\\u{1b}.toml:2:7"), "{msg}");
    let doc = r#"{"asset":{"version":"2.0"},"buffers":[{"byteLength":4,"uri":"x\u0000\n\u001b.bin"}],
                  "scenes":[{"nodes":[]}]}"#;
    std::fs::write(d.join("m.gltf"), doc).unwrap();
    std::fs::write(d.join("s.toml"), "[[object]]\nname = \"o\"\nkind = \"gltf\"\npath = \"m.gltf\"\n")
        .unwrap();
    let msg = load_err(&d.join("s.toml")).to_string();
    assert!(msg.contains("x\\0\\n\\u{1b}.bin"), "{msg}");
    assert!(!msg.contains('\0') && !msg.contains('\n') && !msg.contains('\u{1b}'), "{msg:?}");
    std::fs::remove_dir_all(&d).ok();
}

// ---------------------------------------------------------------------------------------------
// Loops over counts from the file: each bounded by a documented limit, or linear.

/// `n` boxes named `o0`, `o1`, … (a few bytes of TOML each).
fn boxes(n: usize) -> String {
    (0..n).map(|i| format!("[[object]]\nname = \"o{i}\"\nkind = \"box\"\n")).collect()
}

fn names(range: std::ops::Range<usize>) -> String {
    range.map(|i| format!("\"o{i}\"")).collect::<Vec<_>>().join(", ")
}

#[test]
fn material_slots_of_all_objects_are_bounded() {
    let n = hadou_scene::MAX_MATERIAL_SLOTS as usize;
    let s = Scene::parse(&boxes(n), Path::new("x.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.object_names().len(), n);
    let e = err(&boxes(n + 1));
    assert_eq!(at(&e), (3 * n + 3, 1), "{e}");
    assert!(
        e.to_string()
            .contains(&format!("[[object]] \"o{n}\" brings the scene past the limit of {n} material slots")),
        "{e}"
    );
    // A glTF file with more materials than a scene can hold is refused before they are read.
    let mut b = Builder::default();
    let pos = b.positions(&TRI);
    let doc = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
                     "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}],
                     "materials": vec![json!({}); n]});
    let e = gltf_from_bytes(&b.finish(doc), Path::new(".")).unwrap_err();
    assert!(
        e.contains(&format!("it has {n} materials")) && e.contains(&format!("limit of {n} material slots")),
        "{e}"
    );
}

#[test]
fn shadow_casters_are_bounded() {
    let n = hadou_scene::MAX_SHADOW_CASTERS;
    let sun = |k: usize, range: std::ops::Range<usize>| {
        format!(
            "[[shadow]]\nname = \"s{k}\"\nkind = \"sun\"\nmethod = \"plane\"\nplane_point = [0, 0, 0]\n\
             plane_normal = [0, 1, 0]\ncasters = [{}]\nreceivers = [\"o0\"]\n",
            names(range)
        )
    };
    let ok = format!("{}{}{}", boxes(n + 1), sun(0, 1..n / 2 + 1), sun(1, n / 2 + 1..n + 1));
    Scene::parse(&ok, Path::new("x.toml")).unwrap_or_else(|e| panic!("{e}"));
    let e = err(&format!("{}{}{}", boxes(n + 1), sun(0, 1..n / 2 + 1), sun(1, n / 2..n + 1)));
    let msg = e.to_string();
    assert!(
        msg.contains(&format!("casters of all shadows to {}", n + 1))
            && msg.contains(&format!("at most {n} casters")),
        "{msg}"
    );
    // The triangles the shadows cast: a dense sphere cast by many shadows.
    let sphere = "[[object]]\nname = \"ball\"\nkind = \"sphere\"\nsegments = 1024\n";
    let per = 2 * 1024 * 511u64;
    let k = (hadou_scene::MAX_SHADOW_TRIANGLES / per + 1) as usize;
    let shadows: String = (0..k)
        .map(|i| {
            format!(
                "[[shadow]]\nname = \"s{i}\"\nkind = \"sun\"\nplane_point = [0, 0, 0]\nplane_normal = [0, 1, 0]\n\
                 casters = \"ball\"\nreceivers = \"o0\"\n"
            )
        })
        .collect();
    if k <= hadou_scene::MAX_SHADOWS {
        let msg = err(&format!("{}{sphere}{shadows}", boxes(1))).to_string();
        assert!(msg.contains(&format!("triangles they cast to {}", k as u64 * per)), "{msg}");
    }
}

#[test]
fn shadow_lists_and_track_targets_resolve_by_name_in_linear_time() {
    // 60 000 objects, one shadow receiving on all of them and 60 000 tracks: a scan per name
    // would compare 3.6·10⁹ names.
    let n = 60_000;
    let mut text = boxes(n);
    text.push_str(&format!(
        "[[shadow]]\nname = \"s\"\nkind = \"sun\"\nmethod = \"map\"\ncasters = [\"o1\"]\nreceivers = [{}]\n",
        (0..n).rev().map(|i| format!("\"o{i}\"")).collect::<Vec<_>>().join(", ")
    ));
    for i in 0..n {
        text.push_str(&format!(
            "[[track]]\ntarget = \"object.o{i}.position\"\nkeys = [[0, [0, 0, 0]], [1, [0, {i}, 0]]]\n"
        ));
    }
    let start = std::time::Instant::now();
    let s = Scene::parse(&text, Path::new("x.toml")).unwrap_or_else(|e| panic!("{e}"));
    let f = s.at(0.5);
    assert!(f.shadows[0].receives(0) && f.shadows[0].receives(n as u32 - 1));
    assert!(f.shadows[0].receivers.windows(2).all(|w| w[0] < w[1]));
    assert!(start.elapsed() < std::time::Duration::from_secs(30), "{:?}", start.elapsed());
}

#[test]
fn key_time_checks_are_bounded() {
    // A 512-point B-spline (the most a B-spline may have) animated at 70 000 key times would
    // validate its ~1030 numbers 70 000 times.
    let pts: Vec<String> = (0..512).map(|i| format!("[{i}, 0]")).collect();
    let wave = format!(
        "[[wave]]\nname = \"w\"\nkind = \"bspline\"\nO = [0, 0, 0]\nD = [1, 0, 0]\nalpha = 1\npoints = [{}]\n",
        pts.join(", ")
    );
    let keys = |n: usize| (0..n).map(|i| format!("[{i}, {}]", i % 7)).collect::<Vec<_>>().join(", ");
    let text = format!("{wave}[[track]]\ntarget = \"wave.w.points[3][1]\"\nkeys = [{}]\n", keys(70_000));
    let e = err(&text);
    assert!(matches!(e, SceneError::Track { .. }), "{e:?}");
    assert!(
        e.to_string().contains(&format!("limit of {} (key times × numbers)", hadou_scene::MAX_KEY_CHECKS)),
        "{e}"
    );
    // The same curve at 1000 key times, and 100 000 camera keys, are checked.
    let text = format!("{wave}[[track]]\ntarget = \"wave.w.points[3][1]\"\nkeys = [{}]\n", keys(1000));
    Scene::parse(&text, Path::new("x.toml")).unwrap_or_else(|e| panic!("{e}"));
    let cam = (0..100_000).map(|i| format!("[{i}, {}]", 30 + i % 20)).collect::<Vec<_>>().join(", ");
    Scene::parse(&format!("[[track]]\ntarget = \"camera.fov\"\nkeys = [{cam}]\n"), Path::new("x.toml"))
        .unwrap_or_else(|e| panic!("{e}"));
    // Tracks no rule reads (objects, materials) cost no checks however many keys they have.
    let keys: String =
        (0..200_000).map(|i| format!("[{i}, [0, {}, 0]]", i % 5)).collect::<Vec<_>>().join(", ");
    let text = format!("{}[[track]]\ntarget = \"object.o0.position\"\nkeys = [{keys}]\n", boxes(2000));
    Scene::parse(&text, Path::new("x.toml")).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn area_light_rules_follow_its_target_object_keys() {
    // The light's target object moves onto the light at t = 2: an error at that key.
    let text = format!(
        "{}[area_light]\nposition = [0, 5, 0]\nsize = 0.5\ntarget = \"o1\"\n\
         [[track]]\ntarget = \"object.o1.position\"\nkeys = [[0, [0, 0, 0]], [2, [0, 4.8, 0]]]\n",
        boxes(2)
    );
    let e = err(&text);
    assert_eq!(at(&e), (13, 25), "{e}");
    assert!(
        e.to_string().contains("at t = 2 s (this key of `object.o1.position`)")
            && e.to_string().contains("`size` (0.5)"),
        "{e}"
    );
}

#[test]
fn did_you_mean_hints_are_bounded() {
    // A long unknown name among 60 000 objects: no suggestion work over the whole list, and at
    // most 40 names listed.
    let n = 60_000;
    let long = "q".repeat(100_000);
    let text = format!(
        "{}[[shadow]]\nname = \"s\"\nkind = \"sun\"\nmethod = \"map\"\ncasters = [\"{long}\"]\nreceivers = [\"o0\"]\n",
        boxes(n)
    );
    let msg = err(&text).to_string();
    assert!(msg.contains(&format!(", … ({n} in all)")), "{}", &msg[msg.len() - 300..]);
    assert!(msg.len() < long.len() + 2000, "{}", msg.len());
    let text = format!(
        "{}[[shadow]]\nname = \"s\"\nkind = \"sun\"\nmethod = \"map\"\ncasters = [\"o1x\"]\nreceivers = [\"o0\"]\n",
        boxes(20)
    );
    assert!(err(&text).to_string().contains("did you mean `o1`?"));
}

#[test]
fn gltf_scene_roots_are_checked_in_linear_time() {
    // 200 000 roots: checking each against those before it would take 2·10¹⁰ steps.
    let n = 200_000;
    let doc = json!({"asset": {"version": "2.0"}, "scenes": [{"nodes": (0..n).collect::<Vec<_>>()}],
                     "nodes": vec![json!({}); n]});
    let start = std::time::Instant::now();
    let e = gltf_from_bytes(&serde_json::to_vec(&doc).unwrap(), Path::new(".")).unwrap_err();
    assert!(e.contains("no triangles"), "{e}");
    assert!(start.elapsed() < std::time::Duration::from_secs(20), "{:?}", start.elapsed());
    let mut roots: Vec<usize> = (0..n).collect();
    roots.push(17);
    let doc = json!({"asset": {"version": "2.0"}, "scenes": [{"nodes": roots}], "nodes": vec![json!({}); n]});
    let e = gltf_from_bytes(&serde_json::to_vec(&doc).unwrap(), Path::new(".")).unwrap_err();
    assert!(e.contains("lists node 17 twice"), "{e}");
}

#[test]
fn dense_spheres_past_the_triangle_limit_are_refused_before_they_are_built() {
    // Ten spheres of 1024 segments (10.5 M triangles) once needed more than 4 GB to render a
    // 32×24 image; two fill the scene's triangle limit, the third is refused from its size.
    let sphere = |i: usize| format!("[[object]]\nname = \"s{i}\"\nkind = \"sphere\"\nsegments = 1024\n");
    let two: String = (0..2).map(sphere).collect();
    Scene::parse(&two, Path::new("x.toml")).unwrap_or_else(|e| panic!("{e}"));
    let ten: String = (0..10).map(sphere).collect();
    let e = err(&ten);
    assert_eq!(at(&e), (11, 1), "{e}");
    let msg = e.to_string();
    assert!(msg.contains("[[object]] \"s2\" (1046528 triangles, 525825 vertices)"), "{msg}");
    assert!(msg.contains(&format!("limit of {} triangles", hadou_scene::MAX_TRIANGLES)), "{msg}");
}

#[test]
fn gltf_json_structure_is_bounded_before_it_is_parsed() {
    // 9 MB of empty nodes once took 1.2 GB to parse; past 2²⁰ objects the file is refused from a
    // lexical count, before either JSON tree exists.
    let n = hadou_scene::GLTF_MAX_JSON_OBJECTS as usize;
    let doc = |nodes: usize| {
        format!("{{\"asset\":{{\"version\":\"2.0\"}},\"nodes\":[{}]}}", vec!["{}"; nodes].join(","))
    };
    let e = gltf_from_bytes(doc(n).as_bytes(), Path::new(".")).unwrap_err();
    // The document and its `asset` are objects too.
    assert!(
        e.contains(&format!("holds {} objects", n + 2)) && e.contains(&format!("at most {n} objects")),
        "{e}"
    );
    let e = gltf_from_bytes(doc(n - 2).as_bytes(), Path::new(".")).unwrap_err();
    assert!(!e.contains("objects"), "{e}");
    // Values: a scene listing 2²² roots; braces and commas inside strings do not count.
    let v = hadou_scene::GLTF_MAX_JSON_VALUES as usize;
    let many = format!(
        "{{\"asset\":{{\"version\":\"2.0\"}},\"scenes\":[{{\"nodes\":[{}]}}]}}",
        vec!["0"; v].join(",")
    );
    let e = gltf_from_bytes(many.as_bytes(), Path::new(".")).unwrap_err();
    assert!(e.contains(&format!("at most {n} objects and {v} values")), "{e}");
    let quoted =
        format!("{{\"asset\":{{\"version\":\"2.0\",\"generator\":\"{}\\\"{{\"}}}}", "{[,:".repeat(v));
    let e = gltf_from_bytes(quoted.as_bytes(), Path::new(".")).unwrap_err();
    assert!(!e.contains("values fit"), "{e}");
}

#[test]
fn limits_in_the_docs_match_the_code() {
    // docs/scene-format.md writes numbers of five digits or more in groups of three.
    let grouped = |n: u64| {
        let s = n.to_string();
        if s.len() <= 4 {
            return s;
        }
        let mut out = String::new();
        for (i, c) in s.chars().enumerate() {
            if i > 0 && (s.len() - i).is_multiple_of(3) {
                out.push(' ');
            }
            out.push(c);
        }
        out
    };
    let doc =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/scene-format.md")).unwrap();
    let limits = &doc[doc.find("## Limits").unwrap()..doc.find("## Paths").unwrap()];
    for (what, n) in [
        ("MAX_TRIANGLES", hadou_scene::MAX_TRIANGLES),
        ("MAX_VERTICES", hadou_scene::MAX_VERTICES),
        ("MAX_MATERIAL_SLOTS", hadou_scene::MAX_MATERIAL_SLOTS),
        ("MAX_SCENE_TEXELS", MAX_SCENE_TEXELS),
        ("MAX_SKIN_JOINTS", MAX_SKIN_JOINTS),
        ("MAX_SKINNED_NODES", MAX_SKINNED_NODES),
        ("MAX_KEY_CHECKS", hadou_scene::MAX_KEY_CHECKS),
        ("MAX_SHADOW_CASTERS", hadou_scene::MAX_SHADOW_CASTERS as u64),
        ("GLTF_MAX_JSON_OBJECTS", hadou_scene::GLTF_MAX_JSON_OBJECTS),
        ("GLTF_MAX_JSON_VALUES", hadou_scene::GLTF_MAX_JSON_VALUES),
    ] {
        assert!(limits.contains(&grouped(n)), "{what} = {n} ({}) is not in the Limits section", grouped(n));
    }
    assert_eq!(hadou_scene::MAX_SHADOW_TRIANGLES, hadou_scene::MAX_TRIANGLES);
    assert_eq!(hadou_scene::GLTF_MAX_JSON_BYTES, 256 << 20);
    assert!(limits.contains("| 256 MiB, at most"));
}
