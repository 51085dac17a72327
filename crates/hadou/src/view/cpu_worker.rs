//! The CPU path's render thread: the CPU backend renders the newest frame there while the window
//! keeps handling input, and converts its image to the sRGB bytes the viewport texture takes.

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
    pub(super) jobs: mpsc::Sender<(u64, Frame)>,
    pub(super) done: mpsc::Receiver<CpuDone>,
    /// Uploaded pixel buffers, returned to the worker for reuse.
    pub(super) back: mpsc::Sender<Vec<u8>>,
    pub(super) busy: bool,
}

impl CpuWorker {
    pub(super) fn start() -> std::io::Result<CpuWorker> {
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
            }
        })?;
        Ok(CpuWorker { jobs, done, back, busy: false })
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
