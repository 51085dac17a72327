//! Shared helpers of the GPU tests: adapter-or-skip, hand-built frames, and the GPU↔CPU image
//! comparison with its stated tolerances.
#![allow(dead_code)]

use hadou_gpu::GpuBackend;
use hadou_math::energy::{BeamField, CapsuleField, CylinderField, Falloff, SphereField};
use hadou_math::{Mat4, Vec3, Vec3f};
use hadou_scene::{Camera, ColorMapping, Frame, Image, Light, Mesh, Object, ToneMode, Wave, WaveShape};
use std::sync::{Arc, Mutex, MutexGuard, OnceLock};

/// Every example scene in `scenes/` whose file name `keep` accepts, as `(label, frame)` at the
/// start, middle and end of its animation (once for a still scene), at 128×96, in file-name
/// order: the middle frame (a still scene's only one) with the scene's own anti-aliasing
/// (`[image] samples`), the start and end at one sample per pixel. Panics if none is kept or one
/// fails to load.
pub fn example_frames(keep: impl Fn(&str) -> bool) -> Vec<(String, Frame)> {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes");
    let mut paths: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
        .map(|e| e.expect("dir entry").path())
        .filter(|p| {
            p.extension().is_some_and(|x| x == "toml")
                && p.file_name().is_some_and(|n| keep(&n.to_string_lossy()))
        })
        .collect();
    paths.sort();
    assert!(!paths.is_empty(), "no matching scenes in {dir}");
    let mut out = Vec::new();
    for path in paths {
        let scene = hadou_scene::Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let name = path.file_name().unwrap_or_default().to_string_lossy().into_owned();
        let d = scene.duration();
        for t in [0.0, 0.5 * d, d] {
            let mut frame = scene.at(t);
            frame.width = 128;
            frame.height = 96;
            if d > 0.0 && t != 0.5 * d {
                frame.samples = 1;
            }
            out.push((format!("{name} t={t} samples={}", frame.samples), frame));
            if d == 0.0 {
                break;
            }
        }
    }
    out
}

/// The one GPU backend of this test binary, shared by its tests in turn, or `None` (with a clear
/// message on stderr) when this machine has no usable adapter. With `HADOU_REQUIRE_GPU=1` a
/// missing adapter fails the test instead.
///
/// Shared because opening a backend compiles the shaders (tens of seconds on a software adapter)
/// and because Mesa 22's lavapipe crashed (SIGSEGV) with several devices rendering at once from
/// parallel test threads; the lock serialises the GPU work of the tests.
pub fn gpu_or_skip(test: &str) -> Option<MutexGuard<'static, GpuBackend>> {
    static SHARED: OnceLock<Result<Mutex<GpuBackend>, String>> = OnceLock::new();
    match SHARED.get_or_init(|| GpuBackend::new().map(Mutex::new).map_err(|e| e.to_string())) {
        // A test that panicked while holding the lock leaves the backend usable.
        Ok(gpu) => Some(gpu.lock().unwrap_or_else(|p| p.into_inner())),
        Err(msg) if msg.starts_with("no usable device") => {
            if std::env::var("HADOU_REQUIRE_GPU").is_ok_and(|v| v == "1") {
                panic!("{test}: HADOU_REQUIRE_GPU=1 but no GPU adapter: {msg}");
            }
            eprintln!(
                "SKIPPED {test}: no GPU adapter ({msg}); set HADOU_REQUIRE_GPU=1 to make this a failure"
            );
            None
        }
        Err(e) => panic!("{test}: GPU backend failed to start: {e}"),
    }
}

/// An axis-aligned box mesh centred on the origin, outward normals, CCW faces.
pub fn box_mesh(size: [f32; 3]) -> Arc<Mesh> {
    let h = size.map(|s| s * 0.5);
    let mut m = Mesh::default();
    // (normal axis, sign)
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = m.positions.len() as u32;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                let mut p = [0.0f32; 3];
                p[axis] = sign * h[axis];
                p[u] = a * h[u];
                p[v] = b * h[v];
                let mut n = [0.0f32; 3];
                n[axis] = sign;
                m.positions.push(p);
                m.normals.push(n);
            }
            if sign > 0.0 {
                m.indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
            } else {
                m.indices.extend([base, base + 2, base + 1, base, base + 3, base + 2]);
            }
        }
    }
    Arc::new(m)
}

/// A UV sphere of radius `r` with smooth normals.
pub fn sphere_mesh(r: f32, seg: u32) -> Arc<Mesh> {
    let mut m = Mesh::default();
    let rings = seg / 2;
    for i in 0..=rings {
        let th = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..=seg {
            let ph = 2.0 * std::f32::consts::PI * j as f32 / seg as f32;
            let n = [th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()];
            m.positions.push(n.map(|c| c * r));
            m.normals.push(n);
        }
    }
    for i in 0..rings {
        for j in 0..seg {
            let a = i * (seg + 1) + j;
            let b = a + seg + 1;
            m.indices.extend([a, a + 1, b, a + 1, b + 1, b]);
        }
    }
    Arc::new(m)
}

/// A `size × size` plane quad in xz, normal +y.
pub fn plane_mesh(size: f32) -> Arc<Mesh> {
    let h = size * 0.5;
    Arc::new(Mesh {
        positions: vec![[-h, 0.0, -h], [h, 0.0, -h], [h, 0.0, h], [-h, 0.0, h]],
        normals: vec![[0.0, 1.0, 0.0]; 4],
        indices: vec![0, 2, 1, 0, 3, 2],
        ..Mesh::default()
    })
}

pub fn object(name: &str, mesh: Arc<Mesh>, pos: Vec3f, rot: Vec3f, color: [f32; 3]) -> Object {
    Object::new(name, mesh, Mat4::from_trs(pos, rot, Vec3::splat(1.0)), color)
}

pub fn wave(name: &str, color: [f32; 4], falloff: Falloff, core_radius: f32, shape: WaveShape) -> Wave {
    Wave::new(name, color, falloff, core_radius, shape)
}

/// A frame with a camera at `eye` looking at `target`, no objects or waves.
pub fn base_frame(width: u32, height: u32, eye: Vec3f, target: Vec3f, mode: ToneMode) -> Frame {
    Frame {
        width,
        height,
        time: 0.0,
        camera: Camera { position: eye, target, up: Vec3::Y, fov_y_deg: 45.0, near: 0.1, far: 100.0 },
        background: [0.02, 0.03, 0.05],
        light: Light {
            direction: Vec3::new(-0.3, -1.0, -0.5).normalize_or(Vec3::Y),
            color: [0.9, 0.9, 0.85],
            ambient: [0.1, 0.1, 0.12],
        },
        objects: Vec::new(),
        waves: Vec::new(),
        color_mapping: ColorMapping { mode, exposure: 1.0 },
        shadows: Vec::new(),
        area_light: None,
        bloom: None,
        samples: 1,
    }
}

/// The thesis's occlusion set-up (002 Fig. 4.14): a capsule beam between two cubes, faithful.
pub fn occlusion_frame(width: u32, height: u32) -> Frame {
    let mut f = base_frame(width, height, Vec3::new(0.0, 8.0, 40.0), Vec3::ZERO, ToneMode::Faithful);
    let cube = box_mesh([6.0, 6.0, 6.0]);
    f.objects.push(object(
        "a",
        cube.clone(),
        Vec3::new(0.0, 0.0, -20.0),
        Vec3::new(0.0, 30.0, 0.0),
        [0.8, 0.3, 0.2],
    ));
    f.objects.push(object("b", cube, Vec3::new(10.0, 0.0, 10.0), Vec3::ZERO, [0.2, 0.6, 0.9]));
    f.waves.push(wave(
        "beam",
        [0.8, 0.8, 0.2, 1.0],
        Falloff::Faithful,
        0.02,
        WaveShape::Capsule(CapsuleField {
            m: Vec3::new(-15.0, 0.0, 0.0),
            d: Vec3::new(1.0, 0.0, -0.2).normalize_or(Vec3::X),
            length: 25.0,
            alpha_s: 20.0,
            alpha_c: 20.0,
        }),
    ));
    f.waves.push(wave(
        "ball",
        [0.3, 0.5, 1.0, 1.0],
        Falloff::Faithful,
        0.02,
        WaveShape::Sphere(SphereField { center: Vec3::new(5.0, 4.0, 0.0), alpha: 10.0 }),
    ));
    f
}

/// A bulged beam over a ground plane with a sphere, inverse-square falloff, filmic mapping.
pub fn kamehameha_frame(width: u32, height: u32) -> Frame {
    let mut f =
        base_frame(width, height, Vec3::new(6.0, 3.0, 12.0), Vec3::new(0.0, 1.0, 0.0), ToneMode::Filmic);
    f.objects.push(object(
        "ground",
        plane_mesh(40.0),
        Vec3::new(0.0, -1.0, 0.0),
        Vec3::ZERO,
        [0.5, 0.5, 0.45],
    ));
    f.objects.push(object(
        "ball",
        sphere_mesh(1.5, 24),
        Vec3::new(-3.0, 0.5, -2.0),
        Vec3::ZERO,
        [0.9, 0.8, 0.7],
    ));
    f.waves.push(wave(
        "kamehameha",
        [0.4, 0.7, 1.0, 1.0],
        Falloff::InverseSquare,
        0.05,
        WaveShape::Beam(BeamField {
            capsule: CapsuleField {
                m: Vec3::new(-4.0, 1.0, 0.0),
                d: Vec3::new(1.0, 0.1, 0.2).normalize_or(Vec3::X),
                length: 8.0,
                alpha_s: 0.3,
                alpha_c: 0.3,
            },
            head_alpha: 0.8,
            muzzle_alpha: 0.2,
        }),
    ));
    f
}

/// An infinite cylinder seen almost along its axis (the thesis's "bloat" case), filmic.
pub fn axis_view_frame(width: u32, height: u32) -> Frame {
    let mut f = base_frame(width, height, Vec3::new(0.0, 0.3, 10.0), Vec3::ZERO, ToneMode::Filmic);
    f.waves.push(wave(
        "pillar",
        [1.0, 0.4, 0.2, 1.0],
        Falloff::InverseSquare,
        0.05,
        WaveShape::Cylinder(CylinderField { point: Vec3::ZERO, dir: Vec3::new(0.0, 0.0, 1.0), alpha: 0.2 }),
    ));
    f.waves.push(wave(
        "faithful pillar",
        [0.2, 1.0, 0.4, 1.0],
        Falloff::Faithful,
        0.05,
        WaveShape::Cylinder(CylinderField { point: Vec3::new(1.0, 0.0, 0.0), dir: Vec3::Y, alpha: 5.0 }),
    ));
    f
}

/// Outcome of [`compare`].
#[derive(Debug)]
pub struct Comparison {
    /// Pixels that differ beyond tolerance but lie on a silhouette of the CPU image.
    pub silhouette: usize,
    /// Pixels that differ beyond tolerance elsewhere (must be 0).
    pub interior: usize,
    /// Pixels compared.
    pub pixels: usize,
    /// Largest relative energy error among energies above the floor (all pixels within tolerance).
    pub max_energy_rel: f32,
    /// Largest absolute colour error (all pixels within tolerance).
    pub max_color_abs: f32,
    /// Description of the first out-of-tolerance interior pixel, if any.
    pub first_bad: Option<String>,
}

/// Relative energy tolerance where the energy is above the floor.
pub const ENERGY_REL: f32 = 1e-3;
/// Absolute colour tolerance after mapping.
pub const COLOR_ABS: f32 = 2e-3;
/// Share of the image allowed to differ on silhouettes: the two rasterizers (GPU hardware/lavapipe
/// and the CPU reference) may decide coverage differently for pixel centres that lie within
/// rounding distance of a triangle edge.
pub const SILHOUETTE_SHARE: f64 = 0.005;

/// Whether pixel `i` of the CPU image lies on a geometric edge: some 8-neighbour's eye distance
/// differs by more than 1 % or its colour by more than 0.02 in a channel (a silhouette, a crease
/// between faces, or the occlusion boundary of a wave).
fn on_edge(img: &Image, x: u32, y: u32) -> bool {
    let i = img.index(x, y);
    for dy in -1i64..=1 {
        for dx in -1i64..=1 {
            let (nx, ny) = (x as i64 + dx, y as i64 + dy);
            if nx < 0 || ny < 0 || nx >= img.width as i64 || ny >= img.height as i64 {
                continue;
            }
            let j = img.index(nx as u32, ny as u32);
            let (a, b) = (img.depth[i], img.depth[j]);
            if (a - b).abs() > 0.01 * a.abs().max(b.abs()) {
                return true;
            }
            if (0..3).any(|k| (img.color[i][k] - img.color[j][k]).abs() > 0.02) {
                return true;
            }
        }
    }
    false
}

/// Compares a GPU image with the CPU reference (tolerances: [`ENERGY_REL`], [`COLOR_ABS`],
/// [`SILHOUETTE_SHARE`]). Energies are compared relatively where `max(|gpu|, |cpu|)` is above a
/// floor of 1e-5 × the image's largest energy (below it, absolutely against that floor).
pub fn compare(gpu: &Image, cpu: &Image) -> Comparison {
    assert_eq!((gpu.width, gpu.height), (cpu.width, cpu.height));
    let max_e = cpu.energy.iter().copied().fold(0.0f32, f32::max);
    let floor = (1e-5 * max_e).max(1e-12);
    let mut c = Comparison {
        silhouette: 0,
        interior: 0,
        pixels: cpu.energy.len(),
        max_energy_rel: 0.0,
        max_color_abs: 0.0,
        first_bad: None,
    };
    for y in 0..cpu.height {
        for x in 0..cpu.width {
            let i = cpu.index(x, y);
            let (eg, ec) = (gpu.energy[i], cpu.energy[i]);
            assert!(eg.is_finite() && gpu.depth[i].is_finite(), "non-finite GPU value at ({x}, {y})");
            assert!(gpu.color[i].iter().all(|v| v.is_finite()), "non-finite GPU colour at ({x}, {y})");
            let scale = eg.abs().max(ec.abs()).max(floor);
            let e_rel = (eg - ec).abs() / scale;
            let c_abs = (0..4).map(|k| (gpu.color[i][k] - cpu.color[i][k]).abs()).fold(0.0, f32::max);
            let (dg, dc) = (gpu.depth[i], cpu.depth[i]);
            let d_rel = (dg - dc).abs() / dg.abs().max(dc.abs()).max(1e-6);
            if e_rel <= ENERGY_REL && c_abs <= COLOR_ABS && d_rel <= 1e-3 {
                c.max_energy_rel = c.max_energy_rel.max(if scale > floor { e_rel } else { 0.0 });
                c.max_color_abs = c.max_color_abs.max(c_abs);
                continue;
            }
            if on_edge(cpu, x, y) {
                c.silhouette += 1;
            } else {
                c.interior += 1;
                if c.first_bad.is_none() {
                    c.first_bad = Some(format!(
                        "pixel ({x}, {y}): energy gpu {eg} cpu {ec} (rel {e_rel:.2e}); colour gpu {:?} cpu {:?}; \
                         depth gpu {dg} cpu {dc}",
                        gpu.color[i], cpu.color[i]
                    ));
                }
            }
        }
    }
    c
}

/// Asserts that `c` is within the stated tolerances.
pub fn assert_close(name: &str, c: &Comparison) {
    eprintln!(
        "{name}: {} px, silhouette {} ({:.3} %), interior {}, max energy rel {:.2e}, max colour abs {:.2e}",
        c.pixels,
        c.silhouette,
        100.0 * c.silhouette as f64 / c.pixels as f64,
        c.interior,
        c.max_energy_rel,
        c.max_color_abs
    );
    assert_eq!(c.interior, 0, "{name}: {} interior pixels differ; first: {:?}", c.interior, c.first_bad);
    assert!(
        (c.silhouette as f64) <= SILHOUETTE_SHARE * c.pixels as f64,
        "{name}: {} silhouette pixels differ, more than {} % of {}",
        c.silhouette,
        100.0 * SILHOUETTE_SHARE,
        c.pixels
    );
}
