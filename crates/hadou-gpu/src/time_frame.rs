//! [`crate::GpuBackend::time_frame`]: the GPU time of a frame, from timestamps at every pass
//! boundary where the adapter has them (split by pass), else from the wall clock around waited-for
//! submissions. Not on the web.

use crate::render::{Renderer, TileOutput};
use crate::timing::{
    median, split_frame, FrameTiming, PassQueries, PassTime, TimingMethod, PASSES_PER_TILE, SOFT_PREPARATION,
    SOFT_TILES,
};
use hadou_scene::{Frame, RenderError};
use std::time::Instant;

/// See [`crate::GpuBackend::time_frame`].
pub(crate) fn time_frame(
    r: &mut Renderer,
    frame: &Frame,
    iterations: u32,
) -> Result<FrameTiming, RenderError> {
    if iterations == 0 {
        return Err(RenderError::Other("time_frame needs at least one iteration".into()));
    }
    // As `hadou render` draws a PNG's pixels: the wave pass writes their 8-bit sRGB codes (a frame
    // with a `[bloom]` writes the float colour its glare reads, and the glare chain runs after the
    // tiles on each band's linear colour, drawn once here: the pass "bloom").
    let output = if frame.bloom.is_some() { TileOutput::Floats } else { TileOutput::Srgb8 };
    let glare = r.glare_sources(frame)?;
    let prepared = r.prepare(frame, 0..frame.height, output)?;
    let tiles = prepared.tiles.len() as u32;
    // Warm-up: pipelines, caches and first-use costs stay out of the measurement.
    let last = r.ctx.scoped("warming up", || {
        let maps = r.submit_shadow_maps(frame, &prepared, None);
        r.submit_tiles(frame, &prepared, None)
            .map(|tiles| r.submit_glare(frame, &glare, None).or(tiles).or(maps))
    })??;
    if let Some(s) = last {
        r.ctx.wait(s)?;
    }

    let queries = 2 * (PASSES_PER_TILE * tiles + prepared.map_pass_count() + glare.len() as u32);
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
                label: Some("pass timestamps"),
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
        // Per pass name, its time in each iteration.
        let mut passes: Vec<(&'static str, Vec<f64>)> = Vec::new();
        for i in 0..iterations as usize {
            let mut q = PassQueries::new(&set, queries);
            let (last, used) = r.ctx.scoped("timing a frame", || {
                r.submit_shadow_maps(frame, &prepared, Some(&mut q));
                r.submit_tiles(frame, &prepared, Some(&mut q))?;
                r.submit_glare(frame, &glare, Some(&mut q));
                let used = q.used();
                let mut enc = r.ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("timestamp resolve"),
                });
                if used > 0 {
                    enc.resolve_query_set(&set, 0..used, &resolve, 0);
                    enc.copy_buffer_to_buffer(&resolve, 0, &read, 0, used as u64 * 8);
                }
                Ok::<_, RenderError>((r.ctx.queue.submit([enc.finish()]), used))
            })??;
            if used == 0 {
                break;
            }
            let ns = r.ctx.read_buffer(&read, used as u64 * 8, last, |raw| {
                raw.chunks_exact(8)
                    .map(|t| u64::from_ne_bytes(t.try_into().unwrap_or_default()) as f64 * period_ns)
                    .collect::<Vec<f64>>()
            })?;
            let (frame_ms, per_pass) = split_frame(&q.passes, &ns);
            samples.push(frame_ms);
            for (name, ms) in per_pass {
                match passes.iter_mut().find(|(n, _)| *n == name) {
                    Some(p) => p.1.push(ms),
                    None => {
                        // A pass missing from earlier iterations took no time there.
                        let mut v = vec![0.0; i];
                        v.push(ms);
                        passes.push((name, v));
                    }
                }
            }
            for (_, v) in passes.iter_mut() {
                v.resize(i + 1, 0.0);
            }
        }
        let mut timing = FrameTiming::from_samples(TimingMethod::GpuTimestamps, tiles, samples);
        timing.passes = passes
            .into_iter()
            .map(|(name, v)| PassTime { name: name.to_string(), median_ms: median(&v) })
            .collect();
        return Ok(timing);
    }
    if soft {
        let (mut preparation, mut drawing) = (Vec::new(), Vec::new());
        for _ in 0..iterations {
            let start = Instant::now();
            // `prepare` draws the shadow maps and the soft shadows; waiting for all it submitted
            // splits the frame in two.
            let prepared = r.prepare(frame, 0..frame.height, output)?;
            r.ctx.wait(r.ctx.queue.submit([]))?;
            let prepared_at = Instant::now();
            let last = r.ctx.scoped("timing a frame", || {
                r.submit_tiles(frame, &prepared, None)
                    .map(|tiles| r.submit_glare(frame, &glare, None).or(tiles))
            })??;
            if let Some(s) = last {
                r.ctx.wait(s)?;
            }
            samples.push(start.elapsed().as_secs_f64() * 1e3);
            preparation.push((prepared_at - start).as_secs_f64() * 1e3);
            drawing.push(prepared_at.elapsed().as_secs_f64() * 1e3);
        }
        let mut timing = FrameTiming::from_samples(TimingMethod::WallClock, tiles, samples);
        timing.passes = vec![
            PassTime { name: SOFT_PREPARATION.into(), median_ms: median(&preparation) },
            PassTime { name: SOFT_TILES.into(), median_ms: median(&drawing) },
        ];
        return Ok(timing);
    }
    for _ in 0..iterations {
        let start = Instant::now();
        let last = r.ctx.scoped("timing a frame", || {
            let maps = r.submit_shadow_maps(frame, &prepared, None);
            r.submit_tiles(frame, &prepared, None)
                .map(|tiles| r.submit_glare(frame, &glare, None).or(tiles).or(maps))
        })??;
        if let Some(s) = last {
            r.ctx.wait(s)?;
        }
        samples.push(start.elapsed().as_secs_f64() * 1e3);
    }
    Ok(FrameTiming::from_samples(TimingMethod::WallClock, tiles, samples))
}

/// See [`crate::GpuBackend::time_wave_overlay`].
pub(crate) fn time_wave_overlay(
    r: &mut Renderer,
    frame: &Frame,
    iterations: u32,
) -> Result<FrameTiming, RenderError> {
    use crate::overlay::{DepthModel, OverlayBlend, OverlayTarget};
    use crate::passes::setup::{cleared_depth, texture_view};
    use wgpu::TextureUsages;
    if iterations == 0 {
        return Err(RenderError::Other("time_wave_overlay needs at least one iteration".into()));
    }
    crate::prepare::validate_frame(frame)?;
    let size = [frame.width, frame.height];
    let (color, depth) = r.ctx.scoped("creating the overlay's targets", || {
        let d = &r.ctx.device;
        let color = texture_view(
            d,
            "overlay timing colour",
            size,
            OVERLAY_COLOR_FORMAT,
            TextureUsages::RENDER_ATTACHMENT,
        );
        let depth_usage = TextureUsages::RENDER_ATTACHMENT | TextureUsages::TEXTURE_BINDING;
        let depth =
            texture_view(d, "overlay timing depth", size, wgpu::TextureFormat::Depth32Float, depth_usage);
        (color, depth)
    })?;
    // The depth buffer as an engine's would be with nothing drawn: cleared to the far plane.
    let mut enc = r.ctx.device.create_command_encoder(&Default::default());
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("overlay timing depth clear"),
        color_attachments: &[],
        depth_stencil_attachment: cleared_depth(&depth, wgpu::StoreOp::Store),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    r.ctx.queue.submit([enc.finish()]);
    let target = OverlayTarget {
        color: &color,
        color_format: OVERLAY_COLOR_FORMAT,
        depth: &depth,
        depth_model: DepthModel::Standard,
        depth_samples: 1,
        blend: OverlayBlend::Add,
        origin: [0, 0],
        projection: crate::OverlayProjection::Perspective,
    };
    let once = |r: &mut Renderer| -> Result<f64, RenderError> {
        let start = Instant::now();
        let mut enc = r.ctx.device.create_command_encoder(&Default::default());
        r.encode_wave_overlay(frame, &mut enc, &target)?;
        let submission = r.ctx.queue.submit([enc.finish()]);
        r.ctx.wait(submission)?;
        Ok(start.elapsed().as_secs_f64() * 1e3)
    };
    // Warm-up: the pipeline and first-use costs stay out of the measurement.
    once(r)?;
    let samples = (0..iterations).map(|_| once(r)).collect::<Result<Vec<_>, _>>()?;
    Ok(FrameTiming::from_samples(TimingMethod::WallClock, 1, samples))
}

/// The colour format [`time_wave_overlay`] draws into: an engine's HDR target.
const OVERLAY_COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
