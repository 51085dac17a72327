//! The `[area_light]`'s orchestration: every tile rasterized for its visible points, the two maps
//! fitted (on the GPU) and drawn, the classes and the resolve (passes/soft.rs), once per frame before the tiles.

use super::{Prepared, Renderer, TileWork};
use crate::passes::setup::Draw;
#[cfg(not(target_arch = "wasm32"))]
use crate::passes::soft::SoftReadback;
use hadou_scene::{Frame, RenderError};

impl Renderer {
    /// The `[area_light]`'s soft shadows over the whole image: every tile rasterized and its points
    /// gathered, the two maps fitted to them and drawn, the classes, then the resolve; the wave
    /// passes read the visibility.
    pub(super) fn draw_soft(&self, frame: &Frame, prepared: &Prepared) -> Result<(), RenderError> {
        let soft = self.soft.as_ref().expect("created in prepare");
        let groups = prepared.groups.as_ref().expect("bind groups are made in prepare");
        let bind_group = groups.soft.as_ref().expect("made with an area light");
        let d = &self.ctx.device;
        // Only the area light's casters are drawn into its maps (hadou-cpu's `spot_tris`).
        let casters = frame.area_light.as_ref().map_or(&[][..], |l| &l.casters[..]);
        let caster_draws: Vec<Draw> =
            prepared.draws.iter().copied().filter(|dr| casters.contains(&(dr.object as u32))).collect();
        // Every tile of the image, whatever rows are asked for: the search needs them all.
        let tile = prepared.tile;
        for y in (0..frame.height).step_by(tile[1] as usize) {
            for x in (0..frame.width).step_by(tile[0] as usize) {
                let t = ([x, y], [tile[0].min(frame.width - x), tile[1].min(frame.height - y)]);
                let encoders = self.encode_tile_work(frame, prepared, t, TileWork::Classify, None);
                self.submit_tile(encoders)?;
            }
        }
        if let Some(hadou_scene::SoftResolve::Traced { .. }) = frame.area_light.as_ref().map(|l| l.resolve) {
            // No maps: the hierarchy says where a shadow edge can be.
            let uniforms = &self.targets.as_ref().expect("targets are created in prepare").uniforms;
            let mut enc =
                d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("soft traced") });
            self.passes.soft.encode_traced(&mut enc, d, soft, uniforms, frame);
            self.ctx.queue.submit([enc.finish()]);
            return Ok(());
        }
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("soft maps") });
        self.passes.soft.encode_fit(&mut enc, bind_group, soft);
        let objects = &prepared.buffers.objects;
        self.passes.soft.encode_maps(&mut enc, d, soft, objects, &self.meshes, frame, &caster_draws);
        self.passes.soft.encode_class(&mut enc, bind_group, frame);
        self.passes.soft.encode_resolve(&mut enc, bind_group, frame);
        self.ctx.queue.submit([enc.finish()]);
        Ok(())
    }

    /// After [`Renderer::render`] of a frame with an `[area_light]`: every pixel's soft-shadow
    /// class (`hadou_math::soft::Class` as `u8`) and visibility, read back (for tests).
    #[cfg(not(target_arch = "wasm32"))]
    pub(crate) fn read_soft(&self, frame: &Frame) -> Result<Option<SoftReadback>, RenderError> {
        let Some(soft) = self.soft.as_ref().filter(|_| frame.area_light.is_some()) else { return Ok(None) };
        soft.read(&self.ctx, frame).map(Some)
    }
}
