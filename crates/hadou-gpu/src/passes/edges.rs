//! The edge pass (`shaders/edges.wgsl`): closed outlines where objects meet. Two compute
//! dispatches over the tile read the raster pass's G-buffer and write the attributes target the
//! plane shadows and the wave pass read: the raster pass's words with the hull reach cleared, and
//! on the pixels within another object's outline width of its visible edge, in front of their own
//! surface, that object's outline material marked as a hull (`hadou_math::outline`, 000 §2.3;
//! hadou-cpu's `edges.rs` is the twin). The first finds the candidate edge pixels and each 8×8
//! block's largest reach; the second searches only the blocks that reach its pixel. The search
//! stops at the tile's edges.
//!
//! Compute, not a full-screen fragment pass: on GPUs whose graphics units are a small part of the
//! chip (the H100 and H200 run fragment shaders on two of their TPCs) a fragment pass of this
//! search cost 7.8 ms at 1024² (see docs/benchmarks.md).

use super::setup::{self, Binding, Kind};
use crate::device::GpuContext;
use crate::shaders;
use hadou_scene::RenderError;

const CS: wgpu::ShaderStages = wgpu::ShaderStages::COMPUTE;

/// Pixels per edge of a block of the candidate map, and of a workgroup (edges.wgsl `BLOCK`).
pub(crate) const EDGE_BLOCK: u32 = 8;

/// The bindings of edges.wgsl.
pub(crate) const BINDINGS: [Binding; 7] = [
    Binding::new(0, "frame", Kind::Uniform, CS),
    Binding::new(1, "materials", Kind::Storage, CS),
    Binding::new(2, "scene_texels", Kind::UintTexture, CS),
    Binding::new(3, "attribute_texels", Kind::UintTexture, CS),
    Binding::new(4, "out_texels", Kind::UintStorageTexture, CS),
    Binding::new(5, "candidates", Kind::StorageRw, CS),
    Binding::new(6, "blocks", Kind::StorageRw, CS),
];

/// Bytes of the candidate buffer and of the block buffer for a tile of `size` pixels.
pub(crate) fn scratch_bytes(size: [u32; 2]) -> (u64, u64) {
    let pixels = size[0] as u64 * size[1] as u64;
    let blocks = size[0].div_ceil(EDGE_BLOCK) as u64 * size[1].div_ceil(EDGE_BLOCK) as u64;
    (pixels * 8, blocks * 4)
}

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
    /// Where the pass writes target 1 (a [`crate::formats::SCENE_FORMAT`] view with storage
    /// use, not `attributes`).
    pub(crate) output: &'a wgpu::TextureView,
    /// The candidate map and the block maxima, [`scratch_bytes`] long.
    pub(crate) candidates: &'a wgpu::Buffer,
    pub(crate) blocks: &'a wgpu::Buffer,
}

/// The edge pass's two pipelines and their bind group layout.
pub(crate) struct EdgePass {
    candidates: wgpu::ComputePipeline,
    edges: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl EdgePass {
    /// Compiles edges.wgsl and builds the pipelines.
    pub(crate) fn new(ctx: &GpuContext) -> Result<Self, RenderError> {
        let module = setup::compile_module(ctx, "edges", &shaders::compose(shaders::EDGES_PARTS))?;
        ctx.scoped("building the edge pipelines", || {
            let d = &ctx.device;
            let layout = setup::bind_group_layout(d, "edges", &BINDINGS);
            let pipeline_layout = setup::pipeline_layout(d, "edges", &layout);
            let pipeline = |entry: &str| setup::compute_pipeline(d, &pipeline_layout, &module, entry);
            Self { candidates: pipeline("cs_candidates"), edges: pipeline("cs_edges"), layout }
        })
    }

    /// The bind group of `inputs`.
    pub(crate) fn bind_group(&self, device: &wgpu::Device, inputs: &EdgeInputs<'_>) -> wgpu::BindGroup {
        let resources = vec![
            inputs.uniforms.as_entire_binding(),
            inputs.materials.as_entire_binding(),
            wgpu::BindingResource::TextureView(inputs.surface),
            wgpu::BindingResource::TextureView(inputs.attributes),
            wgpu::BindingResource::TextureView(inputs.output),
            inputs.candidates.as_entire_binding(),
            inputs.blocks.as_entire_binding(),
        ];
        setup::bind_group(device, "edges", &self.layout, &BINDINGS, resources)
    }

    /// Records the pass over the `size` pixels at the origin of the bind group's targets.
    pub(crate) fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        size: [u32; 2],
        bind_group: &wgpu::BindGroup,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites<'_>>,
    ) {
        let mut pass =
            enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("edges"), timestamp_writes });
        pass.set_bind_group(0, bind_group, &[]);
        let groups = [size[0].div_ceil(EDGE_BLOCK), size[1].div_ceil(EDGE_BLOCK)];
        for pipeline in [&self.candidates, &self.edges] {
            pass.set_pipeline(pipeline);
            pass.dispatch_workgroups(groups[0], groups[1], 1);
        }
    }
}
