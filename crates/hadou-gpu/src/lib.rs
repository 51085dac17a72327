//! # hadou-gpu
//!
//! hadou's wgpu backend: the real-time path, drawing the same picture as the CPU reference.
//!
//! [`GpuBackend`] renders a [`Frame`] headlessly (no window or surface of its own; see "In a
//! window" below for drawing into one) with a handful of passes, one file each under `passes/`,
//! named like their shaders. Each pass owns its pipelines, declares its shader's bindings once and
//! records itself into a command encoder on targets its caller owns:
//! 1. **shadow maps** (`passes/shadow_maps.rs`, `shaders/shadow_raster.wgsl` `vs_map`), once per
//!    frame: each map cast's casters into a layer of one depth array texture;
//! 2. with an `[area_light]`, **soft** (`passes/soft.rs`, `shaders/soft_map.wgsl`,
//!    `shaders/soft.wgsl`), once per frame: the light's two perspective maps, every pixel of the
//!    image classed umbra / penumbra / lit and the penumbra resolved (003);
//! 3. per tile, **raster** (`passes/raster.rs`, `shaders/raster.wgsl`): the opaque meshes and the
//!    outline hulls, depth-tested into a G-buffer (normal and eye distance; texture coordinates,
//!    vertex colour, material);
//! 4. per tile with plane casts, **plane shadows** (`passes/plane_shadows.rs`,
//!    `shaders/shadow_raster.wgsl`): the most opaque plane cast per pixel;
//! 5. per tile, **wave** (`passes/wave.rs`, `shaders/wave.wgsl`, a compute shader): the visible
//!    surface shaded from the G-buffer (`shaders/shading.wgsl`: materials, the waves as lights;
//!    `shaders/shadow_lookup.wgsl`: hard shadows; the area light's visibility), then per pixel
//!    every wave's exact energy integral along the view ray clipped at that surface (002 §3.3.5;
//!    `shaders/wave_energy.wgsl`, `shaders/energy.wgsl` and `shaders/curve.wgsl`, the WGSL twins
//!    of `hadou_math::energy` and `hadou_math::curve`, on the rays `hadou_scene::CameraBasis::wave_ray`
//!    builds), `scene + exposure·Σ rgb·a·I` and the colour mapping, into an output buffer that is
//!    read back, or that **present** (`passes/present.rs`) copies into a window's texture.
//!
//! The renderer (`render.rs`) owns what a frame's passes share (the mesh cache, the tile
//! targets, the shadow maps, the soft-shadow buffers), prepares each frame (`prepare.rs`: the
//! checks against the device and the records every pass reads) and runs the tile loop. Images
//! are processed in tiles of at most [`MAX_TILE`]² pixels, each read back before the next (or
//! presented), so GPU memory stays bounded whatever the image size. A frame with nothing to draw
//! (waves only) skips the raster pass.
//!
//! For a renderer that draws its own scene (a game engine's frame, a page's canvas),
//! [`GpuBackend::encode_wave_overlay`] records the **wave overlay** (`passes/wave_overlay.rs`,
//! `shaders/wave_overlay.wgsl`): the waves' light, the same `exposure·Σ rgb·a·I`, drawn into the
//! caller's colour target against the caller's depth buffer ([`OverlayTarget`], [`DepthModel`]),
//! added to it before the caller's tone mapping.
//!
//! The wave pass is specialised per frame: the wave module declares pipeline-overridable `bool`
//! constants (`USE_SPHERE`, `USE_CURVE`, `USE_SURFACES`, `USE_TEXTURES`, …, all `true` by
//! default: the uber-shader) guarding each wave kind, falloff, curve integrator and shape, and each
//! shading path; each frame gets a compute pipeline with only what its data can reach compiled in,
//! built on first use and cached by that set. Software adapters need this: llvmpipe (lavapipe,
//! and Mesa's GL) runs every branch of a shader under an execution mask whichever way the pixels
//! go, so with the uber-shader a one-sphere frame paid for every kind, the curve walker and the
//! surface shading (about 0.8 s instead of 6 ms at 512²). A variant renders bit for bit what the
//! uber-shader renders (`tests/variants.rs`). The wave overlay is specialised the same way.
//!
//! Curved waves are prepared once per frame with `hadou_math::curve::prepare` (as the CPU backend
//! does) and uploaded as storage buffers ([`layout::CurveBuffers`]).
//!
//! Failures never panic: no adapter is [`RenderError::NoDevice`]; a lost device, out-of-memory or
//! a GPU that does not answer within a timeout is [`RenderError::Device`]; a shader that fails to
//! compile is [`RenderError::Other`] naming the shader.
//!
//! ## In a window
//!
//! A window (e.g. egui with egui-wgpu) opens its device on a surface-compatible adapter, asking for
//! what [`device_descriptor`] gives (the same as [`GpuBackend::new`] asks), and hands it to
//! [`GpuBackend::from_device`]. [`GpuBackend::render_to_texture`] then draws each frame straight
//! into one full-frame [`PRESENT_FORMAT`] texture on the GPU (a present pass per tile,
//! `shaders/present.wgsl`), with no read-back and no wait: the window samples the texture in its
//! own pass on the same queue. The bytes equal `hadou_math::shade::linear_to_srgb8` of
//! [`Backend::render`]'s colour within one code (`tests/present.rs`). Where the device has
//! timestamp queries, [`GpuBackend::last_present_timing`] gives the GPU time of a recent frame,
//! read back asynchronously (a small ring of staging buffers, mapped without waiting), so a
//! window can show it every frame without blocking.
//!
//! ## On the web (`wasm32`)
//!
//! The crate builds for `wasm32-unknown-unknown` on wgpu's WebGPU backend (WebGL2 lacks compute
//! shaders). A browser may not block, so only the non-blocking path is compiled there:
//! [`GpuBackend::from_device`] (the page requests the adapter and device asynchronously itself,
//! with [`device_descriptor`]), [`GpuBackend::render_to_texture`],
//! [`GpuBackend::encode_wave_overlay`],
//! [`GpuBackend::last_present_timing`], [`GpuBackend::read_presented`] (the drawn texture read
//! back without waiting) and the accessors (an `[area_light]`'s maps are fitted on the GPU, so a
//! web frame's soft shadows are the native ones). Everything
//! that waits for the GPU — [`GpuBackend::new`], [`find_adapter`], the [`Backend`] impl (it reads
//! the image back), `render_soft` and [`GpuBackend::time_frame`] — exists only off the web. There,
//! wgpu error scopes are not used (their results arrive asynchronously): errors reach the
//! device's uncaptured-error handler and are returned by the next frame's call.

#[cfg(test)]
mod curve_twins;
mod device;
mod formats;
pub mod layout;
mod meshes;
mod overlay;
mod passes;
mod prepare;
mod render;
pub mod shaders;
mod texture_read;
#[cfg(not(target_arch = "wasm32"))]
mod time_frame;
mod timing;
#[cfg(test)]
mod trace_twins;
#[cfg(test)]
mod twin_kernel;
#[cfg(test)]
mod twins;
mod window;

pub use formats::{PRESENT_FORMAT, PRESENT_USAGE};
pub use overlay::{DepthModel, OverlayBlend, OverlayProjection, OverlayTarget};
pub use passes::present::PresentedFrame;
pub use passes::soft::SOFT_BYTES_PER_PIXEL;
pub use render::MAX_TILE;
pub use texture_read::TextureRead;
pub use timing::{FrameTiming, PassTime, PresentTiming, TimingMethod, SOFT_PREPARATION, SOFT_TILES};
/// The wgpu version this backend is built on (for [`wgpu::AdapterInfo`] and its types).
pub use wgpu;

#[cfg(not(target_arch = "wasm32"))]
use hadou_scene::{Backend, Image};
use hadou_scene::{Frame, RenderError};

/// The wgpu backend. Create once and reuse: meshes stay uploaded between frames (cached by the
/// address of their `Arc`), and tile resources are reused while the tile size stays the same.
pub struct GpuBackend {
    renderer: render::Renderer,
}

/// The adapter [`GpuBackend::new`] would use, found without opening a device or compiling shaders
/// (cheap: what `--backend auto` asks before deciding). [`RenderError::NoDevice`] when there is
/// none or it cannot run hadou ("unsupported adapter …"). Not on the web.
#[cfg(not(target_arch = "wasm32"))]
pub fn find_adapter() -> Result<wgpu::AdapterInfo, RenderError> {
    device::adapter_info()
}

/// The adapter [`GpuBackend::new`] opens: `WGPU_BACKEND`'s backends when set, otherwise the
/// primary backends (Vulkan, Metal, DX12) and OpenGL only if none of those has one. For callers
/// that open the device themselves ([`GpuBackend::from_device`]); `Err` says why there is none.
/// Not on the web (it blocks).
#[cfg(not(target_arch = "wasm32"))]
pub fn request_adapter() -> Result<wgpu::Adapter, String> {
    device::request_adapter()
}

/// Whether `adapter` can run hadou (the downlevel capabilities, limits and texture formats the
/// passes use); check it before opening a device for [`GpuBackend::from_device`]. Every
/// shortfall is listed in one [`RenderError::NoDevice`] starting "unsupported adapter".
pub fn check_adapter(adapter: &wgpu::Adapter) -> Result<(), RenderError> {
    device::check_adapter(adapter, &adapter.get_info())
}

/// The optional features hadou uses when `adapter` has them: only
/// [`wgpu::Features::TIMESTAMP_QUERY`] (for [`GpuBackend::time_frame`]'s per-pass times and
/// [`GpuBackend::last_present_timing`]); none is
/// required. Part of [`device_descriptor`].
pub fn required_features(adapter: &wgpu::Adapter) -> wgpu::Features {
    device::required_features(adapter)
}

/// The limits hadou asks for: all that `adapter` offers (`adapter.limits()`); the tile size, the
/// shadow maps and the soft shadows' whole-image buffers follow the device's limits. Part of
/// [`device_descriptor`].
pub fn required_limits(adapter: &wgpu::Adapter) -> wgpu::Limits {
    device::required_limits(adapter)
}

/// What a device for [`GpuBackend::from_device`] should be requested with: the descriptor
/// [`GpuBackend::new`] uses ([`required_features`], [`required_limits`], label `"hadou-gpu"`).
/// A window may add the features it needs itself before requesting.
pub fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
    device::device_descriptor(adapter)
}

impl GpuBackend {
    /// Opens the best GPU adapter wgpu finds (honouring `WGPU_BACKEND`, `WGPU_ADAPTER_NAME`) and
    /// compiles the shaders. [`RenderError::NoDevice`] when there is no adapter. Not on the web
    /// (it blocks on the adapter and device requests): use [`GpuBackend::from_device`] there.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn new() -> Result<GpuBackend, RenderError> {
        Ok(Self { renderer: render::Renderer::new()? })
    }

    /// Builds the backend on a device someone else opened on `adapter` — a window's, on an
    /// adapter compatible with its surface, requested with [`device_descriptor`] — and compiles
    /// the shaders. Checks the adapter and the device's granted limits ([`RenderError::NoDevice`]
    /// "unsupported …" naming what is missing). Never blocks, so it is the constructor on the web.
    ///
    /// The backend installs its own uncaptured-error handler and device-lost callback on
    /// `device` (replacing any set before), so that errors become this backend's
    /// [`RenderError`]s; `device` and `queue` are shared handles, and the caller keeps using its
    /// clones for its own drawing.
    pub fn from_device(
        adapter: &wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
    ) -> Result<GpuBackend, RenderError> {
        let ctx = device::GpuContext::from_device(adapter, device, queue, true)?;
        Ok(Self { renderer: render::Renderer::from_context(ctx)? })
    }

    /// As [`GpuBackend::from_device`], but leaves the device's uncaptured-error handler and
    /// device-lost callback alone: for an engine that installed its own and must keep seeing
    /// every error (Bevy's renderer does). The backend still catches the errors of its own work
    /// with error scopes and returns them as [`RenderError`]s; an error outside them, or the
    /// device's loss, is the owner's handler's to report.
    pub fn from_shared_device(
        adapter: &wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
    ) -> Result<GpuBackend, RenderError> {
        let ctx = device::GpuContext::from_device(adapter, device, queue, false)?;
        Ok(Self { renderer: render::Renderer::from_context(ctx)? })
    }

    /// Renders the whole of `frame` (every tile) into one `frame.width × frame.height` texture of
    /// [`PRESENT_FORMAT`] (`Rgba8UnormSrgb`, usages [`PRESENT_USAGE`]) on the GPU, for a window to
    /// draw: no read-back, no wait — the work is submitted and the texture returned. Its bytes
    /// are `hadou_math::shade::linear_to_srgb8` of the colour [`Backend::render`] gives (within one
    /// code), alpha as stored (1). The texture is kept and drawn over while the frame size holds,
    /// and made anew when it changes ([`PresentedFrame::recreated`]). Errors as for `render`; on
    /// the web an error from the GPU surfaces on the next call.
    pub fn render_to_texture(&mut self, frame: &Frame) -> Result<PresentedFrame<'_>, RenderError> {
        self.renderer.render_to_texture(frame)
    }

    /// Starts reading back the texture the last [`GpuBackend::render_to_texture`] drew, without
    /// waiting: its bytes (`Rgba8UnormSrgb`, as drawn) arrive through [`TextureRead::try_take`]
    /// on a later frame. What a web page's screenshots, exports and test mode read. `None` before
    /// the first `render_to_texture`.
    pub fn read_presented(&self) -> Option<TextureRead> {
        self.renderer.read_presented()
    }

    /// Records `frame`'s waves into `encoder`, drawn into a colour target and against a depth
    /// buffer that the caller owns ([`OverlayTarget`]): per pixel the waves' light
    /// `exposure · Σ rgb·a·I` along the pixel's ray, clipped at the surface the depth buffer holds
    /// (002 §3.3.5), added to the target's colour or written over it, with no colour mapping
    /// (the caller's own tone mapping and bloom follow). This is what a game engine calls inside
    /// its frame (after its opaque pass, before tone mapping) and a page on its canvas: the same
    /// light [`Backend::render`] adds to the scene before its colour mapping, without hadou's
    /// objects, materials or shadows. Nothing is submitted or waited for; the buffers it uploads
    /// live as long as the encoded commands. Errors: an invalid frame, a device limit, or (on
    /// the next call, on the web) a target that does not fit the frame's size; a multisampled
    /// depth buffer on OpenGL (which reads it as empty).
    pub fn encode_wave_overlay(
        &mut self,
        frame: &Frame,
        encoder: &mut wgpu::CommandEncoder,
        target: &OverlayTarget<'_>,
    ) -> Result<(), RenderError> {
        self.renderer.encode_wave_overlay(frame, encoder, target)
    }

    /// [`GpuBackend::encode_wave_overlay`] with the frame's waves already prepared
    /// ([`layout::waves_buffers`] of `frame.waves`): a caller drawing the same waves into several
    /// views, or lighting its own materials with the prepared curves ([`layout::wave_lights`]),
    /// prepares each curve once per frame. `prepared` must be of `frame.waves` (the counts are
    /// checked; an error otherwise).
    pub fn encode_prepared_wave_overlay(
        &mut self,
        frame: &Frame,
        prepared: &layout::FrameWaves,
        encoder: &mut wgpu::CommandEncoder,
        target: &OverlayTarget<'_>,
    ) -> Result<(), RenderError> {
        self.renderer.encode_prepared_wave_overlay(frame, prepared, encoder, target)
    }

    /// Records `frame`'s shadow maps into `encoder`, drawn into the layers of a texture the
    /// caller owns: every map cast of its `[[shadow]]`s (`ShadowMethod::Map`; 000 §2.4's wave
    /// shadows and 001's sun shadows found by an orthographic map along each projection
    /// direction), map cast `i` (`layout::FrameShadows::map_casts`) in layer `i`, in the first
    /// `map_size²` texels (`layout::FrameShadows`, whose records say how to look them up, as the
    /// wave pass's `apply_shadows` does). Plane casts draw nothing here. `target` must be
    /// `Depth32Float` with `RENDER_ATTACHMENT` usage, at least `map_size` texels on each side and
    /// as many layers as map casts. Nothing is submitted. What an engine calls once a frame
    /// before the passes that read the maps.
    pub fn encode_shadow_maps_into(
        &mut self,
        frame: &Frame,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::Texture,
    ) -> Result<(), RenderError> {
        self.renderer.encode_shadow_maps_into(frame, encoder, target)
    }

    /// The GPU time of the most recent [`GpuBackend::render_to_texture`] frame whose timestamps
    /// have come back, without waiting: `None` until one has, and always `None` on a device
    /// without [`wgpu::Features::TIMESTAMP_QUERY`] (e.g. WebGL, or OpenGL without
    /// `GL_ARB_timer_query`; Mesa's desktop GL has it). Once one has come back, the
    /// latest stays returned until a newer one arrives ([`PresentTiming::serial`] says which frame
    /// it was: usually a frame or two behind the one just drawn).
    ///
    /// Each frame's passes write timestamps; they are copied into one of a few staging buffers,
    /// mapped asynchronously. This call polls the device without blocking (on the web the browser
    /// completes the maps itself) and reads whatever has been mapped. A frame finding every
    /// staging buffer still in flight is not timed, and neither is a frame with an
    /// `[area_light]` (its whole-image soft-shadow passes run outside the tiles' passes): use
    /// [`GpuBackend::time_frame`] for those.
    pub fn last_present_timing(&mut self) -> Option<PresentTiming> {
        self.renderer.last_present_timing()
    }

    /// The device this backend draws with.
    pub fn device(&self) -> &wgpu::Device {
        &self.renderer.ctx.device
    }

    /// The queue this backend submits to.
    pub fn queue(&self) -> &wgpu::Queue {
        &self.renderer.ctx.queue
    }

    /// The adapter's name (e.g. `"llvmpipe (LLVM 15.0.6, 256 bits)"`).
    pub fn adapter_name(&self) -> &str {
        &self.renderer.ctx.info.name
    }

    /// The adapter's full description from wgpu (backend, driver, device type).
    pub fn adapter_info(&self) -> &wgpu::AdapterInfo {
        &self.renderer.ctx.info
    }

    /// Whether the adapter is a software rasterizer on the CPU (device type `Cpu`, e.g. lavapipe).
    pub fn is_software(&self) -> bool {
        self.renderer.ctx.info.device_type == wgpu::DeviceType::Cpu
    }

    /// Whether the device supports GPU timestamps (then [`GpuBackend::time_frame`] uses them and
    /// [`GpuBackend::last_present_timing`] has times).
    pub fn has_timestamps(&self) -> bool {
        self.renderer.ctx.features.contains(wgpu::Features::TIMESTAMP_QUERY)
    }

    /// Renders `frame` and, when it has an `[area_light]`, reads back every pixel's soft-shadow
    /// class (`hadou_math::soft::Class as u8`) and visibility, row-major: what the differential
    /// tests compare with hadou-cpu's `soft::classify` and `soft::visibility`. `None` without an
    /// area light. With anti-aliasing these are the samples' (the sample frame's pixels,
    /// `Frame::sample_frame`).
    #[doc(hidden)]
    #[cfg(not(target_arch = "wasm32"))]
    pub fn render_soft(
        &mut self,
        frame: &Frame,
    ) -> Result<(Image, Option<passes::soft::SoftReadback>), RenderError> {
        let image = self.renderer.render(frame)?;
        let soft = if !frame.sample_grid().is_single() {
            self.renderer.read_soft(&frame.sample_frame())?
        } else {
            self.renderer.read_soft(frame)?
        };
        Ok((image, soft))
    }

    /// With `false`, every frame's wave pass runs the uber-shader (every wave kind, integrator and
    /// shading path compiled in) instead of the variant built for the frame's contents; for
    /// comparisons and tests. Both draw the same image. On by default.
    #[doc(hidden)]
    pub fn set_specialise(&mut self, on: bool) {
        self.renderer.set_specialise(on);
    }

    /// How many wave-pass pipelines (variants) this backend has built so far; for tests.
    #[doc(hidden)]
    pub fn wave_variants_built(&self) -> usize {
        self.renderer.wave_variants_built()
    }

    /// Measures [`GpuBackend::encode_wave_overlay`] alone: `frame`'s waves drawn additively into
    /// an `Rgba16Float` target against a cleared `Depth32Float` buffer of the frame's size (what a
    /// game engine's HDR view gives it), each iteration encoded, submitted and waited for, after
    /// one untimed warm-up; wall clock ([`TimingMethod::WallClock`]). The figure an engine's
    /// own frame timing of the same pass is compared with. Not on the web.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn time_wave_overlay(&mut self, frame: &Frame, iterations: u32) -> Result<FrameTiming, RenderError> {
        time_frame::time_wave_overlay(&mut self.renderer, frame, iterations)
    }

    /// Measures the GPU time of drawing `frame` as a PNG's pixels are drawn (its shadow maps, then
    /// every pass of every tile, the wave pass writing 8-bit sRGB as
    /// [`Backend::render_rows_rgb8`] does; no read-back), `iterations` times after one untimed
    /// warm-up; see [`FrameTiming`], whose
    /// `passes` split the time by pass when the adapter has timestamp queries. Not on the web.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn time_frame(&mut self, frame: &Frame, iterations: u32) -> Result<FrameTiming, RenderError> {
        time_frame::time_frame(&mut self.renderer, frame, iterations)
    }
}

/// Reads every tile back to the CPU: not on the web.
#[cfg(not(target_arch = "wasm32"))]
impl Backend for GpuBackend {
    fn name(&self) -> &str {
        "gpu"
    }

    fn render(&mut self, frame: &Frame) -> Result<Image, RenderError> {
        self.renderer.render(frame)
    }

    fn render_rows(&mut self, frame: &Frame, rows: std::ops::Range<u32>) -> Result<Image, RenderError> {
        self.renderer.render_rows(frame, rows)
    }

    /// A frame with a `[bloom]` needs the linear colour of a row and its glare halo in one
    /// storage binding ([`wgpu::Limits::max_storage_buffer_binding_size`]); one that does not fit
    /// is refused here, with the radius that fits.
    fn check_frame(&self, frame: &Frame) -> Result<(), String> {
        match &frame.bloom {
            Some(params) if frame.height > 0 => self
                .renderer
                .glare_bands(frame, params, 0..frame.height)
                .map(|_| ())
                .map_err(|e| e.to_string()),
            _ => Ok(()),
        }
    }

    /// The wave pass writes the 8-bit sRGB codes itself (the same thresholds as
    /// `hadou_math::shade::linear_to_srgb8`), so each tile reads back 4 bytes a pixel instead of
    /// 24; a frame with a `[bloom]` is converted from its float image.
    fn render_rows_rgb8(
        &mut self,
        frame: &Frame,
        rows: std::ops::Range<u32>,
    ) -> Result<hadou_scene::Rgb8Image, RenderError> {
        self.renderer.render_rows_rgb8(frame, rows)
    }
}
