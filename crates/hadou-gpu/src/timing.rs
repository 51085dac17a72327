//! GPU frame timing for benchmarks: timestamp queries when the device has them, otherwise the
//! wall time from submitting a frame's work to its completion. Read-back is never included.

use crate::render::Renderer;
use hadou_scene::{Frame, RenderError};
use std::time::Instant;

/// How [`FrameTiming`] was measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimingMethod {
    /// GPU timestamps (`Features::TIMESTAMP_QUERY`) at the start of each tile's raster pass and the
    /// end of its wave pass, summed over tiles: pure GPU execution time.
    GpuTimestamps,
    /// Wall-clock time from the first submit of a frame until the GPU reports it finished; includes
    /// submission and driver overhead. Frames with an `[area_light]` are always timed this way,
    /// with their preparation inside the timing (uploads, the two soft-shadow maps and the
    /// whole-image penumbra resolve run there, before the tiles).
    WallClock,
}

/// The result of [`crate::GpuBackend::time_frame`].
#[derive(Clone, Debug, PartialEq)]
pub struct FrameTiming {
    /// How the times were measured.
    pub method: TimingMethod,
    /// Tiles per frame (each is one raster + one wave pass).
    pub tiles: u32,
    /// Milliseconds per timed iteration, in order.
    pub per_iteration_ms: Vec<f64>,
    /// Mean of `per_iteration_ms`.
    pub mean_ms: f64,
    /// Median of `per_iteration_ms`.
    pub median_ms: f64,
    /// Minimum of `per_iteration_ms`.
    pub min_ms: f64,
}

impl FrameTiming {
    fn from_samples(method: TimingMethod, tiles: u32, per_iteration_ms: Vec<f64>) -> Self {
        let n = per_iteration_ms.len().max(1) as f64;
        let mean_ms = per_iteration_ms.iter().sum::<f64>() / n;
        let mut sorted = per_iteration_ms.clone();
        sorted.sort_by(f64::total_cmp);
        let median_ms = if sorted.is_empty() {
            0.0
        } else if sorted.len() % 2 == 1 {
            sorted[sorted.len() / 2]
        } else {
            0.5 * (sorted[sorted.len() / 2 - 1] + sorted[sorted.len() / 2])
        };
        let min_ms = sorted.first().copied().unwrap_or(0.0);
        Self { method, tiles, per_iteration_ms, mean_ms, median_ms, min_ms }
    }

    /// Frames per second at the median time (0 when the time is 0).
    pub fn fps(&self) -> f64 {
        if self.median_ms > 0.0 {
            1000.0 / self.median_ms
        } else {
            0.0
        }
    }
}

/// See [`crate::GpuBackend::time_frame`].
pub(crate) fn time_frame(
    r: &mut Renderer,
    frame: &Frame,
    iterations: u32,
) -> Result<FrameTiming, RenderError> {
    if iterations == 0 {
        return Err(RenderError::Other("time_frame needs at least one iteration".into()));
    }
    let prepared = r.prepare(frame, 0..frame.height)?;
    let tiles = prepared.tiles.len() as u32;
    // Warm-up: pipelines, caches and first-use costs stay out of the measurement.
    let last = r.ctx.scoped("warming up", || {
        let cmds: Vec<_> = prepared
            .tiles
            .iter()
            .map(|&t| r.encode_tile(frame, &prepared, t, false, None).finish())
            .collect();
        let mut last = None;
        for c in cmds {
            last = Some(r.ctx.queue.submit([c]));
        }
        last
    })?;
    if let Some(s) = last {
        r.ctx.wait(s)?;
    }

    let queries = 2 * tiles;
    let soft = frame.area_light.is_some();
    let use_timestamps = !soft
        && r.ctx.features.contains(wgpu::Features::TIMESTAMP_QUERY)
        && queries <= wgpu::QUERY_SET_MAX_QUERIES;
    let mut samples = Vec::with_capacity(iterations as usize);
    if use_timestamps {
        let bytes = queries as u64 * 8;
        let (set, resolve, read) = r.ctx.scoped("creating timestamp queries", || {
            let d = &r.ctx.device;
            let set = d.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("frame timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: queries,
            });
            let resolve = d.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp resolve"),
                size: bytes,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let read = d.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp read"),
                size: bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            (set, resolve, read)
        })?;
        let period_ns = r.ctx.queue.get_timestamp_period() as f64;
        for _ in 0..iterations {
            let last = r.ctx.scoped("timing a frame", || {
                let mut last = None;
                for (k, &t) in prepared.tiles.iter().enumerate() {
                    let mut enc = r.encode_tile(frame, &prepared, t, false, Some((&set, k as u32)));
                    if k + 1 == prepared.tiles.len() {
                        enc.resolve_query_set(&set, 0..queries, &resolve, 0);
                        enc.copy_buffer_to_buffer(&resolve, 0, &read, 0, bytes);
                    }
                    last = Some(r.ctx.queue.submit([enc.finish()]));
                }
                last
            })?;
            let Some(last) = last else { break };
            let ticks = r.ctx.read_buffer(&read, bytes, last, |raw| {
                raw.chunks_exact(16)
                    .map(|q| {
                        let begin = u64::from_ne_bytes(q[0..8].try_into().unwrap_or_default());
                        let end = u64::from_ne_bytes(q[8..16].try_into().unwrap_or_default());
                        end.saturating_sub(begin)
                    })
                    .sum::<u64>()
            })?;
            samples.push(ticks as f64 * period_ns * 1e-6);
        }
        return Ok(FrameTiming::from_samples(TimingMethod::GpuTimestamps, tiles, samples));
    }
    if soft {
        for _ in 0..iterations {
            let start = Instant::now();
            let prepared = r.prepare(frame, 0..frame.height)?;
            let mut last = None;
            for &t in &prepared.tiles {
                let c = r.encode_tile(frame, &prepared, t, false, None).finish();
                last = Some(r.ctx.queue.submit([c]));
            }
            if let Some(s) = last {
                r.ctx.wait(s)?;
            }
            samples.push(start.elapsed().as_secs_f64() * 1e3);
        }
        return Ok(FrameTiming::from_samples(TimingMethod::WallClock, tiles, samples));
    }
    for _ in 0..iterations {
        let cmds = r.ctx.scoped("encoding a frame", || {
            prepared
                .tiles
                .iter()
                .map(|&t| r.encode_tile(frame, &prepared, t, false, None).finish())
                .collect::<Vec<_>>()
        })?;
        let start = Instant::now();
        let mut last = None;
        for c in cmds {
            last = Some(r.ctx.queue.submit([c]));
        }
        if let Some(s) = last {
            r.ctx.wait(s)?;
        }
        samples.push(start.elapsed().as_secs_f64() * 1e3);
    }
    Ok(FrameTiming::from_samples(TimingMethod::WallClock, tiles, samples))
}
