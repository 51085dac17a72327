//! A frame's output does not depend on timing. The same frames are rendered again and again by
//! one backend while other threads keep every core busy (the software adapters run their shaders
//! on the same cores, so load changes their scheduling), interleaved so that each render follows
//! a different frame (which rewrites the shared tile uniforms and targets, the shadow maps, the
//! soft-shadow buffers and the mesh cache), and across more than one tile; every render of a
//! frame must give the bits of its first render.

mod common;

use common::*;
use hadou_scene::{Backend, Frame, Image};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Threads that spin on floating-point work until dropped.
struct Load {
    stop: Arc<AtomicBool>,
    threads: Vec<std::thread::JoinHandle<()>>,
}

impl Load {
    fn start() -> Load {
        let stop = Arc::new(AtomicBool::new(false));
        let n = std::thread::available_parallelism().map_or(2, |n| n.get()) + 1;
        let threads = (0..n)
            .map(|i| {
                let stop = stop.clone();
                std::thread::spawn(move || {
                    let mut x = 1.0f64 + i as f64;
                    while !stop.load(Ordering::Relaxed) {
                        for _ in 0..10_000 {
                            x = (x * 1.000_000_1).sin().abs() + 1.0;
                        }
                        std::hint::black_box(x);
                    }
                })
            })
            .collect();
        Load { stop, threads }
    }
}

impl Drop for Load {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

/// For each of colour, energy and depth where two renders differ: how many values and the first
/// pixel (x, y); `None` when they are identical.
fn first_difference(a: &Image, b: &Image) -> Option<String> {
    let planes: [(&str, &[f32], &[f32], usize); 3] = [
        ("colour", bytemuck_f32(&a.color), bytemuck_f32(&b.color), 4),
        ("energy", &a.energy, &b.energy, 1),
        ("depth", &a.depth, &b.depth, 1),
    ];
    let mut out = Vec::new();
    for (name, x, y, per) in planes {
        let differing = (0..x.len()).filter(|&i| x[i].to_bits() != y[i].to_bits()).collect::<Vec<_>>();
        if let Some(&i) = differing.first() {
            let p = i / per;
            out.push(format!(
                "{name} differs at {} of {} values; first at pixel ({}, {}): {} then {}",
                differing.len(),
                x.len(),
                p % a.width as usize,
                p / a.width as usize,
                x[i],
                y[i]
            ));
        }
    }
    (!out.is_empty()).then(|| out.join("; "))
}

fn bytemuck_f32(c: &[[f32; 4]]) -> &[f32] {
    c.as_flattened()
}

/// Frames that exercise every pass: surfaces and outlines, plane and map shadows, an
/// `[area_light]`, analytic and curved waves; one of them wider than a tile.
fn frames() -> Vec<(String, Frame)> {
    let mut frames = example_frames(|n| {
        matches!(n, "kamehameha.toml" | "shadow-uneven.toml" | "soft-overlap.toml" | "fig4-2-helix.toml")
    });
    let mut wide = occlusion_frame(hadou_gpu::MAX_TILE + 33, 24);
    wide.width = hadou_gpu::MAX_TILE + 33;
    frames.push(("occlusion, two tiles".into(), wide));
    frames
}

#[test]
fn repeated_renders_under_load_are_bit_identical() {
    let frames = frames();
    let Some(mut gpu) = gpu_or_skip("determinism") else { return };
    let first: Vec<Image> =
        frames.iter().map(|(label, f)| gpu.render(f).unwrap_or_else(|e| panic!("{label}: {e}"))).collect();
    let _load = Load::start();
    let rounds = 4;
    let mut previous = frames.len() - 1;
    for round in 0..rounds {
        // Each round in another order (rotated, and reversed every other round), so a frame
        // follows a different one each time.
        let n = frames.len();
        for k in 0..n {
            let k = if round % 2 == 1 { n - 1 - k } else { k };
            let i = (k + round) % n;
            let (label, f) = &frames[i];
            let again = gpu.render(f).unwrap_or_else(|e| panic!("{label}: {e}"));
            if let Some(d) = first_difference(&first[i], &again) {
                let after = &frames[previous].0;
                panic!(
                    "{label}: render {} under load (after {after}) differs from the first: {d}",
                    round + 2
                );
            }
            previous = i;
        }
    }
}
