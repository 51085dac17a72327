//! The CPU path's render thread: the CPU backend renders the newest frame there while the window
//! keeps handling input, and converts its image to the sRGB bytes the viewport texture takes.
//!
//! Whether a frame is in flight is not a flag the window sets and clears: [`CpuWorker::collect`]
//! derives it from the generations sent and received, and the window calls it every frame
//! whatever it draws with, so no change of state while a frame renders (a backend switch, a scene
//! reload, a resize) can leave the worker looking busy. The thread wakes the event loop when a
//! frame is done, so the window waits for it instead of polling.

use hadou_cpu::CpuBackend;
use hadou_scene::{Frame, Image};
use std::sync::mpsc;
use std::time::Instant;

/// A CPU frame finished on the worker.
pub(super) struct CpuDone {
    pub(super) generation: u64,
    pub(super) size: [u32; 2],
    pub(super) rgba: Vec<u8>,
    pub(super) render_ms: f64,
    pub(super) convert_ms: f64,
}

/// The CPU backend on its own thread: one frame in flight at a time.
pub(super) struct CpuWorker {
    jobs: mpsc::Sender<(u64, Frame)>,
    done: mpsc::Receiver<CpuDone>,
    /// Uploaded pixel buffers, returned to the worker for reuse.
    back: mpsc::Sender<Vec<u8>>,
    /// The generation of the frame sent last and not yet returned.
    in_flight: Option<u64>,
    /// Set when the thread has stopped (it cannot take frames any more).
    stopped: bool,
}

impl CpuWorker {
    /// Starts the thread; `wake` is called on it after each finished frame (it wakes the event
    /// loop).
    pub(super) fn start(wake: impl Fn() + Send + 'static) -> std::io::Result<CpuWorker> {
        let (jobs, job_rx) = mpsc::channel::<(u64, Frame)>();
        let (done_tx, done) = mpsc::channel();
        let (back, back_rx) = mpsc::channel::<Vec<u8>>();
        std::thread::Builder::new().name("hadou-view-cpu".into()).spawn(move || {
            let mut backend = CpuBackend::new();
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
                wake();
            }
        })?;
        Ok(CpuWorker { jobs, done, back, in_flight: None, stopped: false })
    }

    /// Whether a frame is rendering (sent and not yet collected).
    pub(super) fn busy(&self) -> bool {
        self.in_flight.is_some()
    }

    /// Sends frame `generation` to the thread; `false` when it is busy or has stopped.
    pub(super) fn send(&mut self, generation: u64, frame: Frame) -> bool {
        if self.busy() || self.stopped {
            return false;
        }
        if self.jobs.send((generation, frame)).is_err() {
            self.stopped = true;
            return false;
        }
        self.in_flight = Some(generation);
        true
    }

    /// Takes the frames the thread has finished and returns the newest (older ones' buffers go
    /// back for reuse). A frame returned ends the one in flight whatever its generation; a thread
    /// that has stopped ends it too (its `Err` says so, once).
    pub(super) fn collect(&mut self) -> Result<Option<CpuDone>, String> {
        let mut newest: Option<CpuDone> = None;
        loop {
            match self.done.try_recv() {
                Ok(d) => {
                    if self.in_flight.is_some_and(|g| d.generation >= g) {
                        self.in_flight = None;
                    }
                    if let Some(old) = newest.replace(d) {
                        self.recycle(old.rgba);
                    }
                }
                Err(mpsc::TryRecvError::Empty) => return Ok(newest),
                Err(mpsc::TryRecvError::Disconnected) => {
                    self.in_flight = None;
                    if self.stopped {
                        return Ok(newest);
                    }
                    self.stopped = true;
                    return Err("the CPU render thread stopped".into());
                }
            }
        }
    }

    /// Returns an uploaded pixel buffer for reuse.
    pub(super) fn recycle(&self, rgba: Vec<u8>) {
        let _ = self.back.send(rgba);
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
