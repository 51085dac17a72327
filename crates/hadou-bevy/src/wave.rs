//! [`HadouWave`]: one energy wave as a Bevy component, and the checks a wave passes before it is
//! drawn ([`check_wave`]): a wave that fails them is not drawn, and its entity is told why
//! ([`WaveRejected`]).

use bevy::prelude::*;
use hadou_scene::Wave;
pub use hadou_scene::WaveError;

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

/// Checks what the wave pass reads against the ranges the scene reader enforces for the same
/// keys: hadou-scene's [`Wave::check`], with its constants (`ALPHA_MAX`, `ATTENUATION_MAX`,
/// `COORD_MAX`), so a wave an engine builds and a `[[wave]]` of a file are held to one rule.
pub fn check_wave(wave: &Wave) -> Result<(), WaveError> {
    wave.check()
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
