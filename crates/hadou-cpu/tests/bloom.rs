//! `[bloom]` on the CPU: a band rendered with its halo equals those rows of the whole frame bit
//! for bit, the glare brightens the beam's surroundings and leaves dark areas alone, a bloom of
//! weight zero is the image without one, and every pixel stays finite.

use hadou_scene::{BloomParams, Frame, Scene};
use std::path::PathBuf;

fn scene_frame(file: &str, t: f32, width: u32, height: u32) -> Frame {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(file);
    let mut f = Scene::load(path).unwrap_or_else(|e| panic!("{e}")).at(t);
    (f.width, f.height) = (width, height);
    f
}

fn glare_frame() -> Frame {
    scene_frame("glare-kamehameha.toml", 1.5, 160, 90)
}

#[test]
fn bands_equal_the_whole_frame() {
    let f = glare_frame();
    let whole = hadou_cpu::render(&f);
    for rows in [0..1, 0..17, 17..40, 40..41, 41..90, 89..90, 30..60] {
        let band = hadou_cpu::render_rows(&f, rows.clone());
        assert_eq!(band, whole.crop_rows(rows.clone()), "rows {rows:?}");
    }
    // A large radius (the halo reaches the whole image) and a streak only.
    for b in [
        BloomParams { radius: 1.0, ..f.bloom.unwrap() },
        BloomParams { intensity: 0.0, streak: 2.0, ..f.bloom.unwrap() },
    ] {
        let g = Frame { bloom: Some(b), ..f.clone() };
        let whole = hadou_cpu::render(&g);
        for rows in [0..8, 45..46, 70..90] {
            assert_eq!(
                hadou_cpu::render_rows(&g, rows.clone()),
                whole.crop_rows(rows.clone()),
                "{b:?} {rows:?}"
            );
        }
    }
    // Odd width and height: the last row's streak pair and the bilinear taps clamp at the edges.
    let odd = scene_frame("glare-kamehameha.toml", 1.5, 161, 91);
    let whole = hadou_cpu::render(&odd);
    for rows in [0..1, 44..47, 80..91, 90..91] {
        assert_eq!(
            hadou_cpu::render_rows(&odd, rows.clone()),
            whole.crop_rows(rows.clone()),
            "161×91 {rows:?}"
        );
    }
}

#[test]
fn glare_brightens_around_the_beam_only() {
    let f = glare_frame();
    let with = hadou_cpu::render(&f);
    let without = hadou_cpu::render(&Frame { bloom: None, ..f.clone() });
    let lum = |c: [f32; 4]| c[0] + c[1] + c[2];
    let (mut brighter, mut darker, mut max_gain) = (0, 0, 0.0f32);
    for (a, b) in with.color.iter().zip(&without.color) {
        let d = lum(*a) - lum(*b);
        if d > 1e-4 {
            brighter += 1;
        }
        if d < -1e-5 {
            darker += 1;
        }
        max_gain = max_gain.max(d);
    }
    assert_eq!(darker, 0, "a glare only adds light");
    assert!(brighter > 500 && max_gain > 0.05, "{brighter} pixels brighter, at most {max_gain}");
    // The energy and depth are the wave pass's, untouched.
    assert_eq!(with.energy, without.energy);
    assert_eq!(with.depth, without.depth);
    // The streak spreads along rows only: it changes fewer rows than the bloom, all of them
    // rows the bloom changes too (the bloom reaches every row with a bright pixel and beyond).
    let changed_rows = |b: BloomParams| -> Vec<u32> {
        let img = hadou_cpu::render(&Frame { bloom: Some(b), ..f.clone() });
        (0..f.height)
            .filter(|&y| {
                (0..f.width).any(|x| {
                    let i = img.index(x, y);
                    (lum(img.color[i]) - lum(without.color[i])).abs() > 1e-5
                })
            })
            .collect()
    };
    let b = f.bloom.unwrap();
    let streak = changed_rows(BloomParams { intensity: 0.0, streak: 2.0, ..b });
    let bloom = changed_rows(BloomParams { intensity: 2.0, streak: 0.0, ..b });
    assert!(!streak.is_empty() && streak.len() < bloom.len(), "{streak:?} {bloom:?}");
    assert!(streak.iter().all(|y| bloom.contains(y)), "{streak:?} {bloom:?}");
}

#[test]
fn zero_weights_give_the_image_without_bloom() {
    let f = glare_frame();
    let off =
        Frame { bloom: Some(BloomParams { intensity: 0.0, streak: 0.0, ..f.bloom.unwrap() }), ..f.clone() };
    let a = hadou_cpu::render(&off);
    let b = hadou_cpu::render(&Frame { bloom: None, ..f.clone() });
    for (p, q) in a.color.iter().zip(&b.color) {
        for k in 0..3 {
            assert!((p[k] - q[k]).abs() < 1e-6, "{p:?} {q:?}");
        }
    }
}

#[test]
fn strong_glare_on_a_saturated_wave_stays_finite() {
    let mut f = glare_frame();
    f.color_mapping.exposure = 1e30;
    f.bloom = Some(BloomParams { intensity: 16.0, streak: 16.0, threshold: 0.0, ..f.bloom.unwrap() });
    let img = hadou_cpu::render(&f);
    assert!(img.color.iter().flatten().all(|v| v.is_finite() && (0.0..=1.0).contains(v)));
}

/// Issue 41 (glare within the memory promise): a frame with a `[bloom]` draws its opaque pass in
/// chunks of rows (so its memory does not grow with the samples), and every chunking gives the
/// pixels of one chunk over the whole image, bit for bit, outlines (which read rows beyond a
/// chunk) and anti-aliasing included.
#[test]
fn issue_41_the_glare_drawn_in_chunks_equals_one_chunk() {
    let mut f = scene_frame("repainted.toml", 1.5, 96, 64);
    f.samples = 4;
    f.bloom = glare_frame().bloom;
    assert!(f.sample_grid().edge() == 2, "the frame is anti-aliased");
    let one = hadou_cpu::render_rows_glare_chunked(&f, 0..64, usize::MAX);
    assert_eq!(one, hadou_cpu::render(&f), "one chunk is the renderer's own frame here");
    // 1, 3 and 7 rows of samples a chunk (the chunk's size is in samples: width × 4 a row).
    for rows_per_chunk in [1usize, 3, 7] {
        let chunked = hadou_cpu::render_rows_glare_chunked(&f, 0..64, rows_per_chunk * 96 * 4);
        assert_eq!(chunked, one, "{rows_per_chunk} rows a chunk");
        let band = hadou_cpu::render_rows_glare_chunked(&f, 20..33, rows_per_chunk * 96 * 4);
        assert_eq!(band, one.crop_rows(20..33), "rows 20..33, {rows_per_chunk} rows a chunk");
    }
}
