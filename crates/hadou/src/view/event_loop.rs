//! winit's event loop: the window's events, one frame of the viewer per redraw (the disk polled
//! for hot reload, the clock, requests, the viewport's image, the UI drawn and presented, the
//! frame-time samples, the script's next command or its end), and when to draw again: at once only
//! while a frame has work to do, otherwise on input, on the CPU render thread's wake-up ([`Wake`])
//! or on a clock (never `ControlFlow::Poll`, so a viewer waiting for anything does not spin).

use super::app::{App, Sample, Wake};
use super::options::fail;
use super::surface::Drawn;
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
        if now.duration_since(self.last_poll) > DISK_POLL {
            self.last_poll = now;
            let _ = self.viewer.poll_disk();
        }
        if self.minimised {
            return;
        }
        self.viewer.tick(dt);
        let before = self.viewer.message.clone();
        self.service();
        let viewer_ms = self.update_image();
        if self.script_failed(event_loop, before.clone()) {
            return;
        }
        let ui_start = Instant::now();
        let Some(g) = &mut self.gfx else { return };
        let image = self.image;
        let (viewer, ui) = (&mut self.viewer, &mut self.ui);
        match g.draw(&self.egui_ctx, |ui_root| hadou_view::ui::show(ui_root, viewer, image, ui)) {
            Drawn::Presented => self.frames_shown += 1,
            Drawn::Skipped => {}
            Drawn::Failed(m) => {
                self.refuse_size(format!("{m}; nothing is drawn until the window is resized"))
            }
        }
        if self.script_failed(event_loop, before) {
            return;
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
                && !self.cpu.busy();
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

impl ApplicationHandler<Wake> for App {
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
            // egui asks for a repaint after every redraw too; following that would draw forever.
            if r.repaint && !matches!(event, WindowEvent::RedrawRequested) {
                g.window.request_redraw();
            }
        }
        match event {
            WindowEvent::CloseRequested => {
                self.finish_export();
                event_loop.exit();
            }
            WindowEvent::Resized(size) => {
                self.window_resized(size.width, size.height);
                if let Some(g) = &self.gfx {
                    g.window.request_redraw();
                }
            }
            WindowEvent::Occluded(true) => self.minimised = true,
            WindowEvent::Occluded(false) => {
                if let Some(g) = &self.gfx {
                    let s = g.window.inner_size();
                    self.window_resized(s.width, s.height);
                }
            }
            WindowEvent::RedrawRequested => self.redraw(event_loop),
            _ => {}
        }
    }

    fn user_event(&mut self, _event_loop: &ActiveEventLoop, _wake: Wake) {
        // The CPU render thread finished a frame: draw it.
        if let Some(g) = &self.gfx {
            if !self.minimised {
                g.window.request_redraw();
            }
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let Some(g) = &self.gfx else { return };
        let scripted = self.script.is_some() || self.opts.screenshot.is_some();
        // Minimised: no drawing at all (no busy loop).
        if self.minimised {
            if scripted {
                // A scripted run keeps its script going while minimised.
                event_loop.set_control_flow(ControlFlow::WaitUntil(Instant::now() + MINIMISED_SCRIPT_STEP));
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
                event_loop.set_control_flow(ControlFlow::WaitUntil(Instant::now() + DISK_POLL));
            }
            return;
        }
        // Draw when the next frame has something to do; otherwise sleep until input, the render
        // thread's wake-up or the next timed look (the clock, an export's progress, the file).
        // The file is looked at here, and a frame drawn only when it changed.
        let now = Instant::now();
        if now.duration_since(self.last_poll) >= DISK_POLL {
            self.last_poll = now;
            if self.viewer.poll_disk() {
                g.window.request_redraw();
            }
        }
        match self.next_frame() {
            Due::Now => {
                g.window.request_redraw();
                event_loop.set_control_flow(ControlFlow::Wait);
            }
            Due::At(t) if t <= now => {
                g.window.request_redraw();
                event_loop.set_control_flow(ControlFlow::Wait);
            }
            Due::At(t) => event_loop.set_control_flow(ControlFlow::WaitUntil(t)),
            Due::OnEvent => event_loop.set_control_flow(ControlFlow::Wait),
        }
    }
}

/// When the next window frame is due.
enum Due {
    /// At once: it makes progress (a script command, a frame sent to the render thread).
    Now,
    /// At this instant.
    At(Instant),
    /// When input or the render thread's wake-up comes.
    OnEvent,
}

/// How often a playing clock draws at most (about 120 frames a second).
const PLAY_INTERVAL: Duration = Duration::from_millis(8);
/// How often a running export's progress is looked at.
const EXPORT_POLL: Duration = Duration::from_millis(30);
/// How often the file is looked at for hot reload when nothing else happens.
const DISK_POLL: Duration = Duration::from_millis(300);
/// How often a minimised scripted run takes its next command.
const MINIMISED_SCRIPT_STEP: Duration = Duration::from_millis(10);

impl App {
    /// When the next frame is due: at once while a script has commands to run (each frame takes
    /// one) or a scripted run's end waits for a frame it can send now; on the render thread's
    /// wake-up while it renders the frame everything waits for; on a clock while playing or
    /// exporting; otherwise at the next look at the file.
    fn next_frame(&self) -> Due {
        let scripted = self.script.is_some() || self.opts.screenshot.is_some();
        if self.export.is_some() {
            return Due::At(self.last_frame + EXPORT_POLL);
        }
        if self.script.is_some() && !self.script_finished() {
            return Due::Now;
        }
        if scripted {
            // The end of a scripted run: the last image, then the screenshot and exit.
            return if self.cpu.busy() { Due::OnEvent } else { Due::Now };
        }
        if self.viewer.timeline.playing {
            return Due::At(self.last_frame + PLAY_INTERVAL);
        }
        if self.cpu.busy() {
            return Due::OnEvent;
        }
        Due::At(self.last_poll + DISK_POLL)
    }
}
