//! Split screen: a scene's camera drawn into the left half of an image (its viewport at the
//! image's corner) and a second camera, looking at the same scene from another side, into the right
//! half (its viewport away from the corner), each with its own wave pass against its own depth;
//! each half is held to hadou-cpu's render of the frame from that camera (what `hadou render`
//! writes without a GPU; one sample, the scene's mapping) to the parity bound of
//! `tests/parity.rs`. Skips with a message when there is no usable adapter; fails instead under
//! `HADOU_REQUIRE_GPU=1`.

mod common;

use bevy::camera::{RenderTarget, Viewport};
use bevy::image::Image;
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use common::adapter_or_skip;
use common::picture::{difference, scenes};
use hadou_bevy::{HadouCamera, HadouPlugin, HadouSceneRoot, SceneClock, SpawnedScene};
use hadou_math::Vec3f;
use std::sync::{Arc, Mutex};

/// The largest mean absolute difference of the 8-bit RGB values accepted in each half.
const MAX_MEAN: f64 = 2.0;

/// The image both cameras draw into, the size of each half, and the second camera's eye.
#[derive(Resource)]
struct Split {
    image: Handle<Image>,
    half: UVec2,
    eye: Vec3,
    target: Vec3,
}

/// Marks the second camera.
#[derive(Component)]
struct Second;

/// What [`split`] reads of the spawned scene camera.
type SceneCamera = (Entity, &'static mut Camera, &'static HadouCamera, &'static Projection);

/// Puts the spawned scene camera into the left half and a second camera of the same settings
/// into the right half.
fn split(
    mut commands: Commands,
    mut cameras: Query<SceneCamera, (Added<HadouCamera>, Without<Second>)>,
    split: Res<Split>,
) {
    for (entity, mut camera, settings, projection) in &mut cameras {
        camera.viewport = Some(Viewport { physical_size: split.half, ..default() });
        commands.entity(entity).insert(RenderTarget::Image(split.image.clone().into()));
        commands.spawn((
            Second,
            Camera3d::default(),
            Camera {
                order: 1,
                viewport: Some(Viewport {
                    physical_position: UVec2::new(split.half.x, 0),
                    physical_size: split.half,
                    ..default()
                }),
                clear_color: ClearColorConfig::None,
                ..default()
            },
            RenderTarget::Image(split.image.clone().into()),
            bevy::camera::Hdr,
            bevy::render::view::Msaa::Off,
            bevy::camera::Exposure { ev100: 0.0 },
            bevy::core_pipeline::tonemapping::Tonemapping::None,
            *settings,
            projection.clone(),
            Transform::from_translation(split.eye).looking_at(split.target, Vec3::Y),
        ));
    }
}

/// The `rows × (width · 4)` bytes of the `width`-wide half of `image` (4 bytes a pixel, `2 · width`
/// wide) starting at column `x0`.
fn half(image: &[u8], width: usize, x0: usize) -> Vec<u8> {
    image.chunks_exact(8 * width).flat_map(|row| row[4 * x0..4 * (x0 + width)].iter().copied()).collect()
}

#[test]
fn two_viewports_each_draw_their_own_cameras_waves() {
    let test = "two_viewports_each_draw_their_own_cameras_waves";
    if !adapter_or_skip(test) {
        return;
    }
    let (file, time) = ("kamehameha.toml", 1.5);
    let root = scenes().canonicalize().unwrap();
    let mut left = hadou_scene::Scene::load(root.join(file)).unwrap().at(time);
    left.samples = 1;
    left.bloom = None;
    // The second camera: the scene's eye turned 35° about the vertical through its target.
    let c = &left.camera;
    let (t, p) = (c.target, c.position);
    let (s, co) = 35f32.to_radians().sin_cos();
    let (dx, dz) = (p.x - t.x, p.z - t.z);
    let eye = Vec3f::new(t.x + co * dx + s * dz, p.y, t.z - s * dx + co * dz);
    let mut right = left.clone();
    right.camera.position = eye;
    right.camera.up = Vec3f::new(0.0, 1.0, 0.0);
    left.camera.up = Vec3f::new(0.0, 1.0, 0.0);
    let (w, h) = (left.width, left.height);

    let mut app = App::new();
    app.add_plugins(
        common::windowless().set(AssetPlugin { file_path: root.display().to_string(), ..default() }),
    )
    .add_plugins(HadouPlugin { asset_root: root.clone() });
    let image = Image::new_target_texture(2 * w, h, TextureFormat::Rgba8UnormSrgb, None);
    let image = app.world_mut().resource_mut::<Assets<Image>>().add(image);
    let v = |p: Vec3f| Vec3::new(p.x, p.y, p.z);
    app.insert_resource(Split { image: image.clone(), half: UVec2::new(w, h), eye: v(eye), target: v(t) })
        .add_systems(Update, split);
    let scene = app.world().resource::<AssetServer>().load(file.to_string());
    let scene_root = app.world_mut().spawn(HadouSceneRoot { scene, clock: SceneClock::Frozen(time) }).id();
    app.finish();
    app.cleanup();
    let shot: Arc<Mutex<Option<Image>>> = Arc::default();
    let mut drawn = 0;
    for _ in 0..2000 {
        app.update();
        if app.world().get::<SpawnedScene>(scene_root).is_some_and(|s| s.ready) {
            drawn += 1;
        }
        if drawn == 5 {
            let shot = shot.clone();
            app.world_mut().spawn(Screenshot::image(image.clone())).observe(
                move |captured: On<ScreenshotCaptured>| {
                    *shot.lock().unwrap() = Some(captured.image.clone());
                },
            );
        }
        if shot.lock().unwrap().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let shot = shot.lock().unwrap().take().expect("the screenshot came back");
    assert_eq!((shot.width(), shot.height()), (2 * w, h));
    let bytes = shot.data.expect("a captured image has its bytes");
    let (lref, rref) = (hadou_cpu::render(&left), hadou_cpu::render(&right));
    let (lb, rb) = (half(&bytes, w as usize, 0), half(&bytes, w as usize, w as usize));
    let (lm, lmax) = difference(&lb, &lref);
    let (rm, rmax) = difference(&rb, &rref);
    eprintln!("{file} at t = {time}, {w}×{h} each: left mean {lm:.3} (largest {lmax}), right mean {rm:.3} (largest {rmax})");
    assert!(lm <= MAX_MEAN, "left viewport: mean {lm:.3} > {MAX_MEAN} (largest {lmax})");
    assert!(rm <= MAX_MEAN, "right viewport: mean {rm:.3} > {MAX_MEAN} (largest {rmax})");
    // The two cameras see different pictures, and each half is its own camera's.
    let (cross, _) = difference(&rb, &lref);
    assert!(cross > 2.0 * MAX_MEAN, "the right half is the left camera's picture (mean {cross:.3})");
}
