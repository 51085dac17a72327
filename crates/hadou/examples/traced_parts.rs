//! Times the traced resolve of a soft scene for each lamp shape (hierarchy built once):
//! `cargo run --release -p hadou --example traced_parts -- [SCENE] [SIZE] [SAMPLES]`, e.g.
//! `scenes/soft-plaster.toml 512 256`, and a shape's name to time only that one. Prints each shape's median over 5 runs and the pixels
//! that asked for work.

use hadou_cpu::soft::soft_input;
use hadou_cpu::traced::traced_with;
use hadou_math::soft::{Bvh, LampShape};
use hadou_scene::{caster_triangles, AreaLight, Scene};
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args.next().unwrap_or_else(|| "scenes/soft-gradient.toml".into());
    let size: u32 = args.next().and_then(|s| s.parse().ok()).unwrap_or(512);
    let samples: u32 = args.next().and_then(|s| s.parse().ok()).unwrap_or(256);
    let only = args.next();
    let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let mut frame = scene.at(0.0);
    frame.width = size;
    frame.height = size;
    let light = frame.area_light.clone().expect("the scene has an [area_light]");
    let input = soft_input(&frame).expect("area light");
    let t = Instant::now();
    let bvh = Bvh::build(&caster_triangles(&frame, &light.casters));
    let build_ms = t.elapsed().as_secs_f64() * 1e3;
    println!("{path} {size}² {samples} samples: {} triangles, hierarchy {build_ms:.2} ms", bvh.tris.len());
    for (name, shape) in
        [("segment", LampShape::Segment), ("disc", LampShape::Disc), ("sphere", LampShape::Sphere)]
    {
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        let lamp = AreaLight { shape, ..light.clone() };
        let mut times: Vec<f64> = (0..6)
            .map(|_| {
                let t = Instant::now();
                let v = traced_with(&bvh, &lamp, &input.points, input.width, samples);
                std::hint::black_box(v);
                t.elapsed().as_secs_f64() * 1e3
            })
            .skip(1)
            .collect();
        times.sort_by(f64::total_cmp);
        println!("{name:8} {:8.2} ms (fastest {:.2})", times[times.len() / 2], times[0]);
    }
}
