//! winit's event loop: the window's events, one frame of the viewer per redraw (the disk polled
//! for hot reload, the clock, requests, the viewport's image, the UI drawn and presented, the
//! frame-time samples, the script's next command or its end), and when to draw again.

use super::app::{App, Sample};
use super::options::fail;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow};
use winit::window::WindowId;

impl App {
    /// One frame of the viewer.
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
        let image = self.image;
        let (viewer, ui) = (&mut self.viewer, &mut self.ui);
        if g.draw(&self.egui_ctx, |ui_root| hadou_view::ui::show(ui_root, viewer, image, ui)) {
            self.frames_shown += 1;
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
