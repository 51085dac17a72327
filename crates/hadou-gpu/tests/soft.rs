//! GPU ↔ CPU on the `[area_light]`'s soft shadows: every `scenes/soft-*.toml` at the start, middle
//! and end of its animation, at 128×96, with its own resolve, the faithful resolve at `n = 3`, and
//! the exact resolve without the depth-aware search.
//!
//! Tolerances: the two backends' maps and visible points agree to rounding (the rasterizers round
//! differently), so a pixel whose stored and looked-up depths lie within an ulp of the bias may
//! change class. At most [`CLASS_FLIP_SHARE`] of the pixels may differ in class; the colour is
//! within the differential tests' `COLOR_ABS` on all but [`COLOR_SHARE`] of the pixels. Where
//! every class agrees and the search is not depth-aware, the GPU's visibility equals the CPU's
//! exactly, pixel for pixel; otherwise it equals it at all but [`VIS_SHARE`] of the pixels whose
//! class agrees (a flipped class moves its neighbours' nearest umbra or lit pixel).

mod common;

use common::*;
use hadou_cpu::soft::{classify, fitted_maps, soft_input, visibility, SpotDepth};
use hadou_cpu::CpuBackend;
use hadou_scene::{Backend, Frame, SoftResolve};

/// Largest share of pixels whose class may differ.
const CLASS_FLIP_SHARE: f64 = 0.005;
/// Largest share of pixels whose colour may differ beyond `COLOR_ABS`.
const COLOR_SHARE: f64 = 0.01;
/// Largest share of same-class pixels whose visibility may differ.
const VIS_SHARE: f64 = 0.01;

/// The pixels of `g` whose colour differs from `c`'s by more than `COLOR_ABS` in a channel (or is
/// NaN).
fn colours_beyond(g: &hadou_scene::Image, c: &hadou_scene::Image) -> usize {
    g.color
        .iter()
        .zip(&c.color)
        .filter(|(g, c)| {
            (0..4).any(|k| {
                let d = (g[k] - c[k]).abs();
                d.is_nan() || d > COLOR_ABS
            })
        })
        .count()
}

fn check(gpu: &mut hadou_gpu::GpuBackend, label: &str, frame: &Frame) {
    let (g, soft) = gpu.render_soft(frame).unwrap_or_else(|e| panic!("{label}: GPU render failed: {e}"));
    let (g_class, g_vis) = soft.expect("an area light");
    let c = CpuBackend::new().render(frame).unwrap_or_else(|e| panic!("{label}: CPU render failed: {e}"));
    let light = frame.area_light.as_ref().expect("an area light");
    let input = soft_input(frame).expect("an area light");
    let maps =
        fitted_maps(light, &input).map(|m| SpotDepth::render(frame, &light.casters, &m, light.map_size));
    let c_class = classify(&maps, &input);
    let c_vis = visibility(frame, light, &input, light.resolve);
    let n = g_class.len();
    assert_eq!(n, c_class.len());
    let flips = (0..n).filter(|&i| g_class[i] != c_class[i] as u8).count();
    let same: Vec<usize> = (0..n).filter(|&i| g_class[i] == c_class[i] as u8).collect();
    let vis_diff = same.iter().filter(|&&i| g_vis[i] != c_vis[i]).count();
    let max_vis = same.iter().map(|&i| (g_vis[i] - c_vis[i]).abs()).fold(0.0f32, f32::max);
    let color_bad = colours_beyond(&g, &c);
    assert!(g.color.iter().flatten().all(|v| v.is_finite()), "{label}: non-finite colour");
    let penumbra = c_class.iter().filter(|&&k| k as u8 == 2).count();
    eprintln!(
        "{label}: {flips} class flips, {vis_diff} visibility differences (max {max_vis}) among {} same-class \
         pixels, {color_bad} colours beyond {COLOR_ABS}, of {n} ({penumbra} penumbra)",
        same.len()
    );
    assert!(flips as f64 <= CLASS_FLIP_SHARE * n as f64, "{label}: {flips} of {n} pixels change class");
    if flips == 0 && !light.depth_aware {
        assert_eq!(vis_diff, 0, "{label}: visibility differs with every class equal");
    }
    assert!(vis_diff as f64 <= VIS_SHARE * n as f64, "{label}: {vis_diff} visibilities differ");
    assert!(color_bad as f64 <= COLOR_SHARE * n as f64, "{label}: {color_bad} of {n} colours differ");
}

#[test]
fn soft_shadows_match_cpu() {
    let Some(mut gpu) = gpu_or_skip("soft shadows") else { return };
    // Pixel by pixel against the CPU's soft-shadow stage: one sample per pixel (the differential
    // tests compare the anti-aliased frames' colours).
    for (label, mut frame) in example_frames(|name| name.starts_with("soft-")) {
        frame.samples = 1;
        // A traced scene's own resolve draws no maps (traced_resolve_matches_cpu holds it); its
        // maps' resolves are checked below.
        if !matches!(frame.area_light.as_ref().map(|l| l.resolve), Some(SoftResolve::Traced { .. })) {
            check(&mut gpu, &label, &frame);
        }
        let mut faithful = frame.clone();
        faithful.area_light.as_mut().expect("an area light").resolve = SoftResolve::Faithful { n: 3 };
        check(&mut gpu, &format!("{label} faithful n=3"), &faithful);
        let mut plain = frame.clone();
        let light = plain.area_light.as_mut().expect("an area light");
        light.resolve = SoftResolve::Exact;
        light.depth_aware = false;
        check(&mut gpu, &format!("{label} exact, not depth-aware"), &plain);
    }
}

#[test]
fn the_gpu_fits_the_maps_as_the_cpu_does() {
    // soft-plaster at t = 1.5, where the wall (a caster too) would stretch unfitted maps to
    // tan 80°: the GPU's classes match the CPU's fitted ones, which differ from the unfitted
    // maps' at more than twice the share of pixels the tolerance allows, so the GPU must fit
    // them alike.
    let Some(mut gpu) = gpu_or_skip("soft shadows fitted") else { return };
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/soft-plaster.toml");
    let mut frame = hadou_scene::Scene::load(dir).unwrap_or_else(|e| panic!("{e}")).at(1.5);
    (frame.width, frame.height) = (192, 192);
    // Pixel by pixel against the CPU's classes: one sample per pixel.
    frame.samples = 1;
    let light = frame.area_light.as_ref().expect("an area light");
    let input = soft_input(&frame).expect("an area light");
    let render = |maps: [hadou_math::soft::SpotMap; 2]| {
        classify(&maps.map(|m| SpotDepth::render(&frame, &light.casters, &m, light.map_size)), &input)
    };
    let (fitted, full) = (render(fitted_maps(light, &input)), render(light.maps));
    let differ = fitted.iter().zip(&full).filter(|(a, b)| a != b).count();
    let n = fitted.len();
    assert!(
        differ as f64 > 2.0 * CLASS_FLIP_SHARE * n as f64,
        "{differ} of {n} pixels change class with the fit"
    );
    check(&mut gpu, "soft-plaster.toml t=1.5 at 192²", &frame);
}

/// Largest share of lit pixels whose traced visibility may differ from the CPU's by more than
/// `TRACED_STEP`: a sample within rounding of a triangle's edge may go either way on the two
/// backends (the visible points themselves come from two rasterizers).
const TRACED_SHARE: f64 = 0.005;
/// How far a lit pixel's visibility may move: about two samples of a disc's row (a row holds at
/// most 8 % of the disc at 256 samples, 16 to a row) or two and a half of the segment's 256.
const TRACED_STEP: f32 = 0.01;

/// The traced resolve on the GPU walks the same hierarchy as hadou-cpu's `traced` and sets the
/// same samples: every pixel the lamp lights (its unshadowed term not zero) within
/// `TRACED_STEP` of the CPU's visibility at all but `TRACED_SHARE` of them, for every lamp shape
/// on the gradient close-up, the plaster cast and the pebble, and on the disc's and the sphere's
/// own scenes; the frame's colours as the differential tests hold them. And the resolve must
/// matter: many pixels partly lit.
#[test]
fn traced_resolve_matches_cpu() {
    let Some(mut gpu) = gpu_or_skip("traced soft shadows") else { return };
    let scenes = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/");
    let load = |path: String, t: f32| {
        let mut f = hadou_scene::Scene::load(&path).unwrap_or_else(|e| panic!("{e}")).at(t);
        (f.width, f.height, f.samples) = (128, 96, 1);
        f
    };
    let mut frames = Vec::new();
    for (name, t) in
        [("soft-gradient.toml", 1.0), ("soft-plaster.toml", 1.5), ("soft-small-occluder.toml", 0.0)]
    {
        for shape in
            [hadou_scene::LampShape::Segment, hadou_scene::LampShape::Disc, hadou_scene::LampShape::Sphere]
        {
            let mut f = load(format!("{scenes}{name}"), t);
            let light = f.area_light.as_mut().expect("an area light");
            light.shape = shape;
            light.resolve = SoftResolve::Traced { samples: 256 };
            frames.push((format!("{name} {shape:?}"), f));
        }
    }
    for name in ["soft-disc.toml", "soft-sphere.toml"] {
        frames.push((name.to_string(), load(format!("{scenes}{name}"), 1.0)));
    }
    let mut partly = 0;
    for (label, frame) in &frames {
        let (g, soft) = gpu.render_soft(frame).unwrap_or_else(|e| panic!("{label}: GPU render failed: {e}"));
        let (_, g_vis) = soft.expect("an area light");
        let c = CpuBackend::new().render(frame).unwrap_or_else(|e| panic!("{label}: CPU render failed: {e}"));
        let light = frame.area_light.as_ref().expect("an area light");
        let input = soft_input(frame).expect("an area light");
        let c_vis = visibility(frame, light, &input, light.resolve);
        let lit: Vec<usize> = (0..c_vis.len())
            .filter(|&i| input.points[i].is_some_and(|p| p.term.iter().any(|&t| t > 0.0)))
            .collect();
        let off = lit.iter().filter(|&&i| (g_vis[i] - c_vis[i]).abs() > TRACED_STEP).count();
        let max = lit.iter().map(|&i| (g_vis[i] - c_vis[i]).abs()).fold(0.0f32, f32::max);
        partly += lit.iter().filter(|&&i| c_vis[i] > 0.005 && c_vis[i] < 0.995).count();
        let n = g.color.len();
        let color_bad = colours_beyond(&g, &c);
        eprintln!(
            "{label}: {off} of {} lit pixels off (max {max}), {color_bad} colours beyond {COLOR_ABS}",
            lit.len()
        );
        assert!(
            off as f64 <= TRACED_SHARE * lit.len() as f64,
            "{label}: {off} of {} pixels differ",
            lit.len()
        );
        assert!(color_bad as f64 <= COLOR_SHARE * n as f64, "{label}: {color_bad} of {n} colours differ");
    }
    assert!(partly > 1000, "only {partly} pixels in a penumbra");
}

/// With anti-aliasing (2 × 2 samples a pixel) the traced resolve traces one value per image pixel
/// where the pixel's samples show one surface and its neighbours' values are near it, and each
/// sample elsewhere (soft_traced.wgsl `cs_traced_pixels`, the twin of hadou-cpu's
/// `traced::traced_grid`): the sample frame's visibility within `TRACED_STEP` of the CPU's at all
/// but `TRACED_SHARE` of the lit samples, the frame's colours as the differential tests hold
/// them, and most partly lit pixels' four samples one value (each traced alone, they would differ;
/// a pixel in a penumbra narrower than about eight pixels is traced sample by sample).
#[test]
fn traced_resolve_with_anti_aliasing_traces_once_per_pixel_as_the_cpu() {
    let Some(mut gpu) = gpu_or_skip("traced soft shadows, anti-aliased") else { return };
    let scenes = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/");
    for (name, t, shape) in [
        ("soft-gradient.toml", 1.0, hadou_scene::LampShape::Disc),
        ("soft-plaster.toml", 1.5, hadou_scene::LampShape::Disc),
    ] {
        let mut frame =
            hadou_scene::Scene::load(format!("{scenes}{name}")).unwrap_or_else(|e| panic!("{e}")).at(t);
        (frame.width, frame.height, frame.samples) = (96, 72, 4);
        let light = frame.area_light.as_mut().expect("an area light");
        light.shape = shape;
        light.resolve = SoftResolve::Traced { samples: 256 };
        let label = format!("{name} {shape:?}");
        let (g, soft) = gpu.render_soft(&frame).unwrap_or_else(|e| panic!("{label}: GPU render failed: {e}"));
        let (_, g_vis) = soft.expect("an area light");
        let c =
            CpuBackend::new().render(&frame).unwrap_or_else(|e| panic!("{label}: CPU render failed: {e}"));
        let sampled = frame.sample_frame();
        let light = sampled.area_light.as_ref().expect("an area light");
        let mut input = soft_input(&sampled).expect("an area light");
        input.grid = 2;
        let c_vis = visibility(&sampled, light, &input, light.resolve);
        assert_eq!(g_vis.len(), c_vis.len(), "{label}: the sample frame's visibility");
        let lit = |i: usize| input.points[i].is_some_and(|p| p.term.iter().any(|&t| t > 0.0));
        let lit_samples: Vec<usize> = (0..c_vis.len()).filter(|&i| lit(i)).collect();
        let off = lit_samples.iter().filter(|&&i| (g_vis[i] - c_vis[i]).abs() > TRACED_STEP).count();
        let sw = input.width;
        let (mut partly, mut one_value) = (0, 0);
        for y in 0..frame.height as usize {
            for x in 0..frame.width as usize {
                let s: Vec<usize> = (0..4).map(|k| (2 * y + k / 2) * sw + 2 * x + k % 2).collect();
                if s.iter().all(|&i| lit(i)) && s.iter().all(|&i| g_vis[i] > 0.005 && g_vis[i] < 0.995) {
                    partly += 1;
                    one_value += usize::from(s.iter().all(|&i| g_vis[i].to_bits() == g_vis[s[0]].to_bits()));
                }
            }
        }
        let color_bad = colours_beyond(&g, &c);
        eprintln!(
            "{label}: {off} of {} lit samples off, {one_value} of {partly} partly lit pixels one value, \
             {color_bad} colours beyond {COLOR_ABS}",
            lit_samples.len()
        );
        assert!(off as f64 <= TRACED_SHARE * lit_samples.len() as f64, "{label}: {off} samples differ");
        assert!(partly > 100 && one_value * 2 >= partly, "{label}: {one_value} of {partly}");
        let n = g.color.len();
        assert!(color_bad as f64 <= COLOR_SHARE * n as f64, "{label}: {color_bad} of {n} colours differ");
    }
}

/// Outlines under an `[area_light]` (as in scenes/showcase.toml): the tile drawn right after the
/// soft shadows' classification reuses the G-buffer that classification rasterized, and the
/// outlines' edge pass must still run on it (without it a small frame of one tile lost its lamp
/// and most of its colour). soft-plaster with its figure outlined, at 128×96 and at 160×120.
#[test]
fn outlines_under_an_area_light_in_one_tile_match_cpu() {
    let Some(mut gpu) = gpu_or_skip("outlines under an area light") else { return };
    let scenes = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes");
    let dir = std::env::temp_dir().join(format!("hadou-gpu-soft-outlines-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("assets")).unwrap();
    std::fs::copy(format!("{scenes}/assets/hero.glb"), dir.join("assets/hero.glb")).unwrap();
    let text = std::fs::read_to_string(format!("{scenes}/soft-plaster.toml")).unwrap();
    let figure = "material = \"plaster\"\n";
    assert!(text.contains(figure), "soft-plaster's figure");
    let path = dir.join("outlined.toml");
    std::fs::write(
        &path,
        text.replacen(figure, "material = \"plaster\"\noutline = true\noutline_width = 0.006\n", 1),
    )
    .unwrap();
    let scene = hadou_scene::Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    for (w, h) in [(128, 96), (160, 120)] {
        let mut frame = scene.at(1.0);
        (frame.width, frame.height, frame.samples) = (w, h, 1);
        assert!(frame.width <= hadou_gpu::MAX_TILE && frame.height <= hadou_gpu::MAX_TILE, "one tile");
        check(&mut gpu, &format!("soft-plaster outlined {w}×{h}"), &frame);
    }
    std::fs::remove_dir_all(&dir).ok();
}
