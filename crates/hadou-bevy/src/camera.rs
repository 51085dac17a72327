//! [`HadouCamera`]: the per-camera settings of the wave pass, and the hadou camera a Bevy view is
//! drawn with ([`frame_camera`]).

use bevy::camera::Camera3dDepthTextureUsage;
use bevy::prelude::*;
use bevy::render::extract_component::ExtractComponent;
use bevy::render::render_resource::TextureUsages;
use hadou_math::Vec3f;

/// How a [`HadouCamera`]'s view turns its HDR image into the colours it shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ViewMapping {
    /// Bevy's own tone mapping: the camera's `Tonemapping` component, untouched.
    #[default]
    Bevy,
    /// hadou's colour mapping of this mode (a scene's `[color] mode`): `map_faithful`, the
    /// thesis's clamp (002 §3.3), or `map_filmic`, hadou's white-core filmic curve
    /// (`hadou_math::shade`), run by hadou-gpu's WGSL on the HDR image after bloom, in place of
    /// Bevy's tone mapping (the plugin sets the camera's `Tonemapping` to `None`; set it back
    /// yourself when switching to [`ViewMapping::Bevy`]).
    Hadou(hadou_scene::ToneMode),
}

/// Put on a `Camera3d` (with `Hdr`, and `Msaa::Off` for now) to draw the [`crate::HadouWave`]s
/// into its view: after Bevy's main passes, before bloom and tone mapping.
#[derive(Component, Clone, Copy, Debug, PartialEq, ExtractComponent)]
pub struct HadouCamera {
    /// Multiplier of the waves' light (`[color] exposure` of a scene file): the pass adds
    /// `exposure · Σ rgb·a·I` (002 §3.3).
    pub exposure: f32,
    /// The far plane of the waves' rays (`[camera] far`): the length scale of the thesis falloff
    /// and of a curve's attenuation (002 eq. 3.12, 3.23). Bevy's own depth has no far plane.
    pub far: f32,
    /// Bevy's tone mapping (the default) or hadou's colour mapping (what a spawned scene uses:
    /// its `[color] mode`).
    pub mapping: ViewMapping,
}

impl Default for HadouCamera {
    fn default() -> Self {
        HadouCamera { exposure: 1.0, far: 1000.0, mapping: ViewMapping::Bevy }
    }
}

/// The largest `exposure` (the scene format's bound on `[color] exposure`, 1e6: with a wave's
/// strength and colour bounded too, `exposure · α · rgb` stays far inside f32).
pub const EXPOSURE_MAX: f32 = 1e6;

impl HadouCamera {
    /// Why the wave pass cannot draw with these settings, if it cannot: an `exposure` that is not
    /// a number in `0..=EXPOSURE_MAX` would put NaN or infinity into the image. (`far` is checked
    /// with the view's projection, in [`frame_camera`].)
    pub fn check(&self) -> Result<(), String> {
        if !(0.0..=EXPOSURE_MAX).contains(&self.exposure) {
            return Err(format!(
                "HadouCamera::exposure must be in 0..={EXPOSURE_MAX}, got {}",
                self.exposure
            ));
        }
        Ok(())
    }
}

/// Lets the wave pass read the depth buffer of every camera that gained a [`HadouCamera`].
pub(crate) fn bind_depth(mut cameras: Query<&mut Camera3d, Added<HadouCamera>>) {
    for mut camera in &mut cameras {
        let usages = camera.depth_texture_usages.0 | TextureUsages::TEXTURE_BINDING.bits();
        camera.depth_texture_usages = Camera3dDepthTextureUsage(usages);
    }
}

fn v(p: Vec3) -> Vec3f {
    Vec3f::new(p.x, p.y, p.z)
}

/// The hadou camera that sees what a Bevy perspective view sees: eye and axes from
/// `world_from_view` (looking down its −Z, up its +Y), the vertical field of view from
/// `clip_from_view`'s `f = 1 / tan(fov_y / 2)` (its `[1][1]`) and the near plane from its
/// `[3][2]` (Bevy's infinite reverse-Z perspective), `far` from [`HadouCamera`]. `None` for a
/// projection that is not such a perspective (orthographic, or a far plane not beyond the near).
pub fn frame_camera(world_from_view: &Mat4, clip_from_view: &Mat4, far: f32) -> Option<hadou_scene::Camera> {
    let is_perspective = clip_from_view.w_axis.w == 0.0 && clip_from_view.z_axis.w == -1.0;
    let f = clip_from_view.y_axis.y;
    let near = clip_from_view.w_axis.z;
    let planes_ok = near > 0.0 && far > near && far.is_finite();
    if !(is_perspective && f > 0.0 && f.is_finite() && planes_ok) {
        return None;
    }
    let eye = world_from_view.transform_point3(Vec3::ZERO);
    let forward = world_from_view.transform_vector3(Vec3::NEG_Z);
    let up = world_from_view.transform_vector3(Vec3::Y);
    if !(eye.is_finite() && forward.is_finite() && up.is_finite()) {
        return None;
    }
    Some(hadou_scene::Camera {
        position: v(eye),
        target: v(eye + forward),
        up: v(up),
        fov_y_deg: (2.0 * (1.0 / f).atan()).to_degrees(),
        near,
        far,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exposures_that_would_put_nan_or_infinity_into_the_image_are_refused() {
        assert!(HadouCamera::default().check().is_ok());
        for exposure in [f32::NAN, f32::INFINITY, -1.0, 2e6] {
            let e = HadouCamera { exposure, ..default() }.check().unwrap_err();
            assert!(e.contains("exposure") && e.contains("1000000"), "{e}");
        }
        assert!(HadouCamera { exposure: 0.0, ..default() }.check().is_ok());
    }
}
