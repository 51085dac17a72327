//! MToon materials of VRM files: every field of `VRMC_materials_mtoon` 1.0, VRM 0.x's MToon
//! material properties converted to 1.0, and the located messages of wrong types. Every file is
//! built here in memory.

mod common;

use common::gltf::Builder;
use hadou_scene::{
    check_gltf_materials, encode_png, gltf_from_bytes, gltf_from_bytes_with_warnings, Mesh, OutlineWidthMode,
};
use serde_json::{json, Value};
use std::path::Path;

const TRI: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// One triangle with material 0, three textures of three distinct images, `materials` and the
/// extensions of the file.
fn file(materials: Value, extensions: Value, used: &[&str]) -> Vec<u8> {
    let mut b = Builder::default();
    let pos = b.positions(&TRI);
    let uv = b.f32s(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0], 3, "VEC2");
    let imgs: Vec<Value> = (0..3u8)
        .map(|k| {
            let v = b.view(&encode_png(1, 1, &[[40 * k, 80, 120, 255]]));
            json!({"bufferView": v})
        })
        .collect();
    let doc = json!({
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos, "TEXCOORD_0": uv}, "material": 0}]}],
        "images": imgs,
        "textures": [{"source": 0}, {"source": 1}, {"source": 2}],
        "materials": materials,
        "extensions": extensions,
        "extensionsUsed": used,
    });
    b.finish(doc)
}

fn load(bytes: &[u8]) -> (Mesh, Vec<String>) {
    gltf_from_bytes_with_warnings(bytes, Path::new(".")).unwrap_or_else(|e| panic!("{e}"))
}

fn close(a: &[f32], b: &[f32], tol: f32) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
}

fn srgb(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[test]
fn vrm1_mtoon_reads_every_field() {
    let mt = json!({
        "specVersion": "1.0",
        "shadeColorFactor": [0.2, 0.1, 0.3],
        "shadeMultiplyTexture": {"index": 0},
        "shadingShiftFactor": -0.25,
        "shadingShiftTexture": {"index": 1, "scale": 0.5},
        "shadingToonyFactor": 0.8,
        "giEqualizationFactor": 0.4,
        "matcapFactor": [0.5, 0.6, 0.7],
        "matcapTexture": {"index": 2},
        "parametricRimColorFactor": [1.0, 0.5, 0.0],
        "rimMultiplyTexture": {"index": 0},
        "rimLightingMixFactor": 0.3,
        "parametricRimFresnelPowerFactor": 3.0,
        "parametricRimLiftFactor": 0.1,
        "outlineWidthMode": "screenCoordinates",
        "outlineWidthFactor": 0.004,
        "outlineWidthMultiplyTexture": {"index": 1},
        "outlineColorFactor": [0.1, 0.0, 0.2],
        "outlineLightingMixFactor": 0.6,
        "uvAnimationMaskTexture": {"index": 2},
        "uvAnimationScrollXSpeedFactor": 0.1,
        "uvAnimationScrollYSpeedFactor": -0.2,
        "uvAnimationRotationSpeedFactor": 1.5
    });
    let mats = json!([{"name": "skin", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.8, 0.7, 1.0]},
        "emissiveFactor": [0.05, 0.0, 0.0], "emissiveTexture": {"index": 1},
        "extensions": {"VRMC_materials_mtoon": mt}}]);
    let (m, warn) =
        load(&file(mats, json!({"VRMC_vrm": {"specVersion": "1.0"}}), &["VRMC_vrm", "VRMC_materials_mtoon"]));
    let mat = &m.materials[0];
    let t = mat.mtoon.as_ref().expect("an MToon material");
    assert_eq!(t.shade_color, [0.2, 0.1, 0.3]);
    assert_eq!((t.shading_shift, t.shift_texture_scale, t.toony, t.gi_equalization), (-0.25, 0.5, 0.8, 0.4));
    assert_eq!((t.matcap_color, t.rim_color), ([0.5, 0.6, 0.7], [1.0, 0.5, 0.0]));
    assert_eq!((t.rim_lighting_mix, t.rim_fresnel_power, t.rim_lift), (0.3, 3.0, 0.1));
    assert_eq!(
        (t.outline_mode, t.outline_width, t.outline_color),
        (OutlineWidthMode::Screen, 0.004, [0.1, 0.0, 0.2])
    );
    assert_eq!(t.outline_lighting_mix, 0.6);
    assert_eq!((t.uv_scroll, t.uv_rotation, t.uv_mask_channel), ([0.1, -0.2], 1.5, 2));
    assert_eq!(t.emissive, [0.05, 0.0, 0.0]);
    // Each texture slot holds its own image (the PNGs differ in their red channel).
    let red = |r: &Option<hadou_scene::TextureRef>| r.as_ref().map(|r| r.image.texels[0][0]);
    assert_eq!(red(&t.shade_texture), Some(0));
    assert_eq!(red(&t.shift_texture), Some(40));
    assert_eq!(red(&t.matcap_texture), Some(80));
    assert_eq!(red(&t.rim_texture), Some(0));
    assert_eq!(red(&t.outline_width_texture), Some(40));
    assert_eq!(red(&t.uv_mask_texture), Some(80));
    assert_eq!(red(&t.emissive_texture), Some(40));
    // The fallback ramp for renderers without MToon: the threshold at −shift.
    assert_eq!(mat.model, hadou_scene::ShadingModel::Toon);
    assert!((mat.ramp.stops[1].0 - 0.25).abs() < 1e-6, "{:?}", mat.ramp);
    // The MToon outline turns the material's outline on, in MToon's units (a fraction of the
    // image height here), its width texture scaling it per vertex; nothing warns.
    assert_eq!(mat.outline, Some(hadou_scene::Outline { width: 0.004, color: [0.1, 0.0, 0.2] }));
    assert!(warn.is_empty(), "{warn:?}");
    // Screen mode: 0.004 of the height, at any depth (2·tan(fov/2)·w·|z| along the normal).
    assert!((mat.hull_pixels(7.0, 0.5, 1000) - 4.0).abs() < 1e-4);
    assert!((mat.hull_push(3.0, 0.5) - 0.012).abs() < 1e-7);
    // Lit: colour · mix(1, light + ambient, 0.6) = colour · (1 + 1.5 · 0.6).
    let light = hadou_scene::Light {
        direction: hadou_math::Vec3::new(0.0, -1.0, 0.0),
        color: [2.0; 3],
        ambient: [0.5; 3],
    };
    let c = mat.outline_rgb(&light);
    assert!(close(&c, &[0.1 * 1.9, 0.0, 0.2 * 1.9], 1e-6), "{c:?}");
    // World mode: w world units, w·f/|z| pixels.
    let mut world = mat.clone();
    let mut t = (**mat.mtoon.as_ref().unwrap()).clone();
    t.outline_mode = OutlineWidthMode::World;
    world.mtoon = Some(std::sync::Arc::new(t));
    assert_eq!(world.hull_push(3.0, 0.5), 0.004);
    assert!((world.hull_pixels(2.0, 0.5, 1000) - 0.004 / 2.0 * 1000.0).abs() < 1e-3);
}

#[test]
fn vrm1_mtoon_unknown_keys_and_render_state_warn() {
    let mats = json!([{"extensions": {"VRMC_materials_mtoon": {"specVersion": "1.0", "glitter": 1,
        "transparentWithZWrite": true, "renderQueueOffsetNumber": 2}}}]);
    let (m, warn) = load(&file(mats, json!({}), &["VRMC_materials_mtoon"]));
    assert!(m.materials[0].mtoon.is_some());
    assert!(warn.iter().any(|w| w.contains("`glitter`")), "{warn:?}");
    assert!(warn.iter().any(|w| w.contains("transparentWithZWrite")), "{warn:?}");
    assert!(warn.iter().any(|w| w.contains("renderQueueOffsetNumber")), "{warn:?}");
}

#[test]
fn vrm0_mtoon_properties_are_converted() {
    let mats = json!([{"name": "hair", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0]}}]);
    let vrm = json!({"VRM": {"materialProperties": [{
        "name": "hair", "shader": "VRM/MToon",
        "floatProperties": {"_ShadeShift": 0.0, "_ShadeToony": 0.9, "_RimLightingMix": 0.25,
            "_RimFresnelPower": 2.0, "_RimLift": 0.05, "_OutlineWidthMode": 1.0, "_OutlineWidth": 0.3,
            "_OutlineColorMode": 1.0, "_OutlineLightingMix": 0.7, "_UvAnimScrollX": 0.5,
            "_UvAnimScrollY": 0.25, "_UvAnimRotation": 0.5, "_IndirectLightIntensity": 0.3,
            "_BlendMode": 0.0, "_Sparkle": 1.0},
        "vectorProperties": {"_Color": [0.5, 0.5, 0.5, 1.0], "_ShadeColor": [0.2, 0.4, 0.6, 1.0],
            "_RimColor": [1.0, 0.0, 0.0, 1.0], "_OutlineColor": [0.0, 0.0, 0.5, 1.0],
            "_EmissionColor": [0.1, 0.2, 0.3, 1.0]},
        "textureProperties": {"_MainTex": 0, "_ShadeTexture": 1, "_SphereAdd": 2, "_UvAnimMaskTexture": 1}
    }]}});
    let (m, warn) = load(&file(mats, vrm, &["VRM"]));
    let mat = &m.materials[0];
    let t = mat.mtoon.as_ref().expect("an MToon material");
    assert!(close(&mat.base_color, &[srgb(0.5); 3], 1e-6), "{:?}", mat.base_color);
    assert!(close(&t.shade_color, &[srgb(0.2), srgb(0.4), srgb(0.6)], 1e-6));
    assert!(close(&[t.toony, t.shading_shift], &[0.95, -0.05], 1e-6), "{} {}", t.toony, t.shading_shift);
    assert!((t.gi_equalization - 0.7).abs() < 1e-6);
    assert_eq!(
        (t.rim_color, t.rim_lighting_mix, t.rim_fresnel_power, t.rim_lift),
        ([1.0, 0.0, 0.0], 0.25, 2.0, 0.05)
    );
    assert_eq!(t.outline_mode, OutlineWidthMode::World);
    assert!((t.outline_width - 0.003).abs() < 1e-9);
    assert!(close(&t.outline_color, &[0.0, 0.0, srgb(0.5)], 1e-6));
    assert_eq!(t.outline_lighting_mix, 0.7);
    assert_eq!((t.uv_scroll, t.uv_mask_channel), ([0.5, 0.25], 0));
    assert!((t.uv_rotation - std::f32::consts::PI).abs() < 1e-6);
    assert_eq!(t.emissive, [0.1, 0.2, 0.3]);
    assert_eq!(t.matcap_color, [1.0; 3]);
    // `_MainTex` is the base texture when the glTF material has none.
    assert_eq!(mat.base_texture.as_ref().map(|r| r.image.texels[0][0]), Some(0));
    assert_eq!(t.shade_texture.as_ref().map(|r| r.image.texels[0][0]), Some(40));
    assert_eq!(t.matcap_texture.as_ref().map(|r| r.image.texels[0][0]), Some(80));
    assert!(warn.iter().any(|w| w.contains("`_Sparkle`")), "{warn:?}");
    assert!(!warn.iter().any(|w| w.contains("_BlendMode")), "{warn:?}");
}

#[test]
fn vrm0_other_shaders_stay_plain_materials() {
    let mats = json!([{"pbrMetallicRoughness": {"baseColorFactor": [0.3, 0.3, 0.3, 1.0]}}]);
    let vrm = json!({"VRM": {"materialProperties": [{"shader": "VRM/UnlitTexture"}]}});
    let (m, _) = load(&file(mats, vrm, &["VRM"]));
    assert!(m.materials[0].mtoon.is_none());
    assert_eq!(m.materials[0].model, hadou_scene::ShadingModel::Diffuse);
}

#[test]
fn vrm_extensions_may_be_required() {
    let mats = json!([{}]);
    let mut doc: Value = serde_json::from_slice(&file(mats, json!({}), &["VRMC_vrm", "VRM"])).unwrap();
    doc["extensionsRequired"] = json!(["VRMC_vrm", "VRM"]);
    gltf_from_bytes(&serde_json::to_vec(&doc).unwrap(), Path::new(".")).unwrap();
}

#[test]
fn wrong_types_give_located_messages() {
    let cases: [(Value, Value, &str); 8] = [
        (
            json!({"VRMC_materials_mtoon": {"outlineWidthMode": "thick"}}),
            json!({}),
            "material 0 (VRMC_materials_mtoon).outlineWidthMode must be one of",
        ),
        (
            json!({"VRMC_materials_mtoon": {"rimLightingMixFactor": [1]}}),
            json!({}),
            "material 0 (VRMC_materials_mtoon).rimLightingMixFactor must be a finite number",
        ),
        (
            json!({"VRMC_materials_mtoon": {"matcapTexture": {"index": 9}}}),
            json!({}),
            "material 0 (VRMC_materials_mtoon).matcapTexture refers to texture 9",
        ),
        (
            json!({"VRMC_materials_mtoon": {"shadingShiftTexture": {"index": 0, "scale": "big"}}}),
            json!({}),
            "material 0 (VRMC_materials_mtoon).shadingShiftTexture.scale must be a finite number",
        ),
        (
            json!({"VRMC_materials_mtoon": {"transparentWithZWrite": 1}}),
            json!({}),
            "material 0 (VRMC_materials_mtoon).transparentWithZWrite must be true or false",
        ),
        (
            json!({}),
            json!({"VRM": {"materialProperties": [{"shader": "VRM/MToon", "floatProperties": {"_ShadeToony": "x"}}]}}),
            "material 0 (VRM materialProperties).floatProperties._ShadeToony must be a finite number",
        ),
        (
            json!({}),
            json!({"VRM": {"materialProperties": [{"shader": "VRM/MToon", "vectorProperties": {"_ShadeColor": [1, 2]}}]}}),
            "material 0 (VRM materialProperties).vectorProperties._ShadeColor must be an array",
        ),
        (
            json!({}),
            json!({"VRM": {"materialProperties": [{"shader": "VRM/MToon", "textureProperties": {"_ShadeTexture": 5}}]}}),
            "material 0 (VRM materialProperties).textureProperties._ShadeTexture refers to texture 5",
        ),
    ];
    for (ext, root, want) in cases {
        let bytes = file(json!([{"extensions": ext}]), root, &[]);
        let e = gltf_from_bytes(&bytes, Path::new(".")).unwrap_err();
        assert!(e.contains(want), "{e}\nwanted: {want}");
        // The check another glTF loader runs (hadou-bevy's `.vrm` loader) gives the same message.
        let checked = check_gltf_materials(&bytes).unwrap_err();
        assert!(checked.contains(want), "{checked}\nwanted: {want}");
    }
    // A good MToon material passes the check.
    let good = json!([{"extensions": {"VRMC_materials_mtoon": {"shadingToonyFactor": 0.5}}}]);
    check_gltf_materials(&file(good, json!({"VRMC_vrm": {}}), &["VRMC_vrm"])).unwrap();
}

/// Through a scene file, a `.vrm` with a wrong MToon type is an error at the object's `path`
/// (`file:line:col: message`), naming the file, the material and the key.
#[test]
fn a_scene_names_the_bad_vrm_material_where_its_path_is() {
    let d = std::env::temp_dir().join(format!("hadou-gltf-mtoon-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let mats = json!([{"extensions": {"VRMC_materials_mtoon": {"shadingToonyFactor": "soft"}}}]);
    std::fs::write(d.join("a.vrm"), file(mats, json!({"VRMC_vrm": {}}), &["VRMC_vrm"])).unwrap();
    std::fs::write(d.join("s.toml"), "[[object]]\nname = \"avatar\"\nkind = \"gltf\"\npath = \"a.vrm\"\n")
        .unwrap();
    let msg = match hadou_scene::Scene::load(d.join("s.toml")) {
        Ok(_) => panic!("a bad MToon material is refused"),
        Err(e) => e.to_string(),
    };
    assert!(msg.contains("s.toml:4:8:"), "{msg}");
    assert!(
        msg.contains("a.vrm") && msg.contains("material 0 (VRMC_materials_mtoon).shadingToonyFactor"),
        "{msg}"
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn the_outline_width_texture_scales_each_vertex_outline() {
    // MToon's outlineWidthMultiplyTexture (linear data): green 80/255 everywhere; the outline
    // directions come out that long (the hull's width multiplier), a plain material's unit long.
    let mtoon = json!({"specVersion": "1.0", "outlineWidthMode": "worldCoordinates", "outlineWidthFactor": 0.01,
                       "outlineWidthMultiplyTexture": {"index": 1}});
    let bytes = file(
        json!([{"name": "skin", "extensions": {"VRMC_materials_mtoon": mtoon}}]),
        json!({}),
        &["VRMC_materials_mtoon"],
    );
    let (mesh, warn) = load(&bytes);
    assert!(warn.is_empty(), "{warn:?}");
    let mesh = hadou_scene::mesh::with_outline_normals(mesh);
    for n in &mesh.outline_normals {
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((len - 80.0 / 255.0).abs() < 2e-3, "{len}");
    }
    let plain = file(json!([{"name": "plain"}]), json!({}), &[]);
    let mesh = hadou_scene::mesh::with_outline_normals(load(&plain).0);
    for n in &mesh.outline_normals {
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((len - 1.0).abs() < 1e-6, "{len}");
    }
}
