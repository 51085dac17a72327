//! [`HadouMaterial`]: a Bevy material that shades a mesh as hadou does, under a hadou light, with
//! hadou-gpu's own WGSL (`common.wgsl`'s `diffuse` and `ramp_eval`, the twins of
//! `hadou_math::shade::diffuse` and `hadou_math::toon::Ramp::eval`) rather than Bevy's physically
//! based lighting.

use bevy::asset::uuid_handle;
use bevy::pbr::Material;
use bevy::prelude::*;
use bevy::render::render_resource::{AsBindGroup, ShaderType};
use bevy::shader::ShaderRef;
use hadou_scene::ShadingModel;

/// The fragment shader of [`HadouMaterial`], composed at start-up (see [`shader_source`]).
pub(crate) const SHADER: Handle<Shader> = uuid_handle!("0b7e55c1-2f4a-4c63-8d3e-6a9d1f2b7c44");

/// The fragment stage: the albedo (base colour times vertex colour), then hadou's Lambert model
/// `albedo · (ambient + light · max(0, N·(−L)))` (SPEC.md §2.1's diffuse model), the toon model
/// `albedo · ramp(N·(−L))` with the unclamped `m = N·(−L)` (000 §2.1, SPEC.md §2.1) or, unlit,
/// the albedo itself (`diffuse`, `ramp_eval`, `GpuRamp`, `MODEL_*` from hadou-gpu's
/// `common.wgsl`, prepended by [`shader_source`]). The normal is normalised as hadou-gpu's
/// `shade_surface` does (a zero or non-finite normal gives `m = 0`).
const FRAGMENT: &str = r"
struct HadouSurface {
    base_color: vec4<f32>,
    light_direction: vec4<f32>,
    light_color: vec4<f32>,
    ambient: vec4<f32>,
    model: u32,
    ramp: GpuRamp,
}
@group(#{MATERIAL_BIND_GROUP}) @binding(0) var<uniform> surface: HadouSurface;

@fragment
fn fragment(in: VertexOutput) -> @location(0) vec4<f32> {
    var albedo = surface.base_color.xyz;
#ifdef VERTEX_COLORS
    albedo = albedo * in.color.xyz;
#endif
    var c = albedo;
    if (surface.model == MODEL_DIFFUSE) {
        c = diffuse(albedo, in.world_normal, surface.light_direction.xyz, surface.light_color.xyz, surface.ambient.xyz);
    } else if (surface.model == MODEL_TOON) {
        let len = length3(in.world_normal);
        var n = vec3<f32>(0.0);
        if (len > 0.0 && len < 3.0e38) {
            n = in.world_normal / len;
        }
        c = albedo * ramp_eval(surface.ramp, dot3(n, -surface.light_direction.xyz));
    }
    return vec4<f32>(c, 1.0);
}
";

/// The WGSL of [`HadouMaterial`]: Bevy's mesh vertex output, hadou-gpu's `common.wgsl`, then
/// [`FRAGMENT`].
pub(crate) fn shader_source() -> String {
    format!("#import bevy_pbr::forward_io::VertexOutput\n{}\n{FRAGMENT}", hadou_gpu::shaders::COMMON)
}

/// What [`HadouMaterial`]'s shader reads (its uniform).
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
    /// hadou-gpu's shading model code (`layout::MODEL_DIFFUSE`, `MODEL_TOON` or `MODEL_UNLIT`).
    pub model: u32,
    /// The toon ramp (read by `MODEL_TOON` only).
    pub ramp: HadouRamp,
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
        let g = hadou_gpu::layout::GpuRamp::new(ramp);
        HadouRamp {
            stops: g.stops.map(Vec4::from_array),
            count: g.count,
            kind: g.kind,
            smoothing: g.smoothing,
            pad: 0,
        }
    }
}

/// A material shaded as a hadou `[[material]]` under a hadou `[light]` (SPEC.md §2.1):
/// `model = "diffuse"` gives `albedo · (ambient + light · max(0, N·(−L)))`, `"toon"` gives
/// `albedo · ramp(N·(−L))` (000 §2.1, the unclamped `m`; `ramp`, `ramp_kind`, `ramp_smoothing`),
/// `"unlit"` the albedo, with `albedo` the base colour times the mesh's vertex colours, `N` the
/// interpolated world normal. It writes linear colour into the HDR target, before the waves'
/// light and the colour mapping, as hadou's opaque pass does. Textures, `wave_blend`, glow and
/// outlines are not drawn yet.
#[derive(Asset, TypePath, AsBindGroup, Clone, Debug, PartialEq)]
pub struct HadouMaterial {
    /// The uniform.
    #[uniform(0)]
    pub surface: HadouSurface,
}

impl HadouMaterial {
    /// hadou's shading of `material` (its model, base colour and ramp) under `light`.
    pub fn new(material: &hadou_scene::Material, light: &hadou_scene::Light) -> Self {
        let [r, g, b] = material.base_color;
        let v = |c: [f32; 3]| Vec4::new(c[0], c[1], c[2], 0.0);
        let d = light.direction;
        let model = match material.model {
            ShadingModel::Unlit => hadou_gpu::layout::MODEL_UNLIT,
            ShadingModel::Diffuse => hadou_gpu::layout::MODEL_DIFFUSE,
            ShadingModel::Toon => hadou_gpu::layout::MODEL_TOON,
        };
        HadouMaterial {
            surface: HadouSurface {
                base_color: Vec4::new(r, g, b, 1.0),
                light_direction: Vec4::new(d.x, d.y, d.z, 0.0),
                light_color: v(light.color),
                ambient: v(light.ambient),
                model,
                ramp: HadouRamp::new(&material.ramp),
            },
        }
    }
}

impl Material for HadouMaterial {
    fn fragment_shader() -> ShaderRef {
        ShaderRef::Handle(SHADER)
    }
}
