//! Times a scene file on the GPU backend with `GpuBackend::time_frame` at several square sizes
//! (the layout of thesis 002's tables) and prints one line per size, with the GPU time of each
//! pass when the adapter has timestamp queries.
//!
//! `cargo run --release -p hadou-gpu --example time_scene -- SCENE.toml [TIME] [SIZE...]`
//! (defaults: time 0, sizes 512 1024 2048; 5 timed iterations after one warm-up), then the wall
//! time of a whole `render` (preparation and read-back included) and of a PNG's rows, by
//! `render_rows_rgb8` (8-bit words from the wave pass) and by `render` converted on the CPU. `HADOU_UBER=1` times the
//! uber-shader instead of the frame's wave-pass variant. `HADOU_ITERS=N` times `N` iterations
//! and skips the wall-clock part: the process's CPU time at two values of `N` then gives the CPU
//! time of one frame (what docs/benchmarks.md's lavapipe tables call "CPU ms per frame"), which
//! other processes on the machine disturb far less than the wall time.

use hadou_gpu::GpuBackend;

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next() else {
        eprintln!("usage: time_scene SCENE.toml [TIME] [SIZE...]");
        std::process::exit(2);
    };
    let time: f32 = args.next().and_then(|a| a.parse().ok()).unwrap_or(0.0);
    let mut sizes: Vec<u32> = args.filter_map(|a| a.parse().ok()).collect();
    if sizes.is_empty() {
        sizes = vec![512, 1024, 2048];
    }
    let scene = match hadou_scene::Scene::load(&path) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let mut gpu = match GpuBackend::new() {
        Ok(g) => g,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    // HADOU_UBER=1: every frame on the uber-shader (all wave kinds and shading compiled in), the
    // wave pass before it was specialised, for before/after comparisons.
    if std::env::var("HADOU_UBER").is_ok_and(|v| v == "1") {
        gpu.set_specialise(false);
    }
    println!("adapter: {} (software: {})", gpu.adapter_name(), gpu.is_software());
    let iterations: Option<u32> = std::env::var("HADOU_ITERS").ok().and_then(|v| v.parse().ok());
    for size in sizes {
        let mut frame = scene.at(time);
        frame.width = size;
        frame.height = size;
        match gpu.time_frame(&frame, iterations.unwrap_or(5)) {
            Ok(t) => {
                let passes: Vec<String> =
                    t.passes.iter().map(|p| format!("{} {:.3} ms", p.name, p.median_ms)).collect();
                println!(
                    "{path} {size}²: median {:.3} ms, min {:.3} ms ({:.1} fps, {:?}, {} tile(s)){}{}",
                    t.median_ms,
                    t.min_ms,
                    t.fps(),
                    t.method,
                    t.tiles,
                    if passes.is_empty() { "" } else { "; passes: " },
                    passes.join(", ")
                )
            }
            Err(e) => println!("{path} {size}²: {e}"),
        }
        if iterations.is_some() {
            continue;
        }
        // The whole render as a caller sees it: preparation, every pass and the read-back; then
        // a PNG's rows, by the wave pass's 8-bit words and by the float image converted here
        // (the road a PNG took before the words).
        let wall = |gpu: &mut GpuBackend, draw: &dyn Fn(&mut GpuBackend) -> bool| -> f64 {
            draw(gpu);
            let mut v: Vec<f64> = (0..5)
                .map(|_| {
                    let start = std::time::Instant::now();
                    if draw(gpu) {
                        start.elapsed().as_secs_f64() * 1e3
                    } else {
                        f64::NAN
                    }
                })
                .collect();
            v.sort_by(f64::total_cmp);
            v[2]
        };
        let f = &frame;
        let floats = wall(&mut gpu, &|g| hadou_scene::Backend::render(g, f).is_ok());
        let words = wall(&mut gpu, &|g| hadou_scene::Backend::render_rows_rgb8(g, f, 0..f.height).is_ok());
        let converted = wall(&mut gpu, &|g| {
            hadou_scene::Backend::render(g, f)
                .ok()
                .and_then(|image| hadou_scene::Rgb8Image::from_image(&image))
                .is_some()
        });
        println!(
            "{path} {size}², wall clock with read-back, median of 5: render() {floats:.3} ms; \
             PNG rows: render_rows_rgb8() {words:.3} ms, render() + Rgb8Image::from_image {converted:.3} ms"
        );
    }
}
