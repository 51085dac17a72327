//! The wave overlay (`shaders/wave_overlay.wgsl`): the waves' light, exposure · Σ rgb·a·I, drawn
//! into a colour target the caller owns (a game engine's HDR view target, a page's canvas)
//! against that caller's depth buffer, added to what is there (or replacing it), with no colour
//! mapping: the same light the wave pass adds to the scene colour (`wave_energy.wgsl`), for a
//! renderer that shades its own surfaces. One full-screen triangle over a viewport the frame's
//! size; specialised per frame like the wave pass ([`WaveVariant`]), a pipeline per variant,
//! colour format and blend.

use super::setup::{self, triangles, Binding, Kind, Stages};
use super::wave::WaveVariant;
use crate::device::GpuContext;
use crate::shaders;
use hadou_scene::RenderError;
use std::collections::HashMap;

const FS: wgpu::ShaderStages = wgpu::ShaderStages::FRAGMENT;

/// The bindings of the wave overlay module (wave_energy.wgsl 0–1, wave_overlay.wgsl 2–3,
/// curve.wgsl 5–7).
pub(crate) const BINDINGS: [Binding; 7] = [
    Binding::new(0, "frame_uniforms", Kind::Uniform, FS),
    Binding::new(1, "waves", Kind::Storage, FS),
    Binding::new(2, "depth_texels", Kind::Depth, FS),
    Binding::new(3, "overlay", Kind::Uniform, FS),
    Binding::new(5, "curves", Kind::Storage, FS),
    Binding::new(6, "curve_vec4", Kind::Storage, FS),
    Binding::new(7, "curve_f32", Kind::Storage, FS),
];

/// [`BINDINGS`] for a multisampled depth buffer ([`source`]`(true)`).
pub(crate) const BINDINGS_MULTISAMPLED: [Binding; 7] = [
    Binding::new(0, "frame_uniforms", Kind::Uniform, FS),
    Binding::new(1, "waves", Kind::Storage, FS),
    Binding::new(2, "depth_texels", Kind::DepthMultisampled, FS),
    Binding::new(3, "overlay", Kind::Uniform, FS),
    Binding::new(5, "curves", Kind::Storage, FS),
    Binding::new(6, "curve_vec4", Kind::Storage, FS),
    Binding::new(7, "curve_f32", Kind::Storage, FS),
];

/// The overlay module's WGSL, reading a depth buffer of one sample per pixel or, when
/// `multisampled`, its first sample (`textureLoad(…, 0)` is then sample 0: the depth a
/// multisampled engine's opaque pass wrote at the pixel's first sample position); with the
/// attenuated march only when `attenuation` (`shaders::FEATURES`).
pub(crate) fn source(multisampled: bool, attenuation: bool) -> String {
    let features: &[&str] = if attenuation { &["ATTENUATION"] } else { &[] };
    let s = shaders::compose_with(shaders::WAVE_OVERLAY_PARTS, features);
    if multisampled {
        s.replace("var depth_texels: texture_2d<f32>;", "var depth_texels: texture_multisampled_2d<f32>;")
    } else {
        s
    }
}

/// The overrides of the wave overlay module: the wave variant's wave kinds, falloffs and curve
/// parts (the rest of [`WaveVariant::NAMES`] belongs to the wave pass's surfaces).
pub(crate) const OVERRIDES: [&str; 17] = [
    "USE_SPHERE",
    "USE_CYLINDER",
    "USE_CAPSULE",
    "USE_BEAM",
    "USE_CURVE",
    "USE_FAITHFUL",
    "USE_INVERSE_SQUARE",
    "USE_WIDE_SCALE",
    "USE_BEAM_HEAD",
    "USE_BEAM_MUZZLE",
    "USE_CHORD",
    "USE_SIMPSON",
    "USE_NEAREST",
    "USE_HELIX",
    "USE_TRIG",
    "USE_BEZIER",
    "USE_BSPLINE",
];

/// What the overlay reads, in the order of [`BINDINGS`].
pub(crate) struct OverlayInputs<'a> {
    /// The frame's `layout::FrameUniforms` (the whole frame as one tile).
    pub(crate) uniforms: &'a wgpu::Buffer,
    /// The frame's `layout::GpuWave`s.
    pub(crate) waves: &'a wgpu::Buffer,
    /// The caller's depth buffer (a `Depth32Float`-style depth texture view).
    pub(crate) depth: &'a wgpu::TextureView,
    /// `layout::OverlayUniforms`: how to read `depth`.
    pub(crate) overlay: &'a wgpu::Buffer,
    /// The curve buffers (`layout::CurveBuffers`: curves, vec4s, scalars).
    pub(crate) curves: [&'a wgpu::Buffer; 3],
}

/// The overlay's modules (by depth samples, one or several, and attenuation; each built on first
/// use), bind group layouts (by depth samples) and pipelines.
pub(crate) struct WaveOverlayPass {
    modules: HashMap<(bool, bool), wgpu::ShaderModule>,
    layouts: HashMap<bool, wgpu::BindGroupLayout>,
    pipelines: HashMap<
        (WaveVariant, wgpu::TextureFormat, bool, bool),
        (wgpu::RenderPipeline, wgpu::BindGroupLayout),
    >,
}

impl WaveOverlayPass {
    /// An overlay with nothing built yet: modules, layouts and pipelines are built on first use.
    pub(crate) fn new() -> Self {
        Self { modules: HashMap::new(), layouts: HashMap::new(), pipelines: HashMap::new() }
    }

    /// The module for a depth buffer of several samples per pixel or one, with or without the
    /// attenuation, and the bind group layout of that kind of depth buffer, built on first use.
    fn module(
        &mut self,
        ctx: &GpuContext,
        multisampled: bool,
        attenuation: bool,
    ) -> Result<(&wgpu::ShaderModule, &wgpu::BindGroupLayout), RenderError> {
        use std::collections::hash_map::Entry;
        if let Entry::Vacant(slot) = self.modules.entry((multisampled, attenuation)) {
            slot.insert(setup::compile_module(ctx, "wave overlay", &source(multisampled, attenuation))?);
        }
        if let Entry::Vacant(slot) = self.layouts.entry(multisampled) {
            let bindings: &[Binding] = if multisampled { &BINDINGS_MULTISAMPLED } else { &BINDINGS };
            slot.insert(ctx.scoped("building the wave overlay's layout", || {
                setup::bind_group_layout(&ctx.device, "wave overlay", bindings)
            })?);
        }
        Ok((&self.modules[&(multisampled, attenuation)], &self.layouts[&multisampled]))
    }

    /// The pipeline drawing `variant`'s waves into a `format` target, adding to it when
    /// `additive`, else replacing it, against a depth buffer of several samples per pixel when
    /// `multisampled`; built on first use and kept. Also the bind group layout it reads.
    pub(crate) fn pipeline(
        &mut self,
        ctx: &GpuContext,
        variant: WaveVariant,
        format: wgpu::TextureFormat,
        additive: bool,
        multisampled: bool,
    ) -> Result<(wgpu::RenderPipeline, wgpu::BindGroupLayout), RenderError> {
        let key = (variant, format, additive, multisampled);
        if let Some(p) = self.pipelines.get(&key) {
            return Ok(p.clone());
        }
        let constants: Vec<(&str, f64)> =
            OVERRIDES.iter().map(|&n| (n, if variant.has(n) { 1.0 } else { 0.0 })).collect();
        let blend = additive.then_some(wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::One,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Add,
            },
            alpha: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::Zero,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Add,
            },
        });
        let (module, layout) = self.module(ctx, multisampled, variant.attenuation())?;
        let pipeline = ctx.scoped("building the wave overlay pipeline", || {
            let targets =
                [Some(wgpu::ColorTargetState { format, blend, write_mask: wgpu::ColorWrites::ALL })];
            let stages = Stages {
                module,
                vertex: "vs_overlay",
                buffers: &[],
                fragment: Some(("fs_overlay", &targets)),
                constants: &constants,
            };
            setup::render_pipeline(&ctx.device, "wave overlay", layout, &stages, triangles(None), None)
        })?;
        let built = (pipeline, layout.clone());
        self.pipelines.insert(key, built.clone());
        Ok(built)
    }

    /// The bind group of `inputs` (`multisampled`: for a depth buffer of several samples per
    /// pixel) in `layout`, the one [`Self::pipeline`] gave with the pipeline.
    pub(crate) fn bind_group(
        &self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        inputs: &OverlayInputs<'_>,
        multisampled: bool,
    ) -> wgpu::BindGroup {
        let resources = vec![
            inputs.uniforms.as_entire_binding(),
            inputs.waves.as_entire_binding(),
            wgpu::BindingResource::TextureView(inputs.depth),
            inputs.overlay.as_entire_binding(),
            inputs.curves[0].as_entire_binding(),
            inputs.curves[1].as_entire_binding(),
            inputs.curves[2].as_entire_binding(),
        ];
        let bindings: &[Binding] = if multisampled { &BINDINGS_MULTISAMPLED } else { &BINDINGS };
        setup::bind_group(device, "wave overlay", layout, bindings, resources)
    }

    /// Records the overlay into `target` over a `size` viewport at its origin; the target is
    /// loaded, not cleared.
    pub(crate) fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        pipeline: &wgpu::RenderPipeline,
        target: &wgpu::TextureView,
        origin: [u32; 2],
        size: [u32; 2],
        bind_group: &wgpu::BindGroup,
    ) {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("wave overlay"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_viewport(origin[0] as f32, origin[1] as f32, size[0] as f32, size[1] as f32, 0.0, 1.0);
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}
