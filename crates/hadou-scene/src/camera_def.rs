//! The readers of `[image]` (the picture's size and samples per pixel) and `[camera]` (where it is
//! seen from), and the camera's rule across its keys ([`check_camera`]), which the scene reader
//! checks again at every key time of the tracks that move the camera.

use crate::limits::{fmt_f32, FAR_MAX, FOV_MAX, FOV_MIN, NEAR_MIN};
use crate::params::{Constraint, ParamSet, ANY, S, V3};
use crate::scene::up_is_usable;
use crate::toml_read::{Fallback, ParamReader, Res, Table};
use hadou_math::Vec3f;

/// The keys of `[image]`.
pub(crate) const IMAGE_KEYS: &[&str] = &["width", "height", "samples"];
/// The keys of `[camera]`.
pub(crate) const CAMERA_KEYS: &[&str] = &["position", "target", "up", "fov", "near", "far"];

/// `[image]` (`None`: the table is absent): width and height in `1..=16384` (512 each by
/// default) and the samples per pixel ([`crate::check_samples`], [`crate::DEFAULT_SAMPLES`] by
/// default).
pub(crate) fn parse_image(t: Option<&Table<'_, '_>>) -> Res<(u32, u32, u32)> {
    let (mut width, mut height, mut samples) = (512, 512, crate::DEFAULT_SAMPLES);
    if let Some(t) = t {
        t.check_keys(IMAGE_KEYS)?;
        width = t.opt_int("width", 1, 16384)?.map_or(width, |v| v.0 as u32);
        height = t.opt_int("height", 1, 16384)?.map_or(height, |v| v.0 as u32);
        if let Some((v, span)) = t.opt_int("samples", 1, i64::from(crate::MAX_SAMPLES))? {
            samples = v as u32;
            crate::check_samples(samples).map_err(|m| t.src.value_err(&span, m))?;
        }
    }
    Ok((width, height, samples))
}

/// `[camera]` (an empty table where the file has none): its parameters into `rd`'s store, each
/// range-checked, then [`check_camera`].
pub(crate) fn parse_camera(t: &Table<'_, '_>, rd: &mut ParamReader<'_>) -> Res<ParamSet> {
    t.check_keys(CAMERA_KEYS)?;
    let mut camera = ParamSet::default();
    let fov = Constraint::Range { lo: FOV_MIN, hi: FOV_MAX, lo_open: false, hi_open: false };
    let near = Constraint::Range { lo: NEAR_MIN, hi: FAR_MAX, lo_open: false, hi_open: true };
    let far = Constraint::Range { lo: NEAR_MIN, hi: FAR_MAX, lo_open: false, hi_open: false };
    rd.add(t, &mut camera, "position", V3, ANY, Fallback::Value(&[0.0, 0.0, 10.0]), false)?;
    rd.add(t, &mut camera, "target", V3, ANY, Fallback::Value(&[0.0; 3]), false)?;
    rd.add(t, &mut camera, "up", V3, Constraint::NonZero, Fallback::Value(&[0.0, 1.0, 0.0]), false)?;
    rd.add(t, &mut camera, "fov", S, fov, Fallback::Value(&[45.0]), false)?;
    rd.add(t, &mut camera, "near", S, near, Fallback::Value(&[0.1]), false)?;
    rd.add(t, &mut camera, "far", S, far, Fallback::Value(&[100.0]), false)?;
    if let Err((key, msg)) = check_camera(&camera, rd.values) {
        return Err(t.src.value_err(&t.key_span(key), format!("{msg} in [camera]")));
    }
    Ok(camera)
}

/// Camera rules across keys: `near < far`, eye ≠ target, `up` not parallel to the view.
pub(crate) fn check_camera(c: &ParamSet, vals: &[f32]) -> Result<(), (&'static str, String)> {
    let (near, far) = (c.f(vals, "near"), c.f(vals, "far"));
    if near >= far {
        return Err((
            "far",
            format!("`far` ({}) must be greater than `near` ({})", fmt_f32(far), fmt_f32(near)),
        ));
    }
    let eye = c.arr::<3>(vals, "position");
    let target = c.arr::<3>(vals, "target");
    // In f64: the distance of two points within ±1e6 is exact enough, and it cannot overflow.
    let dist =
        eye.iter().zip(&target).map(|(a, b)| (f64::from(*b) - f64::from(*a)).powi(2)).sum::<f64>().sqrt();
    if dist == 0.0 {
        return Err(("target", "`target` must differ from `position`".into()));
    }
    if dist < 1e-6 {
        return Err((
            "target",
            format!(
                "`target` is only {} from `position`; keep them at least 1e-6 apart so the view \
                 direction is defined",
                fmt_f32(dist as f32)
            ),
        ));
    }
    let Some(view) = (Vec3f::from_array(target) - Vec3f::from_array(eye)).try_normalize() else {
        return Err(("target", "`target` and `position` do not give a view direction".into()));
    };
    if !up_is_usable(Vec3f::from_array(c.arr(vals, "up")), view) {
        return Err(("up", "`up` must not be parallel to the view direction (target − position)".into()));
    }
    Ok(())
}
