//! The `[area_light]`'s soft shadows (003; `shaders/soft_map.wgsl`, `shaders/soft.wgsl`; twin of
//! hadou-cpu's `soft`). They need the whole image at once: every tile of the image is rasterized
//! and its visible points gathered into whole-image buffers, with the bounds of those that a
//! caster's box lies in front of ([`SoftPass::encode_points`], `cs_points`); the light's two
//! perspective maps are fitted to those bounds on the GPU ([`SoftPass::encode_fit`], `cs_fit`: no
//! read-back in the middle of the frame, on the web as natively) and drawn
//! ([`SoftPass::encode_maps`]), every pixel is classed umbra / penumbra / lit
//! ([`SoftPass::encode_class`], `cs_class`), the penumbra is resolved over the whole image ([`SoftPass::encode_resolve`]:
//! `cs_columns` + `cs_exact`, or 003's grid search `cs_grid` + `cs_interp`), and each tile's wave
//! pass takes its visibility ([`SoftPass::encode_gather`], `cs_gather`, through the output's
//! eye-distance slot, so the wave pass needs no binding of its own for it). The renderer's tile
//! loop (`render.rs`) orders these around the other passes.

use super::setup::Stages;
use super::setup::{
    self, color_target, depth_test, texture_view, triangles, vertex_layout, Binding, Draw, Kind,
    POSITION_ATTRIBUTE,
};
use crate::device::GpuContext;
use crate::formats::{MAP_FORMAT, SPOT_FORMAT};
use crate::layout::{
    GpuBvhNode, GpuBvhTri, GpuCasterBox, GpuSpotMap, SoftUniforms, TracedGrid, TracedUniforms,
};
use crate::meshes::MeshCache;
use crate::shaders;
use crate::timing::PassQueries;
use hadou_math::soft::{Bvh, FitWindow, LampPattern, BVH_NODE_BYTES, BVH_TRI_BYTES};
use hadou_scene::{Frame, RenderError, SoftResolve};

const VS: wgpu::ShaderStages = wgpu::ShaderStages::VERTEX;
const CS: wgpu::ShaderStages = wgpu::ShaderStages::COMPUTE;

/// The bindings of soft_map.wgsl.
pub(crate) const MAP_BINDINGS: [Binding; 2] =
    [Binding::new(0, "spot", Kind::Uniform, VS), Binding::new(1, "objects", Kind::Storage, VS)];

/// The bindings of soft.wgsl.
pub(crate) const BINDINGS: [Binding; 14] = [
    Binding::new(0, "frame", Kind::Uniform, CS),
    Binding::new(1, "soft", Kind::Uniform, CS),
    Binding::new(2, "scene_texels", Kind::UintTexture, CS),
    Binding::new(3, "attribute_texels", Kind::UintTexture, CS),
    Binding::new(4, "spot_map0", Kind::UintTexture, CS),
    Binding::new(5, "spot_map1", Kind::UintTexture, CS),
    Binding::new(6, "soft_world", Kind::StorageRw, CS),
    Binding::new(7, "soft_normal", Kind::StorageRw, CS),
    Binding::new(8, "visibility", Kind::StorageRw, CS),
    Binding::new(9, "grid", Kind::StorageRw, CS),
    Binding::new(10, "out_buf", Kind::StorageRw, CS),
    Binding::new(11, "caster_boxes", Kind::Storage, CS),
    Binding::new(12, "fit", Kind::StorageRw, CS),
    Binding::new(13, "fitted_maps", Kind::StorageRw, CS),
];

/// The bindings of soft_traced.wgsl.
pub(crate) const TRACED_BINDINGS: [Binding; 8] = [
    Binding::new(0, "frame", Kind::Uniform, CS),
    Binding::new(1, "traced", Kind::Uniform, CS),
    Binding::new(2, "soft_world", Kind::Storage, CS),
    Binding::new(3, "soft_normal", Kind::StorageRw, CS),
    Binding::new(4, "visibility", Kind::StorageRw, CS),
    Binding::new(5, "nodes", Kind::Storage, CS),
    Binding::new(6, "tris", Kind::Storage, CS),
    Binding::new(7, "grid", Kind::Uniform, CS),
];

/// What soft.wgsl reads from a tile (the rest, [`BINDINGS`] 1, 4–9 and 11–13, is
/// [`SoftTargets`]'s).
pub(crate) struct SoftTileInputs<'a> {
    /// The tile's `layout::FrameUniforms`.
    pub(crate) uniforms: &'a wgpu::Buffer,
    /// The tile's G-buffer, as the raster pass drew it.
    pub(crate) surface: &'a wgpu::TextureView,
    pub(crate) attributes: &'a wgpu::TextureView,
    /// The wave pass's output buffer (`cs_gather` writes each pixel's visibility into it).
    pub(crate) output: &'a wgpu::Buffer,
}

/// Every pixel's soft-shadow class (`hadou_math::soft::Class as u8`) and visibility, row-major.
#[cfg(not(target_arch = "wasm32"))]
pub type SoftReadback = (Vec<u8>, Vec<f32>);

/// Bytes per pixel of the whole-image soft-shadow buffers: the visible point and class (16), the
/// unit normal and the column pass's nearest rows (16), the visibility (4); the faithful grid adds
/// at most 4 more (`n = 1`).
pub const SOFT_BYTES_PER_PIXEL: u64 = 36;

/// Checks the frame's `[area_light]` against the device: the map edge within the largest 2D
/// texture, the whole-image buffers within the storage-buffer limits.
pub(crate) fn check_area_light(limits: &wgpu::Limits, frame: &Frame) -> Result<(), RenderError> {
    let Some(light) = &frame.area_light else { return Ok(()) };
    if let SoftResolve::Traced { .. } = light.resolve {
        // The hierarchy's two buffers, at most (every caster triangle kept).
        let tris: u64 = light
            .casters
            .iter()
            .filter_map(|&c| frame.objects.get(c as usize))
            .map(|o| o.mesh.indices.len() as u64 / 3)
            .sum();
        let max = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        let (node_bytes, tri_bytes) = (2 * tris * BVH_NODE_BYTES, tris * BVH_TRI_BYTES);
        if node_bytes.max(tri_bytes) > max {
            return Err(RenderError::Device(format!(
                "[area_light]: the traced resolve's hierarchy over {tris} caster triangles needs buffers of up to \
                 {} bytes, more than this adapter's storage buffer limit of {max} bytes",
                node_bytes.max(tri_bytes)
            )));
        }
    }
    if light.map_size > limits.max_texture_dimension_2d {
        return Err(RenderError::Device(format!(
            "[area_light]: map_size {} exceeds this adapter's largest texture ({})",
            light.map_size, limits.max_texture_dimension_2d
        )));
    }
    let pixels = frame.width as u64 * frame.height as u64;
    let max = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
    if pixels * 16 > max {
        return Err(RenderError::Device(format!(
            "[area_light]: a {}×{} image needs soft-shadow buffers of {} bytes, more than this adapter's storage \
             buffer limit of {max} bytes",
            frame.width,
            frame.height,
            pixels * 16
        )));
    }
    Ok(())
}

/// The faithful grid's size for an image and spacing `n` (hadou-cpu's `Search::faithful`).
fn grid_size(width: u32, height: u32, n: u32) -> [u32; 2] {
    [(width - 1) / n + 1, (height - 1) / n + 1]
}

/// The `[area_light]`'s GPU resources, kept while the image and map sizes hold. GPU memory:
/// [`SOFT_BYTES_PER_PIXEL`] (36, up to 40 with the faithful grid) bytes per image pixel (604 MiB
/// at the loader's limit of 4096² pixels, `SOFT_MAX_PIXELS`), plus 12 bytes per map texel for the
/// two maps and their shared depth buffer (12 MiB at `map_size` 1024).
pub(crate) struct SoftTargets {
    key: (u32, u32, u32, u32),
    spot_views: [wgpu::TextureView; 2],
    spot_depth: wgpu::TextureView,
    /// One uniform buffer per map (soft_map.wgsl binding 0), then the soft uniforms (soft.wgsl 1).
    spot_uniforms: [wgpu::Buffer; 2],
    uniforms: wgpu::Buffer,
    world: wgpu::Buffer,
    normal: wgpu::Buffer,
    visibility: wgpu::Buffer,
    grid: wgpu::Buffer,
    /// The casters' boxes (soft.wgsl binding 11), room for `box_capacity`.
    boxes: wgpu::Buffer,
    box_capacity: usize,
    /// The maps' fit windows (binding 12, `FitWindow` keys), gathered by `cs_points`.
    fit: wgpu::Buffer,
    /// The two maps fitted to them by `cs_fit` (binding 13, `[GpuSpotMap; 2]`), copied into
    /// `spot_uniforms` on the GPU.
    fitted: wgpu::Buffer,
    /// The traced resolve's uniforms and hierarchy (soft_traced.wgsl), made on its first frame and
    /// grown as needed.
    traced: Option<TracedBuffers>,
}

/// The traced resolve's buffers: its uniforms ([`TracedUniforms`], [`TracedGrid`]) and the
/// hierarchy's nodes and triangles, with room for `capacity` of each.
struct TracedBuffers {
    uniforms: wgpu::Buffer,
    grid: wgpu::Buffer,
    /// The sample grid's edge `k` this frame.
    k: u32,
    nodes: wgpu::Buffer,
    tris: wgpu::Buffer,
    capacity: (u64, u64),
}

/// Bytes of the fit windows: four `u32` keys per map.
const FIT_BYTES: u64 = 32;

impl SoftTargets {
    /// Makes `soft` fit `frame` (which has an `[area_light]`; with anti-aliasing the sample frame,
    /// whose image pixels are `grid × grid` of its pixels) and writes its uniforms.
    pub(crate) fn ensure(slot: &mut Option<SoftTargets>, ctx: &GpuContext, frame: &Frame, grid: u32) {
        let light = frame.area_light.as_ref().expect("an area light");
        let n = match light.resolve {
            SoftResolve::Exact | SoftResolve::Traced { .. } => 0,
            SoftResolve::Faithful { n } => n.max(1),
        };
        let gs = grid_size(frame.width, frame.height, n.max(1));
        let grid_len = if n == 0 { 1 } else { gs[0] * gs[1] };
        let key = (frame.width, frame.height, light.map_size.max(1), grid_len);
        let boxes = light.caster_boxes.len().max(1);
        if slot.as_ref().is_none_or(|s| s.key != key || s.box_capacity < boxes) {
            *slot = None; // free the old ones first
            let d = &ctx.device;
            let size = key.2;
            let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
            let texture = |label, format| texture_view(d, label, [size, size], format, usage);
            let buffer = |label, size: u64, usage| {
                d.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size,
                    usage,
                    mapped_at_creation: false,
                })
            };
            let pixels = frame.width as u64 * frame.height as u64;
            let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
            let uniform = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
            let spot = std::mem::size_of::<GpuSpotMap>() as u64;
            *slot = Some(SoftTargets {
                key,
                spot_views: [texture("soft map 1", SPOT_FORMAT), texture("soft map 2", SPOT_FORMAT)],
                spot_depth: texture("soft map depth", MAP_FORMAT),
                spot_uniforms: [buffer("soft map 1", spot, uniform), buffer("soft map 2", spot, uniform)],
                uniforms: buffer("soft uniforms", std::mem::size_of::<SoftUniforms>() as u64, uniform),
                world: buffer("soft points", pixels * 16, storage),
                normal: buffer("soft normals", pixels * 16, storage),
                visibility: buffer("soft visibility", pixels * 4, storage),
                grid: buffer("soft grid", grid_len as u64 * 4, storage),
                boxes: buffer(
                    "soft caster boxes",
                    (boxes * std::mem::size_of::<GpuCasterBox>()) as u64,
                    wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                ),
                box_capacity: boxes,
                fit: buffer("soft fit", FIT_BYTES, storage | wgpu::BufferUsages::COPY_DST),
                fitted: buffer("soft fitted maps", 2 * spot, storage),
                traced: None,
            });
        }
        let soft = slot.as_ref().expect("created above");
        // The unfitted maps, which cs_points fits the windows in; cs_fit narrows them.
        soft.write_uniforms(ctx, frame);
        let boxes: Vec<GpuCasterBox> = light.caster_boxes.iter().map(GpuCasterBox::new).collect();
        if !boxes.is_empty() {
            ctx.queue.write_buffer(&soft.boxes, 0, bytemuck::cast_slice(&boxes));
        }
        let empty = FitWindow::EMPTY;
        let keys = [empty.min, empty.max, empty.min, empty.max].concat();
        ctx.queue.write_buffer(&soft.fit, 0, bytemuck::cast_slice(&keys));
        if let Some(soft) = slot.as_mut() {
            soft.write_traced(ctx, frame, grid);
        }
    }

    /// Writes the frame's `[area_light]` into soft.wgsl's uniforms: its resolve, and the two maps
    /// unfitted (`AreaLight::maps`), which `cs_points` gathers the fit windows in and `cs_fit`
    /// narrows.
    fn write_uniforms(&self, ctx: &GpuContext, frame: &Frame) {
        let light = frame.area_light.as_ref().expect("an area light");
        let n = match light.resolve {
            SoftResolve::Exact | SoftResolve::Traced { .. } => 0,
            SoftResolve::Faithful { n } => n.max(1),
        };
        let u = SoftUniforms {
            maps: light.maps.map(|m| GpuSpotMap::new(&m, self.key.2)),
            depth_aware: u32::from(light.depth_aware),
            grid: n,
            grid_size: grid_size(frame.width, frame.height, n.max(1)),
            ratio: light.penumbra_ratio(),
            boxes: light.caster_boxes.len() as u32,
            _pad: [0; 2],
        };
        ctx.queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
    }

    /// For a frame of the traced resolve: builds the hierarchy of the light's casters' world-space
    /// triangles (`hadou_math::soft::Bvh`, as hadou-cpu's `traced` does) and writes it and the
    /// lamp's sample layout and the sample grid's edge `grid` for soft_traced.wgsl, growing the
    /// buffers as needed.
    pub(crate) fn write_traced(&mut self, ctx: &GpuContext, frame: &Frame, grid: u32) {
        let light = frame.area_light.as_ref().expect("an area light");
        let SoftResolve::Traced { samples } = light.resolve else { return };
        let bvh = Bvh::build(&hadou_scene::caster_triangles(frame, &light.casters));
        let nodes: Vec<GpuBvhNode> = bvh.nodes.iter().map(GpuBvhNode::from).collect();
        let tris: Vec<GpuBvhTri> = bvh.tris.iter().map(GpuBvhTri::from).collect();
        let need = (nodes.len().max(1) as u64, tris.len().max(1) as u64);
        let d = &ctx.device;
        if self.traced.as_ref().is_none_or(|t| t.capacity.0 < need.0 || t.capacity.1 < need.1) {
            let buffer = |label, size: u64, usage| {
                d.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size,
                    usage,
                    mapped_at_creation: false,
                })
            };
            let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
            let capacity = (need.0.next_power_of_two(), need.1.next_power_of_two());
            self.traced = Some(TracedBuffers {
                uniforms: buffer(
                    "traced uniforms",
                    std::mem::size_of::<TracedUniforms>() as u64,
                    wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                ),
                grid: buffer(
                    "traced grid",
                    std::mem::size_of::<TracedGrid>() as u64,
                    wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                ),
                k: 1,
                nodes: buffer("traced hierarchy nodes", capacity.0 * BVH_NODE_BYTES, storage),
                tris: buffer("traced hierarchy triangles", capacity.1 * BVH_TRI_BYTES, storage),
                capacity,
            });
        }
        let t = self.traced.as_mut().expect("made above");
        let pattern = LampPattern::new(light.shape, samples);
        let u = TracedUniforms::new(&pattern, nodes.len() as u32);
        ctx.queue.write_buffer(&t.uniforms, 0, bytemuck::bytes_of(&u));
        t.k = grid.max(1);
        ctx.queue.write_buffer(&t.grid, 0, bytemuck::bytes_of(&TracedGrid { k: t.k, pad: [0; 3] }));
        if !nodes.is_empty() {
            ctx.queue.write_buffer(&t.nodes, 0, bytemuck::cast_slice(&nodes));
            ctx.queue.write_buffer(&t.tris, 0, bytemuck::cast_slice(&tris));
        }
    }

    /// After a frame with an `[area_light]` has been drawn: every pixel's soft-shadow class
    /// (`hadou_math::soft::Class` as `u8`) and visibility, read back (for tests).
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn read(&self, ctx: &GpuContext, frame: &Frame) -> Result<SoftReadback, RenderError> {
        let pixels = frame.width as u64 * frame.height as u64;
        let read = |src: &wgpu::Buffer, bytes: u64| -> Result<Vec<u32>, RenderError> {
            let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("soft read-back"),
                size: bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let mut enc = ctx.device.create_command_encoder(&Default::default());
            enc.copy_buffer_to_buffer(src, 0, &staging, 0, bytes);
            let submission = ctx.queue.submit([enc.finish()]);
            let mut out = Vec::new();
            ctx.read_buffer(&staging, bytes, submission, |raw| {
                out = raw.chunks_exact(4).map(|c| u32::from_ne_bytes([c[0], c[1], c[2], c[3]])).collect();
            })?;
            Ok(out)
        };
        let world = read(&self.world, pixels * 16)?;
        let vis = read(&self.visibility, pixels * 4)?;
        let class = world.chunks_exact(4).map(|p| p[3] as u8).collect();
        Ok((class, vis.into_iter().map(f32::from_bits).collect()))
    }
}

/// The compute pipelines of soft.wgsl.
struct SoftPipelines {
    points: wgpu::ComputePipeline,
    fit: wgpu::ComputePipeline,
    class: wgpu::ComputePipeline,
    columns: wgpu::ComputePipeline,
    exact: wgpu::ComputePipeline,
    grid: wgpu::ComputePipeline,
    interp: wgpu::ComputePipeline,
    gather: wgpu::ComputePipeline,
}

/// The soft-shadow pipelines and bind group layouts.
pub(crate) struct SoftPass {
    /// The traced resolve (soft_traced.wgsl `cs_traced`, and `cs_traced_pixels` first with
    /// anti-aliasing) and its layout.
    traced: wgpu::ComputePipeline,
    traced_pixels: wgpu::ComputePipeline,
    traced_layout: wgpu::BindGroupLayout,
    /// The `[area_light]`'s maps (soft_map.wgsl).
    spot_map: wgpu::RenderPipeline,
    spot_map_layout: wgpu::BindGroupLayout,
    /// The compute passes (soft.wgsl), one layout for all.
    pipelines: SoftPipelines,
    layout: wgpu::BindGroupLayout,
}

impl SoftPass {
    /// Compiles soft_map.wgsl and soft.wgsl and builds their pipelines.
    pub(crate) fn new(ctx: &GpuContext) -> Result<Self, RenderError> {
        let spot_module = setup::compile_module(ctx, "soft map", &shaders::compose(shaders::SOFT_MAP_PARTS))?;
        let soft_module = setup::compile_module(ctx, "soft", &shaders::compose(shaders::SOFT_PARTS))?;
        let traced_module =
            setup::compile_module(ctx, "soft traced", &shaders::compose(shaders::SOFT_TRACED_PARTS))?;
        ctx.scoped("building the soft-shadow pipelines", || {
            let d = &ctx.device;
            let spot_map_layout = setup::bind_group_layout(d, "soft maps", &MAP_BINDINGS);
            let layout = setup::bind_group_layout(d, "soft", &BINDINGS);
            let buffers = [vertex_layout(&POSITION_ATTRIBUTE)];
            let targets = [color_target(SPOT_FORMAT)];
            let stages = Stages {
                module: &spot_module,
                vertex: "vs_spot",
                buffers: &buffers,
                fragment: Some(("fs_spot", &targets)),
                constants: &[],
            };
            // Double-sided, as the CPU draws casters; depth near/z: the nearest surface has the
            // greatest.
            let depth = depth_test(MAP_FORMAT, wgpu::CompareFunction::Greater);
            let spot_map = setup::render_pipeline(
                d,
                "soft maps",
                &spot_map_layout,
                &stages,
                triangles(None),
                Some(depth),
            );
            let soft_pl = setup::pipeline_layout(d, "soft", &layout);
            let pipeline = |entry: &str| setup::compute_pipeline(d, &soft_pl, &soft_module, entry);
            let pipelines = SoftPipelines {
                points: pipeline("cs_points"),
                fit: pipeline("cs_fit"),
                class: pipeline("cs_class"),
                columns: pipeline("cs_columns"),
                exact: pipeline("cs_exact"),
                grid: pipeline("cs_grid"),
                interp: pipeline("cs_interp"),
                gather: pipeline("cs_gather"),
            };
            let traced_layout = setup::bind_group_layout(d, "soft traced", &TRACED_BINDINGS);
            let traced_pl = setup::pipeline_layout(d, "soft traced", &traced_layout);
            let traced = setup::compute_pipeline(d, &traced_pl, &traced_module, "cs_traced");
            let traced_pixels = setup::compute_pipeline(d, &traced_pl, &traced_module, "cs_traced_pixels");
            Self { traced, traced_pixels, traced_layout, spot_map, spot_map_layout, pipelines, layout }
        })
    }

    /// The bind group of soft.wgsl for one tile's inputs and `targets`.
    pub(crate) fn bind_group(
        &self,
        device: &wgpu::Device,
        targets: &SoftTargets,
        tile: &SoftTileInputs<'_>,
    ) -> wgpu::BindGroup {
        let view = wgpu::BindingResource::TextureView;
        let resources = vec![
            tile.uniforms.as_entire_binding(),
            targets.uniforms.as_entire_binding(),
            view(tile.surface),
            view(tile.attributes),
            view(&targets.spot_views[0]),
            view(&targets.spot_views[1]),
            targets.world.as_entire_binding(),
            targets.normal.as_entire_binding(),
            targets.visibility.as_entire_binding(),
            targets.grid.as_entire_binding(),
            tile.output.as_entire_binding(),
            targets.boxes.as_entire_binding(),
            targets.fit.as_entire_binding(),
            targets.fitted.as_entire_binding(),
        ];
        setup::bind_group(device, "soft", &self.layout, &BINDINGS, resources)
    }

    /// Records the light's two maps (soft_map.wgsl): `draws` (instance = object index, only the
    /// light's casters, as hadou-cpu's `spot_tris`) seen from each map's light.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn encode_maps(
        &self,
        enc: &mut wgpu::CommandEncoder,
        device: &wgpu::Device,
        targets: &SoftTargets,
        objects: &wgpu::Buffer,
        meshes: &MeshCache,
        frame: &Frame,
        draws: &[Draw],
    ) {
        for k in 0..2 {
            let resources = vec![targets.spot_uniforms[k].as_entire_binding(), objects.as_entire_binding()];
            let bg = setup::bind_group(device, "soft map", &self.spot_map_layout, &MAP_BINDINGS, resources);
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("soft map"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &targets.spot_views[k],
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        // +∞ as f32 bits: no surface.
                        load: wgpu::LoadOp::Clear(wgpu::Color {
                            r: f32::INFINITY.to_bits() as f64,
                            g: 0.0,
                            b: 0.0,
                            a: 0.0,
                        }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &targets.spot_depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            let edge = targets.key.2 as f32;
            pass.set_viewport(0.0, 0.0, edge, edge, 0.0, 1.0);
            pass.set_pipeline(&self.spot_map);
            pass.set_bind_group(0, &bg, &[]);
            setup::draw_meshes(&mut pass, meshes, frame, draws);
        }
    }

    /// Records the gathering of a `size` tile's visible points and the maps' fit windows
    /// (`cs_points`), after its raster pass.
    pub(crate) fn encode_points(
        &self,
        enc: &mut wgpu::CommandEncoder,
        bind_group: &wgpu::BindGroup,
        size: [u32; 2],
    ) {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&self.pipelines.points);
        pass.set_bind_group(0, bind_group, &[]);
        pass.dispatch_workgroups(size[0].div_ceil(8), size[1].div_ceil(8), 1);
    }

    /// Records the maps' fit (`cs_fit`), once every tile's points are gathered, and the copies
    /// of the fitted maps into the map pass's uniforms: the frame goes on without waiting.
    pub(crate) fn encode_fit(
        &self,
        enc: &mut wgpu::CommandEncoder,
        bind_group: &wgpu::BindGroup,
        targets: &SoftTargets,
    ) {
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipelines.fit);
            pass.set_bind_group(0, bind_group, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        let spot = std::mem::size_of::<GpuSpotMap>() as u64;
        for (k, uniform) in targets.spot_uniforms.iter().enumerate() {
            enc.copy_buffer_to_buffer(&targets.fitted, k as u64 * spot, uniform, 0, spot);
        }
    }

    /// Records the traced resolve over the whole image (`cs_traced`; with anti-aliasing
    /// `cs_traced_pixels` first, one value per image pixel), once every tile's points are
    /// gathered and [`SoftTargets::write_traced`] has written the hierarchy; `uniforms` is the
    /// tiles' `layout::FrameUniforms` (any tile's: the image size and the light are the frame's).
    pub(crate) fn encode_traced(
        &self,
        enc: &mut wgpu::CommandEncoder,
        device: &wgpu::Device,
        targets: &SoftTargets,
        uniforms: &wgpu::Buffer,
        frame: &Frame,
    ) {
        let Some(t) = targets.traced.as_ref() else { return };
        let resources = vec![
            uniforms.as_entire_binding(),
            t.uniforms.as_entire_binding(),
            targets.world.as_entire_binding(),
            targets.normal.as_entire_binding(),
            targets.visibility.as_entire_binding(),
            t.nodes.as_entire_binding(),
            t.tris.as_entire_binding(),
            t.grid.as_entire_binding(),
        ];
        let bg = setup::bind_group(device, "soft traced", &self.traced_layout, &TRACED_BINDINGS, resources);
        if t.k > 1 {
            // Its own pass: cs_traced reads what it writes.
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("soft traced pixels"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.traced_pixels);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups((frame.width / t.k).div_ceil(8), (frame.height / t.k).div_ceil(8), 1);
        }
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("soft traced"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.traced);
        pass.set_bind_group(0, &bg, &[]);
        pass.dispatch_workgroups(frame.width.div_ceil(8), frame.height.div_ceil(8), 1);
    }

    /// Records the classification of the whole image's pixels (`cs_class`), once every tile's
    /// points are gathered and the fitted maps drawn.
    pub(crate) fn encode_class(
        &self,
        enc: &mut wgpu::CommandEncoder,
        bind_group: &wgpu::BindGroup,
        frame: &Frame,
    ) {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&self.pipelines.class);
        pass.set_bind_group(0, bind_group, &[]);
        pass.dispatch_workgroups(frame.width.div_ceil(8), frame.height.div_ceil(8), 1);
    }

    /// Records the resolve of the whole image's penumbra, once every tile is classified: 003's grid
    /// search with bilinear interpolation for `SoftResolve::Faithful`, else the exact resolve.
    pub(crate) fn encode_resolve(
        &self,
        enc: &mut wgpu::CommandEncoder,
        bind_group: &wgpu::BindGroup,
        frame: &Frame,
    ) {
        let (w, h) = (frame.width, frame.height);
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_bind_group(0, bind_group, &[]);
        let p = &self.pipelines;
        match frame.area_light.as_ref().map(|l| l.resolve) {
            Some(SoftResolve::Faithful { n }) => {
                let gs = grid_size(w, h, n.max(1));
                pass.set_pipeline(&p.grid);
                pass.dispatch_workgroups(gs[0].div_ceil(8), gs[1].div_ceil(8), 1);
                pass.set_pipeline(&p.interp);
                pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
            }
            _ => {
                pass.set_pipeline(&p.columns);
                pass.dispatch_workgroups(w.div_ceil(64), 1, 1);
                pass.set_pipeline(&p.exact);
                pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
            }
        }
    }

    /// Records the hand-over of a `size` tile's visibility to its wave pass (`cs_gather`).
    pub(crate) fn encode_gather(
        &self,
        enc: &mut wgpu::CommandEncoder,
        bind_group: &wgpu::BindGroup,
        size: [u32; 2],
        timestamps: Option<&mut PassQueries<'_>>,
    ) {
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("soft gather"),
            timestamp_writes: timestamps.and_then(|q| q.compute("soft gather")),
        });
        pass.set_pipeline(&self.pipelines.gather);
        pass.set_bind_group(0, bind_group, &[]);
        pass.dispatch_workgroups(size[0].div_ceil(8), size[1].div_ceil(8), 1);
    }
}
