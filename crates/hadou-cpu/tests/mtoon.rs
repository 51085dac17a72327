//! The MToon look (`VRMC_materials_mtoon` 1.0) on hand-built frames: a pixel's colour follows the
//! formulas of `hadou_math::mtoon` — the toony step between shade and base colour under the scene
//! light, ambient, parametric rim, matcap, emission, UV animation — a wave lights an MToon
//! surface with the material's own step in the wave's colour (000 §2.1), and MToon outlines are
//! as wide as their mode says, in their lit colour.

use hadou_cpu::render;
use hadou_math::energy::{Falloff, SphereField};
use hadou_math::toon::{srgb_to_linear, Filter, Wrap};
use hadou_math::{Mat4, Vec3, Vec3f};
use hadou_scene::mesh::{plane_mesh, sphere_mesh, with_outline_normals};
use hadou_scene::{
    ColorMapping, Frame, Image, Light, Material, Mtoon, Object, Texture, TextureRef, ToneMode, Wave,
    WaveShape,
};
use hadou_scene::{Outline, OutlineWidthMode};
use std::sync::Arc;

mod common;

/// N·(−L) on the wall: the light grazes it.
const NDL: f32 = 0.1;

/// A 6 × 6 wall in the xy plane facing the camera at (0, 0, 8), material `m`; the light makes
/// `N·(−L) = NDL`, colour (1, 0.9, 0.8), ambient 0.1; faithful mapping with a tiny exposure, so
/// pixels show the surface colour.
fn frame(m: Material, waves: Vec<Wave>) -> Frame {
    let wall = hadou_scene::mesh::transform_mesh(
        &plane_mesh([6.0, 6.0]),
        &Mat4::from_trs(Vec3f::ZERO, Vec3::new(90.0, 0.0, 0.0), Vec3::splat(1.0)),
    );
    let o =
        Object { name: "wall".into(), mesh: Arc::new(wall), transform: Mat4::IDENTITY, materials: vec![m] };
    let s = (1.0 - NDL * NDL).sqrt();
    Frame {
        light: Light { direction: Vec3::new(-s, 0.0, -NDL), color: [1.0, 0.9, 0.8], ambient: [0.1; 3] },
        color_mapping: ColorMapping { mode: ToneMode::Faithful, exposure: 1e-9 },
        ..common::frame(65, 65, common::camera(Vec3::new(0.0, 0.0, 8.0), 40.0), vec![o], waves)
    }
}

fn mtoon(t: Mtoon) -> Material {
    Material { mtoon: Some(Arc::new(t)), ..Material::diffuse([0.8, 0.6, 0.4]) }
}

fn tex(texels: Vec<[u8; 4]>) -> TextureRef {
    let image = Texture { name: "t".into(), width: texels.len() as u32, height: 1, texels };
    TextureRef { image: Arc::new(image), wrap: [Wrap::Repeat; 2], filter: Filter::Nearest }
}

fn px(img: &Image, x: u32, y: u32) -> [f32; 3] {
    let c = img.color[img.index(x, y)];
    [c[0], c[1], c[2]]
}

fn close(a: [f32; 3], b: [f32; 3], tol: f32) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() <= tol)
}

fn base_look() -> Mtoon {
    Mtoon {
        shade_color: [0.2, 0.1, 0.3],
        shading_shift: -0.05,
        toony: 0.9,
        rim_color: [1.0, 0.5, 0.0],
        rim_lift: 0.2,
        rim_fresnel_power: 2.0,
        rim_lighting_mix: 0.5,
        emissive: [0.01, 0.02, 0.03],
        ..Mtoon::default()
    }
}

/// The wall's centre pixel (facing the eye: N·V = 1): the step at N·(−L) + shift = 0.05 over
/// [−0.1, 0.1] is 0.75; lit = mix(shade, base, 0.75)·light = (0.65, 0.475, 0.375)·(1, 0.9, 0.8);
/// ambient base·0.1; rim (1 − 1 + 0.2)² · (1, 0.5, 0) · mix(1, light + ambient, 0.5); emission.
#[test]
fn the_centre_pixel_follows_the_mtoon_formulas() {
    let img = render(&frame(mtoon(base_look()), vec![]));
    let mix = [1.05, 1.0, 0.95];
    let want: [f32; 3] = std::array::from_fn(|k| {
        let lit = [0.65, 0.4275, 0.3][k];
        let gi = [0.08, 0.06, 0.04][k];
        let rim = 0.04 * [1.0, 0.5, 0.0][k] * mix[k];
        lit + gi + rim + [0.01, 0.02, 0.03][k]
    });
    assert!(close(px(&img, 32, 32), want, 1e-4), "{:?} vs {want:?}", px(&img, 32, 32));
    // The shade texture multiplies the shade colour: a black one leaves base·0.75 lit.
    let dark = Mtoon { shade_texture: Some(tex(vec![[0, 0, 0, 255]])), ..base_look() };
    let img = render(&frame(mtoon(dark), vec![]));
    let lit: [f32; 3] = std::array::from_fn(|k| [0.8, 0.6, 0.4][k] * 0.75 * [1.0, 0.9, 0.8][k]);
    let d = px(&img, 32, 32);
    assert!(close(d, std::array::from_fn(|k| want[k] - [0.65, 0.4275, 0.3][k] + lit[k]), 1e-4), "{d:?}");
}

/// The matcap adds `matcapFactor · matcap(uv)` to the rim, times `mix(1, light + ambient,
/// rimLightingMix)` (a one-texel matcap: the same value at every normal); the rim texture
/// multiplies the whole rim.
#[test]
fn matcap_and_rim_texture_scale_the_rim() {
    let plain = px(&render(&frame(mtoon(base_look()), vec![])), 32, 32);
    let cap = Mtoon {
        matcap_color: [0.5, 1.0, 0.25],
        matcap_texture: Some(tex(vec![[128, 128, 128, 255]])),
        ..base_look()
    };
    let with_cap = px(&render(&frame(mtoon(cap.clone()), vec![])), 32, 32);
    let g = srgb_to_linear(128);
    let mix = [1.05, 1.0, 0.95];
    for k in 0..3 {
        let want = plain[k] + [0.5, 1.0, 0.25][k] * g * mix[k];
        assert!((with_cap[k] - want).abs() < 1e-4, "{with_cap:?} channel {k}: {want}");
    }
    // A black rim texture takes the rim (parametric and matcap) away.
    let no_rim = Mtoon { rim_texture: Some(tex(vec![[0, 0, 0, 255]])), ..cap };
    let c = px(&render(&frame(mtoon(no_rim), vec![])), 32, 32);
    for k in 0..3 {
        let rim = 0.04 * [1.0, 0.5, 0.0][k] * mix[k];
        assert!((c[k] - (plain[k] - rim)).abs() < 1e-4, "{c:?}");
    }
}

/// UV animation: the base texture scrolls by `scroll · time` (mask 1): at time 1 with a scroll of
/// 0.25 per second, a pixel on texel 2 of a 4-texel texture shows texel 3.
#[test]
fn uv_animation_scrolls_with_frame_time() {
    let texels = vec![[255, 0, 0, 255], [0, 255, 0, 255], [0, 0, 255, 255], [255, 255, 0, 255]];
    let look = Mtoon { shade_color: [0.8, 0.6, 0.4], uv_scroll: [0.25, 0.0], ..Mtoon::default() };
    let m = Material { base_texture: Some(tex(texels)), ..mtoon(look) };
    let mut f = frame(m, vec![]);
    let at0 = px(&render(&f), 36, 32);
    f.time = 1.0;
    let at1 = px(&render(&f), 36, 32);
    // Blue texel at time 0, yellow at time 1 (red and green channels on, blue off).
    assert!(at0[2] > 0.1 && at0[0] < 1e-4 && at0[1] < 1e-4, "{at0:?}");
    assert!(at1[0] > 0.1 && at1[1] > 0.1 && at1[2] < 1e-4, "{at1:?}");
}

/// A wave lights an MToon surface with the material's own step over 000's m = N·L towards its
/// light point, in the wave's colour: with β = 1 the centre pixel is
/// `mix(shade, base, linearstep(−0.1, 0.1, m − 0.05)) · rgb`.
#[test]
fn a_wave_lights_mtoon_with_its_own_step() {
    let at = Vec3::new(-3.0, 0.0, 0.3);
    let mut w = Wave::new(
        "w",
        [0.5, 0.8, 1.0, 1.0],
        Falloff::InverseSquare,
        0.01,
        WaveShape::Sphere(SphereField { center: at, alpha: 1.0 }),
    );
    w.light.glow = 0.0;
    let m = Material { wave_blend: 1.0, ..mtoon(base_look()) };
    let img = render(&frame(m, vec![w]));
    let mm = at.z / at.length();
    let s = ((mm - 0.05 + 0.1) / 0.2).clamp(0.0, 1.0);
    assert!(s > 0.1 && s < 0.9, "{s}");
    let want: [f32; 3] = std::array::from_fn(|k| {
        let (shade, base) = ([0.2, 0.1, 0.3][k], [0.8, 0.6, 0.4][k]);
        (shade + (base - shade) * s) * [0.5, 0.8, 1.0][k]
    });
    assert!(close(px(&img, 32, 32), want, 2e-3), "{:?} vs {want:?}", px(&img, 32, 32));
}

/// A sphere of radius 1 at the origin seen from `(0, 0, dist)` on a black background, 128² with a
/// 40° field of view, its MToon outline in `mode` of width `w`, colour magenta, lighting mix
/// `mix`; the light (1, 0.9, 0.8), ambient 0.1.
fn outlined_ball(dist: f32, mode: OutlineWidthMode, w: f32, mix: f32) -> Frame {
    let look = Mtoon {
        outline_mode: mode,
        outline_width: w,
        outline_color: [1.0, 0.0, 1.0],
        outline_lighting_mix: mix,
        ..base_look()
    };
    let m = Material { outline: Some(Outline { width: w, color: [1.0, 0.0, 1.0] }), ..mtoon(look) };
    let ball = Object {
        name: "ball".into(),
        mesh: Arc::new(with_outline_normals(sphere_mesh(1.0, 64))),
        transform: Mat4::IDENTITY,
        materials: vec![m],
    };
    Frame {
        light: Light { direction: Vec3::new(0.0, -1.0, 0.0), color: [1.0, 0.9, 0.8], ambient: [0.1; 3] },
        color_mapping: ColorMapping { mode: ToneMode::Faithful, exposure: 1e-9 },
        ..common::frame(128, 128, common::camera(Vec3::new(0.0, 0.0, dist), 40.0), vec![ball], vec![])
    }
}

/// Outline pixels (the outline's colour, up to rounding) in the middle row, left of the centre.
fn outline_run(img: &Image, want: [f32; 3]) -> usize {
    (0..64).filter(|&x| close(px(img, x, 64), want, 1e-4)).count()
}

/// MToon outlines (`VRMC_materials_mtoon` "Outline"): in screen mode `w` of the image height
/// (0.05 · 128 = 6.4 pixels) at any distance; in world mode `w` world units, so twice as wide on
/// screen at half the distance (0.2 at a silhouette about `dist` away, `f = 64/tan 20°`: about
/// 4.4 px at 8, 8.8 px at 4); their colour `outlineColour · mix(1, light + ambient, mix)`.
#[test]
fn mtoon_outlines_in_screen_and_world_units() {
    let magenta = [1.0, 0.0, 1.0];
    for dist in [4.0, 8.0] {
        let n = outline_run(&render(&outlined_ball(dist, OutlineWidthMode::Screen, 0.05, 0.0)), magenta);
        assert!((5..=8).contains(&n), "screen mode at {dist}: {n} px");
    }
    let far = outline_run(&render(&outlined_ball(8.0, OutlineWidthMode::World, 0.2, 0.0)), magenta);
    let near = outline_run(&render(&outlined_ball(4.0, OutlineWidthMode::World, 0.2, 0.0)), magenta);
    assert!((3..=6).contains(&far), "world mode at 8: {far} px");
    assert!((7..=11).contains(&near), "world mode at 4: {near} px");
    // Lighting mix 0.5: magenta · mix(1, (1.1, 1.0, 0.9), 0.5) = (1.05, 0, 0.95), clamped to 1 by
    // the faithful mapping.
    let lit = [1.0, 0.0, 0.95];
    let n = outline_run(&render(&outlined_ball(8.0, OutlineWidthMode::Screen, 0.05, 0.5)), lit);
    assert!((5..=8).contains(&n), "lit outline: {n} px");
}
