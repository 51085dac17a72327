//! The shadow-map pass (`shaders/shadow_raster.wgsl` `vs_map`, depth only): once per frame, every
//! map cast's casters drawn into its layer of one depth array texture ([`MAP_FORMAT`], a layer and
//! a viewport per map cast), which the wave pass reads (`shadow_lookup.wgsl`). The texture is kept
//! across frames while its size holds.

use super::setup::Stages;
use super::setup::{
    self, cleared_depth, depth_test, triangles, vertex_layout, Binding, Draw, Kind, POSITION_ATTRIBUTE,
};
use crate::device::GpuContext;
use crate::formats::MAP_FORMAT;
use crate::layout::FrameShadows;
use crate::meshes::MeshCache;
use crate::shaders;
use crate::timing::PassQueries;
use hadou_scene::{Frame, RenderError};

const VS: wgpu::ShaderStages = wgpu::ShaderStages::VERTEX;

/// The bindings `vs_map` of shadow_raster.wgsl reads.
pub(crate) const BINDINGS: [Binding; 3] = [
    Binding::new(1, "objects", Kind::Storage, VS),
    Binding::new(3, "casts", Kind::Storage, VS),
    Binding::new(4, "draws", Kind::Storage, VS),
];

/// What the shadow-map pass reads, in the order of [`BINDINGS`].
pub(crate) struct ShadowMapInputs<'a> {
    /// The frame's `layout::GpuObject`s.
    pub(crate) objects: &'a wgpu::Buffer,
    /// The frame's `layout::GpuShadowCast`s.
    pub(crate) casts: &'a wgpu::Buffer,
    /// `(cast, object)` per shadow draw (`Draw::instance` indexes it).
    pub(crate) draws: &'a wgpu::Buffer,
}

/// The frame's shadow maps: a `size² × layers` depth array texture, kept between frames while
/// its size stays the same.
pub(crate) struct ShadowMaps {
    size: u32,
    layers: u32,
    /// All layers, as the wave pass reads them.
    pub(crate) view: wgpu::TextureView,
    /// One view per layer, as the map passes draw them.
    pub(crate) layer_views: Vec<wgpu::TextureView>,
}

impl ShadowMaps {
    /// Makes `maps` fit `shadows` (at least 1² × 2 texels: the wave pass binds one even without
    /// map casts); kept while its size holds.
    pub(crate) fn ensure(maps: &mut Option<ShadowMaps>, device: &wgpu::Device, shadows: &FrameShadows) {
        let (size, layers) = (shadows.map_size.max(1), shadows.map_layers.max(2));
        if maps.as_ref().is_some_and(|m| m.size == size && m.layers == layers) {
            return;
        }
        *maps = None; // free the old one first
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow maps"),
            size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: layers },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: MAP_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("shadow maps"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let layer_views = layer_views(&texture, layers);
        *maps = Some(ShadowMaps { size, layers, view, layer_views });
    }
}

/// One 2-D view per layer of `texture`'s first `layers` layers, as the map passes draw them.
pub(crate) fn layer_views(texture: &wgpu::Texture, layers: u32) -> Vec<wgpu::TextureView> {
    (0..layers)
        .map(|layer| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some("shadow map layer"),
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: layer,
                array_layer_count: Some(1),
                ..Default::default()
            })
        })
        .collect()
}

/// One shadow-map layer's pass: its layer, its edge in texels and its draws (instance = index into
/// the shadow draws).
pub(crate) struct MapPass {
    pub(crate) layer: u32,
    pub(crate) edge: f32,
    pub(crate) draws: Vec<Draw>,
}

/// The shadow-map pipeline and its bind group layout.
pub(crate) struct ShadowMapPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl ShadowMapPass {
    /// Compiles shadow_raster.wgsl and builds the pipeline.
    pub(crate) fn new(ctx: &GpuContext) -> Result<Self, RenderError> {
        let module = setup::compile_module(ctx, "shadow", &shaders::compose(shaders::SHADOW_PARTS))?;
        ctx.scoped("building the shadow-map pipeline", || {
            let d = &ctx.device;
            let layout = setup::bind_group_layout(d, "shadow maps", &BINDINGS);
            let buffers = [vertex_layout(&POSITION_ATTRIBUTE)];
            let stages = Stages {
                module: &module,
                vertex: "vs_map",
                buffers: &buffers,
                fragment: None,
                constants: &[],
            };
            // Double-sided, as the CPU draws casters.
            let depth = depth_test(MAP_FORMAT, wgpu::CompareFunction::Less);
            let pipeline =
                setup::render_pipeline(d, "shadow maps", &layout, &stages, triangles(None), Some(depth));
            Self { pipeline, layout }
        })
    }

    /// The bind group of `inputs`.
    pub(crate) fn bind_group(&self, device: &wgpu::Device, inputs: &ShadowMapInputs<'_>) -> wgpu::BindGroup {
        let resources = vec![
            inputs.objects.as_entire_binding(),
            inputs.casts.as_entire_binding(),
            inputs.draws.as_entire_binding(),
        ];
        setup::bind_group(device, "shadow maps", &self.layout, &BINDINGS, resources)
    }

    /// Records every map cast's casters into its layer (of `layer_views`), one render pass per layer
    /// (`timestamps`: a group of its own, a query pair per layer).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        layer_views: &[wgpu::TextureView],
        passes: &[MapPass],
        bind_group: &wgpu::BindGroup,
        meshes: &MeshCache,
        frame: &Frame,
        mut timestamps: Option<&mut PassQueries<'_>>,
    ) {
        if let Some(q) = timestamps.as_deref_mut() {
            q.next_group();
        }
        for m in passes {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow map"),
                color_attachments: &[],
                depth_stencil_attachment: cleared_depth(&layer_views[m.layer as usize], wgpu::StoreOp::Store),
                timestamp_writes: timestamps.as_deref_mut().and_then(|q| q.render("shadow maps")),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            // Texel (x, y) covers the map's pixel x = ⌊s·size⌋, y = ⌊(1 − t)·size⌋.
            pass.set_viewport(0.0, 0.0, m.edge, m.edge, 0.0, 1.0);
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, bind_group, &[]);
            setup::draw_meshes(&mut pass, meshes, frame, &m.draws);
        }
    }
}
