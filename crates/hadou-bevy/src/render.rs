//! The render-world half of [`crate::HadouPlugin`]: the waves extracted each frame, hadou-gpu's
//! backend opened on Bevy's own device, and the wave pass of every view with a
//! [`HadouCamera`], a system of Bevy's `Core3d` schedule after the main passes and before
//! post-processing (bloom, tone mapping), like Bevy's volumetric fog.

use crate::camera::{frame_view, HadouCamera};
use crate::wave::DrawnWaves;
use bevy::prelude::*;
use bevy::render::renderer::{RenderAdapter, RenderContext, RenderDevice, RenderQueue, ViewQuery};
use bevy::render::view::{ExtractedView, Msaa, ViewDepthTexture, ViewTarget};
use bevy::render::Extract;
use hadou_gpu::{DepthModel, GpuBackend, OverlayBlend, OverlayTarget};
use hadou_math::Vec3f;
use hadou_scene::{ColorMapping, Frame, Light, ToneMode, Wave};
use std::collections::HashSet;

/// The main world's [`DrawnWaves`] (the waves and their prepared records, shared, not copied),
/// in the render world every frame.
#[derive(Resource, Default)]
pub(crate) struct ExtractedWaves(pub DrawnWaves);

/// hadou-gpu's backend on Bevy's `RenderDevice` (absent when the adapter cannot run it; that is
/// logged once at start-up).
#[derive(Resource)]
pub(crate) struct HadouRenderer(pub GpuBackend);

/// Views already warned about (invalid settings, a projection the pass cannot follow, a failed
/// pass), so each is logged once.
#[derive(Resource, Default)]
pub(crate) struct Warned(HashSet<(Entity, &'static str)>);

impl Warned {
    fn once(&mut self, view: Entity, what: &'static str, message: impl FnOnce() -> String) {
        if self.0.insert((view, what)) {
            warn!("{}", message());
        }
    }
}

pub(crate) fn extract_waves(mut extracted: ResMut<ExtractedWaves>, drawn: Extract<Res<DrawnWaves>>) {
    extracted.0 = drawn.clone();
}

/// Opens hadou-gpu's backend on Bevy's device, leaving Bevy's error handlers in place.
pub(crate) fn init_renderer(
    mut commands: Commands,
    adapter: Res<RenderAdapter>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
) {
    let queue: &wgpu::Queue = &queue.0;
    match GpuBackend::from_shared_device(&adapter.0, device.wgpu_device().clone(), queue.clone()) {
        Ok(backend) => commands.insert_resource(HadouRenderer(backend)),
        Err(e) => error!("hadou waves will not be drawn: {e}"),
    }
}

/// The frame the wave pass draws for one view: its camera, the extracted waves, the view's size
/// and the camera's exposure. Nothing else of the frame is read by the pass.
pub(crate) fn view_frame(
    camera: hadou_scene::Camera,
    size: UVec2,
    settings: &HadouCamera,
    waves: &[Wave],
) -> Frame {
    Frame {
        width: size.x,
        height: size.y,
        time: 0.0,
        camera,
        background: [0.0; 3],
        light: Light { direction: Vec3f::new(0.0, -1.0, 0.0), color: [1.0; 3], ambient: [0.0; 3] },
        objects: Vec::new(),
        waves: waves.to_vec(),
        color_mapping: ColorMapping { mode: ToneMode::Filmic, exposure: settings.exposure },
        shadows: Vec::new(),
        area_light: None,
        bloom: None,
        samples: 1,
    }
}

/// The wave pass of the current view: adds the waves' light into the view's HDR target, clipped
/// at its depth buffer.
pub(crate) fn wave_pass(
    view: ViewQuery<(&ExtractedView, &ViewTarget, &ViewDepthTexture, &HadouCamera, &Msaa)>,
    waves: Res<ExtractedWaves>,
    renderer: Option<ResMut<HadouRenderer>>,
    mut warned: ResMut<Warned>,
    mut ctx: RenderContext,
) {
    let entity = view.entity();
    let (extracted, target, depth, settings, msaa) = view.into_inner();
    let Some(mut renderer) = renderer else { return };
    let drawn = &waves.0;
    if drawn.waves.is_empty() {
        return;
    }
    if let Err(why) = settings.check() {
        warned.once(entity, "settings", || format!("hadou waves are not drawn into view {entity}: {why}"));
        return;
    }
    let viewport = extracted.viewport;
    if viewport.z == 0 || viewport.w == 0 {
        return; // a minimised window: nothing to draw into
    }
    let world_from_view = extracted.world_from_view.to_matrix();
    let (camera, projection) = match frame_view(&world_from_view, &extracted.clip_from_view, settings.far) {
        Ok(view) => view,
        Err(why) => {
            // The main world's `check_cameras` rejects the projections it can see; this is the
            // view as extracted (its transform too).
            warned.once(entity, "projection", || {
                format!("hadou waves are not drawn into view {entity}: {why}")
            });
            return;
        }
    };
    let prepared = match drawn.prepared.as_ref() {
        Ok(p) => p,
        Err(why) => {
            warned.once(entity, "pass", || format!("hadou waves are not drawn into view {entity}: {why}"));
            return;
        }
    };
    let frame = view_frame(camera, UVec2::new(viewport.z, viewport.w), settings, &drawn.waves);
    let overlay = OverlayTarget {
        color: target.main_texture_view(),
        color_format: target.main_texture_format(),
        depth: depth.view(),
        depth_model: DepthModel::ReverseInfinite,
        // With MSAA the depth buffer is multisampled (its first sample is read) and the target
        // is the resolved image the post-processing reads.
        depth_samples: msaa.samples(),
        blend: OverlayBlend::Add,
        // A viewport's corner (split screen, picture in picture): the frame is the viewport.
        origin: [viewport.x, viewport.y],
        // Perspective rays from the eye, or an orthographic view's parallel rays.
        projection,
    };
    if let Err(e) = renderer.0.encode_prepared_wave_overlay(&frame, prepared, ctx.command_encoder(), &overlay)
    {
        warned.once(entity, "pass", || format!("hadou waves are not drawn into view {entity}: {e}"));
    }
}
