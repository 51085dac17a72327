//! Times the CPU backend's passes on one scene: `cargo run --release -p hadou-cpu --example parts
//! -- SCENE [SIZE] [TIME] [SAMPLES]` prints the median whole render and its opaque, wave and colour parts
//! over nine runs, on every vector path the CPU supports, into the float image
//! (`CpuBackend::render_into_on`) and into 8-bit sRGB (`CpuBackend::render_rgb8_into`), reusing
//! the buffers.
use hadou_scene::Scene;

/// Prints `msg` and exits with status 2 (bad arguments).
fn usage(msg: &str) -> ! {
    eprintln!("parts: {msg}\nusage: parts SCENE [SIZE in 1..=16384] [TIME ≥ 0] [SAMPLES: 1, 4, 9 or 16]");
    std::process::exit(2);
}

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next() else { usage("missing SCENE") };
    let scene = Scene::load(&path).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2)
    });
    let size = match args.next() {
        None => 1024,
        Some(a) => match a.parse::<u32>() {
            Ok(s) if (1..=16384).contains(&s) => s,
            _ => usage(&format!("SIZE {a}: expected a whole number of pixels in 1..=16384")),
        },
    };
    let t = match args.next() {
        None => 0.0,
        Some(a) => match a.parse::<f32>() {
            Ok(t) if t.is_finite() && t >= 0.0 => t,
            _ => usage(&format!("TIME {a}: expected a finite number of seconds ≥ 0")),
        },
    };
    let mut frame = scene.at(t);
    (frame.width, frame.height) = (size, size);
    if let Some(a) = args.next() {
        match a.parse::<u32>() {
            Ok(s) if hadou_scene::check_samples(s).is_ok() => frame.samples = s,
            _ => usage(&format!("SAMPLES {a}: expected 1, 4, 9 or 16")),
        }
    }
    let mut cpu = hadou_cpu::CpuBackend::new();
    for simd in hadou_math::simd::SimdPath::supported() {
        let mut image = hadou_scene::Image::new(0, 0);
        let mut bytes = hadou_scene::Rgb8Image::default();
        for (what, mut draw) in [
            (
                "float",
                Box::new(|cpu: &mut hadou_cpu::CpuBackend| cpu.render_into_on(&frame, &mut image, simd))
                    as Box<dyn FnMut(&mut hadou_cpu::CpuBackend) -> hadou_cpu::PassTimes>,
            ),
            (
                "sRGB8",
                Box::new(|cpu: &mut hadou_cpu::CpuBackend| cpu.render_rgb8_into(&frame, &mut bytes, simd)),
            ),
        ] {
            draw(&mut cpu);
            let mut runs: Vec<(f64, hadou_cpu::PassTimes)> = (0..9)
                .map(|_| {
                    let start = std::time::Instant::now();
                    let p = draw(&mut cpu);
                    (start.elapsed().as_secs_f64() * 1e3, p)
                })
                .collect();
            runs.sort_by(|a, b| a.0.total_cmp(&b.0));
            let (ms, p) = runs[runs.len() / 2];
            let mpx = (size as f64).powi(2) / (ms * 1e3);
            println!(
                "{path} {size}² × {} samples, {simd}, {what}: {ms:.2} ms ({mpx:.1} Mpx/s) = opaque {:.2} + wave {:.2} + colour {:.2}",
                frame.samples, p.opaque_ms, p.wave_ms, p.color_ms
            );
        }
    }
}
