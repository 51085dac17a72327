//! The glare's orchestration (`[bloom]`): a frame's rows cut into bands whose rows and halo fit one
//! storage binding, each band's tiles drawn with the linear colour into one buffer, then the
//! glare chain (passes/bloom.rs) and the band's read-back.

#[cfg(not(target_arch = "wasm32"))]
use super::{alloc_image, copy_tile, FLOATS_PER_PIXEL};
use super::{Renderer, TileOutput};
use crate::passes::bloom::{self, BloomInputs, BloomPass};
#[cfg(not(target_arch = "wasm32"))]
use hadou_scene::Image;
use hadou_scene::{BloomParams, Frame, RenderError};

impl Renderer {
    /// [`Renderer::render_rows`] of a frame with a `[bloom]` (`rows` non-empty): in bands whose
    /// rows and halo fit one storage binding, the tiles of the band and its halo drawn with the
    /// linear colour gathered into one buffer, then the glare pass and the read-back of the band's
    /// mapped colour.
    #[cfg(not(target_arch = "wasm32"))]
    pub(super) fn render_rows_glare(
        &mut self,
        frame: &Frame,
        params: &BloomParams,
        rows: std::ops::Range<u32>,
    ) -> Result<Image, RenderError> {
        let mut image = alloc_image(frame.width, rows.len() as u32)?;
        for band in self.glare_bands(frame, params, rows.clone())? {
            let part = self.glare_band(frame, params, band.clone())?;
            let w = frame.width as usize;
            let at = (band.start - rows.start as usize) * w;
            image.color[at..at + part.color.len()].copy_from_slice(&part.color);
            image.energy[at..at + part.energy.len()].copy_from_slice(&part.energy);
            image.depth[at..at + part.depth.len()].copy_from_slice(&part.depth);
        }
        Ok(image)
    }

    /// `rows` cut into the longest bands whose rows and glare halo fit one storage binding.
    pub(crate) fn glare_bands(
        &self,
        frame: &Frame,
        params: &BloomParams,
        rows: std::ops::Range<u32>,
    ) -> Result<Vec<std::ops::Range<usize>>, RenderError> {
        let limit = self.ctx.limits.max_storage_buffer_binding_size.min(self.ctx.limits.max_buffer_size);
        let mut bands = Vec::new();
        let mut y = rows.start as usize;
        while y < rows.end as usize {
            // The longest band from y whose source rows fit.
            let mut len = rows.end as usize - y;
            while BloomPass::largest_plane(params, frame.width, frame.height, y..y + len) > limit {
                if len == 1 {
                    // The most levels (the widest reach) whose halo fits, as a radius.
                    let (w, h) = (frame.width as usize, frame.height as usize);
                    let fits = (1..=hadou_math::bloom::MAX_LEVELS).rev().find(|&n| {
                        // The middle row: its halo is clamped by neither edge.
                        let rows = hadou_math::bloom::Plan::new(w, h, n, h / 2..h / 2 + 1).source.len();
                        (rows * w) as u64 * bloom::TEXEL_BYTES <= limit
                    });
                    let hint = match fits {
                        Some(n) => {
                            format!("a `radius` of at most {:.4} fits", f64::from(1u32 << n) / h as f64)
                        }
                        None => "no radius fits".to_owned(),
                    };
                    return Err(RenderError::Other(format!(
                        "the [bloom] of a {}×{} image needs more than this device's {limit}-byte storage \
                         binding for one row and its glare halo ({} bytes); {hint} at this size, or `--backend cpu`",
                        frame.width,
                        frame.height,
                        BloomPass::largest_plane(params, frame.width, frame.height, y..y + 1)
                    )));
                }
                len = len.div_ceil(2);
            }
            bands.push(y..y + len);
            y += len;
        }
        Ok(bands)
    }

    /// One band of [`Renderer::render_rows_glare`], read back.
    #[cfg(not(target_arch = "wasm32"))]
    fn glare_band(
        &mut self,
        frame: &Frame,
        params: &BloomParams,
        band: std::ops::Range<usize>,
    ) -> Result<Image, RenderError> {
        let (w, h) = (frame.width as usize, frame.height as usize);
        let src = hadou_math::bloom::source_rows(params, w, h, band.clone());
        let mut image = alloc_image(frame.width, src.len() as u32)?;
        // Each tile read back after its submission (its energy and depth; the colour comes from
        // the glare).
        let (out, mut encoder, _) =
            self.glare_chain(frame, params, band.clone(), |r, submission, origin, size| {
                let origin = [origin[0], origin[1] - src.start as u32];
                let bytes = u64::from(size[0]) * u64::from(size[1]) * FLOATS_PER_PIXEL * 4;
                let staging = &r.targets.as_ref().expect("targets exist").staging;
                r.ctx.read_buffer(staging, bytes, submission, |raw| copy_tile(&mut image, raw, origin, size))
            })?;
        let bytes = (band.len() * w) as u64 * bloom::TEXEL_BYTES;
        let staging = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("bloom read-back"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let submission = self.ctx.scoped("drawing the bloom", || {
            encoder.copy_buffer_to_buffer(&out, 0, &staging, 0, bytes);
            self.ctx.queue.submit([encoder.finish()])
        })?;
        let first = (band.start - src.start) * w;
        self.ctx.read_buffer(&staging, bytes, submission, |raw| {
            let mut floats = vec![0.0f32; raw.len() / 4];
            for (f, c) in floats.iter_mut().zip(raw.chunks_exact(4)) {
                *f = f32::from_ne_bytes([c[0], c[1], c[2], c[3]]);
            }
            for (px, c) in image.color[first..first + band.len() * w].iter_mut().zip(floats.chunks_exact(4)) {
                px.copy_from_slice(c);
            }
        })?;
        Ok(image.crop_rows((band.start - src.start) as u32..(band.end - src.start) as u32))
    }

    /// The linear colour of every band of a frame with a `[bloom]` ([`Renderer::glare_bands`]),
    /// drawn once as `render_rows` draws it (tiles and glare chain, waited for), for
    /// [`crate::GpuBackend::time_frame`] to run the glare chain on again in each timed frame.
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn glare_sources(&mut self, frame: &Frame) -> Result<Vec<GlareSource>, RenderError> {
        let Some(params) = frame.bloom else { return Ok(Vec::new()) };
        let (w, h) = (frame.width as usize, frame.height as usize);
        let mut sources = Vec::new();
        for band in self.glare_bands(frame, &params, 0..frame.height)? {
            let (_, encoder, linear) = self.glare_chain(frame, &params, band.clone(), |_, _, _, _| Ok(()))?;
            let submission =
                self.ctx.scoped("drawing the bloom", || self.ctx.queue.submit([encoder.finish()]))?;
            self.ctx.wait(submission)?;
            let source = hadou_math::bloom::source_rows(&params, w, h, band.clone());
            sources.push(GlareSource { linear, source, band });
        }
        Ok(sources)
    }

    /// The glare chain of every band of `sources` (from [`Renderer::glare_sources`]) submitted,
    /// each band's compute pass its own group of `timestamps` named `"bloom"`. Returns the last
    /// submission (`None` when there is none).
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn submit_glare(
        &self,
        frame: &Frame,
        sources: &[GlareSource],
        mut timestamps: Option<&mut crate::timing::PassQueries<'_>>,
    ) -> Option<wgpu::SubmissionIndex> {
        let params = frame.bloom.as_ref()?;
        let mut last = None;
        for s in sources {
            let d = &self.ctx.device;
            let mut encoder =
                d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("bloom") });
            let inputs = BloomInputs {
                params,
                tone: frame.color_mapping.mode,
                width: frame.width,
                height: frame.height,
                linear: &s.linear,
                source: s.source.clone(),
                band: s.band.clone(),
            };
            let writes = timestamps.as_deref_mut().and_then(|q| {
                q.next_group();
                q.compute("bloom")
            });
            self.passes.bloom.encode(d, &mut encoder, &inputs, writes);
            last = Some(self.ctx.queue.submit([encoder.finish()]));
        }
        last
    }

    /// The glare of the rows `band`: the tiles of its source rows (the band and its halo) drawn
    /// with the linear colour, each tile's colour gathered into one buffer (`after_tile` runs after
    /// each tile's submission, with its origin and size in image pixels), then the glare chain
    /// recorded into a new encoder, not yet submitted. Returns the band's mapped colour (4
    /// floats a pixel, row-major over the band), that encoder and the band's linear colour (its
    /// source rows, which [`crate::GpuBackend::time_frame`] runs the chain on again).
    pub(crate) fn glare_chain(
        &mut self,
        frame: &Frame,
        params: &BloomParams,
        band: std::ops::Range<usize>,
        mut after_tile: impl FnMut(&Self, wgpu::SubmissionIndex, [u32; 2], [u32; 2]) -> Result<(), RenderError>,
    ) -> Result<(wgpu::Buffer, wgpu::CommandEncoder, wgpu::Buffer), RenderError> {
        let (w, h) = (frame.width as usize, frame.height as usize);
        let src = hadou_math::bloom::source_rows(params, w, h, band.clone());
        let mut prepared =
            self.prepare_frame(frame, src.start as u32..src.end as u32, true, TileOutput::Floats)?;
        prepared.linear = true;
        let linear = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("bloom linear colour"),
            size: (src.len() * w) as u64 * bloom::TEXEL_BYTES,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        for &tile in &prepared.tiles {
            let (origin, size) = prepared.output_tile(tile);
            let submission = self.ctx.scoped("rendering a tile", || {
                let mut encoders = self.encode_tile(frame, &prepared, tile, true, None);
                // The tile's colour rows into the band's linear colour.
                let t = self.targets.as_ref().expect("targets exist");
                let row_bytes = u64::from(size[0]) * bloom::TEXEL_BYTES;
                for r in 0..u64::from(size[1]) {
                    let dst = ((u64::from(origin[1]) + r - src.start as u64) * w as u64
                        + u64::from(origin[0]))
                        * bloom::TEXEL_BYTES;
                    encoders.shading.copy_buffer_to_buffer(&t.output, r * row_bytes, &linear, dst, row_bytes);
                }
                self.submit_tile(encoders)
            })??;
            after_tile(self, submission, origin, size)?;
        }
        let d = &self.ctx.device;
        let mut encoder = d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("bloom") });
        let inputs = BloomInputs {
            params,
            tone: frame.color_mapping.mode,
            width: frame.width,
            height: frame.height,
            linear: &linear,
            source: src.clone(),
            band: band.clone(),
        };
        let out = self
            .ctx
            .scoped("recording the bloom", || self.passes.bloom.encode(d, &mut encoder, &inputs, None))?;
        Ok((out, encoder, linear))
    }
}

/// One band's linear colour for timing the glare ([`Renderer::glare_sources`]).
#[cfg(not(target_arch = "wasm32"))]
pub(crate) struct GlareSource {
    /// The linear colour of the rows `source`.
    linear: wgpu::Buffer,
    source: std::ops::Range<usize>,
    band: std::ops::Range<usize>,
}
