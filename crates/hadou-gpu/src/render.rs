//! The renderer: the device, the passes, the resources a frame's passes share (the mesh cache,
//! the tile targets, the shadow maps, the soft-shadow buffers, the window texture), the frame's
//! preparation, the tile loop and the read-back. Each tile is drawn by the passes of `passes/`
//! and read back on its own (or, in `window.rs`, drawn into a window texture), so GPU memory is
//! bounded by the tile size whatever the image size.

mod glare;
mod maps;
mod soft;

use crate::device::GpuContext;
use crate::formats::{DEPTH_FORMAT, PLANE_SHADOW_FORMAT, SCENE_FORMAT};
use crate::layout::{FrameUniforms, TONE_LINEAR};
use crate::meshes::MeshCache;
use crate::passes::bloom::BloomPass;
use crate::passes::edges::{EdgeInputs, EdgePass};
use crate::passes::plane_shadows::{PlaneShadowInputs, PlaneShadowPass};
use crate::passes::present::Presenter;
use crate::passes::raster::{GBuffer, RasterInputs, RasterPass};
use crate::passes::setup::{texture_view, Draw};
use crate::passes::shadow_maps::{MapPass, ShadowMapInputs, ShadowMapPass, ShadowMaps};
use crate::passes::soft::{SoftPass, SoftTargets, SoftTileInputs};
use crate::passes::wave::{WaveInputs, WavePass};
use crate::passes::wave_overlay::WaveOverlayPass;
use crate::prepare::{self, FrameBuffers, FrameData, ShadowFields};
use crate::timing::PassQueries;
#[cfg(not(target_arch = "wasm32"))]
use hadou_scene::Image;
use hadou_scene::{Frame, RenderError, SampleGrid};

/// Largest tile edge in pixels (smaller when the device's limits demand it).
pub const MAX_TILE: u32 = 1024;
/// Floats per pixel in the tile output buffer: colour (4), energy, eye distance.
const FLOATS_PER_PIXEL: u64 = 6;

/// What a tile's wave pass writes for each image pixel (wave.wgsl `store_pixel`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TileOutput {
    /// Colour (4), energy and eye distance as `f32`: [`FLOATS_PER_PIXEL`] floats, what an
    /// [`Image`] holds and the present and glare passes read.
    Floats,
    /// One word of 8-bit sRGB (R, G, B and 255, or 0 where a value is not finite): what a PNG
    /// holds, a sixth of the bytes to write and to read back.
    Srgb8,
}

impl TileOutput {
    /// Bytes per image pixel in the tile output buffer.
    pub(crate) fn bytes_per_pixel(self) -> u64 {
        match self {
            TileOutput::Floats => FLOATS_PER_PIXEL * 4,
            TileOutput::Srgb8 => 4,
        }
    }
}

/// The per-tile GPU resources, sized for one tile edge pair.
pub(crate) struct TileTargets {
    size: [u32; 2],
    /// G-buffer target 0: normal and eye distance (see raster.wgsl and `formats::SCENE_FORMAT`).
    scene_view: wgpu::TextureView,
    /// G-buffer target 1: texture coordinates, vertex colour, material word with the hull reach
    /// (what the later passes read when the frame has no outlines).
    attributes_view: wgpu::TextureView,
    /// Target 1 as the edge pass leaves it (what the plane shadows and the wave pass read).
    edge_attributes_view: wgpu::TextureView,
    /// The edge pass's candidate map and block maxima (`passes::edges::scratch_bytes`).
    edge_candidates: wgpu::Buffer,
    edge_blocks: wgpu::Buffer,
    /// Depth of the raster pass, then of the plane-shadow pass.
    depth_view: wgpu::TextureView,
    /// The plane-shadow pass's target (`formats::PLANE_SHADOW_FORMAT`).
    plane_shadow_view: wgpu::TextureView,
    /// The tile's `FrameUniforms` (rewritten before each tile's submission).
    pub(crate) uniforms: wgpu::Buffer,
    /// The wave pass's output (see wave.wgsl binding 4), read by the present pass.
    pub(crate) output: wgpu::Buffer,
    staging: wgpu::Buffer,
}

impl TileTargets {
    fn g_buffer(&self) -> GBuffer<'_> {
        GBuffer { surface: &self.scene_view, attributes: &self.attributes_view, depth: &self.depth_view }
    }
}

/// Everything a frame's tiles share: buffers of this frame and the tile grid.
pub(crate) struct Prepared {
    pub(crate) tile: [u32; 2],
    pub(crate) tiles: Vec<([u32; 2], [u32; 2])>,
    buffers: FrameBuffers,
    /// The raster pass's draws (instance = object index).
    draws: Vec<Draw>,
    /// Whether any object has an outlined material (then the hull pipeline runs).
    outlines: bool,
    /// The plane casts' draws in cast order (instance = index into the shadow draws).
    plane_draws: Vec<Draw>,
    /// Where the cast records and map-cast indices are in the shading data, and their counts
    /// (the shadow fields of `FrameUniforms`).
    shadow_fields: ShadowFields,
    /// The shadow-map passes, one per map cast, and their bind group (`None` without map casts).
    map_passes: Vec<MapPass>,
    map_bind_group: Option<wgpu::BindGroup>,
    /// The wave pass's pipeline: the variant this frame needs (`passes::wave::WaveVariant`).
    wave_pipeline: wgpu::ComputePipeline,
    /// What that pipeline writes per pixel.
    pub(crate) output: TileOutput,
    /// Whether the tiles need the raster pass: false when nothing is drawn and the wave pass's
    /// variant does not read the G-buffer (no surfaces, no `[area_light]`), so an empty frame
    /// skips clearing 36 bytes per pixel.
    raster: bool,
    /// The tiles' bind groups, made once per frame (set at the end of `prepare`).
    groups: Option<TileBindGroups>,
    /// Whether the wave pass writes the linear colour, unmapped, for the glare
    /// ([`Renderer::render_rows`] of a frame with a `[bloom]`).
    linear: bool,
    /// The frame's sample grid (`Frame::sample_grid`); with more than one sample per pixel
    /// the tiles, the G-buffer, the shadows and the soft shadows are the sample frame's
    /// (`sampled`), and the wave pass resolves each image pixel from its samples.
    grid: SampleGrid,
    sampled: Option<Frame>,
    /// The tile the G-buffer holds when the last tile encoded was classified for the soft
    /// shadows (`TileWork::Classify`), and nothing since: the next tile drawn, if it is that
    /// one, skips the raster pass.
    classified_tile: std::sync::Mutex<Option<([u32; 2], [u32; 2])>>,
}

/// The bind groups every tile of a frame uses (the tile's uniforms are rewritten before each
/// tile's submission, so one set serves them all).
struct TileBindGroups {
    raster: wgpu::BindGroup,
    edges: wgpu::BindGroup,
    wave: wgpu::BindGroup,
    /// Only when the frame has plane casts.
    plane: Option<wgpu::BindGroup>,
    /// Only with an `[area_light]`.
    soft: Option<wgpu::BindGroup>,
}

impl Prepared {
    /// The frame whose pixels the tiles' surface passes draw: the sample frame with
    /// anti-aliasing, else `frame` itself.
    pub(crate) fn surfaces<'a>(&'a self, frame: &'a Frame) -> &'a Frame {
        self.sampled.as_ref().unwrap_or(frame)
    }

    /// A tile of [`Prepared::tiles`] (in samples) in image pixels: what its wave pass writes and
    /// what is read back.
    pub(crate) fn output_tile(&self, (origin, size): ([u32; 2], [u32; 2])) -> ([u32; 2], [u32; 2]) {
        let g = self.grid.edge();
        ([origin[0] / g, origin[1] / g], [size[0] / g, size[1] / g])
    }

    /// The number of shadow-map passes (map casts) of the frame.
    pub(crate) fn map_pass_count(&self) -> u32 {
        self.map_passes.len() as u32
    }
}

/// One tile's commands: the render passes that write its G-buffer and plane shadows (`None` when
/// the frame draws no surfaces), then the compute passes that read them, to which a caller may
/// append (the window's present pass). See [`Renderer::submit_tile`].
pub(crate) struct TileEncoders {
    surfaces: Option<wgpu::CommandEncoder>,
    pub(crate) shading: wgpu::CommandEncoder,
}

/// What a tile's passes are recorded for.
#[derive(Clone, Copy, PartialEq, Eq)]
enum TileWork {
    /// Every pass, then (with `readback`) the copy to the staging buffer.
    Draw { readback: bool },
    /// The raster pass, then the soft shadows' gathering of its visible points.
    Classify,
}

/// The passes, each with its pipelines.
pub(crate) struct Passes {
    raster: RasterPass,
    edges: EdgePass,
    plane_shadows: PlaneShadowPass,
    shadow_maps: ShadowMapPass,
    soft: SoftPass,
    pub(crate) wave: WavePass,
    bloom: BloomPass,
}

/// The renderer's state between frames.
pub(crate) struct Renderer {
    pub(crate) ctx: GpuContext,
    pub(crate) passes: Passes,
    pub(crate) meshes: MeshCache,
    pub(crate) targets: Option<TileTargets>,
    maps: Option<ShadowMaps>,
    /// The `[area_light]`'s resources, kept while the image and map sizes hold.
    soft: Option<SoftTargets>,
    /// The present pass and its window texture, made on the first `render_to_texture`.
    pub(crate) present: Option<Presenter>,
    /// The wave overlay, made on the first `encode_wave_overlay`.
    pub(crate) overlay: Option<WaveOverlayPass>,
}

/// Allocates the host image, reporting (not aborting on) a failed allocation.
#[cfg(not(target_arch = "wasm32"))]
fn alloc_image(width: u32, height: u32) -> Result<Image, RenderError> {
    let n = width as usize * height as usize;
    let oom = |_| {
        RenderError::Memory(format!("the host's copy of a {width}×{height} image could not be allocated"))
    };
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
        let passes = Passes {
            raster: RasterPass::new(&ctx)?,
            edges: EdgePass::new(&ctx)?,
            wave: WavePass::new(&ctx)?,
            plane_shadows: PlaneShadowPass::new(&ctx)?,
            shadow_maps: ShadowMapPass::new(&ctx)?,
            soft: SoftPass::new(&ctx)?,
            bloom: BloomPass::new(&ctx)?,
        };
        Ok(Self {
            ctx,
            passes,
            meshes: MeshCache::default(),
            targets: None,
            maps: None,
            soft: None,
            present: None,
            overlay: None,
        })
    }

    /// See [`crate::GpuBackend::set_specialise`].
    pub(crate) fn set_specialise(&mut self, on: bool) {
        self.passes.wave.specialise = on;
    }

    /// See [`crate::GpuBackend::wave_variants_built`].
    pub(crate) fn wave_variants_built(&self) -> usize {
        self.passes.wave.variant_count()
    }

    fn ensure_targets(&mut self, size: [u32; 2]) {
        if self.targets.as_ref().is_some_and(|t| t.size == size) {
            return;
        }
        self.targets = None; // free the old ones first
        let d = &self.ctx.device;
        // The textures are allocated at the next power of two of the tile (the passes' viewports
        // and dispatches cover only the tile): llvmpipe keys each compiled shader by whether its
        // textures' edges are powers of two, so tiles of every size then share one compile of
        // each pipeline instead of up to four (a cold uber-shader compile is ~20 s on lavapipe).
        let limit = self.ctx.limits.max_texture_dimension_2d;
        let pot = size.map(|e| if e.next_power_of_two() <= limit { e.next_power_of_two() } else { e });
        let texture = |label, format, usage| texture_view(d, label, pot, format, usage);
        let attach_and_read = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let scene_view = texture("normal and distance", SCENE_FORMAT, attach_and_read);
        let attributes_view = texture("uv, colour and material", SCENE_FORMAT, attach_and_read);
        let edge_attributes_view = texture(
            "uv, colour and material, outlines closed",
            SCENE_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let (candidate_bytes, block_bytes) = crate::passes::edges::scratch_bytes(size);
        let scratch = |label, size| {
            d.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            })
        };
        let edge_candidates = scratch("edge candidates", candidate_bytes);
        let edge_blocks = scratch("edge blocks", block_bytes);
        let depth_view = texture("depth", DEPTH_FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT);
        let plane_shadow_view = texture("plane shadows", PLANE_SHADOW_FORMAT, attach_and_read);
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
            edge_attributes_view,
            edge_candidates,
            edge_blocks,
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
    /// The wave pass writes `output` per pixel.
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn prepare(
        &mut self,
        frame: &Frame,
        rows: std::ops::Range<u32>,
        output: TileOutput,
    ) -> Result<Prepared, RenderError> {
        self.prepare_frame(frame, rows, true, output)
    }

    /// [`Renderer::prepare`]; with `submit_maps` false the shadow maps are left for the caller to
    /// submit ([`Renderer::submit_shadow_maps`], e.g. with timestamps) before the tiles. Only for
    /// frames without an `[area_light]`, whose soft shadows are drawn here after the maps.
    pub(crate) fn prepare_frame(
        &mut self,
        frame: &Frame,
        rows: std::ops::Range<u32>,
        submit_maps: bool,
        output: TileOutput,
    ) -> Result<Prepared, RenderError> {
        debug_assert!(submit_maps || frame.area_light.is_none());
        self.ctx.check()?;
        prepare::validate_frame(frame)?;
        let sample_grid = frame.sample_grid();
        let grid = sample_grid.edge();
        let sampled = (!sample_grid.is_single()).then(|| frame.sample_frame());
        let frame = sampled.as_ref().unwrap_or(frame);
        let rows = grid * rows.start..grid * rows.end;
        let mut tile = tile_size(&self.ctx.limits, frame.width, frame.height)?;
        // Whole pixels per tile: tile edges are multiples of the grid (as the frame's are).
        for t in &mut tile {
            *t = (*t / grid).max(1) * grid;
        }
        let data = FrameData::new(&self.ctx.limits, frame)?;
        let variant = data.wave_variant(frame, grid > 1).with_srgb8(output == TileOutput::Srgb8);
        let (wave_pipeline, variant) = self.passes.wave.pipeline(&self.ctx, variant)?;
        let raster =
            variant.has("USE_SURFACES") || frame.area_light.is_some() || !data.plane_draws.is_empty();
        let outlines = data.outlines();
        let scopes = self.ctx.open_scopes();
        let prepared = {
            self.meshes.upload(&self.ctx.device, frame);
            self.ensure_targets(tile);
            ShadowMaps::ensure(&mut self.maps, &self.ctx.device, &data.shadows);
            let d = &self.ctx.device;
            let buffers = FrameBuffers::upload(d, &data);
            let draws = frame
                .objects
                .iter()
                .enumerate()
                .filter_map(|(i, o)| {
                    let c = self.meshes.get(&o.mesh)?;
                    Some(Draw { object: i, index_count: c.index_count, instance: i as u32 })
                })
                .collect();
            let mut tiles = Vec::new();
            for y in rows.clone().step_by(tile[1] as usize) {
                for x in (0..frame.width).step_by(tile[0] as usize) {
                    tiles.push(([x, y], [tile[0].min(frame.width - x), tile[1].min(rows.end - y)]));
                }
            }
            let map_passes = map_passes(&data);
            let map_bind_group = (!map_passes.is_empty()).then(|| {
                let inputs = ShadowMapInputs {
                    objects: &buffers.objects,
                    casts: &buffers.casts,
                    draws: &buffers.shadow_draws,
                };
                self.passes.shadow_maps.bind_group(d, &inputs)
            });
            let mut prepared = Prepared {
                tile,
                tiles,
                buffers,
                draws,
                outlines,
                plane_draws: data.plane_draws,
                shadow_fields: data.shadow_fields,
                map_passes,
                map_bind_group,
                wave_pipeline,
                output,
                raster,
                groups: None,
                linear: false,
                grid: sample_grid,
                sampled: None,
                classified_tile: std::sync::Mutex::new(None),
            };
            if submit_maps || frame.area_light.is_some() {
                self.submit_shadow_maps(frame, &prepared, None);
            }
            if frame.area_light.is_some() {
                SoftTargets::ensure(&mut self.soft, &self.ctx, frame, grid);
            }
            prepared.groups = Some(self.tile_bind_groups(frame, &prepared));
            let soft = if frame.area_light.is_some() { self.draw_soft(frame, &prepared) } else { Ok(()) };
            (prepared, soft)
        };
        let (mut prepared, soft) = prepared;
        self.ctx.close_scopes(scopes, "uploading the frame")?;
        soft?;
        prepared.sampled = sampled;
        Ok(prepared)
    }

    /// Encodes and submits every tile of `prepared` (no read-back), one submission per tile;
    /// the last submission.
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn submit_tiles(
        &self,
        frame: &Frame,
        prepared: &Prepared,
        mut timestamps: Option<&mut PassQueries<'_>>,
    ) -> Result<Option<wgpu::SubmissionIndex>, RenderError> {
        let mut last = None;
        for &t in &prepared.tiles {
            let encoders = self.encode_tile(frame, prepared, t, false, timestamps.as_deref_mut());
            last = Some(self.submit_tile(encoders)?);
        }
        Ok(last)
    }

    /// The bind groups of `prepared`'s tiles (after its shadow maps and soft-shadow resources
    /// exist).
    fn tile_bind_groups(&self, frame: &Frame, prepared: &Prepared) -> TileBindGroups {
        let t = self.targets.as_ref().expect("targets are created in prepare");
        let b = &prepared.buffers;
        let d = &self.ctx.device;
        let raster = RasterInputs { uniforms: &t.uniforms, objects: &b.objects, materials: &b.materials };
        let raster = self.passes.raster.bind_group(d, &raster);
        let edges = EdgeInputs {
            uniforms: &t.uniforms,
            materials: &b.materials,
            surface: &t.scene_view,
            attributes: &t.attributes_view,
            output: &t.edge_attributes_view,
            candidates: &t.edge_candidates,
            blocks: &t.edge_blocks,
        };
        let edges = self.passes.edges.bind_group(d, &edges);
        // Without outlines the edge pass does not run and the raster pass's words carry no reach.
        let attributes = if prepared.outlines { &t.edge_attributes_view } else { &t.attributes_view };
        let wave = WaveInputs {
            uniforms: &t.uniforms,
            waves: &b.waves,
            surface: &t.scene_view,
            attributes,
            output: &t.output,
            curves: [&b.curves[0], &b.curves[1], &b.curves[2]],
            materials: &b.materials,
            lights: &b.lights,
            shading_data: &b.shading_data,
            plane_shadows: &t.plane_shadow_view,
            shadow_maps: &self.maps.as_ref().expect("shadow maps are created in prepare").view,
        };
        let wave = self.passes.wave.bind_group(d, &wave);
        let plane = (!prepared.plane_draws.is_empty()).then(|| {
            let inputs = PlaneShadowInputs {
                uniforms: &t.uniforms,
                objects: &b.objects,
                materials: &b.materials,
                casts: &b.casts,
                draws: &b.shadow_draws,
                surface: &t.scene_view,
                attributes,
            };
            self.passes.plane_shadows.bind_group(d, &inputs)
        });
        let soft = self.soft.as_ref().filter(|_| frame.area_light.is_some()).map(|soft| {
            let tile = SoftTileInputs {
                uniforms: &t.uniforms,
                surface: &t.scene_view,
                attributes: &t.attributes_view,
                output: &t.output,
            };
            self.passes.soft.bind_group(d, soft, &tile)
        });
        TileBindGroups { raster, edges, wave, plane, soft }
    }

    /// Records one tile's passes — raster and edges (unless the frame skips them) and plane shadows into
    /// [`TileEncoders::surfaces`]; the soft shadows' gather, wave and, when `readback`, the copy to
    /// the staging buffer into [`TileEncoders::shading`] — after writing its uniforms. The tiles
    /// share one uniform buffer, so submit each tile ([`Renderer::submit_tile`]) before encoding
    /// the next. `timestamps`: every pass gets a query pair, the tile a group of its own.
    pub(crate) fn encode_tile(
        &self,
        frame: &Frame,
        prepared: &Prepared,
        tile: ([u32; 2], [u32; 2]),
        readback: bool,
        timestamps: Option<&mut PassQueries<'_>>,
    ) -> TileEncoders {
        self.encode_tile_work(frame, prepared, tile, TileWork::Draw { readback }, timestamps)
    }

    /// Submits a tile's two command buffers in order, each on its own, and returns the second's
    /// submission. The compute passes never share a submission with the render passes whose
    /// targets they read: on Mesa's llvmpipe through EGL, a wave pass recorded after the raster
    /// pass in one command buffer sometimes read the G-buffer as the previous frame had left it
    /// (under load, about one test run in twelve; `tests/determinism.rs`), and split submissions
    /// never did in sixty runs. On OpenGL the shading also waits for the surfaces' fence, the one
    /// ordering every GL driver must honour.
    pub(crate) fn submit_tile(&self, tile: TileEncoders) -> Result<wgpu::SubmissionIndex, RenderError> {
        if let Some(surfaces) = tile.surfaces {
            let submission = self.ctx.queue.submit([surfaces.finish()]);
            #[cfg(not(target_arch = "wasm32"))]
            if self.ctx.info.backend == wgpu::Backend::Gl {
                self.ctx.wait(submission)?;
            }
            #[cfg(target_arch = "wasm32")]
            let _ = submission;
        }
        Ok(self.ctx.queue.submit([tile.shading.finish()]))
    }

    /// The passes of one tile for `work` (see [`Renderer::encode_tile`]).
    fn encode_tile_work(
        &self,
        frame: &Frame,
        prepared: &Prepared,
        tile: ([u32; 2], [u32; 2]),
        work: TileWork,
        mut timestamps: Option<&mut PassQueries<'_>>,
    ) -> TileEncoders {
        if let Some(q) = timestamps.as_deref_mut() {
            q.next_group();
        }
        let frame = prepared.surfaces(frame);
        let t = self.targets.as_ref().expect("targets are created in prepare");
        let basis = frame.camera.basis(frame.width, frame.height);
        let (origin, size) = tile;
        let mut uniforms = FrameUniforms::new(frame, &basis, origin, size, prepared.grid);
        prepared.shadow_fields.apply(&mut uniforms);
        if prepared.linear {
            uniforms.tone_mode = TONE_LINEAR;
        }
        self.ctx.queue.write_buffer(&t.uniforms, 0, bytemuck::bytes_of(&uniforms));
        let groups = prepared.groups.as_ref().expect("bind groups are made in prepare");
        let passes = &self.passes;
        let encoder = |label| {
            self.ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) })
        };
        let mut surfaces = None;
        // With an `[area_light]`, `draw_soft` rasterized every tile of the image for its points:
        // the first tile drawn after it may be the one the G-buffer still holds as the raster
        // pass left it (a drawn tile's plane shadows then change its depth, so only a classified
        // tile is reused).
        let reuse = {
            let mut holds = prepared.classified_tile.lock().unwrap_or_else(|e| e.into_inner());
            let reuse = work != TileWork::Classify && *holds == Some(tile);
            *holds = (work == TileWork::Classify).then_some(tile);
            reuse
        };
        if (prepared.raster || work == TileWork::Classify) && !reuse {
            let enc = surfaces.get_or_insert_with(|| encoder("tile surfaces"));
            passes.raster.encode(
                enc,
                &t.g_buffer(),
                size,
                &groups.raster,
                &self.meshes,
                frame,
                &prepared.draws,
                prepared.outlines,
                timestamps.as_deref_mut().and_then(|q| q.render("raster")),
            );
        }
        let mut shading = encoder("tile shading");
        let soft_bg = groups.soft.as_ref().filter(|_| frame.area_light.is_some());
        let readback = match work {
            TileWork::Classify => {
                if let Some(bg) = soft_bg {
                    passes.soft.encode_points(&mut shading, bg, size);
                }
                return TileEncoders { surfaces, shading };
            }
            TileWork::Draw { readback } => readback,
        };
        // The edge pass follows the raster pass of this tile's G-buffer: this one's, or the
        // classification's when the G-buffer is reused (which stopped before it).
        if prepared.outlines && (surfaces.is_some() || reuse) {
            passes.edges.encode(
                surfaces.get_or_insert_with(|| encoder("tile surfaces")),
                size,
                &groups.edges,
                timestamps.as_deref_mut().and_then(|q| q.compute("edges")),
            );
        }
        if let Some(bg) = &groups.plane {
            passes.plane_shadows.encode(
                surfaces.get_or_insert_with(|| encoder("tile surfaces")),
                &t.plane_shadow_view,
                &t.depth_view,
                size,
                bg,
                &self.meshes,
                frame,
                &prepared.plane_draws,
                timestamps.as_deref_mut().and_then(|q| q.render("plane shadows")),
            );
        }
        if let Some(bg) = soft_bg {
            passes.soft.encode_gather(&mut shading, bg, size, timestamps.as_deref_mut());
        }
        let wave_timestamps = timestamps.and_then(|q| q.compute("wave"));
        let (_, pixels) = prepared.output_tile(tile);
        passes.wave.encode(&mut shading, &prepared.wave_pipeline, &groups.wave, pixels, wave_timestamps);
        if readback {
            let bytes = pixels[0] as u64 * pixels[1] as u64 * prepared.output.bytes_per_pixel();
            shading.copy_buffer_to_buffer(&t.output, 0, &t.staging, 0, bytes);
        }
        TileEncoders { surfaces, shading }
    }

    /// Encodes and submits every pass of `tile` with the copy of its output into the staging
    /// buffer, for a read-back after the returned submission.
    #[cfg(not(target_arch = "wasm32"))]
    fn draw_tile_for_readback(
        &self,
        frame: &Frame,
        prepared: &Prepared,
        tile: ([u32; 2], [u32; 2]),
    ) -> Result<wgpu::SubmissionIndex, RenderError> {
        self.ctx.scoped("rendering a tile", || {
            let encoders = self.encode_tile(frame, prepared, tile, true, None);
            self.submit_tile(encoders)
        })?
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
        if let Some(params) = frame.bloom.as_ref().filter(|_| y1 > y0) {
            return self.render_rows_glare(frame, params, rows);
        }
        let prepared = self.prepare(frame, rows.clone(), TileOutput::Floats)?;
        let mut image = alloc_image(frame.width, rows.len() as u32)?;
        for &tile in &prepared.tiles {
            let submission = self.draw_tile_for_readback(frame, &prepared, tile)?;
            let (origin, size) = prepared.output_tile(tile);
            let origin = [origin[0], origin[1] - rows.start];
            let n = size[0] as usize * size[1] as usize;
            let bytes = n as u64 * FLOATS_PER_PIXEL * 4;
            let staging = &self.targets.as_ref().expect("targets exist").staging;
            self.ctx.read_buffer(staging, bytes, submission, |raw| {
                copy_tile(&mut image, raw, origin, size);
            })?;
        }
        Ok(image)
    }
}

impl Renderer {
    /// The rows `rows` of `frame` (clamped to the image) as 8-bit sRGB, what a PNG holds: the
    /// bytes of `Rgb8Image::from_image` of [`Renderer::render_rows`]'s image, refused the same
    /// way where a value is not finite. The wave pass writes each pixel's codes
    /// ([`TileOutput::Srgb8`], wave.wgsl `srgb8_code`: the same thresholds as
    /// `hadou_math::shade::linear_to_srgb8`), so a tile reads back 4 bytes a pixel instead of
    /// 24 and nothing is converted here. A frame with a `[bloom]` takes the float road (the
    /// glare reads the linear colour) and is converted.
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn render_rows_rgb8(
        &mut self,
        frame: &Frame,
        rows: std::ops::Range<u32>,
    ) -> Result<hadou_scene::Rgb8Image, RenderError> {
        let non_finite =
            || RenderError::Other("internal error: the renderer produced a non-finite value".into());
        let (y0, y1) = (rows.start.min(frame.height), rows.end.min(frame.height));
        let rows = y0..y1.max(y0);
        if frame.bloom.is_some() && y1 > y0 {
            let image = self.render_rows(frame, rows)?;
            return hadou_scene::Rgb8Image::from_image(&image).ok_or_else(non_finite);
        }
        let prepared = self.prepare(frame, rows.clone(), TileOutput::Srgb8)?;
        let width = frame.width as usize;
        let n = width * rows.len();
        let mut rgb: Vec<u8> = Vec::new();
        rgb.try_reserve_exact(3 * n).map_err(|_| {
            RenderError::Memory(format!(
                "the host's copy of a {}×{} image could not be allocated",
                frame.width,
                rows.len()
            ))
        })?;
        rgb.resize(3 * n, 0);
        let mut finite = true;
        for &tile in &prepared.tiles {
            let submission = self.draw_tile_for_readback(frame, &prepared, tile)?;
            let (origin, size) = prepared.output_tile(tile);
            let (x0, y0) = (origin[0] as usize, (origin[1] - rows.start) as usize);
            let (w, h) = (size[0] as usize, size[1] as usize);
            let bytes = (w * h) as u64 * TileOutput::Srgb8.bytes_per_pixel();
            let staging = &self.targets.as_ref().expect("targets exist").staging;
            self.ctx.read_buffer(staging, bytes, submission, |raw| {
                for (r, src) in raw.chunks_exact(4 * w).take(h).enumerate() {
                    let start = 3 * ((y0 + r) * width + x0);
                    for (o, p) in rgb[start..start + 3 * w].chunks_exact_mut(3).zip(src.chunks_exact(4)) {
                        o.copy_from_slice(&p[..3]);
                        finite &= p[3] == 255;
                    }
                }
            })?;
        }
        if !finite {
            return Err(non_finite());
        }
        Ok(hadou_scene::Rgb8Image { width: frame.width, height: rows.len() as u32, rgb })
    }
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

/// One pass per map layer of `data`: its layer, its map's edge and its draws.
fn map_passes(data: &FrameData) -> Vec<MapPass> {
    let shadows = &data.shadows;
    data.map_draws
        .iter()
        .enumerate()
        .map(|(layer, draws)| MapPass {
            layer: layer as u32,
            edge: shadows.casts[shadows.map_casts[layer] as usize].map_size as f32,
            draws: draws.clone(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::{self, FrameShadows, ShadingBuffers};
    use crate::passes::setup::compile_module;
    use crate::prepare::check_maps;
    use hadou_scene::Mesh;
    use std::sync::Arc;

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
            bloom: None,
            samples: 1,
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
        let a = r.prepare(&sphere(0.0), 0..8, TileOutput::Floats).unwrap();
        let b = r.prepare(&sphere(2.0), 0..8, TileOutput::Floats).unwrap();
        assert_eq!(a.wave_pipeline, b.wave_pipeline, "same kinds, same pipeline");
        assert_eq!(r.wave_variants_built(), 1);
        assert!(!a.raster, "nothing to draw: no raster pass");
        let mut cylinder = sphere(0.0);
        cylinder.waves[0].shape = hadou_scene::WaveShape::Cylinder(hadou_math::energy::CylinderField {
            point: hadou_math::Vec3::ZERO,
            dir: hadou_math::Vec3::Y,
            alpha: 1.0,
        });
        let c = r.prepare(&cylinder, 0..8, TileOutput::Floats).unwrap();
        assert_ne!(a.wave_pipeline, c.wave_pipeline, "another kind, another pipeline");
        let with_objects = three_triangles(0.0);
        let d = r.prepare(&with_objects, 0..8, TileOutput::Floats).unwrap();
        assert!(d.raster, "objects are rasterized");
        assert_eq!(r.wave_variants_built(), 3);
        r.set_specialise(false);
        let u1 = r.prepare(&sphere(0.0), 0..8, TileOutput::Floats).unwrap();
        let u2 = r.prepare(&cylinder, 0..8, TileOutput::Floats).unwrap();
        assert_eq!(u1.wave_pipeline, u2.wave_pipeline, "one uber-shader for every frame");
        assert!(u1.raster, "the uber-shader reads the G-buffer");
        assert_ne!(u1.wave_pipeline, a.wave_pipeline);
        assert_eq!(r.wave_variants_built(), 4);
        // The 8-bit output is another pipeline, even for the uber-shader.
        let p = r.prepare(&sphere(0.0), 0..8, TileOutput::Srgb8).unwrap();
        assert_eq!(p.output, TileOutput::Srgb8);
        assert_ne!(p.wave_pipeline, u1.wave_pipeline);
        assert_eq!(r.wave_variants_built(), 5);
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
        let buffer_id = format!("{:?}", r.meshes.get(&mesh).unwrap().vertices);
        assert_eq!(r.render(&frame).unwrap(), first);
        assert_eq!(format!("{:?}", r.meshes.get(&mesh).unwrap().vertices), buffer_id, "not re-uploaded");
        // The triangle is visible in the centre.
        assert!(first.depth[first.index(4, 4)] < 6.0);
        drop(frame);
        drop(mesh);
        let other = Arc::new(Mesh::default());
        let mut frame = small_frame();
        frame.objects = vec![object("empty", &other)];
        r.render(&frame).unwrap();
        assert_eq!(r.meshes.len(), 0, "the freed mesh's upload is released; empty meshes are not uploaded");
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
