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

/// The event loop's user event: the CPU render thread finished a frame.
#[derive(Clone, Copy, Debug)]
pub(super) struct Wake;

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

    /// The `--stats` figures as one JSON object: medians over the new images shown, `null` for a
    /// figure with no sample (a static scene's single image may never be timed).
    pub(super) fn stats_json(&self) -> String {
        let median = |f: fn(&Sample) -> f64| median_json(self.samples.iter().map(f));
        let frame = self.viewer.frame();
        format!(
            "{{\"backend\": \"{}\", \"size\": [{}, {}], \"frames\": {}, \"median_frame_ms\": {}, \"median_render_ms\": {}, \"median_image_overhead_ms\": {}, \"median_ui_ms\": {}}}",
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

    /// The window is `w × h` pixels: configures the surface for it (0 on either edge is a
    /// minimised window: nothing is drawn). A size past the limits ([`check_window_size`]) or one
    /// the surface cannot take is refused: `Err` says why, and the surface keeps the last size
    /// that worked.
    pub(super) fn resize(&mut self, w: u32, h: u32) -> Result<(), String> {
        self.minimised = w == 0 || h == 0;
        let Some(g) = &mut self.gfx else { return Ok(()) };
        if self.minimised {
            return Ok(());
        }
        check_window_size(g.max_edge(), w, h)?;
        if g.size() == [w, h] && g.last_good() == [w, h] {
            return Ok(());
        }
        g.configure(w, h)
    }

    /// The window became `w × h` pixels (the user, the window manager or a script resized it): a
    /// size that is refused is reported in the status line and the window asked back to the last
    /// size that worked.
    pub(super) fn window_resized(&mut self, w: u32, h: u32) {
        if let Err(e) = self.resize(w, h) {
            self.refuse_size(e);
        }
    }

    /// Reports a window size the surface does not take and asks the window back to the last size
    /// that worked (the surface is configured at it).
    pub(super) fn refuse_size(&mut self, why: String) {
        let Some(g) = &mut self.gfx else { return };
        let [gw, gh] = g.last_good();
        if g.size() != [gw, gh] {
            let _ = g.configure(gw, gh);
        }
        let _ = g.window.request_inner_size(winit::dpi::PhysicalSize::new(gw, gh));
        self.viewer.complain(why);
    }

    /// Cancels a running export and waits (up to a minute) for it to stop, so that closing the
    /// window leaves no temporary file behind.
    pub(super) fn finish_export(&mut self) {
        if let Some(j) = self.export.take() {
            j.finish();
        }
    }
}

/// The median of the finite `values` as a JSON number with 3 decimals; `null` when there is none.
fn median_json(values: impl Iterator<Item = f64>) -> String {
    let mut v: Vec<f64> = values.filter(|x| x.is_finite()).collect();
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).map_or_else(|| "null".to_string(), |m| format!("{m:.3}"))
}

/// Checks a window size before the surface is configured: each edge in `1..=MAX_IMAGE_EDGE`
/// (16384, the most a script's `resize` may ask for) and at most the adapter's largest surface
/// edge `max_edge`. The window only shows the image; the image keeps the scene's `[image]` size
/// (checked by the loader), so a scene's own image rules (an `[area_light]`'s pixel limit) do not
/// bound the window.
pub(super) fn check_window_size(max_edge: u32, w: u32, h: u32) -> Result<(), String> {
    let limit = max_edge.min(hadou_scene::MAX_IMAGE_EDGE);
    if w == 0 || h == 0 || w > limit || h > limit {
        let why = if max_edge < hadou_scene::MAX_IMAGE_EDGE {
            format!("this adapter's surfaces are 1..={max_edge} pixels on each edge")
        } else {
            format!("window edges are 1..={} pixels", hadou_scene::MAX_IMAGE_EDGE)
        };
        return Err(format!("the window cannot be {w}×{h} pixels: {why}"));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{check_window_size, median_json};

    #[test]
    fn window_sizes_follow_the_edge_limits_and_the_adapter() {
        // A window larger than an [area_light] scene's image limit only shows the image.
        assert!(check_window_size(16384, 5000, 4000).is_ok());
        assert!(check_window_size(16384, 16384, 16384).is_ok());
        let e = check_window_size(16384, 16385, 10).unwrap_err();
        assert!(e.contains("16385×10") && e.contains("1..=16384"), "{e}");
        let e = check_window_size(8192, 8193, 100).unwrap_err();
        assert!(e.contains("adapter") && e.contains("1..=8192"), "{e}");
        assert!(check_window_size(8192, 0, 100).is_err());
    }

    #[test]
    fn a_median_without_samples_is_null_not_nan() {
        assert_eq!(median_json(std::iter::empty()), "null");
        assert_eq!(median_json([f64::NAN, f64::INFINITY].into_iter()), "null");
        assert_eq!(median_json([3.0, 1.0, f64::NAN, 2.0].into_iter()), "2.000");
    }
}
