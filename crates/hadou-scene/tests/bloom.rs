//! `[bloom]`: what it builds (values, defaults, tracks clamped into range), that a scene without
//! it has no bloom, and every bad value pointing at its `line:col`.

mod common;

use common::{at, err};
use hadou_scene::Scene;
use std::path::Path;

fn parse(text: &str) -> Scene {
    Scene::parse(text, Path::new("scenes/x.toml")).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn values_defaults_and_absence() {
    let f = parse(
        "[bloom]\nintensity = 1.5\nthreshold = 0.8\nsoft_knee = 0.25\nradius = 0.1\nstreak = 0.6\nstreak_length = 1.5\n",
    )
    .at(0.0);
    let b = f.bloom.unwrap();
    assert_eq!(
        (b.intensity, b.threshold, b.soft_knee, b.radius, b.streak, b.streak_length),
        (1.5, 0.8, 0.25, 0.1, 0.6, 1.5)
    );
    let d = parse("[bloom]\n").at(0.0).bloom.unwrap();
    assert_eq!(
        (d.intensity, d.threshold, d.soft_knee, d.radius, d.streak, d.streak_length),
        (0.5, 1.0, 0.5, 0.05, 0.0, 0.5)
    );
    assert!(parse("[color]\nexposure = 2\n").at(0.0).bloom.is_none());
}

#[test]
fn every_key_is_animatable_and_kept_in_range() {
    let s = parse(
        "[bloom]\nintensity = 0\n\
         [[track]]\ntarget = \"bloom.intensity\"\nkeys = [[0, 0], [1, 2]]\n\
         [[track]]\ntarget = \"bloom.streak_length\"\nkeys = [[0, 0.5], [1, 4]]\n\
         [[track]]\ntarget = \"bloom.soft_knee\"\ninterpolation = \"smooth\"\nkeys = [[0, 0], [0.5, 1], [1, 0]]\n",
    );
    assert_eq!(s.at(0.5).bloom.unwrap().intensity, 1.0);
    assert_eq!(s.at(1.0).bloom.unwrap().streak_length, 4.0);
    for i in 0..=20 {
        let k = s.at(i as f32 / 20.0).bloom.unwrap().soft_knee;
        assert!((0.0..=1.0).contains(&k), "{k}");
    }
    let names: Vec<String> = s.parameters().iter().map(|p| p.target.clone()).collect();
    assert!(names.iter().any(|n| n == "bloom.radius"), "{names:?}");
}

#[test]
fn bad_values_point_at_their_place() {
    // Negative.
    let e = err("[bloom]\nintensity = -0.5\n");
    assert_eq!(at(&e), (2, 13), "{e}");
    assert!(e.to_string().contains("`intensity` in [bloom] must be in [0, 16], got -0.5"), "{e}");
    // NaN.
    let e = err("[bloom]\nthreshold = nan\n");
    assert_eq!(at(&e), (2, 13), "{e}");
    assert!(e.to_string().contains("finite"), "{e}");
    // Out of range.
    let e = err("[bloom]\nsoft_knee = 1.5\n");
    assert_eq!(at(&e), (2, 13), "{e}");
    let e = err("[bloom]\n radius = 0\n");
    assert_eq!(at(&e), (2, 11), "{e}");
    assert!(e.to_string().contains("(0, 1]"), "{e}");
    let e = err("[bloom]\nradius = 2\n");
    assert_eq!(at(&e), (2, 10), "{e}");
    let e = err("[bloom]\nstreak = 17\n");
    assert_eq!(at(&e), (2, 10), "{e}");
    let e = err("[bloom]\nstreak_length = 5\n");
    assert_eq!(at(&e), (2, 17), "{e}");
    let e = err("[bloom]\nthreshold = 1e5\n");
    assert_eq!(at(&e), (2, 13), "{e}");
    // Wrong type.
    let e = err("[bloom]\nintensity = \"bright\"\n");
    assert_eq!(at(&e), (2, 13), "{e}");
    // Unknown key, with a hint.
    let e = err("[bloom]\nstreak_lenght = 1\n");
    assert_eq!(at(&e), (2, 1), "{e}");
    assert!(e.to_string().contains("did you mean `streak_length`?"), "{e}");
    // Not a table.
    let e = err("bloom = 1\n");
    assert_eq!(at(&e).0, 1, "{e}");
    // A track key out of range, and a track on a scene without [bloom].
    let e = err("[bloom]\n[[track]]\ntarget = \"bloom.intensity\"\nkeys = [[0, 1], [1, -2]]\n");
    assert_eq!(at(&e).0, 4, "{e}");
    let e = err("[[track]]\ntarget = \"bloom.intensity\"\nkeys = [[0, 1]]\n");
    assert!(e.to_string().contains("the scene has no [bloom]"), "{e}");
    assert_eq!(at(&e).0, 2, "{e}");
}
