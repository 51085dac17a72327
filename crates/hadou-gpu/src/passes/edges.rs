//! The edge pass (`shaders/edges.wgsl`): closed outlines where objects meet. A full-screen
//! triangle over the tile reads the raster pass's G-buffer and writes the attributes target the
//! plane shadows and the wave pass read: the raster pass's words with the hull reach cleared, and
//! on the pixels within another object's outline width of its visible edge, in front of their own
//! surface, that object's outline material marked as a hull (`hadou_math::outline`, 000 §2.3;
//! hadou-cpu's `edges.rs` is the twin). The search stops at the tile's edges.

use super::setup::{self, cleared_color, color_target, triangles, Binding, Kind, Stages};
use crate::device::GpuContext;
use crate::formats::SCENE_FORMAT;
use crate::shaders;
use hadou_scene::RenderError;

const FS: wgpu::ShaderStages = wgpu::ShaderStages::FRAGMENT;

/// The bindings of edges.wgsl.
pub(crate) const BINDINGS: [Binding; 4] = [
    Binding::new(0, "frame", Kind::Uniform, FS),
    Binding::new(1, "materials", Kind::Storage, FS),
    Binding::new(2, "scene_texels", Kind::UintTexture, FS),
    Binding::new(3, "attribute_texels", Kind::UintTexture, FS),
];

/// What the edge pass reads, in the order of [`BINDINGS`].
pub(crate) struct EdgeInputs<'a> {
    /// The tile's `layout::FrameUniforms` (`outline_reach` set).
    pub(crate) uniforms: &'a wgpu::Buffer,
    /// The frame's `layout::GpuMaterial`s.
    pub(crate) materials: &'a wgpu::Buffer,
    /// G-buffer target 0 (normal and eye distance).
    pub(crate) surface: &'a wgpu::TextureView,
    /// G-buffer target 1 as the raster pass wrote it.
    pub(crate) attributes: &'a wgpu::TextureView,
}

/// The edge pass's pipeline and bind group layout.
pub(crate) struct EdgePass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl EdgePass {
    /// Compiles edges.wgsl and builds the pipeline.
    pub(crate) fn new(ctx: &GpuContext) -> Result<Self, RenderError> {
        let module = setup::compile_module(ctx, "edges", &shaders::compose(shaders::EDGES_PARTS))?;
        ctx.scoped("building the edge pipeline", || {
            let d = &ctx.device;
            let layout = setup::bind_group_layout(d, "edges", &BINDINGS);
            let targets = [color_target(SCENE_FORMAT)];
            let stages = Stages {
                module: &module,
                vertex: "vs_edges",
                buffers: &[],
                fragment: Some(("fs_edges", &targets)),
                constants: &[],
            };
            let pipeline = setup::render_pipeline(d, "edges", &layout, &stages, triangles(None), None);
            Self { pipeline, layout }
        })
    }

    /// The bind group of `inputs`.
    pub(crate) fn bind_group(&self, device: &wgpu::Device, inputs: &EdgeInputs<'_>) -> wgpu::BindGroup {
        let resources = vec![
            inputs.uniforms.as_entire_binding(),
            inputs.materials.as_entire_binding(),
            wgpu::BindingResource::TextureView(inputs.surface),
            wgpu::BindingResource::TextureView(inputs.attributes),
        ];
        setup::bind_group(device, "edges", &self.layout, &BINDINGS, resources)
    }

    /// Records the pass over a `size` viewport at the origin of `target` (a [`SCENE_FORMAT`]
    /// view, not one the bind group reads).
    pub(crate) fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        size: [u32; 2],
        bind_group: &wgpu::BindGroup,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("edges"),
            color_attachments: &[cleared_color(target)],
            depth_stencil_attachment: None,
            timestamp_writes,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_viewport(0.0, 0.0, size[0] as f32, size[1] as f32, 0.0, 1.0);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}
