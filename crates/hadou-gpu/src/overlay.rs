//! [`crate::GpuBackend::encode_wave_overlay`]: a frame's waves drawn by the wave overlay pass
//! (`passes/wave_overlay.rs`) into a colour target and against a depth buffer that the caller
//! owns, recorded into the caller's command encoder. The frame's objects, materials and shadows
//! are not drawn: the caller's renderer draws its own scene and hadou adds the waves' light to it.

use crate::layout::{
    self, FrameUniforms, GpuWave, OverlayUniforms, DEPTH_REVERSE_INFINITE, DEPTH_STANDARD,
    PROJECTION_ORTHOGRAPHIC, PROJECTION_PERSPECTIVE,
};
use crate::passes::wave::WaveVariant;
use crate::passes::wave_overlay::{OverlayInputs, WaveOverlayPass};
use crate::prepare::{self, check_curves, or_zeroed, upload_curves};
use crate::render::Renderer;
use bytemuck::Zeroable;
use hadou_scene::{Frame, RenderError};
use wgpu::util::DeviceExt;

/// How the values of a caller's depth buffer map to distance from the camera, for
/// [`crate::GpuBackend::encode_wave_overlay`]. The near and far planes are the frame camera's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthModel {
    /// Perspective depth 0 at the near plane, 1 at the far plane, cleared to 1 (hadou's own
    /// raster pass, and most renderers).
    Standard,
    /// Reverse-Z with an infinite far plane: depth `near / z`, 1 at the near plane, cleared to 0
    /// (Bevy's 3-D cameras).
    ReverseInfinite,
}

/// How the overlay's light meets what the colour target holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OverlayBlend {
    /// Added to the target's colour, alpha kept: the waves' light on the caller's linear image
    /// (which needs a blendable format, e.g. `Rgba16Float`).
    Add,
    /// Written over the target's colour, alpha 0: the light alone.
    Replace,
}

/// The rays the overlay integrates along, one per pixel (002 §3.3.3, eq. 3.12–3.13, with the
/// frame camera's `far` as the far plane's distance in both).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OverlayProjection {
    /// From the frame camera's eye through each pixel (`CameraBasis::wave_ray`); the depth buffer
    /// is read by its [`DepthModel`].
    Perspective,
    /// Parallel rays along the frame camera's forward axis (an orthographic view), each starting
    /// at its pixel's point on the view's near plane: `centre + right·ndc_x + up·ndc_y` for the
    /// pixel centre's normalised device coordinates (x right, y up, −1..1 over the frame). The
    /// span and the far point are those of `CameraBasis::wave_ray` for the direction `forward`
    /// (|dir| = 1): the faithful falloff's `t ∈ [0, g]` along `forward·far`, the inverse square's
    /// `t ∈ [0, d]`. The depth buffer runs linearly over `depth_span` from the near plane:
    /// [`DepthModel::Standard`] 0 at the near plane and 1 at the far (cleared to 1),
    /// [`DepthModel::ReverseInfinite`] read as reverse-Z, 1 at the near plane and 0 at the far
    /// (cleared to 0: Bevy's orthographic projection).
    Orthographic {
        /// The world point on the near plane at the frame's centre.
        centre: [f32; 3],
        /// The world vector from `centre` to the near plane's point at NDC x = +1.
        right: [f32; 3],
        /// The world vector from `centre` to the near plane's point at NDC y = +1.
        up: [f32; 3],
        /// The distance from the near plane to the far plane of the depth buffer's range.
        depth_span: f32,
    },
}

/// Where [`crate::GpuBackend::encode_wave_overlay`] draws: views the caller owns, at least the
/// frame's `width × height`, pixel (x, y) of the frame at texel (x, y).
#[derive(Clone, Copy, Debug)]
pub struct OverlayTarget<'a> {
    /// The colour target (a render attachment of `color_format`).
    pub color: &'a wgpu::TextureView,
    /// Its format (the pipeline is built for it).
    pub color_format: wgpu::TextureFormat,
    /// The depth buffer the waves are clipped against (a depth texture view with
    /// `TEXTURE_BINDING`, e.g. `Depth32Float`), read as the frame's camera saw it.
    pub depth: &'a wgpu::TextureView,
    /// How to read `depth`.
    pub depth_model: DepthModel,
    /// Samples per pixel of `depth`: 1, or an MSAA engine's count (its first sample is read; the
    /// colour target is then the resolved, single-sample image).
    pub depth_samples: u32,
    /// How to meet `color`'s contents.
    pub blend: OverlayBlend,
    /// The pixel of `color` and `depth` where the frame's pixel (0, 0) is drawn: `[0, 0]` for a
    /// frame the target's size, a viewport's corner otherwise (split screen, picture in picture).
    /// The frame's `width × height` from there must lie inside both textures.
    pub origin: [u32; 2],
    /// The rays: the frame camera's perspective, or an orthographic view's parallel rays.
    pub projection: OverlayProjection,
}

impl Renderer {
    /// See [`crate::GpuBackend::encode_wave_overlay`].
    pub(crate) fn encode_wave_overlay(
        &mut self,
        frame: &Frame,
        enc: &mut wgpu::CommandEncoder,
        target: &OverlayTarget<'_>,
    ) -> Result<(), RenderError> {
        self.check_overlay(frame, target)?;
        let prepared = layout::frame_waves(frame).map_err(RenderError::Other)?;
        self.encode_prepared_wave_overlay(frame, &prepared, enc, target)
    }

    /// What both overlay entries refuse: a lost device, an invalid frame, a multisampled depth
    /// buffer on OpenGL.
    fn check_overlay(&self, frame: &Frame, target: &OverlayTarget<'_>) -> Result<(), RenderError> {
        self.ctx.check()?;
        prepare::validate_frame(frame)?;
        if target.depth_samples > 1 && self.ctx.info.backend == wgpu::Backend::Gl {
            // OpenGL reads a multisampled depth texture as if nothing were drawn (tests/overlay.rs):
            // wgpu's GL backend creates a sampled multisampled texture with the target
            // GL_TEXTURE_2D, so glTexStorage2DMultisample fails (GL_INVALID_ENUM, in its debug
            // log) and the texture has no storage. Refused rather than drawn through the caller's
            // surfaces.
            return Err(RenderError::Other(format!(
                "the wave overlay cannot read a multisampled depth buffer ({} samples) on OpenGL; \
                 draw the view without MSAA",
                target.depth_samples
            )));
        }
        if let OverlayProjection::Orthographic { centre, right, up, depth_span } = target.projection {
            let finite = centre.iter().chain(&right).chain(&up).all(|c| c.is_finite());
            if !(finite && depth_span.is_finite() && depth_span > 0.0) {
                return Err(RenderError::Other(format!(
                    "the wave overlay's orthographic projection must be finite with depth_span > 0, got \
                     centre {centre:?}, right {right:?}, up {up:?}, depth_span {depth_span}"
                )));
            }
        }
        Ok(())
    }

    /// See [`crate::GpuBackend::encode_prepared_wave_overlay`].
    pub(crate) fn encode_prepared_wave_overlay(
        &mut self,
        frame: &Frame,
        prepared: &layout::FrameWaves,
        enc: &mut wgpu::CommandEncoder,
        target: &OverlayTarget<'_>,
    ) -> Result<(), RenderError> {
        self.check_overlay(frame, target)?;
        let (waves, curves, curve_of) = prepared;
        if curve_of.len() != frame.waves.len() {
            return Err(RenderError::Other(format!(
                "the prepared waves are of {} waves, the frame has {}",
                curve_of.len(),
                frame.waves.len()
            )));
        }
        check_curves(&self.ctx.limits, curves)?;
        let faithful = frame.color_mapping.mode == hadou_scene::ToneMode::Faithful;
        let variant = if self.passes.wave.specialise {
            WaveVariant::of(
                waves,
                &curves.curves,
                &[],
                &[],
                false,
                false,
                (false, false),
                false,
                faithful,
                frame.color_mapping.exposure,
                false,
            )
        } else {
            WaveVariant::UBER
        };
        if self.overlay.is_none() {
            self.overlay = Some(WaveOverlayPass::new());
        }
        let pass = self.overlay.as_mut().expect("made above");
        let additive = target.blend == OverlayBlend::Add;
        let multisampled = target.depth_samples > 1;
        let (pipeline, layout) =
            pass.pipeline(&self.ctx, variant, target.color_format, additive, multisampled)?;
        let pass = self.overlay.as_ref().expect("made above");
        let (ctx, size) = (&self.ctx, [frame.width, frame.height]);
        ctx.scoped("encoding the wave overlay", || {
            let d = &ctx.device;
            let basis = frame.camera.basis(frame.width, frame.height);
            let uniform = |label: &str, contents: &[u8]| {
                d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage: wgpu::BufferUsages::UNIFORM,
                })
            };
            let frame_uniforms =
                FrameUniforms::new(frame, &basis, [0, 0], size, hadou_scene::SampleGrid::SINGLE);
            let uniforms = uniform("overlay frame", bytemuck::bytes_of(&frame_uniforms));
            let depth_model = match target.depth_model {
                DepthModel::Standard => DEPTH_STANDARD,
                DepthModel::ReverseInfinite => DEPTH_REVERSE_INFINITE,
            };
            let v4 = |v: [f32; 3]| [v[0], v[1], v[2], 0.0];
            let (projection, centre, right, up, depth_span) = match target.projection {
                OverlayProjection::Perspective => (PROJECTION_PERSPECTIVE, [0.0; 3], [0.0; 3], [0.0; 3], 0.0),
                OverlayProjection::Orthographic { centre, right, up, depth_span } => {
                    (PROJECTION_ORTHOGRAPHIC, centre, right, up, depth_span)
                }
            };
            let model = OverlayUniforms {
                depth_model,
                near: frame.camera.near,
                far: frame.camera.far,
                projection,
                origin: target.origin,
                depth_span,
                _pad: 0,
                ortho_centre: v4(centre),
                ortho_right: v4(right),
                ortho_up: v4(up),
            };
            let overlay = uniform("overlay depth model", bytemuck::bytes_of(&model));
            let waves = prepare::storage(d, "overlay waves", or_zeroed(waves, &[GpuWave::zeroed()]));
            let curves = upload_curves(d, curves);
            let inputs = OverlayInputs {
                uniforms: &uniforms,
                waves: &waves,
                depth: target.depth,
                overlay: &overlay,
                curves: [&curves[0], &curves[1], &curves[2]],
            };
            let bind_group = pass.bind_group(d, &layout, &inputs, multisampled);
            pass.encode(enc, &pipeline, target.color, target.origin, size, &bind_group);
        })
    }
}
