//! The present pass: the frame drawn straight into one full-frame texture a window can show,
//! without reading anything back to the CPU ([`crate::GpuBackend::render_to_texture`]).
//!
//! Every tile is drawn as for a read-back (raster, plane shadows, soft-shadow gather, wave), then
//! one small render pass (`shaders/present.wgsl`: a full-screen triangle, the viewport set to the
//! tile's rectangle) copies the tile's colour from the wave pass's output buffer into the texture.
//! The texture is [`PRESENT_FORMAT`] (`Rgba8UnormSrgb`): the buffer holds linear mapped colour,
//! and the format clamps and encodes it to sRGB in hardware, so its bytes are
//! `hadou_math::shade::linear_to_srgb8` of the read-back image's colour (to within one code: the
//! hardware's encoding is not required to be exact), alpha stored as it is. Rust twin: `copy_tile`
//! (render.rs) followed by hadou's `output::srgb8`.
//!
//! Nothing here waits for the GPU: the tiles are submitted and the texture's view returned; a
//! window drawing the texture on the same queue sees the finished frame, as queue order
//! guarantees.

use crate::device::GpuContext;
use crate::pipelines::compile_module;
use crate::render::Renderer;
use crate::shaders;
use crate::timing::{PresentTimer, PresentTiming, PRESENT_PASSES_PER_TILE};
use hadou_scene::{Frame, RenderError};

/// The format of the texture [`crate::GpuBackend::render_to_texture`] draws into: 8-bit sRGB
/// with alpha, the format egui and most window surfaces use for colour images.
pub const PRESENT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// The usages of that texture: sampled by the window's renderer, drawn by the present pass,
/// copied from (screenshots, tests).
pub const PRESENT_USAGE: wgpu::TextureUsages = wgpu::TextureUsages::TEXTURE_BINDING
    .union(wgpu::TextureUsages::RENDER_ATTACHMENT)
    .union(wgpu::TextureUsages::COPY_SRC);

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
struct PresentTarget {
    size: [u32; 2],
    texture: wgpu::Texture,
    view: wgpu::TextureView,
}

/// The present pipeline and its texture.
pub(crate) struct Present {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    target: Option<PresentTarget>,
    /// The frames' timestamps, on a device with `TIMESTAMP_QUERY`.
    timer: Option<PresentTimer>,
    /// `render_to_texture` calls so far.
    serial: u64,
}

impl Present {
    /// Compiles present.wgsl and builds its pipeline.
    pub(crate) fn new(ctx: &GpuContext) -> Result<Self, RenderError> {
        let module = compile_module(ctx, "present", &shaders::compose(shaders::PRESENT_PARTS))?;
        ctx.scoped("building the present pipeline", || {
            let d = &ctx.device;
            let fs = wgpu::ShaderStages::FRAGMENT;
            // Keep in sync with the bindings of present.wgsl.
            let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("present"),
                entries: &[
                    wgpu::BindGroupLayoutEntry {
                        binding: 0,
                        visibility: fs,
                        ty: wgpu::BindingType::Buffer {
                            ty: wgpu::BufferBindingType::Uniform,
                            has_dynamic_offset: false,
                            min_binding_size: None,
                        },
                        count: None,
                    },
                    wgpu::BindGroupLayoutEntry {
                        binding: 1,
                        visibility: fs,
                        ty: wgpu::BindingType::Buffer {
                            ty: wgpu::BufferBindingType::Storage { read_only: true },
                            has_dynamic_offset: false,
                            min_binding_size: None,
                        },
                        count: None,
                    },
                ],
            });
            let pipeline_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("present"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
            let pipeline = d.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("present"),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_present"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_present"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: PRESENT_FORMAT,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            });
            let timer =
                ctx.features.contains(wgpu::Features::TIMESTAMP_QUERY).then(|| PresentTimer::new(&ctx.queue));
            Self { pipeline, layout, target: None, timer, serial: 0 }
        })
    }

    /// Makes the texture `size`; whether it was (re)created.
    fn ensure_target(&mut self, device: &wgpu::Device, size: [u32; 2]) -> bool {
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

impl Renderer {
    /// See [`crate::GpuBackend::render_to_texture`]. On a device with `TIMESTAMP_QUERY`, a frame
    /// without an `[area_light]` writes timestamps at every pass (the shadow maps, then per tile
    /// its passes and the present pass), resolved and copied into a staging buffer that is mapped
    /// asynchronously ([`PresentTimer`]): see [`Renderer::last_present_timing`]. Frames with an
    /// `[area_light]` are not timed (their whole-image soft-shadow passes run before the tiles,
    /// in the frame's preparation), nor is a frame finding every staging buffer still in flight.
    pub(crate) fn render_to_texture(&mut self, frame: &Frame) -> Result<PresentedFrame<'_>, RenderError> {
        let size = [frame.width, frame.height];
        let max = self.ctx.limits.max_texture_dimension_2d;
        if size[0] > max || size[1] > max {
            return Err(RenderError::Device(format!(
                "a {}×{} frame does not fit this device's largest texture ({max}²) for drawing to a window",
                size[0], size[1]
            )));
        }
        if self.present.is_none() {
            self.present = Some(Present::new(&self.ctx)?);
        }
        let timed = self.present.as_ref().is_some_and(|p| p.timer.is_some()) && frame.area_light.is_none();
        // When timed, the shadow maps are submitted below, with their timestamps.
        let prepared = self.prepare_frame(frame, 0..frame.height, !timed)?;
        let present = self.present.as_mut().expect("made above");
        present.serial += 1;
        let serial = present.serial;
        let recreated = self
            .ctx
            .scoped("creating the window texture", || present.ensure_target(&self.ctx.device, size))?;
        let queries = 2 * (PRESENT_PASSES_PER_TILE * prepared.tiles.len() as u32 + prepared.map_pass_count());
        let timed_frame = match present.timer.as_mut().filter(|_| timed) {
            Some(timer) => {
                self.ctx.scoped("creating timestamp queries", || timer.begin(&self.ctx.device, queries))?
            }
            None => None,
        };
        let present = self.present.as_ref().expect("made above");
        let target = present.target.as_ref().expect("made above");
        let tiles = self.targets.as_ref().expect("targets are created in prepare");
        let queries = self.ctx.scoped("drawing the frame into the window texture", || {
            let mut q = timed_frame.as_ref().map(|f| f.queries());
            if timed {
                self.submit_shadow_maps(frame, &prepared, q.as_mut());
            }
            let bind_group = self.ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("present"),
                layout: &present.layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: tiles.uniforms.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: tiles.output.as_entire_binding() },
                ],
            });
            for &tile in &prepared.tiles {
                // Writes the tile's uniforms, which the present pass reads too (tile origin and
                // size); submitted before the next tile rewrites them.
                let mut enc = self.encode_tile(frame, &prepared, tile, false, q.as_mut());
                let ([x, y], [w, h]) = tile;
                {
                    let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                        label: Some("present"),
                        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                            view: &target.view,
                            depth_slice: None,
                            resolve_target: None,
                            // Every pixel of the frame is written by exactly one tile's pass.
                            ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
                        })],
                        depth_stencil_attachment: None,
                        // In the tile's group of queries: its span ends with this pass.
                        timestamp_writes: q.as_mut().and_then(|q| q.render("present")),
                        occlusion_query_set: None,
                        multiview_mask: None,
                    });
                    pass.set_viewport(x as f32, y as f32, w as f32, h as f32, 0.0, 1.0);
                    pass.set_scissor_rect(x, y, w, h);
                    pass.set_pipeline(&present.pipeline);
                    pass.set_bind_group(0, &bind_group, &[]);
                    pass.draw(0..3, 0..1);
                }
                self.ctx.queue.submit([enc.finish()]);
            }
            q
        })?;
        if let (Some(f), Some(q)) = (&timed_frame, queries) {
            let (ctx, present) = (&self.ctx, self.present.as_mut().expect("made above"));
            if let Some(timer) = present.timer.as_mut() {
                ctx.scoped("reading the frame's timestamps back", || {
                    timer.finish(&ctx.device, &ctx.queue, f, q, serial)
                })?;
            }
        }
        let target = self.present.as_ref().and_then(|p| p.target.as_ref()).expect("made above");
        Ok(PresentedFrame { texture: &target.texture, view: &target.view, size, recreated, serial })
    }

    /// See [`crate::GpuBackend::last_present_timing`].
    pub(crate) fn last_present_timing(&mut self) -> Option<PresentTiming> {
        let timer = self.present.as_mut()?.timer.as_mut()?;
        timer.latest(&self.ctx.device)
    }
}
