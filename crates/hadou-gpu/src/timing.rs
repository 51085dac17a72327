//! GPU frame timing for benchmarks: timestamp queries when the device has them, otherwise the
//! wall time from submitting a frame's work to its completion. Read-back is never included.

// On the web only the pass queries are used (nothing there waits for the GPU to time it).
#![cfg_attr(target_arch = "wasm32", allow(dead_code))]

use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::Arc;

/// How [`FrameTiming`] was measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimingMethod {
    /// GPU timestamps (`Features::TIMESTAMP_QUERY`) written at the beginning and end of every pass
    /// (`timestamp_writes` of the pass descriptors): the frame is the shadow-map passes' span plus,
    /// per tile, the span from its first pass's beginning to its last pass's end, summed over
    /// tiles, plus a `[bloom]`'s glare pass of each band: pure GPU execution time. [`FrameTiming::passes`] splits it by pass.
    GpuTimestamps,
    /// Wall-clock time from the first submit of a frame (its shadow maps, then its tiles) until the
    /// GPU reports it finished; includes submission and driver overhead. Frames with an `[area_light]` are always timed this way,
    /// with their preparation inside the timing (uploads, the two soft-shadow maps and the
    /// whole-image penumbra resolve run there, before the tiles).
    WallClock,
}

/// The GPU time of one kind of pass in a frame, from [`crate::GpuBackend::time_frame`] (or, for one
/// frame, [`crate::GpuBackend::last_present_timing`]).
#[derive(Clone, Debug, PartialEq)]
pub struct PassTime {
    /// The pass: `"shadow maps"` (once per frame, every map layer), then per tile `"raster"`
    /// (opaque geometry and outline hulls into the G-buffer), `"edges"` (outlines closed where
    /// objects meet), `"plane shadows"` (only when the
    /// frame has plane shadows) and `"wave"` (shading, shadow lookups, the energy integrals and
    /// the colour mapping), then, for a frame with a `[bloom]`, once per glare band `"bloom"` (the
    /// whole glare chain, its composite and colour mapping).
    pub name: String,
    /// Median over the timed iterations of this pass's time summed over the frame's tiles (or
    /// map layers), in milliseconds.
    pub median_ms: f64,
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
    /// The frame split by pass, in the order the passes first run ([`PassTime`]). With
    /// [`TimingMethod::GpuTimestamps`] the passes' GPU times; a frame with an `[area_light]`
    /// (timed by wall clock) is split in two, [`SOFT_PREPARATION`] and [`SOFT_TILES`]; empty when
    /// the adapter has no timestamp queries (some GL and GLES drivers) and the frame has no area
    /// light. Each pass's median is at most `median_ms`, and in any one iteration the passes sum
    /// to at most the frame (the frame also holds the gaps between passes).
    pub passes: Vec<PassTime>,
}

/// The first part of a frame with an `[area_light]` in [`FrameTiming::passes`], by wall clock:
/// uploads, the shadow maps and the soft shadows (every tile rasterized for its points, the fit
/// windows read back, the two maps, the classes and the resolve), until the GPU has finished them.
pub const SOFT_PREPARATION: &str = "soft preparation (wall clock)";
/// The second part: the tiles drawn (raster, edges, plane shadows, the soft gather, the wave
/// pass) and a `[bloom]`'s glare chain, until the GPU has finished them.
pub const SOFT_TILES: &str = "tiles (wall clock)";

/// The median of `samples` (0 when empty).
pub(crate) fn median(samples: &[f64]) -> f64 {
    let mut sorted = samples.to_vec();
    sorted.sort_by(f64::total_cmp);
    match sorted.len() {
        0 => 0.0,
        n if n % 2 == 1 => sorted[n / 2],
        n => 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]),
    }
}

/// Timestamp queries handed out to passes as they are encoded: pass `k` writes queries `2k`
/// (beginning) and `2k + 1` (end). Passes are grouped (one group per tile, one for the shadow
/// maps); a group's span, from its first beginning to its last end, is its share of the frame.
pub(crate) struct PassQueries<'a> {
    set: &'a wgpu::QuerySet,
    capacity: u32,
    /// `(name, group)` of every pass given queries, in encoding order.
    pub(crate) passes: Vec<(&'static str, u32)>,
    group: u32,
}

impl<'a> PassQueries<'a> {
    pub(crate) fn new(set: &'a wgpu::QuerySet, capacity: u32) -> Self {
        Self { set, capacity, passes: Vec::new(), group: 0 }
    }

    /// Starts a new group: the passes encoded from now on belong to it.
    pub(crate) fn next_group(&mut self) {
        self.group += 1;
    }

    /// The query pair of the next pass, named `name`; `None` once the set is full.
    fn slot(&mut self, name: &'static str) -> Option<(u32, u32)> {
        let k = self.passes.len() as u32;
        if 2 * k + 2 > self.capacity {
            return None;
        }
        self.passes.push((name, self.group));
        Some((2 * k, 2 * k + 1))
    }

    /// Timestamp writes for a render pass named `name`.
    pub(crate) fn render(&mut self, name: &'static str) -> Option<wgpu::RenderPassTimestampWrites<'a>> {
        let set = self.set;
        self.slot(name).map(|(b, e)| wgpu::RenderPassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: Some(b),
            end_of_pass_write_index: Some(e),
        })
    }

    /// Timestamp writes for a compute pass named `name`.
    pub(crate) fn compute(&mut self, name: &'static str) -> Option<wgpu::ComputePassTimestampWrites<'a>> {
        let set = self.set;
        self.slot(name).map(|(b, e)| wgpu::ComputePassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: Some(b),
            end_of_pass_write_index: Some(e),
        })
    }

    /// Queries written so far.
    pub(crate) fn used(&self) -> u32 {
        2 * self.passes.len() as u32
    }
}

/// The GPU time of one frame drawn by [`crate::GpuBackend::render_to_texture`], from
/// [`crate::GpuBackend::last_present_timing`]: measured from GPU timestamps as
/// [`TimingMethod::GpuTimestamps`] is, read back without waiting.
#[derive(Clone, Debug, PartialEq)]
pub struct PresentTiming {
    /// The frame's GPU time in milliseconds: the shadow-map passes' span plus, per tile, the span
    /// from its first pass's beginning to its present pass's end, summed over the tiles (the gaps
    /// between submissions excluded).
    pub frame_ms: f64,
    /// The frame split by pass, in the order the passes first run: those of
    /// [`FrameTiming::passes`] and `"present"` (per tile, the copy into the window texture). Each
    /// [`PassTime::median_ms`] is that pass's time in this one frame (summed over its tiles or map
    /// layers), at most `frame_ms`; together they are at most `frame_ms`.
    pub passes: Vec<PassTime>,
    /// Which frame it was: the [`crate::PresentedFrame::serial`] `render_to_texture` returned.
    pub serial: u64,
}

/// Staging buffers in the ring of [`PresentTimer`]: frames whose timestamps may be in flight at
/// once (a window shows its GPU time a frame or two late; a frame finding all of them busy is not
/// timed).
const PRESENT_RING: usize = 3;

/// Passes per tile of `render_to_texture` that may take timestamps: those of `PASSES_PER_TILE`,
/// then the present pass.
pub(crate) const PRESENT_PASSES_PER_TILE: u32 = PASSES_PER_TILE + 1;

/// States of a staging buffer of [`PresentTimer`] (in an `AtomicU8`, set by the map callback).
const FREE: u8 = 0;
const MAPPING: u8 = 1;
const MAPPED: u8 = 2;
const FAILED: u8 = 3;

/// One staging buffer of the ring and the frame it holds.
struct Staging {
    buffer: wgpu::Buffer,
    /// [`FREE`], [`MAPPING`] (copy submitted, `map_async` asked), [`MAPPED`] or [`FAILED`].
    state: Arc<AtomicU8>,
    serial: u64,
    /// The frame's passes (`PassQueries::passes`) and the queries it wrote.
    passes: Vec<(&'static str, u32)>,
    used: u32,
}

/// The timestamps of `render_to_texture` frames, read back without ever waiting: every pass of a
/// frame writes its queries, which are resolved and copied into a free staging buffer of a small
/// ring that is then mapped asynchronously; [`PresentTimer::latest`] polls the device without
/// blocking and reads whatever has been mapped. Only on devices with `TIMESTAMP_QUERY`.
pub(crate) struct PresentTimer {
    /// Nanoseconds per timestamp tick (`Queue::get_timestamp_period`).
    period_ns: f64,
    /// Queries the set, the resolve buffer and each staging buffer hold (0 before the first frame).
    capacity: u32,
    set: Option<wgpu::QuerySet>,
    resolve: Option<wgpu::Buffer>,
    ring: Vec<Staging>,
    /// The most recent frame read back.
    latest: Option<PresentTiming>,
}

/// A frame being timed: the query set its passes write and its staging buffer.
pub(crate) struct TimedFrame {
    set: wgpu::QuerySet,
    capacity: u32,
    slot: usize,
}

impl TimedFrame {
    /// The queries to hand to the frame's passes.
    pub(crate) fn queries(&self) -> PassQueries<'_> {
        PassQueries::new(&self.set, self.capacity)
    }
}

impl PresentTimer {
    pub(crate) fn new(queue: &wgpu::Queue) -> Self {
        Self {
            period_ns: queue.get_timestamp_period() as f64,
            capacity: 0,
            set: None,
            resolve: None,
            ring: Vec::new(),
            latest: None,
        }
    }

    /// Queries for a frame whose passes need `queries` of them, or `None` — the frame is simply
    /// not timed — when every staging buffer still holds a frame in flight, or the frame needs more
    /// than one query set holds. The set and buffers grow to fit (frames in flight then are lost).
    pub(crate) fn begin(&mut self, device: &wgpu::Device, queries: u32) -> Option<TimedFrame> {
        if queries == 0 || queries > wgpu::QUERY_SET_MAX_QUERIES {
            return None;
        }
        if queries > self.capacity {
            let capacity = queries.next_power_of_two().clamp(64, wgpu::QUERY_SET_MAX_QUERIES);
            let bytes = capacity as u64 * 8;
            // Free the old ones first (a pending map of a dropped buffer fails: that frame is lost).
            self.ring.clear();
            self.set = Some(device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("present timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: capacity,
            }));
            self.resolve = Some(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("present timestamp resolve"),
                size: bytes,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }));
            self.ring = (0..PRESENT_RING)
                .map(|_| Staging {
                    buffer: device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("present timestamp read"),
                        size: bytes,
                        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                        mapped_at_creation: false,
                    }),
                    state: Arc::new(AtomicU8::new(FREE)),
                    serial: 0,
                    passes: Vec::new(),
                    used: 0,
                })
                .collect();
            self.capacity = capacity;
        }
        // Collect what came back first, so that its buffers are free again.
        self.collect();
        let slot = self.ring.iter().position(|s| s.state.load(Ordering::Acquire) == FREE)?;
        Some(TimedFrame { set: self.set.clone()?, capacity: self.capacity, slot })
    }

    /// After the frame's passes are submitted, having written `queries`: resolves them, copies
    /// them into the frame's staging buffer and asks for that to be mapped. Never waits.
    pub(crate) fn finish(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        frame: &TimedFrame,
        queries: PassQueries<'_>,
        serial: u64,
    ) {
        let used = queries.used();
        let (Some(resolve), Some(staging)) = (&self.resolve, self.ring.get_mut(frame.slot)) else { return };
        if used == 0 || frame.capacity != self.capacity {
            return;
        }
        let bytes = used as u64 * 8;
        let mut enc = device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("present timestamps") });
        enc.resolve_query_set(&frame.set, 0..used, resolve, 0);
        enc.copy_buffer_to_buffer(resolve, 0, &staging.buffer, 0, bytes);
        queue.submit([enc.finish()]);
        staging.state.store(MAPPING, Ordering::Release);
        staging.serial = serial;
        staging.passes = queries.passes;
        staging.used = used;
        let state = staging.state.clone();
        staging.buffer.slice(..bytes).map_async(wgpu::MapMode::Read, move |r| {
            state.store(if r.is_ok() { MAPPED } else { FAILED }, Ordering::Release);
        });
    }

    /// Reads every staging buffer whose map has completed (and unmaps it for reuse), keeping the
    /// most recent frame's timing. Does not poll.
    fn collect(&mut self) {
        for s in &mut self.ring {
            match s.state.load(Ordering::Acquire) {
                MAPPED => {
                    if self.latest.as_ref().is_none_or(|l| l.serial < s.serial) {
                        let ns: Vec<f64> = {
                            let view = s.buffer.slice(..s.used as u64 * 8).get_mapped_range();
                            view.chunks_exact(8)
                                .map(|t| {
                                    u64::from_ne_bytes(t.try_into().unwrap_or_default()) as f64
                                        * self.period_ns
                                })
                                .collect()
                        };
                        let (frame_ms, per_pass) = split_frame(&s.passes, &ns);
                        let passes = per_pass
                            .into_iter()
                            .map(|(name, ms)| PassTime { name: name.to_string(), median_ms: ms })
                            .collect();
                        self.latest = Some(PresentTiming { frame_ms, passes, serial: s.serial });
                    }
                    s.buffer.unmap();
                    s.state.store(FREE, Ordering::Release);
                }
                FAILED => s.state.store(FREE, Ordering::Release),
                _ => {}
            }
        }
    }

    /// See [`crate::GpuBackend::last_present_timing`]: polls the device without blocking (on the
    /// web a no-op: the browser completes maps on its own) and reads what has come back.
    pub(crate) fn latest(&mut self, device: &wgpu::Device) -> Option<PresentTiming> {
        let _ = device.poll(wgpu::PollType::Poll);
        self.collect();
        self.latest.clone()
    }
}

/// One iteration's timestamps (`ticks`: beginning and end of every pass of `passes`, in
/// nanoseconds) reduced to the frame time and the time per pass name, both in milliseconds, the
/// names in order of first appearance.
pub(crate) fn split_frame(passes: &[(&'static str, u32)], ns: &[f64]) -> (f64, Vec<(&'static str, f64)>) {
    let mut per_pass: Vec<(&'static str, f64)> = Vec::new();
    let mut spans: Vec<(u32, f64, f64)> = Vec::new();
    for (k, &(name, group)) in passes.iter().enumerate() {
        let (Some(&b), Some(&e)) = (ns.get(2 * k), ns.get(2 * k + 1)) else { break };
        let ms = (e - b).max(0.0) * 1e-6;
        match per_pass.iter_mut().find(|(n, _)| *n == name) {
            Some(p) => p.1 += ms,
            None => per_pass.push((name, ms)),
        }
        match spans.iter_mut().find(|s| s.0 == group) {
            Some(s) => {
                s.1 = s.1.min(b);
                s.2 = s.2.max(e);
            }
            None => spans.push((group, b, e)),
        }
    }
    let frame = spans.iter().map(|&(_, b, e)| (e - b).max(0.0) * 1e-6).sum();
    (frame, per_pass)
}

impl FrameTiming {
    pub(crate) fn from_samples(method: TimingMethod, tiles: u32, per_iteration_ms: Vec<f64>) -> Self {
        let n = per_iteration_ms.len().max(1) as f64;
        let mean_ms = per_iteration_ms.iter().sum::<f64>() / n;
        let median_ms = median(&per_iteration_ms);
        let min_ms = per_iteration_ms.iter().copied().min_by(f64::total_cmp).unwrap_or(0.0);
        Self { method, tiles, per_iteration_ms, mean_ms, median_ms, min_ms, passes: Vec::new() }
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

/// Passes per tile that may take timestamps: raster, edges, plane shadows, soft gather, wave.
pub(crate) const PASSES_PER_TILE: u32 = 5;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passes_split_by_name_and_the_frame_is_the_sum_of_group_spans() {
        // Group 1: shadow maps (two layers); groups 2 and 3: tiles with raster and wave passes.
        let passes =
            [("shadow maps", 1), ("shadow maps", 1), ("raster", 2), ("wave", 2), ("raster", 3), ("wave", 3)];
        let ms = 1e6;
        let ns: Vec<f64> =
            [0.0, 1.0, 1.5, 2.0, 3.0, 4.0, 4.5, 9.0, 10.0, 11.0, 11.0, 20.0].iter().map(|t| t * ms).collect();
        let (frame, per_pass) = split_frame(&passes, &ns);
        // Spans: maps 0..2, tile 3..9, tile 10..20.
        assert_eq!(frame, 2.0 + 6.0 + 10.0);
        assert_eq!(per_pass, [("shadow maps", 1.5), ("raster", 2.0), ("wave", 4.5 + 9.0)]);
        assert!(per_pass.iter().map(|p| p.1).sum::<f64>() <= frame);
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(median(&[]), 0.0);
    }
}
