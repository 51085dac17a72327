//! [`HadouCamera`]: the per-camera settings of the wave pass, the hadou camera and rays a Bevy
//! view is drawn with ([`frame_camera`], [`frame_view`]), and the checks a camera passes before
//! its waves are drawn ([`check_camera`], [`CameraRejected`]).

use bevy::camera::Camera3dDepthTextureUsage;
use bevy::ecs::query::QueryItem;
use bevy::prelude::*;
use bevy::render::extract_component::ExtractComponent;
use bevy::render::render_resource::TextureUsages;
use bevy::render::sync_component::SyncComponent;
use hadou_gpu::OverlayProjection;
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

/// Put on a `Camera3d` (with `Hdr`; a perspective or orthographic `Projection`) to draw the
/// [`crate::HadouWave`]s into its view: after Bevy's main passes, before bloom and tone mapping.
/// A camera that fails [`check_camera`] gets [`CameraRejected`] and no waves.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
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

impl SyncComponent for HadouCamera {
    type Target = HadouCamera;
}

/// A camera's settings reach the render world (its wave pass) only while it is not
/// [`CameraRejected`].
impl ExtractComponent for HadouCamera {
    type QueryData = (&'static HadouCamera, Has<CameraRejected>);
    type QueryFilter = ();
    type Out = HadouCamera;

    fn extract_component((camera, rejected): QueryItem<'_, '_, Self::QueryData>) -> Option<HadouCamera> {
        (!rejected).then_some(*camera)
    }
}

/// Why a camera's waves are not drawn: the key of the component that is wrong and what is wrong
/// with it.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraError {
    /// The key: `exposure` or `far` (of [`HadouCamera`]), `fov`, `aspect_ratio`, `near`, `far`,
    /// `scale` or `area` (of the `Projection`), `projection` (its matrix), `viewport` (of
    /// `Camera`).
    pub key: &'static str,
    /// What is wrong, and what would be right.
    pub message: String,
}

impl std::fmt::Display for CameraError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "`{}`: {}", self.key, self.message)
    }
}

/// Put on a camera whose settings failed [`check_camera`] (and removed once they pass): its
/// waves are not drawn (its [`HadouCamera`] is not extracted), the rest of its view is Bevy's.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct CameraRejected(pub CameraError);

fn bad(key: &'static str, message: String) -> Result<(), CameraError> {
    Err(CameraError { key, message })
}

/// Checks what the wave pass reads of a camera: [`HadouCamera::check`] (`exposure`), a finite
/// positive `far`, a projection whose fields and matrix the pass can follow ([`frame_view`]:
/// a perspective `fov` in (0, π), `aspect_ratio` and `near` finite and positive; an orthographic
/// `scale` finite and positive, `area` of finite positive size, `near < far` finite) and a
/// viewport of non-zero size whose depth range lies in 0..=1. Anything else would put NaN or
/// infinity into the image, or draw the waves where the view is not.
pub fn check_camera(
    settings: &HadouCamera,
    projection: &Projection,
    viewport: Option<&bevy::camera::Viewport>,
) -> Result<(), CameraError> {
    if let Err(why) = settings.check() {
        return bad("exposure", why);
    }
    if !(settings.far.is_finite() && settings.far > 0.0) {
        return bad("far", format!("HadouCamera::far must be finite and positive, got {}", settings.far));
    }
    match projection {
        Projection::Perspective(p) => {
            if !(p.fov > 0.0 && p.fov < std::f32::consts::PI) {
                return bad("fov", format!("the perspective fov must be in (0, π) radians, got {}", p.fov));
            }
            if !(p.aspect_ratio.is_finite() && p.aspect_ratio > 0.0) {
                let a = p.aspect_ratio;
                return bad("aspect_ratio", format!("the aspect ratio must be finite and positive, got {a}"));
            }
            if !(p.near.is_finite() && p.near > 0.0 && p.near < settings.far) {
                let (near, far) = (p.near, settings.far);
                return bad(
                    "near",
                    format!("the near plane must be in (0, HadouCamera::far = {far}), got {near}"),
                );
            }
        }
        Projection::Orthographic(o) => {
            if !(o.scale.is_finite() && o.scale > 0.0) {
                return bad(
                    "scale",
                    format!("the orthographic scale must be finite and positive, got {}", o.scale),
                );
            }
            let size = o.area.size();
            if !(size.is_finite() && size.x > 0.0 && size.y > 0.0 && o.area.min.is_finite()) {
                return bad(
                    "area",
                    format!("the orthographic area must have a finite positive size, got {:?}", o.area),
                );
            }
            if !(o.near.is_finite() && o.far.is_finite() && o.far > o.near) {
                let (near, far) = (o.near, o.far);
                return bad(
                    "near",
                    format!("the orthographic planes must be finite with near < far, got {near}, {far}"),
                );
            }
        }
        _ => {}
    }
    if let Err(message) = frame_view(&Mat4::IDENTITY, &projection.get_clip_from_view(), settings.far) {
        return bad("projection", message);
    }
    if let Some(v) = viewport {
        if v.physical_size.x == 0 || v.physical_size.y == 0 {
            return bad(
                "viewport",
                format!("the viewport must have a non-zero size, got {}", v.physical_size),
            );
        }
        let (a, b) = (v.depth.start, v.depth.end);
        if !(0.0 <= a && a <= b && b <= 1.0) {
            return bad("viewport", format!("the viewport's depth range must lie in 0..=1, got {a}..{b}"));
        }
    }
    Ok(())
}

/// The error line logged for a rejected camera: the entity, its `Name` if any, the key and why.
pub fn camera_rejection_message(entity: Entity, name: Option<&Name>, error: &CameraError) -> String {
    match name {
        Some(name) => format!("hadou waves are not drawn into camera {entity} (\"{name}\"): {error}"),
        None => format!("hadou waves are not drawn into camera {entity}: {error}"),
    }
}

/// A camera as [`check_cameras`] reads it.
type CameraToCheck = (
    Entity,
    &'static HadouCamera,
    &'static Projection,
    &'static Camera,
    Option<&'static Name>,
    Option<&'static CameraRejected>,
);

/// A camera whose settings, projection or viewport changed (or were added).
type CameraChanged = Or<(Changed<HadouCamera>, Changed<Projection>, Changed<Camera>)>;

/// Checks every camera whose [`HadouCamera`], `Projection` or `Camera` was added or changed: a
/// failing one gets [`CameraRejected`] and one error log line ([`camera_rejection_message`])
/// each time the key it fails on changes; a passing one loses any [`CameraRejected`].
pub(crate) fn check_cameras(mut commands: Commands, cameras: Query<CameraToCheck, CameraChanged>) {
    for (entity, settings, projection, camera, name, rejected) in &cameras {
        match check_camera(settings, projection, camera.viewport.as_ref()) {
            Ok(()) => {
                if rejected.is_some() {
                    commands.entity(entity).remove::<CameraRejected>();
                }
            }
            Err(error) => {
                if rejected.map(|r| r.0.key) != Some(error.key) {
                    error!("{}", camera_rejection_message(entity, name, &error));
                    commands.entity(entity).insert(CameraRejected(error));
                }
            }
        }
    }
}

/// A camera that gained a [`HadouCamera`] or changed its `Msaa`.
type DepthToBind = (&'static mut Camera3d, Option<&'static bevy::render::view::Msaa>);
/// The cameras [`bind_depth`] looks at: those with a [`HadouCamera`] that is new or whose `Msaa`
/// changed.
type DepthChanged = (With<HadouCamera>, Or<(Added<HadouCamera>, Changed<bevy::render::view::Msaa>)>);

/// Lets the wave pass read the depth buffer of every camera that gained a [`HadouCamera`], except
/// a multisampled one on OpenGL: wgpu's GL backend creates a sampled multisampled texture with
/// the target `GL_TEXTURE_2D`, so its storage fails (`GL_INVALID_ENUM` from
/// `glTexStorage2DMultisample`) and Bevy's own passes draw into an incomplete framebuffer. Its
/// depth stays a render attachment only (the wave pass refuses such a view with a warning).
pub(crate) fn bind_depth(
    mut cameras: Query<DepthToBind, DepthChanged>,
    adapter: Option<Res<bevy::render::renderer::RenderAdapterInfo>>,
) {
    let gl = adapter.is_some_and(|a| a.0.backend == wgpu::Backend::Gl);
    for (mut camera, msaa) in &mut cameras {
        let bit = TextureUsages::TEXTURE_BINDING.bits();
        let usages = if gl && msaa.is_some_and(|m| m.samples() > 1) {
            camera.depth_texture_usages.0 & !bit
        } else {
            camera.depth_texture_usages.0 | bit
        };
        if usages != camera.depth_texture_usages.0 {
            camera.depth_texture_usages = Camera3dDepthTextureUsage(usages);
        }
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

/// The hadou camera and the rays of a Bevy view, for the wave pass
/// ([`hadou_gpu::OverlayProjection`]): a perspective view's from [`frame_camera`]; an
/// orthographic view's (an affine `clip_from_view`, Bevy's reverse-Z: clip depth 1 at the near
/// plane, 0 at the far) from the inverse projection: the near plane's points at NDC (0, 0),
/// (1, 0) and (0, 1) give the rays' start `centre` and the vectors `right`, `up`, the far plane's
/// distance from the near the depth's span, all in world space through `world_from_view`; the
/// frame camera stands at `centre` looking down the view's −Z (its `fov` and `near` are not read
/// by the orthographic rays; `far`, the falloff's and attenuation's length, is
/// [`HadouCamera::far`], 002 eq. 3.12, 3.23). Why not, for a projection the pass cannot follow.
pub fn frame_view(
    world_from_view: &Mat4,
    clip_from_view: &Mat4,
    far: f32,
) -> Result<(hadou_scene::Camera, OverlayProjection), String> {
    let c = clip_from_view;
    let affine = c.x_axis.w == 0.0 && c.y_axis.w == 0.0 && c.z_axis.w == 0.0 && c.w_axis.w == 1.0;
    if !affine {
        return frame_camera(world_from_view, clip_from_view, far)
            .map(|camera| (camera, OverlayProjection::Perspective))
            .ok_or_else(|| {
                format!(
                    "the projection must be Bevy's perspective (0 < near < HadouCamera::far = {far}, a finite fov) \
                     or an orthographic one"
                )
            });
    }
    if !(far.is_finite() && far > 0.0) {
        return Err(format!("HadouCamera::far must be finite and positive, got {far}"));
    }
    let view_from_clip = c.inverse();
    let at = |x: f32, y: f32, z: f32| view_from_clip.transform_point3(Vec3::new(x, y, z));
    let (centre, far_point) = (at(0.0, 0.0, 1.0), at(0.0, 0.0, 0.0));
    let (right, up) = (at(1.0, 0.0, 1.0) - centre, at(0.0, 1.0, 1.0) - centre);
    let span = centre.z - far_point.z;
    // Rays along −Z: the near plane is a z = const plane and the far point lies behind its centre
    // (to the inverse's rounding).
    let tol = 1e-5 * (right.length() + up.length() + span.abs());
    let off_axis = right.z.abs().max(up.z.abs()).max((far_point.truncate() - centre.truncate()).length());
    let square = off_axis <= tol;
    let sized = right.x.abs() > 0.0 && up.y.abs() > 0.0 && right.is_finite() && up.is_finite();
    if !(square && sized && span.is_finite() && span > 0.0) {
        return Err(format!(
            "the orthographic projection must look down −Z with a finite, non-empty area and near < far \
             (its near plane spans {right} × {up}, its depth {span})"
        ));
    }
    let world = |p: Vec3| world_from_view.transform_point3(p);
    let (centre_w, far_w) = (world(centre), world(far_point));
    let (right_w, up_w) = (world_from_view.transform_vector3(right), world_from_view.transform_vector3(up));
    let forward = far_w - centre_w;
    let depth_span = forward.length();
    let world_up = world_from_view.transform_vector3(Vec3::Y);
    let finite = centre_w.is_finite() && right_w.is_finite() && up_w.is_finite() && world_up.is_finite();
    if !(finite && depth_span.is_finite() && depth_span > 0.0) {
        return Err("the camera's transform must be finite and not degenerate".to_string());
    }
    let camera = hadou_scene::Camera {
        position: v(centre_w),
        target: v(centre_w + forward / depth_span),
        up: v(world_up),
        fov_y_deg: 90.0,
        near: far * 1e-6,
        far,
    };
    let a = |p: Vec3| p.to_array();
    Ok((
        camera,
        OverlayProjection::Orthographic { centre: a(centre_w), right: a(right_w), up: a(up_w), depth_span },
    ))
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
