//! [`HadouMaterial`]: a Bevy material that shades a mesh as hadou does, under a hadou light and the
//! waves' light, with hadou-gpu's own WGSL: `shading.wgsl`'s `shade_surface` (the twin of
//! hadou-cpu's `shading::shade`: the own look, the waves' looks weighted by their dominance, glow,
//! base and feature textures), fed by Bevy's mesh vertex output. The waves' light records are the
//! plugin's, shared by every material ([`WAVE_LIGHTS`], [`WAVE_LIGHT_DATA`], refreshed each frame
//! from the [`crate::HadouWave`]s by [`update_wave_lights`]); a material's textures are in its
//! own buffer ([`HadouMaterial::textures`]). The drawn [`crate::HadouAreaLight`] adds its light
//! times the share of its lamp each fragment sees (hadou-gpu's `area_term` and soft_trace.wgsl's
//! `pixel_visibility`; see `area.rs`).

use crate::wave::DrawnWaves;
use bevy::asset::{uuid_handle, RenderAssetUsages};
use bevy::pbr::Material;
use bevy::prelude::*;
use bevy::render::render_resource::{AsBindGroup, ShaderType};
use bevy::render::storage::ShaderBuffer;
use bevy::shader::ShaderRef;
use hadou_gpu::layout::{self, GpuLight, GpuTexture, TextureStore};
use hadou_math::curve::PreparedCurve;
use hadou_scene::{Light, Wave};

/// The fragment shader of [`HadouMaterial`], composed at start-up (see [`shader_source`]).
pub(crate) const SHADER: Handle<Shader> = uuid_handle!("0b7e55c1-2f4a-4c63-8d3e-6a9d1f2b7c44");

/// The plugin's wave-light records: one `GpuLight` (hadou-gpu's layout) per drawn wave, room for
/// [`MAX_WAVE_LIGHTS`]; every [`HadouMaterial`] binds it.
pub const WAVE_LIGHTS: Handle<ShaderBuffer> = uuid_handle!("5c1d7e0a-93b2-4f6e-a8c1-2d4e6f8a0b13");
/// The plugin's wave-light words: the number of lights, whether any glows, two unused words, then
/// the lights' polyline points (3 `f32` bit patterns each); every [`HadouMaterial`] binds it.
pub const WAVE_LIGHT_DATA: Handle<ShaderBuffer> = uuid_handle!("7a2f4c6e-1b3d-4e5f-9a7c-8d0e2f4a6c15");
/// The texture words of a material without textures: hadou's sRGB table only.
pub const NO_TEXTURES: Handle<ShaderBuffer> = uuid_handle!("9e4a6c8e-3d5f-4a7b-8c9d-0f1e3a5c7e17");

/// The shadow maps every [`HadouMaterial`] binds: a `Depth32Float` array texture, one layer per
/// map cast, kept by the plugin.
pub const SHADOW_MAPS: Handle<Image> = uuid_handle!("2b4d6f8a-0c1e-4f3a-9b5d-7e9f1a3c5e21");
/// The shadow records every [`HadouMaterial`] binds: the number of casts, of map casts, the word
/// offsets of the cast records and of the map casts' indices, then those (hadou-gpu's
/// `GpuShadowCast` and `FrameShadows::map_casts`).
pub const SHADOW_DATA: Handle<ShaderBuffer> = uuid_handle!("4d6f8a0c-2e3a-4b5c-8d7e-9f1a3c5e7a23");

/// The drawn [`crate::HadouAreaLight`]'s record every [`HadouMaterial`] binds (kept by the
/// plugin): whether one is drawn, the lamp (shape, centre, axis, size, colour) and its sample
/// layout (hadou-gpu's `TracedUniforms`).
pub const AREA_DATA: Handle<ShaderBuffer> = uuid_handle!("6e8a0c2e-4a5b-4c7d-9e1f-3a5c7e9b1d25");
/// The nodes of the casters' hierarchy (hadou-gpu's `GpuBvhNode`, `hadou_math::soft::BvhNode`'s
/// bytes); every [`HadouMaterial`] binds it.
pub const AREA_NODES: Handle<ShaderBuffer> = uuid_handle!("8a0c2e4a-6c7d-4e9f-8a1b-5c7e9b1d3f27");
/// The triangles of the casters' hierarchy (hadou-gpu's `GpuBvhTri`); every [`HadouMaterial`]
/// binds it.
pub const AREA_TRIS: Handle<ShaderBuffer> = uuid_handle!("0c2e4a6c-8e9f-4a1b-9c3d-7e9b1d3f5a29");

/// The most waves that light a surface (hadou-gpu's `MAX_LIGHTS` in shading.wgsl, hadou-scene's
/// per-scene limit); past it the first by entity are used, and a warning says so once.
pub const MAX_WAVE_LIGHTS: usize = 256;

/// Words before the polyline points in [`WAVE_LIGHT_DATA`].
const LIGHT_DATA_HEADER: usize = 4;

/// The fragment stage: hadou-gpu's `shade_surface` (shading.wgsl; SPEC.md §2.1–2.2: own look
/// `albedo · (ambient + light · max(0, N·(−L)))`, toon `albedo · ramp(N·(−L))` with the unclamped
/// `m`, then `c + β·(look − c)` with the waves' looks weighted by `(ρᵢ/ρ_max)²` (the densities'
/// dominance rule), glow, the feature texture) for the material's record, at the fragment's world
/// point, normal, texture coordinates and vertex colour (quantised to 8 bits as hadou's G-buffer
/// holds it); an MToon material (VRMC_materials_mtoon 1.0, `hadou_math::mtoon`) through
/// shading.wgsl's `mtoon_*` functions, its block in the material's texture buffer, seen from the
/// view's own eye (`mtoon_eye`) and moved by the uniform's scene time (`mtoon_motion`); then the
/// shadows of its mask (`apply_shadows`) and the `[area_light]`'s term (`area_term`) times the
/// share of the lamp the point sees (soft_trace.wgsl's `pixel_visibility`, where the term adds
/// light). `lights`, `shading_data` and `polyline_point` are declared here in place of the wave
/// pass's (`shading_bindings.wgsl`), `nodes`, `tris` and `traced` in place of soft_traced.wgsl's,
/// `frame` is a private copy of what shading.wgsl and soft_trace.wgsl read of hadou's frame
/// uniforms.
const FRAGMENT: &str = r"
struct HadouSurface {
    base_color: vec4<f32>,
    light_direction: vec4<f32>,
    light_color: vec4<f32>,
    ambient: vec4<f32>,
    outline: vec4<f32>,
    model: u32,
    wave_blend: f32,
    shadow_mask: u32,
    mtoon: u32,
    base_texture: vec4<u32>,
    feature_texture: vec4<u32>,
    ramp: GpuRamp,
    time: f32,
}
@group(#{MATERIAL_BIND_GROUP}) @binding(0) var<uniform> surface_uniform: HadouSurface;
// The uniform as the functions below read it: a private copy made by load_surface().
var<private> surface: HadouSurface;
@group(#{MATERIAL_BIND_GROUP}) @binding(1) var<storage, read> lights: array<GpuLight>;
@group(#{MATERIAL_BIND_GROUP}) @binding(2) var<storage, read> light_data: array<u32>;
@group(#{MATERIAL_BIND_GROUP}) @binding(3) var<storage, read> shading_data: array<u32>;
@group(#{MATERIAL_BIND_GROUP}) @binding(4) var shadow_maps: texture_2d_array<f32>;
@group(#{MATERIAL_BIND_GROUP}) @binding(5) var<storage, read> shadow_data: array<u32>;

// The drawn `[area_light]` (area.rs `AreaRecord`, AREA_DATA): `drawn` 0 when there is none.
struct HadouArea {
    drawn: u32,
    shape: u32,
    size: f32,
    pad: u32,
    position: vec4<f32>,
    axis: vec4<f32>,
    color: vec4<f32>,
    pattern: TracedUniforms,
}
@group(#{MATERIAL_BIND_GROUP}) @binding(6) var<storage, read> area: HadouArea;
// The casters' hierarchy, read by soft_trace.wgsl's pixel_visibility (AREA_NODES, AREA_TRIS).
@group(#{MATERIAL_BIND_GROUP}) @binding(7) var<storage, read> nodes: array<BvhNode>;
@group(#{MATERIAL_BIND_GROUP}) @binding(8) var<storage, read> tris: array<BvhTri>;
// soft_trace.wgsl's sample layout, copied from `area` when a fragment walks the hierarchy.
var<private> traced: TracedUniforms;

fn shadow_word(o: u32) -> u32 {
    return shadow_data[o];
}

// No plane-shadow target in Bevy: plane shadows are drawn as maps (shadows.rs).
fn plane_cast_at(pixel: vec2<u32>) -> u32 {
    return 0u;
}

// The eye of the view being drawn (Bevy's), not the block's.
fn mtoon_eye(o: u32) -> vec3<f32> {
    return view_bindings::view.world_position;
}

// The block holds `scroll` and `rotation` themselves (built at time 1): times the scene time here,
// the same f32 products as hadou-cpu's.
fn mtoon_motion(o: u32) -> vec3<f32> {
    return mtoon_vec3(o + 18u) * surface.time;
}

fn polyline_point(offset: u32, i: u32) -> vec3<f32> {
    let o = offset + 3u * i;
    return vec3<f32>(bitcast<f32>(light_data[o]), bitcast<f32>(light_data[o + 1u]), bitcast<f32>(light_data[o + 2u]));
}

struct HadouShadeFrame {
    light_dir: vec3<f32>,
    light_color: vec3<f32>,
    ambient: vec3<f32>,
    wave_count: u32,
    any_glow: u32,
    area_position: vec3<f32>,
    area_color: vec3<f32>,
    area_axis: vec3<f32>,
    area_size: f32,
    area_shape: u32,
    shadow_casts: u32,
    map_casts: u32,
    cast_count: u32,
    map_count: u32,
    plane_count: u32,
}
var<private> frame: HadouShadeFrame;

fn hide1(v: f32, zero: u32) -> f32 {
    return bitcast<f32>(bitcast<u32>(v) | zero);
}

fn hide4(v: vec4<f32>, zero: u32) -> vec4<f32> {
    return bitcast<vec4<f32>>(bitcast<vec4<u32>>(v) | vec4<u32>(zero));
}

// Copies the uniform into `surface`, every word OR-ed with a zero the driver cannot fold: the top
// bit of the number of wave lights (no buffer holds 2³¹ of them), as hadou-gpu's wave_energy.wgsl
// `load_frame` does for the frame's uniforms. Mesa's lavapipe (22.3) folds up to four uniform
// words that decide branches or loop counts into a large shader and compiles it again on every
// bind of the material's group, with no cache of these variants: a whole compile of this shader
// for every HadouMaterial drawn, every frame. Hidden, the values and branches are the same and the
// pipeline's one compile serves every material and frame. The zero comes from `lights`, whose
// record (208 bytes) is not a power of two: the length of an array of `u32` is the buffer's size
// shifted right by 2, which the driver folds with the `>> 31` to a constant 0 (measured: hidden
// with `light_data`'s length, every draw was still a compile).
fn load_surface() {
    let zero = arrayLength(&lights) >> 31u;
    let u = surface_uniform;
    surface.base_color = hide4(u.base_color, zero);
    surface.light_direction = hide4(u.light_direction, zero);
    surface.light_color = hide4(u.light_color, zero);
    surface.ambient = hide4(u.ambient, zero);
    surface.outline = hide4(u.outline, zero);
    surface.model = u.model | zero;
    surface.wave_blend = hide1(u.wave_blend, zero);
    surface.shadow_mask = u.shadow_mask | zero;
    surface.mtoon = u.mtoon | zero;
    surface.base_texture = u.base_texture | vec4<u32>(zero);
    surface.feature_texture = u.feature_texture | vec4<u32>(zero);
    surface.ramp = u.ramp;
    for (var i = 0u; i < 8u; i++) {
        surface.ramp.stops[i] = hide4(u.ramp.stops[i], zero);
    }
    surface.ramp.count = u.ramp.count | zero;
    surface.ramp.kind = u.ramp.kind | zero;
    surface.ramp.smoothing = hide1(u.ramp.smoothing, zero);
    surface.time = hide1(u.time, zero);
}

fn texture_record(t: vec4<u32>) -> GpuTexture {
    return GpuTexture(t.x, t.y, t.z, t.w);
}

@fragment
fn fragment(in: VertexOutput) -> @location(0) vec4<f32> {
    load_surface();
    frame.light_dir = surface.light_direction.xyz;
    frame.light_color = surface.light_color.xyz;
    frame.ambient = surface.ambient.xyz;
    frame.wave_count = light_data[0];
    frame.any_glow = light_data[1];
    frame.cast_count = shadow_data[0];
    frame.map_count = shadow_data[1];
    frame.shadow_casts = shadow_data[2];
    frame.map_casts = shadow_data[3];
    frame.plane_count = 0u;
    let m = GpuMaterial(
        surface.base_color.xyz, surface.model, surface.outline.xyz, surface.wave_blend,
        surface.outline.w, surface.shadow_mask, 0u, surface.mtoon,
        texture_record(surface.base_texture), texture_record(surface.feature_texture), surface.ramp);
    var uv = vec2<f32>(0.0);
#ifdef VERTEX_UVS_A
    uv = in.uv;
#endif
    var color = vec4<f32>(1.0);
#ifdef VERTEX_COLORS
    color = unpack4x8unorm(pack4x8unorm(in.color));
#endif
    let world = in.world_position.xyz;
    var c = apply_shadows(shade_surface(m, world, in.world_normal, uv, color), m.shadow_mask, world, vec2<u32>(0u));
    if (area.drawn != 0u) {
        // As hadou's wave pass: c + visibility · area term, saturated, after the hard shadows. The
        // visibility is the traced resolve's (soft_traced.wgsl's cs_traced at this fragment's
        // pixel): only where the term adds light (a point facing away counts 0 there too).
        frame.area_position = area.position.xyz;
        frame.area_axis = area.axis.xyz;
        frame.area_color = area.color.xyz;
        frame.area_size = area.size;
        frame.area_shape = area.shape;
        let t = area_term(m, world, in.world_normal, uv, color);
        if (t.x > 0.0 || t.y > 0.0 || t.z > 0.0) {
            traced = area.pattern;
            let len = length3(in.world_normal);
            var n = vec3<f32>(0.0);
            if (len > 0.0 && len < 3.0e38) {
                n = in.world_normal / len;
            }
            let r = world + n * (TRACE_BIAS * length3(world - frame.area_position));
            let v = pixel_visibility(r, u32(in.position.x), u32(in.position.y));
            c = vec3<f32>(energy_saturate(c.x + v * t.x), energy_saturate(c.y + v * t.y), energy_saturate(c.z + v * t.z));
        }
    }
    return vec4<f32>(c, 1.0);
}
";

/// hadou-gpu's pipeline-overridable switches become constants (all true: the uber-shader's code).
fn constants(wgsl: &str) -> String {
    wgsl.replace("override USE_", "const USE_")
}

/// The WGSL of [`HadouMaterial`]: Bevy's mesh vertex output, hadou-gpu's `common.wgsl`,
/// `energy.wgsl`, [`FRAGMENT`], `shading.wgsl`, `shadow_lookup.wgsl` (their switches as constants)
/// and `soft_trace.wgsl` (the traced resolve's per-pixel walk).
pub(crate) fn shader_source() -> String {
    use hadou_gpu::shaders::{COMMON, ENERGY, SHADING, SHADOW_LOOKUP, SOFT_TRACE};
    let (energy, shading, shadows) = (constants(ENERGY), constants(SHADING), constants(SHADOW_LOOKUP));
    format!(
        "#import bevy_pbr::forward_io::VertexOutput\n#import bevy_pbr::mesh_view_bindings as view_bindings\n{COMMON}\n{energy}\n{FRAGMENT}\n{shading}\n{shadows}\n{SOFT_TRACE}"
    )
}

/// What [`HadouMaterial`]'s shader reads (its uniform): a hadou `[[material]]`'s record (hadou-gpu's
/// `GpuMaterial`) and the scene's `[light]`.
#[derive(Clone, Copy, Debug, PartialEq, ShaderType)]
pub struct HadouSurface {
    /// Linear RGB base colour (`w` unused).
    pub base_color: Vec4,
    /// The unit direction the light travels, from the light towards the scene (`w` unused).
    pub light_direction: Vec4,
    /// The light's linear RGB intensity (`w` unused).
    pub light_color: Vec4,
    /// The ambient term, linear RGB (`w` unused).
    pub ambient: Vec4,
    /// The outline colour (`xyz`) and width `d` (`w`; 0 = none), for [`crate::HadouOutline`].
    pub outline: Vec4,
    /// hadou-gpu's shading model code (`layout::MODEL_DIFFUSE`, `MODEL_TOON` or `MODEL_UNLIT`).
    pub model: u32,
    /// `wave_blend` β: 0 keeps the own look, 1 takes the waves' (000 §2.1).
    pub wave_blend: f32,
    /// Bit `s` set when the surface receives shadow `s` of [`crate::HadouShadows`]' frame.
    pub shadow_mask: u32,
    /// The word offset of the material's MToon block in its texture buffer (hadou-gpu's
    /// `layout::mtoon_block`, built at time 1 so that its motion words hold the UV scroll and
    /// rotation themselves); 0 = no MToon look.
    pub mtoon: u32,
    /// The base-colour texture (`GpuTexture`: word offset in the material's texture buffer, width,
    /// height, sampling flags); offset 0 = none.
    pub base_texture: UVec4,
    /// The feature texture, likewise.
    pub feature_texture: UVec4,
    /// The toon ramp (read by `MODEL_TOON` only).
    pub ramp: HadouRamp,
    /// The scene time in seconds the MToon UV animation is at ([`HadouMaterial::set_time`]).
    pub time: f32,
}

/// A toon ramp (`hadou_math::toon::Ramp`, 000 §2.1, SPEC.md §2.1) in the layout of hadou-gpu's
/// `GpuRamp` (common.wgsl), as a uniform field: `ramp`'s stops, `ramp_kind`, `ramp_smoothing`.
#[derive(Clone, Copy, Debug, PartialEq, ShaderType)]
pub struct HadouRamp {
    /// `(threshold, r, g, b)` per stop, linear RGB multipliers; the first `count` are used.
    pub stops: [Vec4; hadou_math::toon::MAX_RAMP_BANDS],
    /// Stops used, `1..=8`.
    pub count: u32,
    /// `layout::RAMP_BANDS` or `layout::RAMP_GRADIENT`.
    pub kind: u32,
    /// The width of each step between bands (0 = hard steps).
    pub smoothing: f32,
    /// Padding (the layout of `GpuRamp`).
    pub pad: u32,
}

impl HadouRamp {
    /// `ramp` in hadou-gpu's layout (`layout::GpuRamp::new`: stops beyond eight are dropped, the
    /// scene loader refuses them).
    pub fn new(ramp: &hadou_math::toon::Ramp) -> Self {
        Self::from_gpu(&layout::GpuRamp::new(ramp))
    }

    fn from_gpu(g: &layout::GpuRamp) -> Self {
        HadouRamp {
            stops: g.stops.map(Vec4::from_array),
            count: g.count,
            kind: g.kind,
            smoothing: g.smoothing,
            pad: 0,
        }
    }
}

fn texture_words(t: GpuTexture) -> UVec4 {
    UVec4::new(t.offset, t.width, t.height, t.flags)
}

impl HadouSurface {
    /// The uniform of `material` under `light`, its textures at the word offsets of `textures`
    /// (`[0, 0, 0, 0]`: none).
    pub fn new(material: &hadou_scene::Material, light: &Light, textures: [UVec4; 2]) -> Self {
        let mut store = TextureStore::default();
        let g = layout::material_record(material, 0, &mut Vec::new(), &mut store);
        let v = |c: [f32; 3], w: f32| Vec4::new(c[0], c[1], c[2], w);
        let d = light.direction;
        HadouSurface {
            base_color: v(g.base_color, 1.0),
            light_direction: Vec4::new(d.x, d.y, d.z, 0.0),
            light_color: v(light.color, 0.0),
            ambient: v(light.ambient, 0.0),
            outline: v(g.outline_color, g.outline_width),
            model: g.model,
            wave_blend: g.wave_blend,
            shadow_mask: 0,
            mtoon: 0,
            base_texture: textures[0],
            feature_texture: textures[1],
            ramp: HadouRamp::from_gpu(&g.ramp),
            time: 0.0,
        }
    }
}

/// A material shaded as a hadou `[[material]]` under a hadou `[light]` and the waves' light
/// (SPEC.md §2.1–2.2, hadou-gpu's `shade_surface`): `model = "diffuse"` gives
/// `albedo · (ambient + light · max(0, N·(−L)))`, `"toon"` gives `albedo · ramp(N·(−L))` (000
/// §2.1, the unclamped `m`), `"unlit"` the albedo, with `albedo` the base colour times the base
/// texture times the mesh's vertex colours and `N` the interpolated world normal; then
/// `wave_blend` β moves it towards the waves' looks (each wave's `light_ramp` over
/// `m = N·(e − p)/|e − p|` at its nearest centre-line point `e`, weighted by the densities'
/// dominance rule), glowing waves add their light, and the feature texture multiplies the result.
/// It writes linear colour into the HDR target, before the waves' light and the colour mapping,
/// as hadou's wave pass does.
#[derive(Asset, TypePath, AsBindGroup, Clone, Debug, PartialEq)]
pub struct HadouMaterial {
    /// The uniform.
    #[uniform(0)]
    pub surface: HadouSurface,
    /// The waves as lights ([`WAVE_LIGHTS`], kept by the plugin).
    #[storage(1, read_only)]
    pub lights: Handle<ShaderBuffer>,
    /// Their count and polyline points ([`WAVE_LIGHT_DATA`], kept by the plugin).
    #[storage(2, read_only)]
    pub light_data: Handle<ShaderBuffer>,
    /// The sRGB table and this material's texels ([`NO_TEXTURES`] without textures).
    #[storage(3, read_only)]
    pub textures: Handle<ShaderBuffer>,
    /// The shadow maps ([`SHADOW_MAPS`], kept by the plugin).
    #[texture(4, dimension = "2d_array", sample_type = "float", filterable = false)]
    pub shadow_maps: Handle<Image>,
    /// The shadow records ([`SHADOW_DATA`], kept by the plugin).
    #[storage(5, read_only)]
    pub shadow_data: Handle<ShaderBuffer>,
    /// The drawn [`crate::HadouAreaLight`] ([`AREA_DATA`], kept by the plugin).
    #[storage(6, read_only)]
    pub area: Handle<ShaderBuffer>,
    /// Its casters' hierarchy: nodes ([`AREA_NODES`], kept by the plugin).
    #[storage(7, read_only)]
    pub area_nodes: Handle<ShaderBuffer>,
    /// And triangles ([`AREA_TRIS`], kept by the plugin).
    #[storage(8, read_only)]
    pub area_tris: Handle<ShaderBuffer>,
}

impl HadouMaterial {
    /// hadou's shading of `material` (its model, base colour, ramp, `wave_blend`, outline) under
    /// `light` and the plugin's waves, without textures (see [`HadouMaterial::with_textures`]).
    pub fn new(material: &hadou_scene::Material, light: &Light) -> Self {
        HadouMaterial {
            surface: HadouSurface::new(material, light, [UVec4::ZERO; 2]),
            lights: WAVE_LIGHTS,
            light_data: WAVE_LIGHT_DATA,
            textures: NO_TEXTURES,
            shadow_maps: SHADOW_MAPS,
            shadow_data: SHADOW_DATA,
            area: AREA_DATA,
            area_nodes: AREA_NODES,
            area_tris: AREA_TRIS,
        }
    }

    /// The same material receiving the shadows whose bits are set in `mask` (bit `s`: shadow `s`
    /// of [`crate::HadouShadows`]' frame; [`crate::shadow_mask`] gives an object's).
    pub fn with_shadow_mask(mut self, mask: u32) -> Self {
        self.surface.shadow_mask = mask;
        self
    }

    /// As [`HadouMaterial::new`], with `material`'s base and feature textures (sampled as hadou
    /// samples them: level 0, bilinear in linear light or nearest, its wrap modes) and its MToon
    /// look (block and textures) in a buffer of their own added to `buffers`.
    pub fn with_textures(
        material: &hadou_scene::Material,
        light: &Light,
        buffers: &mut Assets<ShaderBuffer>,
    ) -> Self {
        if material.base_texture.is_none() && material.feature_texture.is_none() && material.mtoon.is_none() {
            return Self::new(material, light);
        }
        let mut data: Vec<u32> = layout::srgb_words().collect();
        let mut store = TextureStore::default();
        let base = store.texture(&mut data, &material.base_texture);
        let feature = store.texture(&mut data, &material.feature_texture);
        // At time 1 the motion words are the scroll and rotation; the shader multiplies them by
        // the uniform's time. The eye words are not read (the view's eye is).
        let mtoon = layout::mtoon_block(material, 1.0, [0.0; 3], &mut data, &mut store);
        let textures = buffers.add(ShaderBuffer::new(bytes(&data), RenderAssetUsages::default()));
        let mut surface = HadouSurface::new(material, light, [texture_words(base), texture_words(feature)]);
        surface.mtoon = mtoon;
        HadouMaterial {
            surface,
            lights: WAVE_LIGHTS,
            light_data: WAVE_LIGHT_DATA,
            textures,
            shadow_maps: SHADOW_MAPS,
            shadow_data: SHADOW_DATA,
            area: AREA_DATA,
            area_nodes: AREA_NODES,
            area_tris: AREA_TRIS,
        }
    }

    /// The scene time `t` (seconds) for the MToon UV animation (`uvAnimationScrollXSpeedFactor`,
    /// `…ScrollY…`, `…RotationSpeedFactor`, times `t` as hadou-cpu's `shading::mtoon_point` takes
    /// them); false when nothing changed (no MToon look, or the same time).
    pub fn set_time(&mut self, t: f32) -> bool {
        if self.surface.mtoon == 0 || self.surface.time.to_bits() == t.to_bits() {
            return false;
        }
        self.surface.time = t;
        true
    }

    /// Sets the uniform from `material` and `light`, keeping the textures, the MToon block, the time and the shadow mask (e.g. when a track
    /// changes `wave_blend`); false when nothing changed.
    pub fn update(&mut self, material: &hadou_scene::Material, light: &Light) -> bool {
        let textures = [self.surface.base_texture, self.surface.feature_texture];
        let mut surface = HadouSurface::new(material, light, textures);
        surface.shadow_mask = self.surface.shadow_mask;
        surface.mtoon = self.surface.mtoon;
        surface.time = self.surface.time;
        let changed = surface != self.surface;
        self.surface = surface;
        changed
    }
}

impl Material for HadouMaterial {
    fn fragment_shader() -> ShaderRef {
        ShaderRef::Handle(SHADER)
    }
}

fn bytes(words: &[u32]) -> &[u8] {
    bytemuck::cast_slice(words)
}

/// The initial contents of the plugin's buffers (no lights; no textures).
pub(crate) fn insert_buffers(buffers: &mut Assets<ShaderBuffer>) {
    let lights = vec![0u8; MAX_WAVE_LIGHTS * std::mem::size_of::<GpuLight>()];
    let empty = |b: &[u8]| ShaderBuffer::new(b, RenderAssetUsages::default());
    let data = vec![0u32; LIGHT_DATA_MIN_WORDS];
    let srgb: Vec<u32> = layout::srgb_words().collect();
    for (handle, buffer) in [
        (&WAVE_LIGHTS, empty(&lights)),
        (&WAVE_LIGHT_DATA, empty(bytes(&data))),
        (&NO_TEXTURES, empty(bytes(&srgb))),
    ] {
        buffers.insert(handle, buffer).expect("a buffer under a fixed handle can be inserted");
    }
}

/// The smallest size of [`WAVE_LIGHT_DATA`], in words; it grows by doubling.
const LIGHT_DATA_MIN_WORDS: usize = 1024;

/// What [`update_wave_lights`] last wrote.
#[derive(Default)]
pub(crate) struct LightsWritten {
    lights: Vec<GpuLight>,
    data: Vec<u32>,
    capacity: usize,
    warned: bool,
}

/// The records of `waves` as lights: the `GpuLight`s and the words of [`WAVE_LIGHT_DATA`]
/// (count, any glow, then polyline points), at most [`MAX_WAVE_LIGHTS`].
pub fn light_records(waves: &[Wave]) -> (Vec<GpuLight>, Vec<u32>) {
    prepared_light_records(waves, &[])
}

/// [`light_records`] with the waves' curves already prepared (`curves[i]` of `waves[i]`, `None`
/// for an analytic wave; a wave past the end of `curves` is prepared here).
pub fn prepared_light_records(waves: &[Wave], curves: &[Option<PreparedCurve>]) -> (Vec<GpuLight>, Vec<u32>) {
    let waves = &waves[..waves.len().min(MAX_WAVE_LIGHTS)];
    let curves = &curves[..curves.len().min(waves.len())];
    let mut data = vec![0u32; LIGHT_DATA_HEADER];
    let lights = layout::wave_lights(waves, curves, &mut data);
    data[0] = lights.len() as u32;
    data[1] = u32::from(waves.iter().any(|w| w.light.glow > 0.0));
    (lights, data)
}

/// Writes the enabled, accepted [`HadouWave`]s (by entity) into [`WAVE_LIGHTS`] and
/// [`WAVE_LIGHT_DATA`] when they changed. The buffers keep their size while they can (the
/// materials' bind groups then stay valid); when the points outgrow [`WAVE_LIGHT_DATA`] it doubles
/// and every [`HadouMaterial`] is marked changed so that Bevy binds the new buffer.
pub(crate) fn update_wave_lights(
    drawn: Res<DrawnWaves>,
    mut buffers: ResMut<Assets<ShaderBuffer>>,
    mut materials: ResMut<Assets<HadouMaterial>>,
    mut written: Local<LightsWritten>,
) {
    if drawn.waves.len() > MAX_WAVE_LIGHTS && !written.warned {
        written.warned = true;
        warn!(
            "{} waves are drawn; the first {MAX_WAVE_LIGHTS} (by entity) light the HadouMaterials",
            drawn.waves.len()
        );
    }
    let curves = drawn.prepared.as_ref().as_ref().map_or(&[][..], |p| &p.2[..]);
    let (lights, data) = prepared_light_records(&drawn.waves, curves);
    if written.capacity != 0 && lights == written.lights && data == written.data {
        return;
    }
    let mut light_bytes = vec![0u8; MAX_WAVE_LIGHTS * std::mem::size_of::<GpuLight>()];
    let used: &[u8] = bytemuck::cast_slice(&lights);
    light_bytes[..used.len()].copy_from_slice(used);
    let capacity = data.len().next_power_of_two().max(LIGHT_DATA_MIN_WORDS).max(written.capacity);
    let mut words = data.clone();
    words.resize(capacity, 0);
    if let Some(mut b) = buffers.get_mut(&WAVE_LIGHTS) {
        b.data = Some(light_bytes);
    }
    if let Some(mut b) = buffers.get_mut(&WAVE_LIGHT_DATA) {
        b.data = Some(bytes(&words).to_vec());
    }
    if written.capacity != 0 && capacity != written.capacity {
        for _ in materials.iter_mut() {}
    }
    *written = LightsWritten { lights, data, capacity, warned: written.warned };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The body of WGSL function `name` in `source` (up to its closing brace at the line start).
    fn wgsl_function<'a>(source: &'a str, name: &str) -> &'a str {
        let start = source.find(&format!("fn {name}(")).unwrap_or_else(|| panic!("no fn {name}"));
        let end = source[start..].find("\n}\n").expect("the function's end") + start;
        &source[start..end]
    }

    /// Issue 45 (a game's load): lavapipe compiled the material's whole fragment shader again for
    /// every HadouMaterial drawn, every frame, because words of the uniform decide branches (Mesa's
    /// uniform inlining). The uniform is read in `load_surface` only, every field of it copied
    /// there through the zero, and the zero's array has a record whose size is not a power of two
    /// (see `load_surface`: a power of two lets the driver fold the zero away).
    #[test]
    fn issue_45_the_uniform_is_read_only_through_the_hidden_copy() {
        let source = shader_source();
        let load = wgsl_function(&source, "load_surface");
        assert_eq!(source.matches("surface_uniform").count(), 2, "the binding and load_surface's one read");
        assert!(load.contains("let u = surface_uniform;"), "{load}");
        assert!(load.contains("let zero = arrayLength(&lights) >> 31u;"), "{load}");
        assert!(!std::mem::size_of::<GpuLight>().is_power_of_two(), "GpuLight's size folds the zero");
        let fields = &FRAGMENT[FRAGMENT.find("struct HadouSurface {").expect("the struct")..];
        let fields = &fields[..fields.find("\n}\n").expect("the struct's end")];
        let names: Vec<&str> = fields
            .lines()
            .skip(1)
            .filter_map(|l| l.trim().split(':').next().filter(|n| !n.is_empty()))
            .collect();
        assert_eq!(names.len(), 13, "{names:?}");
        for name in names.iter().filter(|&&n| n != "ramp") {
            assert!(load.contains(&format!("surface.{name} = ")), "`{name}` is not copied through the zero");
            assert!(
                load.contains(&format!("u.{name}, zero)")) || load.contains(&format!("u.{name} | ")),
                "{name}"
            );
        }
        for name in ["stops[i]", "count", "kind", "smoothing"] {
            assert!(
                load.contains(&format!("surface.ramp.{name} = ")),
                "ramp.{name} is not copied through the zero"
            );
        }
    }
}
