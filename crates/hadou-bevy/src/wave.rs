//! [`HadouWave`]: one energy wave as a Bevy component, and the checks a wave passes before it is
//! drawn ([`check_wave`]): a wave that fails them is not drawn, and its entity is told why
//! ([`WaveRejected`]).

use bevy::prelude::*;
use hadou_gpu::layout::{waves_buffers, FrameWaves};
use hadou_scene::Wave;
pub use hadou_scene::WaveError;
use std::sync::Arc;

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

/// The waves drawn this frame: the enabled, accepted [`HadouWave`]s by entity, and their GPU
/// records with every curve prepared once ([`hadou_gpu::layout::waves_buffers`]). The wave
/// lights of the materials (`material::update_wave_lights`) and the wave pass of every view
/// (`render::wave_pass`, through the render world's copy) read these; nothing prepares a curve
/// again. Made anew only when a wave changed or the set of drawn waves did.
#[derive(Resource, Clone)]
pub(crate) struct DrawnWaves {
    /// The entities of `waves`, in order.
    pub entities: Vec<Entity>,
    /// The waves, by entity.
    pub waves: Arc<Vec<Wave>>,
    /// Their records (an error when the curves outgrow the GPU's buffers: nothing is drawn then,
    /// and the pass says why once per view).
    pub prepared: Arc<Result<FrameWaves, String>>,
    /// How many times the records were made (for tests: once per change, not per view).
    pub preparations: u64,
}

impl Default for DrawnWaves {
    fn default() -> Self {
        DrawnWaves {
            entities: Vec::new(),
            waves: Arc::default(),
            prepared: Arc::new(Ok(FrameWaves::default())),
            preparations: 0,
        }
    }
}

/// Makes [`DrawnWaves`] anew when a [`HadouWave`] changed or the set of drawn ones did.
pub(crate) fn prepare_drawn_waves(
    waves: Query<(Entity, &HadouWave), Without<WaveRejected>>,
    changed: Query<(), Changed<HadouWave>>,
    mut drawn: ResMut<DrawnWaves>,
) {
    let mut now: Vec<(Entity, &Wave)> =
        waves.iter().filter(|(_, w)| w.enabled).map(|(e, w)| (e, &w.wave)).collect();
    now.sort_by_key(|(e, _)| *e);
    let same_set =
        now.len() == drawn.entities.len() && now.iter().zip(&drawn.entities).all(|(a, b)| a.0 == *b);
    if same_set && changed.is_empty() && drawn.preparations > 0 {
        return;
    }
    let list: Vec<Wave> = now.iter().map(|(_, w)| (*w).clone()).collect();
    drawn.prepared = Arc::new(waves_buffers(&list));
    drawn.entities = now.iter().map(|(e, _)| *e).collect();
    drawn.waves = Arc::new(list);
    drawn.preparations += 1;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HadouPlugin;
    use std::path::Path;

    /// The waves' curves are prepared once per change of the drawn waves, not per frame, view or
    /// consumer: frames without a change keep the records; changing a wave, disabling one or
    /// adding one makes them anew; every drawn curve has its prepared form there for the lights.
    #[test]
    fn the_drawn_waves_are_prepared_once_per_change() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/light-curve.toml");
        let waves = hadou_scene::Scene::load(path).expect("the example scene").at(1.0).waves;
        assert!(waves.iter().any(|w| w.shape.curve().is_some()), "a curved wave");
        let mut app = App::new();
        app.add_plugins((MinimalPlugins, AssetPlugin::default(), HadouPlugin::default()));
        let first = app.world_mut().spawn(HadouWave::new(waves[0].clone())).id();
        for w in &waves[1..] {
            app.world_mut().spawn(HadouWave::new(w.clone()));
        }
        let count = |app: &App| app.world().resource::<DrawnWaves>().preparations;
        app.update();
        assert_eq!(count(&app), 1);
        app.update();
        app.update();
        assert_eq!(count(&app), 1, "no change, no preparation");
        {
            let drawn = app.world().resource::<DrawnWaves>();
            assert_eq!(drawn.waves.len(), waves.len());
            let prepared = drawn.prepared.as_ref().as_ref().expect("the records");
            assert_eq!(prepared.2.len(), waves.len(), "one entry per wave");
            for (w, c) in drawn.waves.iter().zip(&prepared.2) {
                assert_eq!(w.shape.curve().is_some(), c.is_some(), "{}", w.name);
            }
        }
        app.world_mut().get_mut::<HadouWave>(first).expect("the wave").wave.color[0] = 0.25;
        app.update();
        assert_eq!(count(&app), 2, "a changed wave");
        app.world_mut().get_mut::<HadouWave>(first).expect("the wave").enabled = false;
        app.update();
        assert_eq!(count(&app), 3, "a disabled wave");
        assert_eq!(app.world().resource::<DrawnWaves>().waves.len(), waves.len() - 1);
        app.update();
        assert_eq!(count(&app), 3);
    }
}
