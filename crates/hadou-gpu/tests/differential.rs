//! GPU ↔ CPU differential tests: every frame is rendered by both backends and compared.
//!
//! Tolerances (set in tests/common/mod.rs): energy relative error ≤ 1e-3 where the energy is
//! above a floor of 1e-5 × the image's peak; colour within 2e-3 absolute after mapping; eye
//! distance within 1e-3 relative. Pixels outside these bounds are allowed only on silhouettes
//! and creases of the CPU image (where the two rasterizers may disagree on which triangle covers
//! a pixel centre lying on an edge), and only up to 0.5 % of the image.
//!
//! Without a GPU adapter each test prints a skip message and passes; `HADOU_REQUIRE_GPU=1` makes
//! a missing adapter a failure (CI, where lavapipe provides one).

mod common;

use common::*;
use hadou_cpu::CpuBackend;
use hadou_scene::{Backend, Frame};

fn check(name: &str, frame: &Frame) {
    let Some(mut gpu) = gpu_or_skip(name) else { return };
    let g = gpu.render(frame).unwrap_or_else(|e| panic!("{name}: GPU render failed: {e}"));
    let c = CpuBackend::new().render(frame).unwrap_or_else(|e| panic!("{name}: CPU render failed: {e}"));
    assert_close(name, &compare(&g, &c));
}

#[test]
fn occlusion_faithful_matches_cpu() {
    check("occlusion", &occlusion_frame(160, 120));
}

#[test]
fn beam_over_scenery_inverse_square_filmic_matches_cpu() {
    check("kamehameha", &kamehameha_frame(160, 120));
}

#[test]
fn cylinder_seen_along_its_axis_matches_cpu() {
    check("axis view", &axis_view_frame(96, 96));
}

#[test]
fn tiled_wide_image_matches_cpu() {
    // Wider than one tile: two tiles side by side, odd sizes, so tile seams and edges are covered.
    check("tiled", &occlusion_frame(hadou_gpu::MAX_TILE + 77, 37));
}

/// Every example scene, at the start, middle and end of its animation, at 128×96.
///
/// GAP(curves): the GPU backend does not draw curved waves yet, so they are left out of both
/// renders (the scenery and the analytic waves of those scenes are still compared); the test says
/// how many it left out.
#[test]
fn every_example_scene_matches_cpu() {
    let Some(mut gpu) = gpu_or_skip("example scenes") else { return };
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes");
    let mut paths: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    assert!(!paths.is_empty(), "no scenes in {dir}");
    let mut cpu = CpuBackend::new();
    for path in paths {
        let scene = hadou_scene::Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let name = path.file_name().unwrap_or_default().to_string_lossy().into_owned();
        let d = scene.duration();
        for t in [0.0, 0.5 * d, d] {
            let mut frame = scene.at(t);
            frame.width = 128;
            frame.height = 96;
            let before = frame.waves.len();
            frame.waves.retain(|w| !matches!(w.shape, hadou_scene::WaveShape::Curve(_)));
            let left_out = before - frame.waves.len();
            let label = format!("{name} t={t}");
            if left_out > 0 {
                eprintln!("{label}: {left_out} curved wave(s) left out (not drawn on the GPU yet)");
            }
            let g = gpu.render(&frame).unwrap_or_else(|e| panic!("{label}: GPU render failed: {e}"));
            let c = cpu.render(&frame).unwrap_or_else(|e| panic!("{label}: CPU render failed: {e}"));
            assert_close(&label, &compare(&g, &c));
            if d == 0.0 {
                break;
            }
        }
    }
}
