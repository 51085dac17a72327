//! # hadou-gpu
//!
//! hadou's wgpu backend: the real-time path, drawing the same picture as the CPU reference.
//!
//! [`GpuBackend`] renders a [`Frame`] headlessly (no window or surface) in two passes per tile:
//! 1. **raster** (`shaders/raster.wgsl`): the opaque meshes, depth-tested, shaded with the WGSL
//!    twin of `hadou_math::shade::diffuse`, writing the scene colour and the Euclidean eye distance
//!    of the visible surface;
//! 2. **wave** (`shaders/wave.wgsl`, a compute shader): per pixel, the ray of
//!    `hadou_scene::CameraBasis::wave_ray` clipped at that distance (002 §3.3.5), the exact energy
//!    integral of every analytic wave (`shaders/energy.wgsl`, twins of `hadou_math::energy`) and
//!    of every curved wave (`shaders/curve.wgsl`, twins of `hadou_math::curve`: the default
//!    chord-walk integrator over the uploaded `PieceTable` and the faithful Simpson integrator),
//!    `scene + exposure·Σ rgb·a·I` and the colour mapping.
//!
//! Hard shadows (`Frame::shadows`) add a plane-shadow pass per tile between the two
//! (`shaders/shadow_raster.wgsl`: each plane cast's casters projected onto its plane, keeping per
//! pixel the most opaque cast), shadow maps drawn once per frame into a depth array texture, and
//! the lookup in the wave pass (`shaders/shadow_lookup.wgsl`), mirroring `hadou-cpu`'s shadows.
//!
//! Images are processed in tiles of at most [`MAX_TILE`]² pixels, each read back before the next,
//! so GPU memory stays bounded whatever the image size. A frame with nothing to draw (waves only)
//! skips the raster pass.
//!
//! The wave pass is specialised per frame: the wave module declares pipeline-overridable `bool`
//! constants (`USE_SPHERE`, `USE_CURVE`, `USE_SURFACES`, `USE_TEXTURES`, …, all `true` by
//! default: the uber-shader) guarding each wave kind, falloff, curve integrator and shape, and each
//! shading path; each frame gets a compute pipeline with only what its data can reach compiled in,
//! built on first use and cached by that set. Software adapters need this: llvmpipe (lavapipe,
//! and Mesa's GL) runs every branch of a shader under an execution mask whichever way the pixels
//! go, so with the uber-shader a one-sphere frame paid for every kind, the curve walker and the
//! surface shading (about 0.8 s instead of 6 ms at 512²). A variant renders bit for bit what the
//! uber-shader renders (`tests/variants.rs`).
//!
//! Curved waves are prepared once per frame with `hadou_math::curve::prepare` (as the CPU backend
//! does) and uploaded as storage buffers ([`layout::CurveBuffers`]).
//!
//! Failures never panic: no adapter is [`RenderError::NoDevice`]; a lost device, out-of-memory or
//! a GPU that does not answer within a timeout is [`RenderError::Device`]; a shader that fails to
//! compile is [`RenderError::Other`] naming the shader.

#[cfg(test)]
mod curve_twins;
mod device;
pub mod layout;
mod pipelines;
mod render;
pub mod shaders;
mod timing;
#[cfg(test)]
mod twins;

pub use render::{MAX_TILE, SOFT_BYTES_PER_PIXEL};
pub use timing::{FrameTiming, PassTime, TimingMethod};
/// The wgpu version this backend is built on (for [`wgpu::AdapterInfo`] and its types).
pub use wgpu;

use hadou_scene::{Backend, Frame, Image, RenderError};

/// The wgpu backend. Create once and reuse: meshes stay uploaded between frames (cached by the
/// address of their `Arc`), and tile resources are reused while the tile size stays the same.
pub struct GpuBackend {
    renderer: render::Renderer,
}

/// The adapter [`GpuBackend::new`] would use, found without opening a device or compiling shaders
/// (cheap: what `--backend auto` asks before deciding). [`RenderError::NoDevice`] when there is
/// none or it cannot run hadou ("unsupported adapter …").
pub fn find_adapter() -> Result<wgpu::AdapterInfo, RenderError> {
    device::adapter_info()
}

impl GpuBackend {
    /// Opens the best GPU adapter wgpu finds (honouring `WGPU_BACKEND`, `WGPU_ADAPTER_NAME`) and
    /// compiles the shaders. [`RenderError::NoDevice`] when there is no adapter.
    pub fn new() -> Result<GpuBackend, RenderError> {
        Ok(Self { renderer: render::Renderer::new()? })
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

    /// Whether the device supports GPU timestamps (then [`GpuBackend::time_frame`] uses them).
    pub fn has_timestamps(&self) -> bool {
        self.renderer.ctx.features.contains(wgpu::Features::TIMESTAMP_QUERY)
    }

    /// Renders `frame` and, when it has an `[area_light]`, reads back every pixel's soft-shadow
    /// class (`hadou_math::soft::Class as u8`) and visibility, row-major: what the differential
    /// tests compare with hadou-cpu's `soft::classify` and `soft::visibility`. `None` without an
    /// area light.
    #[doc(hidden)]
    pub fn render_soft(
        &mut self,
        frame: &Frame,
    ) -> Result<(Image, Option<render::SoftReadback>), RenderError> {
        let image = self.renderer.render(frame)?;
        let soft = self.renderer.read_soft(frame)?;
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

    /// Measures the GPU time of drawing `frame` (its shadow maps, then every pass of every tile,
    /// no read-back), `iterations` times after one untimed warm-up; see [`FrameTiming`], whose
    /// `passes` split the time by pass when the adapter has timestamp queries.
    pub fn time_frame(&mut self, frame: &Frame, iterations: u32) -> Result<FrameTiming, RenderError> {
        timing::time_frame(&mut self.renderer, frame, iterations)
    }
}

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
}
