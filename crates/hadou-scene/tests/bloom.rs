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

/// Issue 41 (glare within the memory promise): an image with a `[bloom]` is at most
/// `GLARE_MAX_PIXELS` (8192²) pixels, refused past it with the `[bloom]`'s place and the limit,
/// whether the size comes from the file's `[image]` or from a caller (the command line's flags);
/// within it, the output bands fit the memory the glare leaves.
#[test]
fn issue_41_an_image_with_a_bloom_is_within_the_glares_memory() {
    use hadou_scene::{
        glare_band_rows, GLARE_BAND_BYTES_PER_PIXEL, GLARE_BYTES_PER_PIXEL, GLARE_MAX_BYTES, GLARE_MAX_PIXELS,
    };
    let e = err("[image]\nwidth = 16384\nheight = 8192\n\n[bloom]\nintensity = 1\n");
    assert_eq!(at(&e), (5, 1), "{e}");
    assert!(e.to_string().contains("at most 67108864 pixels"), "{e}");
    let s = parse("[image]\nwidth = 8192\nheight = 8192\n\n[bloom]\n");
    assert!(s.check_image_size(8192, 8192).is_ok());
    let m = s.check_image_size(8193, 8192).unwrap_err();
    assert!(m.contains("scenes/x.toml:5:1") && m.contains("67108864") && m.contains("GB"), "{m}");
    assert!(s.check_image_size(16384, 16384).is_err());
    // Without a [bloom] the same sizes are the edges' business only.
    assert!(parse("[image]\nwidth = 16384\nheight = 16384\n").check_image_size(16384, 16384).is_ok());
    // The bands: whole images up to about 6 340², never more memory than the limit, at least a row.
    assert_eq!(glare_band_rows(4096, 4096), 4096);
    assert_eq!(glare_band_rows(6340, 6340), 6340);
    for (w, h) in [(8192u32, 8192u32), (16384, 4096), (1, 16384), (7000, 7000), (3, 5)] {
        let rows = glare_band_rows(w, h);
        assert!((1..=h).contains(&rows));
        let px = u64::from(w) * u64::from(h);
        if px <= GLARE_MAX_PIXELS {
            let need =
                px * GLARE_BYTES_PER_PIXEL + u64::from(w) * u64::from(rows) * GLARE_BAND_BYTES_PER_PIXEL;
            assert!(need <= GLARE_MAX_BYTES, "{w}×{h}: {rows} rows need {need} bytes");
        }
    }
}
