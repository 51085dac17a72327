//! The surfaces' shading records: ramps, textures, materials (MToon's block), the waves as lights,
//! and the shading data buffer (`ShadingBuffers`).

use super::shadows::FrameShadows;
use super::waves::v4;
use bytemuck::{Pod, Zeroable};
use hadou_math::curve::PreparedCurve;
use hadou_math::energy::Falloff;
use hadou_math::toon::{Filter, Ramp, RampKind, Wrap, MAX_RAMP_BANDS};
use hadou_scene::{Frame, LightLine, ShadingModel, TextureRef, Wave};

/// `GpuRamp::kind` of [`RampKind::Bands`]. Keep in sync with `RAMP_BANDS` in common.wgsl.
pub const RAMP_BANDS: u32 = 0;
/// `GpuRamp::kind` of [`RampKind::Gradient`]. Keep in sync with `RAMP_GRADIENT`.
pub const RAMP_GRADIENT: u32 = 1;
/// `GpuMaterial::model` of [`ShadingModel::Diffuse`]. Keep in sync with `MODEL_DIFFUSE`.
pub const MODEL_DIFFUSE: u32 = 0;
/// `GpuMaterial::model` of [`ShadingModel::Toon`]. Keep in sync with `MODEL_TOON`.
pub const MODEL_TOON: u32 = 1;
/// `GpuMaterial::model` of [`ShadingModel::Unlit`]. Keep in sync with `MODEL_UNLIT`.
pub const MODEL_UNLIT: u32 = 2;
/// `GpuLight::line_kind`s: a point, a segment, an infinite line, a polyline. Keep in sync with
/// `LINE_*` in common.wgsl.
pub const LINE_POINT: u32 = 0;
/// See [`LINE_POINT`].
pub const LINE_SEGMENT: u32 = 1;
/// See [`LINE_POINT`].
pub const LINE_LINE: u32 = 2;
/// See [`LINE_POINT`].
pub const LINE_POLYLINE: u32 = 3;
/// Bit of the raster pass's material word marking an outline-hull fragment. Keep in sync with
/// `HULL_BIT` in common.wgsl.
pub const HULL_BIT: u32 = 1 << 31;
/// The material index's bits in the raster pass's material word (`MAX_MATERIAL_SLOTS` indices).
/// Keep in sync with `MATERIAL_MASK` in common.wgsl.
pub const MATERIAL_MASK: u32 = 0xffff;
/// Shift of the 8-bit hull reach (`hadou_math::outline::reach_code`) in the raster pass's
/// material word; the edge pass clears it. Keep in sync with `REACH_SHIFT` in common.wgsl.
pub const REACH_SHIFT: u32 = 16;
/// Number of 32-bit words at the start of the shading data buffer holding the sRGB → linear
/// table ([`hadou_math::toon::srgb_table`]).
pub const SRGB_TABLE_WORDS: u32 = 256;

/// A colour ramp ([`Ramp`]) in a fixed-size record. Keep in sync with `GpuRamp` in common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuRamp {
    /// `(threshold, r, g, b)` per stop; `count` are used.
    pub stops: [[f32; 4]; MAX_RAMP_BANDS],
    /// Stops used, `1..=8`.
    pub count: u32,
    /// [`RAMP_BANDS`] or [`RAMP_GRADIENT`].
    pub kind: u32,
    /// Band smoothing width.
    pub smoothing: f32,
    /// Padding.
    pub _pad: u32,
}

impl GpuRamp {
    /// The GPU form of `ramp` (extra stops beyond [`MAX_RAMP_BANDS`] are dropped; the scene
    /// loader refuses them).
    pub fn new(ramp: &Ramp) -> Self {
        let mut g = GpuRamp::zeroed();
        for (i, (t, c)) in ramp.stops.iter().take(MAX_RAMP_BANDS).enumerate() {
            g.stops[i] = [*t, c[0], c[1], c[2]];
        }
        g.count = ramp.stops.len().min(MAX_RAMP_BANDS) as u32;
        match ramp.kind {
            RampKind::Bands { smoothing } => {
                g.kind = RAMP_BANDS;
                g.smoothing = smoothing;
            }
            RampKind::Gradient => g.kind = RAMP_GRADIENT,
        }
        g
    }
}

/// Where a texture's texels are in the shading data buffer and how it is sampled. Keep in sync
/// with `GpuTexture` in common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuTexture {
    /// Word offset of texel (0, 0) in the shading data buffer; 0 = no texture.
    pub offset: u32,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Wrap u (bits 0–1), wrap v (bits 2–3), nearest filter (bit 4); wraps: 0 repeat, 1 clamp,
    /// 2 mirror.
    pub flags: u32,
}

/// One material. Keep in sync with `GpuMaterial` in common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuMaterial {
    /// Linear RGB base colour.
    pub base_color: [f32; 3],
    /// `MODEL_*`.
    pub model: u32,
    /// Outline colour (in a frame's buffers `hadou_scene::Material::outline_rgb`: an MToon
    /// outline's colour lit).
    pub outline_color: [f32; 3],
    /// `β`.
    pub wave_blend: f32,
    /// Outline width: `d` of the hull push `d·|z|` (for an MToon outline in screen mode
    /// `2·tan(fov/2)·w`), or `−w` for an MToon outline in world units (push `w`;
    /// [`gpu_outline_width`]); 0 = no outline.
    pub outline_width: f32,
    /// Bit `s` is set when [`Frame::shadows`]`[s]` lists the material's object among its
    /// receivers.
    pub shadow_mask: u32,
    /// Index of the material's object in the frame (the edge pass tells objects apart by it).
    pub object: u32,
    /// Word offset of the material's MToon block in the shading data ([`mtoon_block`]); 0 for
    /// none (the material's `model` look).
    pub mtoon: u32,
    /// Base-colour texture.
    pub base_texture: GpuTexture,
    /// Feature texture.
    pub feature_texture: GpuTexture,
    /// The toon ramp.
    pub ramp: GpuRamp,
}

/// One wave as a light (000 §2.1): its centre line, strength, falloff and ramp. Keep in sync with
/// `GpuLight` in common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuLight {
    /// `LINE_*`.
    pub line_kind: u32,
    /// Polyline: index of its first point in the shading data buffer (in words).
    pub point_offset: u32,
    /// Polyline: number of points.
    pub point_count: u32,
    /// 1 for the inverse-square falloff, 0 for the thesis's 1/r.
    pub inverse_square: u32,
    /// Point / segment start / a point on the line; `w` = strength `α·a`.
    pub a: [f32; 4],
    /// Segment end / unit line direction; `w` = glow.
    pub b: [f32; 4],
    /// Wave colour `rgb`; `w` = core radius.
    pub color: [f32; 4],
    /// The look ramp.
    pub ramp: GpuRamp,
}

/// The frame's materials, lights and shading data (sRGB table, texels, polyline points).
#[derive(Clone, Debug, Default)]
pub struct ShadingBuffers {
    /// One per material of every object, objects in order.
    pub materials: Vec<GpuMaterial>,
    /// One per wave.
    pub lights: Vec<GpuLight>,
    /// 32-bit words: the sRGB table, then texels (RGBA8 packed little-endian), then polyline
    /// points (3 `f32` bit patterns each).
    pub data: Vec<u32>,
    /// `GpuObject::material_base` per object.
    pub material_base: Vec<u32>,
}

fn wrap_bits(w: Wrap) -> u32 {
    match w {
        Wrap::Repeat => 0,
        Wrap::Clamp => 1,
        Wrap::Mirror => 2,
    }
}

/// Texels stored once per image in a data buffer of 32-bit words (RGBA8 packed little-endian),
/// for [`material_record`]: the shading data of the wave pass, or one material's own buffer.
#[derive(Debug, Default)]
pub struct TextureStore {
    stored: std::collections::HashMap<usize, u32>,
}

impl TextureStore {
    /// Where `t`'s texels are in `data` (appended the first time this image is seen) and how it
    /// is sampled; no texture gives a zeroed record (`offset` 0: opaque white).
    pub fn texture(&mut self, data: &mut Vec<u32>, t: &Option<TextureRef>) -> GpuTexture {
        let Some(t) = t else { return GpuTexture::zeroed() };
        let key = std::sync::Arc::as_ptr(&t.image) as usize;
        let offset = *self.stored.entry(key).or_insert_with(|| {
            let o = data.len() as u32;
            data.extend(t.image.texels.iter().map(|p| u32::from_le_bytes(*p)));
            o
        });
        GpuTexture {
            offset,
            width: t.image.width,
            height: t.image.height,
            flags: wrap_bits(t.wrap[0])
                | wrap_bits(t.wrap[1]) << 2
                | u32::from(t.filter == Filter::Nearest) << 4,
        }
    }
}

/// The sRGB → linear table as the first 256 words of a shading data buffer (shading.wgsl's
/// `srgb` reads it there).
pub fn srgb_words() -> impl Iterator<Item = u32> {
    hadou_math::toon::srgb_table().iter().map(|v| v.to_bits())
}

/// `m`'s record, its textures stored in `data` through `textures` (whose first 256 words must be
/// [`srgb_words`]); `shadow_mask` as [`GpuMaterial::shadow_mask`]; [`GpuMaterial::object`] 0.
pub fn material_record(
    m: &hadou_scene::Material,
    shadow_mask: u32,
    data: &mut Vec<u32>,
    textures: &mut TextureStore,
) -> GpuMaterial {
    GpuMaterial {
        base_color: m.base_color,
        model: match m.model {
            ShadingModel::Diffuse => MODEL_DIFFUSE,
            ShadingModel::Toon => MODEL_TOON,
            ShadingModel::Unlit => MODEL_UNLIT,
        },
        outline_color: m.outline.map_or([0.0; 3], |o| o.color),
        wave_blend: m.wave_blend,
        outline_width: m.outline.map_or(0.0, |o| o.width),
        shadow_mask,
        object: 0,
        mtoon: 0,
        base_texture: textures.texture(data, &m.base_texture),
        feature_texture: textures.texture(data, &m.feature_texture),
        ramp: GpuRamp::new(&m.ramp),
    }
}

/// [`GpuMaterial::outline_width`] of `m` for a camera of `tan_half_fov`
/// (`hadou_scene::Material::hull_push`: `d`, MToon's screen mode `2·tan_half_fov·w`, its world mode
/// `−w`); 0 without an outline or for a width that is not positive.
pub fn gpu_outline_width(m: &hadou_scene::Material, tan_half_fov: f32) -> f32 {
    if m.outline_in_world_units() {
        -m.hull_push(0.0, tan_half_fov)
    } else {
        m.hull_push(1.0, tan_half_fov)
    }
}

/// Words of an MToon block ([`mtoon_block`]).
pub const MTOON_WORDS: usize = 52;

/// Appends `m`'s MToon block to `data` (its textures through `textures`) for a frame at scene
/// time `time` seen from `eye`, and returns its word offset (0 when `m` has no MToon look).
/// Read by shading.wgsl's `mtoon_*` functions; the words are, as `f32` bit patterns unless
/// stated: 0–2 shade colour, 3 toony, 4–6 rim colour, 7 fresnel power, 8–10 matcap factor,
/// 11 rim lift, 12–14 emissive, 15 rim lighting mix, 16 shading shift, 17 shift texture scale,
/// 18–19 `scroll · time`, 20 `rotation · time`, 21 the mask channel (`u32`), 22–23 unused,
/// 24–26 the eye, 27 unused, then six [`GpuTexture`] records (4 words each): shade, shift, rim,
/// matcap, UV mask, emissive. The time-scaled terms are the products hadou-cpu forms, so both
/// backends animate alike.
pub fn mtoon_block(
    m: &hadou_scene::Material,
    time: f32,
    eye: [f32; 3],
    data: &mut Vec<u32>,
    textures: &mut TextureStore,
) -> u32 {
    let Some(t) = &m.mtoon else { return 0 };
    let recs = [
        &t.shade_texture,
        &t.shift_texture,
        &t.rim_texture,
        &t.matcap_texture,
        &t.uv_mask_texture,
        &t.emissive_texture,
    ]
    .map(|x| textures.texture(data, x));
    let offset = data.len() as u32;
    let f = |x: f32| x.to_bits();
    let c3 = |c: [f32; 3]| c.map(f);
    data.extend(c3(t.shade_color));
    data.push(f(t.toony));
    data.extend(c3(t.rim_color));
    data.push(f(t.rim_fresnel_power));
    data.extend(c3(t.matcap_color));
    data.push(f(t.rim_lift));
    data.extend(c3(t.emissive));
    data.push(f(t.rim_lighting_mix));
    data.extend([
        f(t.shading_shift),
        f(t.shift_texture_scale),
        f(t.uv_scroll[0] * time),
        f(t.uv_scroll[1] * time),
    ]);
    data.extend([f(t.uv_rotation * time), u32::from(t.uv_mask_channel.min(3)), 0, 0]);
    data.extend(c3(eye));
    data.push(0);
    for r in recs {
        data.extend([r.offset, r.width, r.height, r.flags]);
    }
    debug_assert_eq!(data.len() - offset as usize, MTOON_WORDS);
    offset
}

/// The waves as lights (000 §2.1): one record per wave, its centre line (`Wave::light_line`),
/// strength, glow, falloff, core radius and ramp; a polyline's points are appended to `data` (3
/// `f32` bit patterns each) and the record holds their word offset in `data`. `curves` are the
/// waves' prepared curves (`None` for an analytic wave, or to prepare it here).
pub fn wave_lights(waves: &[Wave], curves: &[Option<PreparedCurve>], data: &mut Vec<u32>) -> Vec<GpuLight> {
    let mut lights = Vec::with_capacity(waves.len());
    for (i, w) in waves.iter().enumerate() {
        let mut l = GpuLight::zeroed();
        l.inverse_square = u32::from(w.falloff == Falloff::InverseSquare);
        l.color = [w.color[0], w.color[1], w.color[2], w.core_radius];
        l.ramp = GpuRamp::new(&w.light.ramp);
        let (strength, glow) = (w.light_strength(), w.light.glow);
        match w.light_line(curves.get(i).and_then(Option::as_ref)) {
            LightLine::Point(p) => {
                l.line_kind = LINE_POINT;
                l.a = v4(p, strength);
                l.b = v4(p, glow);
            }
            LightLine::Segment(p, q) => {
                l.line_kind = LINE_SEGMENT;
                l.a = v4(p, strength);
                l.b = v4(q, glow);
            }
            LightLine::Line(p, d) => {
                l.line_kind = LINE_LINE;
                l.a = v4(p, strength);
                l.b = v4(d, glow);
            }
            LightLine::Polyline(pts) => {
                l.line_kind = LINE_POLYLINE;
                l.point_offset = data.len() as u32;
                l.point_count = pts.len() as u32;
                data.extend(pts.iter().flat_map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]));
                l.a = [0.0, 0.0, 0.0, strength];
                l.b = [0.0, 0.0, 0.0, glow];
            }
        }
        lights.push(l);
    }
    lights
}

impl ShadingBuffers {
    /// Builds the buffers of `frame`; `curves` are the frame's prepared curves (one per wave,
    /// `None` for analytic ones). Textures shared between materials are stored once.
    pub fn new(frame: &Frame, curves: &[Option<PreparedCurve>]) -> Self {
        let mut b = ShadingBuffers::default();
        b.data.extend(srgb_words());
        let mut textures = TextureStore::default();
        for (oi, o) in frame.objects.iter().enumerate() {
            b.material_base.push(b.materials.len() as u32);
            let shadow_mask = frame
                .shadows
                .iter()
                .take(32)
                .enumerate()
                .filter(|(_, s)| s.receives(oi as u32))
                .fold(0u32, |m, (si, _)| m | 1 << si);
            let fallback = [hadou_scene::Material::default()];
            let mats: &[hadou_scene::Material] =
                if o.materials.is_empty() { &fallback } else { &o.materials };
            let eye = frame.camera.position;
            let tan_half_fov = frame.camera.basis(frame.width, frame.height).tan_half_fov;
            for m in mats {
                let record = material_record(m, shadow_mask, &mut b.data, &mut textures);
                let mtoon = mtoon_block(m, frame.time, [eye.x, eye.y, eye.z], &mut b.data, &mut textures);
                b.materials.push(GpuMaterial {
                    object: oi as u32,
                    mtoon,
                    outline_width: gpu_outline_width(m, tan_half_fov),
                    outline_color: m.outline_rgb(&frame.light),
                    ..record
                });
            }
        }
        b.lights = wave_lights(&frame.waves, curves, &mut b.data);
        b
    }
}

impl ShadingBuffers {
    /// Appends the shadow cast records and the map casts' indices of `shadows` to the data buffer
    /// and returns their word offsets `(casts, map_casts)` (`FrameUniforms::shadow_casts`,
    /// `FrameUniforms::map_casts`).
    pub fn push_shadows(&mut self, shadows: &FrameShadows) -> (u32, u32) {
        let casts = self.data.len() as u32;
        self.data.extend_from_slice(bytemuck::cast_slice(&shadows.casts));
        let map_casts = self.data.len() as u32;
        self.data.extend_from_slice(&shadows.map_casts);
        (casts, map_casts)
    }
}
