//! Pictures of spawned scenes drawn by Bevy into images, and their difference from hadou-cpu's.

use bevy::camera::RenderTarget;
use bevy::image::Image;
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use hadou_bevy::{HadouCamera, HadouPlugin, HadouSceneRoot, SceneClock, SpawnedScene, ViewMapping};
use hadou_math::shade::linear_to_srgb8;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// The repository's scenes folder.
pub fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// The image every spawned scene camera renders into, and the mapping it is given instead of the
/// scene's, if any.
#[derive(Resource)]
struct Target(Handle<Image>, Option<ViewMapping>, bevy::render::view::Msaa);

fn into_image(
    mut commands: Commands,
    mut cameras: Query<(Entity, &mut HadouCamera), Added<HadouCamera>>,
    target: Res<Target>,
) {
    for (camera, mut settings) in &mut cameras {
        commands.entity(camera).insert((RenderTarget::Image(target.0.clone().into()), target.2));
        if let Some(mapping) = target.1 {
            settings.mapping = mapping;
        }
    }
}

/// The scene `file` at `time` drawn by Bevy into a `width × height` image (with `mapping`
/// instead of the scene's colour mapping, if given): its sRGB bytes, 4 per pixel, and the spawned
/// camera's mapping.
pub fn bevy_picture(
    file: &str,
    time: f32,
    size: (u32, u32),
    mapping: Option<ViewMapping>,
) -> (Vec<u8>, ViewMapping) {
    picture_in(&scenes(), file, time, size, mapping, bevy::render::view::Msaa::Off)
}

/// [`bevy_picture`] of the scene `file` in the folder `root`.
pub fn picture_in(
    root: &Path,
    file: &str,
    time: f32,
    size: (u32, u32),
    mapping: Option<ViewMapping>,
    msaa: bevy::render::view::Msaa,
) -> (Vec<u8>, ViewMapping) {
    let (mut pictures, mapping) = pictures_in(root, file, &[time], size, mapping, msaa);
    (pictures.remove(0), mapping)
}

/// [`picture_in`] at each of `times` in turn, drawn by one app (the root's clock is frozen at
/// the next time once a picture has come back): the pictures, and the spawned camera's mapping.
pub fn pictures_in(
    root: &Path,
    file: &str,
    times: &[f32],
    (width, height): (u32, u32),
    mapping: Option<ViewMapping>,
    msaa: bevy::render::view::Msaa,
) -> (Vec<Vec<u8>>, ViewMapping) {
    let root = root.canonicalize().expect("the scenes folder");
    let mut app = App::new();
    app.add_plugins(
        super::windowless().set(AssetPlugin { file_path: root.display().to_string(), ..default() }),
    )
    .add_plugins(HadouPlugin { asset_root: root.clone() });
    let image = Image::new_target_texture(width, height, TextureFormat::Rgba8UnormSrgb, None);
    let image = app.world_mut().resource_mut::<Assets<Image>>().add(image);
    app.insert_resource(Target(image.clone(), mapping, msaa)).add_systems(Update, into_image);
    let scene = app.world().resource::<AssetServer>().load(file.to_string());
    let root = app.world_mut().spawn(HadouSceneRoot { scene, clock: SceneClock::Frozen(times[0]) }).id();
    app.finish();
    app.cleanup();

    let shot: Arc<Mutex<Option<Image>>> = Arc::default();
    let mut pictures = Vec::with_capacity(times.len());
    let mut drawn = 0;
    let start = std::time::Instant::now();
    let mut frames = 0;
    for _ in 0..2000 {
        frames += 1;
        app.update();
        if app.world().get::<SpawnedScene>(root).is_some_and(|s| s.ready) {
            drawn += 1;
        }
        // A few frames after every object has hadou's look (glTF files load asynchronously),
        // once the meshes and pipelines are ready.
        if drawn == 5 {
            let shot = shot.clone();
            app.world_mut().spawn(Screenshot::image(image.clone())).observe(
                move |captured: On<ScreenshotCaptured>| {
                    *shot.lock().unwrap() = Some(captured.image.clone());
                },
            );
        }
        if let Some(image) = shot.lock().unwrap().take() {
            assert_eq!((image.width(), image.height()), (width, height));
            assert_eq!(image.texture_descriptor.format, TextureFormat::Rgba8UnormSrgb);
            pictures.push(image.data.expect("a captured image has its bytes"));
            let Some(&next) = times.get(pictures.len()) else { break };
            app.world_mut().get_mut::<HadouSceneRoot>(root).unwrap().clock = SceneClock::Frozen(next);
            drawn = 0;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    eprintln!(
        "{file}: {frames} updates in {:.1} s until the last of {} screenshots",
        start.elapsed().as_secs_f64(),
        times.len()
    );
    assert_eq!(pictures.len(), times.len(), "every screenshot came back");
    let camera = app.world().get::<SpawnedScene>(root).unwrap().camera;
    let mapping = app.world().get::<HadouCamera>(camera).unwrap().mapping;
    (pictures, mapping)
}

/// The mean and the largest absolute difference of the RGB bytes of `bevy` (4 per pixel) and
/// hadou-cpu's `image` encoded as `hadou render` encodes it.
pub fn difference(bevy: &[u8], image: &hadou_scene::Image) -> (f64, u8) {
    assert_eq!(bevy.len(), image.color.len() * 4);
    let (mut sum, mut max) = (0u64, 0u8);
    for (b, c) in bevy.chunks_exact(4).zip(&image.color) {
        for channel in 0..3 {
            let d = b[channel].abs_diff(linear_to_srgb8(c[channel]));
            sum += u64::from(d);
            max = max.max(d);
        }
    }
    (sum as f64 / (image.color.len() * 3) as f64, max)
}
