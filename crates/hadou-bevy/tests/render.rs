//! The wave pass inside Bevy's renderer, on whatever adapter Bevy finds (lavapipe in CI): three
//! cameras render into images of their own; a sphere wave sits at the origin. The one looking at
//! it with a `HadouCamera` sees its light; the one whose view of it is blocked by a black box
//! sees the light clipped at the box (its own depth buffer); the one without a `HadouCamera`
//! sees none. Skips with a message when there is no usable adapter; fails instead under
//! `HADOU_REQUIRE_GPU=1`.

mod common;

use common::adapter_or_skip;

use bevy::camera::{Hdr, RenderTarget};
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::image::Image;
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::render::view::Msaa;
use hadou_bevy::{HadouCamera, HadouPlugin, HadouWave};
use hadou_math::energy::{Falloff, SphereField};
use hadou_math::Vec3f;
use hadou_scene::{Wave, WaveShape};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

const SIZE: u32 = 64;

type Shots = Arc<Mutex<HashMap<&'static str, Image>>>;

/// The sRGB bytes of pixel (x, y) of a captured `Rgba8UnormSrgb` image.
fn pixel(image: &Image, x: u32, y: u32) -> [u8; 3] {
    let data = image.data.as_ref().expect("a captured image has its bytes");
    let i = ((y * image.width() + x) * 4) as usize;
    [data[i], data[i + 1], data[i + 2]]
}

fn brightness(p: [u8; 3]) -> u32 {
    p.iter().map(|&c| u32::from(c)).sum()
}

fn camera(
    commands: &mut Commands,
    images: &mut Assets<Image>,
    eye: Vec3,
    hadou: bool,
) -> (Entity, Handle<Image>) {
    let image = images.add(Image::new_target_texture(SIZE, SIZE, TextureFormat::Rgba8UnormSrgb, None));
    let mut camera = commands.spawn((
        Camera3d::default(),
        Camera { clear_color: ClearColorConfig::Custom(Color::BLACK), ..default() },
        RenderTarget::Image(image.clone().into()),
        Hdr,
        Msaa::Off,
        Tonemapping::None,
        Transform::from_translation(eye).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    if hadou {
        camera.insert(HadouCamera::default());
    }
    (camera.id(), image)
}

fn setup(
    mut commands: Commands,
    mut images: ResMut<Assets<Image>>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut targets: ResMut<Targets>,
) {
    let sphere = SphereField { center: Vec3f::new(0.0, 0.0, 0.0), alpha: 0.5 };
    let wave =
        Wave::new("ball", [1.0, 0.8, 0.4, 1.0], Falloff::InverseSquare, 0.05, WaveShape::Sphere(sphere));
    commands.spawn(HadouWave::new(wave));
    // A black box between the third camera and the wave.
    commands.spawn((
        Mesh3d(meshes.add(Cuboid::new(2.0, 2.0, 0.2))),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::BLACK,
            unlit: true,
            ..default()
        })),
        Transform::from_xyz(6.0, 0.0, 0.0).looking_at(Vec3::new(10.0, 0.0, 0.0), Vec3::Y),
    ));
    targets.0.push(("seeing", camera(&mut commands, &mut images, Vec3::new(0.0, 0.0, 10.0), true).1));
    targets.0.push(("plain", camera(&mut commands, &mut images, Vec3::new(0.0, 10.0, 0.1), false).1));
    targets.0.push(("blocked", camera(&mut commands, &mut images, Vec3::new(10.0, 0.0, 0.0), true).1));
}

#[derive(Resource, Default)]
struct Targets(Vec<(&'static str, Handle<Image>)>);

#[test]
fn each_camera_gets_its_own_wave_pass_clipped_at_its_own_depth() {
    let test = "each_camera_gets_its_own_wave_pass_clipped_at_its_own_depth";
    if !adapter_or_skip(test) {
        return;
    }
    let mut app = App::new();
    app.add_plugins(common::windowless())
        .add_plugins(HadouPlugin::default())
        .init_resource::<Targets>()
        .add_systems(Startup, setup);
    app.finish();
    app.cleanup();

    let shots: Shots = Arc::default();
    for frame in 0..200 {
        app.update();
        if frame == 5 {
            let targets = app.world().resource::<Targets>().0.clone();
            for (name, image) in targets {
                let shots = shots.clone();
                app.world_mut().spawn(Screenshot::image(image)).observe(
                    move |captured: On<ScreenshotCaptured>| {
                        shots.lock().unwrap().insert(name, captured.image.clone());
                    },
                );
            }
        }
        if shots.lock().unwrap().len() == 3 {
            break;
        }
    }
    let shots = shots.lock().unwrap();
    assert_eq!(shots.len(), 3, "every camera's screenshot came back");
    for image in shots.values() {
        assert_eq!(image.texture_descriptor.format, TextureFormat::Rgba8UnormSrgb);
    }
    let centre = |name: &str| pixel(&shots[name], SIZE / 2, SIZE / 2);
    let corner = |name: &str| pixel(&shots[name], 1, 1);
    let (seeing, plain, blocked) = (centre("seeing"), centre("plain"), centre("blocked"));
    eprintln!(
        "centres: seeing {seeing:?}, plain {plain:?}, blocked {blocked:?}; corner {:?}",
        corner("seeing")
    );
    assert!(brightness(seeing) > 300, "the wave's light at its centre: {seeing:?}");
    assert!(brightness(seeing) > brightness(corner("seeing")), "brighter at the centre than in a corner");
    assert_eq!(plain, [0, 0, 0], "no light without a HadouCamera");
    assert!(
        brightness(blocked) * 4 < brightness(seeing),
        "the box in front clips the light (blocked {blocked:?}, seeing {seeing:?})"
    );
    assert!(brightness(corner("blocked")) > 0, "around the box the light still shows");
}
