//! Split screen: a scene's camera drawn into the left half of an image (its viewport at the
//! image's corner) and a second camera, looking at the same scene from another side, into the right
//! half (its viewport away from the corner), each with its own wave pass against its own depth;
//! each half is held to hadou-cpu's render of the frame from that camera (what `hadou render`
//! writes without a GPU; one sample, the scene's mapping) to the parity bound of
//! `tests/parity.rs` (`common/split.rs`; `tests/window.rs` does the same on a window). Skips with
//! a message when there is no usable adapter; fails instead under `HADOU_REQUIRE_GPU=1`.

mod common;

use bevy::image::Image;
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use common::adapter_or_skip;
use common::picture::scenes;
use common::split::{check, halves, split, Split};
use hadou_bevy::{HadouPlugin, HadouSceneRoot, SceneClock, SpawnedScene};
use std::sync::{Arc, Mutex};

#[test]
fn two_viewports_each_draw_their_own_cameras_waves() {
    let test = "two_viewports_each_draw_their_own_cameras_waves";
    if !adapter_or_skip(test) {
        return;
    }
    let root = scenes().canonicalize().unwrap();
    let halves = halves(&root);
    let (w, h) = (halves.left.width, halves.left.height);

    let mut app = App::new();
    app.add_plugins(
        common::windowless().set(AssetPlugin { file_path: root.display().to_string(), ..default() }),
    )
    .add_plugins(HadouPlugin { asset_root: root.clone() });
    let image = Image::new_target_texture(2 * w, h, TextureFormat::Rgba8UnormSrgb, None);
    let image = app.world_mut().resource_mut::<Assets<Image>>().add(image);
    app.insert_resource(Split::new(Some(image.clone()), &halves)).add_systems(Update, split);
    let scene = app.world().resource::<AssetServer>().load(halves.file.to_string());
    let scene_root =
        app.world_mut().spawn(HadouSceneRoot { scene, clock: SceneClock::Frozen(halves.time) }).id();
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
    check("one image", &halves, shot);
}
