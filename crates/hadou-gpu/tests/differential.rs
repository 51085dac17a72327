//! GPU ↔ CPU differential tests: every frame is rendered by both backends and compared.
//!
//! Tolerances (set in tests/common/mod.rs): energy relative error ≤ 1e-3 where the energy is
//! above a floor of 1e-5 × the image's peak; colour within 2e-3 absolute after mapping; eye
//! distance within 1e-3 relative. Pixels outside these bounds are allowed only on silhouettes
//! and creases of the CPU image (where the two rasterizers may disagree on which triangle covers
//! a pixel centre lying on an edge), and only up to 0.5 % of the image.
//!
//! Without a GPU adapter each test prints a skip message and passes; `HADOU_REQUIRE_GPU=1` makes
//! a missing adapter a failure (CI, where lavapipe provides one).

mod common;

use common::*;
use hadou_cpu::CpuBackend;
use hadou_scene::{Backend, Frame};

fn check(name: &str, frame: &Frame) {
    let Some(mut gpu) = gpu_or_skip(name) else { return };
    let g = gpu.render(frame).unwrap_or_else(|e| panic!("{name}: GPU render failed: {e}"));
    let c = CpuBackend::new().render(frame).unwrap_or_else(|e| panic!("{name}: CPU render failed: {e}"));
    assert_close(name, &compare(&g, &c));
}

#[test]
fn occlusion_faithful_matches_cpu() {
    check("occlusion", &occlusion_frame(160, 120));
}

#[test]
fn beam_over_scenery_inverse_square_filmic_matches_cpu() {
    check("kamehameha", &kamehameha_frame(160, 120));
}

#[test]
fn cylinder_seen_along_its_axis_matches_cpu() {
    check("axis view", &axis_view_frame(96, 96));
}

#[test]
fn tiled_wide_image_matches_cpu() {
    // Wider than one tile: two tiles side by side, odd sizes, so tile seams and edges are covered.
    check("tiled", &occlusion_frame(hadou_gpu::MAX_TILE + 77, 37));
}

/// A helix (default integrator) and a reduced-Simpson Bézier curve, both falloffs, over the
/// occlusion scenery (so curve spans end at visible surfaces too).
#[test]
fn curves_over_scenery_match_cpu() {
    use hadou_math::curve::{CurveFrame, CurveShape, CurveWave, Integrator, Reduction};
    use hadou_math::energy::Falloff;
    use hadou_math::Vec3;
    use hadou_scene::WaveShape;
    let mut f = occlusion_frame(96, 72);
    let helix = CurveWave {
        frame: CurveFrame { origin: Vec3::new(-2.0, 0.5, 0.0), axis: Vec3::X, up: Vec3::Y },
        shape: CurveShape::Helix { radius: 0.6, rate: 2.0, phase: 0.3, length: 4.0 },
        gamma: 1.0,
        extension: 0.9,
        attenuation: 0.0,
        alpha: 0.2,
        integrator: Integrator::Default,
    };
    let bezier = CurveWave {
        frame: CurveFrame { origin: Vec3::new(0.0, -0.5, -1.0), axis: Vec3::new(0.2, 1.0, 0.1), up: Vec3::X },
        shape: CurveShape::Bezier { points: vec![[0.0, 0.0], [1.0, 0.5], [-0.5, 1.0], [0.3, -0.2]] },
        gamma: 2.5,
        extension: 1.0,
        attenuation: 1.5,
        alpha: 0.1,
        integrator: Integrator::Simpson { m: 64, reduction: Some(Reduction { n: 4, epsilon: 0.1 }) },
    };
    f.waves.push(wave("helix", [1.0, 0.6, 0.2, 1.0], Falloff::InverseSquare, 0.05, WaveShape::Curve(helix)));
    f.waves.push(wave("bezier", [0.3, 0.6, 1.0, 1.0], Falloff::Faithful, 0.02, WaveShape::Curve(bezier)));
    check("curves", &f);
}

/// The distance attenuation `(1 − u)^j` (002 eq. 3.23) on every analytic shape, both falloffs,
/// over the occlusion scenery (spans ending at visible surfaces and at the far plane), with the
/// far plane close enough to cut through the shapes.
#[test]
fn attenuated_analytic_shapes_match_cpu() {
    use hadou_math::energy::{BeamField, CapsuleField, CylinderField, Falloff, SphereField};
    use hadou_math::Vec3;
    use hadou_scene::WaveShape;
    let mut f = occlusion_frame(128, 96);
    f.camera.far = 55.0;
    f.waves.clear();
    let capsule =
        CapsuleField { m: Vec3::new(-8.0, 1.0, 5.0), d: Vec3::X, length: 12.0, alpha_s: 0.08, alpha_c: 0.08 };
    let shapes = [
        (
            Falloff::Faithful,
            1.5,
            WaveShape::Sphere(SphereField { center: Vec3::new(-6.0, 3.0, 0.0), alpha: 4.0 }),
        ),
        (
            Falloff::Faithful,
            6.0,
            WaveShape::Cylinder(CylinderField { point: Vec3::new(6.0, -2.0, 0.0), dir: Vec3::Z, alpha: 3.0 }),
        ),
        (Falloff::InverseSquare, 3.0, WaveShape::Capsule(capsule)),
        (
            Falloff::InverseSquare,
            40.0,
            WaveShape::Beam(BeamField {
                capsule: CapsuleField { m: Vec3::new(-4.0, -3.0, -30.0), ..capsule },
                head_alpha: 0.1,
                muzzle_alpha: 0.05,
            }),
        ),
    ];
    for (i, (falloff, j, shape)) in shapes.into_iter().enumerate() {
        let mut w = wave(&format!("w{i}"), [0.8, 0.6, 0.3, 1.0], falloff, 0.05, shape);
        w.attenuation = j;
        f.waves.push(w);
    }
    check("attenuated shapes", &f);
}

/// Every example scene (curved waves included), at the start, middle and end of its animation,
/// at 128×96.
#[test]
fn every_example_scene_matches_cpu() {
    let Some(mut gpu) = gpu_or_skip("example scenes") else { return };
    // `HADOU_SCENES=light-` checks only the scenes whose file name contains that text (local runs).
    let only = std::env::var("HADOU_SCENES").unwrap_or_default();
    let mut cpu = CpuBackend::new();
    for (label, frame) in example_frames(|name| name.contains(&only)) {
        let g = gpu.render(&frame).unwrap_or_else(|e| panic!("{label}: GPU render failed: {e}"));
        let c = cpu.render(&frame).unwrap_or_else(|e| panic!("{label}: CPU render failed: {e}"));
        assert_close(&label, &compare(&g, &c));
    }
}

/// The MToon look (scenes/light-mtoon.toml: step, shade, rim, matcap, emission, textures, UV
/// animation, a wave's light through the materials' own step) at the start, middle and end of its
/// animation, and at 320×180 at the end (the scrolled and turned textures at more pixels).
#[test]
fn light_mtoon_matches_cpu() {
    let Some(mut gpu) = gpu_or_skip("light-mtoon") else { return };
    let mut cpu = CpuBackend::new();
    let mut frames = example_frames(|name| name == "light-mtoon.toml");
    let (_, mut big) = frames.last().cloned().expect("the scene's frames");
    big.width = 320;
    big.height = 180;
    frames.push(("light-mtoon.toml 320×180".into(), big));
    for (label, frame) in frames {
        let g = gpu.render(&frame).unwrap_or_else(|e| panic!("{label}: GPU render failed: {e}"));
        let c = cpu.render(&frame).unwrap_or_else(|e| panic!("{label}: CPU render failed: {e}"));
        assert_close(&label, &compare(&g, &c));
    }
}

/// `render_rows` (how large PNGs are streamed) draws the same pixels as those rows of a whole
/// frame, for bands that start inside a tile and cross tile seams, and matches the CPU's bands.
#[test]
fn row_bands_match_the_whole_frame() {
    let Some(mut gpu) = gpu_or_skip("row bands") else { return };
    let frame = kamehameha_frame(hadou_gpu::MAX_TILE + 40, 70);
    let whole = gpu.render(&frame).expect("whole frame");
    let mut cpu = CpuBackend::new();
    for rows in [0..1, 5..37, 33..70, 69..70] {
        let band = gpu.render_rows(&frame, rows.clone()).expect("band");
        assert_eq!((band.width, band.height), (frame.width, rows.len() as u32));
        let expect = whole.crop_rows(rows.clone());
        // The same kernels per pixel; only the raster's tile origin differs (bands start inside a
        // tile), which moves the clip-space arithmetic by rounding at most.
        assert_close(&format!("rows {rows:?} vs whole"), &compare(&band, &expect));
        let c = cpu.render_rows(&frame, rows.clone()).expect("cpu band");
        assert_close(&format!("rows {rows:?} vs cpu"), &compare(&band, &c));
    }
}

/// Materials on hand-built frames: every shading model, a smoothed-band ramp, a base texture with
/// each wrap mode and both filters, a feature texture, vertex colours, outlines on a box and a
/// sphere, and three waves of every light-line kind (point, segment, curve polyline) sharing the
/// surfaces, one of them glowing.
#[test]
fn materials_outlines_and_wave_lights_match_cpu() {
    use hadou_math::curve::{CurveFrame, CurveShape, CurveWave, Integrator};
    use hadou_math::energy::{CapsuleField, Falloff, SphereField};
    use hadou_math::toon::{Filter, Ramp, RampKind, Wrap};
    use hadou_math::Vec3;
    use hadou_scene::mesh::{box_mesh, sphere_mesh, with_outline_normals};
    use hadou_scene::{Material, Outline, ShadingModel, Texture, TextureRef, WaveShape};
    use std::sync::Arc;
    let checker: Vec<[u8; 4]> = (0..64u32)
        .map(|i| if (i % 8 + i / 8) % 2 == 0 { [230, 40, 40, 255] } else { [30, 200, 90, 255] })
        .collect();
    let image = Arc::new(Texture { name: "checker".into(), width: 8, height: 8, texels: checker });
    let tex =
        |wrap: Wrap, filter: Filter| TextureRef { image: image.clone(), wrap: [wrap, Wrap::Clamp], filter };
    let face = Arc::new(Texture {
        name: "face".into(),
        width: 4,
        height: 4,
        texels: (0..16).map(|i| if i == 5 || i == 6 { [0, 0, 0, 255] } else { [255; 4] }).collect(),
    });
    let mut f = base_frame(160, 120, Vec3::new(0.0, 2.0, 9.0), Vec3::ZERO, hadou_scene::ToneMode::Filmic);
    let models = [ShadingModel::Toon, ShadingModel::Diffuse, ShadingModel::Unlit, ShadingModel::Toon];
    let wraps =
        [(Wrap::Repeat, Filter::Linear), (Wrap::Mirror, Filter::Nearest), (Wrap::Clamp, Filter::Linear)];
    for (i, model) in models.iter().enumerate() {
        let mut mesh = if i % 2 == 0 { sphere_mesh(0.9, 40) } else { box_mesh([1.4, 1.4, 1.4]) };
        mesh.uvs.iter_mut().for_each(|uv| *uv = [uv[0] * 3.0 - 1.0, uv[1] * 2.0]);
        mesh.colors =
            (0..mesh.positions.len()).map(|v| [1.0, 0.6 + 0.4 * ((v % 3) as f32 / 2.0), 1.0, 1.0]).collect();
        let mesh = with_outline_normals(mesh);
        let (wrap, filter) = wraps[i % 3];
        let material = Material {
            name: format!("m{i}"),
            model: *model,
            base_color: [0.9, 0.8, 0.7],
            base_texture: Some(tex(wrap, filter)),
            feature_texture: (i == 0).then(|| TextureRef {
                image: face.clone(),
                wrap: [Wrap::Clamp; 2],
                filter: Filter::Nearest,
            }),
            ramp: Ramp {
                kind: RampKind::Bands { smoothing: 0.08 * i as f32 },
                ..Ramp::two_band(0.1, [0.4, 0.45, 0.6], 0.0)
            },
            wave_blend: [1.0, 0.6, 0.0, 0.3][i],
            outline: (i != 2).then_some(Outline { width: 0.006, color: [0.05, 0.0, 0.1] }),
            mtoon: None,
        };
        let x = -3.0 + 2.0 * i as f32;
        let mut o = object(
            &format!("o{i}"),
            Arc::new(mesh),
            Vec3::new(x, 0.0, 0.0),
            Vec3::new(10.0, 30.0 * i as f32, 0.0),
            [1.0; 3],
        );
        o.materials = vec![material];
        f.objects.push(o);
    }
    f.waves.push(wave(
        "orb",
        [0.3, 0.8, 1.0, 1.0],
        Falloff::InverseSquare,
        0.05,
        WaveShape::Sphere(SphereField { center: Vec3::new(-2.0, 1.5, 1.5), alpha: 0.05 }),
    ));
    let mut beam = wave(
        "beam",
        [1.0, 0.7, 0.2, 1.0],
        Falloff::Faithful,
        0.05,
        WaveShape::Capsule(CapsuleField {
            m: Vec3::new(-4.0, -1.2, 1.0),
            d: Vec3::X,
            length: 8.0,
            alpha_s: 0.5,
            alpha_c: 0.5,
        }),
    );
    beam.light.glow = 0.2;
    f.waves.push(beam);
    let helix = CurveWave {
        frame: CurveFrame { origin: Vec3::new(-4.0, 1.2, -1.0), axis: Vec3::X, up: Vec3::Y },
        shape: CurveShape::Helix { radius: 0.4, rate: 3.0, phase: 0.0, length: 8.0 },
        gamma: 1.0,
        extension: 1.0,
        attenuation: 0.0,
        alpha: 0.05,
        integrator: Integrator::Default,
    };
    f.waves.push(wave("helix", [1.0, 0.3, 0.6, 1.0], Falloff::InverseSquare, 0.03, WaveShape::Curve(helix)));
    check("materials", &f);
}

/// Hard shadows on a hand-built frame: a box and a sphere casting onto a ground plane by
/// projection from the sun and from a wave (overlapping, so the more opaque one must win), a
/// shadow map from the sun onto stairs of boxes and the ground (a receiver that is no plane), an
/// outlined caster (hull pixels take no shadow), and a receiver that is not listed for one shadow.
#[test]
fn shadows_match_cpu() {
    use hadou_math::energy::{Falloff, SphereField};
    use hadou_math::shadow::Plane;
    use hadou_math::Vec3;
    use hadou_scene::mesh::with_outline_normals;
    use hadou_scene::{Material, Outline, Shadow, ShadowLight, ShadowMethod, WaveShape};
    use std::sync::Arc;
    let mut f = base_frame(
        160,
        120,
        Vec3::new(5.0, 4.5, 9.0),
        Vec3::new(1.2, -0.3, 0.0),
        hadou_scene::ToneMode::Filmic,
    );
    let ground_y = -1.0;
    f.objects.push(object(
        "ground",
        plane_mesh(40.0),
        Vec3::new(0.0, ground_y, 0.0),
        Vec3::ZERO,
        [0.6, 0.6, 0.55],
    ));
    f.objects.push(object(
        "box",
        box_mesh([1.4, 1.4, 1.4]),
        Vec3::new(-1.8, 0.2, 0.3),
        Vec3::new(0.0, 35.0, 10.0),
        [0.8, 0.3, 0.2],
    ));
    let mut ball = object(
        "ball",
        Arc::new(with_outline_normals((*sphere_mesh(0.9, 32)).clone())),
        Vec3::new(-0.4, 0.6, 1.2),
        Vec3::ZERO,
        [0.3, 0.5, 0.9],
    );
    ball.materials = vec![Material {
        outline: Some(Outline { width: 0.008, color: [0.02, 0.0, 0.05] }),
        ..Material::diffuse([0.3, 0.5, 0.9])
    }];
    f.objects.push(ball);
    // Stairs: three boxes rising towards −z, x from 3 to 5.
    let stairs: Vec<u32> = (0..3)
        .map(|i| {
            let h = 0.5 * (i + 1) as f32;
            f.objects.push(object(
                &format!("step{i}"),
                box_mesh([2.0, h, 1.2]),
                Vec3::new(4.0, ground_y + 0.5 * h, 1.2 - 1.2 * i as f32),
                Vec3::ZERO,
                [0.7, 0.7, 0.6],
            ));
            f.objects.len() as u32 - 1
        })
        .collect();
    f.objects.push(object(
        "floater",
        sphere_mesh(0.6, 24),
        Vec3::new(3.6, 2.2, 0.2),
        Vec3::ZERO,
        [0.9, 0.8, 0.3],
    ));
    f.objects.push(object(
        "post",
        box_mesh([0.3, 1.6, 0.3]),
        Vec3::new(5.3, 1.6, 0.8),
        Vec3::ZERO,
        [0.5, 0.8, 0.5],
    ));
    let (ground, boxed, ball, floater, post) = (0, 1, 2, stairs[2] + 1, stairs[2] + 2);
    f.waves.push(wave(
        "orb",
        [0.3, 0.8, 1.0, 1.0],
        Falloff::InverseSquare,
        0.05,
        WaveShape::Sphere(SphereField { center: Vec3::new(0.8, 3.5, -1.0), alpha: 0.05 }),
    ));
    let ground_plane = Plane { point: Vec3::new(0.0, ground_y, 0.0), normal: Vec3::Y };
    let sun = f.light.direction;
    f.shadows = vec![
        Shadow {
            name: "sun".into(),
            light: ShadowLight::Sun(sun),
            method: ShadowMethod::Plane(ground_plane),
            up: Vec3::Y,
            casters: vec![boxed, ball],
            receivers: vec![ground],
            color: [0.05, 0.05, 0.12],
            opacity: 0.55,
        },
        Shadow {
            name: "orb".into(),
            light: ShadowLight::Wave { wave: 0, theta: 60f32.to_radians() },
            method: ShadowMethod::Plane(ground_plane),
            up: Vec3::Y,
            casters: vec![boxed, ball],
            receivers: vec![ground],
            color: [0.25, 0.0, 0.3],
            opacity: 0.8,
        },
        Shadow {
            name: "map".into(),
            light: ShadowLight::Sun(Vec3::new(0.35, -1.0, -0.25).normalize_or(Vec3::Y)),
            method: ShadowMethod::Map { size: 512 },
            up: Vec3::Y,
            casters: vec![floater, post],
            // The post casts on the stairs and the ground but not on itself (ascending, as
            // `Shadow::receivers` must be).
            receivers: [ground].into_iter().chain(stairs.iter().copied()).collect(),
            color: [0.0, 0.02, 0.0],
            opacity: 0.7,
        },
        Shadow {
            name: "small map".into(),
            // Onto the box's side and the ground, over the plane shadows there.
            light: ShadowLight::Sun(Vec3::new(-0.9, -0.7, 0.3).normalize_or(Vec3::Y)),
            method: ShadowMethod::Map { size: 96 },
            up: Vec3::Y,
            casters: vec![ball],
            receivers: vec![boxed, ground],
            color: [0.3, 0.0, 0.0],
            opacity: 0.7,
        },
    ];
    let casts = f.shadow_casts(&[f.waves[0].light_line(None)]);
    assert_eq!(casts.len(), 5, "one sun cast, one wave cast per caster, two maps: {casts:?}");
    check("shadows", &f);
    // Without its shadows the same frame renders as before shadows existed (the casts' effect is
    // visible: the images differ).
    let Some(mut gpu) = gpu_or_skip("shadows") else { return };
    let shadowed = gpu.render(&f).expect("shadowed frame");
    f.shadows.clear();
    let plain = gpu.render(&f).expect("plain frame");
    let changed = (0..plain.color.len()).filter(|&i| plain.color[i] != shadowed.color[i]).count();
    assert!(changed > 200, "the shadows changed only {changed} pixels");
    assert_eq!(plain.energy, shadowed.energy, "shadows leave the energy alone");
    assert_eq!(plain.depth, shadowed.depth, "shadows leave the depth alone");
}

/// `[bloom]`: the glare scene two tiles wide, whole and in bands (each band drawing its halo),
/// with the filmic and the faithful mapping and with a streak only, against the CPU.
#[test]
fn glare_matches_cpu_whole_and_in_bands() {
    use hadou_scene::{BloomParams, ToneMode};
    let Some(mut gpu) = gpu_or_skip("glare") else { return };
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/glare-kamehameha.toml");
    let scene = hadou_scene::Scene::load(path).unwrap_or_else(|e| panic!("{e}"));
    let mut frame = scene.at(1.5);
    (frame.width, frame.height) = (hadou_gpu::MAX_TILE + 40, 70);
    let bloom = frame.bloom.expect("the scene has a [bloom]");
    let mut faithful = frame.clone();
    faithful.color_mapping.mode = ToneMode::Faithful;
    faithful.bloom = Some(BloomParams { intensity: 0.0, streak: 1.5, threshold: 0.5, ..bloom });
    let mut cpu = CpuBackend::new();
    for (label, f) in [("glare", &frame), ("glare, faithful streak", &faithful)] {
        let g = gpu.render(f).unwrap_or_else(|e| panic!("{label}: GPU render failed: {e}"));
        let c = cpu.render(f).expect("cpu");
        assert_close(label, &compare(&g, &c));
        let off = cpu.render(&Frame { bloom: None, ..f.clone() }).expect("cpu");
        assert!(
            c.color.iter().zip(&off.color).any(|(a, b)| (a[0] - b[0]).abs() > 0.02),
            "{label}: the glare changes the picture"
        );
    }
    for rows in [0..1, 5..37, 33..70] {
        let band = gpu.render_rows(&frame, rows.clone()).expect("band");
        let c = cpu.render_rows(&frame, rows.clone()).expect("cpu band");
        assert_close(&format!("glare rows {rows:?}"), &compare(&band, &c));
    }
}

/// Issue 41 (glare within the memory promise): a `[bloom]` whose halo does not fit the device's
/// storage binding is refused by `check_frame` before anything is drawn, naming the binding and a
/// radius that fits, and that radius passes; an 8192² image (the glare's pixel limit) with the
/// widest reach is refused exactly where one row's halo needs more than the binding.
#[test]
fn issue_41_a_bloom_past_the_storage_binding_is_refused_with_a_radius_that_fits() {
    use hadou_scene::{Backend, BloomParams};
    let Some(gpu) = gpu_or_skip("bloom binding") else { return };
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/glare-kamehameha.toml");
    let scene = hadou_scene::Scene::load(path).unwrap_or_else(|e| panic!("{e}"));
    let mut frame = scene.at(1.5);
    (frame.width, frame.height) = (8192, 8192);
    let bloom = frame.bloom.expect("the scene has a [bloom]");
    frame.bloom = Some(BloomParams { radius: 1.0, ..bloom });
    // Radius 1 at 8192²: the halo is the whole image, 8192² texels of 16 bytes (1 GiB).
    let need = 8192u64 * 8192 * 16;
    match gpu.check_frame(&frame) {
        Ok(()) => {}
        Err(m) => {
            assert!(m.contains("storage binding") && m.contains("`--backend cpu`"), "{m}");
            let fits: f32 = m
                .split("a `radius` of at most ")
                .nth(1)
                .and_then(|r| r.split_whitespace().next())
                .and_then(|r| r.parse().ok())
                .unwrap_or_else(|| panic!("no radius in: {m}"));
            assert!(fits < 1.0, "{m}");
            frame.bloom = Some(BloomParams { radius: fits, ..bloom });
            assert_eq!(gpu.check_frame(&frame), Ok(()), "the radius the message names fits");
            frame.bloom = Some(BloomParams { radius: 1.0, ..bloom });
            let err = gpu.check_frame(&frame).unwrap_err();
            let limit: u64 = err
                .split("this device's ")
                .nth(1)
                .and_then(|r| r.split('-').next())
                .and_then(|r| r.parse().ok())
                .unwrap_or_else(|| panic!("no limit in: {err}"));
            assert!(limit < need, "refused although {need} bytes fit the {limit}-byte binding");
        }
    }
    // Within the binding (a small image) every radius passes.
    (frame.width, frame.height) = (256, 128);
    assert_eq!(gpu.check_frame(&frame), Ok(()));
}

/// Outlines closed where objects meet (the edge pass): a box standing on the ground seen from
/// above, a little off its axis, has an outline ring on the GPU as on the CPU — every one of 64
/// directions from the box's screen centre meets an outline pixel within 4 pixels past its last
/// box pixel (the hull alone, buried in the ground along the base, leaves 26 without) — and the
/// two backends' images agree; a second, smaller box with its own outline colour stands beside it.
#[test]
fn outlines_close_where_objects_meet() {
    use hadou_math::Vec3;
    use hadou_scene::mesh::{box_mesh, plane_mesh, with_outline_normals};
    use hadou_scene::{Image, Material, Outline, ToneMode};
    use std::sync::Arc;
    const MAGENTA: [f32; 3] = [1.0, 0.0, 1.0];
    let Some(mut gpu) = gpu_or_skip("contact outlines") else { return };
    let mut f = base_frame(128, 128, Vec3::new(1.2, 6.0, 1.6), Vec3::new(0.0, 0.5, 0.0), ToneMode::Faithful);
    f.camera.fov_y_deg = 40.0;
    let mut ground = object("ground", Arc::new(plane_mesh([20.0, 20.0])), Vec3::ZERO, Vec3::ZERO, [1.0; 3]);
    ground.materials = vec![Material::diffuse([0.1, 0.1, 0.8])];
    let mut cube = object(
        "box",
        Arc::new(with_outline_normals(box_mesh([1.0, 1.0, 1.0]))),
        Vec3::new(0.0, 0.5, 0.0),
        Vec3::ZERO,
        [1.0; 3],
    );
    cube.materials = vec![Material {
        outline: Some(Outline { width: 0.02, color: MAGENTA }),
        ..Material::diffuse([0.8, 0.1, 0.1])
    }];
    let mut small = object(
        "small",
        Arc::new(with_outline_normals(box_mesh([0.5, 0.5, 0.5]))),
        Vec3::new(-1.5, 0.25, -1.2),
        Vec3::new(0.0, 30.0, 0.0),
        [1.0; 3],
    );
    small.materials = vec![Material {
        outline: Some(Outline { width: 0.015, color: [0.0, 1.0, 0.0] }),
        ..Material::diffuse([0.7, 0.7, 0.1])
    }];
    f.objects = vec![ground, cube, small];
    let g = gpu.render(&f).expect("GPU render");
    let c = CpuBackend::new().render(&f).expect("CPU render");
    assert_close("contact outlines", &compare(&g, &c));
    let px = |img: &Image, x: i64, y: i64| {
        let p = img.color[img.index(x as u32, y as u32)];
        [p[0], p[1], p[2]]
    };
    let is_box = |img: &Image, x: i64, y: i64| {
        let p = px(img, x, y);
        p != MAGENTA && p[0] > p[2] && p[0] > 2.0 * p[1]
    };
    for (name, img) in [("gpu", &g), ("cpu", &c)] {
        let (mut sx, mut sy, mut n) = (0.0f32, 0.0f32, 0.0f32);
        for y in 0..128 {
            for x in 0..128 {
                if is_box(img, x, y) {
                    (sx, sy, n) = (sx + x as f32, sy + y as f32, n + 1.0);
                }
            }
        }
        assert!(n > 100.0, "{name}: the box is not in view");
        let (cx, cy) = (sx / n, sy / n);
        let mut missing = Vec::new();
        for k in 0..64 {
            let a = k as f32 / 64.0 * std::f32::consts::TAU;
            let at = |t: f32| ((cx + a.cos() * t).round() as i64, (cy + a.sin() * t).round() as i64);
            let inside = |(x, y): (i64, i64)| (0..128).contains(&x) && (0..128).contains(&y);
            let (mut t, mut last) = (0.0, 0.0);
            while inside(at(t)) && t < 40.0 {
                if is_box(img, at(t).0, at(t).1) {
                    last = t;
                }
                t += 0.25;
            }
            let hit = (0..=16)
                .map(|s| at(last + s as f32 * 0.25))
                .any(|p| inside(p) && px(img, p.0, p.1) == MAGENTA);
            if !hit {
                missing.push(k);
            }
        }
        assert!(missing.is_empty(), "{name}: no outline in directions {missing:?} of 64");
    }
}
