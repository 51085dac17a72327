//! `Backend::render_rows_rgb8` on the GPU, where the wave pass writes each pixel's 8-bit sRGB
//! codes itself and a tile reads back 4 bytes a pixel: byte for byte the same as
//! `Rgb8Image::from_image` of `Backend::render_rows`'s float image of the same frame, on example
//! scenes of every kind the wave pass distinguishes (analytic and curved waves, toon shading with
//! outlines, hard and soft shadows, anti-aliasing, the filmic mapping, a `[bloom]`, which takes
//! the float road), on a band of rows, and across tiles.
//!
//! Skips with a message when there is no usable adapter; fails instead under
//! `HADOU_REQUIRE_GPU=1`.

mod common;

use common::{example_frames, gpu_or_skip};
use hadou_scene::{Backend, Frame, Rgb8Image};

/// `render_rows_rgb8` of `rows` against the converted float image of the same rows.
fn assert_same_bytes(
    gpu: &mut hadou_gpu::GpuBackend,
    label: &str,
    frame: &Frame,
    rows: std::ops::Range<u32>,
) {
    let floats = gpu.render_rows(frame, rows.clone()).unwrap_or_else(|e| panic!("{label}: {e}"));
    let want = Rgb8Image::from_image(&floats).unwrap_or_else(|| panic!("{label}: non-finite float image"));
    let got = gpu.render_rows_rgb8(frame, rows.clone()).unwrap_or_else(|e| panic!("{label}: {e}"));
    assert_eq!((got.width, got.height), (want.width, want.height), "{label} rows {rows:?}: size");
    let differing = got.rgb.iter().zip(&want.rgb).filter(|(a, b)| a != b).count();
    if let Some(i) = got.rgb.iter().zip(&want.rgb).position(|(a, b)| a != b) {
        let p = i / 3;
        panic!(
            "{label} rows {rows:?}: {differing} of {} bytes differ; first at pixel ({}, {}) channel {}: {} against {}",
            got.rgb.len(),
            p % got.width as usize,
            p / got.width as usize,
            i % 3,
            got.rgb[i],
            want.rgb[i]
        );
    }
    assert_eq!(got.rgb.len(), want.rgb.len());
}

#[test]
fn the_wave_pass_writes_the_bytes_the_float_image_converts_to() {
    let Some(mut gpu) = gpu_or_skip("rgb8 output") else { return };
    let scenes = [
        "kamehameha.toml",         // analytic waves, filmic, anti-aliasing
        "fig4-1-attenuation.toml", // attenuated analytic waves
        "fig4-9-two-curves.toml",  // curves
        "light-from-front.toml",   // toon shading, outlines
        "shadow-uneven.toml",      // shadow maps
        "shadow-wave-top.toml",    // plane shadows of a wave light
        "soft-gradient.toml",      // the area light's soft shadows
        "glare-kamehameha.toml",   // a `[bloom]`: the float road, converted
    ];
    let frames = example_frames(|name| scenes.contains(&name));
    assert_eq!(
        frames
            .iter()
            .map(|(l, _)| l.split(' ').next().unwrap_or_default())
            .collect::<std::collections::BTreeSet<_>>()
            .len(),
        scenes.len(),
        "every listed scene loads"
    );
    // Every frame of the first scene (one and several samples per pixel: both entry points of
    // the wave pass); of each other scene the one with the most samples.
    let scene_of = |label: &str| label.split(' ').next().unwrap_or_default().to_string();
    let mut kept: Vec<&(String, Frame)> = Vec::new();
    for f in &frames {
        match kept.iter_mut().find(|k| scene_of(&k.0) == scene_of(&f.0) && scene_of(&f.0) != scenes[0]) {
            Some(k) if f.1.samples > k.1.samples => *k = f,
            Some(_) => {}
            None => kept.push(f),
        }
    }
    for (label, frame) in kept {
        assert_same_bytes(&mut gpu, label, frame, 0..frame.height);
    }
    // A band of rows, and rows past the image's end (clamped).
    let (label, frame) = &frames[0];
    assert_same_bytes(&mut gpu, label, frame, 17..61);
    assert_same_bytes(&mut gpu, label, frame, 90..200);
    assert_same_bytes(&mut gpu, label, frame, 50..50);
}

/// An image wider than one tile (`hadou_gpu::MAX_TILE`) is stitched from its tiles' words.
#[test]
fn tiles_are_stitched_into_the_rows() {
    let Some(mut gpu) = gpu_or_skip("rgb8 output across tiles") else { return };
    let mut frames = example_frames(|name| name == "fig4-1-beam.toml");
    let (label, mut frame) = frames.swap_remove(0);
    frame.width = hadou_gpu::MAX_TILE + 37;
    frame.height = 9;
    frame.samples = 2;
    assert_same_bytes(&mut gpu, &label, &frame, 0..frame.height);
    assert_same_bytes(&mut gpu, &label, &frame, 3..8);
}
