//! The raster pass (`shaders/raster.wgsl`): every object's triangles, then the outline hulls
//! (000 §2.3, `vs_hull`, front faces culled), depth-tested into the G-buffer the later passes read
//! ([`SCENE_FORMAT`]: normal and eye distance; texture coordinates, vertex colour and material).

use super::setup::Stages;
use super::setup::{
    self, cleared_color, cleared_depth, color_target, depth_test, triangles, vertex_layout, Binding, Draw,
    Kind, VERTEX_ATTRIBUTES,
};
use crate::device::GpuContext;
use crate::formats::{DEPTH_FORMAT, SCENE_FORMAT};
use crate::meshes::MeshCache;
use crate::shaders;
use hadou_scene::{Frame, RenderError};

const VS_FS: wgpu::ShaderStages = wgpu::ShaderStages::VERTEX.union(wgpu::ShaderStages::FRAGMENT);

/// The bindings of raster.wgsl.
pub(crate) const BINDINGS: [Binding; 3] = [
    Binding::new(0, "frame", Kind::Uniform, VS_FS),
    Binding::new(1, "objects", Kind::Storage, VS_FS),
    Binding::new(2, "materials", Kind::Storage, VS_FS),
];

/// What the raster pass reads, in the order of [`BINDINGS`].
pub(crate) struct RasterInputs<'a> {
    /// The tile's `layout::FrameUniforms`.
    pub(crate) uniforms: &'a wgpu::Buffer,
    /// The frame's `layout::GpuObject`s.
    pub(crate) objects: &'a wgpu::Buffer,
    /// The frame's `layout::GpuMaterial`s.
    pub(crate) materials: &'a wgpu::Buffer,
}

/// Where the raster pass draws: the two G-buffer targets ([`SCENE_FORMAT`]) and a depth buffer
/// ([`DEPTH_FORMAT`]), all at least the viewport's size.
pub(crate) struct GBuffer<'a> {
    /// Target 0: normal and eye distance.
    pub(crate) surface: &'a wgpu::TextureView,
    /// Target 1: texture coordinates, vertex colour, material.
    pub(crate) attributes: &'a wgpu::TextureView,
    /// The depth buffer (cleared, not stored).
    pub(crate) depth: &'a wgpu::TextureView,
}

/// The raster pass's pipelines and bind group layout.
pub(crate) struct RasterPass {
    raster: wgpu::RenderPipeline,
    /// The outline hulls: `vs_hull`, front faces culled (000 §2.3).
    hull: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl RasterPass {
    /// Compiles raster.wgsl and builds the pipelines.
    pub(crate) fn new(ctx: &GpuContext) -> Result<Self, RenderError> {
        let module = setup::compile_module(ctx, "raster", &shaders::compose(shaders::RASTER_PARTS))?;
        ctx.scoped("building the raster pipelines", || {
            let d = &ctx.device;
            let layout = setup::bind_group_layout(d, "raster", &BINDINGS);
            let targets = [color_target(SCENE_FORMAT), color_target(SCENE_FORMAT)];
            let buffers = [vertex_layout(&VERTEX_ATTRIBUTES)];
            let pipeline = |label: &str, vs: &str, cull_mode: Option<wgpu::Face>| {
                let stages = Stages {
                    module: &module,
                    vertex: vs,
                    buffers: &buffers,
                    fragment: Some(("fs_main", &targets)),
                    constants: &[],
                };
                let depth = depth_test(DEPTH_FORMAT, wgpu::CompareFunction::Less);
                setup::render_pipeline(d, label, &layout, &stages, triangles(cull_mode), Some(depth))
            };
            // No culling: open meshes (planes) are visible from both sides, as on the CPU.
            let raster = pipeline("raster", "vs_main", None);
            // Hulls show only their back faces (counter-clockwise front faces, as every mesh).
            let hull = pipeline("outline hull", "vs_hull", Some(wgpu::Face::Front));
            Self { raster, hull, layout }
        })
    }

    /// The bind group of `inputs`.
    pub(crate) fn bind_group(&self, device: &wgpu::Device, inputs: &RasterInputs<'_>) -> wgpu::BindGroup {
        let resources = vec![
            inputs.uniforms.as_entire_binding(),
            inputs.objects.as_entire_binding(),
            inputs.materials.as_entire_binding(),
        ];
        setup::bind_group(device, "raster", &self.layout, &BINDINGS, resources)
    }

    /// Records the pass into `target` over a `size` viewport at its origin: `draws` (instance =
    /// object index), then, with `outlines`, the same draws as hulls. The targets are cleared to
    /// zero bits (distance 0: nothing drawn).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        target: &GBuffer<'_>,
        size: [u32; 2],
        bind_group: &wgpu::BindGroup,
        meshes: &MeshCache,
        frame: &Frame,
        draws: &[Draw],
        outlines: bool,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("raster"),
            color_attachments: &[cleared_color(target.surface), cleared_color(target.attributes)],
            depth_stencil_attachment: cleared_depth(target.depth, wgpu::StoreOp::Discard),
            timestamp_writes,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_viewport(0.0, 0.0, size[0] as f32, size[1] as f32, 0.0, 1.0);
        for (pipeline, enabled) in [(&self.raster, true), (&self.hull, outlines)] {
            if !enabled {
                continue;
            }
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, bind_group, &[]);
            setup::draw_meshes(&mut pass, meshes, frame, draws);
        }
    }
}
