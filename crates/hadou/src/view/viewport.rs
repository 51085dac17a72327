//! The viewport's image: the GPU backend renders straight into a texture the viewport shows
//! ([`GpuBackend::render_to_texture`](hadou_gpu::GpuBackend::render_to_texture): no read-back),
//! with its own timestamps as the render time where the adapter has them; the CPU backend's
//! frames go to the render thread, and its finished images are uploaded into the viewport
//! texture.

use super::app::App;
use super::cpu_worker::CpuDone;
use super::texture::{bind_native, upload_rgba, viewport_texture};
use hadou_view::ui::ViewportImage;
use hadou_view::viewer::BackendKind;
use std::time::Instant;

/// What the viewport shows: the document's text, the time and the backend.
type DrawKey = (String, f32, BackendKind);

impl App {
    /// Starts or collects the viewport's rendering. When a new image is shown, returns the
    /// viewer's own time spent on it outside the renderer (ms): evaluating the frame, and for the
    /// CPU backend converting its image to sRGB bytes and uploading them. The CPU render thread's
    /// finished frames are collected whichever backend draws now (a frame in flight when the
    /// backend changed ends here too, unshown).
    pub(super) fn update_image(&mut self) -> Option<f64> {
        let key = (self.viewer.doc.text().to_string(), self.viewer.timeline.time, self.backend);
        let changed = self.drawn.as_ref() != Some(&key);
        let done = match self.cpu.collect() {
            Ok(d) => d,
            Err(e) => {
                self.viewer.complain(e);
                None
            }
        };
        match self.backend {
            BackendKind::Gpu => {
                if let Some(d) = done {
                    self.cpu.recycle(d.rgba);
                }
                self.update_gpu_image(key, changed)
            }
            BackendKind::Cpu => self.update_cpu_image(key, changed, done),
        }
    }

    /// The GPU path: the newest GPU timestamps as the render time, and a new frame rendered into
    /// the viewport's texture when `changed`.
    fn update_gpu_image(&mut self, key: DrawKey, changed: bool) -> Option<f64> {
        let g = self.gfx.as_mut()?;
        let mut overhead = None;
        // The GPU's own time of the newest frame whose timestamps have come back (never
        // waits; none on adapters without timestamp queries).
        if let Some(t) = g.gpu.as_mut().and_then(|gpu| gpu.last_present_timing()) {
            let passes = t.passes.iter().map(|p| (p.name.as_str(), p.median_ms));
            self.viewer.stats.gpu_timestamps(t.serial, t.frame_ms, passes);
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
                        old => bind_native(&mut g.egui_renderer, &g.device, out.view, old),
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
        overhead
    }

    /// The CPU path: the render thread's finished frame `done` uploaded into the viewport's
    /// texture (when it is the frame sent last), and a new frame sent to it when `changed` and it
    /// is free.
    fn update_cpu_image(&mut self, key: DrawKey, changed: bool, done: Option<CpuDone>) -> Option<f64> {
        let Some(g) = self.gfx.as_mut() else {
            if let Some(d) = done {
                self.cpu.recycle(d.rgba);
            }
            return None;
        };
        let mut overhead = None;
        if let Some(done) = done {
            if done.generation != self.generation {
                self.cpu.recycle(done.rgba);
            } else {
                let u0 = Instant::now();
                let size = done.size;
                let needs_new = g.cpu_texture.as_ref().is_none_or(|t| t.2 != size);
                if needs_new {
                    let tex = viewport_texture(&g.device, size);
                    let view = tex.create_view(&Default::default());
                    let old = g.cpu_texture.take();
                    let id = bind_native(&mut g.egui_renderer, &g.device, &view, old.as_ref().map(|t| t.1));
                    g.cpu_texture = Some((tex, id, size));
                }
                if let Some((tex, id, _)) = &g.cpu_texture {
                    upload_rgba(&g.queue, tex, &done.rgba, size);
                    self.image = Some(ViewportImage { texture: *id, size });
                }
                self.cpu.recycle(done.rgba);
                self.viewer.stats.render_ms = done.render_ms;
                self.viewer.stats.render_method = "CPU backend, wall clock on the render thread".into();
                overhead = Some(self.eval_ms + done.convert_ms + u0.elapsed().as_secs_f64() * 1e3);
            }
        }
        if changed && !self.cpu.busy() {
            let e0 = Instant::now();
            let frame = self.viewer.frame();
            self.eval_ms = e0.elapsed().as_secs_f64() * 1e3;
            if self.cpu.send(self.generation + 1, frame) {
                self.generation += 1;
                self.drawn = Some(key);
            }
        }
        overhead
    }
}
