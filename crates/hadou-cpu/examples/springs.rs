//! Times VRM spring bones against a CPU frame: `cargo run --release -p hadou-cpu --example springs
//! -- [SCENE] [SIZE] [TIME]` (default `scenes/light-blast.toml`, 512, 10 s: `assets/blast.vrm`'s
//! 192 turning spring joints in 28 springs with 4 colliders, blown by a beam). It prints the median
//! over nine runs of
//! - `cold`: `Scene::at(TIME)` on a freshly loaded scene: every step from time 0 (600 at 10 s),
//!   the posed mesh and the rest of the frame;
//! - `rest`: `Scene::at(0)` on a freshly loaded scene: no step, the same posing and frame build;
//! - `next`: `Scene::at` of the next step's time after the last (one step and the posing, as a
//!   sequence of frames or the viewer at 60 frames a second asks);
//! - `frame`: the CPU render of the frame at SIZE² (`hadou_cpu::render`);
//!
//! and the simulation's share of a frame, `(cold − rest) / frame`, and `next`'s.
use hadou_scene::Scene;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/light-blast.toml").to_string());
    let size: u32 =
        args.next().and_then(|a| a.parse().ok()).filter(|s| (1..=16384).contains(s)).unwrap_or(512);
    let t: f32 = args.next().and_then(|a| a.parse().ok()).filter(|t: &f32| t.is_finite()).unwrap_or(10.0);
    let load = || {
        Scene::load(&path).unwrap_or_else(|e| {
            eprintln!("{e}");
            std::process::exit(2)
        })
    };
    let time = |f: &mut dyn FnMut()| {
        let start = Instant::now();
        f();
        start.elapsed().as_secs_f64() * 1e3
    };
    let runs = 9;
    let cold = median(
        (0..runs)
            .map(|_| {
                let s = load();
                time(&mut || drop(s.at(t)))
            })
            .collect(),
    );
    let rest = median(
        (0..runs)
            .map(|_| {
                let s = load();
                time(&mut || drop(s.at(0.0)))
            })
            .collect(),
    );
    let s = load();
    let _ = s.at(t);
    let step = 1.0 / hadou_scene::SPRING_RATE as f32;
    let next = median((1..=runs).map(|k| time(&mut || drop(s.at(t + k as f32 * step)))).collect());
    let mut frame = s.at(t);
    (frame.width, frame.height) = (size, size);
    let _ = hadou_cpu::render(&frame);
    let render = median((0..runs).map(|_| time(&mut || drop(hadou_cpu::render(&frame)))).collect());
    let joints: usize = s.object_springs().iter().map(|j| j.0).sum();
    println!(
        "{path} at {t} s: {joints} spring joints, {} steps",
        (t as f64 * hadou_scene::SPRING_RATE).floor()
    );
    println!("cold {cold:.2} ms, rest {rest:.2} ms, next {next:.2} ms, frame {size}² {render:.2} ms");
    println!(
        "simulation from 0: {:.2} ms = {:.1} % of the frame; a frame in a sequence: {next:.2} ms = {:.2} %",
        cold - rest,
        100.0 * (cold - rest) / render,
        100.0 * next / render
    );
}
