//! Drawing a frame into a window: [`crate::GpuBackend::render_to_texture`] draws every tile as for
//! a read-back (raster, plane shadows, soft-shadow gather, wave), then the present pass
//! (`passes/present.rs`) copies each tile's colour into one full-frame texture. Nothing here waits
//! for the GPU: the tiles are submitted and the texture's view returned; a window drawing the
//! texture on the same queue sees the finished frame, as queue order guarantees. With timestamp
//! queries each such frame's passes are timed without waiting (`timing::PresentTimer`). A frame
//! with a `[bloom]` draws its glare after the tiles of each band, then presents the band's
//! mapped colour: no read-back either, on the web too.

use crate::layout::FrameUniforms;
use crate::passes::present::{PresentedFrame, Presenter};
use crate::render::{Renderer, TileOutput};
use crate::texture_read::TextureRead;
use crate::timing::{PresentTiming, PRESENT_PASSES_PER_TILE};
use hadou_scene::{Frame, RenderError};

impl Renderer {
    /// See [`crate::GpuBackend::render_to_texture`]. On a device with `TIMESTAMP_QUERY`, a frame
    /// without an `[area_light]` writes timestamps at every pass (the shadow maps, then per tile
    /// its passes and the present pass), resolved and copied into a staging buffer that is mapped
    /// asynchronously ([`crate::timing::PresentTimer`]): see [`Renderer::last_present_timing`]. Frames with an
    /// `[area_light]` are not timed (their whole-image soft-shadow passes run before the tiles,
    /// in the frame's preparation), nor is a frame finding every staging buffer still in flight.
    pub(crate) fn render_to_texture(&mut self, frame: &Frame) -> Result<PresentedFrame<'_>, RenderError> {
        let size = [frame.width, frame.height];
        let max = self.ctx.limits.max_texture_dimension_2d;
        if size[0] > max || size[1] > max {
            return Err(RenderError::Device(format!(
                "a {}×{} frame does not fit this device's largest texture ({max}²) for drawing to a window",
                size[0], size[1]
            )));
        }
        if self.present.is_none() {
            self.present = Some(Presenter::new(&self.ctx)?);
        }
        if frame.bloom.is_some() {
            return self.render_glare_to_texture(frame);
        }
        let timed = self.present.as_ref().is_some_and(|p| p.timer.is_some()) && frame.area_light.is_none();
        // When timed, the shadow maps are submitted below, with their timestamps.
        let prepared = self.prepare_frame(frame, 0..frame.height, !timed, TileOutput::Floats)?;
        let present = self.present.as_mut().expect("made above");
        present.serial += 1;
        let serial = present.serial;
        let recreated = self
            .ctx
            .scoped("creating the window texture", || present.ensure_target(&self.ctx.device, size))?;
        let queries = 2 * (PRESENT_PASSES_PER_TILE * prepared.tiles.len() as u32 + prepared.map_pass_count());
        let timed_frame = match present.timer.as_mut().filter(|_| timed) {
            Some(timer) => {
                self.ctx.scoped("creating timestamp queries", || timer.begin(&self.ctx.device, queries))?
            }
            None => None,
        };
        let present = self.present.as_ref().expect("made above");
        let target = present.target.as_ref().expect("made above");
        let tiles = self.targets.as_ref().expect("targets are created in prepare");
        let queries = self.ctx.scoped("drawing the frame into the window texture", || {
            let mut q = timed_frame.as_ref().map(|f| f.queries());
            if timed {
                self.submit_shadow_maps(frame, &prepared, q.as_mut());
            }
            let bind_group = present.pass.bind_group(&self.ctx.device, &tiles.uniforms, &tiles.output);
            for &tile in &prepared.tiles {
                // Writes the tile's uniforms, which the present pass reads too (tile origin and
                // size); submitted before the next tile rewrites them.
                let mut encoders = self.encode_tile(frame, &prepared, tile, false, q.as_mut());
                // In the tile's group of queries: its span ends with this pass.
                let timestamps = q.as_mut().and_then(|q| q.render("present"));
                let pixels = prepared.output_tile(tile);
                present.pass.encode(&mut encoders.shading, &target.view, pixels, &bind_group, timestamps);
                self.submit_tile(encoders)?;
            }
            Ok(q)
        })??;
        if let (Some(f), Some(q)) = (&timed_frame, queries) {
            let (ctx, present) = (&self.ctx, self.present.as_mut().expect("made above"));
            if let Some(timer) = present.timer.as_mut() {
                ctx.scoped("reading the frame's timestamps back", || {
                    timer.finish(&ctx.device, &ctx.queue, f, q, serial)
                })?;
            }
        }
        let target = self.present.as_ref().and_then(|p| p.target.as_ref()).expect("made above");
        Ok(PresentedFrame { texture: &target.texture, view: &target.view, size, recreated, serial })
    }

    /// [`Renderer::render_to_texture`] of a frame with a `[bloom]`: the glare spreads light across
    /// tiles, so it runs once the tiles of a band (and its halo) are drawn. Per band
    /// ([`Renderer::glare_bands`]) the tiles' linear colour is gathered and the glare chain run
    /// ([`Renderer::glare_chain`], as `render_rows` does), and the present pass copies the band's
    /// mapped colour into the texture as it copies a tile's: nothing is read back or waited for,
    /// so it runs on the web too.
    fn render_glare_to_texture(&mut self, frame: &Frame) -> Result<PresentedFrame<'_>, RenderError> {
        let params = frame.bloom.expect("a frame with a [bloom]");
        let size = [frame.width, frame.height];
        let present = self.present.as_mut().expect("made by the caller");
        present.serial += 1;
        let serial = present.serial;
        let recreated = self
            .ctx
            .scoped("creating the window texture", || present.ensure_target(&self.ctx.device, size))?;
        for band in self.glare_bands(frame, &params, 0..frame.height)? {
            let (out, encoder, _) = self.glare_chain(frame, &params, band.clone(), |_, _, _, _| Ok(()))?;
            // The present pass reads the tile's place from the uniforms: the band, in image pixels.
            let mut u: FrameUniforms = bytemuck::Zeroable::zeroed();
            u.grid = hadou_scene::SampleGrid::SINGLE.edge();
            u.tile_origin = [0, band.start as u32];
            u.tile_size = [frame.width, band.len() as u32];
            let d = &self.ctx.device;
            let uniforms = d.create_buffer(&wgpu::BufferDescriptor {
                label: Some("glare present uniforms"),
                size: std::mem::size_of::<FrameUniforms>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            self.ctx.queue.write_buffer(&uniforms, 0, bytemuck::bytes_of(&u));
            let present = self.present.as_ref().expect("made by the caller");
            let target = present.target.as_ref().expect("made above");
            // The glare's compute passes and the present pass that reads their output go in
            // separate submissions, on OpenGL with a fence wait between them, as a tile's passes
            // do (`Renderer::submit_tile`).
            let glare = self.ctx.scoped("drawing the glare", || self.ctx.queue.submit([encoder.finish()]))?;
            #[cfg(not(target_arch = "wasm32"))]
            if self.ctx.info.backend == wgpu::Backend::Gl {
                self.ctx.wait(glare)?;
            }
            #[cfg(target_arch = "wasm32")]
            let _ = glare;
            self.ctx.scoped("drawing the glare into the window texture", || {
                let mut encoder = d
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("glare present") });
                let bind_group = present.pass.bind_group(d, &uniforms, &out);
                let rect = ([0, band.start as u32], [frame.width, band.len() as u32]);
                present.pass.encode(&mut encoder, &target.view, rect, &bind_group, None);
                self.ctx.queue.submit([encoder.finish()]);
            })?;
        }
        let target = self.present.as_ref().and_then(|p| p.target.as_ref()).expect("made above");
        Ok(PresentedFrame { texture: &target.texture, view: &target.view, size, recreated, serial })
    }

    /// See [`crate::GpuBackend::read_presented`].
    pub(crate) fn read_presented(&self) -> Option<TextureRead> {
        let target = self.present.as_ref()?.target.as_ref()?;
        let size = [target.texture.width(), target.texture.height()];
        Some(TextureRead::start(&self.ctx.device, &self.ctx.queue, &target.texture, size))
    }

    /// See [`crate::GpuBackend::last_present_timing`].
    pub(crate) fn last_present_timing(&mut self) -> Option<PresentTiming> {
        let timer = self.present.as_mut()?.timer.as_mut()?;
        timer.latest(&self.ctx.device)
    }
}
