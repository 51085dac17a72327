//! What `hadou view` adds per image on the CPU path, measured apart from the window: for each of
//! `N` frames of a scene (times spread over its animation), the CPU backend's render
//! (`CpuBackend::render_into`), then the viewer's own work on that image: evaluating the frame
//! (`Scene::at`), converting the image to 8-bit sRGB RGBA (`hadou::view::srgba8_into`, into a buffer reused between frames as the window does) and uploading
//! it into a texture (`wgpu::Queue::write_texture` on the GPU backend's device, submitted).
//! Prints a table of medians, or JSON with `--json`.
//!
//! `cargo run --release -p hadou --example view_overhead -- SCENE [FRAMES] [--json]`

use hadou::gpu::wgpu;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    // As the hadou binary does: no Mesa device-selection layer (it wants a display).
    if std::env::var_os("NODEVICE_SELECT").is_none() {
        std::env::set_var("NODEVICE_SELECT", "1");
    }
    let args: Vec<String> = std::env::args().skip(1).collect();
    let json = args.iter().any(|a| a == "--json");
    let pos: Vec<&String> = args.iter().filter(|a| !a.starts_with("--")).collect();
    let Some(path) = pos.first() else {
        eprintln!("usage: view_overhead SCENE [FRAMES] [--json]");
        std::process::exit(2);
    };
    let frames: u32 = match pos.get(1).map(|s| s.parse()) {
        None => 30,
        Some(Ok(n)) if n > 0 => n,
        Some(_) => {
            eprintln!("FRAMES must be a whole number > 0");
            std::process::exit(2);
        }
    };
    let scene = match hadou::Scene::load(path.as_str()) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let gpu = match hadou::GpuBackend::new() {
        Ok(g) => g,
        Err(e) => {
            eprintln!("no GPU device for the upload: {e}");
            std::process::exit(1);
        }
    };
    let (device, queue) = (gpu.device(), gpu.queue());
    let (w, h) = (scene.width(), scene.height());
    let texture = hadou::view::viewport_texture(device, [w, h]);
    let mut cpu = hadou::CpuBackend::new();
    let mut image = hadou::Image::new(1, 1);
    let end = scene.duration().max(1.0);
    let mut rgba = Vec::new();
    let (mut render, mut eval, mut convert, mut upload) = (vec![], vec![], vec![], vec![]);
    for i in 0..=frames {
        let t = end * i as f32 / frames as f32;
        let t0 = Instant::now();
        let frame = scene.at(t);
        let t1 = Instant::now();
        cpu.render_into(&frame, &mut image);
        let t2 = Instant::now();
        hadou::view::srgba8_into(&image, &mut rgba);
        let t3 = Instant::now();
        hadou::view::upload_rgba(queue, &texture, &rgba, [w, h]);
        queue.submit([]);
        let t4 = Instant::now();
        let _ = device.poll(wgpu::PollType::wait_indefinitely());
        if i == 0 {
            continue; // warm-up
        }
        let ms = |a: Instant, b: Instant| (b - a).as_secs_f64() * 1e3;
        eval.push(ms(t0, t1));
        render.push(ms(t1, t2));
        convert.push(ms(t2, t3));
        upload.push(ms(t3, t4));
    }
    let (r, e, c, u) = (median(render), median(eval), median(convert), median(upload));
    let total = e + c + u;
    if json {
        println!(
            "{{\"scene\": \"{path}\", \"size\": [{w}, {h}], \"frames\": {frames}, \"render_ms\": {r:.3}, \"eval_ms\": {e:.4}, \"convert_ms\": {c:.3}, \"upload_ms\": {u:.3}, \"viewer_ms\": {total:.3}}}"
        );
    } else {
        println!("{path}: {w}×{h}, {frames} frames, medians (upload device: {})", gpu.adapter_name());
        println!("| part | ms |");
        println!("|---|---|");
        println!("| render (CPU backend) | {r:.2} |");
        println!("| frame evaluation (Scene::at) | {e:.3} |");
        println!("| sRGB RGBA conversion | {c:.3} |");
        println!("| texture upload (write_texture + submit) | {u:.3} |");
        println!("| **viewer total** | **{total:.3}** ({:.1} % of the render) |", 100.0 * total / r);
    }
}
