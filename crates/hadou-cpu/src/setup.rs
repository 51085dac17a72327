//! The per-frame set-up every CPU render starts from ([`FrameSetup`]): the camera basis, the
//! waves' prepared curve tables, the waves as lights, and the hard shadows' casts with their maps.

use crate::shading::FrameLights;
use crate::shadows::ShadowCasts;
use crate::waves::prepare_curves;
use hadou_math::curve::PreparedCurve;
use hadou_scene::{CameraBasis, Frame};

/// What the passes of one frame share, computed once per frame.
pub(crate) struct FrameSetup {
    /// The camera basis at the frame's image size.
    pub basis: CameraBasis,
    /// The wave pass's prepared curves, one per wave (`None` for analytic waves).
    pub curves: Vec<Option<PreparedCurve>>,
    /// The waves as lights on the surfaces.
    pub lights: FrameLights,
    /// The hard shadows' casts and the maps of the map casts.
    pub shadows: ShadowCasts,
}

impl FrameSetup {
    /// The set-up of `frame`.
    pub(crate) fn new(frame: &Frame) -> Self {
        let basis = frame.camera.basis(frame.width, frame.height);
        let curves = prepare_curves(frame);
        let lights = FrameLights::new(frame, &curves);
        let shadows = ShadowCasts::new(frame, &lights.lines);
        FrameSetup { basis, curves, lights, shadows }
    }
}
