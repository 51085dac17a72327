//! Times a scene file on the GPU backend with `GpuBackend::time_frame` at several square sizes
//! (the layout of thesis 002's tables) and prints one line per size.
//!
//! `cargo run --release -p hadou-gpu --example time_scene -- SCENE.toml [TIME] [SIZE...]`
//! (defaults: time 0, sizes 512 1024 2048; 5 timed iterations after one warm-up).

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
    println!("adapter: {} (software: {})", gpu.adapter_name(), gpu.is_software());
    for size in sizes {
        let mut frame = scene.at(time);
        frame.width = size;
        frame.height = size;
        match gpu.time_frame(&frame, 5) {
            Ok(t) => println!(
                "{path} {size}²: median {:.3} ms, min {:.3} ms ({:.1} fps, {:?}, {} tile(s))",
                t.median_ms,
                t.min_ms,
                t.fps(),
                t.method,
                t.tiles
            ),
            Err(e) => println!("{path} {size}²: {e}"),
        }
    }
}
