//! Helpers shared by the CPU backend's tests: hand-built frames.
#![allow(dead_code)]

use hadou_math::{Vec3, Vec3f};
use hadou_scene::{Camera, ColorMapping, Frame, Light, Object, ToneMode, Wave};

/// A camera at `eye` looking at the origin, y up, vertical field of view `fov_y_deg`, near plane
/// 0.1, far plane 100.
pub fn camera(eye: Vec3f, fov_y_deg: f32) -> Camera {
    Camera { position: eye, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg, near: 0.1, far: 100.0 }
}

/// A `width × height` frame at time 0 seen through `camera`: black background, a white light from
/// `(−0.3, −1, −0.5)` with ambient 0.1, filmic colour mapping at exposure 1, no shadows and no
/// area light.
pub fn frame(width: u32, height: u32, camera: Camera, objects: Vec<Object>, waves: Vec<Wave>) -> Frame {
    Frame {
        width,
        height,
        time: 0.0,
        camera,
        background: [0.0; 3],
        light: Light { direction: Vec3::new(-0.3, -1.0, -0.5), color: [1.0; 3], ambient: [0.1; 3] },
        objects,
        waves,
        color_mapping: ColorMapping { mode: ToneMode::Filmic, exposure: 1.0 },
        shadows: Vec::new(),
        area_light: None,
        bloom: None,
        samples: 1,
    }
}
