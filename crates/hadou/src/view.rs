//! `hadou view`: the window. winit owns the event loop, one wgpu device drives both the window's
//! surface (egui's drawing) and, when it is chosen, the GPU backend, which renders straight into a
//! texture the viewport shows ([`GpuBackend::render_to_texture`]: no read-back). The CPU backend
//! renders on a worker thread, so the UI handles input every frame while a frame renders; its
//! finished image is converted to sRGB bytes there and uploaded into a texture of the same format.
//! The state, panels and script language are `hadou_view`'s; this module is the native shell:
//! devices, threads, screenshots, exports and probes.

use crate::export::{self, AnimationSpec, Control, ExportOutcome};
use crate::output;
use hadou_gpu::wgpu;
use hadou_gpu::GpuBackend;
use hadou_scene::{Backend, Frame, Image, Scene};
use hadou_view::document::Document;
use hadou_view::script::{self, WindowOp};
use hadou_view::ui::{UiState, ViewportImage};
use hadou_view::viewer::{BackendKind, Request, Viewer};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::mpsc;
use std::sync::Arc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::{Window, WindowId};

/// What `hadou view` was asked to do.
#[derive(Clone, Debug, Default)]
pub struct ViewOptions {
    /// The scene file.
    pub scene: PathBuf,
    /// A script to run (see `hadou_view::script`).
    pub script: Option<PathBuf>,
    /// Write the viewport here and exit (after the script, if any).
    pub screenshot: Option<PathBuf>,
    /// Start at this time.
    pub time: Option<f32>,
    /// Force a backend (else chosen automatically).
    pub backend: Option<BackendKind>,
    /// Print the frame-time figures as JSON on exit.
    pub stats: bool,
}

/// A failure with its exit code (2: bad input; 1: everything else).
#[derive(Debug)]
pub struct ViewError {
    /// Exit code.
    pub code: u8,
    /// The message.
    pub message: String,
}

fn fail(code: u8, message: impl Into<String>) -> ViewError {
    ViewError { code, message: message.into() }
}

/// The message when there is no display to open a window on.
pub fn no_display_message(detail: &str) -> String {
    format!(
        "hadou view needs a display, and none could be opened ({detail}). On Linux it uses the X11 \
         server named by DISPLAY or the Wayland compositor named by WAYLAND_DISPLAY; neither is usable \
         here. Run it in a desktop session, or under a virtual X server: `xvfb-run -a hadou view SCENE`; \
         without a window, `hadou render SCENE -o out.png` writes the same image (`--frames A..B` for \
         an animation) and `hadou probe` reads single pixels"
    )
}

/// Opens the viewer on `opts.scene` and runs until the window closes (or the script ends).
pub fn run(opts: ViewOptions) -> Result<(), ViewError> {
    let doc = Document::open(&opts.scene).map_err(|e| fail(2, e.to_string()))?;
    let script = match &opts.script {
        Some(p) => {
            let bytes = hadou_scene::read_regular_file(p, 1 << 20)
                .map_err(|e| fail(2, format!("{}: cannot read the script: {e}", p.display())))?;
            let text = String::from_utf8(bytes).map_err(|e| {
                let at = e.utf8_error().valid_up_to();
                fail(2, format!("{}: the script is not UTF-8 text (byte {at})", p.display()))
            })?;
            Some((script::parse(&text, p).map_err(|e| fail(2, e))?, p.clone()))
        }
        None => None,
    };
    for p in opts.screenshot.iter() {
        output::check_writable(p).map_err(|e| fail(2, e.to_string()))?;
    }
    #[cfg(all(unix, not(target_os = "macos")))]
    if std::env::var_os("DISPLAY").is_none() && std::env::var_os("WAYLAND_DISPLAY").is_none() {
        return Err(fail(1, no_display_message("DISPLAY and WAYLAND_DISPLAY are both unset")));
    }
    let event_loop = EventLoop::new().map_err(|e| fail(1, no_display_message(&e.to_string())))?;
    let mut viewer = Viewer::new(doc);
    if let Some(t) = opts.time {
        viewer.timeline.time = t;
    }
    let cpu = CpuWorker::start().map_err(|e| fail(1, format!("cannot start the CPU render thread: {e}")))?;
    let mut app = App::new(viewer, opts, script, cpu);
    event_loop.run_app(&mut app).map_err(|e| fail(1, format!("the window's event loop failed: {e}")))?;
    if let Some(e) = app.fatal.take() {
        return Err(e);
    }
    if app.opts.stats {
        println!("{}", app.stats_json());
    }
    Ok(())
}

/// A CPU frame finished on the worker.
struct CpuDone {
    generation: u64,
    size: [u32; 2],
    rgba: Vec<u8>,
    render_ms: f64,
    convert_ms: f64,
}

/// The CPU backend on its own thread: one frame in flight at a time.
struct CpuWorker {
    jobs: mpsc::Sender<(u64, Frame)>,
    done: mpsc::Receiver<CpuDone>,
    /// Uploaded pixel buffers, returned to the worker for reuse.
    back: mpsc::Sender<Vec<u8>>,
    busy: bool,
}

impl CpuWorker {
    fn start() -> std::io::Result<CpuWorker> {
        let (jobs, job_rx) = mpsc::channel::<(u64, Frame)>();
        let (done_tx, done) = mpsc::channel();
        let (back, back_rx) = mpsc::channel::<Vec<u8>>();
        std::thread::Builder::new().name("hadou-view-cpu".into()).spawn(move || {
            let mut backend = crate::CpuBackend::new();
            let mut image = Image::new(1, 1);
            let mut spare: Vec<Vec<u8>> = Vec::new();
            while let Ok((mut generation, mut frame)) = job_rx.recv() {
                // Buffers the window has uploaded come back for reuse.
                while let Ok(b) = back_rx.try_recv() {
                    spare.push(b);
                }
                // Only the newest frame matters.
                while let Ok(newer) = job_rx.try_recv() {
                    (generation, frame) = newer;
                }
                let t0 = Instant::now();
                backend.render_into(&frame, &mut image);
                let render_ms = t0.elapsed().as_secs_f64() * 1e3;
                let t1 = Instant::now();
                let mut rgba = spare.pop().unwrap_or_default();
                srgba8_into(&image, &mut rgba);
                let convert_ms = t1.elapsed().as_secs_f64() * 1e3;
                let size = [image.width, image.height];
                if done_tx.send(CpuDone { generation, size, rgba, render_ms, convert_ms }).is_err() {
                    break;
                }
            }
        })?;
        Ok(CpuWorker { jobs, done, back, busy: false })
    }
}

/// 8-bit sRGB RGBA (alpha opaque) of `image`'s colour, as `hadou render`'s PNG codes: what the
/// CPU path uploads for the viewport. Written into `out` (resized; reused between frames so no
/// fresh pages are touched), rows in parallel.
pub fn srgba8_into(image: &Image, out: &mut Vec<u8>) {
    use rayon::prelude::*;
    out.resize(image.color.len() * 4, 255);
    out.par_chunks_mut(4 * 16384)
        .zip(image.color.par_chunks(16384))
        .for_each(|(o, c)| hadou_math::shade::rgba_to_srgba8(c, o));
}

/// The texture the CPU path's image is uploaded into: `size`, `Rgba8UnormSrgb` (the bytes are
/// sRGB codes; sampling gives linear colour back), sampled and written.
pub fn viewport_texture(device: &wgpu::Device, size: [u32; 2]) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("hadou view CPU image"),
        size: wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8UnormSrgb,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

/// Writes 8-bit RGBA rows (`4 · size[0]` bytes each) into the whole of `texture`.
pub fn upload_rgba(queue: &wgpu::Queue, texture: &wgpu::Texture, rgba: &[u8], size: [u32; 2]) {
    queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        rgba,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(4 * size[0]),
            rows_per_image: Some(size[1]),
        },
        wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
    );
}

/// Timings of one new image, ms.
#[derive(Clone, Copy)]
struct Sample {
    /// Wall time since the previous window frame.
    frame: f64,
    /// The renderer's time.
    render: f64,
    /// The viewer's own work on the image (evaluation, conversion, upload).
    image: f64,
    /// Building and drawing the UI.
    ui: f64,
}

/// A running export.
struct ExportJob {
    done: Arc<AtomicU32>,
    total: u32,
    cancel: Arc<AtomicBool>,
    result: mpsc::Receiver<Result<String, String>>,
}

/// The window's GPU state.
struct Gfx {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    device: wgpu::Device,
    queue: wgpu::Queue,
    config: wgpu::SurfaceConfiguration,
    egui_renderer: egui_wgpu::Renderer,
    egui_state: egui_winit::State,
    /// The GPU backend on the window's device (when the adapter can run hadou).
    gpu: Option<GpuBackend>,
    gpu_texture: Option<egui::TextureId>,
    /// The CPU backend's image texture.
    cpu_texture: Option<(wgpu::Texture, egui::TextureId, [u32; 2])>,
    adapter_software: bool,
    adapter_name: String,
}

struct App {
    viewer: Viewer,
    ui: UiState,
    opts: ViewOptions,
    script: Option<(Vec<script::Line>, PathBuf)>,
    script_pos: usize,
    wait_frames: u32,
    gfx: Option<Gfx>,
    egui_ctx: egui::Context,
    backend: BackendKind,
    cpu: CpuWorker,
    /// Generation of the state drawn last (text + time); a new one means a new frame to render.
    drawn: Option<(String, f32, BackendKind)>,
    generation: u64,
    image: Option<ViewportImage>,
    last_frame: Instant,
    last_poll: Instant,
    export: Option<ExportJob>,
    minimised: bool,
    fatal: Option<ViewError>,
    frames_shown: u64,
    /// Per new image, for `--stats`.
    samples: Vec<Sample>,
    /// Time spent evaluating the frame last sent to the CPU worker, ms.
    eval_ms: f64,
    /// Whether the GPU backend has reported timestamps (then they are the render time shown).
    gpu_timed: bool,
    /// The line of the script command run last (failures of what it asked for name it).
    script_line: usize,
    pending_screenshot: bool,
}

impl App {
    fn new(
        viewer: Viewer,
        opts: ViewOptions,
        script: Option<(Vec<script::Line>, PathBuf)>,
        cpu: CpuWorker,
    ) -> App {
        App {
            viewer,
            ui: UiState::default(),
            pending_screenshot: opts.screenshot.is_some(),
            opts,
            script,
            script_pos: 0,
            wait_frames: 0,
            gfx: None,
            egui_ctx: egui::Context::default(),
            backend: BackendKind::Cpu,
            cpu,
            drawn: None,
            generation: 0,
            image: None,
            last_frame: Instant::now(),
            last_poll: Instant::now(),
            export: None,
            minimised: false,
            fatal: None,
            frames_shown: 0,
            samples: Vec::new(),
            eval_ms: 0.0,
            gpu_timed: false,
            script_line: 0,
        }
    }

    fn stats_json(&self) -> String {
        let median = |f: fn(&Sample) -> f64| {
            let mut v: Vec<f64> = self.samples.iter().map(f).filter(|x| x.is_finite()).collect();
            v.sort_by(f64::total_cmp);
            v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
        };
        let frame = self.viewer.frame();
        format!(
            "{{\"backend\": \"{}\", \"size\": [{}, {}], \"frames\": {}, \"median_frame_ms\": {:.3}, \"median_render_ms\": {:.3}, \"median_image_overhead_ms\": {:.3}, \"median_ui_ms\": {:.3}}}",
            self.backend.label(),
            frame.width,
            frame.height,
            self.samples.len(),
            median(|s| s.frame),
            median(|s| s.render),
            median(|s| s.image),
            median(|s| s.ui),
        )
    }

    fn die(&mut self, event_loop: &ActiveEventLoop, e: ViewError) {
        self.finish_export();
        self.fatal = Some(e);
        event_loop.exit();
    }

    fn init(&mut self, event_loop: &ActiveEventLoop) -> Result<(), ViewError> {
        let scene = self.viewer.scene();
        let (w, h) = (scene.width(), scene.height());
        let title = format!("hadou — {}", self.viewer.doc.path().display());
        let size = winit::dpi::LogicalSize::new((w + 380).clamp(640, 1800), (h + 130).clamp(420, 1200));
        let attrs = Window::default_attributes().with_title(title).with_inner_size(size);
        let window = Arc::new(
            event_loop
                .create_window(attrs)
                .map_err(|e| fail(1, no_display_message(&format!("cannot create a window: {e}"))))?,
        );
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
            Box::new(event_loop.owned_display_handle()),
        ));
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| fail(1, format!("cannot draw into the window: {e}")))?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: Some(&surface),
        }))
        .map_err(|e| fail(1, format!("no GPU adapter can draw into the window: {e}")))?;
        let info = adapter.get_info();
        let hadou_ok = hadou_gpu::check_adapter(&adapter);
        let desc = match hadou_ok {
            Ok(()) => hadou_gpu::device_descriptor(&adapter),
            Err(_) => wgpu::DeviceDescriptor {
                label: Some("hadou view"),
                required_limits: wgpu::Limits::downlevel_webgl2_defaults().using_resolution(adapter.limits()),
                ..Default::default()
            },
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&desc))
            .map_err(|e| fail(1, format!("cannot open the GPU device for the window: {e}")))?;
        let caps = surface.get_capabilities(&adapter);
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| !f.is_srgb())
            .or_else(|| caps.formats.first().copied())
            .ok_or_else(|| fail(1, "the window's surface offers no pixel format"))?;
        let scripted = self.script.is_some() || self.opts.screenshot.is_some();
        let present_mode = if scripted && caps.present_modes.contains(&wgpu::PresentMode::Immediate) {
            wgpu::PresentMode::Immediate
        } else {
            wgpu::PresentMode::AutoVsync
        };
        let inner = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: inner.width.max(1),
            height: inner.height.max(1),
            present_mode,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes.first().copied().unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: vec![],
        };
        if inner.width > 0 && inner.height > 0 {
            surface.configure(&device, &config);
        }
        let egui_renderer = egui_wgpu::Renderer::new(&device, format, egui_wgpu::RendererOptions::default());
        let egui_state = egui_winit::State::new(
            self.egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(device.limits().max_texture_dimension_2d as usize),
        );
        let gpu = match hadou_ok {
            Ok(()) => match GpuBackend::from_device(&adapter, device.clone(), queue.clone()) {
                Ok(g) => Some(g),
                Err(e) => {
                    self.viewer.complain(format!("the GPU backend cannot start on {}: {e}", info.name));
                    None
                }
            },
            Err(e) => {
                self.viewer.say(format!("GPU backend unavailable: {e}"));
                None
            }
        };
        let software = info.device_type == wgpu::DeviceType::Cpu;
        let (backend, note) = match (self.opts.backend, &gpu) {
            (Some(BackendKind::Gpu), None) => {
                return Err(fail(
                    2,
                    format!(
                        "--backend gpu: the window's adapter {} cannot run hadou's GPU backend",
                        info.name
                    ),
                ))
            }
            (Some(b), _) => (b, "chosen with --backend".to_string()),
            (None, None) => (BackendKind::Cpu, "auto: no usable GPU backend".into()),
            (None, Some(_)) if software => (
                BackendKind::Cpu,
                format!("auto: {} is a software rasterizer; the CPU backend is faster", info.name),
            ),
            (None, Some(_)) => (BackendKind::Gpu, format!("auto: hardware GPU {}", info.name)),
        };
        self.backend = backend;
        self.viewer.stats.backend = Some(backend);
        self.viewer.stats.backend_note = note;
        self.viewer.stats.adapter = format!("{} ({:?})", info.name, info.backend);
        self.gfx = Some(Gfx {
            window,
            surface,
            device,
            queue,
            config,
            egui_renderer,
            egui_state,
            gpu,
            gpu_texture: None,
            cpu_texture: None,
            adapter_software: software,
            adapter_name: info.name.clone(),
        });
        Ok(())
    }

    fn resize(&mut self, w: u32, h: u32) {
        self.minimised = w == 0 || h == 0;
        if let Some(g) = &mut self.gfx {
            if !self.minimised {
                g.config.width = w;
                g.config.height = h;
                g.surface.configure(&g.device, &g.config);
            }
        }
    }

    /// Runs script commands until one needs frames to pass.
    fn step_script(&mut self, event_loop: &ActiveEventLoop) {
        // A script waits for a running export to finish before its next command.
        if self.export.is_some() {
            return;
        }
        if self.wait_frames > 0 {
            self.wait_frames -= 1;
            return;
        }
        let Some((lines, path)) = &self.script else { return };
        let (lines, path) = (lines.clone(), path.clone());
        // A command runs once the previous frame has been drawn (edits show before the next).
        if let Some(line) = lines.get(self.script_pos) {
            self.script_pos += 1;
            self.script_line = line.line;
            match script::run(&mut self.viewer, line, &path) {
                Ok(WindowOp::None) => {}
                Ok(WindowOp::Wait(n)) => self.wait_frames = n,
                Ok(WindowOp::Resize(w, h)) => {
                    if let Some(g) = &self.gfx {
                        if w > 0 && h > 0 {
                            let _ = g.window.request_inner_size(winit::dpi::PhysicalSize::new(w, h));
                        }
                    }
                    // The path a minimised or 0×0 window takes.
                    self.resize(w, h);
                }
                Ok(WindowOp::Quit) => self.script_pos = lines.len(),
                Err(e) => self.die(event_loop, fail(2, e)),
            }
        }
    }

    /// Carries out what the panel or the script asked for, and follows a running export.
    fn service(&mut self) {
        self.poll_export();
        self.handle_requests();
    }

    /// In a scripted run, an error reported since `before` (a screenshot or export that failed, a
    /// backend that is not there, a GPU render failure) stops the viewer with exit 2, naming the
    /// script line that asked for it. Returns whether it stopped.
    fn script_failed(&mut self, event_loop: &ActiveEventLoop, before: Option<(String, bool)>) -> bool {
        let Some((_, path)) = &self.script else { return false };
        match &self.viewer.message {
            Some((m, true)) if self.viewer.message != before => {
                let e = fail(2, format!("{}:{}: {m}", path.display(), self.script_line));
                self.die(event_loop, e);
                true
            }
            _ => false,
        }
    }

    fn script_finished(&self) -> bool {
        self.script.as_ref().is_none_or(|(l, _)| self.script_pos >= l.len()) && self.wait_frames == 0
    }

    fn handle_requests(&mut self) {
        for r in std::mem::take(&mut self.viewer.requests) {
            match r {
                Request::Backend(b) => {
                    let has_gpu = self.gfx.as_ref().is_some_and(|g| g.gpu.is_some());
                    if b == BackendKind::Gpu && !has_gpu {
                        self.viewer.complain("the GPU backend is not available on this adapter");
                    } else {
                        self.backend = b;
                        self.viewer.stats.backend = Some(b);
                        self.viewer.stats.backend_note = "chosen by you".into();
                        let software = self.gfx.as_ref().is_some_and(|g| g.adapter_software);
                        if b == BackendKind::Gpu && software {
                            let name = self.gfx.as_ref().map(|g| g.adapter_name.clone()).unwrap_or_default();
                            self.viewer.stats.backend_note =
                                format!("chosen by you (software adapter {name})");
                        }
                        self.drawn = None;
                    }
                }
                Request::Probe([x, y]) => {
                    let frame = self.viewer.frame();
                    self.viewer.probe_at = (x < frame.width && y < frame.height).then_some([x, y]);
                    self.viewer.probe = Some(match crate::probe(&frame, x, y) {
                        Some(p) => {
                            let waves: Vec<String> = p
                                .waves
                                .iter()
                                .map(|w| format!("{} E={:.4} ({} evals)", w.name, w.energy, w.evaluations))
                                .collect();
                            format!(
                                "pixel ({x}, {y}): {} · rgb [{:.3}, {:.3}, {:.3}] · depth {:.3}{}",
                                if waves.is_empty() { "no waves".to_string() } else { waves.join(", ") },
                                p.color[0],
                                p.color[1],
                                p.color[2],
                                p.depth,
                                p.object.map(|o| format!(" · object {o}")).unwrap_or_default()
                            )
                        }
                        None => {
                            format!("pixel ({x}, {y}) is outside the {}×{} image", frame.width, frame.height)
                        }
                    });
                }
                Request::Screenshot(path) => match self.screenshot(&path) {
                    Ok(()) => self.viewer.say(format!("wrote {}", path.display())),
                    Err(e) => self.viewer.complain(e),
                },
                Request::Export { path, frames, fps } => self.start_export(path, frames, fps),
                Request::CancelExport => {
                    if let Some(j) = &self.export {
                        j.cancel.store(true, Ordering::Relaxed);
                    }
                }
                Request::Quit => self.script_pos = usize::MAX,
                Request::MeasureGpu => {
                    let frame = self.viewer.frame();
                    match self.gfx.as_mut().and_then(|g| g.gpu.as_mut()) {
                        Some(gpu) => match gpu.time_frame(&frame, 5) {
                            Ok(t) => {
                                let passes: Vec<String> = t
                                    .passes
                                    .iter()
                                    .map(|p| format!("{} {:.2} ms", p.name, p.median_ms))
                                    .collect();
                                let how = if gpu.has_timestamps() {
                                    "GPU timestamps"
                                } else {
                                    "submit-and-wait wall clock (no timestamp queries)"
                                };
                                self.viewer.stats.render_ms = t.median_ms;
                                self.viewer.stats.render_method =
                                    format!("{how}, median of 5: {}", passes.join(", "));
                                self.viewer.say(format!(
                                    "GPU frame {:.2} ms ({how}){}",
                                    t.median_ms,
                                    if passes.is_empty() {
                                        String::new()
                                    } else {
                                        format!(": {}", passes.join(", "))
                                    }
                                ));
                            }
                            Err(e) => self.viewer.complain(format!("GPU timing failed: {e}")),
                        },
                        None => self.viewer.complain("the GPU backend is not available on this adapter"),
                    }
                }
            }
        }
    }

    /// Renders the scene at the current time and size with the active backend and writes it as
    /// `hadou render` does.
    fn screenshot(&mut self, path: &std::path::Path) -> Result<(), String> {
        output::check_writable(path).map_err(|e| e.to_string())?;
        let frame = self.viewer.frame();
        let image = match (self.backend, self.gfx.as_mut().and_then(|g| g.gpu.as_mut())) {
            (BackendKind::Gpu, Some(gpu)) => gpu.render(&frame),
            _ => crate::CpuBackend::new().render(&frame),
        }
        .map_err(|e| format!("render failed: {e}"))?;
        output::write(&image, path).map_err(|e| e.to_string())
    }

    fn start_export(&mut self, path: PathBuf, frames: std::ops::Range<u32>, fps: f32) {
        if self.export.is_some() {
            self.viewer.complain("an export is already running");
            return;
        }
        let scene: Scene = self.viewer.scene().clone();
        let spec = AnimationSpec { frames: frames.clone(), fps, width: None, height: None };
        if let Err(e) = spec.validate() {
            self.viewer.complain(e.to_string());
            return;
        }
        let done = Arc::new(AtomicU32::new(0));
        let cancel = Arc::new(AtomicBool::new(false));
        let (tx, result) = mpsc::channel();
        let (d, c) = (done.clone(), cancel.clone());
        let total = frames.len() as u32;
        std::thread::spawn(move || {
            let mut backend = crate::CpuBackend::new();
            let mut progress = |p: export::Progress| {
                d.store(p.done, Ordering::Relaxed);
                if c.load(Ordering::Relaxed) {
                    Control::Cancel
                } else {
                    Control::Continue
                }
            };
            let r = match export::export_animation(&scene, &mut backend, &spec, &path, &mut progress) {
                Ok(ExportOutcome::Finished { frames }) => {
                    Ok(format!("exported {frames} frames to {}", path.display()))
                }
                Ok(ExportOutcome::Cancelled { frames_written }) => {
                    Ok(format!("export cancelled ({frames_written} frames written)"))
                }
                Err(e) => Err(e.to_string()),
            };
            let _ = tx.send(r);
        });
        self.viewer.export_progress = Some((0, total));
        self.export = Some(ExportJob { done, total, cancel, result });
    }

    /// Cancels a running export and waits (up to a minute) for it to stop, so that closing the
    /// window leaves no temporary file behind.
    fn finish_export(&mut self) {
        if let Some(j) = self.export.take() {
            j.cancel.store(true, Ordering::Relaxed);
            let _ = j.result.recv_timeout(Duration::from_secs(60));
        }
    }

    fn poll_export(&mut self) {
        let Some(j) = &self.export else { return };
        self.viewer.export_progress = Some((j.done.load(Ordering::Relaxed), j.total));
        match j.result.try_recv() {
            Ok(r) => {
                match r {
                    Ok(m) => self.viewer.say(m),
                    Err(m) => self.viewer.complain(m),
                }
                self.export = None;
                self.viewer.export_progress = None;
            }
            Err(mpsc::TryRecvError::Empty) => {}
            Err(mpsc::TryRecvError::Disconnected) => {
                self.viewer.complain("the export stopped unexpectedly");
                self.export = None;
                self.viewer.export_progress = None;
            }
        }
    }

    /// Starts or collects the viewport's rendering. When a new image is shown, returns the
    /// viewer's own time spent on it outside the renderer (ms): evaluating the frame, and for the
    /// CPU backend converting its image to sRGB bytes and uploading them.
    fn update_image(&mut self) -> Option<f64> {
        let key = (self.viewer.doc.text().to_string(), self.viewer.timeline.time, self.backend);
        let changed = self.drawn.as_ref() != Some(&key);
        let g = self.gfx.as_mut()?;
        let mut overhead = None;
        match self.backend {
            BackendKind::Gpu => {
                // The GPU's own time of the newest frame whose timestamps have come back (never
                // waits; none on adapters without timestamp queries).
                if let Some(t) = g.gpu.as_mut().and_then(|gpu| gpu.last_present_timing()) {
                    let passes: Vec<String> =
                        t.passes.iter().map(|p| format!("{} {:.2} ms", p.name, p.median_ms)).collect();
                    self.viewer.stats.render_ms = t.frame_ms;
                    self.viewer.stats.render_method =
                        format!("GPU timestamps of frame {}: {}", t.serial, passes.join(", "));
                    self.gpu_timed = true;
                }
                if changed {
                    let e0 = Instant::now();
                    let frame = self.viewer.frame();
                    let eval_ms = e0.elapsed().as_secs_f64() * 1e3;
                    let gpu = g.gpu.as_mut()?;
                    let r0 = Instant::now();
                    match gpu.render_to_texture(&frame) {
                        Ok(out) => {
                            let id = match g.gpu_texture {
                                Some(id) if !out.recreated => id,
                                Some(id) => {
                                    g.egui_renderer.update_egui_texture_from_wgpu_texture(
                                        &g.device,
                                        out.view,
                                        wgpu::FilterMode::Linear,
                                        id,
                                    );
                                    id
                                }
                                None => g.egui_renderer.register_native_texture(
                                    &g.device,
                                    out.view,
                                    wgpu::FilterMode::Linear,
                                ),
                            };
                            g.gpu_texture = Some(id);
                            overhead = Some(eval_ms);
                            self.image = Some(ViewportImage { texture: id, size: out.size });
                            if !self.gpu_timed {
                                self.viewer.stats.render_ms = r0.elapsed().as_secs_f64() * 1e3;
                                self.viewer.stats.render_method = "encode + submit (the GPU finishes \
                                     asynchronously; this adapter has no timestamp queries)"
                                    .into();
                            }
                        }
                        Err(e) => self.viewer.complain(format!("GPU render failed: {e}")),
                    }
                    self.drawn = Some(key);
                }
            }
            BackendKind::Cpu => {
                // Collect a finished frame.
                while let Ok(done) = self.cpu.done.try_recv() {
                    self.cpu.busy = false;
                    if done.generation != self.generation {
                        continue;
                    }
                    let u0 = Instant::now();
                    let size = done.size;
                    let needs_new = g.cpu_texture.as_ref().is_none_or(|t| t.2 != size);
                    if needs_new {
                        let tex = viewport_texture(&g.device, size);
                        let view = tex.create_view(&Default::default());
                        let id = match g.cpu_texture.take() {
                            Some((_, id, _)) => {
                                g.egui_renderer.update_egui_texture_from_wgpu_texture(
                                    &g.device,
                                    &view,
                                    wgpu::FilterMode::Linear,
                                    id,
                                );
                                id
                            }
                            None => g.egui_renderer.register_native_texture(
                                &g.device,
                                &view,
                                wgpu::FilterMode::Linear,
                            ),
                        };
                        g.cpu_texture = Some((tex, id, size));
                    }
                    if let Some((tex, id, _)) = &g.cpu_texture {
                        upload_rgba(&g.queue, tex, &done.rgba, size);
                        self.image = Some(ViewportImage { texture: *id, size });
                    }
                    let _ = self.cpu.back.send(done.rgba);
                    self.viewer.stats.render_ms = done.render_ms;
                    self.viewer.stats.render_method = "CPU backend, wall clock on the render thread".into();
                    overhead = Some(self.eval_ms + done.convert_ms + u0.elapsed().as_secs_f64() * 1e3);
                }
                if changed && !self.cpu.busy {
                    let e0 = Instant::now();
                    let frame = self.viewer.frame();
                    self.generation += 1;
                    self.eval_ms = e0.elapsed().as_secs_f64() * 1e3;
                    if self.cpu.jobs.send((self.generation, frame)).is_ok() {
                        self.cpu.busy = true;
                        self.drawn = Some(key);
                    }
                }
            }
        }
        overhead
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) {
        let now = Instant::now();
        let dt = now.duration_since(self.last_frame).as_secs_f32();
        let frame_ms = now.duration_since(self.last_frame).as_secs_f64() * 1e3;
        self.last_frame = now;
        if now.duration_since(self.last_poll) > Duration::from_millis(300) {
            self.last_poll = now;
            self.viewer.poll_disk();
        }
        if self.minimised {
            return;
        }
        self.viewer.tick(dt);
        let before = self.viewer.message.clone();
        self.service();
        let viewer_ms = self.update_image();
        if self.script_failed(event_loop, before) {
            return;
        }
        let ui_start = Instant::now();
        let Some(g) = &mut self.gfx else { return };
        let raw = g.egui_state.take_egui_input(&g.window);
        let image = self.image;
        let (viewer, ui) = (&mut self.viewer, &mut self.ui);
        let out = self.egui_ctx.run_ui(raw, |ui_root| hadou_view::ui::show(ui_root, viewer, image, ui));
        g.egui_state.handle_platform_output(&g.window, out.platform_output);
        let jobs = self.egui_ctx.tessellate(out.shapes, out.pixels_per_point);
        for (id, delta) in &out.textures_delta.set {
            g.egui_renderer.update_texture(&g.device, &g.queue, *id, delta);
        }
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [g.config.width, g.config.height],
            pixels_per_point: out.pixels_per_point,
        };
        let surface_texture = match g.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => Some(t),
            _ => {
                g.surface.configure(&g.device, &g.config);
                None
            }
        };
        if let Some(st) = surface_texture {
            let view = st.texture.create_view(&Default::default());
            let mut enc = g.device.create_command_encoder(&Default::default());
            let extra = g.egui_renderer.update_buffers(&g.device, &g.queue, &mut enc, &jobs, &screen);
            {
                let pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("egui"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color { r: 0.05, g: 0.05, b: 0.06, a: 1.0 }),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                let mut pass = pass.forget_lifetime();
                g.egui_renderer.render(&mut pass, &jobs, &screen);
            }
            g.queue.submit(extra.into_iter().chain([enc.finish()]));
            g.window.pre_present_notify();
            st.present();
            self.frames_shown += 1;
        }
        for id in &out.textures_delta.free {
            g.egui_renderer.free_texture(id);
        }
        let ui_ms = ui_start.elapsed().as_secs_f64() * 1e3;
        self.viewer.stats.frame_ms = frame_ms;
        self.viewer.stats.ui_ms = ui_ms;
        if let Some(ms) = viewer_ms {
            self.viewer.stats.overhead_ms = ms;
            if self.frames_shown > 2 {
                self.samples.push(Sample {
                    frame: frame_ms,
                    render: self.viewer.stats.render_ms,
                    image: ms,
                    ui: ui_ms,
                });
            }
        }

        // Scripted runs: the next command, then the screenshot and exit.
        if self.script.is_some() && !self.script_finished() {
            self.step_script(event_loop);
        } else if self.script.is_some() || self.opts.screenshot.is_some() {
            // The end of a scripted run: stop the clock so the last image can catch up.
            self.viewer.timeline.playing = false;
            let image_current = self.image.is_some()
                && self
                    .drawn
                    .as_ref()
                    .is_some_and(|d| d.0 == self.viewer.doc.text() && d.1 == self.viewer.timeline.time)
                && !self.cpu.busy;
            if self.export.is_none() && image_current && self.frames_shown >= 3 {
                if self.pending_screenshot {
                    self.pending_screenshot = false;
                    if let Some(p) = self.opts.screenshot.clone() {
                        if let Err(e) = self.screenshot(&p) {
                            self.die(event_loop, fail(1, e));
                            return;
                        }
                    }
                }
                event_loop.exit();
            }
        }
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_some() {
            return;
        }
        if let Err(e) = self.init(event_loop) {
            self.die(event_loop, e);
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        if let Some(g) = &mut self.gfx {
            let r = g.egui_state.on_window_event(&g.window, &event);
            if r.repaint {
                g.window.request_redraw();
            }
        }
        match event {
            WindowEvent::CloseRequested => {
                self.finish_export();
                event_loop.exit();
            }
            WindowEvent::Resized(size) => {
                self.resize(size.width, size.height);
                if let Some(g) = &self.gfx {
                    g.window.request_redraw();
                }
            }
            WindowEvent::Occluded(true) => self.minimised = true,
            WindowEvent::Occluded(false) => {
                if let Some(g) = &self.gfx {
                    let s = g.window.inner_size();
                    self.resize(s.width, s.height);
                }
            }
            WindowEvent::RedrawRequested => self.redraw(event_loop),
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let Some(g) = &self.gfx else { return };
        let scripted = self.script.is_some() || self.opts.screenshot.is_some();
        // Keep drawing while anything moves; otherwise sleep until input, waking to look at the
        // file for hot reload. Minimised: no drawing at all (no busy loop).
        let busy = self.viewer.timeline.playing || self.cpu.busy || self.export.is_some() || scripted;
        if self.minimised {
            if scripted {
                // A scripted run keeps its script going while minimised.
                event_loop
                    .set_control_flow(ControlFlow::WaitUntil(Instant::now() + Duration::from_millis(10)));
                let before = self.viewer.message.clone();
                self.service();
                if self.script_failed(event_loop, before) {
                    return;
                }
                self.step_script(event_loop);
                let idle = self.viewer.requests.is_empty() && self.export.is_none();
                if self.script_finished() && !self.pending_screenshot && idle {
                    event_loop.exit();
                }
            } else {
                event_loop
                    .set_control_flow(ControlFlow::WaitUntil(Instant::now() + Duration::from_millis(300)));
            }
            return;
        }
        if busy {
            g.window.request_redraw();
            event_loop.set_control_flow(ControlFlow::Poll);
        } else {
            event_loop.set_control_flow(ControlFlow::WaitUntil(Instant::now() + Duration::from_millis(300)));
            if Instant::now().duration_since(self.last_poll) > Duration::from_millis(300) {
                g.window.request_redraw();
            }
        }
    }
}
