//! Keyframe interpolation through the public API: linear exact at keys and midpoints, smooth C1 at
//! keys, holding before the first and after the last key, clamping of overshoot.

use hadou_scene::{Scene, WaveShape};
use std::path::Path;

fn scene(tracks: &str) -> Scene {
    let text = format!(
        "[[wave]]\nname = \"b\"\nkind = \"beam\"\nM = [0, 0, 0]\nD = [1, 0, 0]\nlength = 1\n\
         alpha_s = 1\nalpha_c = 1\n\n{tracks}"
    );
    Scene::parse(&text, Path::new("anim.toml")).unwrap_or_else(|e| panic!("{e}"))
}

fn beam(s: &Scene, t: f32) -> hadou_math::energy::BeamField<f32> {
    match &s.at(t).waves[0].shape {
        WaveShape::Beam(b) => *b,
        other => panic!("{other:?}"),
    }
}

#[test]
fn linear_is_exact_at_keys_and_midpoints_and_holds_outside() {
    let s = scene("[[track]]\ntarget = \"wave.b.length\"\nkeys = [[1.0, 2.0], [2.0, 6.0], [4.0, 5.0]]\n");
    assert_eq!(s.duration(), 4.0);
    let len = |t| beam(&s, t).capsule.length;
    assert_eq!(len(1.0), 2.0);
    assert_eq!(len(2.0), 6.0);
    assert_eq!(len(4.0), 5.0);
    assert_eq!(len(1.5), 4.0);
    assert_eq!(len(3.0), 5.5);
    // Before the first key and after the last: held.
    assert_eq!(len(0.0), 2.0);
    assert_eq!(len(-3.0), 2.0);
    assert_eq!(len(100.0), 5.0);
    assert_eq!(len(f32::NAN), 2.0);
}

#[test]
fn smooth_passes_keys_with_continuous_slope() {
    let s = scene(
        "[[track]]\ntarget = \"wave.b.length\"\ninterpolation = \"smooth\"\n\
         keys = [[0.0, 1.0], [1.0, 3.0], [3.0, 2.0], [4.0, 6.0]]\n",
    );
    let len = |t: f32| beam(&s, t).capsule.length as f64;
    for (t, v) in [(0.0, 1.0), (1.0, 3.0), (3.0, 2.0), (4.0, 6.0)] {
        assert!((len(t) - v).abs() < 1e-6, "{t}: {}", len(t));
    }
    // C1: one-sided slopes agree at inner keys (a linear track's would jump: 2 → −0.5 at t = 1).
    for key in [1.0f32, 3.0] {
        // Second-order one-sided differences, so only a true kink shows.
        let h = 1e-2;
        let left = (3.0 * len(key) - 4.0 * len(key - h) + len(key - 2.0 * h)) / (2.0 * h as f64);
        let right = (-3.0 * len(key) + 4.0 * len(key + h) - len(key + 2.0 * h)) / (2.0 * h as f64);
        assert!((left - right).abs() < 0.01, "slope jump at {key}: {left} vs {right}");
    }
    // Catmull-Rom tangent at t = 1: (2 − 1) / (3 − 0).
    let h = 1e-3;
    let slope = (len(1.0 + h) - len(1.0 - h)) / (2.0 * h as f64);
    assert!((slope - 1.0 / 3.0).abs() < 1e-2, "{slope}");
}

#[test]
fn overshoot_is_clamped_into_range() {
    // Smooth interpolation of alpha_s dips below 0 between the first keys; the frame clamps it.
    let s = scene(
        "[[track]]\ntarget = \"wave.b.alpha_s\"\ninterpolation = \"smooth\"\n\
         keys = [[0.0, 0.0], [1.0, 0.0], [2.0, 10.0]]\n",
    );
    let mut saw_clamp = false;
    for i in 0..=200 {
        let t = i as f32 * 0.01;
        let a = beam(&s, t).capsule.alpha_s;
        assert!(a >= 0.0 && a.is_finite(), "{t}: {a}");
        saw_clamp |= a == 0.0 && t > 0.0 && t < 1.0;
    }
    assert!(saw_clamp, "the Catmull-Rom curve should undershoot between the first two keys");
}

#[test]
fn components_vectors_and_list_elements_animate() {
    let text = "[[wave]]\nname = \"z\"\nkind = \"bezier\"\nO = [0, 0, 0]\nD = [1, 0, 0]\nalpha = 1\n\
                points = [[0, 0], [1, 1], [0, 0]]\n\n\
                [[track]]\ntarget = \"wave.z.points[1]\"\nkeys = [[0, [1, 1]], [2, [3, -1]]]\n\
                [[track]]\ntarget = \"wave.z.rgba.a\"\nkeys = [[0, 0.0], [2, 1.0]]\n\
                [[track]]\ntarget = \"camera.position\"\nkeys = [[0, [0, 0, 10]], [2, [0, 0, 20]]]\n\
                [[track]]\ntarget = \"wave.z.points[2][0]\"\nkeys = [[0, 0.0], [2, 4.0]]\n\
                [[track]]\ntarget = \"background.g\"\nkeys = [[0, 0.0], [2, 0.5]]\n\
                [[track]]\ntarget = \"color.exposure\"\nkeys = [[0, 1.0], [2, 3.0]]\n";
    let s = Scene::parse(text, Path::new("a.toml")).unwrap_or_else(|e| panic!("{e}"));
    let f = s.at(1.0);
    let WaveShape::Curve(c) = &f.waves[0].shape else { panic!() };
    let hadou_math::curve::CurveShape::Bezier { points } = &c.shape else { panic!() };
    assert_eq!(points, &vec![[0.0, 0.0], [2.0, 0.0], [2.0, 0.0]]);
    assert_eq!(f.waves[0].color[3], 0.5);
    assert_eq!(f.camera.position.z, 15.0);
    assert_eq!(f.background, [0.0, 0.25, 0.0]);
    assert_eq!(f.color_mapping.exposure, 2.0);
    assert_eq!(f.time, 1.0);
    assert_eq!(s.track_targets().len(), 6);
}

#[test]
fn object_scale_accepts_a_number_and_static_scenes_have_zero_duration() {
    let text = "[[object]]\nname = \"o\"\nkind = \"box\"\nscale = 2\n\n\
                [[track]]\ntarget = \"object.o.scale\"\nkeys = [[0, 2], [1, [1, 2, 3]]]\n";
    let s = Scene::parse(text, Path::new("a.toml")).unwrap_or_else(|e| panic!("{e}"));
    let m = s.at(1.0).objects[0].transform;
    assert_eq!((m.at(0, 0), m.at(1, 1), m.at(2, 2)), (1.0, 2.0, 3.0));
    let m = s.at(0.0).objects[0].transform;
    assert_eq!((m.at(0, 0), m.at(1, 1), m.at(2, 2)), (2.0, 2.0, 2.0));
    let still = Scene::parse("", Path::new("empty.toml")).unwrap();
    assert_eq!(still.duration(), 0.0);
    assert_eq!((still.width(), still.height()), (512, 512));
}

#[test]
fn m2_form_follows_the_head_and_degenerate_beams_stay_finite() {
    let text = "[[wave]]\nname = \"c\"\nkind = \"capsule\"\nM = [0, 0, 0]\nM2 = [0, 0, -4]\n\
                alpha_s = 1\nalpha_c = 1\n\n\
                [[track]]\ntarget = \"wave.c.M2.z\"\nkeys = [[0, -4], [2, 4]]\n";
    let s = Scene::parse(text, Path::new("a.toml")).unwrap();
    let cap = |t| match &s.at(t).waves[0].shape {
        WaveShape::Capsule(c) => *c,
        _ => panic!(),
    };
    assert_eq!(cap(0.0).length, 4.0);
    assert_eq!(cap(0.0).d.z, -1.0);
    // t = 1: M2 = M, zero length; the direction falls back to the file's and stays unit.
    let c = cap(1.0);
    assert_eq!(c.length, 0.0);
    assert!((c.d.length() - 1.0).abs() < 1e-6 && c.d.is_finite());
    assert_eq!(cap(2.0).d.z, 1.0);
}
