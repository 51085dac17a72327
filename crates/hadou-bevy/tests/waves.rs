//! Bad wave values: `check_wave` names the `[[wave]]` key, and under `HadouPlugin` a bad wave is
//! marked `WaveRejected` (not drawn) without a panic, and accepted again once fixed.

use bevy::prelude::*;
use hadou_bevy::{check_wave, rejection_message, HadouPlugin, HadouWave, WaveRejected};
use hadou_math::energy::{BeamField, CapsuleField, CylinderField, Falloff, SphereField};
use hadou_math::Vec3f;
use hadou_scene::{Wave, WaveShape};

fn beam() -> Wave {
    let capsule = CapsuleField {
        m: Vec3f::new(-7.0, 1.0, 0.0),
        d: Vec3f::new(1.0, 0.0, 0.0),
        length: 5.0,
        alpha_s: 0.08,
        alpha_c: 0.08,
    };
    let shape = WaveShape::Beam(BeamField { capsule, head_alpha: 0.1, muzzle_alpha: 0.08 });
    Wave::new("beam", [0.35, 0.65, 1.0, 1.0], Falloff::InverseSquare, 0.05, shape)
}

fn key_of(wave: &Wave) -> &'static str {
    check_wave(wave).expect_err("the wave must be rejected").key
}

#[test]
fn a_valid_wave_passes() {
    assert_eq!(check_wave(&beam()), Ok(()));
}

#[test]
fn each_bad_value_names_its_key() {
    let mut w = beam();
    w.color[1] = f32::NAN;
    assert_eq!(key_of(&w), "rgba");

    let mut w = beam();
    w.color[3] = 1.5;
    assert_eq!(key_of(&w), "rgba");

    let mut w = beam();
    w.core_radius = -0.1;
    assert_eq!(key_of(&w), "core_radius");

    let mut w = beam();
    if let WaveShape::Beam(b) = &mut w.shape {
        b.capsule.d = Vec3f::new(0.0, 0.0, 0.0);
    }
    assert_eq!(key_of(&w), "D");

    let mut w = beam();
    if let WaveShape::Beam(b) = &mut w.shape {
        b.capsule.length = f32::INFINITY;
    }
    assert_eq!(key_of(&w), "length");

    let mut w = beam();
    if let WaveShape::Beam(b) = &mut w.shape {
        b.head_alpha = -1.0;
    }
    assert_eq!(key_of(&w), "head_alpha");

    let sphere = SphereField { center: Vec3f::new(f32::NAN, 0.0, 0.0), alpha: 1.0 };
    let w = Wave::new("s", [1.0; 4], Falloff::InverseSquare, 0.0, WaveShape::Sphere(sphere));
    assert_eq!(key_of(&w), "M");

    let cylinder =
        CylinderField { point: Vec3f::new(0.0, 0.0, 0.0), dir: Vec3f::new(0.0, 1.0, 0.0), alpha: 2e5 };
    let w = Wave::new("c", [1.0; 4], Falloff::InverseSquare, 0.0, WaveShape::Cylinder(cylinder));
    assert_eq!(key_of(&w), "alpha_c");
}

#[test]
fn the_log_line_names_the_entity_and_the_key() {
    let mut w = beam();
    w.color[0] = f32::NAN;
    let error = check_wave(&w).unwrap_err();
    let entity = Entity::from_raw_u32(7).unwrap();
    let line = rejection_message(entity, Some(&Name::new("beam")), &error);
    assert!(line.contains(&entity.to_string()), "{line}");
    assert!(line.contains("\"beam\"") && line.contains("`rgba`"), "{line}");
}

#[test]
fn a_bad_wave_is_rejected_without_a_panic_and_accepted_once_fixed() {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, HadouPlugin::default()));
    let mut bad = beam();
    bad.core_radius = f32::NAN;
    let good = app.world_mut().spawn(HadouWave::new(beam())).id();
    let wrong = app.world_mut().spawn((Name::new("broken"), HadouWave::new(bad))).id();
    app.update();
    assert!(app.world().get::<WaveRejected>(good).is_none());
    let rejected = app.world().get::<WaveRejected>(wrong).expect("the NaN core radius must be rejected");
    assert_eq!(rejected.0.key, "core_radius");
    app.update();

    app.world_mut().get_mut::<HadouWave>(wrong).unwrap().wave.core_radius = 0.05;
    app.update();
    assert!(app.world().get::<WaveRejected>(wrong).is_none(), "a fixed wave is drawn again");
}
