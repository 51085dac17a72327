//! Every example scene in `scenes/` loads, and evaluates to finite, renderable frames across its
//! duration.

use hadou_scene::{Frame, Scene, WaveShape};
use std::path::PathBuf;

fn scene_files() -> Vec<PathBuf> {
    let dir = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes"));
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("scenes/ exists")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    v.sort();
    v
}

fn check_finite(f: &Frame, what: &str) {
    let c = &f.camera;
    assert!(c.position.is_finite() && c.target.is_finite() && c.up.is_finite(), "{what}");
    assert!(c.fov_y_deg > 0.0 && c.fov_y_deg < 180.0 && c.near > 0.0 && c.far > c.near, "{what}");
    assert!(f.light.direction.is_finite() && (f.light.direction.length() - 1.0).abs() < 1e-5, "{what}");
    assert!(f.color_mapping.exposure > 0.0 && f.color_mapping.exposure.is_finite(), "{what}");
    assert!(f.background.iter().all(|v| v.is_finite() && *v >= 0.0), "{what}");
    for o in &f.objects {
        assert!(o.transform.cols.iter().flatten().all(|v| v.is_finite()), "{what} {}", o.name);
        assert!(!o.mesh.indices.is_empty(), "{what} {}", o.name);
        assert!(o.mesh.positions.iter().flatten().all(|v| v.is_finite()), "{what}");
        assert!(o.mesh.normals.iter().all(|n| {
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            (l - 1.0).abs() < 1e-4
        }));
    }
    for w in &f.waves {
        let ok =
            w.color.iter().all(|v| v.is_finite() && *v >= 0.0) && w.color[3] <= 1.0 && w.core_radius >= 0.0;
        assert!(ok, "{what} {}", w.name);
        match &w.shape {
            WaveShape::Sphere(s) => assert!(s.center.is_finite() && s.alpha >= 0.0),
            WaveShape::Cylinder(c) => assert!((c.dir.length() - 1.0).abs() < 1e-5 && c.alpha >= 0.0),
            WaveShape::Capsule(c) => {
                assert!((c.d.length() - 1.0).abs() < 1e-5 && c.length >= 0.0 && c.m.is_finite(), "{what}")
            }
            WaveShape::Beam(b) => {
                let c = &b.capsule;
                assert!((c.d.length() - 1.0).abs() < 1e-5 && c.length >= 0.0, "{what}");
                assert!(b.head_alpha >= 0.0 && b.muzzle_alpha >= 0.0, "{what}");
            }
            WaveShape::Curve(c) => {
                assert!(c.extension > 0.0 && c.extension <= 1.0, "{what} k = {}", c.extension);
                assert!(c.gamma > 0.0 && c.attenuation >= 0.0 && c.alpha >= 0.0, "{what}");
                assert!(c.frame.origin.is_finite() && c.frame.axis.is_finite() && c.frame.up.is_finite());
                assert!(c.frame.up.cross(c.frame.axis).length() > 1e-4, "{what}");
            }
        }
    }
}

#[test]
fn every_example_scene_loads_and_evaluates() {
    let files = scene_files();
    assert!(files.len() >= 14, "{files:?}");
    for path in files {
        let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let d = scene.duration();
        assert!(d >= 0.0 && d.is_finite());
        for i in 0..=40 {
            let t = -0.5 + (d + 1.0) * i as f32 / 40.0;
            let f = scene.at(t);
            assert_eq!((f.width, f.height), (scene.width(), scene.height()));
            check_finite(&f, &format!("{} at {t}", path.display()));
        }
    }
}

#[test]
fn figure_scenes_use_the_thesis_colours_and_modes() {
    let dir = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes"));
    for name in ["fig4-1-sphere", "fig4-1-cylinder", "fig4-1-capsule", "fig4-1-beam"] {
        let f = Scene::load(dir.join(format!("{name}.toml"))).unwrap().at(0.0);
        assert_eq!(f.waves[0].color, [0.8, 0.8, 0.2, 1.0], "{name}");
        assert_eq!(f.waves[0].falloff, hadou_math::energy::Falloff::Faithful, "{name}");
        assert_eq!(f.color_mapping.mode, hadou_scene::ToneMode::Faithful, "{name}");
    }
    let f = Scene::load(dir.join("fig4-2-bspline.toml")).unwrap().at(0.0);
    assert_eq!(f.waves[0].color, [0.5, 0.5, 1.0, 1.0]);
    let s = Scene::load(dir.join("fig4-13-extension.toml")).unwrap();
    let k = |t| match &s.at(t).waves[0].shape {
        WaveShape::Curve(c) => c.extension,
        _ => panic!(),
    };
    assert_eq!([k(0.0), k(1.0), k(2.0)], [0.1, 0.4, 0.8]);
    let s = Scene::load(dir.join("fig4-14-occlusion.toml")).unwrap();
    let f = s.at(0.0);
    assert_eq!(f.objects.len(), 2);
    let pos: Vec<_> =
        f.objects.iter().map(|o| o.transform.transform_point(hadou_math::Vec3f::ZERO)).collect();
    assert_eq!(pos[0], hadou_math::Vec3f::new(0.0, 0.0, -20.0));
    assert_eq!(pos[1], hadou_math::Vec3f::new(10.0, 0.0, 10.0));
    assert!(s.duration() > 1.0);
}

#[test]
fn the_documented_example_parses() {
    let root = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    let doc = std::fs::read_to_string(root.join("docs/scene-format.md")).expect("docs/scene-format.md");
    let start = doc.rfind("```toml\n").expect("a toml example") + "```toml\n".len();
    let len = doc[start..].find("```").expect("closed block");
    // As if it lived in scenes/, so the glTF path resolves.
    let scene = Scene::parse(&doc[start..start + len], &root.join("scenes/doc-example.toml"))
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.wave_names(), vec!["beam", "spiral"]);
    assert_eq!(scene.duration(), 2.0);
    check_finite(&scene.at(1.0), "doc example");
}
