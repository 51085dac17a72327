//! The GPU-visible structs: one Rust definition each, `bytemuck::Pod` with explicit padding.
//!
//! Keep in sync with `src/shaders/common.wgsl` (same names, same field order, same padding);
//! `shaders::tests::gpu_structs_match_their_rust_definitions` checks every member offset and
//! struct size against the layout naga computes for the WGSL side.

use bytemuck::{Pod, Zeroable};
use hadou_math::curve::{self, CurveShape, Integrator, PreparedCurve, DEFAULT_SETTINGS};
use hadou_math::energy::Falloff;
use hadou_math::outline;
use hadou_math::shadow::MapFrame;
use hadou_math::toon::{Filter, Ramp, RampKind, Wrap, MAX_RAMP_BANDS};
use hadou_math::{Mat4, Vec3f};
use hadou_scene::{
    CameraBasis, Frame, LightLine, Object, SampleGrid, ShadingModel, ShadowCast, ShadowMethod, TextureRef,
    ToneMode, Wave, WaveShape,
};

/// `GpuWave::kind` of a sphere field. Keep in sync with `WAVE_SPHERE` in common.wgsl.
pub const WAVE_SPHERE: u32 = 0;
/// `GpuWave::kind` of an infinite cylinder field. Keep in sync with `WAVE_CYLINDER`.
pub const WAVE_CYLINDER: u32 = 1;
/// `GpuWave::kind` of a capsule field. Keep in sync with `WAVE_CAPSULE`.
pub const WAVE_CAPSULE: u32 = 2;
/// `GpuWave::kind` of a bulged beam. Keep in sync with `WAVE_BEAM`.
pub const WAVE_BEAM: u32 = 3;
/// `GpuWave::kind` of a curved wave. Keep in sync with `WAVE_CURVE`.
pub const WAVE_CURVE: u32 = 4;
/// `GpuCurve::integrator` of [`Integrator::Default`]. Keep in sync with `INTEGRATOR_DEFAULT`.
pub const INTEGRATOR_DEFAULT: u32 = 0;
/// `GpuCurve::integrator` of [`Integrator::Simpson`]. Keep in sync with `INTEGRATOR_SIMPSON`.
pub const INTEGRATOR_SIMPSON: u32 = 1;
/// `GpuCurve::integrator` of [`Integrator::Nearest`]. Keep in sync with `INTEGRATOR_NEAREST`.
pub const INTEGRATOR_NEAREST: u32 = 2;
/// `GpuCurve::shape` of [`CurveShape::Helix`]. Keep in sync with `SHAPE_HELIX`.
pub const SHAPE_HELIX: u32 = 0;
/// `GpuCurve::shape` of [`CurveShape::TrigSum`]. Keep in sync with `SHAPE_TRIG`.
pub const SHAPE_TRIG: u32 = 1;
/// `GpuCurve::shape` of [`CurveShape::Bezier`]. Keep in sync with `SHAPE_BEZIER`.
pub const SHAPE_BEZIER: u32 = 2;
/// `GpuCurve::shape` of [`CurveShape::BSpline`]. Keep in sync with `SHAPE_BSPLINE`.
pub const SHAPE_BSPLINE: u32 = 3;
/// `GpuWave::falloff` of [`Falloff::Faithful`]. Keep in sync with `FALLOFF_FAITHFUL`.
pub const FALLOFF_FAITHFUL: u32 = 0;
/// `GpuWave::falloff` of [`Falloff::InverseSquare`]. Keep in sync with `FALLOFF_INVERSE_SQUARE`.
pub const FALLOFF_INVERSE_SQUARE: u32 = 1;
/// `FrameUniforms::tone_mode` of [`ToneMode::Faithful`]. Keep in sync with `TONE_FAITHFUL`.
pub const TONE_FAITHFUL: u32 = 0;
/// `FrameUniforms::tone_mode` of [`ToneMode::Filmic`]. Keep in sync with `TONE_FILMIC`.
pub const TONE_FILMIC: u32 = 1;
/// `FrameUniforms::tone_mode` of a frame with a `[bloom]`: the wave pass writes the linear colour,
/// unmapped (bloom.wgsl maps it after the glare). Keep in sync with `TONE_LINEAR`.
pub const TONE_LINEAR: u32 = 2;

/// Per-frame, per-tile uniforms: camera basis, light, colour mapping and the tile's place in the
/// image. Keep in sync with `FrameUniforms` in common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameUniforms {
    /// Eye `S`.
    pub eye: [f32; 3],
    /// `tan(fov_y / 2)`.
    pub tan_half_fov: f32,
    /// Unit right.
    pub right: [f32; 3],
    /// Width / height.
    pub aspect: f32,
    /// Unit up.
    pub up: [f32; 3],
    /// Near plane distance.
    pub near: f32,
    /// Unit forward.
    pub forward: [f32; 3],
    /// Far plane distance.
    pub far: f32,
    /// Background linear RGB.
    pub background: [f32; 3],
    /// Wave colour multiplier.
    pub exposure: f32,
    /// Unit direction the light travels.
    pub light_dir: [f32; 3],
    /// [`TONE_FAITHFUL`] or [`TONE_FILMIC`].
    pub tone_mode: u32,
    /// Light intensity, linear RGB.
    pub light_color: [f32; 3],
    /// Number of waves in the wave buffer.
    pub wave_count: u32,
    /// Ambient term, linear RGB.
    pub ambient: [f32; 3],
    /// 1 when some wave glows (`light_glow > 0`): every surface then takes the waves' light.
    pub any_glow: u32,
    /// Whole image size in pixels.
    pub image_size: [u32; 2],
    /// Top-left pixel of the tile in the image.
    pub tile_origin: [u32; 2],
    /// Tile size in pixels.
    pub tile_size: [u32; 2],
    /// Word offset of the frame's [`GpuShadowCast`] records in the shading data buffer
    /// ([`ShadingBuffers::push_shadows`]).
    pub shadow_casts: u32,
    /// Word offset of the map casts' indices (into the cast records) in the shading data buffer.
    pub map_casts: u32,
    /// Tile NDC = image NDC · scale + offset.
    pub ndc_scale: [f32; 2],
    /// See `ndc_scale`.
    pub ndc_offset: [f32; 2],
    /// Number of shadow casts (records at `shadow_casts`); 0 = no shadows.
    pub cast_count: u32,
    /// Number of map casts (indices at `map_casts`).
    pub map_count: u32,
    /// Number of plane casts (when 0 the wave pass does not read the plane-shadow target).
    pub plane_count: u32,
    /// 1 when the frame has an `[area_light]`: the wave pass then reads each pixel's soft-shadow
    /// visibility where it later writes the eye distance, and adds the area term (soft.wgsl).
    pub area: u32,
    /// The area light's centre `L`.
    pub area_position: [f32; 3],
    /// How far the edge pass looks for outlines, in pixels (`hadou_math::outline::reach_window`
    /// of the widest outline; 0: nothing is outlined).
    pub outline_reach: u32,
    /// The area light's colour times intensity.
    pub area_color: [f32; 3],
    /// The edge of the sample grid (`Frame::grid`): 1, or with anti-aliasing these are the
    /// sample frame's uniforms and the wave pass resolves `grid × grid` samples per pixel.
    pub grid: u32,
}

/// How far the edge pass looks (pixels): the widest outline's hull width on screen, rounded up
/// and capped (`hadou_math::outline::reach_window`, as hadou-cpu's `edges::frame_reach`).
fn outline_reach(frame: &Frame) -> u32 {
    outline::reach_window(hadou_scene::widest_outline_pixels(frame))
}

impl FrameUniforms {
    /// Uniforms of the tile at `origin` with `size` pixels, for `frame` seen through `basis`;
    /// `grid` is the sample grid of the image `frame`'s pixels resolve into (`frame` itself is
    /// the sample frame with anti-aliasing, so its own `samples` is 1).
    pub fn new(
        frame: &Frame,
        basis: &CameraBasis,
        origin: [u32; 2],
        size: [u32; 2],
        grid: SampleGrid,
    ) -> Self {
        let (w, h) = (frame.width as f32, frame.height as f32);
        let (tw, th) = (size[0] as f32, size[1] as f32);
        let (ox, oy) = (origin[0] as f32, origin[1] as f32);
        Self {
            eye: basis.eye.to_array(),
            tan_half_fov: basis.tan_half_fov,
            right: basis.right.to_array(),
            aspect: basis.aspect,
            up: basis.up.to_array(),
            near: frame.camera.near,
            forward: basis.forward.to_array(),
            far: frame.camera.far,
            background: frame.background,
            exposure: frame.color_mapping.exposure,
            light_dir: frame.light.direction.to_array(),
            tone_mode: match frame.color_mapping.mode {
                ToneMode::Faithful => TONE_FAITHFUL,
                ToneMode::Filmic => TONE_FILMIC,
            },
            light_color: frame.light.color,
            wave_count: frame.waves.len() as u32,
            ambient: frame.light.ambient,
            any_glow: u32::from(frame.waves.iter().any(|w| w.light.glow > 0.0)),
            image_size: [frame.width, frame.height],
            tile_origin: origin,
            tile_size: size,
            shadow_casts: 0,
            map_casts: 0,
            // Image NDC x_g = 2(px + ½)/W − 1; tile NDC x_t = 2(px − ox + ½)/tw − 1
            // = x_g·W/tw + (W − 2·ox − tw)/tw. For y (downwards rows) the same with a sign flip.
            ndc_scale: [w / tw, h / th],
            ndc_offset: [(w - 2.0 * ox - tw) / tw, (th - h + 2.0 * oy) / th],
            cast_count: 0,
            map_count: 0,
            plane_count: 0,
            area: u32::from(frame.area_light.is_some()),
            area_position: frame.area_light.as_ref().map_or([0.0; 3], |a| a.position.to_array()),
            outline_reach: outline_reach(frame),
            area_color: frame.area_light.as_ref().map_or([0.0; 3], |a| a.color),
            grid: grid.edge(),
        }
    }
}

/// One object's transforms and where its materials start. Keep in sync with `GpuObject` in
/// common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuObject {
    /// Object → world, column-major.
    pub model: [[f32; 4]; 4],
    /// [`Mat4::normal_matrix`] of `model`.
    pub normal_matrix: [[f32; 4]; 4],
    /// Index of the object's first material in the frame's material buffer.
    pub material_base: u32,
    /// Number of its materials (≥ 1); a vertex's slot is clamped to `count − 1`.
    pub material_count: u32,
    /// Padding.
    pub _pad: [u32; 2],
}

impl GpuObject {
    /// The GPU form of `object`, whose materials start at `material_base`.
    pub fn new(object: &Object, material_base: u32) -> Self {
        let m: Mat4 = object.transform;
        Self {
            model: m.cols,
            normal_matrix: m.normal_matrix().cols,
            material_base,
            material_count: object.materials.len().max(1) as u32,
            _pad: [0; 2],
        }
    }
}

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

/// `GpuShadowCast::map_size` of a plane cast. Map casts have a size of at least 1.
pub const CAST_PLANE: u32 = 0;
/// 32-bit words per [`GpuShadowCast`] record in the shading data buffer. Keep in sync with
/// `SHADOW_CAST_WORDS` in common.wgsl.
pub const SHADOW_CAST_WORDS: u32 = (std::mem::size_of::<GpuShadowCast>() / 4) as u32;

/// One shadow cast ([`ShadowCast`]): a plane projection or a shadow map, with what the passes
/// need of its shadow. The plane-shadow and map passes read them from a storage buffer, the wave
/// pass from the shading data buffer (word by word, `load_shadow_cast` in shadow_lookup.wgsl).
/// Keep in sync with `GpuShadowCast` in common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuShadowCast {
    /// Unit projection direction `k` ([`MapFrame::k`] for a map).
    pub k: [f32; 3],
    /// Effective opacity, `> 0`.
    pub opacity: f32,
    /// Plane: a point of the receiver plane.
    pub plane_point: [f32; 3],
    /// Index of the cast's shadow in [`Frame::shadows`] (its bit in `GpuMaterial::shadow_mask`).
    pub shadow: u32,
    /// Plane: the plane's unit normal.
    pub plane_normal: [f32; 3],
    /// Plane: the depth the plane-shadow pass writes (`rank · 2⁻²⁴`, rank 0 for the largest
    /// opacity of the frame's plane casts), so that its `Less` test keeps the most opaque cast
    /// and, among equal opacities, the first.
    pub depth_key: f32,
    /// The shadow's linear RGB colour.
    pub color: [f32; 3],
    /// Map: edge in texels; [`CAST_PLANE`] for a plane cast.
    pub map_size: u32,
    /// Map: [`MapFrame::center`].
    pub map_center: [f32; 3],
    /// Map: `0.5 / radius`, as [`MapFrame::to_map`] computes it.
    pub map_scale: f32,
    /// Map: [`MapFrame::u`].
    pub map_u: [f32; 3],
    /// Map: layer of the shadow-map array texture.
    pub map_layer: u32,
    /// Map: [`MapFrame::v`].
    pub map_v: [f32; 3],
    /// Map: [`MapFrame::bias`] of `map_size`.
    pub map_bias: f32,
}

/// The GPU form of a frame's shadow casts ([`Frame::shadow_casts`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameShadows {
    /// One record per cast, in cast order.
    pub casts: Vec<GpuShadowCast>,
    /// Indices of the map casts, in cast order (map cast `i` is in layer `i`).
    pub map_casts: Vec<u32>,
    /// Edge of the shadow-map texture: the largest map size (0 without map casts).
    pub map_size: u32,
    /// Layers of the shadow-map texture: at least 2 (OpenGL backends mistake a one-layer array
    /// texture for a plain 2D one).
    pub map_layers: u32,
}

impl FrameShadows {
    /// The records of `casts` (from [`Frame::shadow_casts`] of `frame`).
    pub fn new(frame: &Frame, casts: &[ShadowCast]) -> Self {
        let mut opacities: Vec<f32> = casts.iter().filter(|c| c.map.is_none()).map(|c| c.opacity).collect();
        opacities.sort_by(|a, b| b.total_cmp(a));
        opacities.dedup();
        let mut out = FrameShadows { map_layers: 2, ..Default::default() };
        for (j, c) in casts.iter().enumerate() {
            let shadow = &frame.shadows[c.shadow as usize];
            let mut g = GpuShadowCast::zeroed();
            g.k = c.k.to_array();
            g.opacity = c.opacity;
            g.shadow = c.shadow;
            g.color = shadow.color;
            match (c.map, shadow.method) {
                (Some(map), ShadowMethod::Map { size }) => {
                    let size = size.max(1);
                    g.k = map.k.to_array();
                    g.map_size = size;
                    g.map_center = map.center.to_array();
                    g.map_scale = 0.5 / map.radius;
                    g.map_u = map.u.to_array();
                    g.map_v = map.v.to_array();
                    g.map_layer = out.map_casts.len() as u32;
                    g.map_bias = MapFrame::bias(size);
                    out.map_casts.push(j as u32);
                    out.map_size = out.map_size.max(size);
                }
                (_, ShadowMethod::Plane(plane)) => {
                    g.plane_point = plane.point.to_array();
                    g.plane_normal = plane.normal.to_array();
                    let rank = opacities.partition_point(|&o| o > c.opacity);
                    // Exact in f32 below 2²⁴ ranks; more distinct opacities than that cannot occur
                    // (each cast draws at least one mesh).
                    g.depth_key = rank.min((1 << 24) - 1) as f32 / (1u32 << 24) as f32;
                }
                // A map shadow's cast without a map frame (`shadow_casts` makes none): inert, its
                // zero plane normal makes every `t` NaN, so it covers no pixel.
                (None, ShadowMethod::Map { .. }) => {}
            }
            out.casts.push(g);
        }
        out.map_layers = out.map_layers.max(out.map_casts.len() as u32);
        out
    }
}

/// One analytic wave. Keep in sync with `GpuWave` in common.wgsl.
///
/// | kind | `p0` | `p1` | `p2` |
/// |---|---|---|---|
/// | sphere | centre `M`, `α_s` | — | — |
/// | cylinder | point `M`, `α_c` | unit axis `D`, — | — |
/// | capsule | `M`, `α_s` | `D`, `α_c` | `length`, —, — |
/// | beam | `M`, `α_s` | `D`, `α_c` | `length`, `head_alpha`, `muzzle_alpha` |
/// | curve | index into [`CurveBuffers::curves`], —, —, — | — | — |
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuWave {
    /// Base colour `(r, g, b, a)`.
    pub color: [f32; 4],
    /// One of the `WAVE_*` codes.
    pub kind: u32,
    /// [`FALLOFF_FAITHFUL`] or [`FALLOFF_INVERSE_SQUARE`].
    pub falloff: u32,
    /// Core radius `r_c`.
    pub core_radius: f32,
    /// Exponent `j` of the distance attenuation `(1 − u)^j` of an analytic wave (002 eq. 3.23,
    /// SPEC.md §1.4; 0: none). A curve's is in its [`GpuCurve`]; here it is 0.
    pub attenuation: f32,
    /// See the table above.
    pub p0: [f32; 4],
    /// See the table above.
    pub p1: [f32; 4],
    /// See the table above.
    pub p2: [f32; 4],
}

fn v4(v: Vec3f, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

impl GpuWave {
    /// The GPU form of an analytic wave, or `None` for a curved wave (see [`GpuWave::curve`]).
    pub fn new(wave: &Wave) -> Option<Self> {
        let mut g = Self {
            color: wave.color,
            kind: 0,
            falloff: match wave.falloff {
                Falloff::Faithful => FALLOFF_FAITHFUL,
                Falloff::InverseSquare => FALLOFF_INVERSE_SQUARE,
            },
            core_radius: wave.core_radius,
            attenuation: wave.attenuation,
            p0: [0.0; 4],
            p1: [0.0; 4],
            p2: [0.0; 4],
        };
        match &wave.shape {
            WaveShape::Sphere(s) => {
                g.kind = WAVE_SPHERE;
                g.p0 = v4(s.center, s.alpha);
            }
            WaveShape::Cylinder(c) => {
                g.kind = WAVE_CYLINDER;
                g.p0 = v4(c.point, c.alpha);
                g.p1 = v4(c.dir, 0.0);
            }
            WaveShape::Capsule(c) => {
                g.kind = WAVE_CAPSULE;
                g.p0 = v4(c.m, c.alpha_s);
                g.p1 = v4(c.d, c.alpha_c);
                g.p2 = [c.length, 0.0, 0.0, 0.0];
            }
            WaveShape::Beam(b) => {
                let c = &b.capsule;
                g.kind = WAVE_BEAM;
                g.p0 = v4(c.m, c.alpha_s);
                g.p1 = v4(c.d, c.alpha_c);
                g.p2 = [c.length, b.head_alpha, b.muzzle_alpha, 0.0];
            }
            WaveShape::Curve(_) => return None,
        }
        Some(g)
    }

    /// The GPU form of a curved wave whose data is entry `index` of [`CurveBuffers::curves`]
    /// (colour, falloff and core radius from `wave`).
    pub fn curve(wave: &Wave, index: u32) -> Self {
        Self {
            color: wave.color,
            kind: WAVE_CURVE,
            falloff: match wave.falloff {
                Falloff::Faithful => FALLOFF_FAITHFUL,
                Falloff::InverseSquare => FALLOFF_INVERSE_SQUARE,
            },
            core_radius: wave.core_radius,
            attenuation: 0.0,
            // Indices below 2^24 are exact in f32; `CurveBuffers::push` keeps them there.
            p0: [index as f32, 0.0, 0.0, 0.0],
            p1: [0.0; 4],
            p2: [0.0; 4],
        }
    }
}

/// One prepared curved wave ([`PreparedCurve`]) as the GPU reads it: frame, integrator settings,
/// shape parameters and the offsets of its data in [`CurveBuffers`]. Keep in sync with
/// `GpuCurve` in common.wgsl; curve.wgsl reads it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuCurve {
    /// Launch point `O` ([`PreparedCurve::frame_axes`]).
    pub origin: [f32; 3],
    /// Strength `α`.
    pub alpha: f32,
    /// Unit travel axis `D`.
    pub axis_d: [f32; 3],
    /// Axial length `X = γ·k·s_end`.
    pub x_head: f32,
    /// Cross-section axis `ŷ`.
    pub axis_y: [f32; 3],
    /// Attenuation exponent `j`.
    pub attenuation: f32,
    /// Cross-section axis `ẑ`.
    pub axis_z: [f32; 3],
    /// Axial stretch `γ`.
    pub gamma: f32,
    /// Head parameter `k·s_end`.
    pub s_head: f32,
    /// Smallest core radius ([`PreparedCurve::effective_core_radius`] of 0).
    pub core_floor: f32,
    /// Simpson reduction cylinder radius `R + ε`.
    pub cylinder_radius: f32,
    /// [`INTEGRATOR_DEFAULT`], [`INTEGRATOR_SIMPSON`] or [`INTEGRATOR_NEAREST`].
    pub integrator: u32,
    /// Simpson subintervals `m` (clamped, even).
    pub m: u32,
    /// Simpson subintervals outside the cylinder (`simpson::reduced_m`).
    pub m_reduced: u32,
    /// 1 when the Simpson reduction is on.
    pub reduce: u32,
    /// One of the `SHAPE_*` codes.
    pub shape: u32,
    /// B-spline order `k`.
    pub order: u32,
    /// Offset of the control points (or trig terms) in `CurveBuffers::scalars`, as `(y, z)` pairs.
    pub points: u32,
    /// Number of control points.
    pub point_count: u32,
    /// Offset of the B-spline knots in `CurveBuffers::scalars`.
    pub knots: u32,
    /// Lower end of the valid knot range.
    pub lo: f32,
    /// Upper end of the valid knot range.
    pub hi: f32,
    /// Helix / trig angular rate `θ`.
    pub rate: f32,
    /// Helix radius.
    pub radius: f32,
    /// Helix phase.
    pub phase: f32,
    /// Number of `y` trig terms (pairs from `points`), followed by the `z` terms.
    pub y_terms: u32,
    /// Number of `z` trig terms.
    pub z_terms: u32,
    /// Offset of `PieceTable::nodes` in `CurveBuffers::vec4s`.
    pub nodes: u32,
    /// Number of nodes `N + 1`.
    pub node_count: u32,
    /// Offset of `PieceTable::lines` in `CurveBuffers::vec4s`.
    pub lines: u32,
    /// Offset of `PieceTable::errors` in `CurveBuffers::scalars`.
    pub errors: u32,
    /// Offset of `PieceTable::level_offsets` (as `u32` bits) in `CurveBuffers::scalars`.
    pub level_offsets: u32,
    /// Number of levels.
    pub levels: u32,
    /// [`DEFAULT_SETTINGS`] tolerance `τ`.
    pub tolerance: f32,
    /// Part ratio `q` of [`curve::attenuation_split`] for this wave's `j` (0.5 when `j = 0`).
    pub att_q: f32,
    /// Attenuation floor `h_floor` of [`curve::attenuation_split`].
    pub att_floor: f32,
    /// [`PreparedCurve::tail_radius`] (the nearest-point field's open end).
    pub tail_radius: f32,
    /// Padding to the struct's 16-byte alignment.
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
    /// Padding.
    pub _pad2: u32,
}

/// The storage buffers of a frame's curved waves: one [`GpuCurve`] per curve, the piece-table
/// nodes and lines (`vec4s`), and the control points, knots, piece errors and level offsets
/// (`scalars`). Keep in sync with bindings 5–7 of curve.wgsl.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CurveBuffers {
    /// Per-curve headers.
    pub curves: Vec<GpuCurve>,
    /// `PieceTable::nodes` and `PieceTable::lines` of every curve.
    pub vec4s: Vec<[f32; 4]>,
    /// Points, knots, errors and level offsets (bits) of every curve.
    pub scalars: Vec<f32>,
}

fn offset(len: usize) -> Result<u32, String> {
    u32::try_from(len).ok().filter(|&v| v < 1 << 30).ok_or_else(|| "curve data too large".to_string())
}

impl CurveBuffers {
    /// Appends one prepared curve (from [`curve::prepare`]) and returns its index.
    pub fn push(&mut self, prep: &PreparedCurve) -> Result<u32, String> {
        let index = offset(self.curves.len())?;
        if index >= 1 << 24 {
            return Err("too many curved waves".to_string());
        }
        let wave = &prep.wave;
        let (origin, [d, y, z]) = prep.frame_axes();
        let table = prep.table();
        let s_end = match &wave.shape {
            CurveShape::Helix { length, .. } | CurveShape::TrigSum { length, .. } => f64::from(*length),
            CurveShape::Bezier { .. } | CurveShape::BSpline { .. } => 1.0,
        };
        let settings = DEFAULT_SETTINGS;
        let j = f64::from(wave.attenuation);
        let (att_q, att_floor) =
            if j > 0.0 { curve::attenuation_split(j, settings.tolerance) } else { (0.5, 0.0) };
        let mut g = GpuCurve {
            origin: origin.to_array(),
            alpha: wave.alpha,
            axis_d: d.to_array(),
            x_head: prep.axial_length(),
            axis_y: y.to_array(),
            attenuation: wave.attenuation,
            axis_z: z.to_array(),
            gamma: wave.gamma,
            s_head: (f64::from(wave.extension) * s_end) as f32,
            core_floor: prep.effective_core_radius(0.0f32),
            cylinder_radius: prep.bound_radius(),
            integrator: INTEGRATOR_DEFAULT,
            m: 2,
            m_reduced: 2,
            reduce: 0,
            shape: SHAPE_HELIX,
            order: 0,
            points: offset(self.scalars.len())?,
            point_count: 0,
            knots: 0,
            lo: 0.0,
            hi: 1.0,
            rate: 0.0,
            radius: 0.0,
            phase: 0.0,
            y_terms: 0,
            z_terms: 0,
            nodes: 0,
            node_count: 0,
            lines: 0,
            errors: 0,
            level_offsets: 0,
            levels: 0,
            tolerance: settings.tolerance as f32,
            att_q: att_q as f32,
            att_floor: att_floor as f32,
            tail_radius: prep.tail_radius() as f32,
            _pad0: 0,
            _pad1: 0,
            _pad2: 0,
        };
        if wave.integrator == Integrator::Nearest {
            g.integrator = INTEGRATOR_NEAREST;
        }
        if let Integrator::Simpson { m, reduction } = wave.integrator {
            let m = m.clamp(2, curve::MAX_SIMPSON_M);
            let m = m + (m & 1);
            g.integrator = INTEGRATOR_SIMPSON;
            g.m = m;
            if let Some(red) = reduction {
                g.reduce = 1;
                g.m_reduced = curve::simpson::reduced_m(m, red.n);
                g.cylinder_radius = (f64::from(prep.bound_radius()) + f64::from(red.epsilon)) as f32;
            }
        }
        let pairs = |s: &mut Vec<f32>, p: &[[f32; 2]]| s.extend(p.iter().flatten());
        match &wave.shape {
            CurveShape::Helix { radius, rate, phase, .. } => {
                g.shape = SHAPE_HELIX;
                (g.radius, g.rate, g.phase) = (*radius, *rate, *phase);
            }
            CurveShape::TrigSum { rate, y_terms, z_terms, .. } => {
                g.shape = SHAPE_TRIG;
                g.rate = *rate;
                g.y_terms = offset(y_terms.len())?;
                g.z_terms = offset(z_terms.len())?;
                pairs(&mut self.scalars, y_terms);
                pairs(&mut self.scalars, z_terms);
            }
            CurveShape::Bezier { points } => {
                g.shape = SHAPE_BEZIER;
                g.point_count = offset(points.len())?;
                pairs(&mut self.scalars, points);
            }
            CurveShape::BSpline { points, order, knots } => {
                g.shape = SHAPE_BSPLINE;
                g.order = *order;
                g.point_count = offset(points.len())?;
                pairs(&mut self.scalars, points);
                g.knots = offset(self.scalars.len())?;
                let knots: Vec<f32> = match knots {
                    Some(k) => k.clone(),
                    None => curve::clamped_uniform_knots(points.len(), *order as usize)
                        .into_iter()
                        .map(|k| k as f32)
                        .collect(),
                };
                let n = points.len().saturating_sub(1);
                let k = (*order as usize).max(1);
                g.lo = knots.get(k - 1).copied().unwrap_or(0.0);
                g.hi = knots.get(n + 1).copied().unwrap_or(1.0);
                self.scalars.extend(&knots);
            }
        }
        g.nodes = offset(self.vec4s.len())?;
        g.node_count = offset(table.nodes.len())?;
        self.vec4s.extend(&table.nodes);
        g.lines = offset(self.vec4s.len())?;
        self.vec4s.extend(&table.lines);
        g.errors = offset(self.scalars.len())?;
        self.scalars.extend(&table.errors);
        g.level_offsets = offset(self.scalars.len())?;
        g.levels = offset(table.levels())?;
        self.scalars.extend(table.level_offsets.iter().map(|&o| f32::from_bits(o)));
        offset(self.vec4s.len())?;
        offset(self.scalars.len())?;
        self.curves.push(g);
        Ok(index)
    }
}

/// The wave buffer and the curve buffers of a frame: every curved wave is prepared once
/// ([`curve::prepare`], as the CPU backend does per frame) and appended to the curve buffers.
/// Also returns the prepared curves, one entry per wave (`None` for analytic waves), for
/// [`ShadingBuffers::new`].
pub fn frame_waves(frame: &Frame) -> Result<FrameWaves, String> {
    let mut curves = CurveBuffers::default();
    let mut waves = Vec::with_capacity(frame.waves.len());
    let mut prepared = Vec::with_capacity(frame.waves.len());
    for w in &frame.waves {
        match w.shape.curve() {
            Some(c) => {
                let prep = curve::prepare(c);
                let index = curves.push(&prep).map_err(|e| format!("wave `{}`: {e}", w.name))?;
                waves.push(GpuWave::curve(w, index));
                prepared.push(Some(prep));
            }
            None => {
                waves.extend(GpuWave::new(w));
                prepared.push(None);
            }
        }
    }
    Ok((waves, curves, prepared))
}

/// What [`frame_waves`] returns: the wave buffer, the curve buffers, and the prepared curves.
pub type FrameWaves = (Vec<GpuWave>, CurveBuffers, Vec<Option<PreparedCurve>>);

/// One mesh vertex as the raster pass reads it (`VertexIn` in raster.wgsl, locations 0–5).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuVertex {
    /// Object-space position.
    pub position: [f32; 3],
    /// Object-space normal.
    pub normal: [f32; 3],
    /// Object-space outline direction ([`hadou_scene::Mesh::outline_normals`]).
    pub outline_normal: [f32; 3],
    /// Texture coordinates.
    pub uv: [f32; 2],
    /// Linear RGBA vertex colour.
    pub color: [f32; 4],
    /// Material slot of the object.
    pub material: u32,
}

/// One of the `[area_light]`'s two perspective shadow maps (hadou_math::soft::SpotMap) and its
/// edge in texels. Keep in sync with `GpuSpotMap` in common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuSpotMap {
    /// The map's light position.
    pub eye: [f32; 3],
    /// `tan` of the frustum's half-angle.
    pub tan_half: f32,
    /// Unit axis.
    pub forward: [f32; 3],
    /// Near plane distance.
    pub near: f32,
    /// Unit right.
    pub right: [f32; 3],
    /// Edge in texels.
    pub size: u32,
    /// Unit up.
    pub up: [f32; 3],
    /// Padding.
    pub _pad: u32,
}

impl GpuSpotMap {
    /// The map `m` of edge `size`.
    pub fn new(m: &hadou_math::soft::SpotMap, size: u32) -> Self {
        GpuSpotMap {
            eye: m.eye.to_array(),
            tan_half: m.tan_half,
            forward: m.forward.to_array(),
            near: m.near,
            right: m.right.to_array(),
            size,
            up: m.up.to_array(),
            _pad: 0,
        }
    }
}

/// What the soft-shadow passes (soft.wgsl) know of the frame's `[area_light]`. Keep in sync with
/// `SoftUniforms` in soft.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct SoftUniforms {
    /// The two maps, `[L₁, L₂]`.
    pub maps: [GpuSpotMap; 2],
    /// 1 with the depth-aware search.
    pub depth_aware: u32,
    /// 0 for the exact resolve, else the faithful resolve's grid spacing `n`.
    pub grid: u32,
    /// The faithful grid's size in grid pixels.
    pub grid_size: [u32; 2],
    /// `k` of `hadou_math::soft::segment_brightness` (1: 003's linear ratio).
    pub ratio: f32,
    /// How many caster boxes ([`GpuCasterBox`]) the fit tests.
    pub boxes: u32,
    /// Padding to the uniform's 16-byte alignment.
    pub _pad: [u32; 2],
}

/// A caster's box in the world (`hadou_math::soft::CasterBox`), as soft.wgsl's map fit reads it.
/// Keep in sync with `GpuCasterBox` in soft.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuCasterBox {
    /// The corner (w unused).
    pub origin: [f32; 4],
    /// The dual vectors of its edges (w unused).
    pub dual: [[f32; 4]; 3],
}

impl GpuCasterBox {
    /// The box `b`.
    pub fn new(b: &hadou_math::soft::CasterBox) -> Self {
        let v = |v: hadou_math::Vec3f| [v.x, v.y, v.z, 0.0];
        GpuCasterBox { origin: v(b.origin), dual: b.dual.map(v) }
    }
}

/// How the wave overlay (wave_overlay.wgsl) reads the caller's depth buffer. Keep in sync with
/// `OverlayUniforms` in wave_overlay.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct OverlayUniforms {
    /// [`DEPTH_STANDARD`] or [`DEPTH_REVERSE_INFINITE`].
    pub depth_model: u32,
    /// The camera's near plane.
    pub near: f32,
    /// The camera's far plane (the standard model only).
    pub far: f32,
    /// Padding to the uniform's 16-byte alignment.
    pub _pad: u32,
}

/// Depth 0 at the near plane, 1 at the far plane (hadou's raster pass, most engines).
pub const DEPTH_STANDARD: u32 = 0;
/// Depth `near / z`: 1 at the near plane, 0 at infinity (reverse-Z with an infinite far plane, as
/// Bevy draws).
pub const DEPTH_REVERSE_INFINITE: u32 = 1;

/// One step of the glare chain (bloom.wgsl): its planes, each `[level width, level height, first
/// row held, rows held]`, and the frame's bloom values. Keep in sync with `BloomUniforms` in
/// bloom.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct BloomUniforms {
    /// The first input plane.
    pub a: [u32; 4],
    /// The second input plane (the upsample's base, the composite's bloom).
    pub b: [u32; 4],
    /// The third input plane (the composite's streak).
    pub c: [u32; 4],
    /// The output plane.
    pub o: [u32; 4],
    /// `threshold`, `soft_knee`, `intensity/N`, `streak/N_s`.
    pub params: [f32; 4],
    /// 1 when the upsample adds `b`; the tone mode ([`TONE_FAITHFUL`], [`TONE_FILMIC`]); unused.
    pub flags: [u32; 4],
}
