//! Rendering a [`Frame`]: mesh upload (cached per mesh `Arc`), per-frame object and wave buffers,
//! and the tile loop — each tile is rasterized, integrated and read back on its own (or, in
//! `present.rs`, drawn into a window texture), so GPU memory is bounded by the tile size whatever
//! the image size.

use crate::device::GpuContext;
use crate::layout::{
    self, FrameShadows, FrameUniforms, GpuCurve, GpuLight, GpuMaterial, GpuObject, GpuShadowCast, GpuSpotMap,
    GpuVertex, GpuWave, ShadingBuffers, SoftUniforms,
};
use crate::pipelines::{self, Pipelines, WaveVariant};
use crate::timing::PassQueries;
use bytemuck::Zeroable;
#[cfg(not(target_arch = "wasm32"))]
use hadou_scene::Image;
use hadou_scene::{Frame, LightLine, Mesh, RenderError, SoftResolve, MAX_SHADOWS};
use std::collections::HashMap;
use std::sync::{Arc, Weak};
use wgpu::util::DeviceExt;

/// Largest tile edge in pixels (smaller when the device's limits demand it).
pub const MAX_TILE: u32 = 1024;
/// Floats per pixel in the tile output buffer: colour (4), energy, eye distance.
const FLOATS_PER_PIXEL: u64 = 6;

/// A mesh on the GPU, with a weak handle to the `Arc<Mesh>` it came from (so a freed mesh whose
/// address is reused is never mistaken for the cached one).
struct CachedMesh {
    source: Weak<Mesh>,
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
}

/// The per-tile GPU resources, sized for one tile edge pair.
pub(crate) struct TileTargets {
    size: [u32; 2],
    /// G-buffer target 0: normal and eye distance (see raster.wgsl and `pipelines::SCENE_FORMAT`).
    scene_view: wgpu::TextureView,
    /// G-buffer target 1: texture coordinates, vertex colour, material.
    attributes_view: wgpu::TextureView,
    /// Depth of the raster pass, then of the plane-shadow pass.
    depth_view: wgpu::TextureView,
    /// The plane-shadow pass's target (`pipelines::PLANE_SHADOW_FORMAT`).
    plane_shadow_view: wgpu::TextureView,
    /// The tile's `FrameUniforms` (rewritten before each tile's submission).
    pub(crate) uniforms: wgpu::Buffer,
    /// The wave pass's output (see wave.wgsl binding 4), read by the present pass.
    pub(crate) output: wgpu::Buffer,
    staging: wgpu::Buffer,
}

/// Everything a frame's tiles share: buffers of this frame and the tile grid.
pub(crate) struct Prepared {
    pub(crate) tile: [u32; 2],
    pub(crate) tiles: Vec<([u32; 2], [u32; 2])>,
    objects: wgpu::Buffer,
    waves: wgpu::Buffer,
    /// Curve buffers (bindings 5–7 of the wave pass; see `layout::CurveBuffers`).
    curves: [wgpu::Buffer; 3],
    /// Materials, lights and shading data (bindings 8–10; see `layout::ShadingBuffers`).
    materials: wgpu::Buffer,
    lights: wgpu::Buffer,
    shading_data: wgpu::Buffer,
    draws: Vec<(usize, u32)>,
    /// Whether any object has an outlined material (then the hull pipeline runs).
    outlines: bool,
    /// The frame's shadow casts (bindings 3 of shadow_raster.wgsl).
    casts: wgpu::Buffer,
    /// (cast, object) per shadow draw (binding 4 of shadow_raster.wgsl): the plane draws, then the
    /// map draws.
    shadow_draws: wgpu::Buffer,
    /// The plane casts' draws in cast order: (instance = index into `shadow_draws`, object, index
    /// count).
    plane_draws: Vec<(u32, usize, u32)>,
    /// Where the cast records and map-cast indices are in the shading data, and their counts
    /// (the shadow fields of `FrameUniforms`).
    shadow_fields: ShadowFields,
    /// The shadow-map passes, one per map cast, and their bind group (`None` without map casts).
    map_passes: Vec<MapPass>,
    map_bind_group: Option<wgpu::BindGroup>,
    /// The wave pass's pipeline: the variant this frame needs (`pipelines::WaveVariant`).
    wave_pipeline: wgpu::ComputePipeline,
    /// Whether the tiles need the raster pass: false when nothing is drawn and the wave pass's
    /// variant does not read the G-buffer (no surfaces, no `[area_light]`), so an empty frame
    /// skips clearing 36 bytes per pixel.
    raster: bool,
    /// The tiles' bind groups, made once per frame (set at the end of `prepare`).
    groups: Option<TileBindGroups>,
}

/// The bind groups every tile of a frame uses (the tile's uniforms are rewritten before each
/// tile's submission, so one set serves them all).
struct TileBindGroups {
    raster: wgpu::BindGroup,
    wave: wgpu::BindGroup,
    /// Only when the frame has plane casts.
    plane: Option<wgpu::BindGroup>,
    /// Only with an `[area_light]`.
    soft: Option<wgpu::BindGroup>,
}

impl Prepared {
    /// The number of shadow-map passes (map casts) of the frame.
    pub(crate) fn map_pass_count(&self) -> u32 {
        self.map_passes.len() as u32
    }
}

/// The shadow fields of [`FrameUniforms`] for one frame.
#[derive(Clone, Copy, Debug, Default)]
struct ShadowFields {
    shadow_casts: u32,
    map_casts: u32,
    cast_count: u32,
    map_count: u32,
    plane_count: u32,
}

/// The frame's shadow maps: a `size² × layers` depth array texture, kept between frames while
/// its size stays the same.
struct ShadowMaps {
    size: u32,
    layers: u32,
    /// All layers, as the wave pass reads them.
    view: wgpu::TextureView,
    /// One view per layer, as the map passes draw them.
    layer_views: Vec<wgpu::TextureView>,
}

/// One shadow-map layer's pass: its layer, its edge in texels and its draws (instance = index into
/// the shadow draws, object, index count).
pub(crate) struct MapPass {
    layer: u32,
    edge: f32,
    draws: Vec<(u32, usize, u32)>,
}

/// The renderer's state between frames.
pub(crate) struct Renderer {
    pub(crate) ctx: GpuContext,
    pipelines: Pipelines,
    meshes: HashMap<usize, CachedMesh>,
    pub(crate) targets: Option<TileTargets>,
    maps: Option<ShadowMaps>,
    /// The `[area_light]`'s resources, kept while the image and map sizes hold.
    soft: Option<SoftTargets>,
    /// The present pass and its window texture, made on the first `render_to_texture`.
    pub(crate) present: Option<crate::present::Present>,
}

/// Every pixel's soft-shadow class (`hadou_math::soft::Class as u8`) and visibility, row-major.
#[cfg(not(target_arch = "wasm32"))]
pub type SoftReadback = (Vec<u8>, Vec<f32>);

/// Bytes per pixel of the whole-image soft-shadow buffers: the visible point and class (16), the
/// unit normal and the column pass's nearest rows (16), the visibility (4); the faithful grid adds
/// at most 4 more (`n = 1`).
pub const SOFT_BYTES_PER_PIXEL: u64 = 36;

/// The `[area_light]`'s GPU resources. Its soft shadows need the whole image at once: a first
/// sweep over the tiles rasterizes each and classifies its pixels into whole-image buffers
/// (`cs_classify`), the resolve then runs over the whole image (`cs_columns` + `cs_exact`, or
/// `cs_grid` + `cs_interp`), and each tile's wave pass takes its visibility (`cs_gather`).
/// GPU memory: [`SOFT_BYTES_PER_PIXEL`] (36, up to 40 with the faithful grid) bytes per image pixel
/// (604 MiB at the loader's limit of 4096² pixels, `SOFT_MAX_PIXELS`), plus 12 bytes per map texel
/// for the two maps and their shared depth buffer (12 MiB at `map_size` 1024).
struct SoftTargets {
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
}

impl SoftTargets {
    fn bind_group(
        &self,
        d: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        frame_uniforms: &wgpu::Buffer,
        scene: &wgpu::TextureView,
        attributes: &wgpu::TextureView,
        output: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        let view = wgpu::BindingResource::TextureView;
        d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("soft"),
            layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: frame_uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: self.uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: view(scene) },
                wgpu::BindGroupEntry { binding: 3, resource: view(attributes) },
                wgpu::BindGroupEntry { binding: 4, resource: view(&self.spot_views[0]) },
                wgpu::BindGroupEntry { binding: 5, resource: view(&self.spot_views[1]) },
                wgpu::BindGroupEntry { binding: 6, resource: self.world.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 7, resource: self.normal.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 8, resource: self.visibility.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 9, resource: self.grid.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 10, resource: output.as_entire_binding() },
            ],
        })
    }
}

/// Checks the frame's `[area_light]` against the device: the map edge within the largest 2D
/// texture, the whole-image buffers within the storage-buffer limits.
fn check_area_light(limits: &wgpu::Limits, frame: &Frame) -> Result<(), RenderError> {
    let Some(light) = &frame.area_light else { return Ok(()) };
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

fn other(msg: String) -> RenderError {
    RenderError::Other(msg)
}

/// Checks that a frame can be drawn at all, before any GPU work.
fn validate_frame(frame: &Frame) -> Result<(), RenderError> {
    if !(1..=16384).contains(&frame.width) || !(1..=16384).contains(&frame.height) {
        return Err(other(format!(
            "image size {}×{} is outside 1..=16384 in each dimension",
            frame.width, frame.height
        )));
    }
    let c = &frame.camera;
    if !(c.near > 0.0 && c.far > c.near && c.far.is_finite()) {
        return Err(other(format!(
            "camera near/far must satisfy 0 < near < far (got {}, {})",
            c.near, c.far
        )));
    }
    if !(c.fov_y_deg > 0.0 && c.fov_y_deg < 180.0) {
        return Err(other(format!("camera fov must be in (0, 180) degrees (got {})", c.fov_y_deg)));
    }
    for o in &frame.objects {
        let m = &o.mesh;
        if m.normals.len() != m.positions.len() {
            return Err(other(format!(
                "object `{}`: {} normals for {} positions",
                o.name,
                m.normals.len(),
                m.positions.len()
            )));
        }
        if m.indices.len() % 3 != 0 {
            return Err(other(format!(
                "object `{}`: {} indices is not a triangle list",
                o.name,
                m.indices.len()
            )));
        }
        if let Some(bad) = m.indices.iter().find(|&&i| i as usize >= m.positions.len()) {
            return Err(other(format!(
                "object `{}`: index {bad} out of range ({} vertices)",
                o.name,
                m.positions.len()
            )));
        }
    }
    if frame.shadows.len() > MAX_SHADOWS {
        return Err(other(format!(
            "{} shadows; at most {MAX_SHADOWS} fit (receivers carry one bit per shadow)",
            frame.shadows.len()
        )));
    }
    let objects = frame.objects.len();
    for s in &frame.shadows {
        if let Some(bad) = s.casters.iter().chain(&s.receivers).find(|&&o| o as usize >= objects) {
            return Err(other(format!(
                "shadow \"{}\": object index {bad} out of range ({objects} objects)",
                s.name
            )));
        }
    }
    Ok(())
}

/// Checks the frame's shadow maps against the device: each map's edge within the largest 2D
/// texture, their number within the array layers of one texture.
fn check_maps(limits: &wgpu::Limits, frame: &Frame, shadows: &FrameShadows) -> Result<(), RenderError> {
    for (i, g) in shadows.map_casts.iter().map(|&j| &shadows.casts[j as usize]).enumerate() {
        let name = &frame.shadows[g.shadow as usize].name;
        if g.map_size > limits.max_texture_dimension_2d {
            return Err(RenderError::Device(format!(
                "shadow \"{name}\": map_size {} exceeds this adapter's largest texture ({})",
                g.map_size, limits.max_texture_dimension_2d
            )));
        }
        if i as u32 >= limits.max_texture_array_layers {
            return Err(RenderError::Device(format!(
                "shadow \"{name}\": the frame needs {} shadow maps, more than this adapter's {} texture array \
                 layers",
                shadows.map_casts.len(),
                limits.max_texture_array_layers
            )));
        }
    }
    Ok(())
}

/// Allocates the host image, reporting (not aborting on) a failed allocation.
#[cfg(not(target_arch = "wasm32"))]
fn alloc_image(width: u32, height: u32) -> Result<Image, RenderError> {
    let n = width as usize * height as usize;
    let oom = |_| RenderError::Device(format!("out of host memory for a {width}×{height} image"));
    let mut color: Vec<[f32; 4]> = Vec::new();
    color.try_reserve_exact(n).map_err(oom)?;
    let mut energy: Vec<f32> = Vec::new();
    energy.try_reserve_exact(n).map_err(oom)?;
    let mut depth: Vec<f32> = Vec::new();
    depth.try_reserve_exact(n).map_err(oom)?;
    color.resize(n, [0.0; 4]);
    energy.resize(n, 0.0);
    depth.resize(n, 0.0);
    Ok(Image { width, height, color, energy, depth })
}

/// The tile edge pair for an image: at most [`MAX_TILE`], within the device's texture and buffer
/// limits.
fn tile_size(limits: &wgpu::Limits, width: u32, height: u32) -> Result<[u32; 2], RenderError> {
    let mut edge = MAX_TILE.min(limits.max_texture_dimension_2d);
    let max_bytes = limits.max_buffer_size.min(limits.max_storage_buffer_binding_size);
    while edge > 16 && (edge as u64).pow(2) * FLOATS_PER_PIXEL * 4 > max_bytes {
        edge /= 2;
    }
    if (edge as u64).pow(2) * FLOATS_PER_PIXEL * 4 > max_bytes || edge < 16 {
        return Err(RenderError::Device(format!(
            "device limits too small for the renderer (max texture {}, max buffer {} bytes)",
            limits.max_texture_dimension_2d, max_bytes
        )));
    }
    Ok([edge.min(width), edge.min(height)])
}

impl Renderer {
    /// Opens the device and compiles the pipelines.
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn new() -> Result<Self, RenderError> {
        Self::from_context(GpuContext::new()?)
    }

    /// Compiles the pipelines on an open device.
    pub(crate) fn from_context(ctx: GpuContext) -> Result<Self, RenderError> {
        let pipelines = Pipelines::new(&ctx)?;
        Ok(Self {
            ctx,
            pipelines,
            meshes: HashMap::new(),
            targets: None,
            maps: None,
            soft: None,
            present: None,
        })
    }

    /// See [`crate::GpuBackend::set_specialise`].
    pub(crate) fn set_specialise(&mut self, on: bool) {
        self.pipelines.specialise = on;
    }

    /// See [`crate::GpuBackend::wave_variants_built`].
    pub(crate) fn wave_variants_built(&self) -> usize {
        self.pipelines.wave_variant_count()
    }

    fn upload_meshes(&mut self, frame: &Frame) {
        self.meshes.retain(|_, m| m.source.strong_count() > 0);
        for o in &frame.objects {
            if o.mesh.indices.is_empty() {
                continue;
            }
            let key = Arc::as_ptr(&o.mesh) as usize;
            let fresh = self
                .meshes
                .get(&key)
                .is_some_and(|c| c.source.upgrade().is_some_and(|a| Arc::ptr_eq(&a, &o.mesh)));
            if fresh {
                continue;
            }
            let m = &o.mesh;
            let vertices: Vec<GpuVertex> = (0..m.positions.len())
                .map(|i| GpuVertex {
                    position: m.positions[i],
                    normal: m.normals[i],
                    outline_normal: m.outline_normals.get(i).copied().unwrap_or(m.normals[i]),
                    uv: m.uvs.get(i).copied().unwrap_or([0.0; 2]),
                    color: m.colors.get(i).copied().unwrap_or([1.0; 4]),
                    material: m.material_of(i),
                })
                .collect();
            let d = &self.ctx.device;
            let vb = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(&o.name),
                contents: bytemuck::cast_slice(&vertices),
                usage: wgpu::BufferUsages::VERTEX,
            });
            let ib = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(&o.name),
                contents: bytemuck::cast_slice(&m.indices),
                usage: wgpu::BufferUsages::INDEX,
            });
            self.meshes.insert(
                key,
                CachedMesh {
                    source: Arc::downgrade(&o.mesh),
                    vertices: vb,
                    indices: ib,
                    index_count: m.indices.len() as u32,
                },
            );
        }
    }

    fn ensure_targets(&mut self, size: [u32; 2]) {
        if self.targets.as_ref().is_some_and(|t| t.size == size) {
            return;
        }
        self.targets = None; // free the old ones first
        let d = &self.ctx.device;
        let extent = wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 };
        let texture = |label, format, usage| {
            d.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: extent,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
            .create_view(&Default::default())
        };
        let attach_and_read = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let scene_view = texture("normal and distance", pipelines::SCENE_FORMAT, attach_and_read);
        let attributes_view = texture("uv, colour and material", pipelines::SCENE_FORMAT, attach_and_read);
        let depth_view = texture("depth", pipelines::DEPTH_FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT);
        let plane_shadow_view = texture("plane shadows", pipelines::PLANE_SHADOW_FORMAT, attach_and_read);
        let bytes = size[0] as u64 * size[1] as u64 * FLOATS_PER_PIXEL * 4;
        let uniforms = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame uniforms"),
            size: std::mem::size_of::<FrameUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let output = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("tile output"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let staging = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("tile read-back"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        self.targets = Some(TileTargets {
            size,
            scene_view,
            attributes_view,
            depth_view,
            plane_shadow_view,
            uniforms,
            output,
            staging,
        });
    }

    /// Validates the frame, uploads what it needs, plans the tiles covering the rows `rows` and
    /// submits the shadow maps (and, with an `[area_light]`, the soft shadows). Not on the web,
    /// where only `render_to_texture` draws (through [`Renderer::prepare_frame`]).
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn prepare(
        &mut self,
        frame: &Frame,
        rows: std::ops::Range<u32>,
    ) -> Result<Prepared, RenderError> {
        self.prepare_frame(frame, rows, true)
    }

    /// [`Renderer::prepare`]; with `submit_maps` false the shadow maps are left for the caller to
    /// submit ([`Renderer::submit_shadow_maps`], e.g. with timestamps) before the tiles. Only for
    /// frames without an `[area_light]`, whose soft shadows are drawn here after the maps.
    pub(crate) fn prepare_frame(
        &mut self,
        frame: &Frame,
        rows: std::ops::Range<u32>,
        submit_maps: bool,
    ) -> Result<Prepared, RenderError> {
        debug_assert!(submit_maps || frame.area_light.is_none());
        self.ctx.check()?;
        validate_frame(frame)?;
        let tile = tile_size(&self.ctx.limits, frame.width, frame.height)?;
        let (waves, curve_data, prepared_curves) = layout::frame_waves(frame).map_err(other)?;
        let mut shading = ShadingBuffers::new(frame, &prepared_curves);
        // The waves' light lines, as the shading buffers hold them: the wave shadows' lights.
        let lines: Vec<LightLine> =
            frame.waves.iter().zip(&prepared_curves).map(|(w, c)| w.light_line(c.as_ref())).collect();
        let shadow_casts = frame.shadow_casts(&lines);
        let shadows = FrameShadows::new(frame, &shadow_casts);
        check_maps(&self.ctx.limits, frame, &shadows)?;
        check_area_light(&self.ctx.limits, frame)?;
        let (cast_offset, map_offset) = shading.push_shadows(&shadows);
        // Draws of the shadow passes: (cast, object) pairs, the plane casts' first, then each map
        // cast's; casters without triangles draw nothing.
        let mut draw_pairs: Vec<[u32; 2]> = Vec::new();
        let mut plane_draws = Vec::new();
        let mut map_draws: Vec<Vec<(u32, usize, u32)>> = vec![Vec::new(); shadows.map_casts.len()];
        let caster_draws = |j: usize| {
            shadow_casts[j].casters.iter().filter_map(|&o| {
                let count = frame.objects[o as usize].mesh.indices.len() as u32;
                (count > 0).then_some((o as usize, count))
            })
        };
        for (j, g) in shadows.casts.iter().enumerate() {
            if g.map_size == layout::CAST_PLANE {
                for (o, count) in caster_draws(j) {
                    plane_draws.push((draw_pairs.len() as u32, o, count));
                    draw_pairs.push([j as u32, o as u32]);
                }
            }
        }
        for (layer, &j) in shadows.map_casts.iter().enumerate() {
            for (o, count) in caster_draws(j as usize) {
                map_draws[layer].push((draw_pairs.len() as u32, o, count));
                draw_pairs.push([j, o as u32]);
            }
        }
        let shadow_fields = ShadowFields {
            shadow_casts: cast_offset,
            map_casts: map_offset,
            cast_count: shadows.casts.len() as u32,
            map_count: shadows.map_casts.len() as u32,
            plane_count: shadows.casts.len() as u32 - shadows.map_casts.len() as u32,
        };
        let objects: Vec<GpuObject> = frame
            .objects
            .iter()
            .zip(&shading.material_base)
            .map(|(o, &base)| GpuObject::new(o, base))
            .collect();
        let max_binding =
            self.ctx.limits.max_storage_buffer_binding_size.min(self.ctx.limits.max_buffer_size);
        let curve_bytes = [
            std::mem::size_of_val(curve_data.curves.as_slice()),
            std::mem::size_of_val(curve_data.vec4s.as_slice()),
            std::mem::size_of_val(curve_data.scalars.as_slice()),
        ];
        if let Some(&big) = curve_bytes.iter().find(|&&b| b as u64 > max_binding) {
            return Err(RenderError::Device(format!(
                "curve data of {big} bytes exceeds the device's storage buffer limit of {max_binding} bytes"
            )));
        }
        let data_bytes = std::mem::size_of_val(shading.data.as_slice()) as u64;
        if data_bytes > max_binding {
            return Err(RenderError::Device(format!(
                "the frame's textures take {data_bytes} bytes, more than the device's storage buffer limit of \
                 {max_binding} bytes; use smaller textures"
            )));
        }
        let variant = WaveVariant::of(
            &waves,
            &curve_data.curves,
            &shading.materials,
            // The lights shading.wgsl reads (MAX_LIGHTS there).
            &shading.lights[..shading.lights.len().min(256)],
            frame.waves.iter().any(|w| w.light.glow > 0.0),
            // Every object with triangles is drawn (upload_meshes).
            frame.objects.iter().any(|o| !o.mesh.indices.is_empty()),
            (shadow_fields.plane_count > 0, shadow_fields.map_count > 0),
            frame.area_light.is_some(),
            frame.color_mapping.mode == hadou_scene::ToneMode::Faithful,
        );
        let (wave_pipeline, variant) = self.pipelines.wave(&self.ctx, variant)?;
        let raster = variant.has("USE_SURFACES") || frame.area_light.is_some() || !plane_draws.is_empty();
        let (zero_object, zero_wave) = (GpuObject::zeroed(), GpuWave::zeroed());
        let scopes = self.ctx.open_scopes();
        let prepared = {
            self.upload_meshes(frame);
            self.ensure_targets(tile);
            self.ensure_maps(&shadows);
            let d = &self.ctx.device;
            // Storage bindings may not be empty: pad with one zeroed element.
            let objects = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("objects"),
                contents: if objects.is_empty() {
                    bytemuck::bytes_of(&zero_object)
                } else {
                    bytemuck::cast_slice(&objects)
                },
                usage: wgpu::BufferUsages::STORAGE,
            });
            let waves = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("waves"),
                contents: if waves.is_empty() {
                    bytemuck::bytes_of(&zero_wave)
                } else {
                    bytemuck::cast_slice(&waves)
                },
                usage: wgpu::BufferUsages::STORAGE,
            });
            let storage = |label: &str, bytes: &[u8]| {
                d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    // Storage bindings may not be empty: one zeroed 16-byte element instead.
                    contents: if bytes.is_empty() { &[0u8; 16] } else { bytes },
                    usage: wgpu::BufferUsages::STORAGE,
                })
            };
            let zero_curve = [GpuCurve::zeroed()];
            let curves = [
                storage(
                    "curves",
                    bytemuck::cast_slice(if curve_data.curves.is_empty() {
                        &zero_curve[..]
                    } else {
                        &curve_data.curves[..]
                    }),
                ),
                storage("curve vec4s", bytemuck::cast_slice(&curve_data.vec4s)),
                storage("curve scalars", bytemuck::cast_slice(&curve_data.scalars)),
            ];
            let (zero_material, zero_light) = ([GpuMaterial::zeroed()], [GpuLight::zeroed()]);
            let materials = storage(
                "materials",
                bytemuck::cast_slice(if shading.materials.is_empty() {
                    &zero_material[..]
                } else {
                    &shading.materials[..]
                }),
            );
            let lights = storage(
                "lights",
                bytemuck::cast_slice(if shading.lights.is_empty() {
                    &zero_light[..]
                } else {
                    &shading.lights[..]
                }),
            );
            let shading_data = storage("shading data", bytemuck::cast_slice(&shading.data));
            let outlines = shading.materials.iter().any(|m| m.outline_width > 0.0);
            let zero_cast = [GpuShadowCast::zeroed()];
            let casts = storage(
                "shadow casts",
                bytemuck::cast_slice(if shadows.casts.is_empty() {
                    &zero_cast[..]
                } else {
                    &shadows.casts[..]
                }),
            );
            let shadow_draws = storage("shadow draws", bytemuck::cast_slice(&draw_pairs));
            let draws = frame
                .objects
                .iter()
                .enumerate()
                .filter_map(|(i, o)| {
                    let c = self.meshes.get(&(Arc::as_ptr(&o.mesh) as usize))?;
                    Some((i, c.index_count))
                })
                .collect();
            let mut tiles = Vec::new();
            for y in rows.clone().step_by(tile[1] as usize) {
                for x in (0..frame.width).step_by(tile[0] as usize) {
                    tiles.push(([x, y], [tile[0].min(frame.width - x), tile[1].min(rows.end - y)]));
                }
            }
            let map_passes: Vec<MapPass> = map_draws
                .into_iter()
                .enumerate()
                .map(|(layer, draws)| MapPass {
                    layer: layer as u32,
                    edge: shadows.casts[shadows.map_casts[layer] as usize].map_size as f32,
                    draws,
                })
                .collect();
            let map_bind_group = (!map_passes.is_empty()).then(|| {
                d.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("shadow maps"),
                    layout: &self.pipelines.shadow_map_layout,
                    entries: &[
                        wgpu::BindGroupEntry { binding: 1, resource: objects.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 3, resource: casts.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 4, resource: shadow_draws.as_entire_binding() },
                    ],
                })
            });
            let prepared = Prepared {
                tile,
                tiles,
                objects,
                waves,
                curves,
                materials,
                lights,
                shading_data,
                draws,
                outlines,
                casts,
                shadow_draws,
                plane_draws,
                shadow_fields,
                map_passes,
                map_bind_group,
                wave_pipeline,
                raster,
                groups: None,
            };
            if submit_maps || frame.area_light.is_some() {
                self.submit_shadow_maps(frame, &prepared, None);
            }
            if frame.area_light.is_some() {
                self.ensure_soft(frame);
            }
            let mut prepared = prepared;
            prepared.groups = Some(self.tile_bind_groups(frame, &prepared));
            if frame.area_light.is_some() {
                self.draw_soft(frame, &prepared);
            }
            prepared
        };
        self.ctx.close_scopes(scopes, "uploading the frame")?;
        Ok(prepared)
    }

    /// Makes the soft-shadow resources fit `frame` (which has an `[area_light]`) and writes their
    /// uniforms.
    fn ensure_soft(&mut self, frame: &Frame) {
        let light = frame.area_light.as_ref().expect("an area light");
        let n = match light.resolve {
            SoftResolve::Exact => 0,
            SoftResolve::Faithful { n } => n.max(1),
        };
        let gs = grid_size(frame.width, frame.height, n.max(1));
        let grid_len = if n == 0 { 1 } else { gs[0] * gs[1] };
        let key = (frame.width, frame.height, light.map_size.max(1), grid_len);
        if self.soft.as_ref().is_none_or(|s| s.key != key) {
            self.soft = None; // free the old ones first
            let d = &self.ctx.device;
            let size = key.2;
            let texture = |label, format| {
                d.create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: 1 },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
                    view_formats: &[],
                })
                .create_view(&Default::default())
            };
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
            self.soft = Some(SoftTargets {
                key,
                spot_views: [
                    texture("soft map 1", pipelines::SPOT_FORMAT),
                    texture("soft map 2", pipelines::SPOT_FORMAT),
                ],
                spot_depth: texture("soft map depth", pipelines::MAP_FORMAT),
                spot_uniforms: [buffer("soft map 1", spot, uniform), buffer("soft map 2", spot, uniform)],
                uniforms: buffer("soft uniforms", std::mem::size_of::<SoftUniforms>() as u64, uniform),
                world: buffer("soft points", pixels * 16, storage),
                normal: buffer("soft normals", pixels * 16, storage),
                visibility: buffer("soft visibility", pixels * 4, storage),
                grid: buffer("soft grid", grid_len as u64 * 4, storage),
            });
        }
        let soft = self.soft.as_ref().expect("created above");
        let maps = light.maps.map(|m| GpuSpotMap::new(&m, key.2));
        let q = &self.ctx.queue;
        q.write_buffer(&soft.spot_uniforms[0], 0, bytemuck::bytes_of(&maps[0]));
        q.write_buffer(&soft.spot_uniforms[1], 0, bytemuck::bytes_of(&maps[1]));
        let u = SoftUniforms {
            maps,
            depth_aware: u32::from(light.depth_aware),
            grid: n,
            grid_size: gs,
            ratio: light.penumbra_ratio(),
            _pad: [0; 3],
        };
        q.write_buffer(&soft.uniforms, 0, bytemuck::bytes_of(&u));
    }

    /// The `[area_light]`'s soft shadows over the whole image: its two maps (soft_map.wgsl), every
    /// tile rasterized and classified, then the resolve; the wave passes read the visibility.
    fn draw_soft(&self, frame: &Frame, prepared: &Prepared) {
        let soft = self.soft.as_ref().expect("created in ensure_soft");
        let d = &self.ctx.device;
        // Only the area light's casters are drawn into its maps (hadou-cpu's `spot_tris`).
        let casters = frame.area_light.as_ref().map_or(&[][..], |l| &l.casters[..]);
        let caster_draws: Vec<(usize, u32)> =
            prepared.draws.iter().copied().filter(|&(o, _)| casters.contains(&(o as u32))).collect();
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("soft maps") });
        for k in 0..2 {
            let bg = d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("soft map"),
                layout: &self.pipelines.spot_map_layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: soft.spot_uniforms[k].as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: prepared.objects.as_entire_binding() },
                ],
            });
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("soft map"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &soft.spot_views[k],
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
                    view: &soft.spot_depth,
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
            let edge = soft.key.2 as f32;
            pass.set_viewport(0.0, 0.0, edge, edge, 0.0, 1.0);
            pass.set_pipeline(&self.pipelines.spot_map);
            pass.set_bind_group(0, &bg, &[]);
            self.draw_objects(&mut pass, frame, &caster_draws);
        }
        self.ctx.queue.submit([enc.finish()]);
        // Every tile of the image, whatever rows are asked for: the search needs them all.
        let tile = prepared.tile;
        for y in (0..frame.height).step_by(tile[1] as usize) {
            for x in (0..frame.width).step_by(tile[0] as usize) {
                let t = ([x, y], [tile[0].min(frame.width - x), tile[1].min(frame.height - y)]);
                let enc = self.encode_tile_passes(frame, prepared, t, false, None, true);
                self.ctx.queue.submit([enc.finish()]);
            }
        }
        let t = self.targets.as_ref().expect("targets are created in prepare");
        let soft = self.soft.as_ref().expect("created in ensure_soft");
        let bg = soft.bind_group(
            d,
            &self.pipelines.soft_layout,
            &t.uniforms,
            &t.scene_view,
            &t.attributes_view,
            &t.output,
        );
        let (w, h) = (frame.width, frame.height);
        let mut enc =
            d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("soft resolve") });
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_bind_group(0, &bg, &[]);
            let p = &self.pipelines.soft;
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
        self.ctx.queue.submit([enc.finish()]);
    }

    /// Draws every `(object, index count)` of `draws` with its cached mesh, the object's index as
    /// the instance (objects without a cached mesh draw nothing).
    fn draw_objects(&self, pass: &mut wgpu::RenderPass<'_>, frame: &Frame, draws: &[(usize, u32)]) {
        for &(object, index_count) in draws {
            let key = Arc::as_ptr(&frame.objects[object].mesh) as usize;
            let Some(mesh) = self.meshes.get(&key) else { continue };
            pass.set_vertex_buffer(0, mesh.vertices.slice(..));
            pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..index_count, 0, object as u32..object as u32 + 1);
        }
    }

    /// After [`Renderer::render`] of a frame with an `[area_light]`: every pixel's soft-shadow
    /// class (`hadou_math::soft::Class` as `u8`) and visibility, read back (for tests).
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn read_soft(&self, frame: &Frame) -> Result<Option<SoftReadback>, RenderError> {
        let Some(soft) = self.soft.as_ref().filter(|_| frame.area_light.is_some()) else { return Ok(None) };
        let pixels = frame.width as u64 * frame.height as u64;
        let read = |src: &wgpu::Buffer, bytes: u64| -> Result<Vec<u32>, RenderError> {
            let staging = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("soft read-back"),
                size: bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let mut enc = self.ctx.device.create_command_encoder(&Default::default());
            enc.copy_buffer_to_buffer(src, 0, &staging, 0, bytes);
            let submission = self.ctx.queue.submit([enc.finish()]);
            let mut out = Vec::new();
            self.ctx.read_buffer(&staging, bytes, submission, |raw| {
                out = raw.chunks_exact(4).map(|c| u32::from_ne_bytes([c[0], c[1], c[2], c[3]])).collect();
            })?;
            Ok(out)
        };
        let world = read(&soft.world, pixels * 16)?;
        let vis = read(&soft.visibility, pixels * 4)?;
        let class = world.chunks_exact(4).map(|p| p[3] as u8).collect();
        Ok(Some((class, vis.into_iter().map(f32::from_bits).collect())))
    }

    /// Makes the shadow-map texture fit `shadows` (at least 1² × 2 texels: the wave pass binds one
    /// even without map casts); kept while its size holds.
    fn ensure_maps(&mut self, shadows: &FrameShadows) {
        let (size, layers) = (shadows.map_size.max(1), shadows.map_layers.max(2));
        if self.maps.as_ref().is_some_and(|m| m.size == size && m.layers == layers) {
            return;
        }
        self.maps = None; // free the old one first
        let texture = self.ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow maps"),
            size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: layers },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: pipelines::MAP_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("shadow maps"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let layer_views = (0..layers)
            .map(|layer| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some("shadow map layer"),
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        self.maps = Some(ShadowMaps { size, layers, view, layer_views });
    }

    /// Records every map cast's casters into its layer of the shadow maps (nothing when the frame
    /// has no map casts), one render pass per layer.
    pub(crate) fn encode_shadow_maps(
        &self,
        enc: &mut wgpu::CommandEncoder,
        frame: &Frame,
        prepared: &Prepared,
        mut timestamps: Option<&mut PassQueries<'_>>,
    ) {
        let Some(bind_group) = &prepared.map_bind_group else { return };
        let maps = self.maps.as_ref().expect("shadow maps are created in prepare");
        if let Some(q) = timestamps.as_deref_mut() {
            q.next_group();
        }
        for m in &prepared.map_passes {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow map"),
                color_attachments: &[],
                depth_stencil_attachment: cleared_depth(
                    &maps.layer_views[m.layer as usize],
                    wgpu::StoreOp::Store,
                ),
                timestamp_writes: timestamps.as_deref_mut().and_then(|q| q.render("shadow maps")),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            // Texel (x, y) covers the map's pixel x = ⌊s·size⌋, y = ⌊(1 − t)·size⌋.
            pass.set_viewport(0.0, 0.0, m.edge, m.edge, 0.0, 1.0);
            pass.set_pipeline(&self.pipelines.shadow_map);
            pass.set_bind_group(0, bind_group, &[]);
            for &(instance, object, index_count) in &m.draws {
                let key = Arc::as_ptr(&frame.objects[object].mesh) as usize;
                let Some(mesh) = self.meshes.get(&key) else { continue };
                pass.set_vertex_buffer(0, mesh.vertices.slice(..));
                pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..index_count, 0, instance..instance + 1);
            }
        }
    }

    /// Submits the frame's shadow maps (see [`Renderer::encode_shadow_maps`]); `None` when it has
    /// none.
    pub(crate) fn submit_shadow_maps(
        &self,
        frame: &Frame,
        prepared: &Prepared,
        timestamps: Option<&mut PassQueries<'_>>,
    ) -> Option<wgpu::SubmissionIndex> {
        prepared.map_bind_group.as_ref()?;
        let mut enc = self
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("shadow maps") });
        self.encode_shadow_maps(&mut enc, frame, prepared, timestamps);
        Some(self.ctx.queue.submit([enc.finish()]))
    }

    /// Encodes and submits every tile of `prepared` (no read-back), one submission per tile;
    /// the last submission.
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn submit_tiles(
        &self,
        frame: &Frame,
        prepared: &Prepared,
        mut timestamps: Option<&mut PassQueries<'_>>,
    ) -> Option<wgpu::SubmissionIndex> {
        let mut last = None;
        for &t in &prepared.tiles {
            let enc = self.encode_tile(frame, prepared, t, false, timestamps.as_deref_mut());
            last = Some(self.ctx.queue.submit([enc.finish()]));
        }
        last
    }

    /// The bind groups of `prepared`'s tiles (after its shadow maps and soft-shadow resources
    /// exist).
    fn tile_bind_groups(&self, frame: &Frame, prepared: &Prepared) -> TileBindGroups {
        let t = self.targets.as_ref().expect("targets are created in prepare");
        let d = &self.ctx.device;
        let raster = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("raster"),
            layout: &self.pipelines.raster_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: t.uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: prepared.objects.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: prepared.materials.as_entire_binding() },
            ],
        });
        let wave = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("wave"),
            layout: &self.pipelines.wave_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: t.uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: prepared.waves.as_entire_binding() },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&t.scene_view),
                },
                wgpu::BindGroupEntry { binding: 4, resource: t.output.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 5, resource: prepared.curves[0].as_entire_binding() },
                wgpu::BindGroupEntry { binding: 6, resource: prepared.curves[1].as_entire_binding() },
                wgpu::BindGroupEntry { binding: 7, resource: prepared.curves[2].as_entire_binding() },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(&t.attributes_view),
                },
                wgpu::BindGroupEntry { binding: 8, resource: prepared.materials.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 9, resource: prepared.lights.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 10, resource: prepared.shading_data.as_entire_binding() },
                wgpu::BindGroupEntry {
                    binding: 11,
                    resource: wgpu::BindingResource::TextureView(&t.plane_shadow_view),
                },
                wgpu::BindGroupEntry {
                    binding: 12,
                    resource: wgpu::BindingResource::TextureView(
                        &self.maps.as_ref().expect("shadow maps are created in prepare").view,
                    ),
                },
            ],
        });
        let plane = (!prepared.plane_draws.is_empty()).then(|| {
            self.ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("plane shadows"),
                layout: &self.pipelines.plane_shadow_layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: t.uniforms.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: prepared.objects.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: prepared.materials.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 3, resource: prepared.casts.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 4, resource: prepared.shadow_draws.as_entire_binding() },
                    wgpu::BindGroupEntry {
                        binding: 5,
                        resource: wgpu::BindingResource::TextureView(&t.scene_view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 6,
                        resource: wgpu::BindingResource::TextureView(&t.attributes_view),
                    },
                ],
            })
        });
        let soft = self.soft.as_ref().filter(|_| frame.area_light.is_some()).map(|soft| {
            soft.bind_group(
                d,
                &self.pipelines.soft_layout,
                &t.uniforms,
                &t.scene_view,
                &t.attributes_view,
                &t.output,
            )
        });
        TileBindGroups { raster, wave, plane, soft }
    }

    /// Records one tile's passes — raster (unless the frame skips it), plane shadows, the soft
    /// shadows' gather, wave — and, when `readback`, the copy to the staging buffer, after writing
    /// its uniforms. The tiles share one uniform buffer, so submit each tile before encoding the
    /// next. `timestamps`: every pass gets a query pair, the tile a group of its own.
    pub(crate) fn encode_tile(
        &self,
        frame: &Frame,
        prepared: &Prepared,
        tile: ([u32; 2], [u32; 2]),
        readback: bool,
        timestamps: Option<&mut PassQueries<'_>>,
    ) -> wgpu::CommandEncoder {
        self.encode_tile_passes(frame, prepared, tile, readback, timestamps, false)
    }

    /// [`Renderer::encode_tile`], or with `classify` the raster pass then the soft shadows'
    /// classification of the tile's pixels (soft.wgsl `cs_classify`) instead of the other passes.
    fn encode_tile_passes(
        &self,
        frame: &Frame,
        prepared: &Prepared,
        tile: ([u32; 2], [u32; 2]),
        readback: bool,
        mut timestamps: Option<&mut PassQueries<'_>>,
        classify: bool,
    ) -> wgpu::CommandEncoder {
        if let Some(q) = timestamps.as_deref_mut() {
            q.next_group();
        }
        let t = self.targets.as_ref().expect("targets are created in prepare");
        let basis = frame.camera.basis(frame.width, frame.height);
        let (origin, size) = tile;
        let mut uniforms = FrameUniforms::new(frame, &basis, origin, size);
        let sf = prepared.shadow_fields;
        uniforms.shadow_casts = sf.shadow_casts;
        uniforms.map_casts = sf.map_casts;
        uniforms.cast_count = sf.cast_count;
        uniforms.map_count = sf.map_count;
        uniforms.plane_count = sf.plane_count;
        self.ctx.queue.write_buffer(&t.uniforms, 0, bytemuck::bytes_of(&uniforms));
        let groups = prepared.groups.as_ref().expect("bind groups are made in prepare");
        let d = &self.ctx.device;
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("tile") });
        if prepared.raster || classify {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("raster"),
                // Cleared to zero bits: distance 0 marks "nothing drawn".
                color_attachments: &[cleared_color(&t.scene_view), cleared_color(&t.attributes_view)],
                depth_stencil_attachment: cleared_depth(&t.depth_view, wgpu::StoreOp::Discard),
                timestamp_writes: timestamps.as_deref_mut().and_then(|q| q.render("raster")),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_viewport(0.0, 0.0, size[0] as f32, size[1] as f32, 0.0, 1.0);
            let hull = [(&self.pipelines.raster, true), (&self.pipelines.hull, prepared.outlines)];
            for (pipeline, enabled) in hull {
                if !enabled {
                    continue;
                }
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &groups.raster, &[]);
                self.draw_objects(&mut pass, frame, &prepared.draws);
            }
        }
        let soft_bg = groups.soft.as_ref().filter(|_| frame.area_light.is_some());
        if classify {
            if let Some(bg) = soft_bg {
                let mut pass = enc.begin_compute_pass(&Default::default());
                pass.set_pipeline(&self.pipelines.soft.classify);
                pass.set_bind_group(0, bg, &[]);
                pass.dispatch_workgroups(size[0].div_ceil(8), size[1].div_ceil(8), 1);
            }
            return enc;
        }
        if groups.plane.is_some() {
            self.encode_plane_shadows(&mut enc, frame, prepared, t, size, timestamps.as_deref_mut());
        }
        if let Some(bg) = soft_bg {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("soft gather"),
                timestamp_writes: timestamps.as_deref_mut().and_then(|q| q.compute("soft gather")),
            });
            pass.set_pipeline(&self.pipelines.soft.gather);
            pass.set_bind_group(0, bg, &[]);
            pass.dispatch_workgroups(size[0].div_ceil(8), size[1].div_ceil(8), 1);
        }
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("wave"),
                timestamp_writes: timestamps.and_then(|q| q.compute("wave")),
            });
            pass.set_pipeline(&prepared.wave_pipeline);
            pass.set_bind_group(0, &groups.wave, &[]);
            let g = pipelines::WAVE_WORKGROUP;
            pass.dispatch_workgroups(size[0].div_ceil(g), size[1].div_ceil(g), 1);
        }
        if readback {
            let bytes = size[0] as u64 * size[1] as u64 * FLOATS_PER_PIXEL * 4;
            enc.copy_buffer_to_buffer(&t.output, 0, &t.staging, 0, bytes);
        }
        enc
    }

    /// Records the plane-shadow pass of a tile (shadow_raster.wgsl): each plane cast's casters
    /// projected onto its plane, keeping per pixel the most opaque cast that shows there.
    fn encode_plane_shadows(
        &self,
        enc: &mut wgpu::CommandEncoder,
        frame: &Frame,
        prepared: &Prepared,
        t: &TileTargets,
        size: [u32; 2],
        timestamps: Option<&mut PassQueries<'_>>,
    ) {
        let Some(bind_group) = prepared.groups.as_ref().and_then(|g| g.plane.as_ref()) else { return };
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("plane shadows"),
            // 0: no plane cast.
            color_attachments: &[cleared_color(&t.plane_shadow_view)],
            depth_stencil_attachment: cleared_depth(&t.depth_view, wgpu::StoreOp::Discard),
            timestamp_writes: timestamps.and_then(|q| q.render("plane shadows")),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_viewport(0.0, 0.0, size[0] as f32, size[1] as f32, 0.0, 1.0);
        pass.set_pipeline(&self.pipelines.plane_shadow);
        pass.set_bind_group(0, bind_group, &[]);
        for &(instance, object, index_count) in &prepared.plane_draws {
            let key = Arc::as_ptr(&frame.objects[object].mesh) as usize;
            let Some(mesh) = self.meshes.get(&key) else { continue };
            pass.set_vertex_buffer(0, mesh.vertices.slice(..));
            pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..index_count, 0, instance..instance + 1);
        }
    }

    /// Renders `frame` into a new [`Image`].
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn render(&mut self, frame: &Frame) -> Result<Image, RenderError> {
        self.render_rows(frame, 0..frame.height)
    }

    /// Renders the rows `rows` of `frame` (clamped to the image) into a `frame.width ×
    /// rows.len()` [`Image`]: only the tiles of those rows are drawn.
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn render_rows(
        &mut self,
        frame: &Frame,
        rows: std::ops::Range<u32>,
    ) -> Result<Image, RenderError> {
        let (y0, y1) = (rows.start.min(frame.height), rows.end.min(frame.height));
        let rows = y0..y1.max(y0);
        let prepared = self.prepare(frame, rows.clone())?;
        let mut image = alloc_image(frame.width, rows.len() as u32)?;
        for &tile in &prepared.tiles {
            let submission = self.ctx.scoped("rendering a tile", || {
                let enc = self.encode_tile(frame, &prepared, tile, true, None);
                self.ctx.queue.submit([enc.finish()])
            })?;
            let (origin, size) = tile;
            let origin = [origin[0], origin[1] - rows.start];
            let n = size[0] as usize * size[1] as usize;
            let bytes = n as u64 * FLOATS_PER_PIXEL * 4;
            let staging = &self.targets.as_ref().expect("targets exist").staging;
            self.ctx.read_buffer(staging, bytes, submission, |raw| {
                copy_tile(&mut image, raw, origin, size);
            })?;
        }
        let _ = prepared.tile;
        Ok(image)
    }
}

/// A colour attachment cleared to zero bits and stored.
fn cleared_color(view: &wgpu::TextureView) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations {
            load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
            store: wgpu::StoreOp::Store,
        },
    })
}

/// A depth attachment cleared to 1 (the far plane; in a shadow map, "no caster").
fn cleared_depth(
    view: &wgpu::TextureView,
    store: wgpu::StoreOp,
) -> Option<wgpu::RenderPassDepthStencilAttachment<'_>> {
    Some(wgpu::RenderPassDepthStencilAttachment {
        view,
        depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store }),
        stencil_ops: None,
    })
}

/// Copies one tile's read-back bytes (layout: see the output binding in wave.wgsl) into `image`.
#[cfg(not(target_arch = "wasm32"))]
fn copy_tile(image: &mut Image, raw: &[u8], origin: [u32; 2], size: [u32; 2]) {
    let n = size[0] as usize * size[1] as usize;
    let floats: Vec<f32>;
    let data: &[f32] = match bytemuck::try_cast_slice(raw) {
        Ok(f) => f,
        Err(_) => {
            floats = raw.chunks_exact(4).map(|c| f32::from_ne_bytes([c[0], c[1], c[2], c[3]])).collect();
            &floats
        }
    };
    let (color, rest) = data.split_at(4 * n);
    let (energy, depth) = rest.split_at(n);
    let w = size[0] as usize;
    for row in 0..size[1] as usize {
        let dst = image.index(origin[0], origin[1] + row as u32);
        let src = row * w;
        for (k, px) in image.color[dst..dst + w].iter_mut().enumerate() {
            px.copy_from_slice(&color[4 * (src + k)..4 * (src + k) + 4]);
        }
        image.energy[dst..dst + w].copy_from_slice(&energy[src..src + w]);
        image.depth[dst..dst + w].copy_from_slice(&depth[src..src + w]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipelines::compile_module;

    /// A renderer with the crate's GPU test lock, or `None` with a skip message (a failure under
    /// `HADOU_REQUIRE_GPU=1`).
    fn renderer_or_skip(test: &str) -> Option<(Renderer, std::sync::MutexGuard<'static, ()>)> {
        let lock = crate::device::test_gpu_lock();
        match Renderer::new() {
            Ok(r) => Some((r, lock)),
            Err(RenderError::NoDevice(m)) => {
                assert!(std::env::var("HADOU_REQUIRE_GPU").map_or(true, |v| v != "1"), "{test}: {m}");
                eprintln!("SKIPPED {test}: no GPU adapter ({m})");
                None
            }
            Err(e) => panic!("{test}: {e}"),
        }
    }

    #[test]
    fn tile_size_follows_the_device_limits() {
        let mut limits = wgpu::Limits::downlevel_defaults();
        assert_eq!(tile_size(&limits, 5000, 300).unwrap(), [MAX_TILE, 300]);
        assert_eq!(tile_size(&limits, 7, 5).unwrap(), [7, 5]);
        limits.max_texture_dimension_2d = 512;
        assert_eq!(tile_size(&limits, 5000, 5000).unwrap(), [512, 512]);
        // A 1 MiB buffer limit: 6 floats per pixel fit a 128² tile, not 256².
        limits.max_buffer_size = 1 << 20;
        assert_eq!(tile_size(&limits, 5000, 5000).unwrap(), [128, 128]);
        limits.max_buffer_size = 1000;
        assert!(matches!(tile_size(&limits, 5000, 5000), Err(RenderError::Device(_))));
    }

    /// [`small_frame`] with three triangle objects `o0..o2` side by side at height 1, the
    /// triangle's third vertex raised by `tip`.
    fn three_triangles(tip: f32) -> Frame {
        let mut frame = small_frame();
        let mesh = Arc::new(Mesh {
            positions: vec![[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [0.0, tip, 1.0]],
            normals: vec![[0.0, 1.0, 0.0]; 3],
            indices: vec![0, 1, 2],
            ..Mesh::default()
        });
        for i in 0..3 {
            let at = hadou_math::Mat4::from_trs(
                hadou_math::Vec3::new(i as f32, 1.0, 0.0),
                hadou_math::Vec3::ZERO,
                hadou_math::Vec3::splat(1.0),
            );
            frame.objects.push(hadou_scene::Object::new(format!("o{i}"), mesh.clone(), at, [1.0; 3]));
        }
        frame
    }

    #[test]
    fn shadow_maps_are_checked_against_the_device_limits() {
        use hadou_scene::{Shadow, ShadowLight, ShadowMethod};
        let mut frame = three_triangles(0.0);
        let map = |name: &str, size: u32| Shadow {
            name: name.into(),
            light: ShadowLight::Sun(-hadou_math::Vec3::Y),
            method: ShadowMethod::Map { size },
            up: hadou_math::Vec3::Y,
            casters: vec![0],
            receivers: vec![1],
            color: [0.0; 3],
            opacity: 0.5,
        };
        frame.shadows = vec![map("a", 512), map("b", 4096), map("c", 16)];
        let shadows = FrameShadows::new(&frame, &frame.shadow_casts(&[]));
        assert_eq!(shadows.map_casts, [0, 1, 2]);
        assert_eq!((shadows.map_size, shadows.map_layers), (4096, 3));
        let mut limits = wgpu::Limits::downlevel_defaults();
        limits.max_texture_dimension_2d = 8192;
        assert!(check_maps(&limits, &frame, &shadows).is_ok());
        limits.max_texture_dimension_2d = 2048;
        match check_maps(&limits, &frame, &shadows) {
            Err(RenderError::Device(m)) => {
                assert_eq!(m, "shadow \"b\": map_size 4096 exceeds this adapter's largest texture (2048)")
            }
            other => panic!("expected a size error, got {other:?}"),
        }
        limits.max_texture_dimension_2d = 8192;
        limits.max_texture_array_layers = 2;
        match check_maps(&limits, &frame, &shadows) {
            Err(RenderError::Device(m)) => {
                assert!(m.starts_with("shadow \"c\": the frame needs 3 shadow maps"), "{m}")
            }
            other => panic!("expected a layer error, got {other:?}"),
        }
    }

    /// Plane casts get depth keys by decreasing opacity (equal opacities share one, so the first
    /// drawn keeps the pixel); receivers' materials carry their shadows' bits.
    #[test]
    fn plane_casts_rank_by_opacity_and_receivers_carry_their_bits() {
        use hadou_math::shadow::Plane;
        use hadou_scene::{Shadow, ShadowLight, ShadowMethod};
        let mut frame = three_triangles(0.5);
        let plane = |opacity: f32, receivers: Vec<u32>| Shadow {
            name: format!("{opacity}"),
            light: ShadowLight::Sun(-hadou_math::Vec3::Y),
            method: ShadowMethod::Plane(Plane { point: hadou_math::Vec3::ZERO, normal: hadou_math::Vec3::Y }),
            up: hadou_math::Vec3::Y,
            casters: vec![0],
            receivers,
            color: [0.1, 0.2, 0.3],
            opacity,
        };
        frame.shadows =
            vec![plane(0.3, vec![1]), plane(0.9, vec![1, 2]), plane(0.3, vec![2]), plane(0.5, vec![])];
        let casts = frame.shadow_casts(&[]);
        let shadows = FrameShadows::new(&frame, &casts);
        let keys: Vec<f32> = shadows.casts.iter().map(|c| c.depth_key).collect();
        let step = 1.0 / (1u32 << 24) as f32;
        assert_eq!(keys, [2.0 * step, 0.0, 2.0 * step, step]);
        assert!(shadows.casts.iter().all(|c| c.map_size == layout::CAST_PLANE && c.color == [0.1, 0.2, 0.3]));
        assert_eq!((shadows.map_casts.len(), shadows.map_layers), (0, 2));
        let buffers = ShadingBuffers::new(&frame, &[]);
        let masks: Vec<u32> = buffers.materials.iter().map(|m| m.shadow_mask).collect();
        assert_eq!(masks, [0b0000, 0b0011, 0b0110]);
    }

    #[test]
    fn shader_compile_failure_is_an_error_naming_the_shader() {
        let Some((r, _gpu)) = renderer_or_skip("shader compile failure") else { return };
        match compile_module(&r.ctx, "deliberately broken", "fn f( -> { let }") {
            Err(RenderError::Other(m)) => assert!(m.contains("deliberately broken"), "{m}"),
            other => panic!("expected a compile error, got {:?}", other.map(|_| ())),
        }
        // A valid module still compiles afterwards.
        assert!(compile_module(&r.ctx, "fine", "fn f() -> f32 { return 1.0; }").is_ok());
    }

    #[test]
    fn rejected_gpu_work_is_captured_not_panicking() {
        let Some((r, _gpu)) = renderer_or_skip("captured validation error") else { return };
        let too_big = r.ctx.limits.max_buffer_size.saturating_add(4);
        let result = r.ctx.scoped("allocating an impossible buffer", || {
            r.ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("too big"),
                size: too_big,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            })
        });
        match result {
            Err(RenderError::Other(m) | RenderError::Device(m)) => {
                assert!(m.contains("impossible buffer"), "{m}")
            }
            other => panic!("expected an error, got {:?}", other.map(|_| ())),
        }
        assert!(r.ctx.check().is_ok(), "the error was captured by the scope, not left over");
    }

    fn small_frame() -> Frame {
        hadou_scene::Frame {
            width: 8,
            height: 8,
            time: 0.0,
            camera: hadou_scene::Camera {
                position: hadou_math::Vec3::new(0.0, 0.0, 5.0),
                target: hadou_math::Vec3::ZERO,
                up: hadou_math::Vec3::Y,
                fov_y_deg: 45.0,
                near: 0.1,
                far: 100.0,
            },
            background: [0.0; 3],
            light: hadou_scene::Light { direction: -hadou_math::Vec3::Y, color: [1.0; 3], ambient: [0.0; 3] },
            objects: Vec::new(),
            waves: Vec::new(),
            color_mapping: hadou_scene::ColorMapping { mode: hadou_scene::ToneMode::Filmic, exposure: 1.0 },
            shadows: Vec::new(),
            area_light: None,
        }
    }

    /// The wave pipeline comes from the variant cache: the same kinds give the same pipeline
    /// whatever their parameters, other kinds another one; without specialisation every frame gets
    /// the uber-shader. A frame without surfaces skips the raster pass unless the uber-shader
    /// (which reads the G-buffer) runs it.
    #[test]
    fn wave_pipelines_are_cached_per_variant() {
        let Some((mut r, _gpu)) = renderer_or_skip("wave pipeline cache") else { return };
        let sphere = |x: f32| {
            let mut f = small_frame();
            f.waves.push(hadou_scene::Wave::new(
                "orb",
                [1.0; 4],
                hadou_math::energy::Falloff::Faithful,
                0.02,
                hadou_scene::WaveShape::Sphere(hadou_math::energy::SphereField {
                    center: hadou_math::Vec3::new(x, 0.0, 0.0),
                    alpha: 1.0,
                }),
            ));
            f
        };
        let a = r.prepare(&sphere(0.0), 0..8).unwrap();
        let b = r.prepare(&sphere(2.0), 0..8).unwrap();
        assert_eq!(a.wave_pipeline, b.wave_pipeline, "same kinds, same pipeline");
        assert_eq!(r.wave_variants_built(), 1);
        assert!(!a.raster, "nothing to draw: no raster pass");
        let mut cylinder = sphere(0.0);
        cylinder.waves[0].shape = hadou_scene::WaveShape::Cylinder(hadou_math::energy::CylinderField {
            point: hadou_math::Vec3::ZERO,
            dir: hadou_math::Vec3::Y,
            alpha: 1.0,
        });
        let c = r.prepare(&cylinder, 0..8).unwrap();
        assert_ne!(a.wave_pipeline, c.wave_pipeline, "another kind, another pipeline");
        let with_objects = three_triangles(0.0);
        let d = r.prepare(&with_objects, 0..8).unwrap();
        assert!(d.raster, "objects are rasterized");
        assert_eq!(r.wave_variants_built(), 3);
        r.set_specialise(false);
        let u1 = r.prepare(&sphere(0.0), 0..8).unwrap();
        let u2 = r.prepare(&cylinder, 0..8).unwrap();
        assert_eq!(u1.wave_pipeline, u2.wave_pipeline, "one uber-shader for every frame");
        assert!(u1.raster, "the uber-shader reads the G-buffer");
        assert_ne!(u1.wave_pipeline, a.wave_pipeline);
        assert_eq!(r.wave_variants_built(), 4);
    }

    #[test]
    fn meshes_upload_once_per_arc_and_are_dropped_with_it() {
        let Some((mut r, _gpu)) = renderer_or_skip("mesh cache") else { return };
        let mesh = Arc::new(Mesh {
            positions: vec![[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]],
            normals: vec![[0.0, 0.0, 1.0]; 3],
            indices: vec![0, 1, 2],
            ..Mesh::default()
        });
        let object = |name: &str, mesh: &Arc<Mesh>| {
            hadou_scene::Object::new(name, mesh.clone(), hadou_math::Mat4::IDENTITY, [1.0; 3])
        };
        let mut frame = small_frame();
        frame.objects = vec![object("a", &mesh), object("b", &mesh)];
        let first = r.render(&frame).unwrap();
        assert_eq!(r.meshes.len(), 1, "two objects sharing one Arc<Mesh> share one upload");
        let key = Arc::as_ptr(&mesh) as usize;
        let buffer_id = format!("{:?}", r.meshes[&key].vertices);
        assert_eq!(r.render(&frame).unwrap(), first);
        assert_eq!(format!("{:?}", r.meshes[&key].vertices), buffer_id, "not re-uploaded");
        // The triangle is visible in the centre.
        assert!(first.depth[first.index(4, 4)] < 6.0);
        drop(frame);
        drop(mesh);
        let other = Arc::new(Mesh::default());
        let mut frame = small_frame();
        frame.objects = vec![object("empty", &other)];
        r.render(&frame).unwrap();
        assert!(r.meshes.is_empty(), "the freed mesh's upload is released; empty meshes are not uploaded");
    }

    #[test]
    fn lost_device_is_a_device_error() {
        let Some((mut r, _gpu)) = renderer_or_skip("device loss") else { return };
        let frame = small_frame();
        assert!(r.render(&frame).is_ok());
        r.ctx.device.destroy();
        let _ = r.ctx.device.poll(wgpu::PollType::Poll);
        match r.render(&frame) {
            Err(RenderError::Device(m)) => assert!(m.contains("lost") || m.contains("GPU"), "{m}"),
            other => panic!("expected a device error, got {:?}", other.map(|_| ())),
        }
    }
}
