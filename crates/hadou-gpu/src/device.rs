//! Adapter and device set-up, and the failure story: every wgpu error is captured (error scopes
//! plus an uncaptured-error handler that records instead of panicking), device loss is recorded
//! by a callback, and every wait on the GPU has a timeout. All of it ends in a [`RenderError`].
//!
//! On the web (`wasm32`) nothing here blocks: there is no adapter search or device request of our
//! own (the page opens the device and hands it to [`GpuContext::from_device`]), no waits, and no
//! error scopes — their results arrive only after the browser's GPU process answers, so errors
//! go to the uncaptured-error handler instead and [`GpuContext::check`] reports them on the next
//! frame.

use hadou_scene::RenderError;
use std::sync::{Arc, Mutex};
#[cfg(not(target_arch = "wasm32"))]
use std::time::Duration;

/// Serialises the GPU work of this crate's unit tests: Mesa 22's lavapipe crashed (SIGSEGV) with
/// several devices rendering at once from parallel test threads.
#[cfg(test)]
pub(crate) fn test_gpu_lock() -> std::sync::MutexGuard<'static, ()> {
    static LOCK: Mutex<()> = Mutex::new(());
    LOCK.lock().unwrap_or_else(|p| p.into_inner())
}

/// A device for one unit test, holding [`test_gpu_lock`] while the test runs, or `None` with a
/// skip message when there is no usable adapter (a failure under `HADOU_REQUIRE_GPU=1`).
#[cfg(test)]
pub(crate) fn context_or_skip(test: &str) -> Option<(GpuContext, std::sync::MutexGuard<'static, ()>)> {
    let lock = test_gpu_lock();
    match GpuContext::new() {
        Ok(c) => Some((c, lock)),
        Err(RenderError::NoDevice(m)) => {
            assert!(std::env::var("HADOU_REQUIRE_GPU").map_or(true, |v| v != "1"), "{test}: {m}");
            eprintln!("SKIPPED {test}: no GPU adapter ({m})");
            None
        }
        Err(e) => panic!("{test}: {e}"),
    }
}

/// How long one wait for submitted work may take before a hardware device is declared hung.
#[cfg(not(target_arch = "wasm32"))]
pub(crate) const WAIT_TIMEOUT: Duration = Duration::from_secs(120);

/// The same for a software adapter (llvmpipe, SwiftShader, WARP). Such an adapter compiles a
/// shader to machine code when it first runs it, inside the submission being waited for, and on
/// its own CPU cores, which a loaded machine shares: the first frame of a large module (the
/// uber-shader) takes minutes where the shader cache is cold. A hang is still reported, later.
#[cfg(not(target_arch = "wasm32"))]
pub(crate) const SOFTWARE_WAIT_TIMEOUT: Duration = Duration::from_secs(900);

/// How long one wait for submitted work on the adapter `info` may take (see [`WAIT_TIMEOUT`] and
/// [`SOFTWARE_WAIT_TIMEOUT`]).
#[cfg(not(target_arch = "wasm32"))]
pub(crate) fn wait_timeout(info: &wgpu::AdapterInfo) -> Duration {
    if info.device_type == wgpu::DeviceType::Cpu {
        SOFTWARE_WAIT_TIMEOUT
    } else {
        WAIT_TIMEOUT
    }
}

/// Errors the device reported outside any error scope, and the reason it was lost, if it was.
#[derive(Default)]
struct Reports {
    uncaptured: Vec<String>,
    lost: Option<String>,
}

/// Error scopes pushed by [`GpuContext::open_scopes`] (none on the web, see the module docs).
pub(crate) struct ErrorScopes {
    #[cfg(not(target_arch = "wasm32"))]
    oom: wgpu::ErrorScopeGuard,
    #[cfg(not(target_arch = "wasm32"))]
    internal: wgpu::ErrorScopeGuard,
    #[cfg(not(target_arch = "wasm32"))]
    validation: wgpu::ErrorScopeGuard,
}

/// An open device with its queue and error bookkeeping.
pub(crate) struct GpuContext {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    pub(crate) info: wgpu::AdapterInfo,
    pub(crate) limits: wgpu::Limits,
    pub(crate) features: wgpu::Features,
    reports: Arc<Mutex<Reports>>,
}

#[cfg(not(target_arch = "wasm32"))]
impl Drop for GpuContext {
    /// Waits (up to [`wait_timeout`]) for every submission before the queue goes: wgpu's own
    /// wait when a queue is dropped gives up after about 6 s and panics, and a software adapter
    /// compiling a large shader on a busy machine can take longer than that. (Not on the web,
    /// where nothing may block and the browser keeps the work alive.)
    fn drop(&mut self) {
        let _ = self
            .device
            .poll(wgpu::PollType::Wait { submission_index: None, timeout: Some(wait_timeout(&self.info)) });
    }
}

fn lock(reports: &Mutex<Reports>) -> std::sync::MutexGuard<'_, Reports> {
    // A poisoned lock only means a callback panicked mid-push; the data is still usable.
    reports.lock().unwrap_or_else(|p| p.into_inner())
}

/// The best adapter: the primary backends (Vulkan, Metal, DX12) first, OpenGL only if none of
/// those has one. `WGPU_BACKEND` (e.g. `gl`, `vulkan`) overrides the choice.
#[cfg(not(target_arch = "wasm32"))]
pub(crate) fn request_adapter() -> Result<wgpu::Adapter, String> {
    let options = wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        force_fallback_adapter: false,
        compatible_surface: None,
    };
    let from_env = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    let tries = if std::env::var_os("WGPU_BACKEND").is_some() {
        vec![from_env.backends]
    } else {
        vec![wgpu::Backends::PRIMARY, wgpu::Backends::SECONDARY]
    };
    let mut errors = Vec::new();
    for backends in tries {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        desc.backends = backends;
        let instance = wgpu::Instance::new(desc);
        match pollster::block_on(instance.request_adapter(&options)) {
            Ok(a) => return Ok(a),
            Err(e) => errors.push(e.to_string()),
        }
    }
    Err(errors.join("; "))
}

/// The capabilities hadou needs beyond wgpu's downlevel (WebGL2-class) baseline, each with the
/// words an "unsupported adapter" error uses for it.
const NEEDED_DOWNLEVEL: [(wgpu::DownlevelFlags, &str); 3] = [
    (wgpu::DownlevelFlags::COMPUTE_SHADERS, "compute shaders (the wave pass is one)"),
    (wgpu::DownlevelFlags::VERTEX_STORAGE, "storage buffers in vertex shaders (per-object data)"),
    (wgpu::DownlevelFlags::FRAGMENT_STORAGE, "storage buffers in fragment shaders (per-object data)"),
];

/// Storage buffers the wave pass binds in one compute stage (keep in sync with passes/wave.rs BINDINGS):
/// waves, output, three curve buffers, materials, lights, shading data.
const NEEDED_COMPUTE_STORAGE_BUFFERS: u32 = 8;
/// Colour targets of the raster pass (the two G-buffer targets of raster.wgsl).
const NEEDED_COLOR_ATTACHMENTS: u32 = 2;
/// Bytes per sample those targets take together (two `Rgba32Uint`).
const NEEDED_COLOR_BYTES: u32 = 32;
/// Array layers of the shadow-map texture at least (two even for one map: OpenGL backends take a
/// one-layer array texture for a plain 2D one).
const NEEDED_ARRAY_LAYERS: u32 = 2;
/// Textures the wave pass reads in one compute stage: the two G-buffer targets, the plane-shadow
/// target and the shadow maps.
const NEEDED_COMPUTE_TEXTURES: u32 = 4;
/// Storage textures one compute stage writes: the edge pass's output (`Rgba32Uint`).
const NEEDED_STORAGE_TEXTURES: u32 = 1;
/// Invocations per workgroup the kernels use (8×8 wave pass, 64×1 twin-test kernels).
const NEEDED_WORKGROUP_INVOCATIONS: u32 = 64;

/// The optional features hadou uses when `adapter` has them (timestamp queries, for
/// [`crate::GpuBackend::time_frame`]); it requires none.
pub(crate) fn required_features(adapter: &wgpu::Adapter) -> wgpu::Features {
    adapter.features() & wgpu::Features::TIMESTAMP_QUERY
}

/// The limits hadou asks for: everything `adapter` offers (tiles, shadow maps and the soft
/// shadows' whole-image buffers grow with the limits).
pub(crate) fn required_limits(adapter: &wgpu::Adapter) -> wgpu::Limits {
    adapter.limits()
}

/// The descriptor [`GpuContext::new`] opens its device with.
pub(crate) fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
    wgpu::DeviceDescriptor {
        label: Some("hadou-gpu"),
        required_features: required_features(adapter),
        required_limits: required_limits(adapter),
        experimental_features: wgpu::ExperimentalFeatures::disabled(),
        memory_hints: wgpu::MemoryHints::MemoryUsage,
        trace: wgpu::Trace::Off,
    }
}

/// Checks, before a device is opened, that `adapter` can run hadou: the downlevel capabilities,
/// the limits and the texture formats the passes use. Every shortfall is listed in one
/// [`RenderError::NoDevice`] starting "unsupported adapter", so callers and tests treat it like a
/// missing adapter (a skip, or a failure under `HADOU_REQUIRE_GPU=1`).
pub(crate) fn check_adapter(adapter: &wgpu::Adapter, info: &wgpu::AdapterInfo) -> Result<(), RenderError> {
    check_capabilities(adapter, info, &adapter.limits(), "adapter")
}

/// [`check_adapter`] with the limits of a device already opened on `adapter` (`what`:
/// "adapter" or "device", for the message).
fn check_capabilities(
    adapter: &wgpu::Adapter,
    info: &wgpu::AdapterInfo,
    limits: &wgpu::Limits,
    what: &str,
) -> Result<(), RenderError> {
    let mut missing: Vec<String> = Vec::new();
    let downlevel = adapter.get_downlevel_capabilities();
    for (flag, what) in NEEDED_DOWNLEVEL {
        if !downlevel.flags.contains(flag) {
            missing.push(what.into());
        }
    }
    if limits.max_storage_buffers_per_shader_stage < NEEDED_COMPUTE_STORAGE_BUFFERS {
        missing.push(format!(
            "{NEEDED_COMPUTE_STORAGE_BUFFERS} storage buffers per shader stage (it allows {})",
            limits.max_storage_buffers_per_shader_stage
        ));
    }
    if limits.max_color_attachments < NEEDED_COLOR_ATTACHMENTS
        || limits.max_color_attachment_bytes_per_sample < NEEDED_COLOR_BYTES
    {
        missing.push(format!(
            "{NEEDED_COLOR_ATTACHMENTS} colour targets of {NEEDED_COLOR_BYTES} bytes per pixel together (it allows \
             {} targets, {} bytes)",
            limits.max_color_attachments, limits.max_color_attachment_bytes_per_sample
        ));
    }
    if limits.max_compute_invocations_per_workgroup < NEEDED_WORKGROUP_INVOCATIONS
        || limits.max_compute_workgroup_size_x < NEEDED_WORKGROUP_INVOCATIONS
    {
        missing.push(format!(
            "{NEEDED_WORKGROUP_INVOCATIONS} compute invocations per workgroup (it allows {})",
            limits.max_compute_invocations_per_workgroup
        ));
    }
    if limits.max_texture_array_layers < NEEDED_ARRAY_LAYERS {
        missing.push(format!(
            "{NEEDED_ARRAY_LAYERS} texture array layers (it allows {})",
            limits.max_texture_array_layers
        ));
    }
    if limits.max_storage_textures_per_shader_stage < NEEDED_STORAGE_TEXTURES {
        missing.push(format!(
            "{NEEDED_STORAGE_TEXTURES} storage texture per shader stage (it allows {})",
            limits.max_storage_textures_per_shader_stage
        ));
    }
    if limits.max_sampled_textures_per_shader_stage < NEEDED_COMPUTE_TEXTURES {
        missing.push(format!(
            "{NEEDED_COMPUTE_TEXTURES} sampled textures per shader stage (it allows {})",
            limits.max_sampled_textures_per_shader_stage
        ));
    }
    let attach_and_read = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
    let formats = [
        (crate::formats::SCENE_FORMAT, attach_and_read),
        (
            crate::formats::SCENE_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
        ),
        (crate::formats::DEPTH_FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT),
        (crate::formats::PLANE_SHADOW_FORMAT, attach_and_read),
        (crate::formats::MAP_FORMAT, attach_and_read),
        (crate::formats::PRESENT_FORMAT, crate::formats::PRESENT_USAGE),
    ];
    for (format, usages) in formats {
        if !adapter.get_texture_format_features(format).allowed_usages.contains(usages) {
            missing.push(format!("{format:?} textures with usage {usages:?}"));
        }
    }
    if missing.is_empty() {
        return Ok(());
    }
    Err(RenderError::NoDevice(format!(
        "unsupported {what} `{}` ({:?}, driver {} {}): it lacks {}",
        info.name,
        info.backend,
        info.driver,
        info.driver_info,
        missing.join("; ")
    )))
}

/// The adapter [`GpuContext::new`] would open, without opening a device or compiling anything:
/// what `--backend auto` asks before deciding.
#[cfg(not(target_arch = "wasm32"))]
pub(crate) fn adapter_info() -> Result<wgpu::AdapterInfo, RenderError> {
    let adapter =
        request_adapter().map_err(|e| RenderError::NoDevice(format!("no GPU adapter found ({e})")))?;
    let info = adapter.get_info();
    check_adapter(&adapter, &info)?;
    Ok(info)
}

/// The first error of a popped error scope. wgpu-core (every native backend) pops synchronously,
/// so the future is ready at once and this never waits; the blocking fallback is only for a
/// future that is not.
#[cfg(not(target_arch = "wasm32"))]
fn pop_now(scope: wgpu::ErrorScopeGuard) -> Option<wgpu::Error> {
    use std::future::Future;
    let mut future = std::pin::pin!(scope.pop());
    let mut cx = std::task::Context::from_waker(std::task::Waker::noop());
    match future.as_mut().poll(&mut cx) {
        std::task::Poll::Ready(error) => error,
        std::task::Poll::Pending => pollster::block_on(future),
    }
}

impl GpuContext {
    /// Opens the best adapter wgpu finds (no surface; `WGPU_BACKEND` and friends are honoured).
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn new() -> Result<Self, RenderError> {
        let adapter = request_adapter().map_err(|e| {
            RenderError::NoDevice(format!(
                "no GPU adapter found ({e}); install a Vulkan driver (on machines without a GPU, \
                 Mesa's lavapipe: package mesa-vulkan-drivers) or use the CPU backend"
            ))
        })?;
        let info = adapter.get_info();
        check_adapter(&adapter, &info)?;
        let (device, queue) = pollster::block_on(adapter.request_device(&device_descriptor(&adapter)))
            .map_err(|e| RenderError::NoDevice(format!("adapter `{}` refused a device: {e}", info.name)))?;
        Ok(Self::with_device(device, queue, info))
    }

    /// A context on a device someone else opened on `adapter` (a window's, compatible with its
    /// surface): checks the adapter and the device's limits as [`GpuContext::new`] does, and
    /// installs the error and device-loss handlers (replacing any the device had) when
    /// `install_handlers`; without, the owner's handlers stay and see every error outside this
    /// context's error scopes. Never blocks.
    pub(crate) fn from_device(
        adapter: &wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
        install_handlers: bool,
    ) -> Result<Self, RenderError> {
        let info = adapter.get_info();
        check_capabilities(adapter, &info, &device.limits(), "device")?;
        if install_handlers {
            Ok(Self::with_device(device, queue, info))
        } else {
            Ok(Self::without_handlers(device, queue, info))
        }
    }

    fn with_device(device: wgpu::Device, queue: wgpu::Queue, info: wgpu::AdapterInfo) -> Self {
        let context = Self::without_handlers(device, queue, info);
        let r = context.reports.clone();
        context
            .device
            .on_uncaptured_error(Arc::new(move |e: wgpu::Error| lock(&r).uncaptured.push(e.to_string())));
        let r = context.reports.clone();
        context.device.set_device_lost_callback(move |reason, message| {
            lock(&r).lost = Some(format!("{reason:?}: {message}"));
        });
        context
    }

    /// A context whose reports stay empty: errors reach it only through its error scopes.
    fn without_handlers(device: wgpu::Device, queue: wgpu::Queue, info: wgpu::AdapterInfo) -> Self {
        // What the device was granted, which for one opened elsewhere may be less than the adapter's.
        let (limits, features) = (device.limits(), device.features());
        let reports = Arc::new(Mutex::new(Reports::default()));
        Self { device, queue, info, limits, features, reports }
    }

    /// `Err` if the device was lost or reported an error nobody caught.
    pub(crate) fn check(&self) -> Result<(), RenderError> {
        let mut r = lock(&self.reports);
        if let Some(lost) = &r.lost {
            return Err(RenderError::Device(format!("the GPU device was lost ({lost})")));
        }
        if !r.uncaptured.is_empty() {
            let all = std::mem::take(&mut r.uncaptured).join("; ");
            return Err(RenderError::Device(format!("the GPU reported: {all}")));
        }
        Ok(())
    }

    /// Opens out-of-memory, internal and validation error scopes; close them with
    /// [`GpuContext::close_scopes`] on the same thread.
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn open_scopes(&self) -> ErrorScopes {
        ErrorScopes {
            oom: self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory),
            internal: self.device.push_error_scope(wgpu::ErrorFilter::Internal),
            validation: self.device.push_error_scope(wgpu::ErrorFilter::Validation),
        }
    }

    /// On the web: no scopes (see the module docs).
    #[cfg(target_arch = "wasm32")]
    pub(crate) fn open_scopes(&self) -> ErrorScopes {
        ErrorScopes {}
    }

    /// Closes scopes from [`GpuContext::open_scopes`]; any error they caught becomes a
    /// [`RenderError`] (`what` says what was being done).
    /// Never blocks (see [`pop_now`]); on the web there are no scopes and this is
    /// [`GpuContext::check`].
    pub(crate) fn close_scopes(&self, scopes: ErrorScopes, what: &str) -> Result<(), RenderError> {
        #[cfg(target_arch = "wasm32")]
        let _ = (scopes, what);
        #[cfg(not(target_arch = "wasm32"))]
        {
            // Pop in reverse order of pushing.
            let validation = pop_now(scopes.validation);
            let internal = pop_now(scopes.internal);
            let oom = pop_now(scopes.oom);
            Self::scope_errors(oom, internal, validation, what)?;
        }
        self.check()
    }

    /// The first of the errors the scopes caught, as a [`RenderError`].
    #[cfg(not(target_arch = "wasm32"))]
    fn scope_errors(
        oom: Option<wgpu::Error>,
        internal: Option<wgpu::Error>,
        validation: Option<wgpu::Error>,
        what: &str,
    ) -> Result<(), RenderError> {
        if let Some(e) = oom {
            return Err(RenderError::Device(format!("out of GPU memory while {what}: {e}")));
        }
        if let Some(e) = internal {
            return Err(RenderError::Device(format!("GPU internal error while {what}: {e}")));
        }
        if let Some(e) = validation {
            return Err(RenderError::Other(format!("GPU rejected the work while {what}: {e}")));
        }
        Ok(())
    }

    /// Runs `f` inside [`GpuContext::open_scopes`] / [`GpuContext::close_scopes`].
    pub(crate) fn scoped<T>(&self, what: &str, f: impl FnOnce() -> T) -> Result<T, RenderError> {
        let scopes = self.open_scopes();
        let value = f();
        self.close_scopes(scopes, what)?;
        Ok(value)
    }

    /// Waits (with [`wait_timeout`]) until `submission` has finished on the GPU.
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn wait(&self, submission: wgpu::SubmissionIndex) -> Result<(), RenderError> {
        let timeout = wait_timeout(&self.info);
        self.device
            .poll(wgpu::PollType::Wait { submission_index: Some(submission), timeout: Some(timeout) })
            .map_err(|e| RenderError::Device(format!("waiting for the GPU failed after {timeout:?}: {e}")))?;
        self.check()
    }

    /// Maps `buffer` for reading after `submission`, waiting with a timeout, and hands its bytes
    /// to `read`; unmaps afterwards.
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn read_buffer<T>(
        &self,
        buffer: &wgpu::Buffer,
        size: u64,
        submission: wgpu::SubmissionIndex,
        read: impl FnOnce(&[u8]) -> T,
    ) -> Result<T, RenderError> {
        let slot: Arc<Mutex<Option<Result<(), wgpu::BufferAsyncError>>>> = Arc::new(Mutex::new(None));
        let s = slot.clone();
        buffer.slice(..size).map_async(wgpu::MapMode::Read, move |r| {
            *s.lock().unwrap_or_else(|p| p.into_inner()) = Some(r);
        });
        self.wait(submission)?;
        // The callback runs during the poll above; poll once more in case it was queued after.
        let _ = self.device.poll(wgpu::PollType::Poll);
        let outcome = slot.lock().unwrap_or_else(|p| p.into_inner()).take();
        match outcome {
            Some(Ok(())) => {}
            Some(Err(e)) => return Err(RenderError::Device(format!("reading back the image failed: {e}"))),
            None => {
                return Err(RenderError::Device("the GPU never finished mapping the read-back buffer".into()))
            }
        }
        let value = {
            let view = buffer.slice(..size).get_mapped_range();
            read(&view)
        };
        buffer.unmap();
        Ok(value)
    }
}
