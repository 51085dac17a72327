//! The present pass (`shaders/present.wgsl`): a full-screen triangle, the viewport set to a tile's
//! rectangle, copying the tile's colour from the wave pass's output buffer into a
//! [`PRESENT_FORMAT`] texture a window can show, without reading anything back to the CPU
//! ([`crate::GpuBackend::render_to_texture`]). The buffer holds linear mapped colour, and the
//! format clamps and encodes it to sRGB in hardware, so the texture's bytes are
//! `hadou_math::shade::linear_to_srgb8` of the read-back image's colour (to within one code: the
//! hardware's encoding is not required to be exact), alpha stored as it is. Rust twin:
//! `copy_tile` (render.rs) followed by hadou's `output::srgb8`.

use super::setup::{self, color_target, triangles, Binding, Kind, Stages};
use crate::device::GpuContext;
use crate::formats::{PRESENT_FORMAT, PRESENT_USAGE};
use crate::shaders;
use crate::timing::PresentTimer;
use hadou_scene::RenderError;

const FS: wgpu::ShaderStages = wgpu::ShaderStages::FRAGMENT;

/// The bindings of present.wgsl.
pub(crate) const BINDINGS: [Binding; 2] =
    [Binding::new(0, "frame", Kind::Uniform, FS), Binding::new(1, "out_buf", Kind::Storage, FS)];

/// The frame [`crate::GpuBackend::render_to_texture`] drew: its texture (submitted, possibly still
/// being drawn by the GPU; anything later on the same queue sees it finished).
#[derive(Clone, Copy, Debug)]
pub struct PresentedFrame<'a> {
    /// The full-frame texture, `size[0] × size[1]`, [`PRESENT_FORMAT`], [`PRESENT_USAGE`].
    pub texture: &'a wgpu::Texture,
    /// A view of all of it (what `egui_wgpu::Renderer::register_native_texture` takes).
    pub view: &'a wgpu::TextureView,
    /// Width and height in pixels: the frame's.
    pub size: [u32; 2],
    /// Whether the texture is new with this frame (the first frame, or the size changed): a
    /// window that registered the previous texture's view must register this one instead. While
    /// the size holds, the same texture is drawn over each frame.
    pub recreated: bool,
    /// Which frame this is: 1 for the backend's first `render_to_texture`, one more each call
    /// (the [`crate::PresentTiming::serial`] of its GPU time).
    pub serial: u64,
}

/// The full-frame texture, kept while the frame size holds.
pub(crate) struct PresentTarget {
    size: [u32; 2],
    pub(crate) texture: wgpu::Texture,
    pub(crate) view: wgpu::TextureView,
}

/// The present pipeline and its bind group layout.
pub(crate) struct PresentPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl PresentPass {
    /// Compiles present.wgsl and builds its pipeline.
    pub(crate) fn new(ctx: &GpuContext) -> Result<Self, RenderError> {
        let module = setup::compile_module(ctx, "present", &shaders::compose(shaders::PRESENT_PARTS))?;
        ctx.scoped("building the present pipeline", || {
            let d = &ctx.device;
            let layout = setup::bind_group_layout(d, "present", &BINDINGS);
            let targets = [color_target(PRESENT_FORMAT)];
            let stages = Stages {
                module: &module,
                vertex: "vs_present",
                buffers: &[],
                fragment: Some(("fs_present", &targets)),
                constants: &[],
            };
            let pipeline = setup::render_pipeline(d, "present", &layout, &stages, triangles(None), None);
            Self { pipeline, layout }
        })
    }

    /// The bind group reading the tile's `uniforms` (its origin and size) and the wave pass's
    /// `output`.
    pub(crate) fn bind_group(
        &self,
        device: &wgpu::Device,
        uniforms: &wgpu::Buffer,
        output: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        let resources = vec![uniforms.as_entire_binding(), output.as_entire_binding()];
        setup::bind_group(device, "present", &self.layout, &BINDINGS, resources)
    }

    /// Records the copy of one tile (`origin`, `size` in the frame) into `target`, a
    /// [`PRESENT_FORMAT`] view of the whole frame; the rest of `target` is kept.
    pub(crate) fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        (origin, size): ([u32; 2], [u32; 2]),
        bind_group: &wgpu::BindGroup,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let ([x, y], [w, h]) = (origin, size);
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("present"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                // Every pixel of the frame is written by exactly one tile's pass.
                ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_viewport(x as f32, y as f32, w as f32, h as f32, 0.0, 1.0);
        pass.set_scissor_rect(x, y, w, h);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// What drawing into a window needs between frames: the present pass, the full-frame texture,
/// the frames' timestamps (on a device with `TIMESTAMP_QUERY`) and the frame count.
pub(crate) struct Presenter {
    pub(crate) pass: PresentPass,
    pub(crate) target: Option<PresentTarget>,
    pub(crate) timer: Option<PresentTimer>,
    /// `render_to_texture` calls so far.
    pub(crate) serial: u64,
}

impl Presenter {
    /// Builds the present pass (and the timer where the device has timestamps).
    pub(crate) fn new(ctx: &GpuContext) -> Result<Self, RenderError> {
        let pass = PresentPass::new(ctx)?;
        let timer =
            ctx.features.contains(wgpu::Features::TIMESTAMP_QUERY).then(|| PresentTimer::new(&ctx.queue));
        Ok(Self { pass, target: None, timer, serial: 0 })
    }

    /// Makes the texture `size`; whether it was (re)created.
    pub(crate) fn ensure_target(&mut self, device: &wgpu::Device, size: [u32; 2]) -> bool {
        if self.target.as_ref().is_some_and(|t| t.size == size) {
            return false;
        }
        self.target = None; // free the old one first
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("hadou frame"),
            size: wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: PRESENT_FORMAT,
            usage: PRESENT_USAGE,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        self.target = Some(PresentTarget { size, texture, view });
        true
    }
}
