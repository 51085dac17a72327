//! An animation export on its own thread, with progress and cancel: what the panel's and the
//! script's `export` starts.

use crate::export::{self, AnimationSpec, Control, ExportOutcome};
use hadou_cpu::CpuBackend;
use hadou_scene::Scene;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::mpsc;
use std::sync::Arc;
use std::time::Duration;

/// A running export.
pub(super) struct ExportJob {
    done: Arc<AtomicU32>,
    /// Frames to write.
    pub(super) total: u32,
    cancel: Arc<AtomicBool>,
    result: mpsc::Receiver<Result<String, String>>,
}

impl ExportJob {
    /// Starts exporting `frames` of `scene` at `fps` to `path` with the CPU backend; an invalid
    /// frame range or rate is refused with its message before anything starts.
    pub(super) fn start(
        scene: Scene,
        path: PathBuf,
        frames: std::ops::Range<u32>,
        fps: f32,
    ) -> Result<ExportJob, String> {
        let spec = AnimationSpec { frames: frames.clone(), fps, width: None, height: None, samples: None };
        spec.validate().map_err(|e| e.to_string())?;
        let done = Arc::new(AtomicU32::new(0));
        let cancel = Arc::new(AtomicBool::new(false));
        let (tx, result) = mpsc::channel();
        let (d, c) = (done.clone(), cancel.clone());
        let total = frames.len() as u32;
        std::thread::spawn(move || {
            let mut backend = CpuBackend::new();
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
        Ok(ExportJob { done, total, cancel, result })
    }

    /// (frames written, frames to write).
    pub(super) fn progress(&self) -> (u32, u32) {
        (self.done.load(Ordering::Relaxed), self.total)
    }

    /// Asks the export to stop after the frame it is writing.
    pub(super) fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// The export's outcome once it has ended (its message, or its error); `None` while it runs.
    pub(super) fn outcome(&self) -> Option<Result<String, String>> {
        match self.result.try_recv() {
            Ok(r) => Some(r),
            Err(mpsc::TryRecvError::Empty) => None,
            Err(mpsc::TryRecvError::Disconnected) => Some(Err("the export stopped unexpectedly".into())),
        }
    }

    /// Cancels the export and waits (up to a minute) for it to stop, so that closing the window
    /// leaves no temporary file behind.
    pub(super) fn finish(self) {
        self.cancel();
        let _ = self.result.recv_timeout(Duration::from_secs(60));
    }
}
