//! The `--script` runner: one command at a time between drawn frames, waits, window resizes, and a
//! failure of what a command asked for stopping the run with the command's line.

use super::app::{check_window_size, App};
use super::options::fail;
use hadou_view::script::{self, WindowOp};
use winit::event_loop::ActiveEventLoop;

impl App {
    /// Runs script commands until one needs frames to pass.
    pub(super) fn step_script(&mut self, event_loop: &ActiveEventLoop) {
        // A script waits for a running export to finish before its next command.
        if self.export.is_some() {
            return;
        }
        if self.wait_frames > 0 {
            self.wait_frames -= 1;
            return;
        }
        let Some((lines, path)) = &self.script else { return };
        let (line, count, path) = (lines.get(self.script_pos).cloned(), lines.len(), path.clone());
        // A command runs once the previous frame has been drawn (edits show before the next).
        if let Some(line) = line {
            self.script_pos += 1;
            self.script_line = line.line;
            match script::run(&mut self.viewer, &line, &path) {
                Ok(WindowOp::None) => {}
                Ok(WindowOp::Wait(n)) => self.wait_frames = n,
                Ok(WindowOp::Resize(w, h)) => {
                    // Checked before the window or its surface changes; a size past the limits or
                    // one the surface cannot take stops the run with this line.
                    let at = format!("{}:{}:{}", path.display(), line.line, line.arg_col(0));
                    if let Some(g) = &self.gfx {
                        if w > 0 && h > 0 {
                            if let Err(e) = check_window_size(g.max_edge(), w, h) {
                                self.die(event_loop, fail(2, format!("{at}: {e}")));
                                return;
                            }
                            let _ = g.window.request_inner_size(winit::dpi::PhysicalSize::new(w, h));
                        }
                    }
                    // The path a minimised or 0×0 window takes too.
                    if let Err(e) = self.resize(w, h) {
                        self.refuse_size(e.clone());
                        self.die(event_loop, fail(2, format!("{at}: {e}")));
                    }
                }
                Ok(WindowOp::Quit) => self.script_pos = count,
                Err(e) => self.die(event_loop, fail(2, e)),
            }
        }
    }

    /// In a scripted run, an error reported since `before` (a screenshot or export that failed, a
    /// backend that is not there, a GPU render failure, a window surface that cannot be drawn)
    /// stops the viewer: with a script, exit 2 naming the script line that ran last; with only
    /// `--screenshot`, exit 1. Returns whether it stopped.
    pub(super) fn script_failed(
        &mut self,
        event_loop: &ActiveEventLoop,
        before: Option<(String, bool)>,
    ) -> bool {
        if self.script.is_none() && self.opts.screenshot.is_none() {
            return false;
        }
        match &self.viewer.message {
            Some((m, true)) if self.viewer.message != before => {
                let e = match &self.script {
                    Some((_, path)) => fail(2, format!("{}:{}: {m}", path.display(), self.script_line)),
                    None => fail(1, m.clone()),
                };
                self.die(event_loop, e);
                true
            }
            _ => false,
        }
    }

    pub(super) fn script_finished(&self) -> bool {
        self.script.as_ref().is_none_or(|(l, _)| self.script_pos >= l.len()) && self.wait_frames == 0
    }
}
