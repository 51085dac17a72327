//! The smallest use of the plugin: one beam wave whose head travels out and back, drawn into a
//! camera with a `HadouCamera`, with Bevy's bloom and tone mapping after it.
//!
//! ```text
//! cargo run --release --manifest-path crates/hadou-bevy/Cargo.toml --example beam
//! ```

use bevy::post_process::bloom::Bloom;
use bevy::prelude::*;
use hadou_bevy::{HadouCamera, HadouPlugin, HadouWave};
use hadou_math::energy::{BeamField, CapsuleField, Falloff};
use hadou_math::Vec3f;
use hadou_scene::{Wave, WaveShape};

fn main() {
    App::new()
        .add_plugins((DefaultPlugins, HadouPlugin::default()))
        .add_systems(Startup, setup)
        .add_systems(Update, fire)
        .run();
}

fn setup(mut commands: Commands) {
    commands.spawn((
        Camera3d::default(),
        bevy::camera::Hdr,
        bevy::render::view::Msaa::Off,
        Bloom::NATURAL,
        HadouCamera::default(),
        Transform::from_xyz(0.0, 3.0, 16.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    let capsule = CapsuleField {
        m: Vec3f::new(-7.0, 1.0, 0.0),
        d: Vec3f::new(1.0, 0.0, 0.0),
        length: 0.0,
        alpha_s: 0.08,
        alpha_c: 0.08,
    };
    let shape = WaveShape::Beam(BeamField { capsule, head_alpha: 0.1, muzzle_alpha: 0.08 });
    let wave = Wave::new("beam", [0.35, 0.65, 1.0, 1.0], Falloff::InverseSquare, 0.05, shape);
    commands.spawn((Name::new("beam"), HadouWave::new(wave)));
}

/// The head travels 14 units out in two seconds, then starts again.
fn fire(time: Res<Time>, mut waves: Query<&mut HadouWave>) {
    for mut wave in &mut waves {
        if let WaveShape::Beam(beam) = &mut wave.wave.shape {
            beam.capsule.length = (time.elapsed_secs() * 7.0) % 14.0;
        }
    }
}
