//! Times the traced resolve of a soft scene for each lamp shape (hierarchy built once):
//! `cargo run --release -p hadou --example traced_parts -- [SCENE] [SIZE] [SAMPLES]`, e.g.
//! `scenes/soft-plaster.toml 512 256`, and a shape's name to time only that one. Prints each shape's median over 5 runs and the pixels
//! that asked for work. With `HADOU_GRID=2` the points are the sample frame's of 2 × 2 samples a
//! pixel (a `SIZE`² image, `(2·SIZE)`² points), each stage timed sample by sample
//! (`traced_with`) and with one value per pixel where the samples agree (`traced_grid`), in
//! turn. Each line ends with a hash of the values' bits, to tell whether a change to the resolve
//! kept its images.

use hadou_cpu::soft::soft_input;
use hadou_cpu::traced::traced_grid_counted;
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
    let grid: usize = std::env::var("HADOU_GRID").ok().and_then(|s| s.parse().ok()).unwrap_or(1).max(1);
    let mut frame = scene.at(0.0);
    frame.width = size * grid as u32;
    frame.height = size * grid as u32;
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
        let kinds: &[usize] = if grid > 1 { &[1, grid] } else { &[1] };
        let mut times = vec![Vec::new(); kinds.len()];
        let mut counts = vec![None; kinds.len()];
        let mut hashes = vec![0u64; kinds.len()];
        for round in 0..6 {
            for (slot, &k) in kinds.iter().enumerate() {
                let t = Instant::now();
                let (v, count) = traced_grid_counted(&bvh, &lamp, &input.points, input.width, samples, k);
                // FNV-1a over the values' bits.
                hashes[slot] = v.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, x| {
                    (h ^ u64::from(x.to_bits())).wrapping_mul(0x0000_0100_0000_01b3)
                });
                counts[slot] = Some(count);
                if round > 0 {
                    times[slot].push(t.elapsed().as_secs_f64() * 1e3);
                }
            }
        }
        for (((t, &k), count), hash) in times.iter_mut().zip(kinds).zip(&counts).zip(&hashes) {
            t.sort_by(f64::total_cmp);
            let how = if k == 1 { "each point" } else { "per pixel" };
            let settled = match count {
                Some(c) if k > 1 => format!(", {} of {} pixels traced once", c.settled, c.pixels),
                _ => String::new(),
            };
            println!(
                "{name:8} {how:10} {:8.2} ms (fastest {:.2}){settled}, bits {hash:016x}",
                t[t.len() / 2],
                t[0]
            );
        }
    }
}
