//! Every vector path the machine supports (`hadou_math::simd::SimdPath::supported`: the portable
//! lanes everywhere, AVX2 + FMA and AVX-512 where the CPU has them) renders every example scene
//! as the portable path does, within a stated tolerance (the paths differ only in the last bits of
//! their logarithms, `atan2`s and fused multiply-adds); and the colour stage's 8-bit output for
//! PNGs (`CpuBackend::render_rgb8_into`) is, byte for byte, the sRGB of the float image.

use hadou_cpu::CpuBackend;
use hadou_math::simd::SimdPath;
use hadou_scene::{Image, Rgb8Image, Scene};
use std::path::PathBuf;

fn scenes() -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("scenes/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    paths.sort();
    paths
}

/// Largest absolute difference of the mapped colours (mapped colour is in `[0, 1]`).
const COLOR_TOLERANCE: f32 = 1e-3;
/// Largest relative difference of the energies (a few ulp of the kernels, summed).
const ENERGY_TOLERANCE: f32 = 1e-4;

#[test]
fn every_path_renders_every_scene_as_the_portable_path_and_png_bytes_match_the_float_image() {
    let paths = SimdPath::supported();
    let mut cpu = CpuBackend::new();
    let mut checked = 0;
    for scene_path in scenes() {
        let scene = Scene::load(&scene_path).unwrap_or_else(|e| panic!("{e}"));
        let mut frame = scene.at(scene.duration() * 0.6);
        (frame.width, frame.height) = (45, 29);
        let name = scene_path.file_name().unwrap().to_string_lossy().into_owned();
        let mut reference = Image::new(0, 0);
        cpu.render_into_on(&frame, &mut reference, SimdPath::PORTABLE);
        for &path in &paths {
            let mut image = Image::new(0, 0);
            cpu.render_into_on(&frame, &mut image, path);
            let mut bytes = Rgb8Image::default();
            cpu.render_rgb8_into(&frame, &mut bytes, path);
            let want = Rgb8Image::from_image(&image).expect("a finite image");
            assert!(
                bytes == want,
                "{name} on {path}: the 8-bit colour stage differs from the float image's sRGB"
            );
            for i in 0..image.color.len() {
                for c in 0..3 {
                    let (a, b) = (image.color[i][c], reference.color[i][c]);
                    assert!(
                        (a - b).abs() <= COLOR_TOLERANCE,
                        "{name} on {path}: pixel {i} channel {c}: {a} vs {b}"
                    );
                }
                let (a, b) = (image.energy[i], reference.energy[i]);
                assert!(
                    (a - b).abs() <= ENERGY_TOLERANCE * a.abs().max(b.abs()) + 1e-30,
                    "{name} on {path}: pixel {i} energy {a} vs {b}"
                );
                assert_eq!(image.depth[i], reference.depth[i], "{name} on {path}: pixel {i} depth");
            }
        }
        checked += 1;
    }
    assert!(checked >= 30, "only {checked} scenes");
}
