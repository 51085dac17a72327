//! The CPU backend's work fits a small stack: every example scene, on every vector path the
//! machine supports, with one sample and with four per pixel, renders (and probes a pixel) on
//! rayon workers whose stacks are 1 MiB, half rayon's default.
//!
//! In the test profile (opt-level 2) that holds with room to spare. What it guards is the
//! unoptimized build, where only `#[inline(always)]` inlines and every temporary of an inlined
//! function keeps a stack slot of its own: the lane kernels take frames of their own there
//! (`hadou_math::simd::Lane::outlined_if_unoptimized`), and a dispatched body inlining them all
//! needed several megabytes. `cargo test -p hadou-cpu --test stack --config
//! 'profile.test.opt-level=0'` runs it on the frames a dev build gets.

use hadou_cpu::CpuBackend;
use hadou_math::simd::SimdPath;
use hadou_scene::{Image, Scene};
use std::path::PathBuf;

/// The workers' stack.
const STACK: usize = 1 << 20;

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

#[test]
fn every_scene_renders_on_one_mebibyte_worker_stacks() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).stack_size(STACK).build().unwrap();
    for scene_path in scenes() {
        let scene = Scene::load(&scene_path).unwrap_or_else(|e| panic!("{e}"));
        let mut frame = scene.at(scene.duration() * 0.6);
        (frame.width, frame.height) = (64, 36);
        for samples in [1, 4] {
            frame.samples = samples;
            for path in SimdPath::supported() {
                let mut image = Image::new(0, 0);
                let probe = pool.install(|| {
                    CpuBackend::new().render_into_on(&frame, &mut image, path);
                    hadou_cpu::probe(&frame, 32, 18)
                });
                assert_eq!(image.color.len(), 64 * 36);
                assert!(probe.is_some());
            }
        }
    }
}
