//! glTF materials, textures, texture coordinates, vertex colours, skins at rest pose, required
//! extensions, and hostile image data. Every file is built here in memory (JSON with a base64
//! data-URI buffer).

mod common;

use common::gltf::Builder;
use common::png_header_only;

use hadou_scene::{encode_png, gltf_from_bytes, gltf_from_bytes_with_warnings, Mesh, RampKind, ShadingModel};
use hadou_scene::{Filter, Wrap};
use serde_json::{json, Value};
use std::path::Path;

const TRI: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

fn load(bytes: &[u8]) -> (Mesh, Vec<String>) {
    gltf_from_bytes_with_warnings(bytes, Path::new(".")).unwrap_or_else(|e| panic!("{e}"))
}

fn load_err(bytes: &[u8]) -> String {
    match gltf_from_bytes(bytes, Path::new(".")) {
        Ok(_) => panic!("loaded a file that should be refused"),
        Err(e) => e,
    }
}

fn close(a: &[f32], b: &[f32], tol: f32) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
}

/// One triangle per material entry in `prims` (`None` = no material), each its own mesh node.
fn doc_with_prims(b: &mut Builder, prims: &[(Option<usize>, Value)]) -> Value {
    let mut meshes = Vec::new();
    for (m, extra_attrs) in prims {
        let pos = b.positions(&TRI);
        let mut attrs = json!({"POSITION": pos});
        for (k, v) in extra_attrs.as_object().into_iter().flatten() {
            attrs[k] = v.clone();
        }
        let mut p = json!({"attributes": attrs});
        if let Some(m) = m {
            p["material"] = json!(m);
        }
        meshes.push(json!({"primitives": [p]}));
    }
    let nodes: Vec<Value> = (0..prims.len()).map(|i| json!({"mesh": i})).collect();
    json!({"scene": 0, "scenes": [{"nodes": (0..prims.len()).collect::<Vec<_>>()}], "nodes": nodes, "meshes": meshes})
}

fn png_2x2() -> Vec<u8> {
    encode_png(2, 2, &[[255, 0, 0, 255], [0, 255, 0, 255], [0, 0, 255, 255], [255, 255, 255, 255]])
}

#[test]
fn materials_in_order_with_factors_and_a_default_slot() {
    let mut b = Builder::default();
    let mut doc = doc_with_prims(&mut b, &[(Some(0), json!({})), (None, json!({})), (Some(1), json!({}))]);
    doc["materials"] = json!([
        {"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.0, 0.0, 1.0]}},
        {}
    ]);
    let (m, warn) = load(&b.finish(doc));
    assert!(warn.is_empty(), "{warn:?}");
    assert_eq!(m.materials.len(), 3);
    assert_eq!(m.materials[0].name, "red");
    assert_eq!(m.materials[0].base_color, [1.0, 0.0, 0.0]);
    assert_eq!(m.materials[0].model, ShadingModel::Diffuse);
    assert_eq!(m.materials[1].name, "material 1");
    assert_eq!(m.materials[1].base_color, [1.0; 3]);
    assert_eq!(m.materials[2].base_color, [1.0; 3]);
    assert!(m
        .materials
        .iter()
        .all(|x| x.wave_blend == 0.0 && x.outline.is_none() && x.base_texture.is_none()));
    assert_eq!(m.material_ids, vec![0, 0, 0, 2, 2, 2, 1, 1, 1]);
    assert!(m.uvs.is_empty() && m.colors.is_empty());
}

#[test]
fn textures_samplers_and_shared_images() {
    let mut b = Builder::default();
    let uv = b.f32s(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0], 3, "VEC2");
    let mut doc =
        doc_with_prims(&mut b, &[(Some(0), json!({"TEXCOORD_0": uv})), (Some(1), json!({"TEXCOORD_0": uv}))]);
    let img = b.view(&png_2x2());
    doc["images"] = json!([{"bufferView": img, "mimeType": "image/png"}]);
    doc["samplers"] = json!([{"wrapS": 33071, "wrapT": 33648, "magFilter": 9728}]);
    doc["textures"] = json!([{"source": 0, "sampler": 0}, {"source": 0}]);
    doc["materials"] = json!([
        {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}},
        {"pbrMetallicRoughness": {"baseColorTexture": {"index": 1}},
         "extras": {"hadou": {"featureTexture": {"index": 0}}}}
    ]);
    let (m, warn) = load(&b.finish(doc));
    assert!(warn.is_empty(), "{warn:?}");
    let t0 = m.materials[0].base_texture.as_ref().unwrap();
    assert_eq!(t0.wrap, [Wrap::Clamp, Wrap::Mirror]);
    assert_eq!(t0.filter, Filter::Nearest);
    assert_eq!((t0.image.width, t0.image.height), (2, 2));
    assert_eq!(t0.image.texels[1], [0, 255, 0, 255]);
    let t1 = m.materials[1].base_texture.as_ref().unwrap();
    assert_eq!(t1.wrap, [Wrap::Repeat, Wrap::Repeat]);
    assert_eq!(t1.filter, Filter::Linear);
    let f1 = m.materials[1].feature_texture.as_ref().unwrap();
    assert_eq!(f1.filter, Filter::Nearest);
    // One decode, shared.
    assert!(std::sync::Arc::ptr_eq(&t0.image, &t1.image) && std::sync::Arc::ptr_eq(&t0.image, &f1.image));
    assert_eq!(m.uvs.len(), 6);
    assert_eq!(m.uvs[1], [1.0, 0.0]);
}

#[test]
fn unlit_is_accepted_even_when_required() {
    let mut b = Builder::default();
    let mut doc = doc_with_prims(&mut b, &[(Some(0), json!({}))]);
    doc["extensionsUsed"] = json!(["KHR_materials_unlit", "EXT_something_unknown"]);
    doc["extensionsRequired"] = json!(["KHR_materials_unlit"]);
    doc["materials"] = json!([{"extensions": {"KHR_materials_unlit": {}}}]);
    let (m, _) = load(&b.finish(doc));
    assert_eq!(m.materials[0].model, ShadingModel::Unlit);
}

#[test]
fn mtoon_becomes_a_two_band_toon_ramp() {
    let mut b = Builder::default();
    let mut doc = doc_with_prims(&mut b, &[(Some(0), json!({})), (Some(1), json!({}))]);
    doc["extensionsRequired"] = json!(["VRMC_materials_mtoon"]);
    let img = b.view(&png_2x2());
    doc["images"] = json!([{"bufferView": img}]);
    doc["textures"] = json!([{"source": 0}]);
    doc["materials"] = json!([
        {"name": "cel", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 0.0, 1.0]},
         "extensions": {"VRMC_materials_mtoon": {"specVersion": "1.0", "shadeColorFactor": [0.25, 0.5, 0.3],
             "shadingShiftFactor": 0.2, "shadingToonyFactor": 0.7, "shadeMultiplyTexture": {"index": 0}}}},
        {"name": "defaults", "extensions": {"VRMC_materials_mtoon": {"specVersion": "1.0"}}}
    ]);
    let (m, warn) = load(&b.finish(doc));
    let cel = &m.materials[0];
    assert_eq!(cel.model, ShadingModel::Toon);
    let RampKind::Bands { smoothing } = cel.ramp.kind else { panic!("{:?}", cel.ramp) };
    assert!((smoothing - 0.6).abs() < 1e-6, "{smoothing}");
    assert!(close(&cel.ramp.stops[0].1, &[0.5, 2.0, 1.0], 1e-6), "{:?}", cel.ramp);
    assert!((cel.ramp.stops[1].0 + 0.2).abs() < 1e-6, "{:?}", cel.ramp);
    assert_eq!(cel.ramp.stops[1].1, [1.0; 3]);
    assert!(!warn.iter().any(|w| w.contains("shadeMultiplyTexture")), "{warn:?}");
    assert!(cel.mtoon.as_ref().is_some_and(|t| t.shade_texture.is_some()));
    // Spec defaults: shift 0, toony 0.9, black shade on a white base.
    let d = &m.materials[1];
    let RampKind::Bands { smoothing } = d.ramp.kind else { panic!() };
    assert!((smoothing - 0.2).abs() < 1e-6 && d.ramp.stops[1].0 == 0.0 && d.ramp.stops[0].1 == [0.0; 3]);
}

#[test]
fn vertex_colours_and_normalized_uvs() {
    let mut b = Builder::default();
    let c8 = b.acc(&[255, 0, 0, 255, 0, 255, 0, 51, 0, 0, 255, 0], 5121, 3, "VEC4", true);
    let c3 = b.f32s(&[0.5, 0.5, 0.5, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0], 3, "VEC3");
    let uv16: Vec<u8> = [0u16, 65535, 65535, 32768, 0, 0].iter().flat_map(|v| v.to_le_bytes()).collect();
    let uv = b.acc(&uv16, 5123, 3, "VEC2", true);
    let doc = doc_with_prims(
        &mut b,
        &[
            (None, json!({"COLOR_0": c8, "TEXCOORD_0": uv})),
            (None, json!({"COLOR_0": c3})),
            (None, json!({})),
        ],
    );
    let (m, _) = load(&b.finish(doc));
    assert_eq!(m.colors.len(), 9);
    assert!(close(&m.colors[1], &[0.0, 1.0, 0.0, 0.2], 1e-6), "{:?}", m.colors);
    assert!(close(&m.colors[3], &[0.5, 0.5, 0.5, 1.0], 1e-6), "{:?}", m.colors);
    assert_eq!(m.colors[8], [1.0; 4]);
    assert_eq!(m.uvs.len(), 9);
    assert!(close(&m.uvs[0], &[0.0, 1.0], 1e-6) && close(&m.uvs[1], &[1.0, 32768.0 / 65535.0], 1e-6));
    assert_eq!(m.uvs[5], [0.0, 0.0]);
}

#[test]
fn missing_texcoords_warn_and_other_sets_are_used() {
    let mut b = Builder::default();
    let uv0 = b.f32s(&[0.0; 6], 3, "VEC2");
    let uv1 = b.f32s(&[0.25, 0.75, 0.5, 0.5, 1.0, 1.0], 3, "VEC2");
    let mut doc = doc_with_prims(
        &mut b,
        &[(Some(0), json!({})), (Some(1), json!({"TEXCOORD_0": uv0, "TEXCOORD_1": uv1}))],
    );
    let img = b.view(&png_2x2());
    doc["images"] = json!([{"bufferView": img}]);
    doc["textures"] = json!([{"source": 0}]);
    doc["materials"] = json!([
        {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}},
        {"name": "two sets", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1}},
         "extras": {"hadou": {"featureTexture": {"index": 0}}}}
    ]);
    let (m, warn) = load(&b.finish(doc));
    assert!(warn.iter().any(|w| w.contains("mesh 0 primitive 0 has no TEXCOORD_0")), "{warn:?}");
    assert!(
        warn.iter().any(|w| w.contains("`two sets`") && w.contains("different TEXCOORD sets")),
        "{warn:?}"
    );
    assert_eq!(&m.uvs[..3], &[[0.0; 2]; 3]);
    assert_eq!(m.uvs[3..], [[0.25, 0.75], [0.5, 0.5], [1.0, 1.0]]);
}

/// Column-major translation matrix.
fn translation(t: [f32; 3]) -> [f32; 16] {
    [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, t[0], t[1], t[2], 1.0]
}

/// Joint 0 at (0, 1, 0); joint 1 its child at (1, 0, 0) turned 90° about z at rest (bound
/// unturned); the skinned mesh's node has a translation the skin must ignore.
fn skinned(joints: &[u8], weights: &[f32]) -> Vec<u8> {
    let mut b = Builder::default();
    let pos = b.positions(&[[0.0, 1.0, 0.0], [2.0, 1.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 0.0]]);
    let nrm = b.positions(&[[0.0, 0.0, 1.0]; 4]);
    let j = b.acc(joints, 5121, 4, "VEC4", false);
    let w = b.f32s(weights, 4, "VEC4");
    let idx = b.acc(&[0, 1, 2, 0, 2, 3, 0, 0], 5121, 6, "SCALAR", false);
    let ibm: Vec<f32> = [translation([0.0, -1.0, 0.0]), translation([-1.0, -1.0, 0.0])].concat();
    let ibm = b.f32s(&ibm, 2, "MAT4");
    let h = std::f32::consts::FRAC_1_SQRT_2;
    let doc = json!({
        "scene": 0,
        "scenes": [{"nodes": [0, 2]}],
        "nodes": [
            {"translation": [0.0, 1.0, 0.0], "children": [1]},
            {"translation": [1.0, 0.0, 0.0], "rotation": [0.0, 0.0, h, h]},
            {"mesh": 0, "skin": 0, "translation": [100.0, 0.0, 0.0]}
        ],
        "skins": [{"joints": [0, 1], "inverseBindMatrices": ibm}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm, "JOINTS_0": j, "WEIGHTS_0": w},
                                    "indices": idx}]}]
    });
    b.finish(doc)
}

#[test]
fn skins_place_vertices_at_the_rest_pose() {
    let joints = [0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0];
    let weights = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let (m, warn) = load(&skinned(&joints, &weights));
    // Joint 0 only: J0·IBM0 = identity. Joint 1: T(1,1,0)·Rz90·T(−1,−1,0) takes (2,1,0) to (1,2,0):
    // the vertex follows its (turned) joint. Half and half: (1.5, 1.5, 0). All-zero weights: the
    // node's own transform.
    let want = [[0.0, 1.0, 0.0], [1.0, 2.0, 0.0], [1.5, 1.5, 0.0], [100.0, 0.0, 0.0]];
    for (p, w) in m.positions.iter().zip(want) {
        assert!(close(p, &w, 1e-5), "{:?}", m.positions);
    }
    assert!(m.normals.iter().all(|n| close(n, &[0.0, 0.0, 1.0], 1e-5)), "{:?}", m.normals);
    assert!(warn.iter().any(|w| w.contains("1 vertices have all-zero skin weights")), "{warn:?}");

    let bad = [0, 0, 0, 0, 5, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0];
    let e = load_err(&skinned(&bad, &weights));
    assert!(e.contains("bound to joint 5") && e.contains("2 joints"), "{e}");
}

#[test]
fn unsupported_required_extensions_are_refused_by_name() {
    let mut b = Builder::default();
    let mut doc = doc_with_prims(&mut b, &[(None, json!({}))]);
    doc["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    let e = load_err(&b.finish(doc));
    assert!(
        e.contains("requires the glTF extension `KHR_draco_mesh_compression`, which hadou does not support"),
        "{e}"
    );
}

/// A textured file whose image 0 is `image` (a JSON object), `bytes` put in a bufferView first.
fn with_image(bytes: &[u8], image: impl FnOnce(usize) -> Value) -> Vec<u8> {
    let mut b = Builder::default();
    let mut doc = doc_with_prims(&mut b, &[(Some(0), json!({}))]);
    let v = b.view(bytes);
    doc["images"] = json!([image(v)]);
    doc["textures"] = json!([{"source": 0}]);
    doc["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
    b.finish(doc)
}

/// A baseline 8×8 grey JPEG: one component, DC and AC Huffman tables of one code each, every
/// coefficient 0 (so every texel is 128).
fn tiny_jpeg(w: u16, h: u16) -> Vec<u8> {
    let mut j = vec![0xFF, 0xD8];
    j.extend_from_slice(&[0xFF, 0xDB, 0, 67, 0]);
    j.extend_from_slice(&[1; 64]);
    j.extend_from_slice(&[0xFF, 0xC0, 0, 11, 8]);
    j.extend_from_slice(&h.to_be_bytes());
    j.extend_from_slice(&w.to_be_bytes());
    j.extend_from_slice(&[1, 1, 0x11, 0]);
    for class in [0x00, 0x10] {
        j.extend_from_slice(&[0xFF, 0xC4, 0, 20, class, 1]);
        j.extend_from_slice(&[0; 15]);
        j.push(0);
    }
    j.extend_from_slice(&[0xFF, 0xDA, 0, 8, 1, 1, 0x00, 0, 63, 0]);
    // DC "0" (category 0), AC "0" (EOB) per block, padded with ones.
    let blocks = (w as usize).div_ceil(8) * (h as usize).div_ceil(8);
    let bits = 2 * blocks;
    let mut data = vec![0u8; bits.div_ceil(8)];
    let pad = data.len() * 8 - bits;
    if let Some(last) = data.last_mut() {
        *last |= ((1u16 << pad) - 1) as u8;
    }
    j.extend_from_slice(&data);
    j.extend_from_slice(&[0xFF, 0xD9]);
    j
}

#[test]
fn jpeg_images_decode() {
    let (m, _) = load(&with_image(&tiny_jpeg(8, 8), |v| json!({"bufferView": v, "mimeType": "image/jpeg"})));
    let t = &m.materials[0].base_texture.as_ref().unwrap().image;
    assert_eq!((t.width, t.height), (8, 8));
    assert!(
        t.texels.iter().all(|p| p[0].abs_diff(128) <= 1 && p[0] == p[1] && p[1] == p[2] && p[3] == 255),
        "{t:?}"
    );
}

#[test]
fn hostile_images_are_clear_errors() {
    // Texture → image index out of range.
    let mut b = Builder::default();
    let mut doc = doc_with_prims(&mut b, &[(Some(0), json!({}))]);
    doc["textures"] = json!([{"source": 5}]);
    doc["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
    let e = load_err(&b.finish(doc));
    assert!(e.contains("texture 0 refers to image 5"), "{e}");

    // Feature texture index out of range.
    let mut b = Builder::default();
    let mut doc = doc_with_prims(&mut b, &[(Some(0), json!({}))]);
    doc["materials"] = json!([{"extras": {"hadou": {"featureTexture": {"index": 7}}}}]);
    let e = load_err(&b.finish(doc));
    assert!(e.contains("material 0 (extras.hadou.featureTexture) refers to texture 7"), "{e}");
    let mut b = Builder::default();
    let mut doc = doc_with_prims(&mut b, &[(Some(0), json!({}))]);
    doc["materials"] = json!([{"extras": {"hadou": {"featureTexture": {"index": "zero"}}}}]);
    assert!(load_err(&b.finish(doc)).contains("non-negative integer `index`"));

    // Image bufferView out of range.
    let e = load_err(&with_image(&png_2x2(), |_| json!({"bufferView": 9})));
    assert!(e.contains("image 0 refers to bufferView 9"), "{e}");

    // A PNG header claiming 100000 × 100000 texels: refused from the header.
    let e = load_err(&with_image(&png_header_only(100_000, 100_000), |v| json!({"bufferView": v})));
    assert!(
        e.starts_with("material 0: image 0")
            && e.contains("100000×100000")
            && e.contains("larger than the limit"),
        "{e}"
    );

    // JPEG: garbage after the signature, and a header claiming 60000 × 60000 texels.
    let mut garbage = vec![0xFF, 0xD8, 0xFF];
    garbage.extend((0..200u32).map(|i| (i.wrapping_mul(2654435761) >> 13) as u8));
    let e = load_err(&with_image(&garbage, |v| json!({"bufferView": v})));
    assert!(e.starts_with("material 0: image 0") && e.contains("JPEG"), "{e}");
    let e = load_err(&with_image(&tiny_jpeg(60000, 60000), |v| json!({"bufferView": v})));
    assert!(e.starts_with("material 0: image 0") && e.contains("JPEG"), "{e}");
    // Not an image at all, and a truncated PNG.
    let e = load_err(&with_image(b"GIF89a....", |v| json!({"bufferView": v})));
    assert!(e.contains("image 0") && e.contains("not a PNG or JPEG"), "{e}");
    let png = png_2x2();
    let e = load_err(&with_image(&png[..png.len() - 20], |v| json!({"bufferView": v})));
    assert!(e.contains("image 0"), "{e}");

    // External image paths must stay inside the directory.
    let dir = std::env::temp_dir().join(format!("hadou-gltf-materials-{}", std::process::id()));
    let inner = dir.join("inner");
    std::fs::create_dir_all(&inner).unwrap();
    std::fs::write(dir.join("x.png"), png_2x2()).unwrap();
    std::fs::write(inner.join("ok.png"), png_2x2()).unwrap();
    let file = with_image(&png_2x2(), |_| json!({"uri": "../x.png"}));
    let e = gltf_from_bytes(&file, &inner).unwrap_err();
    assert!(e.starts_with("material 0: image 0") && e.contains("outside"), "{e}");
    let file = with_image(&png_2x2(), |_| json!({"uri": "ok.png"}));
    let m = gltf_from_bytes(&file, &inner).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.materials[0].base_texture.as_ref().unwrap().image.width, 2);
    let file = with_image(&png_2x2(), |_| json!({"uri": "missing.png"}));
    assert!(gltf_from_bytes(&file, &inner).unwrap_err().starts_with("material 0: image 0: cannot read"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn mutated_material_json_never_panics() {
    // Wrong types in every field this loader reads from the raw JSON: errors or defaults, never a
    // panic.
    let cases = [
        json!({"extensions": {"VRMC_materials_mtoon": 3}}),
        json!({"extensions": {"VRMC_materials_mtoon": {"shadeColorFactor": [1]}}}),
        json!({"extensions": {"VRMC_materials_mtoon": {"shadingToonyFactor": "x"}}}),
        json!({"extensions": {"VRMC_materials_mtoon": {"shadeColorFactor": [1e39, 0, 0]}}}),
        json!({"extras": {"hadou": {"featureTexture": {"index": 0, "texCoord": -1}}}}),
        json!({"extras": {"hadou": {"featureTexture": []}}}),
        json!({"extras": {"hadou": 5}}),
        json!({"extras": 5, "name": 7}),
        json!({"extensions": {"KHR_materials_unlit": null}}),
    ];
    for mat in cases {
        let mut b = Builder::default();
        let mut doc = doc_with_prims(&mut b, &[(Some(0), json!({}))]);
        let img = b.view(&png_2x2());
        doc["images"] = json!([{"bufferView": img}]);
        doc["textures"] = json!([{"source": 0}]);
        doc["materials"] = json!([mat]);
        let r = gltf_from_bytes(&b.finish(doc), Path::new("."));
        if let Err(e) = r {
            assert!(!e.contains("parser failed"), "{e}");
        }
    }
}
