//! [`HadouWave`]: one energy wave as a Bevy component, and the checks a wave passes before it is
//! drawn ([`check_wave`]): a wave that fails them is not drawn, and its entity is told why
//! ([`WaveRejected`]).

use bevy::prelude::*;
use hadou_math::energy::{BeamField, CapsuleField};
use hadou_math::Vec3f;
use hadou_scene::{Wave, WaveShape, ALPHA_MAX};

/// One energy wave, drawn by [`crate::HadouPlugin`] into every camera with a
/// [`crate::HadouCamera`]. Change `wave` from any system to animate it (its shape's centre,
/// direction, length, strengths, colour, …: the same values as a `[[wave]]` of a scene file).
#[derive(Component, Clone, Debug)]
pub struct HadouWave {
    /// The wave: shape, colour `rgba`, falloff and core radius.
    pub wave: Wave,
    /// Whether it is drawn.
    pub enabled: bool,
}

impl HadouWave {
    /// An enabled wave.
    pub fn new(wave: Wave) -> Self {
        HadouWave { wave, enabled: true }
    }
}

/// Put on an entity whose [`HadouWave`] failed [`check_wave`] (and removed once it passes): the
/// wave is not drawn. The failure is logged once per bad key, naming the entity and the key.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct WaveRejected(pub WaveError);

/// Why a wave cannot be drawn: the scene-file key of the bad value and what is wrong with it.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("`{key}` {message}")]
pub struct WaveError {
    /// The `[[wave]]` key, e.g. `"rgba"`, `"core_radius"`, `"D"`, `"alpha_s"`.
    pub key: &'static str,
    /// What is wrong and what would be right.
    pub message: String,
}

fn fail(key: &'static str, message: impl Into<String>) -> Result<(), WaveError> {
    Err(WaveError { key, message: message.into() })
}

fn finite_point(key: &'static str, p: Vec3f) -> Result<(), WaveError> {
    if [p.x, p.y, p.z].iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        fail(key, format!("must be finite (got [{}, {}, {}])", p.x, p.y, p.z))
    }
}

fn direction(key: &'static str, d: Vec3f) -> Result<(), WaveError> {
    finite_point(key, d)?;
    if d.length() > 1e-6 {
        Ok(())
    } else {
        fail(key, "must be a non-zero direction")
    }
}

fn strength(key: &'static str, alpha: f32) -> Result<(), WaveError> {
    if (0.0..=ALPHA_MAX).contains(&alpha) {
        Ok(())
    } else {
        fail(key, format!("must be in [0, {ALPHA_MAX}] (got {alpha})"))
    }
}

fn non_negative(key: &'static str, v: f32) -> Result<(), WaveError> {
    if v >= 0.0 && v.is_finite() {
        Ok(())
    } else {
        fail(key, format!("must be finite and ≥ 0 (got {v})"))
    }
}

fn capsule(c: &CapsuleField<f32>) -> Result<(), WaveError> {
    finite_point("M", c.m)?;
    direction("D", c.d)?;
    non_negative("length", c.length)?;
    strength("alpha_s", c.alpha_s)?;
    strength("alpha_c", c.alpha_c)
}

fn beam(b: &BeamField<f32>) -> Result<(), WaveError> {
    capsule(&b.capsule)?;
    strength("head_alpha", b.head_alpha)?;
    strength("muzzle_alpha", b.muzzle_alpha)
}

/// Checks what the wave pass reads against the ranges the scene reader enforces for the same
/// keys: `rgba` finite and ≥ 0 with alpha in [0, 1], `core_radius` finite and ≥ 0, positions
/// finite, directions finite and non-zero, lengths ≥ 0, strengths in `[0, ALPHA_MAX]`, the
/// attenuation exponent `j` in `[0, 64]`, and a
/// curve's own checks (`CurveWave::validate`).
pub fn check_wave(wave: &Wave) -> Result<(), WaveError> {
    let [r, g, b, a] = wave.color;
    if ![r, g, b, a].iter().all(|v| v.is_finite() && *v >= 0.0) || a > 1.0 {
        return fail("rgba", format!("must be finite and ≥ 0, alpha in [0, 1] (got [{r}, {g}, {b}, {a}])"));
    }
    non_negative("core_radius", wave.core_radius)?;
    let j = wave.attenuation;
    if !(0.0..=64.0).contains(&j) {
        return fail("j", format!("the attenuation exponent must be in [0, 64] (got {j})"));
    }
    match &wave.shape {
        WaveShape::Sphere(s) => {
            finite_point("M", s.center)?;
            strength("alpha_s", s.alpha)
        }
        WaveShape::Cylinder(c) => {
            finite_point("M", c.point)?;
            direction("D", c.dir)?;
            strength("alpha_c", c.alpha)
        }
        WaveShape::Capsule(c) => capsule(c),
        WaveShape::Beam(b) => beam(b),
        WaveShape::Curve(curve) => {
            strength("alpha", curve.alpha)?;
            curve.validate().map_err(|e| WaveError { key: e.field, message: e.message })
        }
    }
}

/// The error line logged for a rejected wave: the entity, its `Name` if any, the key and why.
pub fn rejection_message(entity: Entity, name: Option<&Name>, error: &WaveError) -> String {
    match name {
        Some(name) => format!("hadou wave {entity} (\"{name}\") not drawn: {error}"),
        None => format!("hadou wave {entity} not drawn: {error}"),
    }
}

/// A wave entity as [`check_changed_waves`] reads it.
type WaveToCheck = (Entity, &'static HadouWave, Option<&'static Name>, Option<&'static WaveRejected>);

/// Checks every added or changed [`HadouWave`]: a failing one gets [`WaveRejected`] and one error
/// log line ([`rejection_message`]) each time the key it fails on changes; a passing one loses
/// any [`WaveRejected`].
pub(crate) fn check_changed_waves(mut commands: Commands, waves: Query<WaveToCheck, Changed<HadouWave>>) {
    for (entity, wave, name, rejected) in &waves {
        match check_wave(&wave.wave) {
            Ok(()) => {
                if rejected.is_some() {
                    commands.entity(entity).remove::<WaveRejected>();
                }
            }
            Err(error) => {
                // Logged when the bad key changes, not on every frame of an animated bad value.
                if rejected.map(|r| r.0.key) != Some(error.key) {
                    error!("{}", rejection_message(entity, name, &error));
                    commands.entity(entity).insert(WaveRejected(error));
                }
            }
        }
    }
}
