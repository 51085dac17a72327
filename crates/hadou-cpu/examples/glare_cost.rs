//! Times a `[bloom]` against none: `cargo run --release -p hadou-cpu --example glare_cost --
//! [SIZES]` renders `scenes/glare-kamehameha.toml` at t = 1.5 s with its `[bloom]` and with it
//! removed, the two alternating (so a busy machine slows both alike), and prints per size the
//! median of nine whole frames of each (`CpuBackend::render_into`, buffers reused) and their
//! ratio, the bloom frame's colour stage (the glare and the colour mapping) against the one
//! without, and the two frames' opaque and wave passes (which the bloom frame runs into its
//! linear colour). `SIZES` is a comma-separated list (default `512,1024`).
use hadou_cpu::CpuBackend;
use hadou_scene::{Frame, Image, Scene};
use std::path::PathBuf;
use std::time::Instant;

/// The median of `v` (non-empty).
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let sizes: Vec<u32> = match std::env::args().nth(1) {
        None => vec![512, 1024],
        Some(a) => a
            .split(',')
            .map(|s| match s.trim().parse::<u32>() {
                Ok(n) if (1..=8192).contains(&n) => n,
                _ => {
                    eprintln!("glare_cost: size {s}: expected a whole number in 1..=8192");
                    std::process::exit(2)
                }
            })
            .collect(),
    };
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/glare-kamehameha.toml");
    let scene = Scene::load(&path).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2)
    });
    println!(
        "| size | bloom ms | no bloom ms | bloom / none | colour stage, bloom / none ms | opaque + waves, bloom / none ms |\n|---|---|---|---|---|---|"
    );
    let (mut backend, mut image) = (CpuBackend::new(), Image::new(1, 1));
    for size in sizes {
        let mut frame = scene.at(1.5);
        (frame.width, frame.height, frame.samples) = (size, size, 1);
        let bare = Frame { bloom: None, ..frame.clone() };
        // One frame of each first (the thread pool, the buffers), then nine pairs.
        backend.render_into(&frame, &mut image);
        backend.render_into(&bare, &mut image);
        let (mut on, mut off, mut con, mut coff) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let (mut won, mut woff) = (Vec::new(), Vec::new());
        for _ in 0..9 {
            for (f, times, color, waves) in
                [(&frame, &mut on, &mut con, &mut won), (&bare, &mut off, &mut coff, &mut woff)]
            {
                let t = Instant::now();
                let parts = backend.render_into(f, &mut image);
                times.push(t.elapsed().as_secs_f64() * 1e3);
                color.push(parts.color_ms);
                waves.push(parts.opaque_ms + parts.wave_ms);
            }
        }
        let (on, off) = (median(on), median(off));
        let (con, coff, won, woff) = (median(con), median(coff), median(won), median(woff));
        println!(
            "| {size}² | {on:.2} | {off:.2} | {:.2}× | {con:.2} / {coff:.2} | {won:.2} / {woff:.2} |",
            on / off
        );
    }
}
