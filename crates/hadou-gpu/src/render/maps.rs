//! The shadow maps' orchestration: every map cast's casters into its layer (passes/shadow_maps.rs),
//! once per frame before the tiles, or into a caller's texture.

use super::{map_passes, Prepared, Renderer};
use crate::passes::shadow_maps::ShadowMapInputs;
use crate::prepare::{self, FrameBuffers, FrameData};
use crate::timing::PassQueries;
use hadou_scene::{Frame, RenderError};

impl Renderer {
    /// Records every map cast's casters into its layer of the shadow maps (nothing when the frame
    /// has no map casts), one render pass per layer.
    pub(crate) fn encode_shadow_maps(
        &self,
        enc: &mut wgpu::CommandEncoder,
        frame: &Frame,
        prepared: &Prepared,
        timestamps: Option<&mut PassQueries<'_>>,
    ) {
        let Some(bind_group) = &prepared.map_bind_group else { return };
        let maps = self.maps.as_ref().expect("shadow maps are created in prepare");
        let passes = &prepared.map_passes;
        let views = &maps.layer_views;
        self.passes.shadow_maps.encode(enc, views, passes, bind_group, &self.meshes, frame, timestamps);
    }

    /// Records `frame`'s shadow maps into the layers of the caller's `target` (see
    /// `GpuBackend::encode_shadow_maps_into`).
    pub(crate) fn encode_shadow_maps_into(
        &mut self,
        frame: &Frame,
        enc: &mut wgpu::CommandEncoder,
        target: &wgpu::Texture,
    ) -> Result<(), RenderError> {
        self.ctx.check()?;
        prepare::validate_frame(frame)?;
        let data = FrameData::new(&self.ctx.limits, frame)?;
        let shadows = &data.shadows;
        if shadows.map_casts.is_empty() {
            return Ok(());
        }
        let size = target.size();
        if target.format() != crate::formats::MAP_FORMAT
            || size.width < shadows.map_size
            || size.height < shadows.map_size
            || size.depth_or_array_layers < shadows.map_casts.len() as u32
            || !target.usage().contains(wgpu::TextureUsages::RENDER_ATTACHMENT)
        {
            return Err(RenderError::Other(format!(
                "the shadow-map target must be Depth32Float with RENDER_ATTACHMENT, at least {0}×{0} texels and \
                 {1} layers (it is {2:?}, {3}×{4}×{5})",
                shadows.map_size,
                shadows.map_casts.len(),
                target.format(),
                size.width,
                size.height,
                size.depth_or_array_layers
            )));
        }
        let scopes = self.ctx.open_scopes();
        {
            self.meshes.upload(&self.ctx.device, frame);
            let d = &self.ctx.device;
            let buffers = FrameBuffers::upload(d, &data);
            let passes = map_passes(&data);
            let inputs = ShadowMapInputs {
                objects: &buffers.objects,
                casts: &buffers.casts,
                draws: &buffers.shadow_draws,
            };
            let bind_group = self.passes.shadow_maps.bind_group(d, &inputs);
            let views = crate::passes::shadow_maps::layer_views(target, shadows.map_casts.len() as u32);
            self.passes.shadow_maps.encode(enc, &views, &passes, &bind_group, &self.meshes, frame, None);
        }
        self.ctx.close_scopes(scopes, "drawing the shadow maps")
    }

    /// Submits the frame's shadow maps (see [`Renderer::encode_shadow_maps`]); `None` when it has
    /// none.
    pub(crate) fn submit_shadow_maps(
        &self,
        frame: &Frame,
        prepared: &Prepared,
        timestamps: Option<&mut PassQueries<'_>>,
    ) -> Option<wgpu::SubmissionIndex> {
        prepared.map_bind_group.as_ref()?;
        let mut enc = self
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("shadow maps") });
        self.encode_shadow_maps(&mut enc, frame, prepared, timestamps);
        Some(self.ctx.queue.submit([enc.finish()]))
    }
}
