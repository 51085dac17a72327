//! The viewer in the page: [`WebApp`] holds `hadou view`'s viewer state and UI, the backend
//! drawing the viewport (the GPU backend on WebGPU, else the CPU backend), the read-backs in
//! flight (screenshots, the GIF export's frames, the test frame) and the page's inbox. One
//! browser frame does at most one frame's rendering, so nothing freezes the tab for longer.

use super::dom;
use super::frames::{self, cpu_frame_bytes, DEFAULT_PRESET};
use crate::dropped;
use crate::export::{png_bytes, GifExport};
use crate::params::PageParams;
use crate::presets;
use hadou_cpu::CpuBackend;
use hadou_gpu::{GpuBackend, TextureRead};
use hadou_scene::Frame;
use hadou_view::document::Document;
use hadou_view::ui::{UiState, ViewportImage};
use hadou_view::viewer::{BackendKind, Request, Viewer};
use web_time::Instant;

/// What the viewport shows: the document's text, the time, the backend and the size.
type DrawKey = (String, f32, BackendKind, [u32; 2]);

/// Test mode on WebGL2 (`test=1&backend=webgl`, see `test_mode.rs`): the frame still to draw.
#[derive(PartialEq)]
enum TestState {
    Off,
    Start,
    Done,
}

/// A GIF export under way: the file so far and the frame being read back.
struct Export {
    gif: GifExport,
    name: String,
    reading: Option<TextureRead>,
    cancelled: bool,
}

pub(super) struct WebApp {
    viewer: Viewer,
    ui: UiState,
    params: PageParams,
    device: wgpu::Device,
    renderer: std::sync::Arc<egui::mutex::RwLock<egui_wgpu::Renderer>>,
    gpu: Option<GpuBackend>,
    cpu: CpuBackend,
    backend: BackendKind,
    drawn: Option<DrawKey>,
    image: Option<ViewportImage>,
    gpu_texture: Option<egui::TextureId>,
    cpu_texture: Option<egui::TextureHandle>,
    last_frame: Instant,
    gpu_timed: bool,
    screenshot: Option<(String, TextureRead)>,
    export: Option<Export>,
    test: TestState,
}

/// The page's viewer on a document: Save downloads the text.
fn viewer_on(doc: Document) -> Viewer {
    let mut v = Viewer::new(doc);
    v.save_downloads = true;
    v
}

/// Opens preset `name` (the presets are mounted).
fn open_preset(name: &str) -> Result<Document, String> {
    let path = presets::scene_path(name)?;
    Document::open(&path).map_err(|e| e.to_string())
}

impl WebApp {
    pub(super) fn new(cc: &eframe::CreationContext<'_>, params: PageParams) -> WebApp {
        let rs = cc.wgpu_render_state.clone().expect("eframe runs on wgpu here");
        hadou_scene::mount_memory_files(Some(presets::files()));
        let mut messages = Vec::new();
        let wanted = params.scene.clone().unwrap_or_else(|| DEFAULT_PRESET.into());
        let doc = match open_preset(&wanted) {
            Ok(d) => d,
            Err(e) => {
                messages.push(e);
                open_preset(DEFAULT_PRESET).expect("the default preset loads")
            }
        };
        let mut viewer = viewer_on(doc);
        if let Some(t) = params.time {
            viewer.timeline.time = t;
        }
        let info = rs.adapter.get_info();
        let (gpu, status) = if info.backend == wgpu::Backend::BrowserWebGpu {
            match GpuBackend::from_device(&rs.adapter, rs.device.clone(), rs.queue.clone()) {
                Ok(g) => (Some(g), format!("WebGPU ({}): the GPU backend draws", adapter_name(&info))),
                Err(e) => (
                    None,
                    format!(
                        "WebGPU ({}), but the GPU backend cannot run on it ({e}): the CPU backend draws",
                        adapter_name(&info)
                    ),
                ),
            }
        } else {
            let why = if params.api == crate::params::ApiChoice::WebGl {
                "WebGL2 was asked for (backend=webgl)"
            } else {
                "this browser gave no WebGPU adapter"
            };
            (None, format!(
                "WebGL2 fallback ({why}): WebGL2 has no compute shaders, so the CPU backend, compiled to WebAssembly, draws the viewport and WebGL2 shows it"
            ))
        };
        dom::set_text(dom::STATUS, &status);
        let backend = if gpu.is_some() { BackendKind::Gpu } else { BackendKind::Cpu };
        viewer.stats.backend = Some(backend);
        viewer.stats.backend_note = if info.backend == wgpu::Backend::BrowserWebGpu {
            "in the browser, on WebGPU".into()
        } else {
            "in the browser, WebGL2 fallback".into()
        };
        viewer.stats.adapter = adapter_name(&info);
        let test = if params.test {
            match &params.scene {
                Some(s) if presets::scene_path(s).is_err() => {
                    dom::set_text(dom::TEST_ERROR, &messages.join("; "));
                    TestState::Done
                }
                _ => TestState::Start,
            }
        } else {
            TestState::Off
        };
        if !messages.is_empty() {
            dom::set_text(dom::MESSAGE, &messages.join("; "));
            viewer.complain(messages.join("; "));
        }
        WebApp {
            viewer,
            ui: UiState::default(),
            params,
            device: rs.device.clone(),
            renderer: rs.renderer.clone(),
            gpu,
            cpu: CpuBackend::new(),
            backend,
            drawn: None,
            image: None,
            gpu_texture: None,
            cpu_texture: None,
            last_frame: Instant::now(),
            gpu_timed: false,
            screenshot: None,
            export: None,
            test,
        }
    }

    /// The frame the viewport shows now, at the URL's size where it gives one.
    fn frame(&self) -> Result<Frame, String> {
        let mut f = self.viewer.frame();
        let overrides = self.params.overrides();
        overrides.apply(&mut f);
        if overrides.sets_size() {
            self.viewer
                .scene()
                .check_image_size(f.width, f.height)
                .map_err(|m| format!("width={} height={}: {m}", f.width, f.height))?;
        }
        Ok(f)
    }

    /// Whether the GPU backend draws: chosen, and the page runs on WebGPU.
    fn on_gpu(&self) -> bool {
        self.backend == BackendKind::Gpu && self.gpu.is_some()
    }

    /// Renders `frame` on the CPU into sRGB RGBA bytes and the render time (ms).
    fn cpu_bytes(&mut self, frame: &Frame) -> Result<(Vec<u8>, f64), String> {
        cpu_frame_bytes(&mut self.cpu, frame)
    }

    /// Keeps the viewport's image current: the GPU backend's texture shown as a native egui
    /// texture (no read-back), or the CPU backend's image uploaded.
    fn update_image(&mut self, ctx: &egui::Context) {
        if let Some(t) = self.gpu.as_mut().and_then(|g| g.last_present_timing()) {
            let passes = t.passes.iter().map(|p| (p.name.as_str(), p.median_ms));
            self.viewer.stats.gpu_timestamps(t.serial, t.frame_ms, passes);
            self.gpu_timed = true;
        }
        let frame = match self.frame() {
            Ok(f) => f,
            Err(m) => {
                if self.drawn.is_none() {
                    self.viewer.complain(m);
                }
                return;
            }
        };
        let key = (
            self.viewer.doc.text().to_string(),
            self.viewer.timeline.time,
            self.backend,
            [frame.width, frame.height],
        );
        if self.drawn.as_ref() == Some(&key) {
            return;
        }
        self.drawn = Some(key);
        if self.on_gpu() {
            let t0 = Instant::now();
            let gpu = self.gpu.as_mut().expect("checked");
            match gpu.render_to_texture(&frame) {
                Ok(out) => {
                    let mut r = self.renderer.write();
                    let id = match self.gpu_texture {
                        Some(id) if !out.recreated => id,
                        Some(id) => {
                            r.update_egui_texture_from_wgpu_texture(
                                &self.device,
                                out.view,
                                wgpu::FilterMode::Linear,
                                id,
                            );
                            id
                        }
                        None => r.register_native_texture(&self.device, out.view, wgpu::FilterMode::Linear),
                    };
                    self.gpu_texture = Some(id);
                    self.image = Some(ViewportImage { texture: id, size: out.size });
                    if !self.gpu_timed {
                        self.viewer.stats.render_ms = t0.elapsed().as_secs_f64() * 1e3;
                        self.viewer.stats.render_method =
                            "encode + submit (the GPU finishes asynchronously; no timestamp queries)".into();
                    }
                }
                Err(e) => self.viewer.complain(format!("GPU render failed: {e}")),
            }
        } else {
            match self.cpu_bytes(&frame) {
                Ok((bytes, ms)) => {
                    let size = [frame.width as usize, frame.height as usize];
                    let img = egui::ColorImage::from_rgba_unmultiplied(size, &bytes);
                    match &mut self.cpu_texture {
                        Some(t) => t.set(img, egui::TextureOptions::LINEAR),
                        None => {
                            self.cpu_texture =
                                Some(ctx.load_texture("hadou-viewport", img, egui::TextureOptions::LINEAR))
                        }
                    }
                    let id = self.cpu_texture.as_ref().expect("set above").id();
                    self.image = Some(ViewportImage { texture: id, size: [frame.width, frame.height] });
                    self.viewer.stats.render_ms = ms;
                    self.viewer.stats.render_method = if self.backend == BackendKind::Gpu {
                        "CPU backend in WebAssembly (a frame with a [bloom] draws on the CPU in the page)"
                            .into()
                    } else {
                        "CPU backend in WebAssembly, wall clock".into()
                    };
                }
                Err(e) => self.viewer.complain(format!("render failed: {e}")),
            }
        }
    }

    /// Takes what the page's script handed in: a chosen preset, dropped files.
    fn take_inbox(&mut self) {
        let (preset, dropped) = super::inbox::INBOX.with(|i| {
            let mut i = i.borrow_mut();
            (i.preset.take(), std::mem::take(&mut i.dropped))
        });
        if let Some(name) = preset {
            match open_preset(&name) {
                Ok(doc) => self.replace_document(doc),
                Err(e) => self.viewer.complain(e),
            }
        }
        for batch in dropped {
            let mut notes = batch.refused.clone();
            if batch.files.iter().any(|(n, _)| n.to_ascii_lowercase().ends_with(".toml")) {
                match dropped::load(&batch, &presets::files()) {
                    Ok(doc) => self.replace_document(doc),
                    Err(e) => notes.insert(0, format!("{e} (the last good scene stays)")),
                }
            } else if !batch.files.is_empty() {
                notes.insert(0, "no scene file (.toml) among the dropped files: drop the scene file together with the files it names".into());
            }
            dom::set_text(dom::MESSAGE, &notes.join("\n"));
            if !notes.is_empty() {
                self.viewer.complain(notes.join("; "));
            }
        }
    }

    fn replace_document(&mut self, doc: Document) {
        let name = doc.path().display().to_string();
        let (stats, timeline) = (self.viewer.stats.clone(), self.viewer.timeline);
        self.viewer = viewer_on(doc);
        self.viewer.stats = stats;
        self.viewer.timeline.speed = timeline.speed;
        self.viewer.timeline.looping = timeline.looping;
        self.ui = UiState::default();
        self.drawn = None;
        self.viewer.say(format!("opened {name}"));
    }

    /// Carries out the panel's requests.
    fn service(&mut self) {
        for r in std::mem::take(&mut self.viewer.requests) {
            match r {
                Request::Backend(b) => {
                    if b == BackendKind::Gpu && self.gpu.is_none() {
                        self.viewer.complain("the GPU backend needs WebGPU, which this page is not running on");
                    } else {
                        self.backend = b;
                        self.viewer.stats.backend = Some(b);
                        self.viewer.stats.backend_note = "chosen by you".into();
                        self.drawn = None;
                    }
                }
                Request::Probe([x, y]) => match self.frame() {
                    Ok(frame) => {
                        self.viewer.probe_at = (x < frame.width && y < frame.height).then_some([x, y]);
                        self.viewer.probe = Some(match hadou_cpu::probe(&frame, x, y) {
                            Some(p) => p.summary(),
                            None => format!("pixel ({x}, {y}) is outside the {}×{} image", frame.width, frame.height),
                        });
                    }
                    Err(m) => self.viewer.complain(m),
                },
                Request::Screenshot(path) => self.screenshot(&path),
                Request::Export { path, frames, fps } => self.start_export(&path, frames, fps),
                Request::CancelExport => {
                    if let Some(e) = &mut self.export {
                        e.cancelled = true;
                    }
                }
                Request::DownloadScene => {
                    let name = file_name(self.viewer.doc.path(), "scene.toml");
                    if let Err(e) = dom::download(&name, self.viewer.doc.text().as_bytes(), "application/toml") {
                        self.viewer.complain(e);
                    }
                }
                Request::MeasureGpu => self.viewer.complain(
                    "the page shows the GPU's own time in the top bar where the adapter has timestamp queries; \
                     the timed benchmark is `hadou bench` natively",
                ),
                Request::Quit => {}
            }
        }
    }

    /// A PNG of the current frame, downloaded: read back from the GPU's texture, or rendered on
    /// the CPU.
    fn screenshot(&mut self, path: &std::path::Path) {
        let name = file_name(path, "hadou.png");
        if !name.to_ascii_lowercase().ends_with(".png") {
            self.viewer
                .complain(format!("{name}: the page saves screenshots as PNG (a name ending in .png)"));
            return;
        }
        let frame = match self.frame() {
            Ok(f) => f,
            Err(m) => return self.viewer.complain(m),
        };
        if self.on_gpu() {
            // The viewport's texture holds the frame once it is current.
            self.drawn = None;
            let gpu = self.gpu.as_mut().expect("checked");
            match gpu.render_to_texture(&frame) {
                Ok(_) => self.screenshot = gpu.read_presented().map(|r| (name, r)),
                Err(e) => self.viewer.complain(format!("GPU render failed: {e}")),
            }
        } else {
            match self.cpu_bytes(&frame).and_then(|(b, _)| png_bytes(&b, frame.width, frame.height)) {
                Ok(png) => self.deliver(&name, &png, "image/png"),
                Err(e) => self.viewer.complain(e),
            }
        }
    }

    fn deliver(&mut self, name: &str, bytes: &[u8], mime: &str) {
        match dom::download(name, bytes, mime) {
            Ok(()) => self.viewer.say(format!("downloading {name} ({} bytes)", bytes.len())),
            Err(e) => self.viewer.complain(e),
        }
    }

    fn poll_screenshot(&mut self) {
        let Some((name, read)) = &mut self.screenshot else { return };
        let Some(outcome) = read.try_take(&self.device) else { return };
        let [w, h] = read.size();
        let name = name.clone();
        self.screenshot = None;
        match outcome.map_err(|e| e.to_string()).and_then(|b| png_bytes(&b, w, h)) {
            Ok(png) => self.deliver(&name, &png, "image/png"),
            Err(e) => self.viewer.complain(e),
        }
    }

    fn start_export(&mut self, path: &std::path::Path, frames: std::ops::Range<u32>, fps: f32) {
        if self.export.is_some() {
            return self.viewer.complain("an export is already running");
        }
        let name = file_name(path, "hadou.gif");
        if !name.to_ascii_lowercase().ends_with(".gif") {
            return self.viewer.complain(format!("{name}: the page exports GIFs (a name ending in .gif)"));
        }
        let frame = match self.frame() {
            Ok(f) => f,
            Err(m) => return self.viewer.complain(m),
        };
        match GifExport::new(frame.width, frame.height, frames, fps) {
            Ok(gif) => {
                self.viewer.export_progress = Some(gif.progress());
                self.export = Some(Export { gif, name, reading: None, cancelled: false });
            }
            Err(e) => self.viewer.complain(format!("{name}: {e}")),
        }
    }

    /// One step of a running export: at most one frame rendered or one read-back collected.
    fn step_export(&mut self) {
        let Some(mut ex) = self.export.take() else { return };
        if ex.cancelled {
            self.viewer.export_progress = None;
            self.drawn = None;
            return self.viewer.say(format!("{}: export cancelled", ex.name));
        }
        let result: Result<(), String> = (|| {
            if let Some(read) = &mut ex.reading {
                if let Some(bytes) = read.try_take(&self.device) {
                    ex.reading = None;
                    ex.gif.push(bytes.map_err(|e| e.to_string())?)?;
                }
                return Ok(());
            }
            let Some(f) = ex.gif.next_frame() else { return Ok(()) };
            let mut frame = self.frame()?;
            let at = self.viewer.scene().at(ex.gif.time_of(f));
            let (w, h) = (frame.width, frame.height);
            frame = at;
            (frame.width, frame.height) = (w, h);
            if self.on_gpu() {
                let gpu = self.gpu.as_mut().expect("checked");
                gpu.render_to_texture(&frame).map_err(|e| e.to_string())?;
                ex.reading = gpu.read_presented();
            } else {
                let (bytes, _) = self.cpu_bytes(&frame)?;
                ex.gif.push(bytes)?;
            }
            Ok(())
        })();
        self.drawn = None;
        if let Err(e) = result {
            self.viewer.export_progress = None;
            return self.viewer.complain(format!("{}: export failed: {e}", ex.name));
        }
        self.viewer.export_progress = Some(ex.gif.progress());
        if ex.gif.next_frame().is_none() && ex.reading.is_none() {
            self.viewer.export_progress = None;
            let name = ex.name.clone();
            match ex.gif.finish() {
                Ok(bytes) => self.deliver(&name, &bytes, "image/gif"),
                Err(e) => self.viewer.complain(format!("{name}: {e}")),
            }
        } else {
            self.export = Some(ex);
        }
    }

    /// Test mode on WebGL2: the URL's frame rendered once on the CPU backend and written into
    /// the page.
    fn step_test(&mut self) {
        if self.test != TestState::Start {
            return;
        }
        self.test = TestState::Done;
        let outcome = frames::test_frame(self.viewer.scene(), &self.params).and_then(|frame| {
            let (bytes, ms) = self.cpu_bytes(&frame)?;
            Ok((bytes, ms, frame))
        });
        match outcome {
            Ok((bytes, ms, frame)) => frames::finish(
                &bytes,
                frame.width,
                frame.height,
                "CPU",
                &self.viewer.stats.adapter,
                ms,
                Some(ms),
            ),
            Err(m) => dom::set_text(dom::TEST_ERROR, &m),
        }
    }

    fn busy(&self) -> bool {
        self.viewer.timeline.playing
            || self.export.is_some()
            || self.screenshot.is_some()
            || self.test == TestState::Start
    }
}

impl eframe::App for WebApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let now = Instant::now();
        let dt = now.duration_since(self.last_frame);
        self.last_frame = now;
        self.take_inbox();
        self.viewer.tick(dt.as_secs_f32());
        self.step_test();
        self.service();
        self.step_export();
        self.poll_screenshot();
        let t0 = Instant::now();
        self.update_image(ui.ctx());
        let image_ms = t0.elapsed().as_secs_f64() * 1e3;
        let ui_start = Instant::now();
        let image = self.image;
        hadou_view::ui::show(ui, &mut self.viewer, image, &mut self.ui);
        self.service();
        self.viewer.stats.frame_ms = dt.as_secs_f64() * 1e3;
        self.viewer.stats.overhead_ms = image_ms - self.viewer.stats.render_ms.min(image_ms);
        self.viewer.stats.ui_ms = ui_start.elapsed().as_secs_f64() * 1e3;
        if self.busy() {
            ui.ctx().request_repaint();
        }
    }
}

/// The adapter's name as the page shows it.
fn adapter_name(info: &wgpu::AdapterInfo) -> String {
    let mut name = if info.name.is_empty() { info.driver.clone() } else { info.name.clone() };
    if name.is_empty() && info.backend == wgpu::Backend::BrowserWebGpu {
        name = super::inbox::WEBGPU_ADAPTER.with(|a| a.borrow().clone());
    }
    if name.is_empty() {
        match info.backend {
            wgpu::Backend::BrowserWebGpu => "the browser's WebGPU adapter".into(),
            b => format!("{b:?}"),
        }
    } else {
        name
    }
}

/// The last component of `path`, or `default`.
fn file_name(path: &std::path::Path, default: &str) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .filter(|n| !n.is_empty())
        .unwrap_or_else(|| default.into())
}
