//! Renders a 4096² frame (a bulged beam over a ground plane and a box) with the GPU backend and
//! prints the process's peak resident memory before and after, next to the size of the `Image`
//! itself. On a software adapter (lavapipe) GPU memory is process memory, so the difference is
//! the backend's whole footprint.
//!
//! `cargo run --release -p hadou-gpu --example peak_memory [SIZE]`

use hadou_gpu::GpuBackend;
use hadou_math::energy::{BeamField, CapsuleField, Falloff};
use hadou_math::{Mat4, Vec3};
use hadou_scene::{Backend, Camera, ColorMapping, Frame, Light, Mesh, Object, ToneMode, Wave, WaveShape};
use std::sync::Arc;

fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

fn quad(size: f32) -> Arc<Mesh> {
    let h = size * 0.5;
    Arc::new(Mesh {
        positions: vec![[-h, 0.0, -h], [h, 0.0, -h], [h, 0.0, h], [-h, 0.0, h]],
        normals: vec![[0.0, 1.0, 0.0]; 4],
        indices: vec![0, 2, 1, 0, 3, 2],
        ..Mesh::default()
    })
}

fn main() {
    let size: u32 = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(4096);
    let frame = Frame {
        width: size,
        height: size,
        time: 0.0,
        camera: Camera {
            position: Vec3::new(6.0, 3.0, 12.0),
            target: Vec3::new(0.0, 1.0, 0.0),
            up: Vec3::Y,
            fov_y_deg: 45.0,
            near: 0.1,
            far: 100.0,
        },
        background: [0.02, 0.03, 0.05],
        light: Light { direction: Vec3::new(0.0, -1.0, 0.0), color: [1.0; 3], ambient: [0.1; 3] },
        objects: vec![Object::new(
            "ground",
            quad(40.0),
            Mat4::translation(Vec3::new(0.0, -1.0, 0.0)),
            [0.5, 0.5, 0.45],
        )],
        waves: vec![Wave {
            light: Default::default(),
            name: "beam".into(),
            color: [0.4, 0.7, 1.0, 1.0],
            falloff: Falloff::InverseSquare,
            core_radius: 0.05,
            attenuation: 0.0,
            shape: WaveShape::Beam(BeamField {
                capsule: CapsuleField {
                    m: Vec3::new(-4.0, 1.0, 0.0),
                    d: Vec3::X,
                    length: 8.0,
                    alpha_s: 0.3,
                    alpha_c: 0.3,
                },
                head_alpha: 0.8,
                muzzle_alpha: 0.2,
            }),
        }],
        color_mapping: ColorMapping { mode: ToneMode::Filmic, exposure: 1.0 },
        shadows: Vec::new(),
        area_light: None,
        bloom: None,
        samples: 1,
    };
    let before = peak_rss_mib().unwrap_or(f64::NAN);
    let mut gpu = match GpuBackend::new() {
        Ok(g) => g,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    let after_init = peak_rss_mib().unwrap_or(f64::NAN);
    let start = std::time::Instant::now();
    let image = match gpu.render(&frame) {
        Ok(i) => i,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    let elapsed = start.elapsed();
    let after = peak_rss_mib().unwrap_or(f64::NAN);
    let image_mib =
        (image.color.len() * 16 + image.energy.len() * 4 + image.depth.len() * 4) as f64 / 1048576.0;
    println!("adapter: {} (software: {})", gpu.adapter_name(), gpu.is_software());
    println!("image {size}×{size}: Image buffers {image_mib:.1} MiB; render {:.2} s", elapsed.as_secs_f64());
    println!(
        "peak RSS: {before:.1} MiB at start, {after_init:.1} MiB after device set-up, {after:.1} MiB after render"
    );
    println!("backend overhead beyond the Image: {:.1} MiB", after - after_init - image_mib);
}
