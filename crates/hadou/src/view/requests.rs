//! What the panel or the script asked for ([`Request`]s), carried out in the window: backend
//! switches, probes, screenshots, exports and GPU timings; and a running export followed.

use super::app::App;
use super::export_job::ExportJob;
use crate::export::ExportError;
use crate::output;
use hadou_cpu::CpuBackend;
use hadou_scene::Backend;
use hadou_view::viewer::{BackendKind, Request};
use std::path::PathBuf;

impl App {
    /// Carries out what the panel or the script asked for, and follows a running export.
    pub(super) fn service(&mut self) {
        self.poll_export();
        self.handle_requests();
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
                    self.viewer.probe = Some(match hadou_cpu::probe(&frame, x, y) {
                        Some(p) => p.summary(),
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
                        j.cancel();
                    }
                }
                Request::Quit => self.script_pos = usize::MAX,
                // The native viewer saves into the file (`save_downloads` is off).
                Request::DownloadScene => {}
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
    /// `hadou render` does: band by band, through a temporary file registered for the interrupt
    /// handler's clean-up.
    pub(super) fn screenshot(&mut self, path: &std::path::Path) -> Result<(), String> {
        output::check_writable(path).map_err(|e| e.to_string())?;
        let frame = self.viewer.frame();
        let mut cpu = CpuBackend::new();
        let backend: &mut dyn Backend = match (self.backend, self.gfx.as_mut().and_then(|g| g.gpu.as_mut())) {
            (BackendKind::Gpu, Some(gpu)) => gpu,
            _ => &mut cpu,
        };
        output::write_banded(path, frame.width, frame.height, output::frame_band_rows(&frame), |rows| {
            Ok::<_, ExportError>(backend.render_rows(&frame, rows)?)
        })
        .map_err(|e| e.to_string())
    }

    fn start_export(&mut self, path: PathBuf, frames: std::ops::Range<u32>, fps: f32) {
        if self.export.is_some() {
            self.viewer.complain("an export is already running");
            return;
        }
        match ExportJob::start(self.viewer.scene().clone(), path, frames, fps) {
            Ok(job) => {
                self.viewer.export_progress = Some((0, job.total));
                self.export = Some(job);
            }
            Err(e) => self.viewer.complain(e),
        }
    }

    fn poll_export(&mut self) {
        let Some(j) = &self.export else { return };
        self.viewer.export_progress = Some(j.progress());
        if let Some(r) = j.outcome() {
            match r {
                Ok(m) => self.viewer.say(m),
                Err(m) => self.viewer.complain(m),
            }
            self.export = None;
            self.viewer.export_progress = None;
        }
    }
}
