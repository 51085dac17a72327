//! The batched wave pass (eight pixels at a time, `hadou_math::energy::lanes`) renders what the
//! scalar kernels give pixel by pixel: every example scene without opaque objects, at a width that
//! is not a multiple of eight (the last batch of each row is partial) and at its start and end,
//! against the scalar `f32` kernels along the rays of `CameraBasis::wave_ray`; and `probe`, which
//! puts its pixel in the first lane, reports what the render put in that pixel.

use hadou_cpu::{probe, render};
use hadou_math::curve;
use hadou_math::energy::{self, FieldParams};
use hadou_scene::{Frame, Scene, WaveShape};
use std::path::PathBuf;

fn scenes_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// Each wave's scalar energy at pixel `(x, y)` with nothing drawn there, summed and saturated.
fn scalar_energy(frame: &Frame, x: u32, y: u32) -> f32 {
    let basis = frame.camera.basis(frame.width, frame.height);
    let mut total = 0.0f32;
    for w in &frame.waves {
        let wr =
            basis.wave_ray(w.falloff, frame.camera.far, x as f32, y as f32, frame.width, frame.height, None);
        let p = FieldParams { falloff: w.falloff, core_radius: w.core_radius };
        let (r, t0, t1) = (&wr.ray, wr.t0, wr.t1);
        // The analytic kinds' attenuation (002 eq. 3.23); j = 0 is the plain closed form.
        let a = &w.attenuation_on(wr.t_far);
        let e = match &w.shape {
            WaveShape::Sphere(f) => energy::sphere_energy_attenuated(&p, r, t0, t1, a, f),
            WaveShape::Cylinder(f) => energy::cylinder_energy_attenuated(&p, r, t0, t1, a, f),
            WaveShape::Capsule(f) => energy::capsule_energy_attenuated(&p, r, t0, t1, a, f),
            WaveShape::Beam(f) => energy::beam_energy_attenuated(&p, r, t0, t1, a, f),
            WaveShape::Curve(c) => curve::curve_energy(&curve::prepare(c), &p, r, t0, t1, wr.t_far).energy,
        };
        total = energy::saturate(total + energy::saturate(e));
    }
    total
}

#[test]
fn the_batched_pass_matches_the_scalar_kernels_on_every_wave_only_scene() {
    let mut checked = 0;
    for entry in std::fs::read_dir(scenes_dir()).expect("scenes/") {
        let path = entry.expect("entry").path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        for t in [0.0, scene.duration()] {
            let mut frame = scene.at(t);
            if !frame.objects.is_empty() || frame.waves.is_empty() || frame.area_light.is_some() {
                continue;
            }
            (frame.width, frame.height) = (37, 23);
            let img = render(&frame);
            let peak = img.energy.iter().copied().fold(0.0f32, f32::max);
            for y in 0..frame.height {
                for x in 0..frame.width {
                    let got = img.energy[img.index(x, y)];
                    let want = scalar_energy(&frame, x, y);
                    assert!(got.is_finite() && got >= 0.0, "{}: ({x}, {y}) {got}", path.display());
                    // Curves: the same integrator per pixel, bit for bit; analytic shapes: the
                    // lanes' logarithm and atan2 against the library's, a few ulp.
                    let tol = 2e-5 * want.abs() + 1e-6 * peak;
                    assert!(
                        (got - want).abs() <= tol,
                        "{} t={t} ({x}, {y}): batched {got}, scalar {want}",
                        path.display()
                    );
                }
            }
            checked += 1;
        }
    }
    assert!(checked >= 10, "only {checked} wave-only frames found");
}

#[test]
fn probe_reports_the_rendered_pixel_whatever_its_lane() {
    for file in ["fig4-14-occlusion.toml", "kamehameha.toml", "spiral-drill.toml", "light-from-front.toml"] {
        let scene = Scene::load(scenes_dir().join(file)).unwrap_or_else(|e| panic!("{e}"));
        let mut frame = scene.at(scene.duration() * 0.5);
        (frame.width, frame.height) = (45, 30);
        // A probe reports the pixel's centre at one sample.
        frame.samples = 1;
        let img = render(&frame);
        for (x, y) in [(0, 0), (7, 3), (8, 15), (22, 14), (44, 29), (41, 10)] {
            let p = probe(&frame, x, y).expect("inside");
            let i = img.index(x, y);
            let sum = p.waves.iter().fold(0.0f32, |t, w| energy::saturate(t + w.energy));
            assert_eq!(sum.to_bits(), img.energy[i].to_bits(), "{file} ({x}, {y}) energy");
            assert_eq!(p.color, img.color[i], "{file} ({x}, {y}) colour");
            assert_eq!(p.depth, img.depth[i], "{file} ({x}, {y}) depth");
        }
    }
}

#[test]
fn frames_drawn_into_reused_buffers_equal_fresh_renders() {
    // One backend and one image through scenes of other sizes, objects, shadows and an area
    // light: each frame equals its fresh render bit for bit (nothing left over from the last).
    let mut cpu = hadou_cpu::CpuBackend::new();
    let mut image = hadou_scene::Image::new(0, 0);
    let sizes = [(64, 48), (33, 17), (64, 48), (40, 40)];
    for (k, file) in ["fig4-14-occlusion.toml", "shadow-sunset.toml", "soft-gradient.toml", "kamehameha.toml"]
        .iter()
        .enumerate()
    {
        let scene = Scene::load(scenes_dir().join(file)).unwrap_or_else(|e| panic!("{e}"));
        let mut frame = scene.at(0.0);
        (frame.width, frame.height) = sizes[k];
        cpu.render_into(&frame, &mut image);
        assert_eq!(image, render(&frame), "{file}");
    }
}
