//! Surface shading: a material's own look under the scene light, the waves as lights on it
//! (000 §2.1, SPEC.md §2.1), and the feature texture (000 §2.2). The GPU's wave pass mirrors
//! [`shade`] line by line (`crates/hadou-gpu/src/shaders/shading.wgsl`).

use hadou_math::curve::PreparedCurve;
use hadou_math::energy::Falloff;
use hadou_math::mtoon;
use hadou_math::soft::{lamp_cosine, lamp_spread, lamp_toon_cosine};
use hadou_math::toon;
use hadou_math::{shade as tone, Vec3f};
use hadou_scene::{AreaLight, Frame, LampShape, LightLine, Material, Mtoon, ShadingModel};

/// The interpolated attributes of a visible surface point.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Surface {
    /// World position.
    pub world: Vec3f,
    /// Interpolated world normal (not unit).
    pub normal: Vec3f,
    /// Texture coordinates.
    pub uv: [f32; 2],
    /// Linear RGBA vertex colour.
    pub color: [f32; 4],
}

/// The frame's waves as lights: each wave's centre line and what weighs it against the others.
pub(crate) struct FrameLights {
    /// Each wave's centre line as a light.
    pub lines: Vec<LightLine>,
    /// `α·a` per wave ([`hadou_scene::Wave::light_strength`]).
    strength: Vec<f32>,
    inverse_square: Vec<bool>,
    core: Vec<f32>,
    /// Whether any wave glows (then every surface takes the waves' light).
    any_glow: bool,
}

impl FrameLights {
    /// The lights of `frame`; `curves` are the wave pass's prepared curves (one per wave, `None`
    /// for analytic waves).
    pub(crate) fn new(frame: &Frame, curves: &[Option<PreparedCurve>]) -> Self {
        let lines = frame.waves.iter().zip(curves).map(|(w, c)| w.light_line(c.as_ref())).collect();
        FrameLights {
            lines,
            strength: frame.waves.iter().map(|w| w.light_strength()).collect(),
            inverse_square: frame.waves.iter().map(|w| w.falloff == Falloff::InverseSquare).collect(),
            core: frame.waves.iter().map(|w| w.core_radius).collect(),
            any_glow: frame.waves.iter().any(|w| w.light.glow > 0.0),
        }
    }
}

/// Most waves whose densities one surface point weighs at once without allocating.
const STACK_WAVES: usize = 16;

/// Albedo `A = base_color · base_texture(uv) · vertex colour` of a surface point with material `m`.
fn albedo(m: &Material, s: &Surface) -> [f32; 3] {
    let tex = m.base_texture.as_ref().map_or([1.0; 4], |t| t.sample(s.uv));
    // Vertex colours are shaded at 8 bits per channel (the GPU's G-buffer keeps them as unorm8,
    // WGSL `pack4x8unorm`): round(255·clamp(c, 0, 1)) / 255.
    let vcolor = s.color.map(|c| (0.5 + 255.0 * c.clamp(0.0, 1.0)).floor() / 255.0);
    std::array::from_fn(|k| m.base_color[k] * tex[k] * vcolor[k])
}

/// What an MToon material reads at a surface point before any light: the animated texture
/// coordinates, the albedo there, the shade colour and the shading shift.
struct MtoonPoint {
    /// Texture coordinates after the UV animation (every texture but the matcap reads them).
    uv: [f32; 2],
    /// `base_color · base_texture · vertex colour`.
    albedo: [f32; 3],
    /// `shadeColorFactor · shadeMultiplyTexture`.
    shade: [f32; 3],
    /// `shadingShiftFactor + shadingShiftTexture.r · scale`.
    shift: f32,
}

fn rgb(c: [f32; 4]) -> [f32; 3] {
    [c[0], c[1], c[2]]
}

/// The [`MtoonPoint`] of `s` at scene time `time` (MToon "UV Animation": the mask channel scales
/// `scroll·time` and `rotation·time`; `hadou_math::mtoon::uv_animation`).
fn mtoon_point(m: &Material, t: &Mtoon, s: &Surface, time: f32) -> MtoonPoint {
    let channel = usize::from(t.uv_mask_channel.min(3));
    let mask =
        t.uv_mask_texture.as_ref().map_or(1.0, |x| mtoon::data_texel(x.sample(s.uv)[channel], channel));
    let uv =
        mtoon::uv_animation(s.uv, mask, [t.uv_scroll[0] * time, t.uv_scroll[1] * time], t.uv_rotation * time);
    let albedo = albedo(m, &Surface { uv, ..*s });
    let st = t.shade_texture.as_ref().map_or([1.0; 4], |x| x.sample(uv));
    let shade = std::array::from_fn(|k| t.shade_color[k] * st[k]);
    let shift = t.shading_shift
        + t.shift_texture
            .as_ref()
            .map_or(0.0, |x| mtoon::data_texel(x.sample(uv)[0], 0) * t.shift_texture_scale);
    MtoonPoint { uv, albedo, shade, shift }
}

/// The MToon look under the scene light (`VRMC_materials_mtoon` 1.0 "Lighting", "Global
/// Illumination", "Rim Lighting", "MatCap", "Emission"; `hadou_math::mtoon`):
/// `mix(shade, A, linearstep(−1 + toony, 1 − toony, N·(−L) + shift)) · light` (hadou's hard
/// shadows then darken the whole shaded colour, as for every material), plus `A · ambient` (the
/// ambient light is uniform, so GI equalisation changes nothing), plus the rim
/// `(matcapFactor · matcap(view-space N) + pow(saturate(1 − N·V + lift), power) · rimColour) ·
/// rimTexture · mix(1, light + ambient, rimLightingMix)`, plus `emissive · emissiveTexture`.
fn mtoon_own(frame: &Frame, t: &Mtoon, p: &MtoonPoint, n: Vec3f, world: Vec3f) -> [f32; 3] {
    let l = &frame.light;
    let sh = mtoon::shading(n.dot(-l.direction), p.shift, t.toony);
    let direct = mtoon::lit(p.shade, p.albedo, sh, l.color);
    let v = (frame.camera.position - world).normalize_or(n);
    let para = mtoon::parametric_rim(n.dot(v), t.rim_lift, t.rim_fresnel_power, t.rim_color);
    let cap = t.matcap_texture.as_ref().map_or([0.0; 3], |x| {
        let c = x.sample(mtoon::matcap_uv(n, v));
        std::array::from_fn(|k| t.matcap_color[k] * c[k])
    });
    let rt = t.rim_texture.as_ref().map_or([1.0; 4], |x| x.sample(p.uv));
    let lighting: [f32; 3] = std::array::from_fn(|k| l.color[k] + l.ambient[k]);
    let mix = mtoon::lighting_mix(lighting, t.rim_lighting_mix);
    let et = t.emissive_texture.as_ref().map_or([1.0; 4], |x| x.sample(p.uv));
    std::array::from_fn(|k| {
        let rim = (cap[k] + para[k]) * rt[k] * mix[k];
        hadou_math::energy::saturate(direct[k] + p.albedo[k] * l.ambient[k] + rim + t.emissive[k] * et[k])
    })
}

/// The look a wave of colour `rgb` gives an MToon surface (000 §2.1 with the material's own
/// step): `mix(shade, A, linearstep(−1 + toony, 1 − toony, m + shift)) · rgb` over the unclamped
/// `m = N·L` towards the wave's light point.
fn mtoon_wave(t: &Mtoon, p: &MtoonPoint, m: f32, rgb: [f32; 3]) -> [f32; 3] {
    mtoon::lit(p.shade, p.albedo, mtoon::shading(m, p.shift, t.toony), rgb)
}

/// What the `[area_light]` adds to a surface point with material `m` where it is fully visible
/// (the soft shadow's visibility scales it): with `l̂` the unit vector from the point to the light
/// centre `L` and `m = N·l̂`, diffuse `A·E·max(0, m)`, toon `A·E·ramp(m)` (unclamped `m`, as the
/// waves light toon materials, 000 §2.1), MToon `mix(shade, A, step(m + shift)) · E` (its own
/// step, at the animated texture coordinates), unlit nothing; `E` the light's colour times
/// intensity; then the feature texture, as for [`shade`]. That is the segment lamp's light
/// (`shape = "segment"`). A disc or sphere lamp (hadou's own, issue 43) spreads over an angular
/// radius `σ` and faces the point by `f` ([`lamp_spread`]: the disc `f = max(0, l̂·P)`,
/// `sin²σ = l²/(l² + d²)`; the sphere `f = 1`, `sin σ = l/d`; `d = |L − p|`): diffuse
/// `A·E·f·lamp_cosine(m, sin σ)` (the horizon-clipped sphere irradiance, [`lamp_cosine`]), toon
/// `A·E·f·ramp(m')` and MToon `f·mix(shade, A, step(m' + shift))·E` with
/// `m' = lamp_toon_cosine(m, sin σ)`. Mirrored by `area_term` in `shading.wgsl`.
pub(crate) fn area_term(light: &AreaLight, m: &Material, s: &Surface, time: f32) -> [f32; 3] {
    let n = s.normal.normalize_or(Vec3f::ZERO);
    let dir = (light.position - s.world).normalize_or(Vec3f::ZERO);
    let mdot = n.dot(dir);
    // The diffuse factor, the ramps' input and the facing (the segment's: exactly as before).
    let (diffuse, ramp_in, facing) = match light.shape {
        LampShape::Segment => (mdot.max(0.0), mdot, None),
        shape => {
            let (f, sin_sigma) = lamp_spread(shape, light.position, light.axis(), light.size, s.world);
            (f * lamp_cosine(mdot, sin_sigma), lamp_toon_cosine(mdot, sin_sigma), Some(f))
        }
    };
    let face = |k: [f32; 3]| facing.map_or(k, |f| k.map(|x| x * f));
    if let Some(t) = &m.mtoon {
        let p = mtoon_point(m, t, s, time);
        let k = face(mtoon_wave(t, &p, ramp_in, light.color));
        let f = m.feature_texture.as_ref().map_or([1.0; 4], |x| x.sample(p.uv));
        return std::array::from_fn(|i| hadou_math::energy::saturate(k[i] * f[i]));
    }
    let k: [f32; 3] = match m.model {
        ShadingModel::Diffuse => [diffuse; 3],
        ShadingModel::Toon => face(m.ramp.eval(ramp_in)),
        ShadingModel::Unlit => return [0.0; 3],
    };
    let a = albedo(m, s);
    let f = m.feature_texture.as_ref().map_or([1.0; 4], |t| t.sample(s.uv));
    std::array::from_fn(|i| hadou_math::energy::saturate(a[i] * light.color[i] * k[i] * f[i]))
}

/// The shaded linear RGB of a surface point with material `m`:
///
/// 1. albedo `A = base_color · base_texture(uv) · vertex colour`;
/// 2. own look: diffuse `A·(ambient + light·max(0, N·(−L)))`, toon `A·ramp(N·(−L))` (unclamped
///    `N·(−L)`), unlit `A`, or MToon (a material with [`Material::mtoon`], whatever its model;
///    `mtoon_own`, at the animated texture coordinates, which every texture of the material
///    reads);
/// 3. wave look (when the material's `β = wave_blend > 0` and a wave has strength): for each wave
///    `i`, the light point `Eᵢ` = nearest point of its centre line, `mᵢ = N·Lᵢ` unclamped
///    (000 §2.1), look `rampᵢ(mᵢ)` (MToon: the material's own step over `mᵢ` in the wave's
///    colour, `mtoon_wave`); the looks are weighted by
///    [`toon::dominance_weights`] of the waves' densities at the point; `S = own + β·(wave − own)`;
/// 4. glow (waves with `light_glow > 0`): `S += glowᵢ · rgbᵢ · ρᵢ`, `ρᵢ` the density of
///    [`toon::dominance`];
/// 5. feature texture: `H = S · T(uv)` (000 §2.2).
pub(crate) fn shade(frame: &Frame, lights: &FrameLights, m: &Material, s: &Surface) -> [f32; 3] {
    let n = s.normal.normalize_or(Vec3f::ZERO);
    let l = &frame.light;
    let point = m.mtoon.as_ref().map(|t| (t.as_ref(), mtoon_point(m, t, s, frame.time)));
    let mut c = match (&point, m.model) {
        (Some((t, p)), _) => mtoon_own(frame, t, p, n, s.world),
        (None, ShadingModel::Diffuse) => tone::diffuse(albedo(m, s), n, l.direction, l.color, l.ambient),
        (None, ShadingModel::Toon) => {
            let (a, r) = (albedo(m, s), m.ramp.eval(n.dot(-l.direction)));
            std::array::from_fn(|k| a[k] * r[k])
        }
        (None, ShadingModel::Unlit) => albedo(m, s),
    };
    let uv = point.as_ref().map_or(s.uv, |(_, p)| p.uv);
    let waves = &frame.waves;
    if !waves.is_empty() && (m.wave_blend > 0.0 || lights.any_glow) {
        let mut rho_buf = [0.0f32; STACK_WAVES];
        let mut rho_vec = Vec::new();
        let rho: &mut [f32] = if waves.len() <= STACK_WAVES {
            &mut rho_buf[..waves.len()]
        } else {
            rho_vec.resize(waves.len(), 0.0);
            &mut rho_vec
        };
        let mut nearest_buf = [Vec3f::ZERO; STACK_WAVES];
        let mut nearest_vec = Vec::new();
        let nearest: &mut [Vec3f] = if waves.len() <= STACK_WAVES {
            &mut nearest_buf[..waves.len()]
        } else {
            nearest_vec.resize(waves.len(), Vec3f::ZERO);
            &mut nearest_vec
        };
        for i in 0..waves.len() {
            let e = lights.lines[i].nearest(s.world);
            nearest[i] = e;
            rho[i] = toon::dominance(
                (e - s.world).length(),
                lights.core[i],
                lights.strength[i],
                lights.inverse_square[i],
            );
        }
        // Glow before the densities become weights.
        let mut glow = [0.0f32; 3];
        for (i, w) in waves.iter().enumerate() {
            if w.light.glow > 0.0 {
                for (g, c) in glow.iter_mut().zip(&w.color) {
                    *g += w.light.glow * c * rho[i];
                }
            }
        }
        if m.wave_blend > 0.0 {
            toon::dominance_weights(rho);
            if rho.iter().any(|&w| w > 0.0) {
                let mut look = [0.0f32; 3];
                for (i, w) in waves.iter().enumerate() {
                    if rho[i] > 0.0 {
                        let wm = toon::wave_m(s.world, n, nearest[i]);
                        let r = match &point {
                            Some((t, p)) => mtoon_wave(t, p, wm, rgb(w.color)),
                            None => w.light.ramp.eval(wm),
                        };
                        for k in 0..3 {
                            look[k] += rho[i] * r[k];
                        }
                    }
                }
                for k in 0..3 {
                    c[k] += m.wave_blend * (look[k] - c[k]);
                }
            }
        }
        for k in 0..3 {
            c[k] = hadou_math::energy::saturate(c[k] + glow[k]);
        }
    }
    if let Some(t) = &m.feature_texture {
        let f = t.sample(uv);
        for k in 0..3 {
            c[k] *= f[k];
        }
    }
    c
}
