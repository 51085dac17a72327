//! `scenes/assets/hero.glb` (written by `scenes/assets/make_hero.py`): a skinned character with
//! several materials, a base texture and a feature texture, placed by its skin at rest.

use hadou_scene::{load_gltf, ShadingModel};
use std::path::Path;

#[test]
fn hero_loads_with_materials_textures_and_its_skin_applied() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/assets/hero.glb");
    let m = load_gltf(&path).unwrap_or_else(|e| panic!("{e}"));
    let names: Vec<&str> = m.materials.iter().map(|x| x.name.as_str()).collect();
    assert!(m.materials.len() >= 3, "{names:?}");
    assert_eq!(names[..4], ["suit", "skin", "face", "hair"]);
    assert!(m.materials.iter().any(|x| x.base_texture.is_some()));
    let face = m.materials.iter().position(|x| x.name == "face").unwrap();
    assert!(m.materials[face].feature_texture.is_some());
    assert_eq!(m.materials[3].model, ShadingModel::Toon);
    assert_eq!(m.uvs.len(), m.positions.len());
    assert_eq!(m.material_ids.len(), m.positions.len());

    // Standing on y = 0, about 1.8 tall; without the skin the mesh node's (0, 3, 0) would lift it.
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in &m.positions {
        assert!(p[0].abs() < 1.5 && p[2].abs() < 1.5 && (0.0..=2.2).contains(&p[1]), "{p:?}");
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    assert!(lo[1].abs() < 1e-4 && (1.6..2.0).contains(&hi[1]), "{lo:?} {hi:?}");

    let of =
        |slot: usize| m.positions.iter().zip(&m.material_ids).filter(move |(_, &id)| id as usize == slot);
    // The head sits above the torso (suit).
    let torso_top = of(0).map(|(p, _)| p[1]).fold(f32::NEG_INFINITY, f32::max);
    let head_bottom = of(face).map(|(p, _)| p[1]).fold(f32::INFINITY, f32::min);
    assert!(head_bottom > torso_top, "head from {head_bottom}, torso up to {torso_top}");
    // Face features on +z: the texels that are dark are sampled on the front of the head.
    let tex = m.materials[face].feature_texture.as_ref().unwrap();
    let dark: Vec<[f32; 3]> = of(face)
        .zip(m.uvs.iter().enumerate().filter(|(i, _)| m.material_ids[*i] as usize == face).map(|(_, uv)| uv))
        .filter(|(_, uv)| tex.sample(**uv)[0] < 0.5)
        .map(|((p, _), _)| *p)
        .collect();
    assert!(!dark.is_empty() && dark.iter().all(|p| p[2] > 0.05), "{dark:?}");
    // The arms hang from the shoulders (their joints turned at rest): the hands reach hip height,
    // close to the body, not out at the T-pose's ±0.8.
    let arm: Vec<&[f32; 3]> = of(1).map(|(p, _)| p).filter(|p| p[1] < 1.4).collect();
    let lowest = arm.iter().map(|p| p[1]).fold(f32::INFINITY, f32::min);
    assert!(lowest < 0.9, "the arms do not hang: lowest arm vertex at y = {lowest}");
    assert!(arm.iter().all(|p| p[0].abs() < 0.5), "an arm vertex is detached from the body");
}

#[test]
fn a_scene_names_the_gltf_file_each_object_was_read_from() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/light-normal-vs-wave.toml");
    let scene = hadou_scene::Scene::load(&path).unwrap();
    let names = scene.object_names();
    let files = scene.object_files();
    assert_eq!(files.len(), names.len());
    for (name, file) in names.iter().zip(&files) {
        match *name {
            "hero" => assert_eq!(*file, Some(Path::new("assets/hero.glb"))),
            _ => assert_eq!(*file, None, "{name} is a primitive"),
        }
    }
}
