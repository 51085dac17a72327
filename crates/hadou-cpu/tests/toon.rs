//! The wave as a light on toon-shaded surfaces (000 §2.1–2.3, SPEC.md §2.1–2.3) on hand-built
//! frames: the ramp bands facing towards and away from the wave, several waves sharing a point,
//! feature textures, and inverted-hull outlines.

use hadou_cpu::render;
use hadou_math::energy::{Falloff, SphereField};
use hadou_math::toon::{Filter, Ramp, Wrap};
use hadou_math::{Mat4, Vec3, Vec3f};
use hadou_scene::mesh::{box_mesh, plane_mesh, sphere_mesh, with_outline_normals};
use hadou_scene::{
    ColorMapping, Frame, Image, Light, Material, Mesh, Object, Outline, ShadingModel, Texture, TextureRef,
    ToneMode, Wave, WaveShape,
};
use std::sync::Arc;

mod common;

const BG: [f32; 3] = [0.0, 0.0, 0.0];

fn frame(size: u32, eye: Vec3f, objects: Vec<Object>, waves: Vec<Wave>) -> Frame {
    Frame {
        background: BG,
        light: Light { direction: Vec3::new(0.0, -1.0, 0.0), color: [1.0; 3], ambient: [0.2; 3] },
        // Faithful mapping with a tiny exposure: the waves' own glow adds < 1e-6, so pixels show
        // the surface colour.
        color_mapping: ColorMapping { mode: ToneMode::Faithful, exposure: 1e-9 },
        ..common::frame(size, size, common::camera(eye, 40.0), objects, waves)
    }
}

fn toon(base: [f32; 3], blend: f32) -> Material {
    Material {
        name: "toon".into(),
        model: ShadingModel::Toon,
        ramp: Ramp::two_band(0.0, [0.5; 3], 0.0),
        wave_blend: blend,
        ..Material::diffuse(base)
    }
}

fn object(mesh: Mesh, at: Vec3f, material: Material) -> Object {
    Object {
        name: "o".into(),
        mesh: Arc::new(mesh),
        transform: Mat4::translation(at),
        materials: vec![material],
    }
}

fn point_wave(name: &str, at: Vec3f, ramp: Ramp) -> Wave {
    let mut w = Wave::new(
        name,
        [1.0, 1.0, 1.0, 1.0],
        Falloff::InverseSquare,
        0.01,
        WaveShape::Sphere(SphereField { center: at, alpha: 1.0 }),
    );
    w.light.ramp = ramp;
    w
}

fn px(img: &Image, x: u32, y: u32) -> [f32; 3] {
    let c = img.color[img.index(x, y)];
    [c[0], c[1], c[2]]
}

fn close(a: [f32; 3], b: [f32; 3], tol: f32) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() <= tol)
}

/// 000 §2.1 with the thesis's blue bands: a sphere lit by a wave on its right shows the bright
/// band (0.9, 0.9, 1.0) on the side facing the wave (m ≥ 0), the middle band next to it and the
/// dark band (0, 0.2, 0.4) on the far side (m < −0.3); its own colour is gone (β = 1).
#[test]
fn the_side_facing_the_wave_takes_the_bright_band() {
    let wave = point_wave("w", Vec3::new(6.0, 0.0, 0.0), Ramp::thesis_blue());
    let f = frame(
        65,
        Vec3::new(0.0, 0.0, 6.0),
        vec![object(sphere_mesh(1.0, 64), Vec3f::ZERO, toon([1.0, 0.0, 0.0], 1.0))],
        vec![wave],
    );
    let img = render(&f);
    // Sphere spans about ±1/(6·tan 20°)·32 ≈ ±14.6 px around the centre pixel 32.
    assert!(close(px(&img, 43, 32), [0.9, 0.9, 1.0], 1e-4), "{:?}", px(&img, 43, 32));
    assert!(close(px(&img, 21, 32), [0.0, 0.2, 0.4], 1e-4), "{:?}", px(&img, 21, 32));
    // Between: some pixel takes the middle band.
    assert!((21..43).any(|x| close(px(&img, x, 32), [0.5, 0.7, 0.9], 1e-4)));
    // β = 0: the material's own toon look (red; lit from above, the upper half takes the white
    // band of its two-band ramp).
    let mut f0 = f.clone();
    f0.objects[0].materials[0].wave_blend = 0.0;
    let own = px(&render(&f0), 32, 24);
    assert!(close(own, [1.0, 0.0, 0.0], 1e-4), "{own:?}");
    // β = 0.5: half way.
    f0.objects[0].materials[0].wave_blend = 0.5;
    let half = px(&render(&f0), 43, 32);
    let own43 = px(
        &render(&{
            let mut g = f0.clone();
            g.objects[0].materials[0].wave_blend = 0.0;
            g
        }),
        43,
        32,
    );
    for k in 0..3 {
        let want = 0.5 * own43[k] + 0.5 * [0.9, 0.9, 1.0][k];
        assert!((half[k] - want).abs() < 1e-4, "{half:?} vs {want}");
    }
}

/// Several waves: each point takes the look of the wave whose density dominates there; where two
/// waves are equally dense the looks mix half and half, and the colour varies continuously across
/// the surface (no seam).
#[test]
fn two_waves_share_a_surface_without_a_seam() {
    let red = Ramp { stops: vec![(-1.0, [1.0, 0.0, 0.0])], ..Ramp::thesis_blue() };
    let blue = Ramp { stops: vec![(-1.0, [0.0, 0.0, 1.0])], ..Ramp::thesis_blue() };
    let waves = vec![
        point_wave("left", Vec3::new(-2.0, 0.0, 1.0), red),
        point_wave("right", Vec3::new(2.0, 0.0, 1.0), blue),
    ];
    let mut wall = plane_mesh([6.0, 6.0]);
    // Face the camera: rotate the xz plane to xy.
    wall = hadou_scene::mesh::transform_mesh(
        &wall,
        &Mat4::from_trs(Vec3f::ZERO, Vec3::new(90.0, 0.0, 0.0), Vec3::splat(1.0)),
    );
    let f = frame(64, Vec3::new(0.0, 0.0, 8.0), vec![object(wall, Vec3f::ZERO, toon([0.5; 3], 1.0))], waves);
    let img = render(&f);
    // Pixel columns 31 and 32 straddle x = 0: mirror images of each other, each near half-half.
    let (l, r) = (px(&img, 31, 32), px(&img, 32, 32));
    assert!((l[0] - r[2]).abs() < 1e-5 && (l[2] - r[0]).abs() < 1e-5, "{l:?} {r:?}");
    assert!((l[0] + l[2] - 1.0).abs() < 1e-5 && l[0] > 0.5 && l[0] < 0.6, "{l:?}");
    // Far left is red, far right blue, and neighbours never jump.
    assert!(px(&img, 4, 32)[0] > 0.95 && px(&img, 59, 32)[2] > 0.95);
    for x in 1..64 {
        let (a, b) = (px(&img, x - 1, 32), px(&img, x, 32));
        assert!((a[0] - b[0]).abs() < 0.1, "jump at x = {x}: {a:?} → {b:?}");
    }
}

fn feature_texture() -> TextureRef {
    // 2×1: black | white, nearest: the left half of the uv square is black.
    let image =
        Texture { name: "f".into(), width: 2, height: 1, texels: vec![[0, 0, 0, 255], [255, 255, 255, 255]] };
    TextureRef { image: Arc::new(image), wrap: [Wrap::Clamp; 2], filter: Filter::Nearest }
}

/// 000 §2.2: the feature texture multiplies the shaded colour (H = S·T): dark features stay dark
/// under the wave's light, white leaves the shade unchanged.
#[test]
fn features_survive_the_waves_light() {
    let wave = point_wave("w", Vec3::new(0.0, 0.0, 3.0), Ramp::thesis_blue());
    let mut m = toon([1.0; 3], 1.0);
    m.feature_texture = Some(feature_texture());
    let wall = hadou_scene::mesh::transform_mesh(
        &plane_mesh([4.0, 4.0]),
        &Mat4::from_trs(Vec3f::ZERO, Vec3::new(90.0, 0.0, 0.0), Vec3::splat(1.0)),
    );
    let f = frame(64, Vec3::new(0.0, 0.0, 8.0), vec![object(wall, Vec3f::ZERO, m)], vec![wave]);
    let img = render(&f);
    // The plane spans about ±2/(8·tan 20°)·32 ≈ ±22 px; u runs left to right.
    assert!(close(px(&img, 20, 32), [0.0; 3], 1e-6), "{:?}", px(&img, 20, 32));
    assert!(close(px(&img, 44, 32), [0.9, 0.9, 1.0], 1e-4), "{:?}", px(&img, 44, 32));
}

fn outline_material(width: f32) -> Material {
    Material {
        outline: Some(Outline { width, color: [1.0, 0.0, 1.0] }),
        ..Material::diffuse([0.2, 0.8, 0.2])
    }
}

/// Number of outline-coloured pixels in row `y`, left of the centre.
fn outline_run(img: &Image, y: u32) -> usize {
    (0..img.width / 2).filter(|&x| px(img, x, y) == [1.0, 0.0, 1.0]).count()
}

/// 000 §2.3: the hull's offset is scaled by view depth, so the outline is as wide on screen at
/// any distance: the same sphere at distance 5 and 10 has outline widths within one pixel, both
/// about d / (2·tan(fov/2)) · height pixels.
#[test]
fn outline_width_is_constant_on_screen() {
    let d = 0.02;
    let widths: Vec<usize> = [5.0, 10.0]
        .iter()
        .map(|&dist| {
            let o = object(with_outline_normals(sphere_mesh(1.0, 96)), Vec3f::ZERO, outline_material(d));
            let img = render(&frame(256, Vec3::new(0.0, 0.0, dist), vec![o], Vec::new()));
            outline_run(&img, 128)
        })
        .collect();
    let expect = d / (2.0 * 20f32.to_radians().tan()) * 256.0;
    assert!(widths[0].abs_diff(widths[1]) <= 1, "{widths:?}");
    for w in &widths {
        assert!((*w as f32 - expect).abs() <= 1.5, "{widths:?} vs {expect}");
    }
    // The interior shows the object, not the hull.
    let o = object(with_outline_normals(sphere_mesh(1.0, 96)), Vec3f::ZERO, outline_material(d));
    let img = render(&frame(256, Vec3::new(0.0, 0.0, 5.0), vec![o], Vec::new()));
    assert_ne!(px(&img, 128, 128), [1.0, 0.0, 1.0]);
}

/// A hard-edged box gets a closed outline: with the hull pushed along normals averaged per corner
/// no background pixel touches the box's own surface.
#[test]
fn a_box_gets_a_closed_outline() {
    let cube = with_outline_normals(box_mesh([1.0, 1.0, 1.0]));
    let mut o = object(cube.clone(), Vec3f::ZERO, outline_material(0.01));
    o.transform = Mat4::from_trs(Vec3f::ZERO, Vec3::new(25.0, 35.0, 10.0), Vec3::splat(1.0));
    let img = render(&frame(128, Vec3::new(0.0, 1.0, 4.0), vec![o.clone()], Vec::new()));
    let is_bg = |x: u32, y: u32| px(&img, x, y) == BG;
    let is_surface = |x: u32, y: u32| !is_bg(x, y) && px(&img, x, y) != [1.0, 0.0, 1.0];
    let mut touching = 0;
    for y in 1..127 {
        for x in 1..127 {
            if is_surface(x, y)
                && [(x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)].iter().any(|&(a, b)| is_bg(a, b))
            {
                touching += 1;
            }
        }
    }
    assert_eq!(touching, 0, "the outline has gaps");
    // Without the averaged normals (face normals only) the hull splits at the edges.
    let mut open = cube;
    open.outline_normals.clear();
    o.mesh = Arc::new(open);
    let img2 = render(&frame(128, Vec3::new(0.0, 1.0, 4.0), vec![o], Vec::new()));
    let gaps = (1..127u32)
        .flat_map(|y| (1..127u32).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let c = px(&img2, x, y);
            c != BG
                && c != [1.0, 0.0, 1.0]
                && [(x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)]
                    .iter()
                    .any(|&(a, b)| px(&img2, a, b) == BG)
        })
        .count();
    assert!(gaps > 0, "face normals alone should leave gaps (the test would not see a broken hull)");
}
