//! `[[material]]`, the material keys of `[[object]]` and the light keys of `[[wave]]`: what they
//! build and every bad input with its line and column.

mod common;

use common::{at, err};
use hadou_scene::{RampKind, Scene, ShadingModel};
use std::path::{Path, PathBuf};

const BASE: &str = "[[object]]\nname = \"o\"\nkind = \"box\"\n";

fn parse(text: &str) -> Scene {
    Scene::parse(text, Path::new("scenes/x.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// A fresh directory holding `files`.
fn dir_with(name: &str, files: &[(&str, &[u8])]) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hadou-materials-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    for (f, bytes) in files {
        std::fs::write(d.join(f), bytes).unwrap();
    }
    d
}

#[test]
fn materials_bind_to_objects_and_animate() {
    let s = parse(
        r#"
[[material]]
name = "skin"
model = "toon"
base_color = [0.9, 0.7, 0.6]
ramp = [[-1.0, 0.5, 0.5, 0.6], [0.1, 1.0, 1.0, 1.0]]
ramp_smoothing = 0.05
wave_blend = 0.25
outline = true
outline_width = 0.01
outline_color = [0.1, 0.0, 0.0]

[[object]]
name = "hero"
kind = "sphere"
material = "skin"

[[object]]
name = "plain"
kind = "box"
color = [0.2, 0.3, 0.4]
wave_blend = 0.5

[[wave]]
name = "w"
kind = "sphere"
M = [0, 0, 0]
alpha_s = 1
light_ramp = [[-1.0, 0, 0, 1], [0.5, 1, 1, 1]]
light_ramp_kind = "gradient"
light_glow = 0.3

[[track]]
target = "material.skin.wave_blend"
keys = [[0, 0.25], [1, 1.0]]
"#,
    );
    let f = s.at(0.5);
    let m = &f.objects[0].materials[0];
    assert_eq!(m.model, ShadingModel::Toon);
    assert_eq!(m.base_color, [0.9, 0.7, 0.6]);
    assert_eq!(m.ramp.kind, RampKind::Bands { smoothing: 0.05 });
    assert_eq!(m.ramp.stops[1], (0.1, [1.0; 3]));
    assert!((m.wave_blend - 0.625).abs() < 1e-6, "{}", m.wave_blend);
    let o = m.outline.expect("outline");
    assert_eq!((o.width, o.color), (0.01, [0.1, 0.0, 0.0]));
    let p = &f.objects[1].materials[0];
    assert_eq!(
        (p.model, p.base_color, p.wave_blend, p.outline),
        (ShadingModel::Diffuse, [0.2, 0.3, 0.4], 0.5, None)
    );
    let w = &f.waves[0].light;
    assert_eq!((w.ramp.kind, w.glow), (RampKind::Gradient, 0.3));
    // A wave without light keys gets the ramp derived from its colour.
    let d = parse(
        "[[wave]]\nname = \"w\"\nkind = \"sphere\"\nM = [0, 0, 0]\nalpha_s = 1\nrgba = [0, 0.5, 1, 1]\n",
    );
    assert_eq!(d.at(0.0).waves[0].light.ramp, hadou_scene::Ramp::for_wave_color([0.0, 0.5, 1.0]));
    // Primitive meshes carry outline normals and texture coordinates.
    let mesh = &f.objects[1].mesh;
    assert_eq!(mesh.outline_normals.len(), mesh.positions.len());
    assert_eq!(mesh.uvs.len(), mesh.positions.len());
}

#[test]
fn bad_ramps_blends_and_bindings_are_located() {
    let mat = |extra: &str| format!("[[material]]\nname = \"m\"\nmodel = \"toon\"\n{extra}\n");
    let e = err(&mat("ramp = [[0.0, 1, 1, 1], [-0.5, 0, 0, 0]]"));
    assert!(e.to_string().contains("must be sorted"), "{e}");
    assert_eq!(at(&e), (4, 26));
    let e = err(&mat("ramp = [[0.0, 1, 1, 1], [0.0, 0, 0, 0]]"));
    assert!(e.to_string().contains("overlap"), "{e}");
    let e = err(&mat("ramp = [[1.5, 1, 1, 1]]"));
    assert!(e.to_string().contains("[-1, 1]"), "{e}");
    let e = err(&mat("ramp = []"));
    assert!(e.to_string().contains("1 to 8 rows"), "{e}");
    let e = err(&mat("ramp = [[0, 1, 1]]"));
    assert!(e.to_string().contains("4 numbers"), "{e}");
    let e = err(&mat("ramp = [[0, -1, 1, 1]]"));
    assert!(e.to_string().contains("must be in [0, 1e6], got -1"), "{e}");
    let e = err(&mat("ramp_smoothing = 0.1"));
    assert!(e.to_string().contains("applies to `ramp`"), "{e}");
    let e = err(&mat("ramp = [[0, 1, 1, 1]]\nramp_kind = \"gradient\"\nramp_smoothing = 0.1"));
    assert!(e.to_string().contains("not to a gradient"), "{e}");
    let e = err(&mat("wave_blend = 1.5"));
    assert!(e.to_string().contains("[0, 1]"), "{e}");
    assert_eq!(at(&e), (4, 14));
    let e = err("[[material]]\nname = \"m\"\nramp = [[0, 1, 1, 1]]\n");
    assert!(e.to_string().contains("model = \"toon\""), "{e}");
    let e = err(&mat("outline = 1"));
    assert!(e.to_string().contains("true or false"), "{e}");
    let e = err("[[material]]\nname = \"m\"\nmodel = \"cel\"\n");
    assert!(e.to_string().contains("cannot be \"cel\""), "{e}");
    let e = err(&format!("{BASE}material = \"nope\"\n"));
    assert!(e.to_string().contains("no [[material]] is named \"nope\""), "{e}");
    assert_eq!(at(&e), (4, 12));
    let e = err(&format!("{}{BASE}material = \"m\"\ncolor = [1, 1, 1]\n", mat("")));
    assert!(e.to_string().contains("base_color"), "{e}");
    let e = err(&format!("{}{BASE}materials = {{ Skin = \"m\" }}\n", mat("")));
    assert!(e.to_string().contains("has no material \"Skin\""), "{e}");
    let e = err(&format!("{BASE}wave_blend = -0.1\n"));
    assert!(e.to_string().contains("[0, 1]"), "{e}");
    let e = err("[[wave]]\nname = \"w\"\nkind = \"sphere\"\nM = [0, 0, 0]\nalpha_s = 1\nlight_ramp = [[0, 1, 1, 1], [-1, 0, 0, 0]]\n");
    assert!(e.to_string().contains("must be sorted"), "{e}");
    let e = err("[[wave]]\nname = \"w\"\nkind = \"sphere\"\nM = [0, 0, 0]\nalpha_s = 1\nlight_glow = -1\n");
    assert!(e.to_string().contains("light_glow"), "{e}");
    let e = err(&format!("{}[[track]]\ntarget = \"material.m.wave_blend\"\nkeys = [[0, 2.0]]\n", mat("")));
    assert!(e.to_string().contains("[0, 1]"), "{e}");
    let e = err(&format!("{}[[track]]\ntarget = \"material.q.wave_blend\"\nkeys = [[0, 1.0]]\n", mat("")));
    assert!(e.to_string().contains("no material is named \"q\""), "{e}");
}

#[test]
fn texture_files_are_checked() {
    let png = hadou_scene::encode_png(
        2,
        2,
        &[[255, 0, 0, 255], [0, 255, 0, 255], [0, 0, 255, 255], [9, 9, 9, 255]],
    );
    let d = dir_with("tex", &[("face.png", &png), ("notes.txt", b"not an image"), ("empty.png", b"")]);
    let scene = |key: &str, file: &str| {
        let text = format!("[[material]]\nname = \"m\"\n{key} = \"{file}\"\n{BASE}material = \"m\"\n");
        std::fs::write(d.join("s.toml"), text).unwrap();
        Scene::load(d.join("s.toml"))
    };
    let s = scene("feature_texture", "face.png").unwrap_or_else(|e| panic!("{e}"));
    let t = s.at(0.0).objects[0].materials[0].feature_texture.clone().expect("texture");
    assert_eq!((t.image.width, t.image.height, t.image.texels[1]), (2, 2, [0, 255, 0, 255]));
    for (file, want) in [
        ("missing.png", "cannot read"),
        ("notes.txt", "not a PNG or JPEG"),
        ("empty.png", "empty"),
        ("../outside.png", "cannot read"),
    ] {
        let e = scene("base_texture", file).expect_err(file);
        assert!(e.to_string().contains(want), "{file}: {e}");
        assert_eq!(at(&e), (3, 16), "{file}: {e}");
    }
    std::fs::write(d.join("abs.toml"), "[[material]]\nname = \"m\"\nbase_texture = \"/etc/passwd\"\n")
        .unwrap();
    let e = Scene::load(d.join("abs.toml")).expect_err("absolute");
    assert!(e.to_string().contains("must be relative"), "{e}");
    // A directory is not a texture.
    std::fs::create_dir_all(d.join("dir.png")).unwrap();
    let e = scene("base_texture", "dir.png").expect_err("dir");
    assert!(e.to_string().contains("directory"), "{e}");
}

#[test]
fn textures_on_a_mesh_without_uvs_are_dropped_with_a_warning() {
    let png = hadou_scene::encode_png(1, 1, &[[0, 0, 0, 255]]);
    let crystal =
        std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/assets/crystal.glb")).unwrap();
    let d = dir_with("nouv", &[("f.png", &png), ("c.glb", &crystal)]);
    let text = "[[material]]\nname = \"m\"\nfeature_texture = \"f.png\"\n\n[[object]]\nname = \"c\"\nkind = \"gltf\"\npath = \"c.glb\"\nmaterial = \"m\"\n";
    std::fs::write(d.join("s.toml"), text).unwrap();
    let s = Scene::load(d.join("s.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        s.warnings().iter().any(|w| w.contains("no texture coordinates") && w.contains("5:1")),
        "{:?}",
        s.warnings()
    );
    assert!(s.at(0.0).objects[0].materials[0].feature_texture.is_none());
}
