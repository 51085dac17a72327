//! The viewer's state in the window: [`App`] holds the viewer and its UI, the window's GPU state,
//! the backend drawing the viewport, the CPU render thread, a running export, the script's place
//! and the frame-time samples. The other files of `view` give it its behaviour: the event loop
//! (`event_loop.rs`), the viewport's image (`viewport.rs`), the panel's and script's requests
//! (`requests.rs`) and the script runner (`script_runner.rs`).

use super::cpu_worker::CpuWorker;
use super::export_job::ExportJob;
use super::options::{ViewError, ViewOptions};
use super::surface::Gfx;
use hadou_view::script;
use hadou_view::ui::{UiState, ViewportImage};
use hadou_view::viewer::{BackendKind, Viewer};
use std::path::PathBuf;
use std::time::Instant;
use winit::event_loop::ActiveEventLoop;

/// Timings of one new image, ms.
#[derive(Clone, Copy)]
pub(super) struct Sample {
    /// Wall time since the previous window frame.
    pub(super) frame: f64,
    /// The renderer's time.
    pub(super) render: f64,
    /// The viewer's own work on the image (evaluation, conversion, upload).
    pub(super) image: f64,
    /// Building and drawing the UI.
    pub(super) ui: f64,
}

/// The viewer in its window (see the module documentation).
pub(super) struct App {
    pub(super) viewer: Viewer,
    pub(super) ui: UiState,
    pub(super) opts: ViewOptions,
    pub(super) script: Option<(Vec<script::Line>, PathBuf)>,
    pub(super) script_pos: usize,
    pub(super) wait_frames: u32,
    pub(super) gfx: Option<Gfx>,
    pub(super) egui_ctx: egui::Context,
    pub(super) backend: BackendKind,
    pub(super) cpu: CpuWorker,
    /// Generation of the state drawn last (text + time); a new one means a new frame to render.
    pub(super) drawn: Option<(String, f32, BackendKind)>,
    pub(super) generation: u64,
    pub(super) image: Option<ViewportImage>,
    pub(super) last_frame: Instant,
    pub(super) last_poll: Instant,
    pub(super) export: Option<ExportJob>,
    pub(super) minimised: bool,
    pub(super) fatal: Option<ViewError>,
    pub(super) frames_shown: u64,
    /// Per new image, for `--stats`.
    pub(super) samples: Vec<Sample>,
    /// Time spent evaluating the frame last sent to the CPU worker, ms.
    pub(super) eval_ms: f64,
    /// Whether the GPU backend has reported timestamps (then they are the render time shown).
    pub(super) gpu_timed: bool,
    /// The line of the script command run last (failures of what it asked for name it).
    pub(super) script_line: usize,
    pub(super) pending_screenshot: bool,
}

impl App {
    pub(super) fn new(
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

    pub(super) fn stats_json(&self) -> String {
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

    pub(super) fn die(&mut self, event_loop: &ActiveEventLoop, e: ViewError) {
        self.finish_export();
        self.fatal = Some(e);
        event_loop.exit();
    }

    /// Opens the window and its GPU state, and takes the backend chosen for the viewport.
    pub(super) fn init(&mut self, event_loop: &ActiveEventLoop) -> Result<(), ViewError> {
        let scripted = self.script.is_some() || self.opts.screenshot.is_some();
        let (gfx, backend) =
            Gfx::open(event_loop, &mut self.viewer, &self.egui_ctx, scripted, self.opts.backend)?;
        self.backend = backend;
        self.gfx = Some(gfx);
        Ok(())
    }

    pub(super) fn resize(&mut self, w: u32, h: u32) {
        self.minimised = w == 0 || h == 0;
        if let Some(g) = &mut self.gfx {
            if !self.minimised {
                g.configure(w, h);
            }
        }
    }

    /// Cancels a running export and waits (up to a minute) for it to stop, so that closing the
    /// window leaves no temporary file behind.
    pub(super) fn finish_export(&mut self) {
        if let Some(j) = self.export.take() {
            j.finish();
        }
    }
}
