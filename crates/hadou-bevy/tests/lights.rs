//! The waves as lights of every `HadouMaterial`: the plugin writes the drawn waves' records
//! (hadou-gpu's `GpuLight`s and a curve's polyline points) into the shared buffers each frame,
//! leaving out disabled and rejected waves.

use bevy::prelude::*;
use bevy::render::storage::ShaderBuffer;
use hadou_bevy::{light_records, HadouPlugin, HadouWave, MAX_WAVE_LIGHTS, WAVE_LIGHTS, WAVE_LIGHT_DATA};
use hadou_gpu::layout::{GpuLight, LINE_POLYLINE};
use std::path::Path;

fn waves_of(scene: &str) -> Vec<hadou_scene::Wave> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(scene);
    hadou_scene::Scene::load(path).unwrap().at(1.0).waves
}

fn words(app: &App, handle: &Handle<ShaderBuffer>) -> Vec<u32> {
    let buffers = app.world().resource::<Assets<ShaderBuffer>>();
    let data = buffers.get(handle).unwrap().data.as_ref().unwrap();
    bytemuck::pod_collect_to_vec(data)
}

#[test]
fn curves_light_from_their_polylines_and_glow_is_flagged() {
    let waves = waves_of("light-curve.toml");
    let (lights, data) = light_records(&waves);
    assert_eq!(data[0] as usize, waves.len());
    assert_eq!(data[1], u32::from(waves.iter().any(|w| w.light.glow > 0.0)));
    let curve = lights.iter().find(|l| l.line_kind == LINE_POLYLINE).expect("a curve lights from a polyline");
    assert!(curve.point_count >= 2);
    let end = (curve.point_offset + 3 * curve.point_count) as usize;
    assert!(curve.point_offset >= 4 && end <= data.len(), "the points follow the header");
    let first = f32::from_bits(data[curve.point_offset as usize]);
    assert!(first.is_finite());
}

#[test]
fn past_the_limit_the_first_waves_light() {
    let beam = waves_of("kamehameha.toml").remove(0);
    let (lights, data) = light_records(&vec![beam; MAX_WAVE_LIGHTS + 3]);
    assert_eq!((lights.len(), data[0] as usize), (MAX_WAVE_LIGHTS, MAX_WAVE_LIGHTS));
}

#[test]
fn the_plugin_writes_the_drawn_waves_into_the_shared_buffers() {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, AssetPlugin::default(), HadouPlugin::default()));
    let waves = waves_of("light-curve.toml");
    let beam = waves_of("kamehameha.toml").remove(0);
    let entities: Vec<Entity> =
        waves.iter().map(|w| app.world_mut().spawn(HadouWave::new(w.clone())).id()).collect();
    let beam_entity = app.world_mut().spawn(HadouWave::new(beam.clone())).id();
    app.update();
    // The plugin takes the waves in the order of their entities.
    let mut pairs: Vec<(Entity, hadou_scene::Wave)> =
        entities.iter().copied().zip(waves.iter().cloned()).collect();
    pairs.push((beam_entity, beam.clone()));
    let in_order = |pairs: &[(Entity, hadou_scene::Wave)]| {
        let mut pairs = pairs.to_vec();
        pairs.sort_by_key(|(e, _)| *e);
        pairs.into_iter().map(|(_, w)| w).collect::<Vec<_>>()
    };
    let (lights, data) = light_records(&in_order(&pairs));
    let written = words(&app, &WAVE_LIGHT_DATA);
    assert_eq!(&written[..data.len()], &data[..]);
    let light_words = words(&app, &WAVE_LIGHTS);
    let stride = std::mem::size_of::<GpuLight>() / 4;
    assert_eq!(light_words.len(), MAX_WAVE_LIGHTS * stride, "the lights buffer keeps its size");
    assert_eq!(&light_words[..lights.len() * stride], bytemuck::cast_slice::<GpuLight, u32>(&lights));

    // Disabled: not a light.
    app.world_mut().get_mut::<HadouWave>(entities[0]).unwrap().enabled = false;
    // Rejected (a NaN colour): not a light either.
    app.world_mut().get_mut::<HadouWave>(beam_entity).unwrap().wave.color[0] = f32::NAN;
    app.update();
    app.update();
    let written = words(&app, &WAVE_LIGHT_DATA);
    let (_, data) = light_records(&in_order(&pairs[1..waves.len()]));
    assert_eq!(written[0] as usize, waves.len() - 1);
    assert_eq!(&written[..data.len()], &data[..]);
}
