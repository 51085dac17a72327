//! Splits the soft-shadow stage of `scenes/soft-gradient.toml` into its parts: the maps' fit, the
//! two maps, the classes, and each resolve. `cargo run --release -p hadou --example soft_parts [SIZE]`.

use hadou_cpu::soft::{classify, fitted_maps, soft_input, visibility, SpotDepth};
use hadou_scene::{Scene, SoftResolve};
use std::time::Instant;

fn median(mut f: impl FnMut()) -> f64 {
    f();
    let mut v: Vec<f64> = (0..9)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let size: u32 = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(512);
    let scene = Scene::load("scenes/soft-gradient.toml").expect("run from the repository root");
    let mut frame = scene.at(0.0);
    frame.width = size;
    frame.height = size;
    let light = frame.area_light.clone().expect("area light");
    let input = soft_input(&frame).expect("area light");
    let fit_ms = median(|| {
        let _ = fitted_maps(&light, &input);
    });
    let fitted = fitted_maps(&light, &input);
    let maps_ms = median(|| {
        let _ = rayon::join(
            || SpotDepth::render(&frame, &light.casters, &fitted[0], light.map_size),
            || SpotDepth::render(&frame, &light.casters, &fitted[1], light.map_size),
        );
    });
    let maps = fitted.map(|m| SpotDepth::render(&frame, &light.casters, &m, light.map_size));
    let class_ms = median(|| {
        let _ = classify(&maps, &input);
    });
    println!("{size}²: fit {fit_ms:.2} ms, maps {maps_ms:.2} ms, classes {class_ms:.2} ms");
    for (name, r) in [("exact", SoftResolve::Exact), ("faithful-n3", SoftResolve::Faithful { n: 3 })] {
        let ms = median(|| {
            let _ = visibility(&frame, &light, &input, r);
        });
        println!("{name}: whole stage {ms:.2} ms, resolve ≈ {:.2} ms", ms - fit_ms - maps_ms - class_ms);
    }
}
