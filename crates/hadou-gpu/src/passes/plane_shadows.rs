//! The plane-shadow pass (`shaders/shadow_raster.wgsl` `vs_plane`, `fs_plane`), per tile after the
//! raster pass: each plane cast's casters projected onto its plane, fragments discarded by the
//! CPU's rules (`t < 0`, an outline hull, an object that does not receive the shadow, a visible
//! point off the plane), and through the depth test (depth = the cast's opacity rank) the most
//! opaque cast per pixel kept in a [`PLANE_SHADOW_FORMAT`] target that the wave pass reads
//! (`shadow_lookup.wgsl`), as `hadou-cpu`'s `shadows` does.

use super::setup::Stages;
use super::setup::{
    self, cleared_color, cleared_depth, color_target, depth_test, triangles, vertex_layout, Binding, Draw,
    Kind, POSITION_ATTRIBUTE,
};
use crate::device::GpuContext;
use crate::formats::{DEPTH_FORMAT, PLANE_SHADOW_FORMAT};
use crate::meshes::MeshCache;
use crate::shaders;
use hadou_scene::{Frame, RenderError};

const VS_FS: wgpu::ShaderStages = wgpu::ShaderStages::VERTEX.union(wgpu::ShaderStages::FRAGMENT);
const FS: wgpu::ShaderStages = wgpu::ShaderStages::FRAGMENT;

/// The bindings of shadow_raster.wgsl that `vs_plane` and `fs_plane` read.
pub(crate) const BINDINGS: [Binding; 7] = [
    Binding::new(0, "frame", Kind::Uniform, VS_FS),
    Binding::new(1, "objects", Kind::Storage, VS_FS),
    Binding::new(2, "materials", Kind::Storage, VS_FS),
    Binding::new(3, "casts", Kind::Storage, VS_FS),
    Binding::new(4, "draws", Kind::Storage, VS_FS),
    Binding::new(5, "scene_texels", Kind::UintTexture, FS),
    Binding::new(6, "attribute_texels", Kind::UintTexture, FS),
];

/// What the plane-shadow pass reads, in the order of [`BINDINGS`].
pub(crate) struct PlaneShadowInputs<'a> {
    /// The tile's `layout::FrameUniforms`.
    pub(crate) uniforms: &'a wgpu::Buffer,
    /// The frame's `layout::GpuObject`s.
    pub(crate) objects: &'a wgpu::Buffer,
    /// The frame's `layout::GpuMaterial`s (each receiver's shadow bits).
    pub(crate) materials: &'a wgpu::Buffer,
    /// The frame's `layout::GpuShadowCast`s.
    pub(crate) casts: &'a wgpu::Buffer,
    /// `(cast, object)` per shadow draw (`Draw::instance` indexes it).
    pub(crate) draws: &'a wgpu::Buffer,
    /// The tile's G-buffer, as the raster pass drew it.
    pub(crate) surface: &'a wgpu::TextureView,
    pub(crate) attributes: &'a wgpu::TextureView,
}

/// The plane-shadow pipeline and its bind group layout.
pub(crate) struct PlaneShadowPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl PlaneShadowPass {
    /// Compiles shadow_raster.wgsl and builds the pipeline.
    pub(crate) fn new(ctx: &GpuContext) -> Result<Self, RenderError> {
        let module = setup::compile_module(ctx, "shadow", &shaders::compose(shaders::SHADOW_PARTS))?;
        ctx.scoped("building the plane-shadow pipeline", || {
            let d = &ctx.device;
            let layout = setup::bind_group_layout(d, "plane shadows", &BINDINGS);
            let buffers = [vertex_layout(&POSITION_ATTRIBUTE)];
            let targets = [color_target(PLANE_SHADOW_FORMAT)];
            let stages = Stages {
                module: &module,
                vertex: "vs_plane",
                buffers: &buffers,
                fragment: Some(("fs_plane", &targets)),
                constants: &[],
            };
            // Double-sided, as the CPU draws casters.
            let depth = depth_test(DEPTH_FORMAT, wgpu::CompareFunction::Less);
            let pipeline =
                setup::render_pipeline(d, "plane shadows", &layout, &stages, triangles(None), Some(depth));
            Self { pipeline, layout }
        })
    }

    /// The bind group of `inputs`.
    pub(crate) fn bind_group(
        &self,
        device: &wgpu::Device,
        inputs: &PlaneShadowInputs<'_>,
    ) -> wgpu::BindGroup {
        let view = wgpu::BindingResource::TextureView;
        let resources = vec![
            inputs.uniforms.as_entire_binding(),
            inputs.objects.as_entire_binding(),
            inputs.materials.as_entire_binding(),
            inputs.casts.as_entire_binding(),
            inputs.draws.as_entire_binding(),
            view(inputs.surface),
            view(inputs.attributes),
        ];
        setup::bind_group(device, "plane shadows", &self.layout, &BINDINGS, resources)
    }

    /// Records the pass into `target` ([`PLANE_SHADOW_FORMAT`], cleared to 0: no plane cast) with
    /// the depth buffer `depth` over a `size` viewport: the plane casts' `draws` in cast order.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        depth: &wgpu::TextureView,
        size: [u32; 2],
        bind_group: &wgpu::BindGroup,
        meshes: &MeshCache,
        frame: &Frame,
        draws: &[Draw],
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("plane shadows"),
            color_attachments: &[cleared_color(target)],
            depth_stencil_attachment: cleared_depth(depth, wgpu::StoreOp::Discard),
            timestamp_writes,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_viewport(0.0, 0.0, size[0] as f32, size[1] as f32, 0.0, 1.0);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        setup::draw_meshes(&mut pass, meshes, frame, draws);
    }
}
