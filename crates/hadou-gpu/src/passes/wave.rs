//! The wave pass (`shaders/wave.wgsl`, a compute shader, with energy.wgsl, curve.wgsl,
//! shading.wgsl and shadow_lookup.wgsl composed in): per pixel, the visible surface from the
//! G-buffer shaded (materials, lights, textures, the waves as lights, hard shadows, the
//! `[area_light]`'s term), then every wave's energy integral along the view ray clipped at that
//! surface (002 §3.3.5), `scene + exposure·Σ rgb·a·I` and the colour mapping, written to an output
//! buffer (colour, energy, eye distance per pixel) that the read-back or the present pass takes.
//!
//! The pass is specialised per frame ([`WaveVariant`]): the module is composed with only the
//! source features the frame uses (attenuation, 8-bit output, the samples' entry point:
//! `shaders::compose_with`), it declares pipeline-overridable `bool` constants, one per part, and
//! each frame gets a pipeline with only what its data can reach compiled in, modules and pipelines
//! built on first use and cached.

use super::setup::{self, Binding, Kind};
use crate::device::GpuContext;
use crate::layout;
use crate::shaders;
use hadou_scene::RenderError;
use std::collections::HashMap;

/// Workgroup edge of the wave pass (keep in sync with `@workgroup_size` in wave.wgsl).
pub(crate) const WAVE_WORKGROUP: u32 = 8;

const CS: wgpu::ShaderStages = wgpu::ShaderStages::COMPUTE;

/// The bindings of the wave module (wave.wgsl 0–4 and 13, curve.wgsl 5–7, shading_bindings.wgsl
/// 8–10, shadow_bindings.wgsl 11–12).
pub(crate) const BINDINGS: [Binding; 14] = [
    Binding::new(0, "frame_uniforms", Kind::Uniform, CS),
    Binding::new(1, "waves", Kind::Storage, CS),
    Binding::new(2, "scene_texels", Kind::UintTexture, CS),
    Binding::new(3, "attribute_texels", Kind::UintTexture, CS),
    Binding::new(4, "out_buf", Kind::StorageRw, CS),
    Binding::new(5, "curves", Kind::Storage, CS),
    Binding::new(6, "curve_vec4", Kind::Storage, CS),
    Binding::new(7, "curve_f32", Kind::Storage, CS),
    Binding::new(8, "materials", Kind::Storage, CS),
    Binding::new(9, "lights", Kind::Storage, CS),
    Binding::new(10, "shading_data", Kind::Storage, CS),
    Binding::new(11, "plane_shadow_texels", Kind::UintTexture, CS),
    Binding::new(12, "shadow_maps", Kind::DepthArray, CS),
    Binding::new(13, "srgb8_next", Kind::Uniform, CS),
];

/// What the wave pass reads and writes, in the order of [`BINDINGS`].
pub(crate) struct WaveInputs<'a> {
    /// The tile's `layout::FrameUniforms`.
    pub(crate) uniforms: &'a wgpu::Buffer,
    /// The frame's `layout::GpuWave`s.
    pub(crate) waves: &'a wgpu::Buffer,
    /// The tile's G-buffer, as the raster pass drew it ([`crate::formats::SCENE_FORMAT`]).
    pub(crate) surface: &'a wgpu::TextureView,
    pub(crate) attributes: &'a wgpu::TextureView,
    /// The output: per pixel colour (4), energy, eye distance as `f32`, or one word of 8-bit sRGB
    /// (see wave.wgsl binding 4).
    pub(crate) output: &'a wgpu::Buffer,
    /// The curve buffers (`layout::CurveBuffers`: curves, vec4s, scalars).
    pub(crate) curves: [&'a wgpu::Buffer; 3],
    /// Materials, lights and shading data (`layout::ShadingBuffers`).
    pub(crate) materials: &'a wgpu::Buffer,
    pub(crate) lights: &'a wgpu::Buffer,
    pub(crate) shading_data: &'a wgpu::Buffer,
    /// The plane-shadow pass's target of the tile.
    pub(crate) plane_shadows: &'a wgpu::TextureView,
    /// The frame's shadow maps (all layers).
    pub(crate) shadow_maps: &'a wgpu::TextureView,
}

/// Each GPU wave kind (`layout::GpuWave::kind`): its constant in common.wgsl, which the wave
/// module branches on, and the override that compiles its kernel in. A kind of the scene format
/// with no row here has no kernel on the GPU (`every_wave_kind_has_a_kernel` fails).
pub(crate) const KIND_KERNELS: [(u32, &str, &str); 5] = [
    (layout::WAVE_SPHERE, "WAVE_SPHERE", "USE_SPHERE"),
    (layout::WAVE_CYLINDER, "WAVE_CYLINDER", "USE_CYLINDER"),
    (layout::WAVE_CAPSULE, "WAVE_CAPSULE", "USE_CAPSULE"),
    (layout::WAVE_BEAM, "WAVE_BEAM", "USE_BEAM"),
    (layout::WAVE_CURVE, "WAVE_CURVE", "USE_CURVE"),
];

/// The largest α of an analytic wave for which energy.wgsl's α·I can be one multiplication
/// (`USE_WIDE_SCALE` off): α·2·`ENERGY_MAX` (2·10³⁰, two pieces summed) stays below `f32::MAX`
/// (3.4·10³⁸) with room to spare.
const WIDE_ALPHA: f32 = 1.0e8;

/// Each curve shape (`layout::GpuCurve::shape`), as [`KIND_KERNELS`].
pub(crate) const SHAPE_KERNELS: [(u32, &str, &str); 4] = [
    (layout::SHAPE_HELIX, "SHAPE_HELIX", "USE_HELIX"),
    (layout::SHAPE_TRIG, "SHAPE_TRIG", "USE_TRIG"),
    (layout::SHAPE_BEZIER, "SHAPE_BEZIER", "USE_BEZIER"),
    (layout::SHAPE_BSPLINE, "SHAPE_BSPLINE", "USE_BSPLINE"),
];

/// The override of `code`'s kernel in `table`; for a code with no row (none is made), every
/// kernel of the table, so nothing it could need is compiled out.
fn kernels(table: &[(u32, &'static str, &'static str)], code: u32) -> Vec<&'static str> {
    match table.iter().find(|k| k.0 == code) {
        Some(k) => vec![k.2],
        None => table.iter().map(|k| k.2).collect(),
    }
}

/// Which parts of the wave pass a frame needs: one bit per pipeline-overridable `USE_*` constant of
/// the wave module (wave.wgsl, energy.wgsl, curve.wgsl, shading.wgsl, shadow_lookup.wgsl), and
/// three bits that choose the module's source itself: the samples' entry point, the 8-bit output
/// and the attenuation (`shaders::FEATURES`). A clear `USE_*` bit compiles its part out (the
/// constant is `false`, so the branch is dead and the driver drops it); a clear source bit leaves
/// its code out of the module altogether ([`WaveVariant::source`]). A set bit leaves the code
/// exactly as the uber-shader's ([`WaveVariant::UBER`], every part set). [`WaveVariant::of`] sets
/// a bit for everything the frame's data can reach, so a frame renders identically with its
/// variant and with the uber-shader.
///
/// Why: a software adapter such as llvmpipe runs a shader's branches under an execution mask,
/// both sides of every `if` and every `switch` case, whichever the pixels take; the uber-shader
/// made a one-sphere frame pay for every wave kind, the curve walker and the surface shading.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct WaveVariant(u64);

impl WaveVariant {
    /// The `USE_*` overrides, bit `i` of the variant is the `i`-th name.
    pub(crate) const NAMES: [&'static str; 31] = [
        // wave.wgsl
        "USE_SPHERE",
        "USE_CYLINDER",
        "USE_CAPSULE",
        "USE_BEAM",
        "USE_CURVE",
        "USE_SURFACES",
        "USE_AREA",
        "USE_TONE_FAITHFUL",
        "USE_TONE_FILMIC",
        // energy.wgsl
        "USE_FAITHFUL",
        "USE_INVERSE_SQUARE",
        "USE_WIDE_SCALE",
        "USE_BEAM_HEAD",
        "USE_BEAM_MUZZLE",
        // curve.wgsl
        "USE_CHORD",
        "USE_SIMPSON",
        "USE_NEAREST",
        "USE_HELIX",
        "USE_TRIG",
        "USE_BEZIER",
        "USE_BSPLINE",
        // shading.wgsl
        "USE_TOON",
        "USE_MTOON",
        "USE_TEXTURES",
        "USE_WAVE_LIGHTS",
        "USE_LINE_POINT",
        "USE_LINE_SEGMENT",
        "USE_LINE_LINE",
        "USE_LINE_POLYLINE",
        // shadow_lookup.wgsl
        "USE_PLANE_SHADOWS",
        "USE_MAP_SHADOWS",
    ];
    /// Every part, the attenuation included: the uber-shader, right for any frame of one sample
    /// per pixel (writing floats).
    pub(crate) const UBER: WaveVariant = WaveVariant(((1 << Self::NAMES.len()) - 1) | Self::ATTENUATION);
    /// The bit past the overrides: pixels are resolved from several samples, by the wave samples
    /// module's entry point `cs_samples` instead of the wave module's `cs_main` (a module of its
    /// own, so a frame of one sample per pixel compiles nothing of the samples' loops).
    const SAMPLES: u64 = 1 << Self::NAMES.len();
    /// The next bit: the pass writes each pixel's 8-bit sRGB bytes (what a PNG holds) instead of
    /// its float colour, energy and depth (the source feature `SRGB8`: a module without it holds
    /// none of the encoding).
    const SRGB8: u64 = 1 << (Self::NAMES.len() + 1);
    /// The next bit: some wave of the frame is attenuated, `j > 0` (002 eq. 3.23; the source
    /// feature `ATTENUATION`: a module without it holds none of the attenuated march, which a
    /// software adapter would otherwise run under a mask for every piece of every pixel).
    const ATTENUATION: u64 = 1 << (Self::NAMES.len() + 2);

    /// Whether this variant resolves pixels from several samples (`cs_samples`).
    pub(crate) fn samples(self) -> bool {
        self.0 & Self::SAMPLES != 0
    }

    /// This variant, resolving pixels from several samples or not.
    pub(crate) fn with_samples(self, on: bool) -> Self {
        if on {
            WaveVariant(self.0 | Self::SAMPLES)
        } else {
            WaveVariant(self.0 & !Self::SAMPLES)
        }
    }

    /// Whether this variant writes 8-bit sRGB words (see [`Self::SRGB8`]).
    pub(crate) fn srgb8(self) -> bool {
        self.0 & Self::SRGB8 != 0
    }

    /// This variant, writing 8-bit sRGB words or the float outputs.
    pub(crate) fn with_srgb8(self, on: bool) -> Self {
        if on {
            WaveVariant(self.0 | Self::SRGB8)
        } else {
            WaveVariant(self.0 & !Self::SRGB8)
        }
    }

    /// Whether this variant integrates the attenuation `(1 − u)^j` (see [`Self::ATTENUATION`]).
    pub(crate) fn attenuation(self) -> bool {
        self.0 & Self::ATTENUATION != 0
    }

    /// The source features (`shaders::FEATURES`) of this variant's module.
    pub(crate) fn features(self) -> Vec<&'static str> {
        let mut on = Vec::new();
        if self.attenuation() {
            on.push("ATTENUATION");
        }
        if self.srgb8() {
            on.push("SRGB8");
        }
        on
    }

    /// The WGSL of this variant's module: the wave module (entry point `cs_main`) or, with
    /// samples, the wave samples module (`cs_samples`), composed with [`Self::features`].
    pub(crate) fn source(self) -> String {
        let parts = if self.samples() { shaders::WAVE_SAMPLES_PARTS } else { shaders::WAVE_PARTS };
        shaders::compose_with(parts, &self.features())
    }

    /// The bit of override `name`.
    fn bit(name: &str) -> u64 {
        let i = Self::NAMES.iter().position(|n| *n == name).expect("a USE_* name");
        1 << i
    }

    /// Whether the override `name` is set.
    pub(crate) fn has(self, name: &str) -> bool {
        self.0 & Self::bit(name) != 0
    }

    /// The variant with nothing but the overrides in `names` set.
    pub(crate) fn from_names<'a>(names: impl IntoIterator<Item = &'a str>) -> Self {
        WaveVariant(names.into_iter().fold(0, |v, n| v | Self::bit(n)))
    }

    /// The variant a frame needs, from what the wave pass will read: the waves, the curves, the
    /// materials and lights (the lights shading.wgsl reads), whether anything is drawn, whether
    /// some wave glows, the shadow casts (plane, map), the `[area_light]`, the colour mapping and
    /// whether pixels are resolved from several samples (anti-aliasing).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn of(
        waves: &[layout::GpuWave],
        curves: &[layout::GpuCurve],
        materials: &[layout::GpuMaterial],
        lights: &[layout::GpuLight],
        any_glow: bool,
        surfaces: bool,
        shadows: (bool, bool),
        area: bool,
        tone_faithful: bool,
        exposure: f32,
        samples: bool,
    ) -> Self {
        let mut on: Vec<&str> = Vec::new();
        // energy.wgsl's USE_WIDE_SCALE: every α·I fits in f32 only when every analytic wave's α
        // is at most WIDE_ALPHA (its pieces are at most ENERGY_MAX, two summed at most twice
        // that), every curve's α and the exposure at most 1 (their sums are only saturated).
        // A NaN (never validated through) takes the wide road, as the shader's `alpha <= 1.0` sends it.
        let above = |x: f32, limit: f32| x.is_nan() || x > limit;
        let analytic_alphas = |w: &layout::GpuWave| [w.p0[3], w.p1[3], w.p2[1], w.p2[2]];
        let wide = above(exposure, 1.0)
            || waves.iter().any(|w| {
                w.kind != layout::WAVE_CURVE && analytic_alphas(w).iter().any(|a| above(*a, WIDE_ALPHA))
            })
            || curves.iter().any(|c| above(c.alpha, 1.0));
        if wide {
            on.push("USE_WIDE_SCALE");
        }
        // `!(j == 0)`: the shaders' own test, so a NaN (never validated through) is attenuated too.
        let attenuated =
            waves.iter().any(|w| !(w.attenuation == 0.0)) || curves.iter().any(|c| !(c.attenuation == 0.0));
        for w in waves {
            on.extend(kernels(&KIND_KERNELS, w.kind));
            // The beam's bulbs (p2.y head, p2.z muzzle), by the shader's own test `α ≠ 0`.
            let bulbs = !matches!(
                w.kind,
                layout::WAVE_SPHERE | layout::WAVE_CYLINDER | layout::WAVE_CAPSULE | layout::WAVE_CURVE
            );
            if bulbs && w.p2[1] != 0.0 {
                on.push("USE_BEAM_HEAD");
            }
            if bulbs && w.p2[2] != 0.0 {
                on.push("USE_BEAM_MUZZLE");
            }
            on.push(if w.falloff == layout::FALLOFF_FAITHFUL {
                "USE_FAITHFUL"
            } else {
                "USE_INVERSE_SQUARE"
            });
        }
        for c in curves {
            on.push(match c.integrator {
                layout::INTEGRATOR_SIMPSON => "USE_SIMPSON",
                layout::INTEGRATOR_NEAREST => "USE_NEAREST",
                _ => "USE_CHORD",
            });
            on.extend(kernels(&SHAPE_KERNELS, c.shape));
        }
        if surfaces {
            on.push("USE_SURFACES");
            if materials.iter().any(|m| m.model == layout::MODEL_TOON) {
                on.push("USE_TOON");
            }
            let mtoon = materials.iter().any(|m| m.mtoon != 0);
            if mtoon {
                on.push("USE_MTOON");
            }
            if mtoon || materials.iter().any(|m| m.base_texture.offset != 0 || m.feature_texture.offset != 0)
            {
                on.push("USE_TEXTURES");
            }
            let lit = !lights.is_empty() && (any_glow || materials.iter().any(|m| m.wave_blend > 0.0));
            if lit {
                on.push("USE_WAVE_LIGHTS");
                for l in lights {
                    on.push(match l.line_kind {
                        layout::LINE_POINT => "USE_LINE_POINT",
                        layout::LINE_SEGMENT => "USE_LINE_SEGMENT",
                        layout::LINE_LINE => "USE_LINE_LINE",
                        _ => "USE_LINE_POLYLINE",
                    });
                }
            }
            if shadows.0 {
                on.push("USE_PLANE_SHADOWS");
            }
            if shadows.1 {
                on.push("USE_MAP_SHADOWS");
            }
            if area {
                on.push("USE_AREA");
            }
        }
        on.push(if tone_faithful { "USE_TONE_FAITHFUL" } else { "USE_TONE_FILMIC" });
        let v = Self::from_names(on).with_samples(samples);
        if attenuated {
            WaveVariant(v.0 | Self::ATTENUATION)
        } else {
            v
        }
    }

    /// The override values of this variant (`1.0` true, `0.0` false), for the pipeline.
    fn constants(self) -> Vec<(&'static str, f64)> {
        let bit = |on: bool| if on { 1.0 } else { 0.0 };
        Self::NAMES.iter().map(|&n| (n, bit(self.has(n)))).collect()
    }
}

/// What picks a wave module's source: samples (the `cs_samples` module), 8-bit output,
/// attenuation ([`WaveVariant::source`]).
type ModuleKey = (bool, bool, bool);

/// The wave modules, their bind group layout and the pipelines built so far.
pub(crate) struct WavePass {
    /// The wave modules built so far, one per source ([`WaveVariant::source`]; variants of one
    /// module set its `USE_*` overrides).
    modules: HashMap<ModuleKey, wgpu::ShaderModule>,
    pipeline_layout: wgpu::PipelineLayout,
    layout: wgpu::BindGroupLayout,
    /// `srgb8_next` (binding 13): the 8-bit sRGB thresholds, written once.
    srgb8_next: wgpu::Buffer,
    /// The wave pipelines built so far, one per variant (see [`WavePass::pipeline`]).
    variants: HashMap<WaveVariant, wgpu::ComputePipeline>,
    /// Whether [`WavePass::pipeline`] specialises; `false` gives every frame the uber-shader.
    pub(crate) specialise: bool,
}

impl WavePass {
    /// The bind group layout and thresholds; modules and pipelines are built per variant on
    /// first use.
    pub(crate) fn new(ctx: &GpuContext) -> Result<Self, RenderError> {
        ctx.scoped("building the wave pipeline layout", || {
            let layout = setup::bind_group_layout(&ctx.device, "wave", &BINDINGS);
            let pipeline_layout = setup::pipeline_layout(&ctx.device, "wave", &layout);
            let next = hadou_math::shade::srgb8_encoder().next_thresholds();
            let srgb8_next = wgpu::util::DeviceExt::create_buffer_init(
                &ctx.device,
                &wgpu::util::BufferInitDescriptor {
                    label: Some("sRGB 8-bit thresholds"),
                    contents: bytemuck::cast_slice(next),
                    usage: wgpu::BufferUsages::UNIFORM,
                },
            );
            Self {
                modules: HashMap::new(),
                pipeline_layout,
                layout,
                srgb8_next,
                variants: HashMap::new(),
                specialise: true,
            }
        })
    }

    /// The wave pipeline of `variant` ([`WaveVariant::UBER`] when not specialising, resolving
    /// samples if `variant` does), built on first use and kept: the same variant always gets the
    /// same pipeline. Also the variant it is.
    pub(crate) fn pipeline(
        &mut self,
        ctx: &GpuContext,
        variant: WaveVariant,
    ) -> Result<(wgpu::ComputePipeline, WaveVariant), RenderError> {
        let variant = if self.specialise {
            variant
        } else {
            WaveVariant::UBER.with_samples(variant.samples()).with_srgb8(variant.srgb8())
        };
        if let Some(p) = self.variants.get(&variant) {
            return Ok((p.clone(), variant));
        }
        let key = (variant.samples(), variant.srgb8(), variant.attenuation());
        let module = match self.modules.entry(key) {
            std::collections::hash_map::Entry::Occupied(m) => m.into_mut(),
            std::collections::hash_map::Entry::Vacant(slot) => {
                let label = if variant.samples() { "wave samples" } else { "wave" };
                slot.insert(setup::compile_module(ctx, label, &variant.source())?)
            }
        };
        let constants = variant.constants();
        let pipeline = ctx.scoped("building the wave pipeline", || {
            ctx.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("wave"),
                layout: Some(&self.pipeline_layout),
                module,
                entry_point: Some(if variant.samples() { "cs_samples" } else { "cs_main" }),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &constants,
                    ..Default::default()
                },
                cache: None,
            })
        })?;
        self.variants.insert(variant, pipeline.clone());
        Ok((pipeline, variant))
    }

    /// How many wave pipelines have been built.
    pub(crate) fn variant_count(&self) -> usize {
        self.variants.len()
    }

    /// The bind group of `inputs`.
    pub(crate) fn bind_group(&self, device: &wgpu::Device, inputs: &WaveInputs<'_>) -> wgpu::BindGroup {
        let view = wgpu::BindingResource::TextureView;
        let resources = vec![
            inputs.uniforms.as_entire_binding(),
            inputs.waves.as_entire_binding(),
            view(inputs.surface),
            view(inputs.attributes),
            inputs.output.as_entire_binding(),
            inputs.curves[0].as_entire_binding(),
            inputs.curves[1].as_entire_binding(),
            inputs.curves[2].as_entire_binding(),
            inputs.materials.as_entire_binding(),
            inputs.lights.as_entire_binding(),
            inputs.shading_data.as_entire_binding(),
            view(inputs.plane_shadows),
            view(inputs.shadow_maps),
            self.srgb8_next.as_entire_binding(),
        ];
        setup::bind_group(device, "wave", &self.layout, &BINDINGS, resources)
    }

    /// Records the pass over a `size` tile with `pipeline` (a variant from [`WavePass::pipeline`]).
    pub(crate) fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        pipeline: &wgpu::ComputePipeline,
        bind_group: &wgpu::BindGroup,
        size: [u32; 2],
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        let mut pass =
            enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("wave"), timestamp_writes });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        let g = WAVE_WORKGROUP;
        pass.dispatch_workgroups(size[0].div_ceil(g), size[1].div_ceil(g), 1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bytemuck::Zeroable;

    /// `WaveVariant::NAMES` are exactly the wave module's overrides, each a `bool` defaulting to
    /// true (so the module alone is the uber-shader), in every source the variants compose.
    #[test]
    fn variant_names_are_the_wave_modules_overrides() {
        for variant in
            [WaveVariant::UBER, WaveVariant(0), WaveVariant::UBER.with_samples(true).with_srgb8(true)]
        {
            let source = variant.source();
            let module = naga::front::wgsl::parse_str(&source).expect("the wave module parses");
            let mut overrides: Vec<&str> = Vec::new();
            for (_, o) in module.overrides.iter() {
                let name = o.name.as_deref().expect("named override");
                assert_eq!(module.types[o.ty].inner, naga::TypeInner::Scalar(naga::Scalar::BOOL), "{name}");
                let init = o.init.expect("a default");
                assert!(
                    matches!(
                        module.global_expressions[init],
                        naga::Expression::Literal(naga::Literal::Bool(true))
                    ),
                    "{name} defaults to true"
                );
                overrides.push(name);
            }
            overrides.sort_unstable();
            let mut names = WaveVariant::NAMES.to_vec();
            names.sort_unstable();
            assert_eq!(overrides, names);
        }
        assert!(WaveVariant::NAMES.iter().all(|n| WaveVariant::UBER.has(n)));
        assert!(
            WaveVariant::UBER.attenuation() && !WaveVariant::UBER.srgb8() && !WaveVariant::UBER.samples()
        );
        let uber = WaveVariant::UBER.constants();
        assert!(uber.iter().all(|&(_, v)| v == 1.0));
        assert_eq!(uber.len(), WaveVariant::NAMES.len());
    }

    /// A frame without attenuation, samples or 8-bit output gets a module that holds none of
    /// their code: no function, binding or entry point of theirs is in the naga module its
    /// source parses to (and each is there once the frame uses it).
    #[test]
    fn a_frame_compiles_in_only_the_features_it_uses() {
        let sphere = layout::GpuWave {
            kind: layout::WAVE_SPHERE,
            falloff: layout::FALLOFF_FAITHFUL,
            ..layout::GpuWave::zeroed()
        };
        let plain =
            WaveVariant::of(&[sphere], &[], &[], &[], false, false, (false, false), false, true, 1.0, false);
        // The code of each feature: functions, global variables (bindings) and entry points.
        const ATTENUATION: &[&str] = &[
            "rq_attenuated",
            "att_mean_line",
            "att_mean_peak",
            "att_density",
            "att_factor",
            "curve_piece_attenuated",
            "segment_attenuated",
            "segment_moments",
        ];
        const SRGB8: &[&str] = &["srgb8_code", "is_finite_f32", "srgb8_next"];
        const SAMPLES: &[&str] = &["cs_samples", "tile_sample"];
        let names = |v: WaveVariant| -> Vec<String> {
            let source = v.source();
            let module = naga::front::wgsl::parse_str(&source).expect("the variant's module parses");
            let functions = module.functions.iter().filter_map(|(_, f)| f.name.clone());
            let globals = module.global_variables.iter().filter_map(|(_, g)| g.name.clone());
            let entries = module.entry_points.iter().map(|e| e.name.clone());
            functions.chain(globals).chain(entries).collect()
        };
        let has = |v: WaveVariant, item: &str| names(v).iter().any(|n| n == item);
        for item in ATTENUATION.iter().chain(SRGB8).chain(SAMPLES) {
            assert!(!has(plain, item), "{item} is in the module of a frame without its feature");
            assert!(
                !plain.source().contains(&format!("{item}(")) || *item == "srgb8_next",
                "{item} in the source"
            );
        }
        assert!(has(plain, "cs_main") && has(plain, "rq_integral") && has(plain, "out_buf"));
        // Each feature brings its own code, and only its own.
        let attenuated = WaveVariant::of(
            &[layout::GpuWave { attenuation: 8.0, ..sphere }],
            &[],
            &[],
            &[],
            false,
            false,
            (false, false),
            false,
            true,
            1.0,
            false,
        );
        assert!(attenuated.attenuation() && !plain.attenuation());
        assert!(ATTENUATION.iter().all(|item| has(attenuated, item)));
        assert!(!SRGB8.iter().chain(SAMPLES).any(|item| has(attenuated, item)));
        let png = plain.with_srgb8(true);
        assert!(SRGB8.iter().all(|item| has(png, item)));
        assert!(!ATTENUATION.iter().chain(SAMPLES).any(|item| has(png, item)));
        let aa = plain.with_samples(true);
        assert!(SAMPLES.iter().all(|item| has(aa, item)));
        assert!(!ATTENUATION.iter().chain(SRGB8).any(|item| has(aa, item)));
        // A curve's attenuation counts too.
        let curve = layout::GpuCurve { attenuation: 1.5, ..Zeroable::zeroed() };
        let v =
            WaveVariant::of(&[], &[curve], &[], &[], false, false, (false, false), false, true, 1.0, false);
        assert!(v.attenuation());
    }

    /// Every `[[wave]] kind` of the scene format reaches a kernel of its own: its GPU form has a
    /// row in [`KIND_KERNELS`] (and, for a curve, [`SHAPE_KERNELS`]) that no other kind shares, and
    /// the uber-shader's source branches on the row's constant under the row's override. A new
    /// kind fails here until the WGSL has its kernel (ARCHITECTURE.md, "Add a wave shape").
    #[test]
    fn every_wave_kind_has_a_kernel() {
        use hadou_math::curve::{CurveFrame, CurveShape, CurveWave, Integrator};
        use hadou_math::energy::{BeamField, CapsuleField, CylinderField, Falloff, SphereField};
        use hadou_math::Vec3;
        use hadou_scene::{CurveKind, WaveKind, WaveShape};
        let source = WaveVariant::UBER.source();
        // The source without its comments, where the overrides are used.
        let code: String =
            source.lines().map(|l| l.split("//").next().unwrap_or("")).collect::<Vec<_>>().join("\n");
        let capsule = CapsuleField { m: Vec3::ZERO, d: Vec3::X, length: 2.0, alpha_s: 0.5, alpha_c: 0.5 };
        let points = vec![[0.0, 0.0], [1.0, 0.5], [0.0, 1.0]];
        let mut seen = Vec::new();
        for kind in WaveKind::ALL {
            let curve = |shape| CurveWave {
                frame: CurveFrame { origin: Vec3::ZERO, axis: Vec3::X, up: Vec3::Y },
                shape,
                gamma: 1.0,
                extension: 1.0,
                attenuation: 0.0,
                alpha: 0.3,
                integrator: Integrator::Default,
            };
            let shape = match kind {
                WaveKind::Sphere => WaveShape::Sphere(SphereField { center: Vec3::ZERO, alpha: 1.0 }),
                WaveKind::Cylinder => {
                    WaveShape::Cylinder(CylinderField { point: Vec3::ZERO, dir: Vec3::Y, alpha: 1.0 })
                }
                WaveKind::Capsule => WaveShape::Capsule(capsule),
                WaveKind::Beam => WaveShape::Beam(BeamField { capsule, head_alpha: 1.0, muzzle_alpha: 0.2 }),
                WaveKind::Curve(CurveKind::Helix) => WaveShape::Curve(curve(CurveShape::Helix {
                    radius: 1.0,
                    rate: 2.0,
                    phase: 0.0,
                    length: 4.0,
                })),
                WaveKind::Curve(CurveKind::Trig) => WaveShape::Curve(curve(CurveShape::TrigSum {
                    rate: 2.0,
                    y_terms: vec![[0.5, 0.0]],
                    z_terms: vec![],
                    length: 4.0,
                })),
                WaveKind::Curve(CurveKind::Bezier) => {
                    WaveShape::Curve(curve(CurveShape::Bezier { points: points.clone() }))
                }
                WaveKind::Curve(CurveKind::BSpline) => WaveShape::Curve(curve(CurveShape::BSpline {
                    points: points.clone(),
                    order: 3,
                    knots: None,
                })),
            };
            let wave = hadou_scene::Wave::new(kind.name(), [1.0; 4], Falloff::Faithful, 0.0, shape);
            // The kind's rows: its wave record's, and its curve record's if it is a curve.
            let mut rows = Vec::new();
            let record = match &wave.shape {
                WaveShape::Curve(c) => {
                    let mut buffers = layout::CurveBuffers::default();
                    let index = buffers.push(&hadou_math::curve::prepare(c)).expect("one curve");
                    let shape = buffers.curves[index as usize].shape;
                    let row = SHAPE_KERNELS.iter().find(|k| k.0 == shape);
                    rows.push(
                        *row.unwrap_or_else(|| panic!("{}: curve shape {shape} has no kernel", kind.name())),
                    );
                    layout::GpuWave::curve(&wave, index)
                }
                WaveShape::Sphere(_)
                | WaveShape::Cylinder(_)
                | WaveShape::Capsule(_)
                | WaveShape::Beam(_) => layout::GpuWave::new(&wave).expect("an analytic wave"),
            };
            let row = KIND_KERNELS.iter().find(|k| k.0 == record.kind);
            rows.push(
                *row.unwrap_or_else(|| panic!("{}: wave kind {} has no kernel", kind.name(), record.kind)),
            );
            for (_, constant, flag) in &rows {
                assert!(
                    source.contains(&format!("const {constant}: u32"))
                        && (source.contains(&format!("== {constant}"))
                            || source.contains(&format!("case {constant}"))),
                    "{}: the wave module does not branch on {constant}",
                    kind.name()
                );
                assert!(
                    source.contains(&format!("override {flag}: bool")),
                    "{}: no override {flag}",
                    kind.name()
                );
                let uses = code.matches(flag).count();
                assert!(uses >= 2, "{}: {flag} is declared but guards nothing", kind.name());
            }
            let key: Vec<&str> = rows.iter().map(|r| r.2).collect();
            assert!(!seen.contains(&key), "{}: shares its kernel {key:?} with another kind", kind.name());
            seen.push(key);
        }
    }

    /// The wave modules read the uniforms only through `load_frame`'s private copy: the binding
    /// appears in its declaration and in the copy, nowhere else, and every entry point calls
    /// `load_frame` first (ARCHITECTURE.md's invariant: lavapipe would compile the pass again for
    /// every value of a uniform that decides a branch).
    #[test]
    fn the_frame_is_read_through_its_private_copy() {
        let sources = [
            ("wave", WaveVariant::UBER.source()),
            ("wave samples", WaveVariant::UBER.with_samples(true).source()),
            ("wave overlay", crate::shaders::compose(crate::shaders::WAVE_OVERLAY_PARTS)),
        ];
        for (name, source) in sources {
            let code: Vec<&str> = source.lines().map(|l| l.split("//").next().unwrap_or("")).collect();
            let uses = code.iter().filter(|l| l.contains("frame_uniforms")).count();
            assert_eq!(uses, 2, "{name}: `frame_uniforms` outside its declaration and load_frame");
            let module = naga::front::wgsl::parse_str(&source).expect("the module parses");
            assert!(!module.entry_points.is_empty(), "{name}");
            for entry in &module.entry_points {
                // An entry point reading no global and calling nothing (the overlay's vertex
                // stage) has no frame to read.
                let f = &entry.function;
                let reads =
                    f.expressions.iter().any(|(_, e)| matches!(e, naga::Expression::GlobalVariable(_)))
                        || f.body.iter().any(|s| matches!(s, naga::Statement::Call { .. }));
                if !reads {
                    continue;
                }
                let first_call = entry.function.body.iter().find_map(|s| match s {
                    naga::Statement::Call { function, .. } => module.functions[*function].name.clone(),
                    _ => None,
                });
                assert_eq!(
                    first_call.as_deref(),
                    Some("load_frame"),
                    "{name}: {} calls load_frame first",
                    entry.name
                );
            }
        }
    }

    /// `WaveVariant::of` sets a part exactly when the frame's data can reach it.
    #[test]
    fn a_variant_has_exactly_what_the_frame_uses() {
        let wave = |kind, falloff| layout::GpuWave { kind, falloff, ..layout::GpuWave::zeroed() };
        let waves = [wave(layout::WAVE_SPHERE, layout::FALLOFF_FAITHFUL), wave(layout::WAVE_CURVE, 1)];
        let curve = layout::GpuCurve {
            integrator: layout::INTEGRATOR_SIMPSON,
            shape: layout::SHAPE_BEZIER,
            ..Zeroable::zeroed()
        };
        let mut toon = layout::GpuMaterial::zeroed();
        toon.model = layout::MODEL_TOON;
        toon.wave_blend = 0.5;
        let light = layout::GpuLight { line_kind: layout::LINE_POLYLINE, ..Zeroable::zeroed() };
        let names = |v: WaveVariant| -> Vec<&str> {
            WaveVariant::NAMES.iter().copied().filter(|n| v.has(n)).collect()
        };
        let v = WaveVariant::of(
            &waves,
            &[curve],
            &[toon],
            &[light],
            false,
            true,
            (false, true),
            false,
            false,
            1.0,
            false,
        );
        assert_eq!(
            names(v),
            [
                "USE_SPHERE",
                "USE_CURVE",
                "USE_SURFACES",
                "USE_TONE_FILMIC",
                "USE_FAITHFUL",
                "USE_INVERSE_SQUARE",
                "USE_SIMPSON",
                "USE_BEZIER",
                "USE_TOON",
                "USE_WAVE_LIGHTS",
                "USE_LINE_POLYLINE",
                "USE_MAP_SHADOWS"
            ]
        );
        // Without surfaces nothing of the shading is compiled in; without blending or glow, no
        // wave lights.
        let v = WaveVariant::of(
            &waves[..1],
            &[],
            &[toon],
            &[light],
            true,
            false,
            (true, true),
            true,
            true,
            1.0,
            false,
        );
        assert_eq!(names(v), ["USE_SPHERE", "USE_TONE_FAITHFUL", "USE_FAITHFUL"]);
        // α·I in one multiplication unless some product can overflow; a beam's bulbs only where
        // their α is not 0 (a NaN counts as not 0, and takes the wide road).
        let of_waves = |waves: &[layout::GpuWave], curves: &[layout::GpuCurve], exposure: f32| {
            names(WaveVariant::of(
                waves,
                curves,
                &[],
                &[],
                false,
                false,
                (false, false),
                false,
                true,
                exposure,
                false,
            ))
        };
        let mut beam = wave(layout::WAVE_BEAM, layout::FALLOFF_FAITHFUL);
        beam.p0[3] = 4.0;
        beam.p1[3] = 4.0;
        beam.p2 = [5.0, 8.0, 0.0, 0.0];
        assert_eq!(
            of_waves(&[beam], &[], 1.0),
            ["USE_BEAM", "USE_TONE_FAITHFUL", "USE_FAITHFUL", "USE_BEAM_HEAD"]
        );
        beam.p2[2] = f32::NAN;
        assert!(of_waves(&[beam], &[], 1.0).contains(&"USE_BEAM_MUZZLE"));
        assert!(of_waves(&[beam], &[], 1.0).contains(&"USE_WIDE_SCALE"));
        beam.p2[2] = 0.0;
        for (w, c, exposure) in [
            (layout::GpuWave { p1: [0.0, 0.0, 1.0, 2.0e8], ..beam }, curve, 1.0),
            (layout::GpuWave { p0: [0.0, 0.0, 0.0, f32::NAN], ..beam }, curve, 1.0),
            (beam, layout::GpuCurve { alpha: 1.5, ..curve }, 1.0),
            (beam, curve, 1.5),
        ] {
            assert!(of_waves(&[w], &[c], exposure).contains(&"USE_WIDE_SCALE"), "{w:?} {c:?} {exposure}");
        }
        // A curve wave's p0 holds its curve's index, not an α.
        let curve_wave = layout::GpuWave { p0: [3.0e9, 0.0, 0.0, 0.0], ..wave(layout::WAVE_CURVE, 0) };
        assert!(!of_waves(&[beam, curve_wave], &[curve], 1.0).contains(&"USE_WIDE_SCALE"));
        // Samples choose the entry point, not an override: the same parts, another pipeline.
        let aa = v.with_samples(true);
        assert!(aa.samples() && !v.samples());
        assert_eq!(names(aa), names(v));
        assert_ne!(aa, v);
        assert!(!WaveVariant::UBER.samples());
        // So does the 8-bit output: another pipeline, independent of the samples bit.
        let png = aa.with_srgb8(true);
        assert!(png.srgb8() && png.samples() && !aa.srgb8() && !WaveVariant::UBER.srgb8());
        assert_eq!(names(png), names(v));
        assert_eq!(png.with_srgb8(false), aa);
        toon.wave_blend = 0.0;
        let v =
            WaveVariant::of(&[], &[], &[toon], &[light], false, true, (true, false), true, true, 1.0, false);
        assert_eq!(
            names(v),
            ["USE_SURFACES", "USE_AREA", "USE_TONE_FAITHFUL", "USE_TOON", "USE_PLANE_SHADOWS"]
        );
    }

    /// wave.wgsl's `srgb8_code` (the 8-bit output) from its source.
    fn srgb8_source() -> &'static str {
        let wave = shaders::WAVE;
        let start =
            wave.find("// hadou_math::shade::linear_to_srgb8 exactly").expect("srgb8_code in wave.wgsl");
        let end = wave.find("// Whether `v` is neither NaN").expect("is_finite_f32 after it");
        &wave[start..end]
    }

    /// The values the 8-bit tests encode: every threshold of `linear_to_srgb8` and the three
    /// floats on each side of it, values spread over every octave from 10⁻¹² to 2, and the edges
    /// (zeros, negatives, 1, NaN, infinities, the largest float, a subnormal).
    fn srgb8_probes() -> Vec<f32> {
        let next = hadou_math::shade::srgb8_encoder().next_thresholds();
        let mut xs = Vec::new();
        for t in next.iter().filter(|t| t.is_finite()) {
            let (mut lo, mut hi) = (*t, *t);
            xs.push(*t);
            for _ in 0..3 {
                lo = lo.next_down();
                hi = hi.next_up();
                xs.extend([lo, hi]);
            }
        }
        let n = 20_000;
        xs.extend((0..n).map(|i| (1e-12f64 * (2e12f64).powf(i as f64 / n as f64)) as f32));
        xs.extend([0.0, -0.0, -1.0, 1.0, f32::NAN, f32::INFINITY, f32::NEG_INFINITY, f32::MAX, 1e-40]);
        xs
    }

    /// The first guess of `srgb8_code`, in f32 as the shader computes it, is within one code of
    /// `linear_to_srgb8` wherever a code changes and everywhere between: what lets one comparison
    /// on each side settle the code.
    #[test]
    fn srgb8_guess_is_within_one_code() {
        let source = srgb8_source();
        let fit_line = source.lines().find(|l| l.starts_with("const SRGB8_FIT")).expect("SRGB8_FIT");
        let inside =
            &fit_line[fit_line.find("vec4<f32>(").expect("a vec4") + 10..fit_line.rfind(')').expect(")")];
        let fit: Vec<f32> = inside.split(',').map(|w| w.trim().parse().expect("a number")).collect();
        assert_eq!(fit.len(), 4);
        let mut worst = 0.0f64;
        for x in srgb8_probes() {
            let v = if x > 0.0 { x.min(1.0) } else { 0.0 };
            let (s1, s2) = (v.sqrt(), v.sqrt().sqrt());
            let s3 = s2.sqrt();
            let guess = if v <= 0.003_130_8 {
                3294.6 * v
            } else {
                fit[0] * s1 + fit[1] * s2 + fit[2] * s3 + fit[3] * v
            };
            let rounded = (guess + 0.5).clamp(0.0, 255.0).floor();
            let code = f32::from(hadou_math::shade::linear_to_srgb8(x));
            assert!((rounded - code).abs() <= 1.0, "{x:e}: guess {guess} against code {code}");
            let exact = 255.0 * f64::from(hadou_math::shade::linear_to_srgb(v));
            worst = worst.max((f64::from(guess) - exact).abs());
        }
        // The margin: the guess is far closer than the one code the comparisons can correct.
        assert!(worst < 0.05, "the fit is {worst} codes off");
    }

    /// `srgb8_code` on the GPU gives `linear_to_srgb8`'s code for every probe, bit for bit.
    #[test]
    fn srgb8_code_is_linear_to_srgb8() {
        let Some((ctx, _gpu)) = crate::device::context_or_skip("8-bit codes") else { return };
        let source = format!(
            "@group(0) @binding(2) var<storage, read> srgb8_next: array<vec4<f32>, 64>;\n\
             @group(0) @binding(0) var<storage, read> xs: array<f32>;\n\
             @group(0) @binding(1) var<storage, read_write> results: array<f32>;\n{}\n\
             @compute @workgroup_size(64, 1, 1)\n\
             fn twin_main(@builtin(global_invocation_id) id: vec3<u32>) {{\n\
                 if (id.x < arrayLength(&xs)) {{ results[id.x] = f32(srgb8_code(xs[id.x])); }}\n\
             }}\n",
            srgb8_source()
        );
        let xs = srgb8_probes();
        let next = hadou_math::shade::srgb8_encoder().next_thresholds();
        let inputs: [(u32, &[u8]); 2] = [(0, bytemuck::cast_slice(&xs)), (2, bytemuck::cast_slice(next))];
        let got = crate::twin_kernel::run(&ctx, "8-bit codes", &source, &inputs, xs.len())
            .expect("GPU 8-bit codes");
        for (x, g) in xs.iter().zip(&got) {
            assert_eq!(
                *g,
                f32::from(hadou_math::shade::linear_to_srgb8(*x)),
                "code of {x:e} ({:#x})",
                x.to_bits()
            );
        }
    }
}
